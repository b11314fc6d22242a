"""OpenCascade faces built from a use-based non-manifold structure, sharing its edges.

:func:`structure_to_occ` turns the faces of a
:class:`~surfprep.algorithms.nonmanifold.NonManifoldModel` (or a selection of them)
into ``TopoDS_Face`` s whose loops are made of one ``TopoDS_Edge`` per edge of the
structure: an edge used by two, three or four faces is one edge carrying a pcurve on
each of them (:meth:`~surfprep.algorithms.nonmanifold.NonManifoldModel.edge_geometry`
puts them on one parameter), its ends the structure's vertices. Nothing is sewn:
the sharing is the structure's, and an edge's tolerance is the distance measured
between its curves (10 % over the largest of four points a knot span, at least
:data:`MIN_TOLERANCE`, and at least the tolerance its occurrences came with), a
vertex's what holds the ends of its edges' curves: not a tolerance a sewing found
large enough.

A face used twice by one edge (a seam of a closed surface) gets both its pcurves on
that edge (the first for the edge FORWARD in the face). Degenerated edges (poles)
are built per face on the vertex at their point. An edge whose uses do not share a
parametrization (measured: a use's pcurve through its surface farther than the
tolerance, and than twice the tolerance the file gave the edge, from the edge's points)
is made SameParameter by OpenCascade (``BRepLib::SameParameter``) and its tolerance is
what that measures.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_INTERNAL, TopAbs_REVERSED
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Edge, TopoDS_Face, TopoDS_Shell, TopoDS_Vertex, TopoDS_Wire

from ...algorithms.nonmanifold import NonManifoldModel
from ...algorithms.trimmed import curve3d_points
from ...errors import OpenCascadeError
from .edges import build_trim_edge, check_edge_builder
from .geom import curve2d_to_occ, curve_to_occ, surface_to_occ

__all__ = ["MIN_TOLERANCE", "StructureFaces", "structure_to_occ"]

#: the smallest tolerance given to a face, edge or vertex (OpenCascade's
#: ``Precision::Confusion``)
MIN_TOLERANCE = 1e-7


@dataclass(frozen=True)
class StructureFaces:
    """What :func:`structure_to_occ` built.

    Attributes
    ----------
    faces : tuple of TopoDS_Face
        One per face asked for, in the order asked.
    shell : TopoDS_Shell
        All of them in one shell (non-manifold where an edge has more than two uses).
    shells : tuple of TopoDS_Shell
        One shell per connected component (faces joined through the edges they share).
    valid : bool
        BRepCheck finds every face valid.
    max_tolerance : float
        The largest edge tolerance set.
    reparametrized : int
        Edges whose uses did not share a parametrization (made SameParameter by
        OpenCascade).
    """

    faces: tuple
    shell: object
    shells: tuple
    valid: bool
    max_tolerance: float
    reparametrized: int


def structure_to_occ(model: NonManifoldModel, faces: Iterable[int] | None = None, *,
                     turned: Iterable[int] = (), tol: float) -> StructureFaces:
    """``TopoDS_Face`` s of ``model.faces[faces]`` (all when None) sharing the structure's
    edges and vertices (the module doc); the faces in ``turned`` are turned over (their
    orientation reversed: ``b``'s pieces in a cut). An edge whose uses lie farther than
    ``tol`` (model units; the structure's matching tolerance) from its points is made
    SameParameter by OpenCascade at ``tol``.

    Raises
    ------
    OpenCascadeError
        A builder fails.
    """
    chosen = list(range(len(model.faces))) if faces is None else [int(f) for f in faces]
    wanted, turned = set(chosen), {int(f) for f in turned}
    builder, location = BRep_Builder(), TopLoc_Location()
    surfaces = {f: surface_to_occ(model.faces[f].surface) for f in chosen}
    occ_faces: dict[int, TopoDS_Face] = {}
    for f in chosen:
        face = TopoDS_Face()
        builder.MakeFace(face, surfaces[f], location, MIN_TOLERANCE)
        occ_faces[f] = face
    vertices: dict[int, TopoDS_Vertex] = {}
    vertex_tol: dict[int, float] = {}
    same_as = _corners(model, chosen, tol)

    def vertex(v: int, point: np.ndarray, spread: float = 0.0, edge_tol: float = MIN_TOLERANCE) -> TopoDS_Vertex:
        """The structure's vertex ``v`` (or the one a loop's corner makes it), its
        tolerance raised to hold ``point`` and the curve ends within ``spread`` of it,
        and no less than ``edge_tol``."""
        v = same_as[v]
        need = max(edge_tol, 1.001 * (float(np.linalg.norm(point - model.vertices[v])) + spread))
        if v not in vertices:
            vertices[v] = TopoDS_Vertex()
            vertex_tol[v] = max(MIN_TOLERANCE, need)
            builder.MakeVertex(vertices[v], gp_Pnt(*model.vertices[v].tolist()), vertex_tol[v])
        elif need > vertex_tol[v]:
            vertex_tol[v] = need
            builder.UpdateVertex(vertices[v], need)
        return vertices[v]

    # per (face, loop, position): the edge and how it lies in that loop
    placed: dict[tuple[int, int, int], TopoDS_Edge] = {}
    largest, reparametrized = MIN_TOLERANCE, 0
    for e in range(model.n_edges):
        if not any(u.face in wanted for u in model.uses[e]):
            continue
        g = model.edge_geometry(e, wanted)
        came_with = max(u.occurrence(model.faces).tolerance for u in g.uses)
        # uses of one parametrization: within tol, or within what the file's edge said
        # (its pcurves were that far from its curve; measured densely, a little farther)
        same = max(g.deviation) <= max(tol, 2.0 * came_with)
        edge_tol = max(MIN_TOLERANCE, 1.1 * max(g.deviation) if same else tol, came_with)
        v0 = vertex(g.start, g.ends[0], g.end_gap[0], edge_tol)
        v1 = vertex(g.end, g.ends[1], g.end_gap[1], edge_tol)
        if g.curve3d is not None:
            maker = BRepBuilderAPI_MakeEdge(curve_to_occ(g.curve3d), v0, v1, g.t0, g.t1)
        else:
            ref = g.uses[0].face
            maker = BRepBuilderAPI_MakeEdge(curve2d_to_occ(g.pcurves[0]), surfaces[ref], v0, v1, g.t0, g.t1)
        check_edge_builder(maker)
        edge = maker.Edge()
        by_face: dict[int, list[int]] = {}
        for k, use in enumerate(g.uses):
            by_face.setdefault(use.face, []).append(k)
        for f, ks in by_face.items():
            if len(ks) == 1:
                builder.UpdateEdge(edge, curve2d_to_occ(g.pcurves[ks[0]]), surfaces[f], location, edge_tol)
            elif len(ks) == 2 and g.reversed[ks[0]] != g.reversed[ks[1]]:
                forward, back = (ks[0], ks[1]) if not g.reversed[ks[0]] else (ks[1], ks[0])
                builder.UpdateEdge(edge, curve2d_to_occ(g.pcurves[forward]), curve2d_to_occ(g.pcurves[back]),
                                   surfaces[f], location, edge_tol)
            else:
                raise OpenCascadeError(f"face {f} uses edge {e} {len(ks)} times the same way round")
        if g.curve3d is None and not BRepLib.BuildCurve3d_s(edge, edge_tol):
            raise OpenCascadeError("BRepLib.BuildCurve3d could not build a 3D curve for an edge")
        if not same:
            BRepLib.SameParameter_s(edge, tol)
            reparametrized += 1
            for v in (g.start, g.end):                   # as the edge's tolerance came out
                vertex(v, model.vertices[v], 0.0, BRep_Tool.Tolerance_s(edge))
        largest = max(largest, BRep_Tool.Tolerance_s(edge))
        for k, use in enumerate(g.uses):
            orientation = (TopAbs_INTERNAL if use.loop < 0
                           else TopAbs_REVERSED if g.reversed[k] else TopAbs_FORWARD)
            placed[(use.face, use.loop, use.position)] = TopoDS.Edge_s(edge.Oriented(orientation))
    out = []
    for f in chosen:
        face, trimmed = occ_faces[f], model.faces[f]
        for li, loop in enumerate(trimmed.loops):
            wire = TopoDS_Wire()
            builder.MakeWire(wire)
            for k, e in enumerate(loop.edges):
                occ_edge = placed.get((f, li, k))
                if occ_edge is None:                     # a pole: an edge of this face only
                    occ_edge = _degenerated(model, f, e, surfaces[f], vertex, tol)
                builder.Add(wire, occ_edge)
            wire.Closed(True)
            builder.Add(face, wire)
        for k in range(len(trimmed.internal)):
            wire = TopoDS_Wire()
            builder.MakeWire(wire)
            builder.Add(wire, placed[(f, -1, k)])
            wire.Closed(False)
            builder.Add(face, wire)
        if trimmed.reversed != (f in turned):
            face = TopoDS.Face_s(face.Reversed())
        out.append(face)
    position = {f: k for k, f in enumerate(chosen)}
    shells = tuple(_shell(builder, [out[position[f]] for f in component])
                   for component in model.components(chosen))
    valid = all(BRepCheck_Analyzer(face).IsValid() for face in out)
    return StructureFaces(tuple(out), _shell(builder, out), shells, valid, largest, reparametrized)


def _shell(builder: BRep_Builder, faces: list) -> TopoDS_Shell:
    shell = TopoDS_Shell()
    builder.MakeShell(shell)
    for face in faces:
        builder.Add(shell, face)
    return shell


def _corners(model: NonManifoldModel, chosen: list[int], tol: float) -> np.ndarray:
    """``(nv,)`` int: per vertex of ``model`` the vertex it is built as. Consecutive edges
    of a loop whose ends the structure did not merge (a file's corner wider than ``tol``
    but within its own tolerances: ten times the edges' and vertices' tolerances it
    came with) meet at one vertex, the first's."""
    parent = np.arange(len(model.vertices))

    def root(v: int) -> int:
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return int(v)
    ends: dict[tuple[int, int, int], tuple[int, int]] = {}      # loop-direction start, end
    for e, uses in enumerate(model.uses):
        a, b = (int(x) for x in model.edge_vertices[e])
        for u in uses:
            ends[(u.face, u.loop, u.position)] = (b, a) if u.against else (a, b)
    for f in chosen:
        for li, loop in enumerate(model.faces[f].loops):
            present = [k for k in range(len(loop.edges)) if (f, li, k) in ends]
            for k, j in zip(present, present[1:] + present[:1]):
                v, w = root(ends[(f, li, k)][1]), root(ends[(f, li, j)][0])
                if v == w:
                    continue
                allowed = 10.0 * max(tol, *loop.edges[k].vertex_tolerances, *loop.edges[j].vertex_tolerances,
                                     loop.edges[k].tolerance, loop.edges[j].tolerance)
                if np.linalg.norm(model.vertices[v] - model.vertices[w]) <= allowed:
                    parent[w] = v
    return np.array([root(v) for v in range(len(parent))], dtype=np.int64)


def _degenerated(model: NonManifoldModel, f: int, e, occ_surface, vertex, tol: float) -> TopoDS_Edge:
    """A degenerated edge (a pole) of face ``f`` on the structure's vertex at its point
    (a new one when no edge ends there)."""
    point = curve3d_points(e, model.faces[f].surface, np.array([0.5 * (e.t0 + e.t1)]))[0]
    distance = np.linalg.norm(model.vertices - point, axis=1) if len(model.vertices) else np.array([])
    if distance.size and distance.min() <= max(tol, e.tolerance):
        v = vertex(int(np.argmin(distance)), point)
    else:
        v = TopoDS_Vertex()
        BRep_Builder().MakeVertex(v, gp_Pnt(*point.tolist()), max(MIN_TOLERANCE, e.tolerance))
    edge = build_trim_edge(model.faces[f].surface, occ_surface, e, v, v, MIN_TOLERANCE)
    return TopoDS.Edge_s(edge.Oriented(TopAbs_REVERSED if e.reversed else TopAbs_FORWARD))
