"""The faces taking part in :func:`surfprep.plugin.intersect.intersect` and the
point-in-face test the clipping uses.

* :class:`FaceOperand`: one face (its NURBS form, the OpenCascade face when its
  surface keeps the same parameters), with its trimming loops prepared once
  (polygon segments, :class:`surfprep.plugin.trim_loops.LoopIndex`, a k-d tree
  of the trimming edges in space) and cached;
* :func:`face_operands`: the faces of anything ``intersect`` accepts (NURBS
  surfaces, trimmed faces, ``Geom_Surface``, ``TopoDS_Face``/shapes, CadModel,
  cadquery/build123d objects, lists of these), numbered in order;
* :func:`inside_face`: even-odd rule on the sampled loops, with a band around
  them measured in space.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.Geom import Geom_Surface
from OCP.TopoDS import TopoDS_Face

from ..algorithms import NurbsSurface
from ..errors import OpenCascadeError
from .convert import to_nurbs
from .faces import TrimmedFace, make_face, needs_nurbs_convert, trimmed_face_to_occ
from .io import CadModel
from .trim_loops import EDGE_SAMPLES, LoopIndex, SegmentTree, is_rectangle, loop_segments

__all__ = ["NEAR_BOUNDARY", "ON_BOUNDARY", "FaceOperand", "face_operands", "inside_face"]

#: a (u, v) this close to a trimming loop (relative to the domain diagonal) is inside
ON_BOUNDARY = 1e-9
#: (u, v) this close to a loop (relative to the domain diagonal) are measured in space
NEAR_BOUNDARY = 1e-2


# ------------------------------------------------------------------ operands
@dataclass(frozen=True, eq=False)
class FaceOperand:
    """One face taking part: its NURBS form and, when known, its OpenCascade face.

    Attributes
    ----------
    index : int
        Position among the faces of its operand (``a`` or ``b``).
    trimmed : TrimmedFace
    occ_face : TopoDS_Face or None
        The face as given, when its surface is exactly ``trimmed.surface`` (same
        parameters); None when it must be rebuilt (:meth:`face_for_edges`).
    """

    index: int
    trimmed: TrimmedFace
    occ_face: TopoDS_Face | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def surface(self) -> NurbsSurface:
        return self.trimmed.surface

    @property
    def name(self) -> str | None:
        return self.trimmed.name

    def face_for_edges(self) -> TopoDS_Face:
        """A face whose surface has ``surface``'s parameters, to hang pcurves on:
        the given face, else the trimmed face rebuilt (natural bounds if that fails)."""
        if self.occ_face is not None:
            return self.occ_face
        if "face" not in self._cache:
            try:
                face = trimmed_face_to_occ(self.trimmed) if self.trimmed.loops else \
                    make_face(self.surface)
            except OpenCascadeError:
                face = make_face(self.surface)
            self._cache["face"] = face
        return self._cache["face"]

    def boundary_segments(self) -> NDArray:
        """``(m, 2, 2)`` segments of the sampled trimming loops in ``(u, v)`` (cached)."""
        if "segments" not in self._cache:
            (self._cache["segments"], self._cache["segment_edges"],
             self._cache["segment_params"]) = loop_segments(self.trimmed)
        return self._cache["segments"]

    def segment_edges(self) -> tuple[NDArray, NDArray]:
        """Edge index ``(m,)`` and pcurve parameters ``(m, 2)`` of each boundary segment."""
        self.boundary_segments()
        return self._cache["segment_edges"], self._cache["segment_params"]

    def boundary_polylines(self) -> list[NDArray]:
        """Samples ``(k, 3)`` in space of every trimming edge, one polyline each (cached)."""
        if "polylines" not in self._cache:
            lines = []
            for edge in self.trimmed.edges:
                uv = edge.pcurve.evaluate(np.linspace(edge.t0, edge.t1, 2 * EDGE_SAMPLES))
                lines.append(self.surface.evaluate(uv[:, 0], uv[:, 1]))
            self._cache["polylines"] = lines
        return self._cache["polylines"]

    def edge_tolerance(self) -> float:
        return max((e.tolerance for e in self.trimmed.edges), default=0.0)

    def loop_index(self) -> LoopIndex | None:
        """The trimming loops prepared for :func:`inside_face` (cached; None: a rectangle)."""
        if "loop_index" not in self._cache:
            seg = self.boundary_segments()
            u0, u1, v0, v1 = self.surface.domain
            eps = ON_BOUNDARY * np.hypot(u1 - u0, v1 - v0)
            rect = seg.shape[0] == 0 or is_rectangle(seg, self.surface.domain, 1e3 * eps)
            self._cache["loop_index"] = None if rect else LoopIndex.build(seg)
        return self._cache["loop_index"]

    def loop_tree(self) -> SegmentTree | None:
        """Segment tree of the loop polygon in ``(u, v)`` (the loop index's own when the
        face has one, else built once; None without loops)."""
        index = self.loop_index()
        if index is not None:
            return index.uv_tree
        if "loop_tree" not in self._cache:
            seg = self.boundary_segments()
            self._cache["loop_tree"] = SegmentTree.from_segments(
                seg[:, 0], seg[:, 1] - seg[:, 0]) if seg.shape[0] else None
        return self._cache["loop_tree"]

    def edge_distance(self, points: NDArray) -> NDArray:
        """Distance ``(n,)`` of ``points (n, 3)`` to the sampled trimming edges in space
        (:meth:`boundary_polylines`; k-d tree built once per face)."""
        if "edge_tree" not in self._cache:
            lines = self.boundary_polylines()
            self._cache["edge_tree"] = SegmentTree.from_polylines(lines) if lines else None
        tree = self._cache["edge_tree"]
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        return np.full(points.shape[0], np.inf) if tree is None else tree.distance(points)


def _as_faces(x: Any) -> list[tuple[TrimmedFace, TopoDS_Face | None]]:
    if isinstance(x, NurbsSurface):
        return [(TrimmedFace(x), None)]
    if isinstance(x, TrimmedFace):
        return [(x, None)]
    if isinstance(x, Geom_Surface):
        return [(TrimmedFace(to_nurbs(x)), None)]
    if isinstance(x, CadModel):
        faces = to_nurbs(x)
        return [(t, f if not needs_nurbs_convert(f) else None) for t, f in zip(faces, x.faces)]
    if isinstance(x, TopoDS_Face):
        return [(to_nurbs(x), None if needs_nurbs_convert(x) else x)]
    if isinstance(x, (list, tuple)) and not isinstance(x, CadModel):
        return [item for y in x for item in _as_faces(y)]
    wrapped = getattr(x, "wrapped", None)
    if isinstance(wrapped, TopoDS_Face):
        return _as_faces(wrapped)
    from .convert import _unwrap, faces_of
    shape = _unwrap(x)
    if isinstance(shape, list):
        return [item for y in shape for item in _as_faces(y)]
    if isinstance(shape, (TopoDS_Face, Geom_Surface)):
        return _as_faces(shape)
    from OCP.TopoDS import TopoDS_Shape
    if isinstance(shape, TopoDS_Shape):
        return [item for f in faces_of(shape) for item in _as_faces(f)]
    converted = to_nurbs(x)          # raises ConversionError for what it cannot take
    return _as_faces(converted)


def face_operands(x: Any) -> list[FaceOperand]:
    """The faces of anything :func:`intersect` accepts, numbered in order."""
    return [FaceOperand(i, t, f) for i, (t, f) in enumerate(_as_faces(x))]


# ------------------------------------------------------------------ classification
def inside_face(operand: FaceOperand, uv: NDArray, tol: float = 0.0) -> NDArray:
    """``(n,) bool``: which ``uv (n, 2)`` lie inside the face.

    Even-odd rule on the sampled loops (rays in +u, segments bucketed by their
    v-range so each point meets only its neighbours); points within
    ``ON_BOUNDARY`` times the domain diagonal of a loop count as inside, and so
    do points whose image lies within ``tol`` plus twice the face's largest edge
    tolerance of a trimming edge in space (a curve running along a shared edge
    of two faces is on both). A face without loops, or whose loops run along
    its parameter rectangle, is the rectangle.
    """
    uv = np.asarray(uv, dtype=float).reshape(-1, 2)
    u0, u1, v0, v1 = operand.surface.domain
    eps = ON_BOUNDARY * np.hypot(u1 - u0, v1 - v0)
    in_box = ((uv[:, 0] >= u0 - eps) & (uv[:, 0] <= u1 + eps) & (uv[:, 1] >= v0 - eps)
              & (uv[:, 1] <= v1 + eps))
    index = operand.loop_index()
    if index is None:
        return in_box
    odd = index.crossings(uv) % 2 == 1
    inside = in_box & odd
    # the distance to the loops is needed only for the points outside by the ray test
    test = np.flatnonzero(in_box & ~odd)
    if test.size:
        near = index.uv_tree.distance(uv[test])
        inside[test] = near <= eps
        if tol > 0:
            # close to a loop in (u, v): measure in space against the trimming edges
            band = test[(near > eps) & (near <= NEAR_BOUNDARY * np.hypot(u1 - u0, v1 - v0))]
            if band.size:
                p = operand.surface.evaluate(uv[band, 0], uv[band, 1])
                limit = tol + 2.0 * operand.edge_tolerance()
                inside[band] = operand.edge_distance(p) <= limit
    return inside
