"""Faces lying partly on others (001 §1 "overlaps", for :func:`surfprep.heal`): found and
measured here, cut by
:mod:`surfprep.plugin.heal.trim_back`.

Two faces *overlap partially* when a part of one (B, the later) lies on the other
(A) within ``gap_tol`` - a corner of two sheets of the same surface (an L-shaped
union), a face lying partly on another, trimmed or not, any number of sides - and
the part is neither the whole of B (an exact duplicate,
:func:`.adjacency.duplicate_faces`) nor a strip along one side of B
(:func:`is_strip`; between two four-sided faces :mod:`.strip_overlap`
re-approximates the trimmed face). :func:`on_face` samples B's surface on a grid
of cell centres and projects the samples onto A (:func:`overlap_share`,
:func:`overlap_area` by the midpoint rule); :func:`partial_overlap_pairs` culls
the pairs with sample grids first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..projection import project_to_surface
from ..trimmed import TrimmedFace
from .strip_overlap import SurfaceGrid, surface_grid

__all__ = ["AREA_SAMPLES", "MAX_SHARE", "MIN_SHARE", "SAMPLES", "PartialOverlap", "is_strip",
           "on_face", "overlap_area", "overlap_share", "partial_overlap_pairs", "surface_samples"]

#: samples per direction of a face tested for lying on another
SAMPLES = 15
#: samples per direction measuring the area of a face lying on another
AREA_SAMPLES = 61
#: shares of a face's samples on the other between these bounds make a partial overlap
MIN_SHARE, MAX_SHARE = 0.01, 0.98


@dataclass(frozen=True)
class PartialOverlap:
    """Face ``trimmed`` (input index) lay on face ``kept`` over ``area_cut`` (model
    units squared), ``pieces`` faces left of it; ``share_before`` is the share of its
    samples that lay on ``kept``."""

    kept: int
    trimmed: int
    share_before: float
    area_cut: float
    pieces: int

    def as_dict(self) -> dict:
        return {"kept": self.kept, "trimmed": self.trimmed, "share_before": self.share_before,
                "area_cut": self.area_cut, "pieces": self.pieces, "action": "trimmed back"}


def surface_samples(face: TrimmedFace, n: int) -> NDArray:
    """``(n * n, 3)`` points of the face's surface at the centres of an ``n x n`` grid of cells."""
    u0, u1, v0, v1 = face.surface.domain
    t = (np.arange(n) + 0.5) / n
    return face.surface.evaluate_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0)).reshape(-1, 3)


def on_face(b: TrimmedFace, a: TrimmedFace, gap_tol: float, n: int = SAMPLES) -> NDArray:
    """(n, n) bool: cell-centre samples of ``b``'s surface lying on ``a``'s surface within
    ``gap_tol`` with their closest point inside ``a``'s domain (not on its border)."""
    pts = surface_samples(b, n)
    lo, hi = a.surface.bounding_box()
    near = np.all((pts >= lo - gap_tol) & (pts <= hi + gap_tol), axis=1)
    out = np.zeros(len(pts), bool)
    if np.any(near):
        foot = project_to_surface(a.surface, pts[near])
        u0, u1, v0, v1 = a.surface.domain
        eps = 1e-9 * max(u1 - u0, v1 - v0)
        interior = ((foot.uv[:, 0] > u0 + eps) & (foot.uv[:, 0] < u1 - eps)
                    & (foot.uv[:, 1] > v0 + eps) & (foot.uv[:, 1] < v1 - eps))
        out[near] = (foot.distance <= gap_tol) & interior
    return out.reshape(n, n)


def overlap_share(b: TrimmedFace, a: TrimmedFace, gap_tol: float) -> float:
    """Share of ``b``'s surface samples ``(SAMPLES ** 2)`` on ``a`` (:func:`on_face`)."""
    return float(on_face(b, a, gap_tol).mean())


def overlap_area(b: TrimmedFace, a: TrimmedFace, gap_tol: float) -> float:
    """Area of ``b``'s surface on ``a`` (midpoint rule on ``AREA_SAMPLES ** 2`` cells)."""
    n = AREA_SAMPLES
    u0, u1, v0, v1 = b.surface.domain
    t = (np.arange(n) + 0.5) / n
    d = b.surface.derivatives_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0), 1)
    cell = np.linalg.norm(np.cross(d[:, :, 1, 0], d[:, :, 0, 1]), axis=-1)
    cell *= (u1 - u0) * (v1 - v0) / n ** 2
    return float(np.sum(cell * on_face(b, a, gap_tol, n)))


def is_strip(mask: NDArray) -> bool:
    """Whether the samples on the other face are full lines along one side of the
    domain (a strip: :mod:`.strip_overlap`'s case)."""
    for m in (mask, mask[::-1], mask.T, mask.T[::-1]):
        k = int(np.argmin(np.all(m, axis=1))) if not np.all(m) else len(m)
        if 0 < k < len(m) and not np.any(m[k:]):
            return True
    return False


def _may_lie_on(b_samples: NDArray, a: SurfaceGrid, b_box: NDArray, gap_tol: float) -> bool:
    """Cheap test before projecting: enough of ``b``'s samples have an interior sample
    of ``a`` as nearest grid point within ``spacing`` (a point beyond ``a``'s edge has
    a border sample nearest)."""
    reach = a.spacing + gap_tol
    if np.any(a.box[0] - reach > b_box[1]) or np.any(b_box[0] > a.box[1] + reach):
        return False
    d, k = a.tree.query(b_samples, distance_upper_bound=reach)
    hit = np.isfinite(d)
    return int(np.sum(a.interior[k[hit]])) >= MIN_SHARE * len(b_samples)


def partial_overlap_pairs(faces: list, candidates: list[int], skip: set, gap_tol: float):
    """``(i, j, share)`` for faces ``j`` of ``candidates`` lying partly on an earlier face ``i``
    (``share`` of ``j``'s samples on ``i``, between ``MIN_SHARE`` and ``MAX_SHARE``,
    not a strip) that lies partly on ``j`` too; pairs in ``skip`` left out."""
    grids = {i: surface_grid(faces[i], SAMPLES) for i in candidates}
    samples = {i: surface_samples(faces[i], SAMPLES) for i in candidates}
    for n, i in enumerate(candidates):
        for j in candidates[n + 1:]:
            if (i, j) in skip or not _may_lie_on(samples[j], grids[i], grids[j].box, gap_tol):
                continue
            mask = on_face(faces[j], faces[i], gap_tol)
            share = float(mask.mean())
            if not MIN_SHARE <= share <= MAX_SHARE or is_strip(mask):
                continue
            if overlap_share(faces[i], faces[j], gap_tol) >= MIN_SHARE:
                yield i, j, share
