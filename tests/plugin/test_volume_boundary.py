"""The boundary of a trivariate solid as an OpenCascade solid (plugin/volume_boundary.py),
checked against the exact volumes and by BRepCheck; written by ``compose --boundary``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.io import write_g2
from surfprep.algorithms.volume import NurbsVolume
from surfprep.algorithms.volume_builders import block, revolve, solid_sphere, solid_torus
from surfprep.errors import InvalidGeometryError
from surfprep.plugin.io import read
from surfprep.plugin.occ.shapes import is_valid
from surfprep.plugin.volume_boundary import boundary_solid, composed_volumes


@pytest.mark.parametrize(("solid", "exact", "faces"), [
    (solid_sphere(2.0), 4 / 3 * np.pi * 8, ("u1",)),                 # poles and centre collapse
    (solid_torus(3.0, 1.0), 2 * np.pi ** 2 * 3.0, ("u1",)),          # seams glued
    (block((1.0, 2.0, 3.0)), 6.0, ("u0", "u1", "v0", "v1", "w0", "w1")),
])
def test_the_boundary_closes_into_a_valid_solid_of_the_exact_volume(solid, exact, faces):
    b = boundary_solid(solid)
    assert b.faces == faces
    assert b.closed and b.free_edges == 0 and is_valid(b.shape)
    # OpenCascade's own integration of our faces (outward: a positive volume)
    assert b.volume == pytest.approx(exact, rel=2e-7)


def test_a_left_handed_solid_gets_outward_faces_too():
    right = block((1.0, 2.0, 3.0))
    left = NurbsVolume(right.control_points[::-1], right.knots_u, right.knots_v, right.knots_w,
                       right.degree_u, right.degree_v, right.degree_w)
    b = boundary_solid(left)
    assert b.closed and b.volume == pytest.approx(6.0, rel=1e-12)


def test_a_revolved_sheet_makes_a_ring_with_its_volume():
    # a rectangle 1 x 2 at distance 3..4 from the z axis, turned by 270 degrees
    x, z = np.meshgrid(np.linspace(3.0, 4.0, 3), np.linspace(0.0, 2.0, 3), indexing="ij")
    sheet = interpolate_surface(np.stack([x, np.zeros_like(x), z], axis=-1), degree_u=1,
                                degree_v=1)
    ring = revolve(sheet, (0, 0, 0), (0, 0, 1), angle=1.5 * np.pi)
    b = boundary_solid(ring)
    exact = 0.75 * np.pi * (4.0 ** 2 - 3.0 ** 2) * 2.0
    assert b.closed and b.free_edges == 0
    assert b.volume == pytest.approx(exact, rel=1e-7)
    assert b.volume == pytest.approx(ring.volume(), rel=1e-7)


def test_only_solids_in_space_have_a_boundary_solid():
    with pytest.raises(InvalidGeometryError, match="NurbsVolume in 3D"):
        boundary_solid(solid_sphere(1.0).isosurface(0.5, "u"))


def test_compose_writes_both_boundaries_to_step(tmp_path, capsys):
    a, b = tmp_path / "a.g2", tmp_path / "b.g2"
    write_g2(a, [solid_sphere(5.0, (0, 0, 0))])
    write_g2(b, [block((4.0, 4.0, 4.0), origin=(3.0, -2.0, -2.0))])
    out, report = tmp_path / "both.step", tmp_path / "r.json"
    code, stdout, err = run(capsys, "compose", a, b, "--shell", out, "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())["boundary"]["solids"]
    assert data["A"]["closed"] and data["B"]["closed"]
    assert data["A"]["volume"] == pytest.approx(4 / 3 * np.pi * 125, rel=2e-7)
    assert data["B"]["volume"] == pytest.approx(64.0, rel=1e-12)
    model = read(out)
    assert model.n_faces == 7 and is_valid(model.shape)
    assert "written to" in stdout and "solid of 6 face(s)" in stdout
    # an input is never an output
    code, _, err = run(capsys, "compose", a, b, "--shell", a)
    assert code == 2 and len(err.strip().splitlines()) == 1


def test_compose_writes_the_common_part_and_the_volumes(tmp_path, capsys):
    a, b = tmp_path / "a.g2", tmp_path / "b.g2"
    write_g2(a, [solid_sphere(5.0, (0, 0, 0))])
    write_g2(b, [solid_sphere(5.0, (6, 0, 0))])
    out, report = tmp_path / "lens.step", tmp_path / "r.json"
    code, stdout, err = run(capsys, "compose", a, b, "--boundary", "common", "--shell", out,
                            "--volumes", "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())
    lens, ball = _lens(5.0, 6.0), 4 / 3 * np.pi * 125
    assert data["boundary"]["solids"]["common"]["volume"] == pytest.approx(lens, rel=3e-7)
    assert data["volume_common"] == pytest.approx(lens, rel=1e-9)       # ours
    assert data["volume_union"] == pytest.approx(2 * ball - lens, rel=1e-9)
    assert data["volumes_occ"]["both"] == pytest.approx(lens, rel=3e-7)   # OpenCascade's
    model = read(out)
    assert model.n_faces >= 2 and is_valid(model.shape)     # a cap of each ball (one cut
    assert "common: common solid of" in stdout              # at its seam as well)


def _lens(radius, distance):
    """Volume of the intersection of two balls of equal radius ``distance`` apart."""
    return np.pi * (4 * radius + distance) * (2 * radius - distance) ** 2 / 12


@pytest.mark.parametrize(("a", "b", "both"), [
    (solid_sphere(5.0), solid_sphere(5.0, (6.0, 0.0, 0.0)), _lens(5.0, 6.0)),
    (block((10.0, 10.0, 10.0), origin=(-5.0, -5.0, -5.0)), solid_sphere(2.0),
     4 / 3 * np.pi * 8),                                      # a ball inside a block
    (solid_sphere(1.0), solid_sphere(1.0, (5.0, 0.0, 0.0)), 0.0),   # apart
])
def test_composed_volumes_against_exact_answers(a, b, both):
    v = composed_volumes(a, b)
    assert v.both == pytest.approx(both, rel=3e-7, abs=1e-12)
    assert v.a_only == pytest.approx(a.volume() - both, rel=1e-6)
    assert v.b_only == pytest.approx(b.volume() - both, rel=1e-6, abs=1e-9)
