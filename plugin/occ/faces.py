"""Trimmed faces between OpenCascade topology and surfprep's NURBS types.

:func:`face_to_nurbs` reads a ``TopoDS_Face`` as a
:class:`~surfprep.algorithms.trimmed.TrimmedFace`: one
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

:func:`make_face` goes the other way (edges: :mod:`.edges`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_NurbsConvert
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.Geom import Geom_BSplineSurface, Geom_TrimmedCurve
from OCP.Geom2d import Geom2d_TrimmedCurve
from OCP.gp import gp_Pnt
from OCP.ShapeFix import ShapeFix_Face
from OCP.TopAbs import (
    TopAbs_EDGE,
    TopAbs_FORWARD,
    TopAbs_INTERNAL,
    TopAbs_REVERSED,
    TopAbs_VERTEX,
    TopAbs_WIRE,
)
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Iterator, TopoDS_Vertex, TopoDS_Wire

from ...algorithms import NurbsCurve, NurbsSurface
from ...algorithms.tolerance import check_tolerance
from ...algorithms.trimmed import DEFAULT_TOLERANCE, TrimEdge, TrimLoop, TrimmedFace, curve3d_points
from ...errors import ConversionError, InvalidGeometryError, OpenCascadeError
from .edges import EXACT_2D, EXACT_3D, build_trim_edge, converts_exactly, read_trim_edge
from .failures import describe, is_occ_failure
from .geom import surface_from_occ, surface_to_occ
from .shapes import check_valid

__all__ = [
    "checked_or_fixed",
    "face_to_nurbs",
    "make_face",
    "needs_nurbs_convert",
    "trimmed_face_to_occ",
]

#: make_face refuses a loop whose consecutive edge ends are further apart than this many
#: times ``tol``, or this many times the largest edge or vertex tolerance of the two edges.
_MAX_GAP_IN_TOLERANCES = 100.0
_MAX_GAP_IN_EDGE_TOLERANCES = 10.0


# ----------------------------------------------------------------- reading
def needs_nurbs_convert(face: TopoDS_Face) -> bool:
    """True when :func:`face_to_nurbs` converts ``face`` with
    BRepBuilderAPI_NurbsConvert (its surface is not a B-spline, or an edge curve
    is not a B-spline, Bezier or line); False when the face is read exactly."""
    if not isinstance(BRep_Tool.Surface_s(face), Geom_BSplineSurface):
        return True
    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        explorer.Next()
        if not converts_exactly(BRep_Tool.Curve_s(edge, 0.0, 0.0), EXACT_3D, Geom_TrimmedCurve):
            return True
        pcurve = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
        if not converts_exactly(pcurve, EXACT_2D, Geom2d_TrimmedCurve):
            return True
    return False


def _nurbs_convert(face: TopoDS_Face) -> TopoDS_Face:
    try:
        converter = BRepBuilderAPI_NurbsConvert(face, True)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"BRepBuilderAPI_NurbsConvert failed: {describe(exc)}") from exc
    if not converter.IsDone():
        raise OpenCascadeError("BRepBuilderAPI_NurbsConvert: IsDone() is false")
    return TopoDS.Face_s(converter.Shape())


def face_to_nurbs(face: TopoDS_Face, name: str | None = None) -> TrimmedFace:
    """Read a ``TopoDS_Face`` as a :class:`TrimmedFace` (see the module doc)."""
    if not isinstance(face, TopoDS_Face) or face.IsNull():
        raise ConversionError(f"expected a non-null TopoDS_Face, got {type(face).__name__}")
    reversed_ = face.Orientation() == TopAbs_REVERSED
    forward = TopoDS.Face_s(face.Oriented(TopAbs_FORWARD))
    if needs_nurbs_convert(forward):
        forward = TopoDS.Face_s(_nurbs_convert(forward).Oriented(TopAbs_FORWARD))
    geom_surface = BRep_Tool.Surface_s(forward)
    surface = surface_from_occ(geom_surface, BRepTools.UVBounds_s(forward))

    outer = BRepTools.OuterWire_s(forward)
    loops: list[TrimLoop] = []
    internal: list[TrimEdge] = []
    outer_index = 0
    curves3d: list[tuple[TopoDS_Edge, NurbsCurve]] = []   # seam edges, read once
    wires = TopExp_Explorer(forward, TopAbs_WIRE)
    while wires.More():
        wire = TopoDS.Wire_s(wires.Current())
        wires.Next()
        if not outer.IsNull() and wire.IsSame(outer):
            outer_index = len(loops)
        occ_edges = _wire_edges(wire, forward)
        if occ_edges and all(e.Orientation() == TopAbs_INTERNAL for e in occ_edges):
            internal.extend(read_trim_edge(e, forward, curves3d) for e in occ_edges)
            continue                              # edges inside the face, bounding nothing
        edges = [read_trim_edge(e, forward, curves3d) for e in occ_edges]
        if edges:
            loops.append(TrimLoop(tuple(edges)))
    return TrimmedFace(surface, tuple(loops), outer_index, reversed_, name, tuple(internal))


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


# ----------------------------------------------------------------- building
def make_face(surface: NurbsSurface, loops: Sequence[TrimLoop] | None = None,
              tol: float = DEFAULT_TOLERANCE, *, reversed: bool = False,
              internal: Sequence[TrimEdge] = ()) -> TopoDS_Face:
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
    internal : sequence of TrimEdge
        Edges inside the face that bound nothing (:attr:`TrimmedFace.internal`): each
        in a wire of its own, oriented INTERNAL, after the loops have been checked.

    Raises
    ------
    OpenCascadeError
        When a builder fails or the face is not valid for ``BRepCheck_Analyzer``
        even after ``ShapeFix_Face``.
    """
    tol = check_tolerance(tol)
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
        face = checked_or_fixed(face, tol)
    if internal:
        face = _with_internal_edges(face, surface, occ_surface, internal, tol)
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
    return make_face(face.surface, face.loops, tol, reversed=face.reversed, internal=face.internal)


def checked_or_fixed(face: TopoDS_Face, tol: float) -> TopoDS_Face:
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
        p = curve3d_points(e, surface, np.array([e.t0, e.t1]))
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
        # the tolerances the input gave this corner
        corner_tol = max(max(edges[k - 1].corner_tolerances()[1], edges[k].corner_tolerances()[0])
                         for k in members)
        edge_tol = max(max(edges[k - 1].tolerance, edges[k].tolerance) for k in members)
        allowed = max(_MAX_GAP_IN_TOLERANCES * tol,
                      _MAX_GAP_IN_EDGE_TOLERANCES * max(edge_tol, corner_tol))
        if gap > allowed:
            raise InvalidGeometryError(
                f"trimming loop not closed: gap {2 * gap:.3g} at the start of edge {members[0]} "
                f"(allowed {2 * allowed:.3g} from the tolerances)")
        vtol = max(tol, 1.001 * gap, corner_tol)
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
            occ_edge = build_trim_edge(surface, occ_surface, e, v_first, v_last, tol)
            if e.is_seam:
                built_seams.append((e, occ_edge))
        brep.Add(wire, occ_edge.Oriented(TopAbs_REVERSED if e.reversed else TopAbs_FORWARD))
    wire.Closed(True)
    return wire


def _with_internal_edges(face: TopoDS_Face, surface: NurbsSurface, occ_surface,
                         internal: Sequence[TrimEdge], tol: float) -> TopoDS_Face:
    """``face`` (just built, so it is changed in place) with each of ``internal`` as an
    INTERNAL edge in an open wire of its own: the edge lies in the face and bounds
    nothing (OpenCascade's convention, as its General Fuse writes it). The pcurves are
    put on the face's own surface (``checked_or_fixed`` may have given it a new one)."""
    face.Free(True)
    occ_surface = BRep_Tool.Surface_s(face)
    brep = BRep_Builder()
    existing = []                      # the loops' vertices: a spur's end on the boundary is one
    explorer = TopExp_Explorer(face, TopAbs_VERTEX)
    while explorer.More():
        v = TopoDS.Vertex_s(explorer.Current())
        p = BRep_Tool.Pnt_s(v)
        existing.append((np.array([p.X(), p.Y(), p.Z()]), BRep_Tool.Tolerance_s(v), v))
        explorer.Next()
    for e in internal:
        ends = curve3d_points(e, surface, np.array([e.t0, e.t1]))
        vertices = []
        for p in ends:
            shared = next((v for q, vt, v in existing
                           if np.linalg.norm(q - p) <= max(vt, tol, e.tolerance)), None)
            if shared is None:
                shared = TopoDS_Vertex()
                brep.MakeVertex(shared, gp_Pnt(*p.tolist()), max(tol, e.tolerance))
            vertices.append(shared)
        occ_edge = build_trim_edge(surface, occ_surface, e, vertices[0], vertices[1], tol)
        wire = TopoDS_Wire()
        brep.MakeWire(wire)
        brep.Add(wire, occ_edge.Oriented(TopAbs_INTERNAL))
        wire.Closed(False)
        brep.Add(face, wire)
    return face


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


