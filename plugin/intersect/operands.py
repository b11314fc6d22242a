"""The faces taking part in :func:`surfprep.intersect`.

* :class:`FaceOperand`: one face: its NURBS form, the OpenCascade face when its
  surface keeps the same parameters (to hang the result's pcurves on), and its
  :class:`~surfprep.algorithms.face_region.FaceRegion` (the point-in-face test and
  the distances to its trimming edges, built once);
* :func:`face_operands`: the faces of anything ``intersect`` accepts (NURBS
  surfaces, trimmed faces, ``Geom_Surface``, ``TopoDS_Face``/shapes, CadModel,
  cadquery/build123d objects, lists of these), numbered in order.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property
from typing import Any

from OCP.Geom import Geom_Surface
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape

from ...algorithms import NurbsSurface
from ...algorithms.face_region import FaceRegion
from ...algorithms.trimmed import TrimmedFace
from ...errors import OpenCascadeError
from ...inputs import ShapeLike
from ..convert import to_nurbs, unwrap
from ..io import CadModel, read
from ..occ.faces import make_face, needs_nurbs_convert, trimmed_face_to_occ
from ..occ.shapes import all_faces

__all__ = ["DEFAULT_TOL_FACTOR", "MIN_TOL_FACTOR", "FaceOperand", "face_operands"]

#: default ``tol`` of an intersection: this times the diagonal of the box of all faces
DEFAULT_TOL_FACTOR = 1e-6
#: smallest accepted ``tol``: this times that diagonal
MIN_TOL_FACTOR = 1e-9


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

    @cached_property
    def region(self) -> FaceRegion:
        """The face's region in ``(u, v)``: which points lie inside, distances to its
        trimming edges (built on first use)."""
        return FaceRegion(self.trimmed)

    @property
    def surface(self) -> NurbsSurface:
        return self.trimmed.surface

    @property
    def name(self) -> str | None:
        return self.trimmed.name

    def face_for_edges(self) -> TopoDS_Face:
        """A face whose surface has ``surface``'s parameters, to hang pcurves on:
        the given face, else the trimmed face rebuilt (natural bounds if that fails)."""
        return self.occ_face if self.occ_face is not None else self._rebuilt_face

    @cached_property
    def _rebuilt_face(self) -> TopoDS_Face:
        try:
            return trimmed_face_to_occ(self.trimmed) if self.trimmed.loops else \
                make_face(self.surface)
        except OpenCascadeError:
            return make_face(self.surface)


def _as_faces(x: Any) -> list[tuple[TrimmedFace, TopoDS_Face | None]]:
    if isinstance(x, (str, os.PathLike)):            # a STEP/IGES file, read as a model
        return _as_faces(read(x))
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
    shape = unwrap(x)
    if isinstance(shape, list):
        return [item for y in shape for item in _as_faces(y)]
    if isinstance(shape, (TopoDS_Face, Geom_Surface)):
        return _as_faces(shape)
    if isinstance(shape, TopoDS_Shape):
        return [item for f in all_faces(shape) for item in _as_faces(f)]
    converted = to_nurbs(x)          # raises ConversionError for what it cannot take
    return _as_faces(converted)


def face_operands(x: ShapeLike) -> list[FaceOperand]:
    """The faces of anything :func:`intersect` accepts, numbered in order."""
    return [FaceOperand(i, t, f) for i, (t, f) in enumerate(_as_faces(x))]
