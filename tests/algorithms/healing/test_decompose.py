"""Faces that are not four-sided split into four-sided sub-patches (decompose.py), each
approximated by :func:`local_approximant` over the face's own surface and joined by
:func:`connect`; everything measured densely against the original surface."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import (
    disc,
    notched,
    outline_uv,
    pentagon,
    six_edges_two_smooth,
    triangle,
    wavy_surface,
)

from surfprep.algorithms.face_region import inside_loops
from surfprep.algorithms.healing import connect, local_approximant
from surfprep.algorithms.healing.connectivity import Side, side_points
from surfprep.algorithms.healing.decompose import (
    NotDecomposableError,
    decompose_loop,
    join_curves,
    reverse_curve,
)
from surfprep.algorithms.projection import distance_to_surface, project_to_curve, project_to_surface

SURFACE = wavy_surface()


def area(surface, n=160):
    """Area by the midpoint rule on an n x n grid of the domain."""
    u0, u1, v0, v1 = surface.domain
    u = u0 + (np.arange(n) + 0.5) / n * (u1 - u0)
    v = v0 + (np.arange(n) + 0.5) / n * (v1 - v0)
    d = surface.derivatives_grid(u, v, 1)
    cross = np.cross(d[:, :, 1, 0], d[:, :, 0, 1])
    return float(np.linalg.norm(cross, axis=-1).sum() * (u1 - u0) * (v1 - v0) / n ** 2)


def face_area(surface, edges, n=400):
    """Area of the part of ``surface`` inside the loop (uv mask on a fine grid)."""
    u = (np.arange(n) + 0.5) / n
    gu, gv = np.meshgrid(u, u, indexing="ij")
    inside = inside_loops(np.column_stack([gu.ravel(), gv.ravel()]), [outline_uv(edges)])
    d = surface.derivatives_grid(u, u, 1)
    jac = np.linalg.norm(np.cross(d[:, :, 1, 0], d[:, :, 0, 1]), axis=-1).ravel()
    return float(jac[inside].sum() / n ** 2)


def test_reverse_and_join_are_exact():
    edges = six_edges_two_smooth(SURFACE)
    joined = join_curves([edges[3].curve, edges[4].curve])           # the two arcs
    t = np.linspace(0, 1, 50)
    pts = np.concatenate([edges[3].curve.evaluate(t), edges[4].curve.evaluate(t)])
    assert project_to_curve(joined, pts).distance.max() < 1e-12
    assert np.allclose(joined.evaluate(np.array(joined.domain)),
                       [edges[3].curve.evaluate(0.0), edges[4].curve.evaluate(1.0)])
    back = reverse_curve(edges[0].curve)
    assert np.allclose(back.evaluate(1 - t), edges[0].curve.evaluate(t), atol=1e-14)


@pytest.mark.parametrize(("case", "n_quads"), [(triangle, 3), (pentagon, 5),
                                               (six_edges_two_smooth, 1), (disc, 1)])
def test_layout(case, n_quads):
    d = decompose_loop(SURFACE, case(SURFACE))
    assert len(d.quads) == n_quads
    for quad in d.quads:                       # four curves meeting end to end
        ends = np.array([[c.evaluate(c.domain[0]), c.evaluate(c.domain[1])] for c in quad])
        assert np.linalg.norm(ends[:, 1] - np.roll(ends[:, 0], -1, axis=0), axis=1).max() < 1e-9


def test_six_edges_merge_at_the_four_cornery_vertices():
    d = decompose_loop(SURFACE, six_edges_two_smooth(SURFACE))
    assert list(d.corners) == [0, 2, 3, 5]
    assert np.degrees(d.turning[[1, 4]]).max() < 1.0


def test_disc_of_three_arcs_keeps_its_vertices_as_corners():
    edges = disc(SURFACE, pieces=3)
    d = decompose_loop(SURFACE, edges)
    corners = np.array([c.evaluate(c.domain[0]) for c in d.quads[0]])
    vertices = np.array([e.curve.evaluate(0.0) for e in edges])
    assert np.min(np.linalg.norm(corners[:, None] - vertices[None], axis=2), axis=0).max() < 1e-9
    lengths = [c.arc_length() for c in d.quads[0]]
    arcs = [e.curve.arc_length() for e in edges]
    whole = [x for x in lengths if np.isclose(arcs, x, rtol=1e-9).any()]
    halves = [x for x in lengths if x not in whole]
    assert len(whole) == 2 and len(halves) == 2             # two arcs whole, one cut in two
    assert abs(sum(lengths) - sum(arcs)) < 1e-9 and abs(halves[0] - halves[1]) < 1e-3


def test_disc_of_one_edge_is_cut_in_four_equal_arcs():
    d = decompose_loop(SURFACE, disc(SURFACE, pieces=1))
    lengths = [c.arc_length() for c in d.quads[0]]
    assert max(lengths) / min(lengths) < 1.01


def test_very_non_convex_outline_is_refused_with_the_reason():
    with pytest.raises(NotDecomposableError, match="non-convex"):
        decompose_loop(SURFACE, notched(SURFACE))


def _approximate(edges, continuity):
    d = decompose_loop(SURFACE, edges)
    las = [local_approximant(list(q), SURFACE) for q in d.quads]
    return d, las, connect(las, continuity=continuity)


def _check_network(edges, las, net, continuity):
    size = float(np.linalg.norm(np.ptp(SURFACE.bounding_box(), axis=0)))
    tol = max(la.tol for la in las)
    assert all(la.converged for la in las)
    # dense deviation of the joined patches from the original surface
    t = np.linspace(0, 1, 41)
    for p in net.patches:
        pts = p.evaluate_grid(t, t).reshape(-1, 3)
        assert distance_to_surface(SURFACE, pts).max() <= tol
    # gaps and angles measured on the geometry, independently of the report
    for join in net.joins:
        pts = side_points(net.patches[join.a], join.side_a, 300)
        foot = project_to_surface(net.patches[join.b], pts)
        assert foot.distance.max() <= 1e-9 * size
        if continuity == "G1":
            na = net.patches[join.a].normals(*_side_uv(net.patches[join.a], join.side_a, 300).T)
            nb = net.patches[join.b].normals(foot.uv[:, 0], foot.uv[:, 1])
            cos = np.abs(np.einsum("nc,nc->n", na, nb))
            # G1 of 001 §8 (collinear control triples) on the face: 0.06 deg (triangle),
            # 0.11 deg along the spokes of the pentagon (measured)
            assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 0.2
    # the union covers the face: area, and its outline is the face's boundary
    total = sum(area(p) for p in net.patches)
    assert abs(total - face_area(SURFACE, edges)) <= 2e-3 * total
    shared = {(j.a, j.side_a) for j in net.joins} | {(j.b, j.side_b) for j in net.joins}
    outer = np.concatenate([side_points(p, s, 200) for k, p in enumerate(net.patches)
                            for s in Side if (k, s) not in shared])
    t = np.linspace(0, 1, 400)
    rim = np.concatenate([e.curve.evaluate(t) for e in edges])
    to_rim = np.min([project_to_curve(e.curve, outer).distance for e in edges], axis=0)
    assert to_rim.max() <= tol          # keep_boundary interpolates the rim's samples
    from scipy.spatial import cKDTree
    assert cKDTree(outer).query(rim)[0].max() <= 0.01 * size    # the rim is covered (sampling)


def _side_uv(surface, side, n):
    lo, hi = side.running_domain(surface)
    return side.uv(surface, np.linspace(lo, hi, n))


@pytest.mark.parametrize("case", [triangle, six_edges_two_smooth, disc])
def test_sub_patches_follow_the_face_and_meet_g1(case):
    edges = case(SURFACE)
    _, las, net = _approximate(edges, "G1")
    _check_network(edges, las, net, "G1")


@pytest.mark.slow
@pytest.mark.parametrize("continuity", ["G0", "G1"])
def test_pentagon_sub_patches(continuity):
    edges = pentagon(SURFACE)
    _, las, net = _approximate(edges, continuity)
    assert len(net.joins) == 5
    _check_network(edges, las, net, continuity)


def test_turning_angle_where_an_edge_has_a_vanishing_end_derivative():
    """An edge whose last control point is repeated (C' = 0 at its end, as in high-degree
    edges of occt_t4m_euclid.stp) continuing straight on: turning 0, not a cusp."""
    from surfprep.algorithms.curve import NurbsCurve
    from surfprep.algorithms.healing.decompose import LoopEdge, turning_angles

    def edge(points):
        p = np.asarray(points, float)
        n = len(p)
        knots = np.r_[np.zeros(n), np.ones(n)]
        return LoopEdge(NurbsCurve(p, knots, n - 1), NurbsCurve(p[:, :2], knots, n - 1))

    square = [edge([[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [1, 0, 0]]),    # C'(1) = 0
              edge([[1, 0, 0], [2, 0, 0]]), edge([[2, 0, 0], [2, 1, 0]]),
              edge([[2, 1, 0], [0, 1, 0]]), edge([[0, 1, 0], [0, 0, 0]])]
    turning = np.degrees(turning_angles(square))
    assert turning[1] < 1e-6
    assert np.allclose(turning[[0, 2, 3, 4]], 90.0)
