"""The steps of the RCA method: boundary points, reconciliation, interior relocation."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.curve import NurbsCurve
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.projection import distance_to_curve
from surfprep.algorithms.reparam import (
    arc_length_table,
    boundary_fractions,
    initial_guess,
    penalties,
    reconcile_fractions,
    relocate,
)
from surfprep.algorithms.reparam.boundary_points import boundary_interpolant
from surfprep.algorithms.reparam.deviation import subdivide


def _quarter_circle_squared() -> NurbsCurve:
    """Exact rational quarter circle of radius 2, reparametrized so the speed varies."""
    w = np.sqrt(0.5)
    return NurbsCurve(np.array([[2.0, 0, 0], [2, 2, 0], [0, 2, 0]]), [0, 0, 0, 1, 1, 1], 2,
                      weights=np.array([1.0, w, 1.0]))


def test_arc_length_table_of_circle():
    table = arc_length_table(_quarter_circle_squared())
    assert table.length == pytest.approx(np.pi, rel=1e-9)
    assert np.allclose(table.curvature, 0.5, rtol=1e-3)
    t = table.parameters_at(np.array([0.0, 0.5, 1.0]))
    mid = table.curve.evaluate(t[1])
    assert np.allclose(mid[:2], [np.sqrt(2), np.sqrt(2)], atol=1e-6)


@pytest.mark.parametrize("tol", [1e-3, 1e-5])
def test_boundary_fit_within_tol_densely(tol):
    table = arc_length_table(_quarter_circle_squared())
    fractions, error = boundary_fractions(table, tol)
    assert error <= tol
    fit = boundary_interpolant(table, fractions)
    dense = table.curve.evaluate(np.linspace(0.0, 1.0, 2001))
    assert distance_to_curve(fit, dense).max() <= tol
    # the count follows the tolerance: h ~ tol^(1/4)
    assert 3 <= len(fractions) - 1 <= 4 * (np.pi / (76.8 * tol * 8) ** 0.25 + 3)


def test_boundary_points_crowd_where_curvature_is():
    t = np.linspace(0.0, 1.0, 40)
    x = 4 * t
    y = np.where(t > 0.5, 0.3 * np.sin(20 * np.pi * (t - 0.5)) * (t - 0.5), 0.0)
    from surfprep.algorithms.fitting import interpolate_curve
    curve = interpolate_curve(np.stack([x, y, 0 * t], -1), parameters=t)
    fractions, _ = boundary_fractions(arc_length_table(curve), 1e-4)
    steps = np.diff(fractions)
    first = steps[fractions[1:] < 0.4].mean()
    second = steps[fractions[:-1] > 0.6].mean()
    assert first > 2 * second


def test_reconcile_matches_and_inserts():
    a = np.array([0.0, 0.25, 0.5, 1.0])
    b = np.array([0.0, 0.26, 0.8, 1.0])
    out = reconcile_fractions(a, b)
    assert out[0] == 0.0 and out[-1] == 1.0
    assert np.allclose(out, [0.0, 0.255, 0.5, 0.8, 1.0])       # 0.25 ~ 0.26 matched
    assert np.array_equal(reconcile_fractions(a, None), a)      # a pole takes the other
    assert np.array_equal(reconcile_fractions(a, a), a)


def test_reconcile_merges_a_cluster_from_many_lines():
    """Four lines (two boundaries, two crease lines) nearly agreeing: one point each,
    not pairs plus leftovers (near-equal fractions are tiny knot intervals)."""
    base = np.array([0.0, 0.14, 0.28, 0.43, 0.57, 0.71, 0.86, 1.0])
    sets = [base + d * np.r_[0, np.ones(6), 0] for d in (0.0, 0.001, -0.0015, 0.002)]
    out = reconcile_fractions(*sets)
    assert len(out) == len(base)
    assert np.allclose(out, base, atol=0.002)
    # two points of the same line are never merged, however close
    tight = np.array([0.0, 0.5, 0.501, 1.0])
    assert len(reconcile_fractions(tight, tight + np.r_[0, 1e-4, 1e-4, 0])) == 4


def test_initial_guess_is_the_line_intersection():
    bottom, top = np.array([0.0, 0.3, 1.0]), np.array([0.0, 0.5, 1.0])
    left, right = np.array([0.0, 0.2, 1.0]), np.array([0.0, 0.6, 1.0])
    uv = initial_guess(bottom, top, left, right, (0.0, 1.0, 0.0, 1.0))
    u, v = uv[1, 1]
    assert u == pytest.approx(0.3 + 0.2 * v)             # on the line bottom -> top
    assert v == pytest.approx(0.2 + 0.4 * u)             # on the line left -> right
    assert np.allclose(uv[:, 0, 0], bottom) and np.allclose(uv[-1, :, 1], right)


def test_relocation_recovers_the_cartesian_grid_of_a_sheared_plane():
    """Plane x = a(u, v), y = v with a sheared u: the nodes must end at x = f_i exactly."""
    t = np.linspace(0.0, 1.0, 15)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    a = uu ** (1.0 + np.sin(np.pi * vv))
    plane = interpolate_surface(np.stack([a, vv, 0 * a], -1), params_u=t, params_v=t)
    fu = np.array([0.0, 0.1, 0.3, 0.45, 0.7, 0.85, 1.0])
    fv = np.array([0.0, 0.2, 0.5, 0.8, 1.0])
    # boundary nodes at the fractions (u = f on v = 0, 1 where a = u; v = f on u = 0, 1)
    uv = initial_guess(fu, fu, fv, fv, plane.domain)
    before = penalties(plane.evaluate(uv[..., 0], uv[..., 1]), fu, fv).max()
    result = relocate(plane, uv, fu, fv)
    assert before > 0.3
    assert result.converged and result.penalty_after <= 1e-3
    # the global Newton solve does the work, the node-by-node sweeps only confirm it
    assert result.newton_steps >= 1 and result.sweeps <= 3
    x = result.points
    assert np.allclose(x[..., 0], fu[:, None], atol=2e-3)
    assert np.allclose(x[..., 1], fv[None, :], atol=2e-3)


def test_subdivide():
    assert np.allclose(subdivide(np.array([0.0, 1.0, 3.0]), 2), [0, 0.5, 1, 2, 3])
