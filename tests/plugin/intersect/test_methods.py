"""surfprep.intersect(method=...) and ``surfprep intersect --method``: the characteristic
method in the product (issue 4): small loops added by the certificate, tangential
contact points returned as isolated points, the result still a list."""

from __future__ import annotations

import json

import cadquery as cq
import numpy as np
import pytest
from helpers.cli import run
from OCP.BRepCheck import BRepCheck_Analyzer

import surfprep
from surfprep.plugin.intersect import FoundBy, IntersectionResult, Method, intersect

R2 = np.sqrt(0.5)


@pytest.fixture(scope="module")
def sphere():
    return cq.Solid.makeSphere(1.0, angleDegrees1=-90, angleDegrees2=90)


def plane_at(loop_radius: float):
    """A square face facing (1, 1, 0) cutting the unit sphere in a circle of
    ``loop_radius`` (0: touching it at (R2, R2, 0))."""
    d = np.sqrt(1 - loop_radius ** 2)
    return cq.Face.makePlane(0.6, 0.6, basePnt=(d * R2, d * R2, 0), dir=(R2, R2, 0))


def test_small_loop_missed_by_the_triangles_is_added(sphere):
    """A circle of radius 5e-4 (the triangles, at their default mesh tolerance, miss it):
    ``auto`` traces it from the characteristic points, within tol of both faces."""
    mesh = intersect(sphere, plane_at(5e-4), tol=1e-8, method="mesh")
    auto = intersect(sphere, plane_at(5e-4), tol=1e-8)
    assert isinstance(auto, IntersectionResult) and auto.method is Method.AUTO
    assert len(auto) == 1 and auto[0].closed
    assert len(auto) > len(mesh)                         # pinned: the triangles miss it
    assert auto[0].found_by is FoundBy.CHARACTERISTIC
    assert auto[0].max_deviation().max <= 1e-8
    p = auto[0].points
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1.0, atol=1e-8)
    centre = np.sqrt(1 - 5e-4 ** 2) * np.array([R2, R2, 0])
    np.testing.assert_allclose(np.linalg.norm(p - centre, axis=1), 5e-4, atol=1e-8 / 5e-4)
    (edge,) = auto[0].to_edges()
    assert BRepCheck_Analyzer(edge).IsValid()


def test_tangent_plane_gives_an_isolated_point_not_a_curve(sphere):
    for method in (Method.AUTO, "characteristic"):
        res = intersect(sphere, plane_at(0.0), tol=1e-8, method=method)
        assert res == [] and len(res) == 0
        (p,) = res.isolated_points
        np.testing.assert_allclose(p.point, [R2, R2, 0], atol=1e-6)
        assert p.faces == (0, 0)
    assert intersect(sphere, plane_at(0.0), tol=1e-8, method="mesh").isolated_points == []


def test_methods_agree_on_an_ordinary_cut(sphere):
    cut = cq.Face.makePlane(4, 4, basePnt=(0, 0, 0.3))
    lengths = {}
    for method in Method:
        res = intersect(sphere, cut, tol=1e-7, method=method)
        assert len(res) == 1 and res[0].closed
        assert res[0].max_deviation().max <= 1e-7
        lengths[method] = float(res[0].curve.parameters[-1])
        assert all(r.found_by is (FoundBy.MESH if method is not Method.CHARACTERISTIC
                                  else FoundBy.CHARACTERISTIC) for r in res)
        assert len(res.records) == 1
        assert (res.records[0].record is None) == (method is Method.MESH)
    ref = 2 * np.pi * np.sqrt(0.91)
    for value in lengths.values():
        assert value == pytest.approx(ref, rel=1e-4)


def test_bad_method_is_refused(sphere):
    with pytest.raises(ValueError):
        intersect(sphere, plane_at(0.0), method="triangles")



def test_cli_method_found_by_and_plot(sphere, tmp_path, capsys):
    a, b = tmp_path / "sphere.step", tmp_path / "plane.step"
    surfprep.write(sphere, a)
    surfprep.write(plane_at(5e-4), b)
    out, report, plot = tmp_path / "cut.step", tmp_path / "r.json", tmp_path / "p.png"
    code, stdout, err = run(capsys, "intersect", a, b, "-o", out, "--json", report,
                            "--plot", plot, "--tol", "1e-8", "--method", "auto")
    assert code == 0, err
    assert "found only by the characteristic method" in stdout
    r = json.loads(report.read_text())
    assert r["method"] == "auto" and r["n_curves"] == 1
    assert r["curves"][0]["found_by"] == "characteristic"
    (pair,) = r["pairs"]
    assert pair["found_by_characteristic"] == 1
    assert pair["route"] == "small crossing angle"       # a tiny loop near the pole: flat
    assert pair["characteristic_points"].get("minimum", 0) + \
        pair["characteristic_points"].get("maximum", 0) == 1
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, stdout, err = run(capsys, "intersect", a, b, "-o", tmp_path / "m.step", "--json", "-",
                            "--tol", "1e-8", "--method", "mesh")
    assert code == 0 and json.loads(stdout)["n_curves"] == 0
    code, stdout, err = run(capsys, "intersect", a, b, "-o", tmp_path / "x.step",
                            "--method", "bogus")
    assert code != 0


def test_cli_reports_the_contact_point(sphere, tmp_path, capsys):
    a, b = tmp_path / "sphere.step", tmp_path / "touch.step"
    surfprep.write(sphere, a)
    surfprep.write(plane_at(0.0), b)
    code, stdout, err = run(capsys, "intersect", a, b, "-o", tmp_path / "c.step", "--json", "-",
                            "--tol", "1e-8")
    assert code == 0, err
    r = json.loads(stdout)
    assert r["n_curves"] == 0 and len(r["isolated_points"]) == 1
    np.testing.assert_allclose(r["isolated_points"][0]["point"], [R2, R2, 0], atol=1e-6)


def test_certificate_skips_plane_and_ruled_pairs():
    """Box faces (planes) x a cylinder's side (straight along its axis): ``auto`` skips
    the certificate there (prefilter) and answers exactly what ``mesh`` does."""
    box = cq.Solid.makeBox(2, 2, 2, pnt=cq.Vector(-1, -1, -1))
    cylinder = cq.Solid.makeCylinder(0.5, 3, pnt=cq.Vector(0.3, 0, -1.5))
    side = [f for f in cylinder.Faces() if f.geomType() == "CYLINDER"]
    auto = intersect(box, side, tol=1e-7)
    mesh = intersect(box, side, tol=1e-7, method="mesh")
    assert auto.records and all(r.record is not None and r.record.extra.get("skipped")
                                for r in auto.records)
    assert sorted(round(c.length, 6) for c in auto) == sorted(round(c.length, 6) for c in mesh)
    assert len(auto) >= 2 and all(c.found_by is FoundBy.MESH for c in auto)


@pytest.mark.parametrize("method", ["auto", "characteristic"])
def test_cadquery_sphere_resting_on_a_plate_touches_at_its_pole(method):
    """cadquery's sphere has its poles on the z axis: a plate on top touches it at
    the north pole, a collapsed side of the face's parametrization (no interior
    critical point of phi there); the contact is one isolated point, no curve.
    With the plate 1e-3 lower it cuts a small circle instead."""
    sphere = cq.Workplane().sphere(10)
    touch = intersect(sphere, cq.Workplane().box(30, 30, 1).translate((0, 0, 10.5)),
                      tol=1e-6, method=method)
    assert len(touch) == 0 and len(touch.isolated_points) == 1
    np.testing.assert_allclose(touch.isolated_points[0].point, [0, 0, 10], atol=1e-9)
    cut = intersect(sphere, cq.Workplane().box(30, 30, 1).translate((0, 0, 10.499)),
                    tol=1e-6, method=method)
    assert cut.isolated_points == [] and len(cut) == 1
    assert cut[0].curve.length == pytest.approx(2 * np.pi * np.sqrt(100 - 9.999 ** 2), rel=1e-5)


@pytest.fixture(scope="module")
def torus():
    return cq.Solid.makeTorus(1.0, 0.3)


def top_plane(gap: float):
    return cq.Face.makePlane(3.0, 3.0, basePnt=(0, 0, 0.3 - gap), dir=(0, 0, 1))


def test_torus_cut_just_below_its_top_gives_both_circles(torus):
    """A plane normal to the torus axis 1e-6 below the top: two circles 1.5e-3 apart
    (radii 1 +- sqrt(0.3^2 - 0.299999^2)). phi is constant along the circles of
    latitude (a ridge of critical points, not isolated ones); the certificate traces
    the ridge and finds both circles, which the triangles miss."""
    gap, tol = 1e-6, 1e-8
    auto = intersect(torus, top_plane(gap), tol=tol)
    mesh = intersect(torus, top_plane(gap), tol=tol, method="mesh")
    assert len(auto) == 2 and len(mesh) < 2                  # pinned: the triangles miss
    half = np.sqrt(0.3 ** 2 - (0.3 - gap) ** 2)
    radii = []
    for c in auto:
        assert c.closed and c.found_by is FoundBy.CHARACTERISTIC
        assert c.max_deviation().max <= tol
        p = c.curve.curve3d.evaluate(np.linspace(*c.curve.curve3d.domain, 500))
        np.testing.assert_allclose(p[:, 2], 0.3 - gap, atol=tol)
        rho = np.hypot(p[:, 0], p[:, 1])
        radii.append(rho.mean())
        target = 1 + half if rho.mean() > 1 else 1 - half
        # within tol of both surfaces, meeting at a small angle: radial slack tol / sin
        assert np.abs(rho - target).max() <= 10 * tol / (half / 0.3)
    assert min(radii) < 1 < max(radii)


def test_torus_touching_a_plane_along_its_top_circle(torus):
    """Tangential contact along a whole circle: one curve (not fragments, not a hang)."""
    tol = 1e-8
    res = intersect(torus, top_plane(0.0), tol=tol)
    assert len(res) == 1 and res.isolated_points == []
    c = res[0]
    assert c.closed and c.max_deviation().max <= tol
    p = c.curve.curve3d.evaluate(np.linspace(*c.curve.curve3d.domain, 500))
    np.testing.assert_allclose(p[:, 2], 0.3, atol=tol)
    # along a tangency a point within tol of both surfaces may sit sqrt(2 r tol) off
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 1.0, atol=2 * np.sqrt(0.6 * tol))
