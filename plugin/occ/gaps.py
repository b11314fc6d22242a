"""Gaps in the geometry of a sewn shape: where the faces sharing an edge lie apart.

Sewing joins two faces' edges when their 3D curves lie within its tolerance and then
raises the shared edge's tolerance to cover what separates the faces. Whether a model is
closed *in the geometry* is a question about the faces themselves: the points of each
face along the edge, its pcurve mapped through its surface ``S_F(pc_F(t))``. An edge
is open at ``tight`` when those points of one face lie farther than ``tight`` from the
other face's (the directed Hausdorff distance either way: closest points on the other
face's edge by Gauss-Newton steps from the nearest sample, so neither the edge's
parametrization nor the sampling's chords enter). A model's free edges in the geometry
are its free edges plus, per open shared edge, one per face: what sewing the faces
apart at ``tight`` would leave, measured on the faces rather than on the 3D curves a
file carries (which may lie off their surfaces by their tolerance).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Edge
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape
from scipy.spatial import cKDTree

__all__ = ["PROBE_SAMPLES", "SIDE_SAMPLES", "GeometricGaps", "gaps_in_geometry"]

#: samples where the faces are first compared at equal parameters (an edge whose faces
#: lie within half ``tight`` there is closed) ...
PROBE_SAMPLES = 33
#: ... and per face where the distance to the other face's points is measured otherwise
SIDE_SAMPLES = 129
#: Gauss-Newton steps from the nearest sample to the closest point, for this many of a
#: side's points farthest from the other side's polyline
_NEWTON_STEPS = 3
_REFINED = 8


@dataclass(frozen=True)
class GeometricGaps:
    """The gaps of a sewn shape (:func:`gaps_in_geometry`).

    Attributes
    ----------
    free : int
        Edges one face uses (degenerated edges not counted).
    open_edges : tuple of (TopoDS_Edge, int, float)
        Shared edges whose faces lie farther apart than ``tight``: the edge, its number
        of faces, the largest distance.
    polylines : tuple of (n, 3) float
        Points along every free edge and along each face's side of every open edge.
    owners : tuple of int
        The face of each polyline (its index among the shape's faces, ``TopExp``
        order).
    sewn : tuple of bool
        Per polyline, whether it is a face's side of an open shared edge (else a free
        edge).
    largest : float
        The largest distance over all shared edges (0 when none).
    """

    free: int
    open_edges: tuple
    polylines: tuple
    largest: float
    owners: tuple = ()
    sewn: tuple = ()

    @property
    def free_in_geometry(self) -> int:
        """Free edges plus one per face of each open shared edge."""
        return self.free + sum(n for _, n, _ in self.open_edges)


def gaps_in_geometry(shape, tight: float, *, samples: int = 9) -> GeometricGaps:
    """The free edges of ``shape`` and its shared edges open at ``tight`` (the module
    doc); ``samples`` points per polyline."""
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    face_index = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, face_index)
    free, open_, lines, owners, sewn, largest = 0, [], [], [], [], 0.0
    for k in range(1, edge_faces.Extent() + 1):
        edge = TopoDS.Edge_s(edge_faces.FindKey(k))
        if BRep_Tool.Degenerated_s(edge):
            continue
        faces = _distinct(edge_faces.FindFromIndex(k))
        if len(faces) == 1:
            if not BRep_Tool.IsClosed_s(edge, faces[0]):
                free += 1
                lines.append(_Side(edge, faces[0]).points(np.linspace(0, 1, samples)))
                owners.append(face_index.FindIndex(faces[0]) - 1)
                sewn.append(False)
            continue
        gap = _gap(edge, faces, tight)
        largest = max(largest, gap)
        if gap > tight:
            open_.append((edge, len(faces), gap))
            lines.extend(_Side(edge, f).points(np.linspace(0, 1, samples)) for f in faces)
            owners.extend(face_index.FindIndex(f) - 1 for f in faces)
            sewn.extend(True for _ in faces)
    return GeometricGaps(free, tuple(open_), tuple(lines), largest, tuple(owners),
                         tuple(sewn))


def _distinct(faces) -> list:
    out = []
    for f in faces:
        if not any(f.IsSame(g) for g in out):
            out.append(TopoDS.Face_s(f))
    return out


class _Side:
    """One face's points along an edge, ``S_F(pc_F(t))``, at ``s`` in [0, 1] of the
    pcurve's range."""

    def __init__(self, edge: TopoDS_Edge, face) -> None:
        self.curve = BRepAdaptor_Curve2d(edge, face)
        self.surface = BRepAdaptor_Surface(face)
        self.t0, self.t1 = self.curve.FirstParameter(), self.curve.LastParameter()

    def points(self, s: NDArray) -> NDArray:
        t = self.t0 + s * (self.t1 - self.t0)
        return np.array([self.surface.Value(*self.curve.Value(x).Coord()).Coord() for x in t])

    def point_and_tangent(self, t: float) -> tuple[NDArray, NDArray]:
        p2, v2 = gp_Pnt2d(), gp_Vec2d()
        self.curve.D1(t, p2, v2)
        p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        self.surface.D1(p2.X(), p2.Y(), p, du, dv)
        tangent = np.array(du.Coord()) * v2.X() + np.array(dv.Coord()) * v2.Y()
        return np.array(p.Coord()), tangent

    def distance(self, q: NDArray, s0: float) -> float:
        """Distance from ``q`` to this side, from the sample at ``s0`` by Gauss-Newton
        steps on ``|C(t) - q|`` (kept within the range)."""
        t = self.t0 + s0 * (self.t1 - self.t0)
        lo, hi = min(self.t0, self.t1), max(self.t0, self.t1)
        best = np.inf
        for _ in range(_NEWTON_STEPS + 1):
            p, tangent = self.point_and_tangent(t)
            best = min(best, float(np.linalg.norm(p - q)))
            norm2 = float(tangent @ tangent)
            if norm2 <= 0.0:
                break
            t = float(np.clip(t - (p - q) @ tangent / norm2, lo, hi))
        return best


def _gap(edge: TopoDS_Edge, faces: list, tight: float) -> float:
    """Largest distance from a face's points along ``edge`` to another face's (the module
    doc); the equal-parameter distance when that is within half ``tight``."""
    sides = [_Side(edge, f) for f in faces]
    probe = np.linspace(0.0, 1.0, PROBE_SAMPLES)
    points = [side.points(probe) for side in sides]
    same = max(float(np.max(np.linalg.norm(a - b, axis=1)))
               for i, a in enumerate(points) for b in points[i + 1:])
    if same <= 0.5 * tight:
        return same
    s = np.linspace(0.0, 1.0, SIDE_SAMPLES)
    dense = [side.points(s) for side in sides]
    worst = 0.0
    for i, pts in enumerate(dense):
        for j, other in enumerate(sides):
            if i == j:
                continue
            # the distance to the other side's polyline (above the true one by at most a
            # chord's sagitta) ranks the points; the farthest are measured exactly
            near, nearest = _to_polyline(pts, dense[j])
            for n in np.argsort(near)[::-1][:_REFINED]:
                worst = max(worst, other.distance(pts[n], s[nearest[n]]))
    return worst


def _to_polyline(points: NDArray, line: NDArray) -> tuple[NDArray, NDArray]:
    """Distance from each of ``points`` (m, 3) to the polyline ``line`` (n, 3) and the
    index of its nearest vertex."""
    nearest = cKDTree(line).query(points)[1]
    best = np.linalg.norm(points - line[nearest], axis=1)
    for shift in (-1, 0):                 # the segments before and after the vertex
        a = np.clip(nearest + shift, 0, len(line) - 2)
        d = line[a + 1] - line[a]
        t = np.clip(np.einsum("ij,ij->i", points - line[a], d)
                    / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - line[a] - t[:, None] * d, axis=1))
    return best, nearest
