"""The methods of :func:`surfprep.intersect` and its result types.

* :class:`Method`: ``"mesh"`` (triangles), ``"characteristic"`` (paper 002),
  ``"auto"`` (triangles, then the characteristic points as a certificate);
* :class:`IntersectionResult`: the returned list of curves, with the isolated
  (tangential contact) points, the coincident regions, the per-pair records and
  the JSON report (:meth:`IntersectionResult.report`);
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
    """Two faces that coincide within ``tol`` over ``region`` (no curves there): the faces
    themselves, measured densely both ways (:func:`~surfprep.algorithms.characteristic.
    face_coincidence`); ``region.share`` is the larger of the two faces' coinciding shares."""

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


@dataclass(frozen=True)
class StoppedPair:
    """A face pair stopped by the caller's time limit (:class:`~surfprep.errors.TimeLimitExceeded`):
    its curves are missing from the result."""

    face_a: FaceOperand
    face_b: FaceOperand
    time_s: float

    @property
    def faces(self) -> tuple[int, int]:
        return self.face_a.index, self.face_b.index


class IntersectionResult(list):
    """What :func:`surfprep.intersect` found: a ``list`` of :class:`FaceIntersection` (the
    curves, clipped to both faces) and everything else it measured.

    Attributes
    ----------
    isolated_points : list of ContactPoint
        Tangential contact points inside both faces.
    coincident : list of CoincidentFaces
    records : list of PairRecord
        One per face pair whose boxes overlap and that ran to its end.
    stopped : list of StoppedPair
        Face pairs stopped by the caller's time limit (their curves are missing).
    method : Method
    tol : float or None
        The tolerance the curves were computed to (model units).
    time_s : float
        Wall time of the intersection.
    """

    def __init__(self, curves=(), *, isolated_points=(), coincident=(), records=(),
                 stopped=(), method: Method = Method.AUTO, tol: float | None = None,
                 time_s: float = 0.0) -> None:
        super().__init__(curves)
        self.isolated_points = list(isolated_points)
        self.coincident = list(coincident)
        self.records = list(records)
        self.stopped = list(stopped)
        self.method = Method(method)
        self.tol = tol
        self.time_s = time_s

    @property
    def geometry(self) -> list:
        """The curves (:class:`FaceIntersection`), as every verb's result has its geometry."""
        return list(self)

    def edges(self) -> list:
        """``[TopoDS_Edge]``: every curve with a pcurve on each face
        (:meth:`FaceIntersection.to_edges`)."""
        return [e for r in self for e in r.to_edges()]

    def report(self) -> dict:
        """Plain-JSON report: per curve its faces, closedness, points, length, largest
        distance from each surface, end kinds and how it was found; the method, the
        isolated points, the coincident regions and, per face pair, the
        characteristic points by kind and the times of the two stages."""
        curves = []
        for k, r in enumerate(self):
            dev = r.max_deviation()
            curves.append({
                "index": k,
                "faces": list(r.faces),
                "face_names": [r.face_a.name, r.face_b.name],
                "closed": r.closed,
                "points": int(r.points.shape[0]),
                "length": r.length,
                "max_distance_a": dev.to_a,
                "max_distance_b": dev.to_b,
                "start": r.curve.start_kind,
                "end": r.curve.end_kind,
                "found_by": r.found_by,
            })
        pairs = []
        for rec in self.records:
            entry = {"faces": [rec.face_a.index, rec.face_b.index], "time_s": rec.time_s,
                     "curves_before_clipping": len(rec.curves)}
            if rec.record is not None:
                r = rec.record
                entry.update({
                    "phi_on": r.phi_on,
                    "characteristic_points": r.counts(),
                    "characteristic_curves": len(r.characteristic_curves),
                    "found_by_characteristic": len(r.added),
                    "characteristic_time_s": r.characteristic_time_s,
                    "intersection_time_s": r.intersection_time_s,
                })
                if "skipped" in r.extra:
                    entry["certificate_skipped"] = r.extra["skipped"]
                if "route" in r.extra:
                    entry["route"] = r.extra["route"]
            pairs.append(entry)
        return {
            "n_curves": len(self),
            "curves": curves,
            "method": self.method.value,
            "isolated_points": [{"faces": list(p.faces), "point": p.point.tolist(),
                                 "uv_a": p.uv_a.tolist(), "uv_b": p.uv_b.tolist()}
                                for p in self.isolated_points],
            "coincident": [{"faces": list(c.faces), "share": c.region.share,
                            "box_a": c.region.box_a.tolist(), "box_b": c.region.box_b.tolist(),
                            "max_distance": c.region.max_distance} for c in self.coincident],
            "pairs": pairs,
            "stopped_pairs": [{"faces": list(p.faces), "time_s": p.time_s}
                              for p in self.stopped],
        }


def _mesh_curves(fa: FaceOperand, fb: FaceOperand, tol: float, mesh_tol: float | None,
                 tangential: Sequence[IntersectionCurve] = (), *, within: bool = False
                 ) -> list[IntersectionCurve]:
    """The triangle method on a face pair, its failures as warnings; ``within`` (two faces
    of one shape): surfaces that only touch along a side are not followed there."""
    try:
        return intersect_surfaces(fa.surface, fb.surface, tol=tol, mesh_tol=mesh_tol,
                                  stray=StrayCurves.DROP, tangential=tangential,
                                  touching_sides=not within)
    except (InvalidGeometryError, InvalidToleranceError, ValueError, IndexError,
            FloatingPointError) as exc:
        warnings.warn(f"faces {fa.index} and {fb.index}: triangle intersection skipped: {exc}",
                      stacklevel=4)
        return []


def pair_curves(fa: FaceOperand, fb: FaceOperand, tol: float, mesh_tol: float | None,
                method: Method, *, within: bool = False
                ) -> tuple[list[IntersectionCurve], list[FoundBy], CharacteristicRecord | None]:
    """Untrimmed curves of one face pair by ``method``, how each was found, the record.

    ``within``: the faces belong to one shape, whose curves along the faces' edges
    are dropped anyway: the triangle method does not look for surfaces touching
    along a side of their domains (``touching_sides=False``).

    ``"auto"`` is :func:`surfprep.algorithms.characteristic.auto_intersection`
    (prefilter, characteristic stage, the characteristic method alone where the
    surfaces cross at a small angle, else the triangle method and the
    certificate; ``record.extra["route"]`` says which), with the triangle
    method's failures turned into warnings.
    """
    if method is Method.MESH:
        curves = _mesh_curves(fa, fb, tol, mesh_tol, within=within)
        return curves, [FoundBy.MESH] * len(curves), None
    a, b = fa.surface, fb.surface
    try:
        if method is Method.CHARACTERISTIC:
            record = characteristic_intersection(a, b, tol=tol)
        else:
            record = auto_intersection(
                a, b, tol=tol, mesh_tol=mesh_tol,
                triangles=lambda tangential: _mesh_curves(fa, fb, tol, mesh_tol, tangential,
                                                          within=within))
    except (InvalidGeometryError, InvalidToleranceError, FloatingPointError) as exc:
        warnings.warn(f"faces {fa.index} and {fb.index}: characteristic method skipped: {exc}",
                      stacklevel=3)
        if method is Method.CHARACTERISTIC:
            return [], [], None
        curves = _mesh_curves(fa, fb, tol, mesh_tol, within=within)
        return curves, [FoundBy.MESH] * len(curves), None
    return list(record.curves), list(record.found_by), record


