"""``local_approximant(side_error=True)``: sides that cut across a tight bend of their
boundary curve between the kept samples count in the error and raise the resolution."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_curve, interpolate_surface
from surfprep.algorithms.healing import local_approximant
from surfprep.algorithms.healing.connectivity import Side, side_points
from surfprep.algorithms.projection import project_to_curve


def plane():
    x = np.linspace(-0.2, 1.2, 4)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, 0.0 * gx], axis=-1), degree_u=1, degree_v=1)


def bumpy_boundary():
    """A square whose bottom side has a narrow in-plane bump (width 0.06) near x = 0.8."""
    x = np.linspace(0, 1, 401)
    bottom = interpolate_curve(np.column_stack([x, 0.1 * np.exp(-((x - 0.8) / 0.06) ** 2),
                                                0 * x]))
    lines = [np.array([[1.0, 0, 0], [1, 1, 0]]), np.array([[1.0, 1, 0], [0, 1, 0]]),
             np.array([[0.0, 1, 0], [0, 0, 0]])]
    return [bottom, *lines]


def side_deviation(surface, curve, n=2000):
    return project_to_curve(curve, side_points(surface, Side.V0, n)).distance.max()


@pytest.mark.slow
def test_side_error_resolves_a_tight_bend_of_a_side():
    boundary = bumpy_boundary()
    plain = local_approximant(boundary, plane())
    checked = local_approximant(boundary, plane(), side_error=True)
    assert plain.converged                          # the interior is flat: 001's error is 0
    assert side_deviation(plain.surface, boundary[0]) > plain.tol     # the side is not
    assert checked.converged and checked.resolution[0] > plain.resolution[0]
    assert side_deviation(checked.surface, boundary[0]) <= checked.tol
    assert checked.max_error >= plain.max_error
