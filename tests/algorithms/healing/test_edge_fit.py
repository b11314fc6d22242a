"""Surfaces moved onto target edges (algorithms/healing/edge_fit.py): checked densely
along the edges, away from them, and against exact answers."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.healing.edge_fit import EdgeTarget, fit_to_edges
from surfprep.algorithms.surface import NurbsSurface
from surfprep.errors import InvalidGeometryError


def _graph(n=8):
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    return interpolate_surface(np.stack([x, y, 0.2 * np.sin(3 * x) * np.cos(2 * y)], axis=-1))


def _circle(surface, n, amplitude=1e-3):
    a = np.linspace(0, 2 * np.pi, n)
    uv = np.stack([0.5 + 0.3 * np.cos(a), 0.5 + 0.3 * np.sin(a)], axis=1)
    points = surface.evaluate(uv[:, 0], uv[:, 1])
    points[:, 2] += amplitude * np.exp(np.sin(5 * a))        # not in any spline space
    return uv, points


def test_a_constant_lift_of_a_boundary_edge_is_exact_and_fades_away_from_it():
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1))
    u = np.linspace(0, 1, 50)
    edge = EdgeTarget(np.stack([u, 0 * u], axis=1), np.stack([u, 0 * u, 0 * u + 1e-3], axis=1))
    fit = fit_to_edges(flat, [edge], tol=1e-9)
    assert fit.converged and fit.inserted == 0
    dense = np.linspace(0, 1, 1001)
    on_edge = fit.surface.evaluate(dense, 0 * dense)
    assert np.max(np.abs(on_edge[:, 2] - 1e-3)) <= 1e-9
    assert np.max(np.abs(on_edge[:, :2] - np.stack([dense, 0 * dense], axis=1))) <= 1e-12
    # the membrane decays away from the edge and never exceeds the lift asked for
    g = np.linspace(0, 1, 41)
    lift = fit.surface.evaluate_grid(g, g)[..., 2]
    assert lift.max() <= 1e-3 + 1e-12 and lift.min() >= -1e-12
    assert np.all(np.diff(lift, axis=1) <= 1e-15)          # falling with v
    assert fit.moved == pytest.approx(1e-3, rel=1e-9)


def test_a_wavy_interior_edge_is_met_densely_between_the_samples():
    s = _graph()
    uv, points = _circle(s, 1600)
    v = np.linspace(0, 1, 100)
    held_uv = np.stack([0 * v, v], axis=1)
    held = EdgeTarget(held_uv, s.evaluate(held_uv[:, 0], held_uv[:, 1]))
    fit = fit_to_edges(s, [EdgeTarget(uv, points), held], tol=1e-6)
    assert fit.converged and fit.inserted > 0
    check_uv, check = _circle(s, 20001)                  # 12x denser than the fit
    miss = np.linalg.norm(fit.surface.evaluate(check_uv[:, 0], check_uv[:, 1]) - check, axis=1)
    assert miss.max() <= 2e-6
    vv = np.linspace(0, 1, 2001)
    still = fit.surface.evaluate(0 * vv, vv) - s.evaluate(0 * vv, vv)
    assert np.max(np.linalg.norm(still, axis=1)) <= 2e-6
    # the displacement is of the size the targets ask (their offsets reach 2.7e-3)
    g = np.linspace(0, 1, 101)
    moved = np.linalg.norm(fit.surface.evaluate_grid(g, g) - s.evaluate_grid(g, g), axis=-1)
    assert moved.max() <= 2.5 * 2.72e-3
    assert fit.moved >= moved.max() - 1e-12             # the control points bound it


def _tent_side(kink):
    """A flat bicubic patch whose side u = 0 is split at v = 0.5 into two edges lifted
    by ``1e-3 (1 - |v - 0.5| / 0.5)`` (kink) or ``1e-3 v^2`` (smooth)."""
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1))

    def lift(v):
        return 1e-3 * (1 - np.abs(v - 0.5) / 0.5) if kink else 1e-3 * v ** 2

    targets = []
    for a, b in ((0.0, 0.5), (0.5, 1.0)):
        v = np.linspace(a, b, 300)
        targets.append(EdgeTarget(np.stack([0 * v, v], axis=1), np.stack([0 * v, v, lift(v)], axis=1)))
    return flat, targets, lift


def test_a_kink_where_two_edges_of_a_side_meet_is_one_knot_line_not_many():
    """The displacement turns at the vertex between two edges of one side: a knot of
    full multiplicity there meets it exactly (the Mars capsule's faces grew from 7 x 4
    to 105 x 139 control points by knots graded towards such kinks)."""
    flat, targets, lift = _tent_side(kink=True)
    fit = fit_to_edges(flat, targets, tol=1e-8)
    assert fit.converged
    knots, counts = np.unique(fit.surface.knots_v, return_counts=True)
    assert counts[np.isclose(knots, 0.5)].tolist() == [3]
    assert fit.surface.n_control[1] <= 10, fit.surface.n_control
    v = np.linspace(0, 1, 4001)                                 # 7x denser than the fit
    miss = fit.surface.evaluate(0 * v, v) - np.stack([0 * v, v, lift(v)], axis=1)
    assert np.max(np.linalg.norm(miss, axis=1)) <= 1e-8


def test_a_smooth_side_split_by_a_vertex_keeps_its_continuity():
    flat, targets, lift = _tent_side(kink=False)
    fit = fit_to_edges(flat, targets, tol=1e-8)
    assert fit.converged
    _, counts = np.unique(fit.surface.knots_v, return_counts=True)
    assert counts[1:-1].max(initial=0) < fit.surface.degree_v      # no C0 knot line
    v = np.linspace(0, 1, 4001)
    miss = fit.surface.evaluate(0 * v, v) - np.stack([0 * v, v, lift(v)], axis=1)
    assert np.max(np.linalg.norm(miss, axis=1)) <= 1e-8


def test_a_kink_inside_one_edge_is_located_between_its_samples():
    """A neighbour's boundary turns inside an edge (at its own knot): refinement alone
    stalls when the spans around the turn hold too few samples; the turn is found
    between two samples and a knot line put there."""
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1))
    kink = 0.3719

    def lift(v):
        return 1e-3 * np.where(v < kink, v / kink, (1 - v) / (1 - kink))

    v = np.linspace(0, 1, 300)
    edge = EdgeTarget(np.stack([0 * v, v], axis=1), np.stack([0 * v, v, lift(v)], axis=1))
    fit = fit_to_edges(flat, [edge], tol=1e-8)
    assert fit.converged
    knots, counts = np.unique(fit.surface.knots_v, return_counts=True)
    assert np.any((np.abs(knots - kink) < 1e-6) & (counts == 3))
    dense = np.linspace(0, 1, 20001)
    miss = fit.surface.evaluate(0 * dense, dense) - np.stack([0 * dense, dense, lift(dense)], axis=1)
    assert np.max(np.linalg.norm(miss, axis=1)) <= 1e-8


def test_samples_piled_at_one_parameter_beside_a_kink_are_no_line():
    """A window round a miss holding samples piled at one parameter (an edge's end
    reaching past a corner) is not fitted by a line there (a zero-length run crashed
    the least squares)."""
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1))
    kink = 0.3719
    v = np.sort(np.concatenate([np.linspace(0, 1, 300), np.full(12, 0.372)]))
    lift = 1e-3 * np.where(v < kink, v / kink, (1 - v) / (1 - kink))
    edge = EdgeTarget(np.stack([0 * v, v], axis=1), np.stack([0 * v, v, lift], axis=1))
    fit = fit_to_edges(flat, [edge], tol=1e-8)
    assert fit.converged
    dense = np.linspace(0, 1, 20001)
    lifted = 1e-3 * np.where(dense < kink, dense / kink, (1 - dense) / (1 - kink))
    miss = fit.surface.evaluate(0 * dense, dense) - np.stack([0 * dense, dense, lifted], axis=1)
    assert np.max(np.linalg.norm(miss, axis=1)) <= 1e-8


def test_a_wavy_side_is_met_by_knots_along_it_only():
    """A side of the domain is its row of control points: knots across it would only
    add knot lines (ICEM's degree 7 nets were split to spans of 1e-8 at their sides)."""
    x, y = np.meshgrid(np.linspace(0, 1, 8), np.linspace(0, 1, 8), indexing="ij")
    flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1), degree_u=7, degree_v=7)
    v = np.linspace(0, 1, 2000)

    def lift(v):
        return 1e-3 * np.sin(7 * v) * np.exp(v)

    edge = EdgeTarget(np.stack([0 * v, v], axis=1), np.stack([0 * v, v, lift(v)], axis=1))
    fit = fit_to_edges(flat, [edge], tol=1e-8)
    assert fit.converged and fit.inserted > 0
    assert np.array_equal(fit.surface.knots_u, flat.knots_u)
    dense = np.linspace(0, 1, 20001)
    miss = fit.surface.evaluate(0 * dense, dense) - np.stack([0 * dense, dense, lift(dense)], axis=1)
    assert np.max(np.linalg.norm(miss, axis=1)) <= 1e-8


def test_samples_too_sparse_for_the_tolerance_are_reported_not_converged():
    s = _graph()
    uv, points = _circle(s, 40)
    fit = fit_to_edges(s, [EdgeTarget(uv, points)], tol=1e-9)
    assert not fit.converged
    miss = np.linalg.norm(fit.surface.evaluate(uv[:, 0], uv[:, 1]) - points, axis=1)
    assert fit.residual == pytest.approx(miss.max(), rel=1e-12)


def test_a_rational_cylinder_keeps_its_weights_and_moves_radially():
    w = np.sqrt(0.5)
    arc = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cp = np.stack([np.concatenate([np.repeat(arc[:, :1], 1, 1), arc[:, 1:], np.full((3, 1), z)], 1)
                   for z in (0.0, 1.0)], axis=1)                                    # (3, 2, 3)
    weights = np.array([[1.0, 1.0], [w, w], [1.0, 1.0]])
    cyl = NurbsSurface(cp, [0, 0, 0, 1, 1, 1], [0, 0, 1, 1], 2, 1, weights)
    u = np.linspace(0, 1, 200)
    edge_uv = np.stack([u, np.full_like(u, 1.0)], axis=1)                          # the top
    on = cyl.evaluate(edge_uv[:, 0], edge_uv[:, 1])
    assert np.allclose(np.hypot(on[:, 0], on[:, 1]), 1.0)
    radial = np.stack([on[:, 0], on[:, 1], 0 * u], axis=1)
    fit = fit_to_edges(cyl, [EdgeTarget(edge_uv, on + 1e-3 * radial)], tol=1e-7)
    assert fit.converged
    assert fit.surface.weights is not None
    out = fit.surface.evaluate(np.linspace(0, 1, 999), np.ones(999))
    assert np.max(np.abs(np.hypot(out[:, 0], out[:, 1]) - 1.001)) <= 1e-7
    bottom = fit.surface.evaluate(np.linspace(0, 1, 99), np.zeros(99))
    assert np.max(np.abs(np.hypot(bottom[:, 0], bottom[:, 1]) - 1.0)) <= 1e-3  # decayed


@pytest.mark.parametrize("make, match", [
    (lambda s: ([], 1e-6), "at least one"),
    (lambda s: ([EdgeTarget(np.zeros((5, 2)), np.zeros((5, 3)))], 0.0), "positive"),
    (lambda s: ([EdgeTarget(np.zeros((5, 2)), np.zeros((5, 3)))], float("nan")), "positive"),
])
def test_bad_arguments_are_refused(make, match):
    targets, tol = make(None)
    with pytest.raises(InvalidGeometryError, match=match):
        fit_to_edges(_graph(), targets, tol=tol)


@pytest.mark.parametrize("uv, points, match", [
    (np.zeros((1, 2)), np.zeros((1, 3)), "m >= 2"),
    (np.zeros((5, 3)), np.zeros((5, 3)), r"\(m, 2\)"),
    (np.zeros((5, 2)), np.zeros((4, 3)), r"\(5, 3\)"),
    (np.full((5, 2), np.nan), np.zeros((5, 3)), "NaN"),
])
def test_bad_targets_are_refused(uv, points, match):
    with pytest.raises(InvalidGeometryError, match=match):
        EdgeTarget(uv, points)


def test_a_lift_next_to_short_knot_spans_turns_the_surface_as_little_as_a_uniform_net():
    """A flat patch whose knots crowd towards its edge v = 0 (as the fits of graded
    refinement leave them), that edge lifted by h, the opposite edge held: the least
    change spreads the lift over the patch (the membrane is measured on the parameter
    domain, not in control-net steps), so its tangent planes turn by a few h (the lift
    decays over a third of the patch), within twice what they turn on a uniform net; a
    membrane on the net's steps moved the crowded rows alone and turned the surface by
    89 degrees within them (the KCS hull's face 5 folded over so)."""
    from surfprep.algorithms.measure import normal_turn

    h = 1e-3
    t = np.linspace(0, 1, 4)
    x, y = np.meshgrid(t, t, indexing="ij")
    flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1), params_u=t, params_v=t)
    crowded = flat.refine(np.array([1e-5, 1e-4, 1e-3, 1e-2, 0.1]), "v")
    u = np.linspace(0, 1, 200)
    lifted = EdgeTarget(np.stack([u, 0 * u], axis=1), np.stack([u, 0 * u, 0 * u + h], axis=1))
    held = EdgeTarget(np.stack([u, 0 * u + 1], axis=1), np.stack([u, 0 * u + 1, 0 * u], axis=1))
    g = np.unique(np.concatenate([np.linspace(0, 1, 101), np.geomspace(1e-7, 1e-1, 50)]))
    gu, gv = np.meshgrid(g, g, indexing="ij")
    turns = []
    for surface in (flat, crowded):
        fit = fit_to_edges(surface, [lifted, held], tol=1e-9)
        assert fit.converged
        turns.append(float(np.nanmax(normal_turn(surface, fit.surface, gu, gv))))
    uniform, graded = turns
    assert uniform <= 2 * np.arctan(h)          # (the lift decays over a third)
    assert graded <= 2 * uniform


def test_a_lift_beside_a_pole_keeps_the_rows_next_to_it_with_it():
    """A fan (its side v = 1 collapsed to a point) with knots crowding towards the pole,
    its side v = 0 lifted by h and the pole held: the rows next to the pole move with
    it, the surface's tangent planes turning by a few h next to it (a membrane measured
    in space, where a point has no length, let them move apart and the face folded
    there: the K1 CATIA/debis demo's grid had 13 folded cells)."""
    from surfprep.algorithms.measure import normal_turn

    h = 1e-3
    t = np.linspace(0, 1, 5)
    x, y = np.meshgrid(t, t, indexing="ij")
    fan = interpolate_surface(np.stack([x * (1 - y), y, 0 * x], axis=-1), params_u=t, params_v=t)
    crowded = fan.refine(np.array([0.9, 0.99, 0.999, 0.9999]), "v")
    u = np.linspace(0, 1, 200)
    lifted = EdgeTarget(np.stack([u, 0 * u], axis=1), np.stack([u, 0 * u, 0 * u + h], axis=1))
    pole = EdgeTarget(np.stack([u, 0 * u + 1], axis=1), np.repeat([[0.0, 1.0, 0.0]], u.size, axis=0))
    fit = fit_to_edges(crowded, [lifted, pole], tol=1e-9)
    assert fit.converged
    g = np.unique(np.concatenate([np.linspace(0, 1, 101), 1 - np.geomspace(1e-6, 1e-1, 50)]))
    gu, gv = np.meshgrid(np.linspace(0.05, 0.95, 31), g, indexing="ij")
    turn = normal_turn(crowded, fit.surface, gu, gv)
    assert np.count_nonzero(np.isfinite(turn)) > 0.75 * turn.size      # (NaN within 1e-3 of it)
    assert float(np.nanmax(turn)) <= 10 * h


@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("batched", [False, True])
def test_the_collocation_rows_are_the_basis_and_its_normal_matrix_is_a_t_a(
        rational, batched, monkeypatch):
    # the normal matrix is summed per knot cell (one dense product per cell of samples,
    # the cells scattered in batches): it must equal the sparse product, and the rows
    # must evaluate the surface
    from surfprep.algorithms.healing import edge_fit
    from surfprep.algorithms.healing.edge_fit import _collocation
    if batched:
        monkeypatch.setattr(edge_fit, "_GRAM_ENTRIES", 1000)     # two cells a batch
    rng = np.random.default_rng(3)
    s = _graph(9).elevate_degree(1, 0)
    if rational:
        s = NurbsSurface(s.control_points, s.knots_u, s.knots_v, s.degree_u, s.degree_v,
                         rng.uniform(0.5, 2.0, s.n_control))
    t = np.linspace(0, 1, 200)
    uv = np.concatenate([np.stack([t, 0 * t], 1), np.stack([0 * t + 1, t], 1),   # sides
                         rng.uniform(0, 1, (300, 2))])                          # inside
    c = _collocation(s, uv)
    dense = c.matrix.toarray()
    assert np.allclose(c.gram().toarray(), dense.T @ dense, rtol=0, atol=1e-13)
    points = dense @ s.control_points.reshape(-1, 3)
    assert np.allclose(points, s.evaluate(uv[:, 0], uv[:, 1]), rtol=0, atol=1e-13)
    assert np.allclose(dense.sum(axis=1), 1.0)
