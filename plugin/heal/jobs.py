"""The approximants :func:`surfprep.heal` builds (001, 003), planned and built.

:func:`plan_jobs` lists one :class:`Job` per face to replace (its own four edges,
its strip-trimmed boundary, or its four-sided sub-patches,
:func:`surfprep.algorithms.healing.decompose.quad_boundaries`), per union of two
overlapping faces and per hole; :func:`approximate` builds each with
:func:`surfprep.algorithms.healing.local_approximant` (a face's own surface its
preferred source) and keeps a face whole unless every sub-patch of it fits;
:func:`directed_jobs` adds the directed patches :mod:`.cut` built. Each job's
:class:`PatchOrigin` says where the approximant comes from, for the report.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...algorithms.healing import LocalApproximant, local_approximant
from ...algorithms.healing.adjacency import four_sided_boundary
from ...algorithms.healing.decompose import quad_boundaries, why_not_decomposable
from ...algorithms.healing.fidelity import InputFaces, surface_deviation
from ...algorithms.trimmed import TrimmedFace
from ...errors import SurfprepError, TimeLimitExceeded
from .cut import CutModel
from .spec import DirectedPatch

__all__ = ["FILLS", "INPUT_CHECK_TOL", "RETRY_MARGIN", "Job", "PatchOrigin", "approximate",
           "directed_jobs", "plan_jobs", "replaced_faces"]

#: the dense check against the input projects to this times the patch's tol
INPUT_CHECK_TOL = 1e-3
#: first resolution of a patch over a hole's cap: the cap is smooth and fully hit, so
#: the first (8, 8) already meets tol, but the tangent planes at the rim follow the
#: cap's to 0.02 degrees only; at (16, 16) to 0.004-0.012 (an n-sided hole in a fan)
CAP_RESOLUTION = (16, 16)
#: the kinds of patch over a gap in the model (not replacing a face): filled by all
#: their sub-patches or left open
FILLS = ("hole", "ring")
#: a patch off the input is rebuilt once to its own error times tol / deviation, times this
RETRY_MARGIN = 0.8


@dataclass(frozen=True)
class PatchOrigin:
    """Where an approximant comes from: ``kind`` "face", "hole", "ring", "union" or
    "directed", and face indices: the face replaced, the faces bounding the hole or the
    ring (:mod:`.rings`), the two faces of
    a union, the input faces a directed patch cut. Indices other than a directed
    patch's count the faces after the cuts (a cut face's pieces take its place)."""

    kind: str
    faces: tuple[int, ...]
    index: int


@dataclass(frozen=True)
class Job:
    """One approximant to build: where it comes from, its four boundary curves, its name
    and the face whose orientation it takes."""

    origin: PatchOrigin
    boundary: Any
    name: str | None
    reference: TrimmedFace | None     # face whose orientation the approximant takes
    split: bool = False               # one of several sub-patches of a face or a hole
    rim_sides: tuple[int, ...] = (0, 1, 2, 3)   # a hole's sides on its rim (the others cross it)
    cap: Any = None                   # a hole's cap or a strip's ruled surface (its
    #                                   artificial projections lie on it)


def _face_boundaries(face: TrimmedFace, index: int, split_faces: bool, gap_tol: float,
                     skipped: list[str]) -> tuple[list, bool]:
    """The four-curve boundaries replacing ``face``: its own four edges, or with
    ``split_faces`` the sub-patches of
    :func:`surfprep.algorithms.healing.decompose.quad_boundaries`; and
    whether the face was split (its sides then also checked against the edges)."""
    curves = four_sided_boundary(face)
    if curves is not None:
        return [curves], False
    if not split_faces:
        return [], False
    boundaries = quad_boundaries(face, gap_tol=gap_tol)
    if boundaries is None:
        skipped.append(f"face {index}: not split into four-sided patches "
                       f"({why_not_decomposable(face, gap_tol=gap_tol)}); kept as it is")
        return [], False
    return boundaries, True


def plan_jobs(faces, kept, holes, trimmed: dict, unions: dict, *, split_faces: bool = False,
              gap_tol: float = 0.0, skipped: list[str] | None = None,
              rings: Sequence = ()) -> list[Job]:
    """The approximants to build: one per union of overlapping faces, per kept face
    (its own four edges, a strip-trimmed boundary, or its four-sided sub-patches), per
    sub-patch of a hole to fill (``holes``: :class:`.loops.FreeLoop`) and per strip of
    a ring to bridge (``rings``: :class:`.rings.Ring`)."""
    jobs = []
    for i, (j, outline) in unions.items():
        jobs.append(Job(PatchOrigin("union", (i, j), i), outline, faces[i].name, faces[i]))
    in_union = set(unions) | {j for j, _ in unions.values()}
    for i in (i for i in kept if i not in in_union):
        if trimmed.get(i):
            boundaries, split = [trimmed[i]], False
        else:
            boundaries, split = _face_boundaries(faces[i], i, split_faces, gap_tol,
                                                 [] if skipped is None else skipped)
        short = min((_side_length(c) for curves in boundaries for c in curves), default=np.inf)
        if short < gap_tol:
            if skipped is not None:
                skipped.append(f"face {i}: an approximant side {short:.3g} long, shorter than "
                               f"gap_tol {gap_tol:.3g} (sewing at gap_tol would collapse it); "
                               "kept as it is")
            continue
        for n, curves in enumerate(boundaries):
            name = faces[i].name if len(boundaries) == 1 or not faces[i].name \
                else f"{faces[i].name}_{n}"
            jobs.append(Job(PatchOrigin("face", (i,), i), curves, name, faces[i], split))
    for loop in holes:
        many = len(loop.boundaries) > 1
        for n, (curves, rim) in enumerate(loop.boundaries):
            name = f"heal_hole_{loop.index}_{n}" if many else f"heal_hole_{loop.index}"
            jobs.append(Job(PatchOrigin("hole", loop.faces, loop.index), curves, name, None,
                            many, tuple(rim), loop.cap))
    for ring in (r for r in rings if r.fill):
        faces_of = tuple(sorted(set(ring.faces[0]) | set(ring.faces[1])))
        for n, (curves, ruled) in enumerate(ring.strips):
            jobs.append(Job(PatchOrigin("ring", faces_of, ring.index), curves,
                            f"heal_ring_{ring.index}_{n}", None, True, (0, 2), ruled))
    return jobs


def _side_length(curve) -> float:
    """Length of a boundary side: a NurbsCurve's arc length, or a polyline's."""
    if hasattr(curve, "arc_length"):
        return float(curve.arc_length())
    points = np.asarray(curve, dtype=float)
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def replaced_faces(done) -> set[int]:
    """Input faces an approximant of ``done`` replaces (faces and unions)."""
    return {f for job, _ in done if job.origin.kind in ("face", "union") for f in job.origin.faces}


def directed_jobs(directed: list[DirectedPatch], cut: CutModel) -> list[tuple[Job, Any]]:
    """The directed patches' approximants (built by :func:`cut_under_patches` from the
    uncut faces) as jobs done; their origin lists the input faces they cut."""
    out = []
    for k, la in cut.approximants:
        faces = tuple(sorted({c.face for c in cut.cuts if c.patch == k}))
        out.append((Job(PatchOrigin("directed", faces, k), la.boundary,
                         directed[k].name or f"heal_patch_{k}", None), la))
    return out


def approximate(jobs: list[Job], sources, source_of: dict[int, int], tol, gap_tol,
                skipped: list[str], inputs: InputFaces | None = None, progress=None
                ) -> list[tuple[Job, LocalApproximant]]:
    """One approximant per job; a face's own surface is its preferred source (other
    faces only where it is missed), so long segments do not pick far-away faces.

    With ``inputs`` (the input faces), the approximant of a face or union is measured
    densely against them (:func:`~surfprep.algorithms.healing.fidelity.surface_deviation`):
    its own error is measured only where its grid landed on the sources and misses a
    bulge over a hole. One off by more than its tol is rebuilt once to a tighter
    error, and if still off the face is kept as it was, and said so.

    ``progress(done, total)`` is called before each job and after the last; a job
    the caller stops by raising :class:`~surfprep.errors.TimeLimitExceeded` into it
    is left as it was (its face kept whole), with a note."""
    out, failed = [], set()
    for n, job in enumerate(jobs):
        if progress is not None:
            progress(n, len(jobs))
        if job.split and (job.origin.kind, job.origin.index) in failed:
            continue              # kept whole / left open: its other sub-patches are moot
        try:
            la = _one_job(job, sources, source_of, tol, gap_tol, skipped, inputs)
        except TimeLimitExceeded as exc:
            la = None
            skipped.append(f"{job.origin.kind} {job.origin.index}: stopped ({exc}); left as "
                           "it was")
        if la is None:
            failed |= {(job.origin.kind, job.origin.index)} if job.split else set()
            continue
        out.append((job, la))
    if progress is not None:
        progress(len(jobs), len(jobs))
    return _whole_faces_only(jobs, out, skipped, failed)


def _one_job(job: Job, sources, source_of: dict[int, int], tol, gap_tol, skipped: list[str],
             inputs: InputFaces | None) -> LocalApproximant | None:
    """The approximant of one job (:func:`approximate`), or None with a note."""
    own = source_of.get(job.origin.faces[0]) if job.origin.kind == "face" else None
    extra = {} if job.cap is None else {"resolution": CAP_RESOLUTION,
                                        "fill_source": job.cap.source(job.name or "")}
    if job.origin.kind == "ring":
        # a strip is new geometry across a gap: its ruled surface is its one source
        # (the faces beside it are the loops' faces, which a strip tilted across a
        # cone's rim would otherwise hit and bend towards)
        sources, extra = [extra["fill_source"]], {"resolution": CAP_RESOLUTION}

    def build(target):
        return local_approximant(job.boundary, sources, tol=target, gap_tol=gap_tol,
                                 preferred_source=own, side_error=job.split, **extra)
    try:
        la = build(tol)
    except TimeLimitExceeded:
        raise
    except (SurfprepError, np.linalg.LinAlgError) as exc:
        skipped.append(f"{job.origin.kind} {job.origin.index}: no approximant "
                       f"({type(exc).__name__}: {exc}); left as it was")
        return None
    if job.origin.kind in ("face", "union") and not la.converged:
        last = la.history[-1]
        if la.max_error <= la.tol:      # met tol only with points filled, not projected
            why = (f"approximant within tol {la.tol:.3g} only at resolution {la.resolution} "
                   f"({la.max_error:.3g}, {100 * la.artificial_share:.0f}% of its points "
                   f"filled where no face was hit), {last.max_error:.3g} refined to "
                   f"{last.resolution}")
        else:
            why = (f"approximant error {la.max_error:.3g} > tol {la.tol:.3g} up to "
                   f"resolution {last.resolution}")
        skipped.append(f"face {job.origin.index}: {why}; kept as it was")
        return None
    if job.origin.kind == "ring" and not la.converged:
        skipped.append(f"ring {job.origin.index} (free edges of faces "
                       f"{list(job.origin.faces)}): strip {job.name} misses its ruled surface "
                       f"by {la.max_error:.3g} > tol {la.tol:.3g}; left open")
        return None
    if job.origin.kind == "hole" and not la.converged:
        # the error is measured only where segments land on the originals: over a real
        # hole that is its rim; a loop of free edges whose inside meets faces (the mouth
        # of a slot, an open end) is no hole, and a patch over it would not fit them
        skipped.append(f"hole {job.origin.index} (free edges of faces {list(job.origin.faces)}"
                       f"): {100 * (1 - la.artificial_share):.0f}% of its projections land on "
                       f"faces with error {la.max_error:.3g} > tol {la.tol:.3g}: not a hole, "
                       "left open")
        return None
    if job.origin.kind in ("face", "union") and inputs is not None:
        return _held_to_input(job, la, build, inputs, skipped)
    return la


def _held_to_input(job: Job, la: LocalApproximant, build, inputs: InputFaces,
                   skipped: list[str]) -> LocalApproximant | None:
    """``la`` if it lies within its tol of the input faces densely, else the approximant
    rebuilt to a tighter error if that one does, else None (with a note)."""
    tol = la.tol
    deviation = surface_deviation(la.surface, inputs, tol=INPUT_CHECK_TOL * tol)
    if deviation.max_distance <= tol:
        return la
    first, retried = deviation, ""
    if la.max_error > 0:
        target = la.max_error * RETRY_MARGIN * tol / deviation.max_distance
        try:
            again = build(target)
        except TimeLimitExceeded:
            raise
        except (SurfprepError, np.linalg.LinAlgError):
            again = None
        if again is not None and again.converged:
            deviation = surface_deviation(again.surface, inputs, tol=INPUT_CHECK_TOL * tol)
            if deviation.max_distance <= tol:
                # held to the caller's tol, not to the tighter target it was built to
                return replace(again, tol=tol, converged=again.max_error <= tol)
            retried = f", {deviation.max_distance:.3g} at a finer resolution"
    where = ", ".join(f"{x:.6g}" for x in first.worst_point)
    what = "sub-patch of face" if job.split else job.origin.kind
    skipped.append(f"{what} {job.origin.index}: its approximant lies {first.max_distance:.3g} "
                   f"from the input faces at ({where}) on a dense sample ({first.samples} "
                   f"points; tol {tol:.3g}, its own error measure {la.max_error:.3g})"
                   f"{retried}; kept as it was")
    return None


def _whole_faces_only(jobs: list[Job], out: list, skipped: list[str],
                      failed: set[tuple[str, int]] = frozenset()) -> list:
    """A face split into sub-patches is replaced, a hole filled by several, only when
    every sub-patch fits (the sub-patches after the first that does not fit, of a face
    or hole in ``failed`` (``(kind, index)``), are not built)."""
    def key(job):
        return job.origin.kind, job.origin.index

    split = [j for j in jobs if j.origin.kind in ("face", *FILLS)]
    want = Counter(key(j) for j in split)
    got = Counter(key(j) for j, _ in out if j.origin.kind in ("face", *FILLS))
    partial = {k for k, n in want.items() if got[k] not in (0, n)} | \
        {k for k in failed if got[k]}
    skipped += [f"{kind} {i}: {got[kind, i]} of {want[kind, i]} sub-patches fit"
                f"{' (the rest not tried after one failed)' if (kind, i) in failed else ''}; "
                + ("kept as it was" if kind == "face" else "left open")
                for kind, i in sorted(partial)]
    return [(j, la) for j, la in out if key(j) not in partial]
