"""Meshes as healing sources (001 takes triangles as input): a hole whose missing face
carried a bump the neighbours cannot predict is filled following a triangulation of the
true surface, and without it by the multiquadric fill of the neighbours' shape."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.intersection import TriangleMesh
from surfprep.algorithms.io import write_stl
from surfprep.errors import ConversionError
from surfprep.plugin.heal import heal
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import compound

BUMP = 0.05


def truth(x, y):
    """A smooth sheet with a bump of height BUMP over the middle cell [1/3, 2/3]^2 only."""
    inside = (x > 1 / 3) & (x < 2 / 3) & (y > 1 / 3) & (y < 2 / 3)
    bump = BUMP * np.sin(np.pi * (3 * x - 1)) ** 2 * np.sin(np.pi * (3 * y - 1)) ** 2
    return 0.2 * np.sin(1.3 * x) * np.cos(0.9 * y) + np.where(inside, bump, 0.0)


def patch(x0, x1, y0, y1):
    x, y = np.meshgrid(np.linspace(x0, x1, 7), np.linspace(y0, y1, 7), indexing="ij")
    return interpolate_surface(np.stack([x, y, truth(x, y)], axis=-1))


@pytest.fixture(scope="module")
def holed_grid():
    return compound([make_face(patch(i / 3, (i + 1) / 3, j / 3, (j + 1) / 3))
                     for i in range(3) for j in range(3) if (i, j) != (1, 1)])


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    """The true surface over the middle cell and a margin, sampled 81 x 81, as an STL."""
    x, y = np.meshgrid(np.linspace(0.3, 0.7, 81), np.linspace(0.3, 0.7, 81), indexing="ij")
    mesh = TriangleMesh.from_grids([np.stack([x, y, truth(x, y)], axis=-1)])
    return write_stl(mesh, tmp_path_factory.mktemp("scan") / "scan.stl")


def _hole_deviation(result) -> float:
    """Largest |z - truth| over the hole's patch, on 41 x 41 of its parameters."""
    (hole,) = [k for k, p in enumerate(result.patches) if p.origin.kind == "hole"]
    s = result.approximants[hole].surface
    u0, u1, v0, v1 = s.domain
    pts = s.evaluate_grid(np.linspace(u0, u1, 41), np.linspace(v0, v1, 41))
    return float(np.max(np.abs(pts[..., 2] - truth(pts[..., 0], pts[..., 1]))))


@pytest.mark.slow
def test_a_mesh_over_the_hole_gives_the_patch_its_shape(holed_grid, scan):
    without = heal(holed_grid)
    with_scan = heal(holed_grid, meshes=[scan])
    assert _hole_deviation(without) > 0.5 * BUMP          # the bump cannot be guessed
    assert _hole_deviation(with_scan) < 0.05 * BUMP       # it follows the scan
    assert with_scan.valid_after and with_scan.tight_free_edges_after == 12   # the border


def test_a_mesh_source_must_be_a_mesh(holed_grid):
    with pytest.raises(ConversionError, match="healing mesh"):
        heal(holed_grid, meshes=[42])


@pytest.mark.slow
def test_the_command_takes_a_mesh(holed_grid, scan, tmp_path, capsys):
    import json

    import surfprep
    from helpers.cli import run
    source = tmp_path / "grid.step"
    surfprep.write(holed_grid, source)
    code, _, err = run(capsys, "heal", source, "-o", tmp_path / "out.step", "--mesh", scan,
                       "--json", tmp_path / "r.json")
    assert code == 0, err
    report = json.loads((tmp_path / "r.json").read_text())
    assert [p["kind"] for p in report["patches"]].count("hole") == 1
    code, _, err = run(capsys, "heal", source, "-o", tmp_path / "x.step", "--mesh",
                       tmp_path / "missing.stl")
    assert code == 2 and "missing.stl" in err
