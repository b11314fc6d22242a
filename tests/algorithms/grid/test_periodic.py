"""A closed face's seam solved across (O-type grids), measured on the grids' nodes."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import warped_plane
from helpers.occ_shapes import cylinder, sphere, torus

import surfprep
from surfprep.algorithms.grid import grid_surface
from surfprep.algorithms.grid.periodic import Seam
from surfprep.errors import DegenerateGeometryError


def _turns(points: np.ndarray) -> np.ndarray:
    """Turning angle (degrees) of every i-line at every node, the seam (node 0 = node -1)
    included: (ni - 1, nj)."""
    closed = np.concatenate([points[-2:-1], points], axis=0)     # the node before the seam
    a, b = closed[1:-1] - closed[:-2], closed[2:] - closed[1:-1]
    cos = np.einsum("...k,...k->...", a, b) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def _seam_kink(points: np.ndarray) -> float:
    """How much more the i-lines turn at the seam i0 = i1 than at their other nodes (degrees):
    0 for lines as smooth across the seam as elsewhere."""
    turns = _turns(points)
    return float(np.abs(turns[0] - np.median(turns[1:], axis=0)).max())


def test_a_torus_is_solved_across_its_seam():
    """Holding the seam's nodes kinked the lines there by 35 degrees and skewed the cells to
    0.20 (the harmonic lines drift toward the inside of the tube); solved across it, with the
    spacing of the start kept round the closed lines, the grid of a surface of revolution is
    (nearly) its start: the param grid's angles, no kink."""
    ring = torus(10.0, 3.0)
    grid = grid_surface(ring, dims=(41, 11))
    assert grid.seam is not None and grid.seam.axis == 0
    assert grid.elliptic.converged and grid.quality.folded_cells == 0
    p = grid.points
    assert np.abs(p[0] - p[-1]).max() < 1e-12 * 26                 # one seam
    assert _seam_kink(p) < 0.5
    assert grid.quality.max_skewness <= grid.start_quality.max_skewness + 1e-3      # was 0.20
    assert abs(grid.quality.min_angle - grid.start_quality.min_angle) < 0.1


def test_a_cylinder_keeps_its_exact_grid():
    can = cylinder(5.0, 10.0)
    grid = grid_surface(can, dims=(33, 9), tol=1e-8)
    assert grid.seam is not None
    assert grid.quality.max_skewness < 1e-6 and _seam_kink(grid.points) < 1e-6


def test_an_open_face_has_no_seam():
    grid = grid_surface(warped_plane(), dims=(9, 7))
    assert grid.seam is None
    st = grid.parameters
    assert Seam.find(st, grid.points, warped_plane().domain, 1.4) is None


def test_a_torus_in_a_model_has_smooth_lines_across_both_seams(tmp_path):
    """The model's torus face: its seam i0 = i1 solved across, j0 = j1 slid as a shared edge."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeTorus
    path = tmp_path / "ring.step"
    surfprep.write(BRepPrimAPI_MakeTorus(10.0, 3.0).Shape(), path)
    result = surfprep.grid(path)
    report = result.report()
    assert len(result.blocks) == 1 and len(report["interfaces"]) == 2
    assert max(i["kink_deg"] for i in report["interfaces"]) < 1.0
    assert report["worst"]["max_skewness"] < 0.06 and report["worst"]["folded_cells"] == 0


def test_a_sphere_alone_is_refused_with_the_way_out():
    with pytest.raises(DegenerateGeometryError, match="pole to pole.*pole_halves"):
        grid_surface(sphere(2.0), dims=(9, 9))
