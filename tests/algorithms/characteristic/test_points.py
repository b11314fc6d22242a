"""Characteristic points (002 §3.3, §4.2, §6.3 steps 1-2) and the curve tracer (eqs. 17-21, 33)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import horizontal_plane, plane_patch, several_bumps, touching_bumps

from surfprep.algorithms.characteristic import (
    CurveKind,
    DistanceField,
    EndReason,
    PointKind,
    Projector,
    classify_critical,
    critical_points,
    trace_curves,
)
from surfprep.algorithms.characteristic.points import (
    border_points,
    edge_roots,
    solve_held,
)
from surfprep.algorithms.intersection import EndKind


@pytest.fixture(scope="module")
def bumps_field():
    return DistanceField(several_bumps(), Projector(horizontal_plane(0.3), tol=1e-13))


def test_classify_critical_by_the_hessian():
    hess = np.array([[[-2.0, 0], [0, -1]], [[2.0, 0], [0, 1]], [[1.0, 0], [0, -1]],
                     [[1.0, 0], [0, 1e-9]], [[1.0, 0], [0, 1]], [[1.0, 0], [0, -1]],
                     [[1.0, 0], [0, 0]]])
    phi = np.array([0.3, -0.2, 0.1, 0.2, 0.0, 1e-12, -1e-12])
    assert classify_critical(phi, hess, 1e-9) == [
        PointKind.MAXIMUM, PointKind.MINIMUM, PointKind.SADDLE, PointKind.DEGENERATE,
        PointKind.ISOLATED, PointKind.DOUBLE_POINT, PointKind.CUSP]
    assert PointKind.ISOLATED.is_singular and PointKind.SADDLE.is_critical
    assert not PointKind.BORDER.is_critical


def test_critical_points_of_three_bumps(bumps_field):
    """Newton from a grid finds the three tops (grad phi = 0 there, det H > 0, H < 0)
    and the saddles between them; each is a true zero of the gradient."""
    g = np.linspace(0.05, 0.95, 10)
    seeds = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    crit = critical_points(bumps_field, seeds)
    kinds = classify_critical(crit.phi, crit.hess, 1e-9)
    tops = crit.uv[[k is PointKind.MAXIMUM for k in kinds]]
    assert tops.shape[0] == 3
    assert np.abs(crit.grad).max() <= 1e-10
    np.testing.assert_allclose(np.sort(tops[:, 0]), [0.28116173, 0.5, 0.71883827], atol=1e-6)
    assert kinds.count(PointKind.SADDLE) >= 2
    # heights: phi of a top is its height above the plane (up to the plane's orientation)
    np.testing.assert_allclose(np.sort(np.abs(crit.phi[[k is PointKind.MAXIMUM for k in kinds]])),
                               np.sort(crit.point[[k is PointKind.MAXIMUM for k in kinds], 2] - 0.3),
                               atol=1e-12)


def test_edge_roots_are_zeros_of_the_derivative_on_the_sides(bumps_field):
    for comp in (0, 1):
        uv, st, side = edge_roots(bumps_field, comp)
        assert uv.shape[0] >= 2
        jet = bumps_field.jet(uv, st)
        assert np.abs(jet.grad[:, comp]).max() <= 1e-9 * np.abs(jet.hess).max()
        on_side = np.isclose(uv[np.arange(uv.shape[0]), side], 0) | \
            np.isclose(uv[np.arange(uv.shape[0]), side], 1)
        assert on_side.all()


def test_border_points_lie_on_a_side_and_on_both_surfaces():
    a = several_bumps()
    b = plane_patch([0.5, 0.5, 0.05], [0.3, 0.0, 1.0], half=0.9)      # tilted: cuts two sides
    fields = (DistanceField(a, Projector(b, tol=1e-13)),
              DistanceField(b, Projector(a, tol=1e-13), True))
    pts, ua, ub = border_points(fields, 1e-9)
    assert pts.shape[0] >= 2
    np.testing.assert_allclose(a.evaluate(ua[:, 0], ua[:, 1]), pts, atol=1e-9)
    np.testing.assert_allclose(b.evaluate(ub[:, 0], ub[:, 1]), pts, atol=1e-9)
    side = np.minimum(np.minimum(ua, 1 - ua).min(axis=1), np.minimum(ub, 1 - ub).min(axis=1))
    assert np.all(side <= 1e-12)


def test_solve_held_keeps_the_side():
    a, _, _ = touching_bumps()
    flat = horizontal_plane(0.5 * a.evaluate(0.0, 0.5)[2])      # crosses the side u = 0 twice
    ua, ub, ok = solve_held(a, flat, np.array([[0.0, 0.4]]), np.array([[0.1, 0.4]]),
                            np.array([0]), np.array([0]), np.array([0.0]), 1e-12)
    assert ok.all() and ua[0, 0] == 0.0
    np.testing.assert_allclose(a.evaluate(*ua[0]), flat.evaluate(*ub[0]), atol=1e-12)


def test_u_characteristic_curve_is_traced_with_phi_u_zero(bumps_field):
    uv, st, _ = edge_roots(bumps_field, 0)
    inward = 0.5 - uv
    curves = trace_curves(bumps_field, CurveKind.U_CHARACTERISTIC, uv, st, inward, h0=0.02,
                          h_max=0.1)
    for c in curves:
        assert c.end_reason in (EndReason.DOMAIN, EndReason.CLOSED)
        scale = np.abs(c.grad).max() + 1.0
        assert np.abs(c.grad[:, 0]).max() <= 1e-6 * scale          # on phi_u = 0 (eq. 13)
        if c.end_reason is EndReason.DOMAIN:
            end = c.uv[-1]
            assert min(end.min(), 1 - end.max()) <= 1e-12
    # a u-characteristic curve through a top crosses phi_v = 0 there: sign change seen
    assert any(np.any(np.diff(np.sign(c.grad[:, 1])) != 0) for c in curves)


def test_intersection_loop_closes_and_step_cap_is_a_cap(bumps_field):
    """eq. 33 around the first bump at z = 0.3: a closed loop of samples on phi = 0;
    with max_steps = 5 the trace stops at the cap."""
    start = np.array([[0.28116173, 0.30090869]])
    jet = bumps_field.jet(start)
    # walk from the top along +u to the loop (phi changes sign there)
    t = np.linspace(0, 0.2, 401)
    ray = bumps_field.jet(np.stack([0.28116173 + t, np.full_like(t, 0.30090869)], -1))
    k = int(np.flatnonzero(np.sign(ray.phi) != np.sign(jet.phi[0]))[0])
    uv0 = ray.uv[k:k + 1]
    (loop,) = trace_curves(bumps_field, CurveKind.INTERSECTION, uv0, ray.st[k:k + 1],
                           np.array([[0.0, 1.0]]), h0=1e-3, h_max=0.03, ctol=1e-12)
    assert loop.end_reason is EndReason.CLOSED
    assert np.abs(loop.phi).max() <= 1e-10
    (capped,) = trace_curves(bumps_field, CurveKind.INTERSECTION, uv0, ray.st[k:k + 1],
                             np.array([[0.0, 1.0]]), h0=1e-3, h_max=0.03, max_steps=5)
    assert capped.end_reason is EndReason.STEP_LIMIT and capped.uv.shape[0] == 6


def test_saddle_on_the_intersection_is_a_double_point():
    """z = g(x) - g(y) against z = 0: the diagonals x = y and x = 1 - y cross at the
    centre, a saddle of phi with phi = 0 (eq. 8, det H < 0); the tracer splits at the
    double point, so four half-diagonals come back, each from a side to the centre
    (a BIFURCATION end there), exactly."""
    from helpers.surfaces import clamped, height_field

    from surfprep.algorithms.basis import greville_abscissae
    from surfprep.algorithms.characteristic import characteristic_intersection
    x = greville_abscissae(clamped(6, 3), 3)
    X, Y = np.meshgrid(x, x, indexing="ij")
    a = height_field(0.3 * (X - 0.5) ** 2 - 0.3 * (Y - 0.5) ** 2)
    b = horizontal_plane(0.0)
    rec = characteristic_intersection(a, b, tol=1e-9)
    (double,) = rec.of_kind(PointKind.DOUBLE_POINT)
    np.testing.assert_allclose(double.uv_a, [0.5, 0.5], atol=1e-9)
    assert len(rec.curves) == 4 and not any(c.closed for c in rec.curves)
    for c in rec.curves:
        assert EndKind.BIFURCATION in (c.start_kind, c.end_kind)
        p = c.curve3d.evaluate(np.linspace(0, c.parameters[-1], 101))
        np.testing.assert_allclose(p[:, 2], 0.0, atol=1e-9)
        np.testing.assert_allclose(np.abs(p[:, 0] - 0.5), np.abs(p[:, 1] - 0.5), atol=1e-9)
        assert c.parameters[-1] == pytest.approx(np.sqrt(2) / 2, rel=1e-9)


@pytest.mark.parametrize("pair", ["degree six", "torus ridge"])
def test_compiled_critical_newton_matches_the_numpy_form(pair):
    """points_kernels runs critical_points' Newton seed by seed: the same points (plain
    step on the degree-6 pair; pseudo-inverse steps onto the torus's ridge of
    critical points, where det H = 0 all along the top circle)."""
    from helpers.surfaces import degree_six_pair, torus_and_plane

    from surfprep.algorithms.characteristic import points_kernels
    from surfprep.algorithms.characteristic.grid import choose_field, field_grid
    from surfprep.algorithms.characteristic.points import grid_seeds

    assert points_kernels.AVAILABLE                # numba is a declared dependency
    a, b = degree_six_pair() if pair == "degree six" else torus_and_plane(1e-3)
    field = choose_field(a, b, tol=1e-9)
    grid, shape = field_grid(field)
    seeds = grid_seeds(grid, shape)
    scale = float(np.abs(grid.hess).max()) if pair == "torus ridge" else 0.0
    ref = critical_points(field, seeds, hess_scale=scale, compiled=False)
    new = critical_points(field, seeds, hess_scale=scale, compiled=True)
    assert ref is not None and new is not None
    assert ref.uv.shape[0] >= (3 if pair == "degree six" else 2)
    np.testing.assert_allclose(new.uv, ref.uv, atol=1e-9 * field.diagonal)
    np.testing.assert_allclose(new.phi, ref.phi, atol=1e-12)
    assert np.abs(new.grad).max() <= 1e-9 * max(np.abs(new.hess).max(), 1.0)


def test_first_apart_keeps_the_earlier_of_close_points():
    """The dedupe of critical and border points: greedy in order, a point kept when
    farther than the radius from every one kept before it (not from dropped ones)."""
    from surfprep.algorithms.characteristic.points import _first_apart
    pts = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.55, 0.0], [1.0, 0.61]])
    assert _first_apart(pts, 0.6) == [0, 2, 4]
    assert _first_apart(pts, 0.4) == [0, 1, 2, 3, 4]
    assert _first_apart(np.zeros((0, 3)), 1.0) == []
