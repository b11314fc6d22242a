"""Overlaps in general for :func:`surfprep.heal`: one face trimmed back to the other.

Two faces *overlap partially* when a part of one (B, the later) lies on the
other (A) within ``gap_tol`` — a corner of two sheets of the same surface (an
L-shaped union), a face lying partly on another, trimmed or not, any number of
sides — and the part is neither the whole of B (an exact duplicate,
:func:`.heal_topology.duplicate_faces`) nor a strip along one side of B (:func:`is_strip`; between two four-sided faces
:mod:`.heal_overlap` re-approximates the trimmed face). B is trimmed back
to A's boundary: the region of B inside a thin slab around A's surface
(:func:`.heal_cut.slab`, half thickness ``SLAB_GAPS x gap_tol``) is cut away with
``BRepAlgoAPI_Cut``, so B's new edges are the exact intersection of B with the
slab's sides, i.e. A's boundary curves running inside B. The area cut away must
agree with the area of B measured on A (:func:`overlap_area`, within
``AREA_AGREEMENT``), else nothing is cut and the report says so. The output then has no
doubled area; A and B's remainder meet along A's boundary like any neighbours.

Only an untrimmed A (its face is the whole surface) gives a slab: of a pair the
untrimmed face is kept and the other trimmed back; two trimmed faces are
reported and left (the slab would cover the part trimmed away).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..algorithms.projection import project_to_surface
from ..errors import OpenCascadeError
from .faces import TrimmedFace
from .heal_cut import cut_faces, outline, read_faces, rebuilt_model, replace_pieces, slab
from .heal_overlap import SurfaceGrid, surface_grid
from .heal_topology import duplicate_faces, face_edges, pair_edges

__all__ = ["PartialOverlap", "is_natural", "is_strip", "loop_uv", "on_face", "overlap_area",
           "overlap_share", "trim_overlaps_of", "trim_partial_overlaps"]

#: pcurve samples per edge of a trimming loop (:func:`loop_uv`)
LOOP_SAMPLES_PER_EDGE = 33
#: samples per direction of a face tested for lying on another
SAMPLES = 15
#: the slab around the kept face is this many gap_tol thick on either side
SLAB_GAPS = 2.0
#: samples per direction measuring the area of a face lying on another
AREA_SAMPLES = 61
#: the area cut away must agree with the measured overlap within this share
AREA_AGREEMENT = 0.1
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


def _samples(face: TrimmedFace, n: int) -> NDArray:
    u0, u1, v0, v1 = face.surface.domain
    t = (np.arange(n) + 0.5) / n
    return face.surface.evaluate_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0)).reshape(-1, 3)


def on_face(b: TrimmedFace, a: TrimmedFace, gap_tol: float, n: int = SAMPLES) -> NDArray:
    """(n, n) bool: cell-centre samples of ``b``'s surface lying on ``a``'s surface within
    ``gap_tol`` with their closest point inside ``a``'s domain (not on its border)."""
    pts = _samples(b, n)
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
    domain (a strip: :mod:`.heal_overlap`'s case)."""
    for m in (mask, mask[::-1], mask.T, mask.T[::-1]):
        k = int(np.argmin(np.all(m, axis=1))) if not np.all(m) else len(m)
        if 0 < k < len(m) and not np.any(m[k:]):
            return True
    return False


def loop_uv(loop) -> NDArray:
    """(n, 2) float: one trimming loop sampled along its pcurves, in loop order."""
    parts = []
    for e in loop.edges:
        t = np.linspace(e.t0, e.t1, LOOP_SAMPLES_PER_EDGE)
        uv = e.pcurve.evaluate(t[::-1] if e.reversed else t)
        parts.append(uv[:-1])
    return np.concatenate(parts)


def is_natural(face: TrimmedFace) -> bool:
    """No loop, or one loop running along the domain's rectangle: the face is its
    whole surface."""
    if not face.loops:
        return True
    if len(face.loops) != 1:
        return False
    u0, u1, v0, v1 = face.surface.domain
    eps = 1e-7 * max(u1 - u0, v1 - v0)
    uv = loop_uv(face.loops[0])
    on_side = ((np.abs(uv[:, 0] - u0) <= eps) | (np.abs(uv[:, 0] - u1) <= eps)
               | (np.abs(uv[:, 1] - v0) <= eps) | (np.abs(uv[:, 1] - v1) <= eps))
    return bool(np.all(on_side))


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


def _pairs(faces: list, candidates: list[int], skip: set, gap_tol: float):
    grids = {i: surface_grid(faces[i], SAMPLES) for i in candidates}
    samples = {i: _samples(faces[i], SAMPLES) for i in candidates}
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


def trim_partial_overlaps(model, faces: list[TrimmedFace | None], candidates: list[int],
                          skip: set, *, gap_tol: float, tight: float, skipped: list[str]):
    """Later faces of partially overlapping pairs among ``candidates`` trimmed back to
    the earlier (module docstring); pairs in ``skip`` (strips, handled elsewhere) left.

    Returns
    -------
    model : CadModel
        Same as given when nothing was trimmed, else the trimmed faces replaced by
        their pieces (names kept).
    faces : list of TrimmedFace or None
    origin : list of int
        Given face index of every face of the returned model.
    overlaps : list of PartialOverlap
    """
    found = list(_pairs(faces, candidates, skip, gap_tol))
    occ, names = list(model.faces), list(model.face_names)
    colors, origin = list(model.face_colors), list(range(len(occ)))
    done, used = [], set()
    for i, j, share in found:
        if j in used or i in used:
            continue
        if not is_natural(faces[i]):
            if not is_natural(faces[j]):
                skipped.append(f"faces {i} and {j} overlap ({100 * share:.0f}% of {j} on "
                               f"{i}), but both are trimmed: left as they are")
                continue
            i, j, share = j, i, overlap_share(faces[i], faces[j], gap_tol)
        try:
            tool = slab(faces[i].surface, SLAB_GAPS * gap_tol, tight)
            k = origin.index(j)
            pieces, cuts = cut_faces([occ[k]], tool, outline(_unit(faces[i].surface)), 0, tight)
        except OpenCascadeError as exc:
            skipped.append(f"faces {i} and {j} overlap, {j} not trimmed back ({exc})")
            continue
        if not cuts:
            continue
        expected = overlap_area(faces[j], faces[i], gap_tol)
        if abs(cuts[0].area_cut - expected) > AREA_AGREEMENT * expected:
            skipped.append(f"faces {i} and {j} overlap over about {expected:.4g}, but cutting "
                           f"{j} back to {i} would remove {cuts[0].area_cut:.4g}: left as "
                           "they are")
            continue
        used.add(j)
        done.append(PartialOverlap(i, j, share, cuts[0].area_cut, cuts[0].pieces))
        occ, names, colors, origin = replace_pieces({k: pieces[0]}, occ, names, colors,
                                                     origin)
    if not done:
        return model, faces, list(range(len(faces))), []
    return rebuilt_model(model, occ, names, colors), read_faces(occ, names), origin, done


def _unit(surface):
    """``surface`` reparametrized on ``[0, 1]^2`` (for :func:`outline`)."""
    from dataclasses import replace
    u0, u1, v0, v1 = surface.domain
    return replace(surface, knots_u=(surface.knots_u - u0) / (u1 - u0),
                   knots_v=(surface.knots_v - v0) / (v1 - v0))


def trim_overlaps_of(work, faces: list[TrimmedFace | None], *, gap_tol: float, tight: float,
                     skipped: list[str]):
    """:func:`trim_partial_overlaps` over the readable faces of ``work`` that are no
    duplicates (:func:`duplicate_faces`, dropped later); strips (:func:`is_strip`) are
    left to :func:`.heal_overlap.find_overlaps`. Returns ``(model, faces, overlaps)``."""
    edges = face_edges(faces)
    twins = {b for _, b in duplicate_faces(faces, edges, pair_edges(edges, gap_tol), gap_tol)}
    readable = [i for i, f in enumerate(faces) if f is not None and i not in twins]
    strips: set = set()            # strips are told apart by is_strip (cheaper)
    work, faces, _, partial = trim_partial_overlaps(work, faces, readable, strips,
                                                    gap_tol=gap_tol, tight=tight,
                                                    skipped=skipped)
    return work, faces, partial
