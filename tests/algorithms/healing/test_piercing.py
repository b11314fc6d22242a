"""Projection of the Coons grid onto the originals (001 §4, eqs. 9-11) and the error
points of §7 (eq. 19): segment hits, exact piercing, closest points on triangles, hole rule."""

from __future__ import annotations

import numpy as np
from helpers.heal_cases import smooth_surface

from surfprep.algorithms.healing.clipping import as_sources, clip_sources
from surfprep.algorithms.healing.error import (
    closest_on_triangles,
    distance_to_sources,
    distance_to_triangles,
    error_parameters,
)
from surfprep.algorithms.healing.piercing import (
    intersect_segments,
    pierce_surface,
    project_grid,
)
from surfprep.algorithms.surface import NurbsSurface

RNG = np.random.default_rng(11)


def test_segment_hits_keep_the_hit_nearest_the_midpoint():
    low = np.array([[[-1, -1, 0.1], [2, -1, 0.1], [0, 2, 0.1]]], float)    # z = 0.1
    high = np.array([[[-1, -1, 0.7], [2, -1, 0.7], [0, 2, 0.7]]], float)   # z = 0.7
    tri = np.concatenate([low, high])
    a = np.array([[0.2, 0.2, 1.0], [0.2, 0.2, 1.0], [5.0, 5.0, 1.0]])
    b = np.array([[0.2, 0.2, 0.0], [0.2, 0.2, 0.5], [5.0, 5.0, 0.0]])
    hits = intersect_segments(a, b, tri)
    np.testing.assert_array_equal(hits.found, [True, True, False])
    # first segment: z = 0.7 at t = 0.3 beats z = 0.1 at t = 0.9; second: only z = 0.7
    np.testing.assert_array_equal(hits.triangle[:2], [1, 1])
    np.testing.assert_allclose(hits.t[:2], [0.3, 0.6])
    p = np.einsum("pk,pkc->pc", hits.barycentric[:2], tri[hits.triangle[:2]])
    np.testing.assert_allclose(p, a[:2] + hits.t[:2, None] * (b[:2] - a[:2]), atol=1e-15)


def test_hits_on_a_shared_edge_are_not_lost():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    s = np.linspace(0.01, 0.99, 99)
    a = np.stack([s, 1 - s, np.ones_like(s)], axis=1)          # all on the diagonal edge
    hits = intersect_segments(a, a - [0, 0, 2], tri)
    assert hits.found.all()


def test_piercing_lands_on_the_exact_surface_and_the_segment():
    s = smooth_surface()
    uv_true = RNG.uniform(0.1, 0.9, (200, 2))
    p = s.evaluate(uv_true[:, 0], uv_true[:, 1])
    direction = RNG.normal(size=(200, 3)) * 0.05 + [0, 0, -1]
    origin = p - 0.4 * direction
    uv, t, ok = pierce_surface(s, origin, direction, uv_true + RNG.normal(size=(200, 2)) * 0.02,
                               np.full(200, 0.3), 1e-12)
    assert ok.all()
    q = s.evaluate(uv[:, 0], uv[:, 1])
    np.testing.assert_allclose(q, origin + t[:, None] * direction, atol=1e-12)
    np.testing.assert_allclose(q, p, atol=1e-9)


def test_closest_points_on_triangles_against_brute_force():
    tri = RNG.normal(size=(300, 3, 3))
    pts = RNG.normal(size=(300, 3)) * 2
    foot, bary = closest_on_triangles(pts, tri)
    assert np.all(bary >= -1e-12) and np.allclose(bary.sum(axis=1), 1)
    w = RNG.dirichlet(np.ones(3), size=4000)                   # dense samples of each triangle
    dense = np.einsum("sk,tkc->tsc", w, tri)
    brute = np.linalg.norm(dense - pts[:, None], axis=2).min(axis=1)
    got = np.linalg.norm(foot - pts, axis=1)
    assert np.all(got <= brute + 1e-12)
    assert np.all(brute - got < 0.05 * (1 + brute))


def test_error_points_skip_cells_over_holes():
    found = np.ones((5, 4), bool)
    uv = error_parameters(found)
    assert uv.shape == (4 * 4 + 5 * 3 + 4 * 3, 2)            # e, f, g of eq. (19)
    found[2, 1] = False
    uv = error_parameters(found)
    # e: 2 edges along u touch (2, 1); f: 2 edges along v; g: 4 cells
    assert uv.shape[0] == 4 * 4 + 5 * 3 + 4 * 3 - 2 - 2 - 4
    hole = np.array([2 / 4, 1 / 3])
    near = np.abs(uv - hole) < np.array([1 / 4, 1 / 3]) - 1e-12
    assert not np.any(near.all(axis=1))


def test_distance_through_triangles_matches_global_inversion():
    s = smooth_surface()
    sources = as_sources([s.restrict(None, 0.5, None, None), s.restrict(0.5, None, None, None)])
    box = np.array([[0.1, 0.1, -1.0], [0.9, 0.9, 2.0]])
    clipped = clip_sources(sources, box, mesh_tol=0.01)       # coarse chords: 1e-2
    uv = RNG.uniform(0.2, 0.8, (300, 2))
    pts = s.evaluate(uv[:, 0], uv[:, 1]) + RNG.normal(scale=0.01, size=(300, 3))
    local = distance_to_triangles(pts, clipped, tol=1e-12)
    glob = distance_to_sources(pts, sources, tol=1e-12)
    np.testing.assert_allclose(local, glob, atol=1e-10)       # exact, not the chords


def test_distance_through_triangles_with_many_sources():
    """Four sources, two of them copies of the surface lifted by 0.05 and 0.3: the
    nearest triangles per source (compiled kernel) seed the inversions, and the
    distances equal the global inversion onto every source."""
    s = smooth_surface()
    lifted = [NurbsSurface(s.control_points + [0, 0, dz], s.knots_u, s.knots_v, s.degree_u,
                           s.degree_v) for dz in (0.05, 0.3)]
    sources = as_sources([s.restrict(None, 0.5, None, None), s.restrict(0.5, None, None, None),
                          *lifted])
    clipped = clip_sources(sources, np.array([[0.1, 0.1, -1.0], [0.9, 0.9, 2.0]]), mesh_tol=0.01)
    uv = RNG.uniform(0.2, 0.8, (400, 2))
    pts = s.evaluate(uv[:, 0], uv[:, 1]) + RNG.normal(scale=0.05, size=(400, 3))
    local = distance_to_triangles(pts, clipped, tol=1e-12)
    glob = distance_to_sources(pts, sources, tol=1e-12)
    np.testing.assert_allclose(local, glob, atol=1e-10)


def _plane(z: float, lo: float = -1.0, hi: float = 2.0) -> NurbsSurface:
    c = np.array([[[lo, lo, z], [lo, hi, z]], [[hi, lo, z], [hi, hi, z]]], float)
    return NurbsSurface(c, np.array([0, 0, 1, 1.0]), np.array([0, 0, 1, 1.0]), 1, 1)


def test_preferred_source_wins_over_a_hit_nearer_the_midpoint():
    # planes z = 0.7 (nearer the segments' midpoints) and z = 0.1 (the preferred one)
    sources = as_sources([_plane(0.7), _plane(0.1)])
    clipped = clip_sources(sources, np.array([[-1, -1, -1], [2, 2, 2.0]]), mesh_tol=1e-3)
    s = np.linspace(0.0, 1.0, 5)
    a = np.stack([s, s, np.ones_like(s)], axis=1)
    b = a - [0, 0, 1.0]
    y, t, found, src = project_grid(a, b, clipped, tol=1e-12)
    assert found.all() and np.all(src == 0)
    np.testing.assert_allclose(y[:, 2], 0.7)
    y, t, found, src = project_grid(a, b, clipped, tol=1e-12, preferred=1)
    assert found.all() and np.all(src == 1)
    np.testing.assert_allclose(y[:, 2], 0.1)
    np.testing.assert_allclose(t, 0.9)


def test_coarse_plane_not_crowded_out_by_a_fine_neighbour():
    # a plane in two big triangles next to a finely triangulated curved patch: the error
    # of points on the plane is ~0 even where the patch's centroids are all nearer
    plane = _plane(0.0, 0.0, 100.0)
    fine = smooth_surface()                        # ~unit size, near the plane's corner
    sources = as_sources([plane, fine])
    clipped = clip_sources(sources, np.array([[-1, -1, -1], [101, 101, 1.0]]), mesh_tol=1e-4)
    assert np.sum(clipped.source == 0) <= 8 < np.sum(clipped.source == 1)
    pts = np.stack([RNG.uniform(0.5, 3.0, 200), RNG.uniform(0.5, 3.0, 200),
                    np.zeros(200)], axis=1)
    d = distance_to_triangles(pts, clipped, tol=1e-12)
    assert d.max() < 1e-9


def test_closest_on_degenerate_triangles_uses_their_edges():
    """Slivers and points (zero-area triangles of a trimmed triangulation) give the
    closest point of their edges instead of a singular system."""
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [2, 0, 0]],          # collinear
                    [[1.0, 1, 1], [1, 1, 1], [1, 1, 1]],          # a point
                    [[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])         # a proper one
    points = np.array([[1.5, 0.5, 0.0], [0.0, 0, 0], [0.2, 0.2, 0.3]])
    foot, bary = closest_on_triangles(points, tri)
    assert np.allclose(foot, [[1.5, 0, 0], [1, 1, 1], [0.2, 0.2, 0]])
    assert np.allclose(bary.sum(axis=1), 1.0)


def test_a_source_farther_than_the_best_distance_is_not_inverted(monkeypatch):
    """A copy of the surface lifted by 5 (its control-net box 4.5 and more above every
    point): no point is inverted on it, as it cannot come nearer than the box; the
    distances still equal the global inversion onto every source."""
    from surfprep.algorithms.healing import error
    s = smooth_surface()
    far = NurbsSurface(s.control_points + [0, 0, 5.0], s.knots_u, s.knots_v, s.degree_u,
                       s.degree_v)
    sources = as_sources([s, far])
    clipped = clip_sources(sources, np.array([[-1.0, -1.0, -1.0], [2.0, 2.0, 7.0]]),
                           mesh_tol=0.01)
    uv = RNG.uniform(0.2, 0.8, (200, 2))
    pts = s.evaluate(uv[:, 0], uv[:, 1]) + RNG.normal(scale=0.05, size=(200, 3))
    inverted = []
    real = error.project_to_surface

    def counted(surface, points, **kw):
        inverted.append((surface, len(points)))
        return real(surface, points, **kw)

    monkeypatch.setattr(error, "project_to_surface", counted)
    local = distance_to_triangles(pts, clipped, tol=1e-12)
    assert [n for surface, n in inverted if surface is far] == []
    assert sum(n for _, n in inverted) == sum(n for surface, n in inverted if surface is s) == 200
    monkeypatch.setattr(error, "project_to_surface", real)
    np.testing.assert_allclose(local, distance_to_sources(pts, sources, tol=1e-12), atol=1e-10)
