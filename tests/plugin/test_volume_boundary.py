"""The boundary of a trivariate solid as an OpenCascade solid (plugin/volume_boundary.py),
checked against the exact volumes and by BRepCheck; written by ``compose --boundary``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run
from helpers.measure import distance_to_curves

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


def test_the_tori_of_fig_8_against_opencascade_s_booleans_and_section():
    """No closed form for two misaligned tori: our volumes (divergence theorem in the math
    layer) against GProp of BRepAlgoAPI_Common / Fuse of the boundary solids, and
    BRepAlgoAPI_Section's points against our curves and both exact tori."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Fuse, BRepAlgoAPI_Section
    from OCP.BRepGProp import BRepGProp
    from OCP.GCPnts import GCPnts_AbscissaPoint
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from surfprep.algorithms.composition import compose
    centre, axis = np.array([1.0, 0.5, 0.3]), np.array([0.2, 0.1, 1.0])
    a, b = solid_torus(3.0, 1.0), solid_torus(3.0, 1.0, centre, axis)
    ours = compose(a, b)
    sa, sb = boundary_solid(a).shape, boundary_solid(b).shape

    def volume(op):
        op.Build()
        assert op.IsDone()
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(op.Shape(), props, 1e-9)
        return props.Mass()
    assert ours.volume("common") == pytest.approx(volume(BRepAlgoAPI_Common(sa, sb)), rel=1e-7)
    assert ours.volume("union") == pytest.approx(volume(BRepAlgoAPI_Fuse(sa, sb)), rel=1e-7)
    section = BRepAlgoAPI_Section(sa, sb)
    section.Build()
    assert section.IsDone()
    occ, length, ex = [], 0.0, TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while ex.More():
        c = BRepAdaptor_Curve(TopoDS.Edge_s(ex.Current()))
        length += GCPnts_AbscissaPoint.Length_s(c)
        for t in np.linspace(c.FirstParameter(), c.LastParameter(), 400):
            p = c.Value(t)
            occ.append((p.X(), p.Y(), p.Z()))
        ex.Next()
    occ = np.array(occ)
    curves = [c for _, _, c in ours.curves]
    dense = np.vstack([c.curve3d.evaluate(np.linspace(*c.curve3d.domain, 2000)) for c in curves])
    # OpenCascade's section lies on our curves (to its own accuracy, 2.5e-6 in the
    # benchmark) and is as long as all of them together
    assert distance_to_curves(curves, occ, 1e-12).max() < 1e-5
    assert sum(c.length for c in curves) == pytest.approx(length, rel=1e-6)

    def tube(p, c, n):
        q = p - c
        z = q @ (n / np.linalg.norm(n))
        rho = np.linalg.norm(q - z[:, None] * n / np.linalg.norm(n), axis=1)
        return np.abs(np.hypot(rho - 3.0, z) - 1.0)
    assert max(tube(dense, np.zeros(3), np.array([0.0, 0, 1])).max(), tube(dense, centre, axis).max()) <= ours.tol
