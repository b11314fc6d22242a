"""Edges between OpenCascade and surfprep's NURBS types.

:func:`edge_to_nurbs` reads an edge's 3D curve; :func:`make_edge` builds an edge
with pcurves on one or two faces. The reading and building of the edges inside
a face's loops (:class:`~surfprep.algorithms.trimmed.TrimEdge`, used by
:mod:`.faces`) live here too.
"""

from __future__ import annotations

from collections.abc import Sequence

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.BRepLib import BRepLib
from OCP.Geom import Geom_BezierCurve, Geom_BSplineCurve, Geom_Line
from OCP.Geom2d import Geom2d_BezierCurve, Geom2d_BSplineCurve, Geom2d_Line
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_REVERSED
from OCP.TopExp import TopExp
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Vertex

from ...algorithms import NurbsCurve, NurbsSurface
from ...algorithms.tolerance import check_tolerance
from ...algorithms.trimmed import DEFAULT_TOLERANCE, TrimEdge, edge_deviation
from ...errors import ConversionError, InvalidGeometryError, OpenCascadeError
from .geom import curve2d_to_occ, curve_from_occ, curve_to_occ
from .shapes import check_valid

__all__ = ["build_trim_edge", "edge_to_nurbs", "make_edge", "read_trim_edge"]

# ----------------------------------------------------------------- reading
EXACT_3D = (Geom_BSplineCurve, Geom_BezierCurve, Geom_Line)
EXACT_2D = (Geom2d_BSplineCurve, Geom2d_BezierCurve, Geom2d_Line)


def converts_exactly(curve, exact_types, trimmed_type) -> bool:
    """True when ``curve_from_occ`` keeps the curve's parametrization."""
    while isinstance(curve, trimmed_type):
        curve = curve.BasisCurve()
    return curve is None or isinstance(curve, exact_types)


def _reparametrize(curve: NurbsCurve, t0: float, t1: float) -> NurbsCurve:
    """The same curve with its domain mapped affinely onto ``[t0, t1]``."""
    a, b = curve.domain
    if (a, b) == (t0, t1):
        return curve
    knots = t0 + (curve.knots - a) * ((t1 - t0) / (b - a))
    return NurbsCurve(curve.control_points, knots, curve.degree, curve.weights)


def _read_pcurve(edge: TopoDS_Edge, face: TopoDS_Face, t0: float, t1: float) -> NurbsCurve:
    pcurve = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
    if pcurve is None:
        raise ConversionError("an edge of the face has no pcurve on it")
    p0, p1 = BRep_Tool.Range_s(edge, face)
    return _reparametrize(curve_from_occ(pcurve, (p0, p1)), t0, t1)


def edge_to_nurbs(edge: TopoDS_Edge) -> NurbsCurve:
    """The edge's 3D curve restricted to its range, location applied.

    The curve keeps the curve's natural direction (the edge's orientation is
    not applied). B-spline, Bezier and line edges keep their parameter exactly;
    other curves (conics...) go through GeomConvert, which keeps the shape and
    the end points but not the parametrization. Raises
    :class:`ConversionError` for a degenerated edge or an edge without 3D curve.
    """
    if BRep_Tool.Degenerated_s(edge):
        raise ConversionError("a degenerated edge has no 3D curve")
    curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)
    if curve is None:
        raise ConversionError("the edge has no 3D curve")
    return curve_from_occ(curve, BRep_Tool.Range_s(edge))


def _vertex_tolerances(edge: TopoDS_Edge) -> tuple[float, float]:
    """Tolerances of the vertices at the start and end of the edge's curve."""
    ends = (TopExp.FirstVertex_s(edge), TopExp.LastVertex_s(edge))   # not cumulating orientation
    return tuple(DEFAULT_TOLERANCE if v.IsNull() else BRep_Tool.Tolerance_s(v) for v in ends)


def read_trim_edge(edge: TopoDS_Edge, face: TopoDS_Face,
                   seam_curves: list[tuple[TopoDS_Edge, NurbsCurve]]) -> TrimEdge:
    """One occurrence of ``edge`` in a wire of ``face`` (FORWARD) as a TrimEdge.

    ``seam_curves`` caches the 3D curves of seam edges already read, so both
    occurrences of a seam share one NurbsCurve object. The pcurve is mapped
    affinely onto the 3D curve's range (exact for SameRange edges, which is
    what OpenCascade's readers produce).
    """
    tolerance = BRep_Tool.Tolerance_s(edge)
    vertex_tolerances = _vertex_tolerances(edge)
    reversed_ = edge.Orientation() == TopAbs_REVERSED
    if BRep_Tool.Degenerated_s(edge) or BRep_Tool.Curve_s(edge, 0.0, 0.0) is None:
        t0, t1 = BRep_Tool.Range_s(edge, face)
        return TrimEdge(None, _read_pcurve(edge, face, t0, t1), t0, t1, reversed_, tolerance,
                        degenerated=BRep_Tool.Degenerated_s(edge),
                        vertex_tolerances=vertex_tolerances)
    t0, t1 = BRep_Tool.Range_s(edge)
    is_seam = BRep_Tool.IsClosed_s(edge, face)
    curve3d = None
    if is_seam:
        curve3d = next((c for e, c in seam_curves if e.IsSame(edge)), None)
    if curve3d is None:
        curve3d = edge_to_nurbs(edge)
        if is_seam:
            seam_curves.append((edge, curve3d))
    pcurve = _read_pcurve(edge, face, t0, t1)
    seam_pcurve = None
    if is_seam:
        seam_pcurve = _read_pcurve(TopoDS.Edge_s(edge.Reversed()), face, t0, t1)
    return TrimEdge(curve3d, pcurve, t0, t1, reversed_, tolerance, seam_pcurve,
                    vertex_tolerances=vertex_tolerances)


# ----------------------------------------------------------------- building
def make_edge(curve3d: NurbsCurve,
              pcurves: Sequence[tuple[NurbsCurve, TopoDS_Face]] = (),
              tol: float = DEFAULT_TOLERANCE) -> TopoDS_Edge:
    """An edge on a 3D curve over its whole domain, with optional pcurves.

    Parameters
    ----------
    curve3d : NurbsCurve, d=3
    pcurves : sequence of (NurbsCurve d=2, TopoDS_Face)
        Pcurves over the same parameter range as ``curve3d``. A face given
        twice makes the edge a seam of that face: the first pcurve is the one
        of the FORWARD edge, the second of the REVERSED edge.
    tol : float
        Edge tolerance.
    """
    tol = check_tolerance(tol)
    if not isinstance(curve3d, NurbsCurve) or curve3d.dimension != 3:
        raise ConversionError("make_edge needs a 3D NurbsCurve")
    builder = BRepBuilderAPI_MakeEdge(curve_to_occ(curve3d))
    check_edge_builder(builder)
    edge = builder.Edge()
    brep = BRep_Builder()
    brep.UpdateEdge(edge, curve_to_occ(curve3d), tol)
    by_face: list[tuple[TopoDS_Face, list[NurbsCurve]]] = []
    for pcurve, face in pcurves:
        if not isinstance(pcurve, NurbsCurve) or pcurve.dimension != 2:
            raise ConversionError("pcurves must be 2D NurbsCurve objects")
        if pcurve.domain != curve3d.domain:
            raise InvalidGeometryError(
                f"pcurve domain {pcurve.domain} differs from the 3D curve's {curve3d.domain}")
        for f, curves in by_face:
            if f.IsSame(face):
                curves.append(pcurve)
                break
        else:
            by_face.append((face, [pcurve]))
    for face, curves in by_face:
        if len(curves) == 1:
            brep.UpdateEdge(edge, curve2d_to_occ(curves[0]), face, tol)
        elif len(curves) == 2:
            brep.UpdateEdge(edge, curve2d_to_occ(curves[0]), curve2d_to_occ(curves[1]), face, tol)
        else:
            raise InvalidGeometryError("an edge can carry at most two pcurves on one face")
    check_valid(edge, "edge")
    return edge


def check_edge_builder(builder: BRepBuilderAPI_MakeEdge) -> None:
    if not builder.IsDone():
        raise OpenCascadeError(f"BRepBuilderAPI_MakeEdge failed: {builder.Error().name}")


def build_trim_edge(surface: NurbsSurface, occ_surface, e: TrimEdge,
                    v_first: TopoDS_Vertex, v_last: TopoDS_Vertex, tol: float) -> TopoDS_Edge:
    brep = BRep_Builder()
    location = TopLoc_Location()
    etol = max(tol, e.tolerance, 1.001 * edge_deviation(e, surface))
    if e.degenerated:
        edge = TopoDS_Edge()
        brep.MakeEdge(edge)
        brep.UpdateEdge(edge, curve2d_to_occ(e.pcurve), occ_surface, location, etol)
        brep.Add(edge, v_first.Oriented(TopAbs_FORWARD))
        brep.Add(edge, v_last.Oriented(TopAbs_REVERSED))
        brep.Range(edge, e.t0, e.t1)
        brep.Degenerated(edge, True)
        return edge
    if e.curve3d is None:
        builder = BRepBuilderAPI_MakeEdge(curve2d_to_occ(e.pcurve), occ_surface,
                                          v_first, v_last, e.t0, e.t1)
        check_edge_builder(builder)
        edge = builder.Edge()
        if not BRepLib.BuildCurve3d_s(edge, etol):
            raise OpenCascadeError("BRepLib.BuildCurve3d could not build a 3D curve for an edge")
        return edge
    curve = curve_to_occ(e.curve3d)
    builder = BRepBuilderAPI_MakeEdge(curve, v_first, v_last, e.t0, e.t1)
    check_edge_builder(builder)
    edge = builder.Edge()
    if e.is_seam:
        first, second = (e.seam_pcurve, e.pcurve) if e.reversed else (e.pcurve, e.seam_pcurve)
        brep.UpdateEdge(edge, curve2d_to_occ(first), curve2d_to_occ(second),
                        occ_surface, location, etol)
    else:
        brep.UpdateEdge(edge, curve2d_to_occ(e.pcurve), occ_surface, location, etol)
    return edge

