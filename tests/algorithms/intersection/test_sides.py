"""SSI along a domain side (algorithms.intersection.sides): a wall standing on a plane.

The wall's side v = 0 is the parabola ``y = 1 - x^2`` in the plane ``z = 0``; the
tessellations only touch there (its chords lie in the plane exactly), which gave
scattered pieces before the side was intersected directly.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import plane_z, wall

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import intersect_surfaces
from surfprep.algorithms.intersection.sides import (
    DomainSide,
    may_run_along,
    may_run_along_many,
    side_curves,
)
from surfprep.algorithms.projection import distance_to_curve, distance_to_surface

TOL = 1e-7




def parabola(x0: float = -1.0, x1: float = 1.0, n: int = 20001) -> np.ndarray:
    x = np.linspace(x0, x1, n)
    return np.stack([x, 1 - x * x, np.zeros_like(x)], axis=1)


def check_on_both(curves, a, b, per_span: int = 7) -> None:
    for c in curves:
        t = c.span_parameters(per_span).ravel()
        p = np.concatenate([c.points, c.curve3d.evaluate(t)])
        assert distance_to_surface(a, p).max() <= TOL
        assert distance_to_surface(b, p).max() <= TOL


def covers(curves, exact: np.ndarray) -> float:
    return float(np.min([distance_to_curve(c.curve3d, exact[::50]) for c in curves], axis=0).max())


@pytest.mark.parametrize("order", ["plane_first", "wall_first"])
def test_wall_on_plane_one_curve_along_the_side(order):
    a, b = (plane_z(0.0), wall()) if order == "plane_first" else (wall(), plane_z(0.0))
    curves = intersect_surfaces(a, b, tol=TOL)
    assert len(curves) == 1
    check_on_both(curves, a, b)
    exact = parabola()
    assert covers(curves, exact) <= TOL
    length = np.linalg.norm(np.diff(exact, axis=0), axis=1).sum()
    assert curves[0].length == pytest.approx(length, rel=1e-6)
    ends = curves[0].points[[0, -1]]
    assert np.sort(ends[:, 0]) == pytest.approx([-1, 1], abs=TOL)


def test_side_leaving_the_other_surface_ends_at_its_edge():
    """The plane only reaches x = 0.5: the run along the side stops there (bisection)."""
    a = NurbsSurface(np.array([[[-2, -2, 0], [-2, 2, 0]], [[0.5, -2, 0], [0.5, 2, 0]]], float),
                     [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    curves, runs = side_curves(a, wall(), [DomainSide(1, 1, 0.0)], tol=TOL)
    assert len(curves) == len(runs) == 1
    p = curves[0].points
    assert p[:, 0].min() == pytest.approx(-1, abs=TOL)
    assert p[:, 0].max() == pytest.approx(0.5, abs=1e-6)
    assert distance_to_surface(a, p).max() <= TOL / 16


def test_sides_not_on_the_other_surface_give_nothing():
    lifted = NurbsSurface(plane_z(0.0).control_points + [0, 0, 1e-3], [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    assert side_curves(lifted, wall(), [DomainSide(1, 1, 0.0)], tol=TOL) == ([], [])


def test_narrow_face_is_not_taken_for_a_closed_surface():
    """A 0.02 wide strip (x = 0, y in [0, 0.02], z in [-0.4, 1.6]) cut by the plane z = 0
    with mesh_tol 0.01: its opposite sides are nearer than 4 mesh_tol, which made
    the seam cut treat the strip as closed and the curve ran half-way out and back
    (KCS hull transom). Now one straight curve across the strip."""
    strip = NurbsSurface(np.array([[[0, 0, -0.4], [0, 0, 1.6]], [[0, 0.02, -0.4], [0, 0.02, 1.6]]],
                                  float), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    curves = intersect_surfaces(strip, plane_z(0.0), tol=TOL, mesh_tol=0.01)
    assert len(curves) == 1
    p = curves[0].points
    assert np.sort(p[[0, -1], 1]) == pytest.approx([0, 0.02], abs=TOL)
    assert curves[0].length == pytest.approx(0.02, rel=1e-9)


def test_may_run_along_tells_a_side_on_the_surface_from_a_crossing():
    """The cheap pre-test of a side scan: the wall's foot (side v = 0) lies on the
    plane next to a traced point on it; the wall's end u = 0, sunk to cross the
    plane at its middle, leaves the plane half a sample spacing either side."""
    flat, standing = plane_z(0.0), wall()
    foot = DomainSide(owner=0, coord=1, value=0.0)
    assert may_run_along(standing, flat, foot, np.array([0.5]), np.array([[0.5, 0.75]]),
                         tol=TOL)
    sunk = NurbsSurface(standing.control_points - np.array([0.0, 0.0, 0.5]),
                        standing.knots_u, standing.knots_v, 2, 1)
    end = DomainSide(owner=0, coord=0, value=0.0)
    assert not may_run_along(sunk, flat, end, np.array([0.5]), np.array([[0.25, 0.5]]),
                             tol=TOL)
    # a curve through the corner: the probe beyond the side's end is not taken
    assert not may_run_along(standing, flat, end, np.array([0.0]), np.array([[0.25, 0.5]]),
                             tol=TOL)
    # several sides in one batch: the same answers as one by one
    far = DomainSide(owner=0, coord=0, value=1.0)
    sides = [foot, end, far, end]
    ts = [np.array([0.5, 0.25]), np.array([0.0]), np.array([2.0]), np.array([0.5])]
    guesses = [np.array([[0.5, 0.75], [0.25, 0.75]]), np.array([[0.25, 0.5]]),
               np.array([[0.25, 0.5]]), np.array([[0.25, 0.5]])]
    one_by_one = [may_run_along(standing, flat, s, t, g, tol=TOL)
                  for s, t, g in zip(sides, ts, guesses)]
    assert may_run_along_many(standing, flat, sides, ts, guesses, tol=TOL) == one_by_one
    assert one_by_one[0] and one_by_one[2]          # on the plane; no probe inside: True


def test_touching_sides_can_be_left_out():
    """Two planes meeting at a right angle along a side of each (an L): the
    tessellations do not cross, the side is found by default; a caller that drops
    every curve along a face's edges (a shape's self-intersection) leaves it out.
    A crossing is still found."""
    k = [0, 0, 1, 1]
    flat = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]], float),
                        k, k, 1, 1)

    def upright(x):                                   # the plane x = const, z in [0, 1]
        return NurbsSurface(np.array([[[x, 0, 0], [x, 0, 1]], [[x, 1, 0], [x, 1, 1]]],
                                     float), k, k, 1, 1)

    (side,) = intersect_surfaces(flat, upright(0.0), tol=TOL)
    check_on_both([side], flat, upright(0.0))
    assert side.length == pytest.approx(1.0, abs=TOL)
    assert intersect_surfaces(flat, upright(0.0), tol=TOL, touching_sides=False) == []
    (cut,) = intersect_surfaces(flat, upright(0.5), tol=TOL, touching_sides=False)
    np.testing.assert_allclose(cut.points[:, [0, 2]], 0.0 * cut.points[:, [0, 2]] + [0.5, 0],
                               atol=TOL)
    assert cut.length == pytest.approx(1.0, abs=TOL)
