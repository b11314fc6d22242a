"""Faces and edges between OpenCascade topology and surfprep's NURBS types.

:func:`face_to_nurbs` reads a ``TopoDS_Face`` as a :class:`TrimmedFace`: one
:class:`~surfprep.algorithms.NurbsSurface` (the face's location applied) and its
trimming loops, every edge with its 3D curve and its pcurve (2D curve in the
surface's parameters), both restricted to the edge's range.

Analytic faces (planes, cylinders, cones, spheres, tori, revolutions,
extrusions, offsets) are converted by OpenCascade's
``BRepBuilderAPI_NurbsConvert`` on the whole face rather than surface by surface:
the rational B-spline form of a circle does not use the angle as parameter, so
converting the surface alone (``GeomConvert``) moves its parametrization by
up to ~4 % of the radius while the face's pcurves stay in the old parameters.
``BRepBuilderAPI_NurbsConvert`` converts surface, pcurves and 3D curves
consistently (measured: pcurve mapped through the surface equals the 3D curve
to ~1e-15 on cadquery's analytic solids). Faces already made of B-spline
surfaces and of B-spline / Bezier / line curves are read exactly, without it.

:func:`make_face` and :func:`make_edge` go the other way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import (BRepBuilderAPI_EdgeDone, BRepBuilderAPI_MakeEdge,
                                BRepBuilderAPI_MakeFace, BRepBuilderAPI_NurbsConvert)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.Geom import (Geom_BezierCurve, Geom_BSplineCurve, Geom_BSplineSurface, Geom_Line,
                      Geom_TrimmedCurve)
from OCP.Geom2d import Geom2d_BezierCurve, Geom2d_BSplineCurve, Geom2d_Line, Geom2d_TrimmedCurve
from OCP.gp import gp_Pnt
from OCP.ShapeFix import ShapeFix_Face
from OCP.Standard import Standard_Failure
from OCP.TopAbs import (TopAbs_EDGE, TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_VERTEX,
                        TopAbs_WIRE)
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Iterator, TopoDS_Vertex, TopoDS_Wire

from ..algorithms import NurbsCurve, NurbsSurface
from ..errors import ConversionError, InvalidGeometryError, InvalidToleranceError, OpenCascadeError
from .geom import curve2d_to_occ, curve_from_occ, curve_to_occ, surface_from_occ, surface_to_occ

__all__ = [
    "TrimEdge",
    "TrimLoop",
    "TrimmedFace",
    "face_to_nurbs",
    "edge_to_nurbs",
    "make_face",
    "make_edge",
    "check_valid",
]

#: Default tolerance of built edges, vertices and faces (OpenCascade's Precision::Confusion).
DEFAULT_TOLERANCE = 1e-7
#: make_face refuses a loop whose consecutive edge ends are further apart than this many
#: times ``tol``, or this many times the largest edge or vertex tolerance of the two edges.
_MAX_GAP_IN_TOLERANCES = 100.0
_MAX_GAP_IN_EDGE_TOLERANCES = 10.0


# ------------------------------------------------------------------ data types
@dataclass(frozen=True, eq=False)
class TrimEdge:
    """One edge of a trimming loop, as it is used in the loop.

    Attributes
    ----------
    curve3d : NurbsCurve (d=3) or None
        The edge's 3D curve restricted to ``[t0, t1]``; ``None`` for a
        degenerated edge (a surface pole) or when only the pcurve is known.
    pcurve : NurbsCurve (d=2)
        The edge's curve in the surface's ``(u, v)`` parameters, over the same
        range ``[t0, t1]`` (same parameter as ``curve3d``): for this
        occurrence of the edge (on a seam, the pcurve of this side).
    t0, t1 : float
        Edge range, in the natural direction of the curves.
    reversed : bool
        True when the loop runs along the edge from ``t1`` to ``t0``.
    tolerance : float
        OpenCascade's edge tolerance (max. distance between the 3D curve and
        the pcurve mapped through the surface).
    vertex_tolerance : float
        The larger tolerance of the edge's two vertices (how far the curve
        ends may be from the loop's corners).
    seam_pcurve : NurbsCurve (d=2) or None
        For a seam edge (one edge used twice on a closed surface) the pcurve
        of the other side; ``None`` otherwise.
    degenerated : bool
        True for an edge collapsed to a point in 3D.
    """

    curve3d: NurbsCurve | None
    pcurve: NurbsCurve
    t0: float
    t1: float
    reversed: bool = False
    tolerance: float = DEFAULT_TOLERANCE
    seam_pcurve: NurbsCurve | None = None
    degenerated: bool = False
    vertex_tolerance: float = DEFAULT_TOLERANCE

    def __post_init__(self) -> None:
        if self.pcurve.dimension != 2:
            raise InvalidGeometryError(f"pcurve must be 2D, got dimension {self.pcurve.dimension}")
        if self.curve3d is not None and self.curve3d.dimension != 3:
            raise InvalidGeometryError(f"curve3d must be 3D, got dimension {self.curve3d.dimension}")
        if self.seam_pcurve is not None and self.seam_pcurve.dimension != 2:
            raise InvalidGeometryError("seam_pcurve must be 2D")
        if not self.t0 < self.t1:
            raise InvalidGeometryError(f"empty edge range [{self.t0}, {self.t1}]")
        object.__setattr__(self, "t0", float(self.t0))
        object.__setattr__(self, "t1", float(self.t1))

    @property
    def is_seam(self) -> bool:
        return self.seam_pcurve is not None

    def __repr__(self) -> str:
        kind = "degenerated" if self.degenerated else ("seam" if self.is_seam else "edge")
        return (f"TrimEdge({kind}, range=({self.t0:g}, {self.t1:g}), reversed={self.reversed}, "
                f"tolerance={self.tolerance:g})")

    def uv_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """Start and end of this occurrence in ``(u, v)``, in loop direction."""
        a, b = self.pcurve.evaluate(np.array([self.t0, self.t1]))
        return (b, a) if self.reversed else (a, b)


@dataclass(frozen=True, eq=False)
class TrimLoop:
    """A closed loop of edges (an OpenCascade wire), in loop order."""

    edges: tuple[TrimEdge, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "edges", tuple(self.edges))
        if not self.edges:
            raise InvalidGeometryError("a trimming loop needs at least one edge")

    def __repr__(self) -> str:
        return f"TrimLoop({len(self.edges)} edges)"


@dataclass(frozen=True, eq=False)
class TrimmedFace:
    """A trimmed face in NURBS terms.

    Attributes
    ----------
    surface : NurbsSurface
        The face's surface, its location applied.
    loops : tuple of TrimLoop
        Every wire of the face, in the orientation it has in the face seen as
        FORWARD (outer loop counter-clockwise in ``(u, v)``, holes clockwise).
    outer_loop_index : int
        Index of the outer loop in ``loops`` (0 when there is no loop).
    reversed : bool
        The face's orientation: True when its normal is opposite to
        ``S_u x S_v``.
    name : str or None
    """

    surface: NurbsSurface
    loops: tuple[TrimLoop, ...] = ()
    outer_loop_index: int = 0
    reversed: bool = False
    name: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "loops", tuple(self.loops))
        if self.loops and not 0 <= self.outer_loop_index < len(self.loops):
            raise InvalidGeometryError(
                f"outer_loop_index {self.outer_loop_index} out of range for {len(self.loops)} loops")

    def __repr__(self) -> str:
        return (f"TrimmedFace({self.surface!r}, loops={[len(lp.edges) for lp in self.loops]}, "
                f"outer_loop_index={self.outer_loop_index}, reversed={self.reversed}, "
                f"name={self.name!r})")

    @property
    def edges(self) -> tuple[TrimEdge, ...]:
        """All edge occurrences of all loops."""
        return tuple(e for loop in self.loops for e in loop.edges)


# ----------------------------------------------------------------- reading
_EXACT_3D = (Geom_BSplineCurve, Geom_BezierCurve, Geom_Line)
_EXACT_2D = (Geom2d_BSplineCurve, Geom2d_BezierCurve, Geom2d_Line)


def _converts_exactly(curve, exact_types, trimmed_type) -> bool:
    """True when ``curve_from_occ`` keeps the curve's parametrization."""
    while isinstance(curve, trimmed_type):
        curve = curve.BasisCurve()
    return curve is None or isinstance(curve, exact_types)


def _needs_nurbs_convert(face: TopoDS_Face) -> bool:
    if not isinstance(BRep_Tool.Surface_s(face), Geom_BSplineSurface):
        return True
    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        explorer.Next()
        if not _converts_exactly(BRep_Tool.Curve_s(edge, 0.0, 0.0), _EXACT_3D, Geom_TrimmedCurve):
            return True
        pcurve = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
        if not _converts_exactly(pcurve, _EXACT_2D, Geom2d_TrimmedCurve):
            return True
    return False


def _nurbs_convert(face: TopoDS_Face) -> TopoDS_Face:
    try:
        converter = BRepBuilderAPI_NurbsConvert(face, True)
    except Standard_Failure as exc:
        raise OpenCascadeError(f"BRepBuilderAPI_NurbsConvert failed: {exc}") from exc
    if not converter.IsDone():
        raise OpenCascadeError("BRepBuilderAPI_NurbsConvert: IsDone() is false")
    return TopoDS.Face_s(converter.Shape())


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
    not applied). Raises :class:`ConversionError` for a degenerated edge or an
    edge without 3D curve.
    """
    if BRep_Tool.Degenerated_s(edge):
        raise ConversionError("a degenerated edge has no 3D curve")
    curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)
    if curve is None:
        raise ConversionError("the edge has no 3D curve")
    return curve_from_occ(curve, BRep_Tool.Range_s(edge))


def face_to_nurbs(face: TopoDS_Face, name: str | None = None) -> TrimmedFace:
    """Read a ``TopoDS_Face`` as a :class:`TrimmedFace` (see the module doc)."""
    if not isinstance(face, TopoDS_Face) or face.IsNull():
        raise ConversionError(f"expected a non-null TopoDS_Face, got {type(face).__name__}")
    reversed_ = face.Orientation() == TopAbs_REVERSED
    forward = TopoDS.Face_s(face.Oriented(TopAbs_FORWARD))
    if _needs_nurbs_convert(forward):
        forward = TopoDS.Face_s(_nurbs_convert(forward).Oriented(TopAbs_FORWARD))
    geom_surface = BRep_Tool.Surface_s(forward)
    surface = surface_from_occ(geom_surface, BRepTools.UVBounds_s(forward))

    outer = BRepTools.OuterWire_s(forward)
    loops: list[TrimLoop] = []
    outer_index = 0
    curves3d: list[tuple[TopoDS_Edge, NurbsCurve]] = []   # seam edges, read once
    wires = TopExp_Explorer(forward, TopAbs_WIRE)
    while wires.More():
        wire = TopoDS.Wire_s(wires.Current())
        wires.Next()
        if not outer.IsNull() and wire.IsSame(outer):
            outer_index = len(loops)
        edges = [_read_edge(e, forward, curves3d) for e in _wire_edges(wire, forward)]
        if edges:
            loops.append(TrimLoop(tuple(edges)))
    return TrimmedFace(surface, tuple(loops), outer_index, reversed_, name)


def _wire_edges(wire: TopoDS_Wire, face: TopoDS_Face) -> list[TopoDS_Edge]:
    """The wire's edges in connection order (BRepTools_WireExplorer), or in
    stored order when the explorer cannot walk the whole wire (non-manifold wires)."""
    stored = []
    it = TopoDS_Iterator(wire)
    while it.More():
        if it.Value().ShapeType() == TopAbs_EDGE:
            stored.append(TopoDS.Edge_s(it.Value()))
        it.Next()
    ordered = []
    explorer = BRepTools_WireExplorer(wire, face)
    while explorer.More():
        ordered.append(TopoDS.Edge_s(explorer.Current()))
        explorer.Next()
    if len(ordered) == len(stored):
        return ordered
    # TopoDS_Iterator does not compose the wire's orientation; do it here.
    if wire.Orientation() == TopAbs_REVERSED:
        stored = [TopoDS.Edge_s(e.Reversed()) for e in reversed(stored)]
    return stored


def _vertex_tolerance(edge: TopoDS_Edge) -> float:
    tolerances = [DEFAULT_TOLERANCE]
    explorer = TopExp_Explorer(edge, TopAbs_VERTEX)
    while explorer.More():
        tolerances.append(BRep_Tool.Tolerance_s(TopoDS.Vertex_s(explorer.Current())))
        explorer.Next()
    return max(tolerances)


def _read_edge(edge: TopoDS_Edge, face: TopoDS_Face,
               seam_curves: list[tuple[TopoDS_Edge, NurbsCurve]]) -> TrimEdge:
    tolerance = BRep_Tool.Tolerance_s(edge)
    vertex_tolerance = _vertex_tolerance(edge)
    reversed_ = edge.Orientation() == TopAbs_REVERSED
    if BRep_Tool.Degenerated_s(edge) or BRep_Tool.Curve_s(edge, 0.0, 0.0) is None:
        t0, t1 = BRep_Tool.Range_s(edge, face)
        return TrimEdge(None, _read_pcurve(edge, face, t0, t1), t0, t1, reversed_, tolerance,
                        degenerated=BRep_Tool.Degenerated_s(edge),
                        vertex_tolerance=vertex_tolerance)
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
                    vertex_tolerance=vertex_tolerance)


# ----------------------------------------------------------------- building
def check_valid(shape, what: str = "shape") -> None:
    """Raise :class:`OpenCascadeError` unless ``BRepCheck_Analyzer`` finds ``shape`` valid."""
    if not BRepCheck_Analyzer(shape).IsValid():
        raise OpenCascadeError(f"the {what} built is not valid (BRepCheck_Analyzer)")


def _check_tolerance(tol: float) -> float:
    tol = float(tol)
    if not np.isfinite(tol) or tol <= 0:
        raise InvalidToleranceError(f"tolerance must be a finite number > 0, got {tol}")
    return tol


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
    tol = _check_tolerance(tol)
    if not isinstance(curve3d, NurbsCurve) or curve3d.dimension != 3:
        raise ConversionError("make_edge needs a 3D NurbsCurve")
    builder = BRepBuilderAPI_MakeEdge(curve_to_occ(curve3d))
    _check_edge_builder(builder)
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


def _check_edge_builder(builder: BRepBuilderAPI_MakeEdge) -> None:
    if not builder.IsDone():
        raise OpenCascadeError(f"BRepBuilderAPI_MakeEdge failed: {builder.Error().name}")


def make_face(surface: NurbsSurface, loops: Sequence[TrimLoop] | None = None,
              tol: float = DEFAULT_TOLERANCE, *, reversed: bool = False) -> TopoDS_Face:
    """A ``TopoDS_Face`` on ``surface``.

    Parameters
    ----------
    surface : NurbsSurface
    loops : sequence of TrimLoop, optional
        Trimming loops as in :class:`TrimmedFace` (outer loop counter-clockwise
        in ``(u, v)``, holes clockwise). Without loops the face covers the
        whole parameter rectangle.
    tol : float
        Minimum tolerance of edges and vertices. Edge tolerances are raised to
        the measured distance between the 3D curve and the pcurve mapped
        through the surface, vertex tolerances to the gap between the ends of
        the edges they join.
    reversed : bool
        Orientation of the face (see :attr:`TrimmedFace.reversed`).

    Raises
    ------
    OpenCascadeError
        When a builder fails or the face is not valid for ``BRepCheck_Analyzer``
        even after ``ShapeFix_Face``.
    """
    tol = _check_tolerance(tol)
    if not isinstance(surface, NurbsSurface):
        raise ConversionError(f"make_face needs a NurbsSurface, got {type(surface).__name__}")
    for loop in loops or ():
        for k, edge in enumerate(loop.edges):
            _check_pcurve_in_domain(surface, edge, k)
    occ_surface = surface_to_occ(surface)
    if not loops:
        builder = BRepBuilderAPI_MakeFace(occ_surface, tol)
        if not builder.IsDone():
            raise OpenCascadeError(f"BRepBuilderAPI_MakeFace failed: {builder.Error().name}")
        face = builder.Face()
    else:
        face = TopoDS_Face()
        brep = BRep_Builder()
        brep.MakeFace(face, occ_surface, TopLoc_Location(), tol)
        corners: list[tuple[np.ndarray, float, TopoDS_Vertex]] = []
        for loop in loops:
            brep.Add(face, _make_wire(surface, occ_surface, loop, tol, corners))
        face = _checked_or_fixed(face, tol)
    if reversed:
        face = TopoDS.Face_s(face.Reversed())
    check_valid(face, "face")
    return face


#: How far (relative to the domain's size) a pcurve may leave the surface's domain.
#: Real files do overshoot a little (up to 0.3 % in occt_b1_euclid and
#: pyiges_impeller_solidworks, faces valid for BRepCheck); this only catches gross errors.
_DOMAIN_SLACK = 0.05


def _check_pcurve_in_domain(surface: NurbsSurface, edge: TrimEdge, index: int) -> None:
    """Refuse pcurves that leave the parameter rectangle: OpenCascade would
    extrapolate the surface there and BRepCheck does not notice."""
    u0, u1, v0, v1 = surface.domain
    slack_u, slack_v = _DOMAIN_SLACK * (u1 - u0), _DOMAIN_SLACK * (v1 - v0)
    t = np.linspace(edge.t0, edge.t1, 33)
    for pcurve in (edge.pcurve, edge.seam_pcurve):
        if pcurve is None:
            continue
        uv = pcurve.evaluate(t)
        if (uv[:, 0].min() < u0 - slack_u or uv[:, 0].max() > u1 + slack_u
                or uv[:, 1].min() < v0 - slack_v or uv[:, 1].max() > v1 + slack_v):
            raise InvalidGeometryError(
                f"the pcurve of edge {index} leaves the surface's domain "
                f"[{u0:g}, {u1:g}] x [{v0:g}, {v1:g}]: u in [{uv[:, 0].min():g}, "
                f"{uv[:, 0].max():g}], v in [{uv[:, 1].min():g}, {uv[:, 1].max():g}]")


def trimmed_face_to_occ(face: TrimmedFace, tol: float = DEFAULT_TOLERANCE) -> TopoDS_Face:
    """:func:`make_face` on a :class:`TrimmedFace`."""
    return make_face(face.surface, face.loops, tol, reversed=face.reversed)


def _checked_or_fixed(face: TopoDS_Face, tol: float) -> TopoDS_Face:
    """Return ``face`` if valid; else what ShapeFix_Face makes of it."""
    if BRepCheck_Analyzer(face).IsValid():
        return face
    BRepLib.SameParameter_s(face, tol, True)
    if BRepCheck_Analyzer(face).IsValid():
        return face
    fixer = ShapeFix_Face(face)
    fixer.SetPrecision(tol)
    fixer.Perform()
    return TopoDS.Face_s(fixer.Face())


def _curve3d_points(edge: TrimEdge, surface: NurbsSurface, t: np.ndarray) -> np.ndarray:
    if edge.curve3d is not None:
        return edge.curve3d.evaluate(t)
    uv = edge.pcurve.evaluate(t)
    return surface.evaluate(uv[:, 0], uv[:, 1])


def _edge_deviation(edge: TrimEdge, surface: NurbsSurface, samples: int = 33) -> float:
    """Max distance between the 3D curve and the pcurve(s) mapped through the surface."""
    if edge.curve3d is None:
        return 0.0
    t = np.linspace(edge.t0, edge.t1, samples)
    c = edge.curve3d.evaluate(t)
    dev = 0.0
    for pc in (edge.pcurve, edge.seam_pcurve):
        if pc is not None:
            uv = pc.evaluate(t)
            dev = max(dev, float(np.max(np.linalg.norm(surface.evaluate(uv[:, 0], uv[:, 1]) - c, axis=1))))
    return dev


def _make_wire(surface: NurbsSurface, occ_surface, loop: TrimLoop, tol: float,
               corners: list[tuple[np.ndarray, float, TopoDS_Vertex]]) -> TopoDS_Wire:
    """A wire for ``loop``; ``corners`` holds the vertices of the face's loops built
    so far and is extended: loops touching at a corner share its vertex, as
    BRepCheck requires (else the wires count as intersecting)."""
    brep = BRep_Builder()
    edges = loop.edges
    n = len(edges)
    # Vertex k joins the end of edge k-1 to the start of edge k (loop direction).
    ends = []
    for e in edges:
        p = _curve3d_points(e, surface, np.array([e.t0, e.t1]))
        uv = e.pcurve.evaluate(np.array([e.t0, e.t1]))
        s = surface.evaluate(uv[:, 0], uv[:, 1])
        start, end = (1, 0) if e.reversed else (0, 1)
        ends.append(((p[start], s[start]), (p[end], s[end])))
    # An edge closed in 3D (a full circle, a pole) starts and ends at one vertex.
    group = list(range(n))
    for k, e in enumerate(edges):
        (p_start, _), (p_end, _) = ends[k]
        if e.degenerated or np.linalg.norm(p_end - p_start) <= max(tol, e.tolerance):
            a, b = group[k], group[(k + 1) % n]
            group = [a if g == b else g for g in group]
    by_group: dict[int, TopoDS_Vertex] = {}
    for g in sorted(set(group)):
        pts = np.array([q for k in range(n) if group[k] == g
                        for q in (*ends[k - 1][1], *ends[k][0])])
        centre = pts.mean(axis=0)
        gap = float(np.max(np.linalg.norm(pts - centre, axis=1)))
        members = [k for k in range(n) if group[k] == g]
        allowed = max(_MAX_GAP_IN_TOLERANCES * tol,
                      _MAX_GAP_IN_EDGE_TOLERANCES * max(
                          max(edges[k - 1].tolerance, edges[k].tolerance,
                              edges[k - 1].vertex_tolerance, edges[k].vertex_tolerance)
                          for k in members))
        if gap > allowed:
            raise InvalidGeometryError(
                f"trimming loop not closed: gap {2 * gap:.3g} at the start of edge {members[0]} "
                f"(allowed {2 * allowed:.3g} from the tolerances)")
        vtol = max(tol, 1.001 * gap)
        vertex = TopoDS_Vertex()
        shared = next((c for c in corners if np.linalg.norm(c[0] - centre) <= max(c[1], vtol)), None)
        if shared is None:
            brep.MakeVertex(vertex, gp_Pnt(*centre.tolist()), vtol)
            corners.append((centre, vtol, vertex))
        else:
            vertex = shared[2]
            brep.UpdateVertex(vertex, max(shared[1], vtol + float(np.linalg.norm(shared[0] - centre))))
        by_group[g] = vertex
    vertices = [by_group[g] for g in group]

    wire = TopoDS_Wire()
    brep.MakeWire(wire)
    built_seams: list[tuple[TrimEdge, TopoDS_Edge]] = []
    for k, e in enumerate(edges):
        v_start, v_end = vertices[k], vertices[(k + 1) % n]
        v_first, v_last = (v_end, v_start) if e.reversed else (v_start, v_end)
        occ_edge = None
        if e.is_seam:
            occ_edge = next((b for a, b in built_seams if _same_seam(a, e)), None)
        if occ_edge is None:
            occ_edge = _make_loop_edge(surface, occ_surface, e, v_first, v_last, tol)
            if e.is_seam:
                built_seams.append((e, occ_edge))
        brep.Add(wire, occ_edge.Oriented(TopAbs_REVERSED if e.reversed else TopAbs_FORWARD))
    wire.Closed(True)
    return wire


def _same_seam(a: TrimEdge, b: TrimEdge) -> bool:
    """True when ``b`` is the other occurrence of the seam edge ``a``."""
    if a.reversed == b.reversed or (a.t0, a.t1) != (b.t0, b.t1):
        return False
    if a.curve3d is not None and a.curve3d is b.curve3d:
        return True
    if a.curve3d is None or b.curve3d is None:
        return False
    return (np.array_equal(a.curve3d.knots, b.curve3d.knots)
            and np.array_equal(a.curve3d.control_points, b.curve3d.control_points))


def _make_loop_edge(surface: NurbsSurface, occ_surface, e: TrimEdge,
                    v_first: TopoDS_Vertex, v_last: TopoDS_Vertex, tol: float) -> TopoDS_Edge:
    brep = BRep_Builder()
    location = TopLoc_Location()
    etol = max(tol, e.tolerance, 1.001 * _edge_deviation(e, surface))
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
        _check_edge_builder(builder)
        edge = builder.Edge()
        if not BRepLib.BuildCurve3d_s(edge, etol):
            raise OpenCascadeError("BRepLib.BuildCurve3d could not build a 3D curve for an edge")
        return edge
    curve = curve_to_occ(e.curve3d)
    builder = BRepBuilderAPI_MakeEdge(curve, v_first, v_last, e.t0, e.t1)
    _check_edge_builder(builder)
    edge = builder.Edge()
    if e.is_seam:
        first, second = (e.seam_pcurve, e.pcurve) if e.reversed else (e.pcurve, e.seam_pcurve)
        brep.UpdateEdge(edge, curve2d_to_occ(first), curve2d_to_occ(second),
                        occ_surface, location, etol)
    else:
        brep.UpdateEdge(edge, curve2d_to_occ(e.pcurve), occ_surface, location, etol)
    return edge
