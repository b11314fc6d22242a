"""Hanging (OPEN) ends of traced curves continued by marching (algorithms.intersection.extend)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import plane_z, wall

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection.extend import extend_open_ends
from surfprep.algorithms.intersection.refine import RefinedCurve
from surfprep.algorithms.projection import distance_to_surface

TOL = 1e-7


def sunk_wall() -> NurbsSurface:
    """The parabola wall y = 1 - x^2 from z = -0.5 to 0.5: the plane z = 0 cuts it
    along its v = 0.5 isoline, x from -1 to 1 (its u sides)."""
    w = wall()
    return NurbsSurface(w.control_points - [0, 0, 0.5], w.knots_u, w.knots_v, 2, 1)


def piece(u0: float, u1: float, n: int = 9) -> RefinedCurve:
    """A part of the exact curve, u in [u0, u1] of the wall (x = 2u - 1)."""
    u = np.linspace(u0, u1, n)
    x = 2 * u - 1
    points = np.stack([x, 1 - x * x, np.zeros(n)], axis=1)
    uv_plane = np.stack([(x + 2) / 4, (points[:, 1] + 2) / 4], axis=1)
    uv_wall = np.stack([u, np.full(n, 0.5)], axis=1)
    return RefinedCurve(points, uv_plane, uv_wall, False, np.ones(n, bool), np.zeros(n, bool))


@pytest.mark.parametrize("ends", [(True, True), (True, False), (False, True)])
def test_open_ends_marched_to_the_domain_sides(ends):
    a, b = plane_z(0.0), sunk_wall()
    (out,), (reached,) = extend_open_ends([piece(0.25, 0.6)], [ends], a, b, tol=TOL, step=0.01)
    assert reached == ends
    x = out.points[:, 0]
    assert x[0] == pytest.approx(-1 if ends[0] else -0.5, abs=1e-9)
    assert x[-1] == pytest.approx(1 if ends[1] else 0.2, abs=1e-9)
    assert np.all(np.diff(x) > 0)                              # in order, no fold
    assert distance_to_surface(a, out.points).max() <= TOL / 16
    assert distance_to_surface(b, out.points).max() <= TOL / 16
    np.testing.assert_allclose(out.points[:, 1], 1 - x * x, atol=TOL)


def test_march_stops_at_another_curves_end():
    """Two pieces of one curve with a gap: the march from one stops at the other."""
    a, b = plane_z(0.0), sunk_wall()
    left, right = piece(0.1, 0.4), piece(0.5, 0.9)
    out, reached = extend_open_ends([left, right], [(False, True), (False, False)], a, b,
                                    tol=TOL, step=0.01)
    assert reached == [(False, False), (False, False)]
    end = out[0].points[-1]
    assert np.linalg.norm(end - right.points[0]) <= 0.03       # within a step of it
    assert out[0].points[:, 0].max() <= right.points[0, 0] + 0.03
