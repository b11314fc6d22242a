"""Boundary curves of a local approximant: orientation, gaps, arc-length sampling (001 §3)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.curve import NurbsCurve
from surfprep.algorithms.fitting import interpolate_curve
from surfprep.algorithms.healing import as_boundary, corners_boundary
from surfprep.algorithms.healing.coons import discrete_coons
from surfprep.errors import DegenerateGeometryError, InvalidGeometryError

P = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [1.0, 1.0, 0.0], [0.0, 1.0, 0.2]])


def test_corners_boundary_straight_sides_and_corners():
    b = corners_boundary(*P)
    np.testing.assert_array_equal(b.corners, P)
    bottom, top, left, right = b.sample(4, 5)
    np.testing.assert_allclose(bottom, np.linspace(P[0], P[1], 5), atol=1e-15)
    np.testing.assert_allclose(top, np.linspace(P[3], P[2], 5), atol=1e-15)
    np.testing.assert_allclose(left, np.linspace(P[0], P[3], 6), atol=1e-15)
    np.testing.assert_allclose(right, np.linspace(P[1], P[2], 6), atol=1e-15)


def test_curves_given_against_the_loop_are_reversed():
    lines = [np.stack([P[0], P[1]]), np.stack([P[1], P[2]]), np.stack([P[3], P[2]]),
             np.stack([P[0], P[3]])]                         # top and left "forward"
    b = as_boundary(lines)
    np.testing.assert_array_equal(b.corners, P)
    assert np.all(b.gaps == 0)
    reversed_first = as_boundary([lines[0][::-1]] + lines[1:])
    np.testing.assert_array_equal(reversed_first.corners, P)


def test_gap_between_curves_is_reported_with_its_size():
    lines = [np.stack([P[k], P[(k + 1) % 4]]) for k in range(4)]
    lines[1] = lines[1] + np.array([0.0, 0.0, 0.05])
    with pytest.raises(InvalidGeometryError, match=r"bottom curve ends 0\.05 from the start of "
                                                   r"the right curve"):
        as_boundary(lines)
    small = [np.stack([P[k], P[(k + 1) % 4]]) for k in range(4)]
    small[1] = small[1] + np.array([0.0, 0.0, 1e-6])
    b = as_boundary(small, gap_tol=1e-5)                     # within gap_tol: averaged
    np.testing.assert_allclose(b.corners[1], P[1] + [0, 0, 0.5e-6], atol=1e-15)
    assert b.gaps[0] == pytest.approx(1e-6)


@pytest.mark.parametrize("bad, match", [
    ([np.zeros((2, 3))] * 3, "exactly four"),
    ([np.array([[0, 0, np.nan], [1, 0, 0]])] + [np.zeros((2, 3))] * 3, "NaN"),
    ([np.zeros((2, 2))] * 4, r"shape \(n >= 2, 3\)"),
    (["abc"] * 4, "NurbsCurve or an"),
])
def test_bad_boundaries_are_refused(bad, match):
    with pytest.raises(InvalidGeometryError, match=match):
        as_boundary(bad)


def test_zero_length_side_is_degenerate():
    with pytest.raises(DegenerateGeometryError):
        as_boundary([np.zeros((2, 3))] + [np.stack([P[k], P[(k + 1) % 4]]) for k in range(1, 4)])
    with pytest.raises(InvalidGeometryError, match="3D point"):
        corners_boundary(P[0], P[1], P[2], P[3][:2])


def test_nurbs_sides_are_sampled_uniformly_in_arc_length():
    # a cubic whose parameter speed varies strongly along the side
    pts = np.array([[0, 0, 0], [0.05, 0, 0.02], [0.2, 0, 0.03], [1.0, 0, 0.0]], float)
    bottom = interpolate_curve(pts, parameters=[0, 0.6, 0.8, 1.0])
    right = np.stack([pts[-1], [1.0, 1.0, 0.0]])
    top = np.stack([[1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    left = np.stack([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    b = as_boundary([bottom, right, top, left])
    samples = b.sample(10, 2)[0]
    dense = bottom.evaluate(np.linspace(0, 1, 20001))
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    # arc length at each sample: nearest dense point
    near = np.argmin(np.linalg.norm(dense[None] - samples[:, None], axis=2), axis=1)
    np.testing.assert_allclose(np.diff(s[near]), s[-1] / 10, rtol=2e-3)
    assert isinstance(b.curves[0], NurbsCurve)


def test_coons_grid_of_straight_boundary_is_the_bilinear_patch():
    g = discrete_coons(corners_boundary(*P), 6, 4)
    u, v = g.u[..., None], g.v[..., None]
    bilinear = (1 - u) * (1 - v) * P[0] + u * (1 - v) * P[1] + u * v * P[2] + (1 - u) * v * P[3]
    np.testing.assert_allclose(g.points, bilinear, atol=1e-15)
    assert g.resolution == (6, 4)
    with pytest.raises(InvalidGeometryError, match="at least"):
        discrete_coons(corners_boundary(*P), 1, 4)
