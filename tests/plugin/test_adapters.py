"""surfprep.cadquery and surfprep.build123d: the verbs on CadQuery / build123d objects,
returning that library's objects, and the opt-in Workplane methods."""

from __future__ import annotations

import doctest
import json
import math
import subprocess
import sys

import build123d as bd
import cadquery as cq
import numpy as np
import pytest

import surfprep
import surfprep.build123d
import surfprep.cadquery
from surfprep.plugin import adapters
from surfprep.plugin.adapters import ModelReparametrizeResult
from surfprep.plugin.adapters import build123d as bd_adapter
from surfprep.plugin.adapters import cadquery as cq_adapter

RADIUS = 10.0


def _ball() -> cq.Workplane:
    return cq.Workplane().sphere(RADIUS)


def _slab() -> cq.Workplane:
    """Between z = 4.5 and z = 5.5: it cuts the sphere in two circles."""
    return cq.Workplane().box(30, 30, 1).translate((0, 0, 5))


def _uneven_face():
    """A bicubic sheet with x = 10 u^3 (the reparametrize docstring's, 10 times larger): its
    chord-length mismatch is 7, as a TopoDS_Face."""
    from surfprep.algorithms.fitting import interpolate_surface

    t = np.linspace(0, 1, 9)
    u, v = np.meshgrid(t, t, indexing="ij")
    sheet = interpolate_surface(np.stack([10 * u**3, 10 * v, np.sin(3 * u**3)], axis=-1),
                                params_u=t, params_v=t)
    return surfprep.make_face(sheet)


def _bd_loft() -> bd.Part:
    """A circle lofted to a rectangle: five B-spline side faces and two planar caps."""
    with bd.BuildPart() as loft:
        with bd.BuildSketch():
            bd.Circle(5)
        with bd.BuildSketch(bd.Plane.XY.offset(10)):
            bd.Rectangle(6, 8)
        bd.loft()
    return loft.part


def _run(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip()


# ------------------------------------------------------------------ imports
def test_import_surfprep_loads_neither_cadquery_nor_build123d():
    code = ("import sys, surfprep; print(sorted(m for m in ('cadquery', 'build123d', "
            "'surfprep.cadquery', 'surfprep.build123d', 'surfprep.plugin.adapters') "
            "if m in sys.modules))")
    assert _run(code) == "[]"


def test_surfprep_cadquery_does_not_hide_the_real_cadquery_nor_load_build123d():
    code = ("import sys, surfprep.cadquery, cadquery; "
            "print(cadquery is not surfprep.cadquery, hasattr(cadquery, 'Workplane'), "
            "'site-packages' in cadquery.__file__, 'build123d' in sys.modules, "
            "hasattr(cadquery.Workplane, 'surface_intersections'))")
    assert _run(code) == "True True True False False"


def test_the_facades_export_the_adapter_functions():
    for facade, adapter in ((surfprep.cadquery, cq_adapter), (surfprep.build123d, bd_adapter)):
        for name in facade.__all__:
            assert getattr(facade, name) is getattr(adapter, name)
        assert set(facade.__all__) == set(adapter.__all__)
    assert set(surfprep.build123d.__all__) == {"heal", "reparametrize", "intersect", "split",
                                               "boolean", "prepare"}


@pytest.mark.parametrize("module", [surfprep.cadquery, surfprep.build123d, cq_adapter, bd_adapter,
                                    adapters], ids=lambda m: m.__name__.removeprefix("surfprep."))
def test_the_examples_run(module, workplane_without_our_methods):
    tests = [t for t in doctest.DocTestFinder().find(module, module.__name__, globs={})
             if t.examples and t.name.startswith(module.__name__)]
    assert tests
    runner = doctest.DocTestRunner()
    for test in tests:
        runner.run(test)
    assert runner.tries > len(tests) and runner.failures == 0, f"{runner.failures} example(s) failed"


# ------------------------------------------------------------------ cadquery
def test_cadquery_intersect_gives_the_two_circles_as_cq_edges():
    edges, result = surfprep.cadquery.intersect(_ball(), _slab(), tol=1e-7, report=True)
    assert isinstance(result, surfprep.IntersectionResult) and len(result) == 2
    assert len(edges) == 2 and all(type(e) is cq.Edge for e in edges)
    heights = []
    for edge in edges:
        assert edge.IsClosed()
        p = np.array([edge.positionAt(t).toTuple() for t in np.linspace(0, 1, 41)])
        z = p[0, 2]
        heights.append(round(z, 6))
        np.testing.assert_allclose(p[:, 2], z, atol=1e-6)                       # on the slab's face
        np.testing.assert_allclose(np.linalg.norm(p, axis=1), RADIUS, atol=1e-6)  # on the sphere
        np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), math.sqrt(RADIUS**2 - z**2),
                                   atol=1e-6)
    assert sorted(heights) == [4.5, 5.5]


def test_cadquery_takes_shapes_and_topods_alike():
    edges = surfprep.cadquery.intersect(_ball().val(), _slab().val().wrapped)
    assert [type(e) for e in edges] == [cq.Edge, cq.Edge]
    with pytest.raises(surfprep.ConversionError, match="Workplane holds no shape"):
        surfprep.cadquery.heal(cq.Workplane())


def test_cadquery_heal_split_boolean_and_prepare_return_cadquery_shapes():
    healed, result = surfprep.cadquery.heal(cq.Workplane().box(10, 20, 3), report=True)
    assert type(healed) is cq.Solid and isinstance(result, surfprep.HealResult)
    assert healed.Volume(tol=1e-9) == pytest.approx(600.0, rel=1e-9)
    pieces, cut = surfprep.cadquery.split(_ball(), _slab(), report=True)
    assert type(pieces) is cq.Compound and isinstance(cut, surfprep.SplitResult)
    assert len(pieces.Faces()) == 11 and cut.report()["pieces"] == 7    # 3 zones; 6 + 2 slab faces
    assert len(pieces.Shells()) == 1                                    # sewn, not loose faces
    ready, prepared = surfprep.cadquery.prepare(cq.Workplane().box(10, 20, 3), report=True)
    assert type(ready) is cq.Solid and isinstance(prepared, surfprep.PrepareResult)


def test_cadquery_boolean_is_the_lens_of_two_balls():
    lens, result = surfprep.cadquery.boolean(cq.Workplane().sphere(5),
                                             cq.Workplane().sphere(5).translate((6, 0, 0)),
                                             "common", report=True)
    assert type(lens) is cq.Solid and isinstance(result, surfprep.BooleanResult)
    exact = 2 * math.pi * 2**2 * (3 * 5 - 2) / 3                         # two caps of height 2
    assert lens.Volume(tol=1e-9) == pytest.approx(exact, rel=1e-6)


def test_cadquery_reparametrize_a_face_and_a_shape():
    sheet = cq.Face(_uneven_face())
    face, result = surfprep.cadquery.reparametrize(sheet, report=True)
    assert type(face) is cq.Face and isinstance(result, surfprep.ReparametrizeResult)
    assert result.report()["mismatch_after"] < 1.1 < result.report()["mismatch_before"]
    assert face.Area() == pytest.approx(sheet.Area(), rel=1e-4)
    loft = cq.Workplane().circle(5).workplane(offset=10).rect(6, 8).loft()
    solid, model = surfprep.cadquery.reparametrize(loft, report=True)
    assert type(solid) is cq.Solid and isinstance(model, ModelReparametrizeResult)
    report = model.report()
    json.dumps(report)
    assert report["reparametrized"] == 5 and report["skipped"] == 0
    assert solid.isValid() and len(solid.Faces()) == len(loft.val().Faces())


# ------------------------------------------------------- Workplane methods
@pytest.fixture
def workplane_without_our_methods():
    """``cq.Workplane`` as CadQuery defines it; afterwards exactly as the test found it."""
    found = dict(vars(cq.Workplane))
    had_ours = cq_adapter.unregister()
    yield dict(vars(cq.Workplane))
    cq_adapter.unregister()
    if had_ours:
        cq_adapter.register()
    assert dict(vars(cq.Workplane)) == found


def test_the_method_names_are_not_cadquery_attributes(workplane_without_our_methods):
    for name in surfprep.cadquery.WORKPLANE_METHODS:
        assert not hasattr(cq.Workplane, name), name
    assert callable(cq.Workplane.intersect) and callable(cq.Workplane.split)   # CadQuery's own


def test_register_adds_only_new_methods_and_unregister_restores_the_class(
        workplane_without_our_methods):
    before = workplane_without_our_methods
    added = surfprep.cadquery.register()
    assert added == surfprep.cadquery.WORKPLANE_METHODS
    after = dict(vars(cq.Workplane))
    assert set(after) - set(before) == set(added)
    assert all(after[name] is value for name, value in before.items())   # nothing replaced
    assert surfprep.cadquery.register() == added and dict(vars(cq.Workplane)) == after  # idempotent
    assert surfprep.cadquery.unregister() == added
    assert dict(vars(cq.Workplane)) == before
    assert surfprep.cadquery.unregister() == ()


def test_register_refuses_a_name_cadquery_already_has(workplane_without_our_methods, monkeypatch):
    monkeypatch.setattr(cq.Workplane, "split_faces", lambda self: self, raising=False)
    with pytest.raises(RuntimeError, match="split_faces"):
        surfprep.cadquery.register()
    assert not any(name in vars(cq.Workplane) for name in ("heal", "reparametrize",
                                                            "surface_intersections"))
    assert surfprep.cadquery.unregister() == ()                   # not ours: left alone
    assert "split_faces" in vars(cq.Workplane)


def test_registered_methods_chain_like_cadquerys_own(workplane_without_our_methods):
    surfprep.cadquery.register()
    try:
        ball = _ball()
        curves = ball.surface_intersections(_slab())
        assert type(curves) is cq.Workplane and curves.parent is ball
        assert [type(v) for v in curves.vals()] == [cq.Edge, cq.Edge]
        assert sorted(round(e.Center().z, 6) for e in curves.vals()) == [4.5, 5.5]
        common = ball.intersect(_slab())                          # CadQuery's Boolean, unchanged
        assert common.val().Volume() == pytest.approx(math.pi * (100 - 25 - 1 / 12), rel=1e-3)
        pieces = ball.split_faces(_slab())
        assert type(pieces.val()) is cq.Compound and len(pieces.faces().vals()) == 11
        healed = cq.Workplane().box(10, 20, 3).heal()
        assert type(healed.val()) is cq.Solid
        assert healed.val().Volume(tol=1e-9) == pytest.approx(600.0, rel=1e-9)
        even = cq.Workplane().add(cq.Face(_uneven_face())).reparametrize()
        assert type(even.val()) is cq.Face
        assert surfprep.parametrization_quality(
            surfprep.to_nurbs(even.val()).surface).worst < 1.1
        with pytest.raises(TypeError, match="report"):                # a method keeps the chain
            ball.heal(report=True)
    finally:
        surfprep.cadquery.unregister()


# ----------------------------------------------------------------- build123d
def _labelled(shape: bd.Shape, label: str = "plate") -> bd.Shape:
    shape.label = label
    shape.color = bd.Color(0.2, 0.4, 0.6)
    return shape


def _same_label_and_color(a: bd.Shape, b: bd.Shape) -> bool:
    return a.label == b.label and tuple(a.color) == tuple(b.color)


def test_build123d_reparametrize_refuses_a_box_it_has_no_b_spline_face():
    plate = _labelled(bd.Box(10, 20, 3))
    with pytest.raises(surfprep.InvalidGeometryError, match="no B-spline face"):
        surfprep.build123d.reparametrize(plate)
    with pytest.raises(surfprep.ConversionError, match="Geom_Plane"):
        surfprep.build123d.reparametrize(plate.faces()[0])


def test_build123d_reparametrize_keeps_label_and_colour():
    sheet = _labelled(bd.Face(_uneven_face()), "sheet")
    face, result = surfprep.build123d.reparametrize(sheet, report=True)
    assert type(face) is bd.Face and _same_label_and_color(face, sheet)
    assert result.report()["mismatch_after"] < 1.1 < result.report()["mismatch_before"]
    assert face.area == pytest.approx(sheet.area, rel=1e-4)
    loft = _labelled(_bd_loft())
    part, model = surfprep.build123d.reparametrize(loft, report=True)
    assert type(part) is bd.Compound and _same_label_and_color(part, loft)
    assert isinstance(model, ModelReparametrizeResult) and model.report()["reparametrized"] == 5
    assert part.volume == pytest.approx(loft.volume, rel=1e-4)


def test_build123d_heal_in_builder_mode():
    plate = _labelled(bd.Box(10, 20, 3))
    healed = surfprep.build123d.heal(plate, replace="all")      # every face an approximant
    assert type(healed) is bd.Solid and _same_label_and_color(healed, plate)
    with bd.BuildPart() as builder:
        bd.insert(healed)
        bd.Hole(radius=1)                                        # and CAD goes on as usual
    assert builder.part.volume == pytest.approx(600.0 - math.pi * 3, rel=1e-6)
    assert builder.part.area == pytest.approx(2 * (200 + 30 + 60) + 2 * math.pi * 3 - 2 * math.pi,
                                              rel=1e-6)


def test_build123d_algebra_mode_and_verbs_without_a_label():
    ball, slab = bd.Sphere(RADIUS), bd.Pos(0, 0, 5) * bd.Box(30, 30, 1)
    part = surfprep.build123d.split(ball, slab)
    assert type(part) is bd.Compound and len(part.faces()) == 11
    moved = bd.Pos(100, 0, 0) * part
    assert moved.center().X == pytest.approx(100 + part.center().X)
    alone = surfprep.build123d.split(_labelled(bd.Sphere(RADIUS)))   # one operand: label kept
    assert alone.label == "plate"
    edges = surfprep.build123d.intersect(ball, slab)
    assert [type(e) for e in edges] == [bd.Edge, bd.Edge]
    assert sorted(round(e.position_at(0).Z, 6) for e in edges) == [4.5, 5.5]
    lens = surfprep.build123d.boolean(bd.Sphere(5), bd.Pos(6, 0, 0) * bd.Sphere(5), "common")
    assert type(lens) is bd.Solid
    half = lens - bd.Pos(0, 0, 5) * bd.Box(20, 20, 10)          # algebra on the result
    assert half.volume == pytest.approx(lens.volume / 2, rel=1e-3)


def test_build123d_takes_topods_and_prepare_keeps_the_label():
    healed = surfprep.build123d.heal(bd.Box(10, 20, 3).wrapped)
    assert type(healed) is bd.Solid and healed.label == ""
    plate = _labelled(bd.Box(10, 20, 3))
    ready, result = surfprep.build123d.prepare(plate, report=True)
    assert type(ready) is bd.Solid and _same_label_and_color(ready, plate)
    assert isinstance(result, surfprep.PrepareResult)
    assert ready.volume == pytest.approx(600.0)
