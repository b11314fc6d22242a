"""Cuts: curves to cut a trimmed face along (:func:`.face_split.split_face`), and which of
them divide it.

A :class:`Cut` is a curve in a face's ``(u, v)`` with its 3D curve when known. Before a
face is cut, the cuts that divide nothing are left out: a cut running along the face's
boundary (two faces of one model meeting another along their shared edge, two solids
touching) and a cut repeating another (the same curve reported twice); and a cut
ending a tolerance away from a corner of the face's loop is moved onto the corner, so
no sliver of the edge is left.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .face_region import FaceRegion
from .trimmed import TrimEdge, TrimLoop, TrimmedFace, curve3d_points

__all__ = ["CUT_SAMPLES", "Cut", "cut_point_at", "distinct_cuts", "runs_along_boundary",
           "snap_to_corner"]

#: samples of a cut's pcurve for the topology (crossings, containment)
CUT_SAMPLES = 257


@dataclass(frozen=True, eq=False)
class Cut:
    """A curve to cut a face along.

    Attributes
    ----------
    pcurve : NurbsCurve (2D)
        The curve in the face's ``(u, v)``, over its whole domain.
    curve3d : NurbsCurve (3D) or None
        The same curve in space, on the same parameter.
    """

    pcurve: NurbsCurve
    curve3d: NurbsCurve | None = None

    def __post_init__(self) -> None:
        if self.pcurve.dimension != 2:
            raise InvalidGeometryError(f"a cut's pcurve must be 2D, got dimension {self.pcurve.dimension}")
        if self.curve3d is not None and self.curve3d.dimension != 3:
            raise InvalidGeometryError("a cut's 3D curve must be 3D")

    @property
    def range(self) -> tuple[float, float]:
        return self.pcurve.domain

    def samples(self) -> NDArray:
        t0, t1 = self.range
        return self.pcurve.evaluate(np.linspace(t0, t1, CUT_SAMPLES))


def cut_point_at(cut: Cut, face: TrimmedFace, t: float) -> NDArray:
    """The cut's point in space at its parameter ``t``."""
    if cut.curve3d is not None:
        return cut.curve3d.evaluate(np.array([t]))[0]
    uv = cut.pcurve.evaluate(np.array([t]))
    return face.surface.evaluate(uv[:, 0], uv[:, 1])[0]


def snap_to_corner(edge: TrimEdge, surface, t: float, eps: float, tol3d: float | None) -> float:
    """``t`` moved to the edge's end when its point lies that close to it (within ``tol3d``
    in space, else ``eps`` in the parameters): a cut ending at a corner of the loop,
    found a tolerance away from it, would leave a sliver of the edge."""
    ends = np.array([edge.t0, edge.t1])
    if tol3d is not None:
        pts = curve3d_points(edge, surface, np.array([t, edge.t0, edge.t1]))
        near, limit = np.linalg.norm(pts[1:] - pts[0], axis=1), tol3d
    else:
        uv = edge.pcurve.evaluate(np.array([t, edge.t0, edge.t1]))
        near, limit = np.linalg.norm(uv[1:] - uv[0], axis=1), eps
    k = int(np.argmin(near))
    return float(ends[k]) if near[k] <= limit else t


def distinct_cuts(cuts: list[Cut], face: TrimmedFace, eps: float, tol3d: float | None) -> list[Cut]:
    """The cuts without repeats: a cut whose every sample lies within ``tol3d`` in space
    (``eps`` in the parameters) of a cut kept before it is the same curve found twice
    (as an intersection can report it from two methods or two passes) and is left out."""
    kept: list[tuple[Cut, NDArray]] = []
    for cut in cuts:
        uv = cut.samples()
        points = (face.surface.evaluate(uv[:, 0], uv[:, 1]) if tol3d is not None else uv)
        limit = tol3d if tol3d is not None else eps
        same = False
        for _, other in kept:
            ends = min(np.linalg.norm(points[[0, -1]] - other[[0, -1]], axis=1).max(),
                       np.linalg.norm(points[[0, -1]] - other[[-1, 0]], axis=1).max())
            if ends > limit:
                continue
            gaps = np.min(np.linalg.norm(points[::16, None] - other[None], axis=2), axis=1)
            if np.all(gaps <= limit + _chord(other)):
                same = True
                break
        if not same:
            kept.append((cut, points))
    return [cut for cut, _ in kept]


def _chord(points: NDArray) -> float:
    """Half the longest step between consecutive samples: how far a point of the curve can
    lie from the nearest sample."""
    return 0.5 * float(np.max(np.linalg.norm(np.diff(points, axis=0), axis=1))) if len(points) > 1 else 0.0


def runs_along_boundary(face: TrimmedFace, loops: list[TrimLoop], cut: Cut, eps: float,
                    tol3d: float | None) -> bool:
    """True when the cut runs along the face's boundary (every sample within ``tol3d`` of
    a trimming edge in space, or ``eps`` in the parameters): it divides nothing -- two
    faces of one model meeting another along a shared edge, two touching solids."""
    region = FaceRegion(TrimmedFace(face.surface, tuple(loops), 0, face.reversed))
    uv = cut.samples()[::8]
    if tol3d is not None:
        t0, t1 = cut.range
        points = (cut.curve3d.evaluate(np.linspace(t0, t1, uv.shape[0])) if cut.curve3d is not None
                  else face.surface.evaluate(uv[:, 0], uv[:, 1]))
        return bool(np.all(region.edge_distance(points) <= tol3d))
    index = region.loop_index()
    if index is not None:
        return bool(np.all(index.uv_tree.distance(uv) <= eps))
    u0, u1, v0, v1 = face.surface.domain          # the loops are the parameter rectangle
    side = np.min(np.abs(np.stack([uv[:, 0] - u0, uv[:, 0] - u1, uv[:, 1] - v0, uv[:, 1] - v1])), axis=0)
    return bool(np.all(side <= eps))
