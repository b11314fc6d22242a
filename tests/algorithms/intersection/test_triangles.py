"""Triangle-triangle intersection: hand cases, sign rule on shared edges, random pairs vs a reference."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms.intersection.triangles import intersect_triangles
from surfprep.errors import InvalidGeometryError

A = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)


def one(b, a=A):
    return intersect_triangles(np.asarray(a, float)[None], np.asarray(b, float)[None])


def segment_tri(p, q, tri):
    """Möller-Trumbore: the point where segment pq meets triangle tri, or None."""
    e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
    d = q - p
    h = np.cross(d, e2)
    det = e1 @ h
    if abs(det) < 1e-14:
        return None
    s = p - tri[0]
    u = (s @ h) / det
    qv = np.cross(s, e1)
    v = (d @ qv) / det
    t = (e2 @ qv) / det
    if u < 0 or v < 0 or u + v > 1 or t < 0 or t > 1:
        return None
    return p + t * d


def reference(a, b):
    """Segment of two generic triangles from edge-triangle tests, oriented along na x nb."""
    pts = [segment_tri(x[i], x[(i + 1) % 3], y) for x, y in ((a, b), (b, a)) for i in range(3)]
    pts = [p for p in pts if p is not None]
    if len(pts) < 2:
        return None
    direction = np.cross(np.cross(a[1] - a[0], a[2] - a[0]), np.cross(b[1] - b[0], b[2] - b[0]))
    s = [p @ direction for p in pts]
    return np.array([pts[int(np.argmin(s))], pts[int(np.argmax(s))]])


# ------------------------------------------------------------- hand cases
def test_crossing():
    hits = one([[0.2, 0.2, -1], [0.2, 0.2, 1], [0.6, 0.1, 0]])
    np.testing.assert_allclose(hits.segments, [[[0.6, 0.1, 0], [0.2, 0.2, 0]]], atol=1e-15)
    np.testing.assert_array_equal(hits.index, [0])
    # the ends in a: interior points; in b: a corner and the midpoint of edge 0-1
    np.testing.assert_allclose(hits.bary_a, [[[0.3, 0.6, 0.1], [0.6, 0.2, 0.2]]], atol=1e-15)
    np.testing.assert_allclose(hits.bary_b, [[[0, 0, 1], [0.5, 0.5, 0]]], atol=1e-15)
    np.testing.assert_array_equal(hits.source, [[1, 1]])
    assert hits.touch_points.shape == (0, 3) and hits.coplanar_index.size == 0


def test_barycentric_maps_reproduce_points():
    b = np.array([[0.1, 0.3, -0.5], [0.7, 0.1, 0.4], [0.2, 0.6, 0.3]])
    hits = one(b)
    np.testing.assert_allclose(np.einsum("ec,cd->ed", hits.bary_a[0], A), hits.segments[0],
                               atol=1e-15)
    np.testing.assert_allclose(np.einsum("ec,cd->ed", hits.bary_b[0], b), hits.segments[0],
                               atol=1e-15)
    np.testing.assert_allclose(hits.bary_a.sum(axis=2), 1)


def test_orientation_along_normal_cross_product():
    b = np.array([[0.2, 0.2, -1], [0.2, 0.2, 1], [0.6, 0.1, 0]])
    forward = one(b).segments[0]
    backward = one(b[::-1]).segments[0]                      # flipped normal of b
    np.testing.assert_array_equal(forward, backward[::-1])
    direction = np.cross(np.cross(A[1] - A[0], A[2] - A[0]), np.cross(b[1] - b[0], b[2] - b[0]))
    assert (forward[1] - forward[0]) @ direction > 0


@pytest.mark.parametrize("b", [
    [[0.2, 0.2, 0], [1, 0.2, 1], [0.2, 1, 1]],           # corner on a's face, from above
    [[0.2, 0.2, 0], [1, 0.2, -1], [0.2, 1, -1]],         # from below
    [[0.2, 0.2, 0], [1, 0.2, 1], [0.2, 1, -1e-300 + 1]],
])
def test_touching_at_a_vertex(b):
    hits = one(b)
    assert hits.segments.shape == (0, 2, 3)
    np.testing.assert_allclose(hits.touch_points, [[0.2, 0.2, 0]], atol=1e-15)
    np.testing.assert_array_equal(hits.touch_index, [0])
    np.testing.assert_allclose(hits.touch_bary_a, [[0.6, 0.2, 0.2]], atol=1e-15)


def test_touching_corner_to_corner():
    hits = one([[1, 0, 0], [2, 0, 1], [2, 1, -1]])
    assert hits.segments.shape[0] == 0
    np.testing.assert_array_equal(hits.touch_points, [[1, 0, 0]])


def test_sharing_an_edge_is_an_edge_contact():
    """A fin standing on a's edge: no segment (the paper's case 2), both ends as touching points."""
    hits = one([[0, 0, 0], [1, 0, 0], [0, 0, 1]])
    assert hits.segments.shape[0] == 0
    np.testing.assert_array_equal(hits.touch_points, [[0, 0, 0], [1, 0, 0]])
    np.testing.assert_array_equal(hits.touch_index, [0, 0])


def test_coplanar_overlapping_and_disjoint():
    tris_b = np.array([[[0.2, 0.2, 0], [1, 0.2, 0], [0.2, 1, 0]],     # overlapping
                       [[1, 1, 0], [2, 1, 0], [1, 2, 0]],             # disjoint, same plane
                       [[0.5, 0.5, 0], [2, 0.5, 0], [0.5, 2, 0]]])    # touching a's edge
    hits = intersect_triangles(np.repeat(A[None], 3, axis=0), tris_b)
    np.testing.assert_array_equal(hits.coplanar_index, [0, 2])
    assert hits.segments.shape[0] == 0 and hits.touch_points.shape[0] == 0


def test_coplanar_after_rounding_far_from_origin():
    shift = np.array([1e3, -2e3, 5e2])
    rot = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    a = (A * 1e-3) @ rot.T + shift
    b = (np.array([[0.2, 0.2, 0], [1, 0.2, 0], [0.2, 1, 0]]) * 1e-3) @ rot.T + shift
    hits = one(b, a)
    np.testing.assert_array_equal(hits.coplanar_index, [0])
    assert hits.segments.shape[0] == 0


def test_disjoint_and_empty():
    hits = one(A + [0, 0, 1])
    assert hits.segments.shape == (0, 2, 3) and hits.touch_points.shape == (0, 3)
    empty = intersect_triangles(np.zeros((0, 3, 3)), np.zeros((0, 3, 3)))
    assert empty.segments.shape == (0, 2, 3) and empty.index.shape == (0,)


@pytest.mark.parametrize("a, b, match", [
    (np.zeros((2, 3, 2)), np.zeros((2, 3, 2)), "shape"),
    (np.zeros((2, 3, 3)), np.zeros((1, 3, 3)), "differ"),
    (np.full((1, 3, 3), np.nan), np.zeros((1, 3, 3)), "NaN"),
])
def test_validation(a, b, match):
    with pytest.raises(InvalidGeometryError, match=match):
        intersect_triangles(a, b)


# ----------------------------------------------- meshes: the sign rule
def grid_mesh(xs, ys, z=0.0, flip=()):
    """Triangles of a grid in the plane z = const; ``flip`` reverses some triangles."""
    tris = []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            p00, p10 = [xs[i], ys[j], z], [xs[i + 1], ys[j], z]
            p11, p01 = [xs[i + 1], ys[j + 1], z], [xs[i], ys[j + 1], z]
            tris += [[p00, p10, p11], [p00, p11, p01]]
    tris = np.array(tris, float)
    for k in flip:
        tris[k] = tris[k][::-1]
    return tris


def all_pairs(ta, tb):
    i, j = np.meshgrid(np.arange(len(ta)), np.arange(len(tb)), indexing="ij")
    return intersect_triangles(ta[i.ravel()], tb[j.ravel()])


def covered_length(segments, axis):
    """Total length of segments along a line, and the length of their union."""
    lo = np.sort(segments[:, :, axis], axis=1)
    total = np.sum(lo[:, 1] - lo[:, 0])
    order = np.argsort(lo[:, 0])
    union, reach = 0.0, -np.inf
    for a, b in lo[order]:
        union += max(0.0, b - max(a, reach))
        reach = max(reach, b)
    return total, union


@pytest.mark.parametrize("flip_a, flip_b", [((), ()), ((1, 2), ()), ((), (0, 3)),
                                            ((0, 3), (2,))])
def test_edges_lying_in_the_other_plane(flip_a, flip_b):
    """Both meshes have edges on the intersection line x = 0.5, z = 0: one segment per
    piece, whatever the triangles' orientations, no gap, no double cover."""
    a = grid_mesh([0, 0.5, 1], [0, 1])                                     # z = 0 plane
    b = grid_mesh([-1, 0, 1], [-1, 2], z=0.5, flip=flip_b)[:, :, [2, 1, 0]]  # plane x = 0.5
    a = a.copy()
    for k in flip_a:
        a[k] = a[k][::-1]
    hits = all_pairs(a, b)
    assert np.all(hits.segments[:, :, 0] == 0.5) and np.all(hits.segments[:, :, 2] == 0)
    total, union = covered_length(hits.segments, axis=1)
    assert union == pytest.approx(1.0, abs=1e-15) and total == pytest.approx(1.0, abs=1e-15)


def test_curve_through_a_shared_edge_chains_bitwise():
    """A plane cutting two triangles across their shared edge: two segments with one
    common end, bitwise equal, produced by the same edge."""
    a = np.array([[[0, 0, 0], [1, 0, 0.2], [0, 1, 0.1]], [[1, 0, 0.2], [1, 1, 0.3], [0, 1, 0.1]]])
    b = np.array([[[0.3, -5, -5], [0.9, 5, -5], [0.6, 0, 5]]])
    hits = intersect_triangles(a, np.repeat(b, 2, axis=0))
    assert hits.segments.shape[0] == 2
    ends = hits.segments.reshape(-1, 3)
    _, counts = np.unique(ends, axis=0, return_counts=True)
    assert sorted(counts.tolist()) == [1, 1, 2]
    # the segments run the same way: end of one is start of the other
    assert (np.array_equal(hits.segments[0, 1], hits.segments[1, 0])
            or np.array_equal(hits.segments[1, 1], hits.segments[0, 0]))


def test_curve_through_a_shared_vertex():
    """A plane through a mesh vertex: the chain passes it without a gap."""
    a = grid_mesh([0, 0.5, 1], [0, 0.5, 1])
    b = np.array([[[0.5, 0.5, -1], [2, 2, -1], [-2, -2, 3.0]]])          # contains (0.5, 0.5, 0)
    hits = all_pairs(a, b)
    total, union = covered_length(hits.segments, axis=0)
    assert union == pytest.approx(1.0, abs=1e-12) and total == pytest.approx(1.0, abs=1e-12)


# ---------------------------------------------------- random vs reference
@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-3, 1.0, 1e3]))
def test_random_pairs_match_reference(seed, scale):
    rng = np.random.default_rng(seed)
    k = 200
    a = rng.random((k, 3, 3)) * scale
    b = rng.random((k, 3, 3)) * scale
    hits = intersect_triangles(a, b)
    got = {int(i): s for i, s in zip(hits.index, hits.segments)}
    for i in range(k):
        ref = reference(a[i], b[i])
        if ref is None or np.linalg.norm(ref[1] - ref[0]) < 1e-9 * scale:
            assert i not in got or np.linalg.norm(got[i][1] - got[i][0]) < 1e-9 * scale
            continue
        assert i in got
        np.testing.assert_allclose(got[i], ref, atol=1e-9 * scale)
    assert hits.touch_points.shape[0] == 0 and hits.coplanar_index.size == 0


def lattice_mesh(rng, n, flip_share=0.3):
    """Triangles of an n x n unit grid in z = 0, random diagonals and orientations."""
    tris = []
    for i in range(n):
        for j in range(n):
            p00, p10, p11, p01 = [i, j, 0], [i + 1, j, 0], [i + 1, j + 1, 0], [i, j + 1, 0]
            if rng.random() < 0.5:
                tris += [[p00, p10, p11], [p00, p11, p01]]
            else:
                tris += [[p00, p10, p01], [p10, p11, p01]]
    tris = np.array(tris, float)
    flip = rng.random(len(tris)) < flip_share
    tris[flip] = tris[flip][:, ::-1]
    return tris


def wall_mesh(rng, origin, direction, z_rows, flip_share=0.3):
    """Vertical strip over the line origin + t direction, t in [-20, 20], rows at z_rows."""
    ts = np.arange(-20, 21, 2.0)
    tris = []
    for t0, t1 in zip(ts[:-1], ts[1:]):
        for z0, z1 in zip(z_rows[:-1], z_rows[1:]):
            q = [np.r_[origin + t * direction, z] for t, z in ((t0, z0), (t1, z0), (t1, z1),
                                                                (t0, z1))]
            if rng.random() < 0.5:
                tris += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
            else:
                tris += [[q[0], q[1], q[3]], [q[1], q[2], q[3]]]
    tris = np.array(tris, float)
    flip = rng.random(len(tris)) < flip_share
    tris[flip] = tris[flip][:, ::-1]
    return tris


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1),
       direction=st.sampled_from([(1, 0), (0, 1), (1, 1), (1, -1), (2, 1)]),
       offset=st.sampled_from([(2, 0), (1, 1), (2, 2), (0.5, 1), (0, 0)]),
       z_rows=st.sampled_from([(-1.0, 0.0, 1.0), (-1.0, 1.0), (-0.5, 0.0, 0.25, 1.0)]))
def test_lattice_degeneracies_cover_the_line_once(seed, direction, offset, z_rows):
    """Meshes whose vertices and edges lie exactly in the other plane, in every
    orientation: the segments cover the exact intersection once, no gap, no overlap.

    Along the boundary of a (the line y = 0 or x = 0) the contact is degenerate:
    the perturbation decides all or nothing, and nothing leaves touching points."""
    rng = np.random.default_rng(seed)
    n = 4
    a = lattice_mesh(rng, n)
    d = np.array(direction, float)
    b = wall_mesh(rng, np.array(offset, float), d, np.array(z_rows))
    hits = all_pairs(a, b)
    # the exact intersection: the line clipped to the square [0, n]^2, parameter along d
    t = (hits.segments[..., :2] - offset) @ d / (d @ d)
    lo, hi = -np.inf, np.inf
    for k in range(2):
        if d[k] != 0:
            ends = sorted([(0 - offset[k]) / d[k], (n - offset[k]) / d[k]])
            lo, hi = max(lo, ends[0]), min(hi, ends[1])
        elif not 0 <= offset[k] <= n:
            lo, hi = 1, 0
    expected = max(hi - lo, 0.0)
    assert np.all(np.abs(hits.segments[..., 2]) == 0)
    t = np.sort(t, axis=1)
    total = np.sum(t[:, 1] - t[:, 0])
    union, reach = 0.0, -np.inf
    for s0, s1 in t[np.argsort(t[:, 0])]:
        union += max(0.0, s1 - max(s0, reach))
        reach = max(reach, s1)
    on_boundary = any(d[1 - k] == 0 and offset[1 - k] in (0, n) for k in range(2))
    if expected == 0:
        assert hits.segments.shape[0] == 0
    elif on_boundary:
        assert union == total and union in (0.0, pytest.approx(expected, abs=1e-12))
        if union == 0:
            assert hits.touch_points.shape[0] > 0
    else:
        assert union == pytest.approx(expected, abs=1e-12)
        assert total == pytest.approx(expected, abs=1e-12)
