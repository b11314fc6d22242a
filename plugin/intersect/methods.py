"""The methods of :func:`surfprep.intersect` and its result types.

* :class:`Method`: ``"mesh"`` (triangles), ``"characteristic"`` (paper 002),
  ``"auto"`` (triangles, then the characteristic points as a certificate);
* :class:`IntersectionResult`: the returned list of curves, with the isolated
  (tangential contact) points, the coincident regions and the per-pair records;
* :func:`pair_curves`: the untrimmed curves of one face pair by a method.
"""

from __future__ import annotations

import enum
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from numpy.typing import NDArray

from ...algorithms.characteristic import (
    CharacteristicRecord,
    CoincidentRegion,
    FoundBy,
    auto_intersection,
    characteristic_intersection,
)
from ...algorithms.intersection import (
    IntersectionCurve,
    StrayCurves,
    intersect_surfaces,
)
from ...errors import InvalidGeometryError, InvalidToleranceError

if TYPE_CHECKING:
    from .operands import FaceOperand

__all__ = [
    "CoincidentFaces",
    "ContactPoint",
    "FoundBy",
    "IntersectionResult",
    "Method",
    "PairRecord",
    "pair_curves",
]


class Method(str, enum.Enum):
    """How :func:`intersect` finds the curves of a face pair."""

    MESH = "mesh"
    CHARACTERISTIC = "characteristic"
    AUTO = "auto"


@dataclass(frozen=True, eq=False)
class ContactPoint:
    """A tangential contact of two faces: an isolated point of their intersection.

    Attributes
    ----------
    point : (3,) float
    uv_a, uv_b : (2,) float
        Parameters on each face's surface.
    face_a, face_b : FaceOperand
    """

    point: NDArray
    uv_a: NDArray
    uv_b: NDArray
    face_a: FaceOperand
    face_b: FaceOperand

    @property
    def faces(self) -> tuple[int, int]:
        return self.face_a.index, self.face_b.index


@dataclass(frozen=True, eq=False)
class CoincidentFaces:
    """Two faces whose surfaces coincide within ``tol`` over ``region`` (no curves there)."""

    face_a: FaceOperand
    face_b: FaceOperand
    region: CoincidentRegion

    @property
    def faces(self) -> tuple[int, int]:
        return self.face_a.index, self.face_b.index


@dataclass(frozen=True, eq=False)
class PairRecord:
    """The characteristic record of one face pair (None with ``method="mesh"``), and
    the untrimmed curves before clipping."""

    face_a: FaceOperand
    face_b: FaceOperand
    record: CharacteristicRecord | None
    curves: tuple[IntersectionCurve, ...]
    time_s: float


class IntersectionResult(list):
    """The curves of :func:`intersect` (a ``list`` of :class:`FaceIntersection`) and more.

    Attributes
    ----------
    isolated_points : list of ContactPoint
        Tangential contact points inside both faces.
    coincident : list of CoincidentFaces
    records : list of PairRecord
        One per face pair whose boxes overlap.
    method : Method
    """

    def __init__(self, curves=(), *, isolated_points=(), coincident=(), records=(),
                 method: Method = Method.AUTO) -> None:
        super().__init__(curves)
        self.isolated_points = list(isolated_points)
        self.coincident = list(coincident)
        self.records = list(records)
        self.method = Method(method)


def _mesh_curves(fa: FaceOperand, fb: FaceOperand, tol: float, mesh_tol: float | None,
                 tangential: Sequence[IntersectionCurve] = ()) -> list[IntersectionCurve]:
    """The triangle method on a face pair, its failures as warnings."""
    try:
        return intersect_surfaces(fa.surface, fb.surface, tol=tol, mesh_tol=mesh_tol,
                                  stray=StrayCurves.DROP, tangential=tangential)
    except (InvalidGeometryError, InvalidToleranceError, ValueError, IndexError,
            FloatingPointError) as exc:
        warnings.warn(f"faces {fa.index} and {fb.index}: triangle intersection skipped: {exc}",
                      stacklevel=4)
        return []


def pair_curves(fa: FaceOperand, fb: FaceOperand, tol: float, mesh_tol: float | None,
                method: Method) -> tuple[list[IntersectionCurve], list[FoundBy],
                                         CharacteristicRecord | None]:
    """Untrimmed curves of one face pair by ``method``, how each was found, the record.

    ``"auto"`` is :func:`surfprep.algorithms.characteristic.auto_intersection`
    (prefilter, characteristic stage, the characteristic method alone where the
    surfaces cross at a small angle, else the triangle method and the
    certificate; ``record.extra["route"]`` says which), with the triangle
    method's failures turned into warnings.
    """
    if method is Method.MESH:
        curves = _mesh_curves(fa, fb, tol, mesh_tol)
        return curves, [FoundBy.MESH] * len(curves), None
    a, b = fa.surface, fb.surface
    try:
        if method is Method.CHARACTERISTIC:
            record = characteristic_intersection(a, b, tol=tol)
        else:
            record = auto_intersection(
                a, b, tol=tol, mesh_tol=mesh_tol,
                triangles=lambda tangential: _mesh_curves(fa, fb, tol, mesh_tol, tangential))
    except (InvalidGeometryError, InvalidToleranceError, FloatingPointError) as exc:
        warnings.warn(f"faces {fa.index} and {fb.index}: characteristic method skipped: {exc}",
                      stacklevel=3)
        if method is Method.CHARACTERISTIC:
            return [], [], None
        curves = _mesh_curves(fa, fb, tol, mesh_tol)
        return curves, [FoundBy.MESH] * len(curves), None
    return list(record.curves), list(record.found_by), record


