"""grid_surface: dims, spacing laws measured in 3D, reports, refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.grid_cases import warped_cylinder, warped_plane
from helpers.surfaces import sphere_patch

from surfprep.algorithms.grid import Spacing, grid_surface
from surfprep.errors import InvalidGeometryError


def test_dims_and_size():
    grid = grid_surface(warped_plane(), dims=(7, 4))
    assert grid.points.shape == (7, 4, 3) and grid.parameters.shape == (7, 4, 2)
    assert grid.dims == (7, 4)
    # cylinder: sides of length pi (u) and 4 (v): size 0.25 -> 14 and 17 nodes
    grid = grid_surface(warped_cylinder(), size=0.25, smooth="none")
    assert grid.dims == (int(np.ceil(np.pi / 0.25)) + 1, 17)


def test_nodes_lie_on_the_surface_and_the_corners_are_the_surfaces():
    surface = sphere_patch(1.0)
    grid = grid_surface(surface, dims=(11, 9))
    np.testing.assert_allclose(np.linalg.norm(grid.points, axis=-1), 1.0, atol=1e-12)
    u0, u1, v0, v1 = surface.domain
    np.testing.assert_allclose(grid.parameters[0, 0], [u0, v0])
    np.testing.assert_allclose(grid.parameters[-1, -1], [u1, v1])


@pytest.mark.parametrize("spacing", [Spacing(first=0.01), Spacing(first=0.02, last=0.05),
                                     Spacing(law="geometric", first=0.03)])
def test_first_spacing_is_measured_in_space(spacing):
    """The sphere patch is rational (not arc-length parametrized): the first
    interval is the distance asked for between the first two nodes."""
    grid = grid_surface(sphere_patch(), dims=(21, 15), spacing=spacing)
    p = grid.points
    for line in (p[:, 0], p[:, -1], p[0], p[-1]):
        legs = np.linalg.norm(np.diff(line, axis=0), axis=1)
        # chord of the first arc: the arc length asked for, shortened by the curvature
        assert legs[0] == pytest.approx(spacing.first, rel=1e-4)
        if spacing.last is not None:
            assert legs[-1] == pytest.approx(spacing.last, rel=1e-4)
    assert grid.spacing_error < 1e-4
    assert grid.quality.folded_cells == 0


def test_the_laws_differ_per_direction():
    grid = grid_surface(warped_cylinder(), dims=(21, 15),
                        spacing=(Spacing(growth=1.1), Spacing()))
    legs_i = np.linalg.norm(np.diff(grid.points[:, 0], axis=0), axis=1)
    legs_j = np.linalg.norm(np.diff(grid.points[0], axis=0), axis=1)
    np.testing.assert_allclose(legs_i[1:] / legs_i[:-1], 1.1, rtol=1e-3)
    np.testing.assert_allclose(legs_j, legs_j[0], rtol=1e-9)


def test_report_is_plain_json():
    report = grid_surface(warped_plane(), dims=(9, 9)).report()
    text = json.dumps(report, allow_nan=False)
    assert '"elliptic"' in text and report["dims"] == [9, 9]
    assert report["quality"]["max_skewness"] < report["start_quality"]["max_skewness"]
    assert grid_surface(warped_plane(), dims=(5, 5), smooth="none").elliptic is None


@pytest.mark.parametrize("kwargs, match", [
    ({"dims": (5, 5), "size": 0.1}, "not both"),
    ({"dims": (1, 5)}, ">= 2"),
    ({"dims": (5.5, 5)}, "integers"),
    ({"size": -1.0}, "positive"),
    ({"size": 1e-9}, "at most"),
    ({"smooth": "laplace"}, "smooth"),
    ({"spacing": "tanh"}, "Spacing"),
])
def test_bad_arguments_are_refused(kwargs, match):
    with pytest.raises(InvalidGeometryError, match=match):
        grid_surface(warped_plane(), **kwargs)


@pytest.mark.parametrize("kwargs, match", [
    ({"law": "sine"}, "unknown spacing law"),
    ({"first": -0.1}, "positive"),
    ({"law": "tanh"}, "first or a last"),
    ({"law": "geometric"}, "growth ratio or a first"),
])
def test_bad_spacings_are_refused(kwargs, match):
    with pytest.raises(InvalidGeometryError, match=match):
        Spacing(**kwargs)
