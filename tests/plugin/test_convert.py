"""The public dispatchers ``to_nurbs`` / ``to_occ`` on OCP, cadquery and build123d input."""

from __future__ import annotations

import build123d as bd
import cadquery as cq
import numpy as np
import pytest
from helpers.paths import SAMPLES
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.Geom import (
    Geom_BSplineCurve,
    Geom_BSplineSurface,
    Geom_Circle,
    Geom_Plane,
    Geom_SphericalSurface,
    Geom_TrimmedCurve,
)
from OCP.Geom2d import Geom2d_BSplineCurve, Geom2d_Circle
from OCP.gp import gp_Ax1, gp_Ax2, gp_Ax2d, gp_Ax3, gp_Dir, gp_Pnt, gp_Pnt2d, gp_Trsf, gp_Vec
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Face

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.algorithms.trimmed import TrimmedFace
from surfprep.errors import ConversionError
from surfprep.plugin.convert import to_nurbs, to_occ
from surfprep.plugin.occ.faces import make_face as to_occ_face
from surfprep.plugin.occ.shapes import all_faces
from surfprep.plugin.occ_reference import evaluate_curve


def _same_face(a: TrimmedFace, b: TrimmedFace) -> bool:
    return (np.array_equal(a.surface.control_points, b.surface.control_points)
            and np.array_equal(a.surface.knots_u, b.surface.knots_u)
            and len(a.edges) == len(b.edges) and a.reversed == b.reversed
            and all(np.array_equal(e.pcurve.control_points, f.pcurve.control_points)
                    for e, f in zip(a.edges, b.edges)))


# ------------------------------------------------------------------ geometry
def test_geometry_inputs():
    sphere = Geom_SphericalSurface(gp_Ax3(), 2.0)
    surface = to_nurbs(sphere)
    assert isinstance(surface, NurbsSurface)
    # GeomConvert reparametrizes; the points still lie on the sphere
    u0, u1, v0, v1 = surface.domain
    pts = surface.evaluate(*np.meshgrid(np.linspace(u0, u1, 7), np.linspace(v0, v1, 7)))
    assert np.allclose(np.linalg.norm(pts, axis=-1), 2.0, atol=1e-12)
    assert isinstance(to_occ(surface), Geom_BSplineSurface)

    circle = Geom_Circle(gp_Ax2(gp_Pnt(1, 2, 3), gp_Dir(0, 0, 1)), 1.5)
    curve = to_nurbs(Geom_TrimmedCurve(circle, 0.0, 2.0))
    assert curve.dimension == 3
    assert isinstance(to_occ(curve), Geom_BSplineCurve)
    pcurve = to_nurbs(Geom2d_Circle(gp_Ax2d(gp_Pnt2d(0, 0), gp_Dir2d_x()), 1.0))
    assert pcurve.dimension == 2
    assert isinstance(to_occ(pcurve), Geom2d_BSplineCurve)


def gp_Dir2d_x():
    from OCP.gp import gp_Dir2d
    return gp_Dir2d(1, 0)


def test_infinite_surface_needs_a_face():
    with pytest.raises(ConversionError, match="infinite"):
        to_nurbs(Geom_Plane(gp_Ax3()))


# ------------------------------------------------------------------ topology
def test_face_edge_and_shape_inputs():
    box = cq.Workplane().box(1, 2, 3).val().wrapped
    faces = to_nurbs(box)
    assert isinstance(faces, list) and len(faces) == 6
    assert all(isinstance(f, TrimmedFace) for f in faces)
    assert _same_face(to_nurbs(all_faces(box)[0]), faces[0])
    edge = cq.Workplane().box(1, 2, 3).edges().vals()[0]
    curve = to_nurbs(edge.wrapped)
    assert isinstance(curve, NurbsCurve) and curve.dimension == 3


def test_located_shapes_apply_the_location():
    """Faces and edges of moved shapes come out where OpenCascade's adaptors
    (which apply the location) put them."""
    # a B-spline face moved by a rotation + translation location
    x, y = np.meshgrid(np.linspace(0, 3, 4), np.linspace(0, 2, 4), indexing="ij")
    cp = np.stack([x, y, np.zeros((4, 4))], axis=-1)
    cp[1:3, 1:3, 2] = 0.7
    surface = NurbsSurface(cp, [0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1], 3, 3)
    trsf = gp_Trsf()
    trsf.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 1, 0)), 0.6)
    trsf.SetTranslationPart(gp_Vec(5, -2, 1))
    moved = TopoDS.Face_s(to_occ_face(surface).Moved(TopLoc_Location(trsf)))
    tf = to_nurbs(moved)
    adaptor = BRepAdaptor_Surface(moved)
    u, v = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    ref = np.array([adaptor.Value(a, b).Coord() for a, b in zip(u.ravel(), v.ravel())])
    assert np.max(np.abs(tf.surface.evaluate(u.ravel(), v.ravel()) - ref)) <= 1e-12 * 6
    for edge in tf.edges:
        t = np.linspace(edge.t0, edge.t1, 5)
        uv = edge.pcurve.evaluate(t)
        assert np.allclose(tf.surface.evaluate(uv[:, 0], uv[:, 1]), edge.curve3d.evaluate(t),
                           atol=1e-12)
    # analytic solid: rotated and moved
    shape = (cq.Workplane().cylinder(2, 1).val()
             .rotate((0, 0, 0), (1, 1, 0), 30).translate((5, -2, 1)))
    for face in all_faces(shape.wrapped):
        tf = to_nurbs(face)
        converted = BRepAdaptor_Surface(TopoDS.Face_s(BRepBuilderAPI_NurbsConvert(face, True).Shape()))
        u0, u1, v0, v1 = tf.surface.domain
        u, v = np.meshgrid(np.linspace(u0, u1, 5), np.linspace(v0, v1, 5), indexing="ij")
        ref = np.array([converted.Value(a, b).Coord() for a, b in zip(u.ravel(), v.ravel())])
        assert np.max(np.abs(tf.surface.evaluate(u.ravel(), v.ravel()) - ref)) <= 1e-12 * 10
    for edge in shape.Edges():
        ours = to_nurbs(edge.wrapped)
        adaptor = BRepAdaptor_Curve(edge.wrapped)
        if ours.domain == (adaptor.FirstParameter(), adaptor.LastParameter()):
            t = np.linspace(*ours.domain, 9)
            ref = np.array([adaptor.Value(x).Coord() for x in t])
            # lines keep their parameter, so points must agree exactly
            if ours.degree == 1:
                assert np.allclose(ours.evaluate(t), ref, atol=1e-12)
        # the ends always agree
        ends = np.array([adaptor.Value(adaptor.FirstParameter()).Coord(),
                         adaptor.Value(adaptor.LastParameter()).Coord()])
        assert np.allclose(ours.evaluate(np.array(ours.domain)), ends, atol=1e-12)


def test_bspline_edge_is_restricted_to_its_range():
    spline = cq.Edge.makeSpline([cq.Vector(0, 0, 0), cq.Vector(1, 2, 0), cq.Vector(3, 1, 1),
                                 cq.Vector(4, 0, 0)])
    occ_curve = BRepAdaptor_Curve(spline.wrapped)
    t0, t1 = occ_curve.FirstParameter(), occ_curve.LastParameter()
    ours = to_nurbs(spline.wrapped)
    assert ours.domain == pytest.approx((t0, t1), abs=0)
    t = np.linspace(t0, t1, 11)
    ref = np.array([occ_curve.Value(x).Coord() for x in t])
    assert np.max(np.abs(ours.evaluate(t) - ref)) < 1e-12 * 5


# ------------------------------------------------------------ cadquery / build123d
def test_cadquery_inputs_match_raw_topods():
    wp = cq.Workplane().box(4, 4, 1).faces(">Z").workplane().hole(1)
    raw = to_nurbs(wp.val().wrapped)
    from_workplane = to_nurbs(wp)
    from_shape = to_nurbs(wp.val())
    assert len(raw) == len(from_workplane) == len(from_shape) == 7
    assert all(_same_face(a, b) and _same_face(a, c)
               for a, b, c in zip(raw, from_workplane, from_shape))
    face = wp.faces(">Z").val()
    assert isinstance(face, cq.Face)
    assert _same_face(to_nurbs(face), to_nurbs(face.wrapped))
    assert len(to_nurbs(wp.faces(">Z or <Z"))) == 2


def test_build123d_inputs_match_raw_topods():
    part = bd.Cylinder(1, 2) - bd.Box(0.5, 0.5, 5)
    raw = to_nurbs(part.wrapped)
    assert all(_same_face(a, b) for a, b in zip(raw, to_nurbs(part)))
    face_list = part.faces()
    assert isinstance(face_list, bd.ShapeList)
    assert all(_same_face(a, b) for a, b in zip(raw, to_nurbs(face_list)))
    assert _same_face(to_nurbs(face_list[0]), to_nurbs(face_list[0].wrapped))
    edge = part.edges()[0]
    assert np.array_equal(to_nurbs(edge).control_points, to_nurbs(edge.wrapped).control_points)


# ------------------------------------------------------------------ round trip
def test_to_occ_round_trip_of_a_trimmed_face():
    face = to_nurbs(cq.Workplane().sphere(1).val().wrapped)[0]
    occ_face = to_occ(face)
    assert isinstance(occ_face, TopoDS_Face)
    assert BRepCheck_Analyzer(occ_face).IsValid()
    again = to_nurbs(occ_face)
    assert np.array_equal(again.surface.control_points, face.surface.control_points)
    assert len(again.edges) == len(face.edges)


def test_to_occ_curves_evaluate_the_same():
    curve = NurbsCurve([[0, 0, 0], [1, 2, 0], [3, 1, 1]], [0, 0, 0, 1, 1, 1], 2, [1, 0.5, 2])
    t = np.linspace(0, 1, 7)
    assert np.allclose(evaluate_curve(to_occ(curve), t, 1), curve.derivatives(t, 1), atol=1e-14)


# ------------------------------------------------------------------ errors
@pytest.mark.parametrize("bad", [42, "face.step", None, np.zeros(3), object()])
def test_unknown_inputs_name_their_type(bad):
    with pytest.raises(ConversionError, match=type(bad).__name__):
        to_nurbs(bad)
    with pytest.raises(ConversionError, match=type(bad).__name__):
        to_occ(bad)


def test_shapes_without_faces():
    wire = cq.Wire.makePolygon([cq.Vector(0, 0, 0), cq.Vector(1, 0, 0), cq.Vector(1, 1, 0)])
    with pytest.raises(ConversionError, match="no face"):
        to_nurbs(wire.wrapped)
    with pytest.raises(ConversionError, match="null"):
        to_nurbs(TopoDS_Compound())
    with pytest.raises(ConversionError):
        to_nurbs(cq.Workplane())      # empty workplane
    with pytest.raises(ConversionError, match="null"):
        to_nurbs(TopoDS_Face())


def test_curve_of_unsupported_dimension():
    with pytest.raises(ConversionError, match="dimension"):
        to_occ(NurbsCurve(np.zeros((2, 1)) + [[0.0], [1.0]], [0, 0, 1, 1], 1))


def test_cad_model_faces_carry_their_names_from_the_file():
    from surfprep.plugin.io import read

    sample = SAMPLES / "synthetic_named_faces.step"
    model = read(sample)
    faces = to_nurbs(model)
    assert [f.name for f in faces] == list(model.face_names)
    assert [f.name for f in faces][:2] == ["uniform_patch", "cubic_u_patch"]
