"""SSI step 4: Point/PointUse/Segment topology and curve tracing on synthetic segment soups.

The soups imitate triangle-triangle intersection output: polylines sampled from
known curves, cut into segments, shuffled, each segment randomly flipped, and
every shared end point jittered by ~1e-12 so that no two copies are bitwise equal.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms.intersection.topology import EndKind, build_topology
from surfprep.errors import InvalidGeometryError, InvalidToleranceError

TOL = 1e-9


def soup(polylines, rng, jitter=1e-12, uvs=None):
    """Segments of the polylines, shuffled and flipped; returns (points, uv) (k, 2, 3), (k, 2, 2)."""
    segs, uv = [], []
    for i, line in enumerate(polylines):
        segs.append(np.stack([line[:-1], line[1:]], axis=1))
        if uvs is not None:
            uv.append(np.stack([uvs[i][:-1], uvs[i][1:]], axis=1))
    pts = np.concatenate(segs)
    pts = pts + rng.uniform(-jitter, jitter, pts.shape)
    order = rng.permutation(len(pts))
    flip = rng.random(len(pts)) < 0.5
    pts = pts[order]
    pts[flip] = pts[flip, ::-1]
    if uvs is None:
        return pts, None
    uv = np.concatenate(uv)[order]
    uv[flip] = uv[flip, ::-1]
    return pts, uv


def helix(n, t0=0.0, t1=3.0):
    t = np.linspace(t0, t1, n)
    return np.stack([np.cos(t), np.sin(t), 0.1 * t], axis=1)


def circle(n, center=(0.0, 0.0, 0.0), r=1.0, closed=True):
    t = np.linspace(0, 2 * np.pi, n + 1)
    pts = np.stack([center[0] + r * np.cos(t), center[1] + r * np.sin(t),
                    np.full(t.size, center[2])], axis=1)
    pts[-1] = pts[0]
    return pts


def assert_same_polyline(traced, expected, closed=False):
    """The traced points are the expected ones in order, up to direction (and start, if closed)."""
    assert len(traced) == len(expected) - (1 if closed else 0)
    exp = expected[:-1] if closed else expected
    if closed:
        k = int(np.argmin(np.linalg.norm(exp - traced[0], axis=1)))
        exp = np.roll(exp, -k, axis=0)
        if np.linalg.norm(exp[1] - traced[1]) > 1e-6:
            exp = np.roll(exp[::-1], 1, axis=0)
    elif np.linalg.norm(traced[0] - exp[0]) > 1e-6:
        exp = exp[::-1]
    np.testing.assert_allclose(traced, exp, atol=1e-9)


@given(st.integers(0, 2**32 - 1), st.integers(2, 60))
@settings(max_examples=30, deadline=None)
def test_open_chain(seed, n):
    rng = np.random.default_rng(seed)
    line = helix(n)
    pts, _ = soup([line], rng)
    topo = build_topology(pts, tol=TOL)
    assert len(topo.chains) == 1
    chain = topo.chains[0]
    assert not chain.closed
    assert chain.start_kind is EndKind.OPEN and chain.end_kind is EndKind.OPEN
    assert_same_polyline(topo.chain_points(chain), line)
    assert np.sort(topo.uses).tolist() == [1, 1] + [2] * (n - 2)
    # segment ids join consecutive points
    seg = topo.segments[chain.segment_ids]
    pairs = np.sort(np.stack([chain.point_ids[:-1], chain.point_ids[1:]], axis=1), axis=1)
    np.testing.assert_array_equal(np.sort(seg, axis=1), pairs)


@pytest.mark.parametrize("closed", [False, True])
def test_chains_follow_segment_direction(closed):
    """Shuffled but not flipped (as the soup orients them): chains run the input way."""
    rng = np.random.default_rng(11)
    line = circle(16) if closed else helix(16)
    for reverse in (False, True):
        seq = line[::-1] if reverse else line
        segs = np.stack([seq[:-1], seq[1:]], axis=1)[rng.permutation(15 if not closed else 16)]
        segs[:2] = segs[:2, ::-1]                       # a few stray flips are outvoted
        c = build_topology(segs, tol=TOL).chains[0]
        p = build_topology(segs, tol=TOL).chain_points(c)
        step = p[1] - p[0]
        expected = seq[1] - seq[0] if not closed else None
        if closed:
            k = int(np.argmin(np.linalg.norm(seq[:-1] - p[0], axis=1)))
            expected = seq[k + 1] - seq[k]
        else:
            np.testing.assert_allclose(p[0], seq[0], atol=1e-12)
        np.testing.assert_allclose(step, expected, atol=1e-12)


@given(st.integers(0, 2**32 - 1))
@settings(max_examples=20, deadline=None)
def test_two_disjoint_loops(seed):
    rng = np.random.default_rng(seed)
    a, b = circle(17), circle(23, center=(3.0, 0.0, 1.0), r=0.5)
    pts, _ = soup([a, b], rng)
    topo = build_topology(pts, tol=TOL)
    assert len(topo.chains) == 2
    assert all(c.closed and c.start_kind is EndKind.CLOSED for c in topo.chains)
    sizes = sorted(len(c) for c in topo.chains)
    assert sizes == [17, 23]
    for c in topo.chains:
        ref = a if len(c) == 17 else b
        assert_same_polyline(topo.chain_points(c), ref, closed=True)
        assert c.segment_ids.size == len(c)
    assert np.all(topo.uses == 2)


def test_figure_eight_breaks_at_bifurcation():
    rng = np.random.default_rng(1)
    left = circle(12, center=(-1.0, 0.0, 0.0))     # both circles pass through the origin
    right = circle(12, center=(1.0, 0.0, 0.0))
    np.testing.assert_allclose(left[0], 0, atol=1e-15)
    np.testing.assert_allclose(right[6], 0, atol=1e-15)
    pts, _ = soup([left, right], rng)
    topo = build_topology(pts, tol=TOL)
    center = int(np.argmin(np.linalg.norm(topo.points, axis=1)))
    assert topo.uses[center] == 4
    assert len(topo.chains) == 2
    for c in topo.chains:
        assert not c.closed
        assert c.start_kind is EndKind.BIFURCATION and c.end_kind is EndKind.BIFURCATION
        assert c.point_ids[0] == center and c.point_ids[-1] == center
        assert len(c) == 13


def test_t_junction_three_curves():
    rng = np.random.default_rng(2)
    x = np.linspace(-1, 1, 11)
    bar = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)
    stem = np.stack([np.zeros(6), np.linspace(0, -1, 6), np.zeros(6)], axis=1)
    pts, _ = soup([bar, stem], rng)
    topo = build_topology(pts, tol=TOL)
    assert sorted(len(c) for c in topo.chains) == [6, 6, 6]
    kinds = sorted((c.start_kind.value, c.end_kind.value) for c in topo.chains)
    assert all(EndKind.BIFURCATION.value in k for k in kinds)


def test_overlapping_segments_along_one_line_are_one_curve():
    """A plane through a row of mesh vertices: the triangles on both sides of that row
    each give segments along it, finer on one side than on the other, overlapping
    without sharing their ends. Split at each other's ends they are one simple curve
    (they were read as three-way junctions: the sheet z = 0.1 x y cut by y = 0.5 came
    out as seven pieces)."""
    x = lambda *v: np.array([[t, 0.5, 0.05 * t] for t in v])
    coarse = [x(0.0, 0.4), x(0.4, 0.7), x(0.7, 1.0)]
    fine = [x(0.0, 0.2), x(0.2, 0.4), x(0.4, 0.55), x(0.55, 0.7), x(0.7, 0.85), x(0.85, 1.0)]
    shifted = [x(0.3, 0.6)]                                     # ends on neither side's ends
    topo = build_topology(np.array(coarse + fine + shifted), tol=TOL)
    assert len(topo.chains) == 1 and not topo.chains[0].closed
    assert np.all(topo.uses <= 2)
    chain = topo.points[topo.chains[0].point_ids]
    assert np.all(np.diff(chain[:, 0]) > 0) or np.all(np.diff(chain[:, 0]) < 0)
    assert {chain[0, 0], chain[-1, 0]} == {0.0, 1.0}


def test_box_border_gap_merged():
    """A curve cut at an overlap-box border: the two halves end 1e-12 apart."""
    rng = np.random.default_rng(3)
    line = helix(31)
    first, second = line[:16].copy(), line[15:].copy()
    second[0] += 1e-12 * np.array([1.0, -1.0, 0.5])
    pts, _ = soup([first, second], rng, jitter=0)
    topo = build_topology(pts, tol=TOL)
    assert len(topo.chains) == 1 and len(topo.chains[0]) == 31


def test_hanging_ends_joined_with_join_tol():
    """Misaligned triangulations of two boxes leave a 1e-4 gap: joined only with join_tol."""
    rng = np.random.default_rng(4)
    line = helix(31)
    first, second = line[:16].copy(), line[15:].copy()
    second[0] += 1e-4
    pts, _ = soup([first, second], rng)
    assert len(build_topology(pts, tol=TOL).chains) == 2
    topo = build_topology(pts, tol=TOL, join_tol=1e-3)
    assert len(topo.chains) == 1 and len(topo.chains[0]) == 31
    assert topo.chains[0].start_kind is EndKind.OPEN


def test_join_closes_a_loop():
    rng = np.random.default_rng(5)
    ring = circle(20)
    ring[-1] = ring[0] + 1e-5
    pts, _ = soup([ring], rng)
    assert not build_topology(pts, tol=TOL).chains[0].closed
    topo = build_topology(pts, tol=TOL, join_tol=1e-4)
    assert len(topo.chains) == 1 and topo.chains[0].closed and len(topo.chains[0]) == 20


def test_duplicate_and_zero_length_segments_dropped():
    rng = np.random.default_rng(6)
    line = helix(21)
    pts, _ = soup([line], rng)
    dup = pts[[3, 7, 11]][:, ::-1] + 1e-13           # same segments again, reversed
    zero = np.repeat(line[[5, 9]][:, None, :], 2, axis=1)
    zero[:, 1] += 1e-13
    all_pts = np.concatenate([pts, dup, zero])
    topo = build_topology(all_pts, tol=TOL)
    assert topo.segments.shape[0] == 20
    assert len(topo.chains) == 1 and len(topo.chains[0]) == 21
    assert np.all(topo.source < len(pts))           # the first copy is kept


def test_boundary_ends_from_uv():
    rng = np.random.default_rng(7)
    t = np.linspace(0, 1, 11)
    line = np.stack([t, 0.5 * np.ones_like(t), np.zeros_like(t)], axis=1)
    uv_a = np.stack([t, 0.5 * np.ones_like(t)], axis=1)          # (0, .5) and (1, .5) on the boundary
    uv_b = np.stack([0.2 + 0.5 * t, 0.3 * np.ones_like(t)], axis=1)
    pts, uva = soup([line], rng, uvs=[uv_a])
    _, uvb = soup([line], np.random.default_rng(7), uvs=[uv_b])
    topo = build_topology(pts, uva, uvb, tol=TOL, domain_a=(0, 1, 0, 1), domain_b=(0, 1, 0, 1))
    c = topo.chains[0]
    assert c.start_kind is EndKind.BOUNDARY and c.end_kind is EndKind.BOUNDARY
    # uv carried along with the points
    np.testing.assert_allclose(topo.uv_a[:, 0], topo.points[:, 0], atol=1e-11)
    np.testing.assert_allclose(topo.uv_b[:, 0], 0.2 + 0.5 * topo.points[:, 0], atol=1e-11)
    # without domains the same ends are OPEN
    topo = build_topology(pts, uva, uvb, tol=TOL)
    assert topo.chains[0].start_kind is EndKind.OPEN


def test_empty_soup():
    topo = build_topology(np.zeros((0, 2, 3)), tol=TOL)
    assert topo.chains == () and topo.points.shape == (0, 3)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, "x"])
def test_bad_tolerance(bad):
    with pytest.raises(InvalidToleranceError):
        build_topology(np.zeros((1, 2, 3)), tol=bad)


def test_bad_shapes():
    with pytest.raises(InvalidGeometryError, match=r"\(k, 2, 3\)"):
        build_topology(np.zeros((4, 3)), tol=TOL)
    with pytest.raises(InvalidGeometryError, match="uv_a"):
        build_topology(np.zeros((2, 2, 3)), np.zeros((2, 2, 3)), tol=TOL)
    with pytest.raises(InvalidGeometryError, match="NaN"):
        build_topology(np.full((1, 2, 3), np.nan), tol=TOL)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_points_piled_in_one_spot_cluster_as_all_pairs_would(seed):
    """Segment ends piled by the thousand at a few spots (two half cylinders touching
    along their seams: 5986 ends at 18 places, 17.8 million pairs within the merge
    distance) are merged into the same groups as every pair within it would give,
    scattered points and spots just within and just beyond the distance included."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    from surfprep.algorithms.intersection.topology import _cluster

    rng = np.random.default_rng(seed)
    tol = 1e-3
    spots = rng.uniform(0, 0.05, (6, 3))
    spots[1] = spots[0] + [0.999 * tol, 0, 0]       # within the distance of spot 0
    spots[3] = spots[2] + [1.001 * tol, 0, 0]       # just beyond spot 2
    piles = [s + rng.uniform(-1e-7, 1e-7, (400, 3)) for s in spots]
    scattered = rng.uniform(0, 0.05, (300, 3))
    points = np.concatenate(piles + [scattered, spots[:2]])[rng.permutation(6 * 400 + 302)]
    pairs = cKDTree(points).query_pairs(tol, output_type="ndarray")
    n = points.shape[0]
    _, truth = connected_components(coo_matrix((np.ones(len(pairs)), tuple(pairs.T)),
                                               shape=(n, n)), directed=False)
    labels = _cluster(points, tol)
    # the same partition: each label maps to one true component and back
    joint = np.unique(np.stack([labels, truth], axis=1), axis=0)
    assert joint.shape[0] == np.unique(labels).size == np.unique(truth).size
    # numbered by first member
    first = [int(np.flatnonzero(labels == k)[0]) for k in range(labels.max() + 1)]
    assert first == sorted(first)
