"""Faces lying partly on others, trimmed back (001 §1 "overlaps", for :func:`surfprep.heal`).

Two faces *overlap partially* when a part of one (B, the later) lies on the
other (A) within ``gap_tol``, and the part is neither the whole of B (an exact
duplicate) nor a strip along one side of B: such pairs are found and measured by
:mod:`surfprep.algorithms.healing.partial_overlap` (strips between four-sided
faces are :mod:`surfprep.algorithms.healing.strip_overlap`'s). B is trimmed back
to A's boundary: the region of B inside a thin slab around A's surface
(:func:`.cut.slab`, half thickness ``SLAB_GAPS x gap_tol``) is cut away with
``BRepAlgoAPI_Cut``, so B's new edges are the exact intersection of B with the
slab's sides, i.e. A's boundary curves running inside B. The area cut away must
agree with the area of B measured on A (``overlap_area``, within
``AREA_AGREEMENT``), else nothing is cut and the report says so. The output then
has no doubled area; A and B's remainder meet along A's boundary like any
neighbours.

Only an untrimmed A (its face is the whole surface) gives a slab: of a pair the
untrimmed face is kept and the other trimmed back; two trimmed faces are
reported and left (the slab would cover the part trimmed away).
"""

from __future__ import annotations

from ...algorithms.healing.adjacency import duplicate_faces
from ...algorithms.healing.partial_overlap import (
    PartialOverlap,
    overlap_area,
    overlap_share,
    partial_overlap_pairs,
)
from ...algorithms.trimmed import TrimmedFace, is_natural
from ...errors import OpenCascadeError
from .cut import cut_faces, outline, read_faces, rebuilt_model, replace_pieces, slab

__all__ = ["AREA_AGREEMENT", "SLAB_GAPS", "trim_overlaps_of", "trim_partial_overlaps"]

#: the slab around the kept face is this many gap_tol thick on either side
SLAB_GAPS = 2.0
#: the area cut away must agree with the measured overlap within this share
AREA_AGREEMENT = 0.1


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
    found = list(partial_overlap_pairs(faces, candidates, skip, gap_tol))
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
        expected = overlap_area(faces[j], faces[i], gap_tol)
        if expected <= 0.0:
            continue     # samples near a curve where j crosses i, none on it (.crossings)
        try:
            tool = slab(faces[i].surface, SLAB_GAPS * gap_tol, tight)
            k = origin.index(j)
            pieces, cuts = cut_faces([occ[k]], tool, outline(_unit(faces[i].surface)), 0, tight)
        except OpenCascadeError as exc:
            skipped.append(f"faces {i} and {j} overlap, {j} not trimmed back ({exc})")
            continue
        if not cuts:
            continue
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


def trim_overlaps_of(work, faces: list[TrimmedFace | None], edges, pairs, *, gap_tol: float,
                     tight: float, skipped: list[str]):
    """:func:`trim_partial_overlaps` over the readable faces of ``work`` that are no
    duplicates (:func:`duplicate_faces` on ``edges`` and their ``pairs``, dropped later);
    strips (:func:`is_strip`) are left to
    :func:`surfprep.algorithms.healing.strip_overlap.find_overlaps`. Returns ``(model,
    faces, overlaps, duplicates)``, the duplicates those of the faces given (the same as
    the faces returned when no overlap was trimmed)."""
    duplicates = duplicate_faces(faces, edges, pairs, gap_tol)
    twins = {b for _, b in duplicates}
    readable = [i for i, f in enumerate(faces) if f is not None and i not in twins]
    strips: set = set()            # strips are told apart by is_strip (cheaper)
    work, faces, _, partial = trim_partial_overlaps(work, faces, readable, strips,
                                                    gap_tol=gap_tol, tight=tight,
                                                    skipped=skipped)
    return work, faces, partial, duplicates
