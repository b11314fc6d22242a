"""Faces cutting through each other healed without a patch spec (plugin/heal/crossings.py):
found from the free edges, cut along their crossing curve, the overshoots dropped, the
faces kept on their own surfaces and met along the curve. Two bent sheets crossing
(001 Fig. 7), a box whose walls and lid overshoot each other, a crossing whose sides
cannot be told apart."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import SLOPE, X_CROSS, compound, sheet, truth_area
from helpers.heal_cases import overshooting_box as box_surfaces
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.ShapeFix import ShapeFix_Shape
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from surfprep.plugin.convert import to_nurbs
from surfprep.plugin.heal import heal
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import all_faces, count_free_edges, face_area, is_valid


@pytest.fixture(scope="module")
def sheets():
    a, b = sheet(0.0, 1.2, 0.0), sheet(0.8, 2.0, SLOPE)       # each overshoots by 0.2
    return a, b, heal(compound([make_face(a), make_face(b)]))


def test_two_sheets_are_trimmed_back_to_their_crossing(sheets):
    a, b, r = sheets
    rep = r.report()
    (crossing,) = rep["crossings"]
    assert crossing["action"] == "trimmed back" and crossing["faces"] == [0, 1]
    # A loses x in [1, 1.2], B x in [0.8, 1] (times the sheets' stretch)
    assert 0.2 < crossing["area_cut"][0] < 0.21 and 0.2 < crossing["area_cut"][1] < 0.23
    assert r.model.n_faces == 2 and r.valid_after
    # free edges: the outer border of the two, six edges; nothing open along the curve
    assert (r.free_edges_before, r.free_edges_after) == (8, 6)
    assert r.tight_free_edges_after == 6
    # the faces keep their own surfaces (trimmed, not approximated)
    out = to_nurbs(r.model.shape)
    def same(f, s):
        return (f.surface.control_points.shape == s.control_points.shape
                and np.allclose(f.surface.control_points, s.control_points, atol=1e-12))
    assert sorted([k for k, s in enumerate((a, b)) if same(f, s)] for f in out) == [[0], [1]]
    # the doubled overshoots are gone: the area is the intended surface's
    assert abs(face_area(r.model.shape) - truth_area()) < 5e-3
    assert not any("overlap over" in note for note in rep["skipped"])  # a crossing is no overlap


def test_the_report_gives_the_time_of_each_stage(sheets):
    rep = sheets[2].report()
    stages = rep["stage_times_s"]
    assert list(stages) == ["reading the faces", "directed patches and overlaps",
                            "finding gaps, holes and crossings",
                            "triangulating the faces as sources", "approximants",
                            "joining, sewing and checking", "closing gaps in the geometry",
                            "classifying the free edges"]
    assert all(t >= 0 for t in stages.values())
    assert 0.9 * rep["time_s"] <= sum(stages.values()) <= rep["time_s"]


def test_nothing_crosses_in_the_output_but_the_shared_edge(sheets):
    # OpenCascade's section of the two output faces: only the curve x = 1 they share
    f, g = all_faces(sheets[2].model.shape)
    section = BRepAlgoAPI_Section(f, g)
    section.Build()
    assert section.IsDone()
    points = []
    explorer = TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current()))
        points += [curve.Value(t).Coord() for t in
                   np.linspace(curve.FirstParameter(), curve.LastParameter(), 33)]
        explorer.Next()
    points = np.array(points)
    assert len(points) > 0
    assert np.max(np.abs(points[:, 0] - X_CROSS)) < 1e-6


def test_with_g1_asked_the_crease_is_said(sheets):
    a, b, r = sheets
    assert not any("not G1" in note for note in r.report()["skipped"])   # G0 asked
    g1 = heal(compound([make_face(a), make_face(b)]), continuity="G1")
    assert [c["action"] for c in g1.report()["crossings"]] == ["trimmed back"]
    assert any("not G1" in note for note in g1.report()["skipped"])
    assert g1.tight_free_edges_after == 6 and g1.valid_after


def test_crossings_are_left_when_asked(sheets):
    a, b, _ = sheets
    r = heal(compound([make_face(a), make_face(b)]), trim_crossings=False)
    assert r.report()["crossings"] == []
    assert r.model.n_faces == 2 and r.free_edges_after == 8
    assert abs(face_area(r.model.shape) - face_area(compound([make_face(a), make_face(b)]))) < 1e-9


def test_a_crossing_half_way_is_left_with_the_reason():
    # two sheets crossing in their middles: no side of either is an overshoot
    a, b = sheet(0.0, 2.0, 0.0), sheet(0.0, 2.0, SLOPE)
    r = heal(compound([make_face(a), make_face(b)]))
    (crossing,) = r.report()["crossings"]
    assert crossing["action"] == "left" and "about the same area" in crossing["reason"]
    assert crossing["area_cut"] == [0.0, 0.0]
    assert r.model.n_faces == 2
    assert any("left as they are" in note for note in r.report()["skipped"])


def overshooting_box(over=0.1, height=1.1):
    return compound([make_face(f) for f in box_surfaces(over, height)])


def volume(shape) -> float:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return float(props.Mass())


def test_a_box_whose_walls_and_lid_overshoot_heals_closed():
    r = heal(overshooting_box())
    rep = r.report()
    assert [c["action"] for c in rep["crossings"]] == ["trimmed back"] * 4
    # each wall loses its 0.1 collar, the lid its rim (0.44, counted once)
    assert np.allclose([c["area_cut"][0] for c in rep["crossings"]], 0.1)
    assert np.isclose(sum(c["area_cut"][1] for c in rep["crossings"]), 1.44 - 1.0)
    assert r.model.n_faces == 6 and r.valid_after
    assert r.free_edges_after == 0 and r.tight_free_edges_after == 0
    assert r.model.shape.ShapeType().name == "TopAbs_SOLID"
    assert abs(face_area(r.model.shape) - 6.0) < 1e-9
    assert abs(abs(volume(r.model.shape)) - 1.0) < 1e-9


def test_sewing_and_shapefix_leave_the_box_open():
    # the reference: OpenCascade's sewing at the same tolerance does not cut faces, so
    # the collar and the rim stay, and every one of their edges stays free
    sewing = BRepBuilderAPI_Sewing(1e-3)
    sewing.Add(overshooting_box())
    sewing.Perform()
    fix = ShapeFix_Shape(sewing.SewedShape())
    fix.Perform()
    shape = fix.Shape()
    assert count_free_edges(shape) == 8
    assert is_valid(shape)
