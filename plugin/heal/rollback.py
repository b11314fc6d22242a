"""How :func:`surfprep.heal` puts its result together and takes back what made it worse.

The approximants are joined and snapped (:func:`connect`,
:func:`~surfprep.algorithms.healing.snap.snap_to_originals`), sewn with the untouched
faces at ``gap_tol``, checked, and measured against the input faces
(:func:`no_worse_than_before`); approximants and duplicate drops that leave more free
edges at ``gap_tol`` than the input had are taken back and the rest joined again, and
then those that leave more free edges in the geometry (measured on the faces at
``TIGHT_FACTOR`` x size) than the input had (:func:`tight_round`).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
from OCP.TopoDS import TopoDS_Face

from ...algorithms.face_region import SegmentTree
from ...algorithms.healing import connect
from ...algorithms.healing.adjacency import dense_edge
from ...algorithms.healing.fidelity import InputFaces, surface_deviation
from ...algorithms.healing.snap import snap_to_originals
from ...algorithms.projection import project_to_surface
from ...algorithms.trimmed import TrimmedFace
from ..io import CadModel
from ..occ.faces import make_face
from ..occ.gaps import gaps_in_geometry
from ..occ.shapes import (
    FaceNames,
    all_faces,
    boundary_edge_points,
    count_free_edges,
    is_valid,
    max_edge_tolerance,
    sew,
)
from .jobs import FILLS, INPUT_CHECK_TOL, replaced_faces
from .result import HealResult, PatchReport

__all__ = ["ROLLBACK_ROUNDS", "TIGHT_FACTOR", "Before", "no_worse_than_before", "tight_round",
           "without_jobs"]

#: free edges are also counted after sewing at this times the diagonal (geometric closure)
TIGHT_FACTOR = 1e-7
#: times heal takes back the approximants and drops that opened free edges and joins the
#: rest again, before it takes back all of them
ROLLBACK_ROUNDS = 2

#: samples per direction of the replaced face's surface for the orientation start
_ORIENT_SAMPLES = 9


def _oriented_face(surface, reference: TrimmedFace | None) -> TopoDS_Face:
    """A face on ``surface`` whose normal agrees with the replaced face's (compared at
    the foot of the approximant's centre, projected from the nearest of a coarse grid:
    only the sign of the normals' dot product is used)."""
    if reference is None:
        return make_face(surface)
    n_new = surface.normals(0.5, 0.5)
    center = surface.evaluate(0.5, 0.5)
    old = reference.surface
    u0, u1, v0, v1 = old.domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, _ORIENT_SAMPLES),
                         np.linspace(v0, v1, _ORIENT_SAMPLES), indexing="ij")
    grid = old.evaluate_grid(uu[:, 0], vv[0]).reshape(-1, 3)
    k = int(np.argmin(np.linalg.norm(grid - center, axis=1)))
    foot = project_to_surface(old, center, guess=np.array([uu.ravel()[k], vv.ravel()[k]]))
    n_old = old.normals(foot.uv[0], foot.uv[1])
    if reference.reversed:
        n_old = -n_old
    return make_face(surface, reversed=bool(np.dot(n_new, n_old) < 0))


def tight_round(result, done, snapped, dropped, again, before: Before, *, model,
                gap_tol: float):
    """With more free edges in the geometry (at ``TIGHT_FACTOR`` x size) than the
    input had, the approximants along the new ones (:func:`_opened_in_geometry`) taken
    back and the rest joined again (``again``, :func:`no_worse_than_before`, from the
    same drops, so its notes say again what it takes back); kept when that leaves
    fewer, with a note."""
    network = result.network
    blame = _opened_in_geometry(result.model.shape, done, network, before, model, gap_tol)
    if not blame:
        return result, done, snapped
    retry, retry_done, retry_snapped = again(without_jobs(done, blame), dropped)
    if retry.tight_free_edges_after >= result.tight_free_edges_after:
        return result, done, snapped
    what = sorted({f"{done[k][0].origin.kind} {done[k][0].origin.index}" for k in blame})
    note = (f"free edges in the geometry (measured on the faces at {TIGHT_FACTOR:g} x size) "
            f"{result.tight_free_edges_before} -> {result.tight_free_edges_after} with them, "
            f"{retry.tight_free_edges_after} without: taken back (faces kept as they were): "
            f"{', '.join(what)}")
    return (dataclasses.replace(retry, skipped=retry.skipped + (note,)), retry_done,
            retry_snapped)


def no_worse_than_before(done, dropped, skipped: list[str], before: Before, *, every_edge,
                          model, work, inputs, gap_tol, tol, continuity, start,
                          keep_split: bool):
    """The approximants of ``done`` joined and sewn with the untouched faces, taking back
    what leaves more free edges (at ``gap_tol``) than the input had (:func:`_opening`) and
    joining the rest again; after ``ROLLBACK_ROUNDS`` rounds, or with nothing to blame,
    every approximant and drop. Not taken back, with a note: free edges only a dropped
    duplicate of their own face closed in the input, and with ``keep_split``
    (``replace="all"``) a free border of the input cut into the sides of sub-patches. The
    caller's directed patches stay: if they alone leave more free edges, the round with
    the fewest is returned, with a note. Returns ``(result, done, sides snapped)``."""
    best = None
    for round_ in range(ROLLBACK_ROUNDS + 2):
        notes: list[str] = []
        network, snapped = _joined(done, every_edge, {b for _, b in dropped}, gap_tol,
                                   continuity, TIGHT_FACTOR * model.size)
        deviations = _deviations(done, network, inputs, gap_tol, notes)
        result = _assemble(model, work, done, network, dropped, skipped + notes, gap_tol, tol,
                           continuity, start, deviations, before)
        more = result.free_edges_after - result.free_edges_before
        if more <= 0:
            return result, done, snapped
        if best is None or result.free_edges_after < best[0].free_edges_after:
            best = (result, done, snapped)
        blame = _opening(result.shape, done, network, every_edge, dropped, before.free_lines,
                         gap_tol)
        excused = blame.revealed + (blame.split_pieces if keep_split else 0)
        if not blame.jobs and not blame.drops and excused >= more:
            note = _excused(result, blame, keep_split)
            return dataclasses.replace(result, skipped=result.skipped + (note,)), done, snapped
        jobs, drops = blame.jobs, blame.drops
        if not jobs and not drops:
            jobs = blame.split_jobs
        if round_ >= ROLLBACK_ROUNDS or not (jobs or drops):
            # still worse after ROLLBACK_ROUNDS, or nothing to blame: everything back
            jobs = {k for k, (job, _) in enumerate(done) if job.origin.kind != "directed"}
            drops = set(dropped)
        if not jobs and not drops:
            break
        skipped.append(_rolled_back(done, jobs, drops, result))
        done = without_jobs(done, jobs)
        dropped = [d for d in dropped if d not in drops]
    result, done, snapped = best
    note = (f"free edges {result.free_edges_before} -> {result.free_edges_after}: more after "
            "than before; taking back the approximants and drops did not lower it (the "
            "directed patches are never taken back): the result with the fewest is returned")
    return dataclasses.replace(result, skipped=result.skipped + (note,)), done, snapped


def _excused(result: HealResult, blame: _Blame, keep_split: bool) -> str:
    why = []
    if blame.revealed:
        why.append(f"{blame.revealed} are edges of a face that only its duplicate (dropped) "
                   "closed in the input")
    if keep_split and blame.split_pieces:
        why.append(f"{blame.split_pieces} more come from free edges of the input cut into "
                   "the sides of several sub-patches (replace='all'; no gap opened)")
    return (f"free edges {result.free_edges_before} -> {result.free_edges_after}, kept: "
            + "; ".join(why))


def _joined(done, edges, gone, gap_tol, continuity, tight):
    """The approximants of ``done`` joined (:func:`connect`) and their sides fitted to the
    edges (every loop's) of the faces neither replaced nor dropped (in ``gone``)
    (:func:`snap_to_originals`): ``(network or None, sides snapped)``."""
    if not done:
        return None, 0
    network = connect([la.surface for _, la in done], continuity=continuity, gap_tol=gap_tol,
                      strict=False)
    out = replaced_faces(done) | gone
    return snap_to_originals(network, [e for e in edges if e.face not in out], gap_tol, tight)


@dataclass(frozen=True)
class _Blame:
    """What :func:`_opening` found: approximants (indices of ``done``) and duplicate drops
    that opened free edges; free edges only a dropped duplicate of their own face closed
    in the input (``revealed``); free edges more than the input's along its free edges
    (``split_pieces``: a free border cut into the sides of several patches)."""

    jobs: set
    drops: set
    revealed: int = 0
    split_pieces: int = 0
    split_jobs: set = field(default_factory=set)     # the approximants along those


def _opening(shape, done, network, edges, dropped, input_free: list, gap_tol: float) -> _Blame:
    """What to take back when the result ``shape`` has more free edges than the input.

    A free edge of the result is *opened* when it runs along no free edge of the input
    (``input_free``: the input sewn at ``gap_tol`` by OpenCascade, the figure the result
    is compared with; our own pairing misses edges OpenCascade pairs, as a long edge
    against two shorter ones). An opened edge is blamed on the approximants whose rim it
    runs along, on those replacing a face with an input edge (any loop) it runs along, and
    on the dropped duplicates with such an edge when two or more kept faces meet there (a
    wall two solids share: its edges were left with three faces). One that runs along a
    single kept face's edge and its dropped duplicates' is *revealed*, not opened: only
    the duplicate closed it. Where nothing was opened, the approximants along free edges
    that share a free edge of the input are blamed (``split_jobs``: a free border cut
    into the sides of several sub-patches). The caller's directed patches are never
    taken back."""
    free = boundary_edge_points(shape, 9)
    if not free:
        return _Blame(set(), set())
    jobs_of: dict[int, set[int]] = {}
    for k, (job, _) in enumerate(done):
        if job.origin.kind in ("face", "union"):
            for f in job.origin.faces:
                jobs_of.setdefault(f, set()).add(k)
    twin_of = {b: a for a, b in dropped}
    rims = [_rim(surface) for surface in network.patches] if network is not None else []
    near_rim = (_polylines_along([np.concatenate(r) for r in rims], free, gap_tol, pieces=rims)
                if rims else [[] for _ in free])
    # an approximant's side lies up to its tol off the input edges it follows
    along = gap_tol + max((la.tol for _, la in done), default=0.0)
    lines = [dense_edge(e) for e in edges]
    near_edge = _polylines_along(lines, free, along) if lines else [[] for _ in free]
    near_input = (_polylines_along(input_free, free, along) if input_free
                  else [[] for _ in free])
    jobs, drops, revealed = set(), set(), 0
    for n in range(len(free)):
        if near_input[n]:
            continue                          # along a free edge of the input
        faces = {edges[i].face for i in near_edge[n]}
        kept = faces - set(twin_of)
        if len(kept) == 1 and faces != kept and all(twin_of[f] in kept for f in faces - kept):
            revealed += 1
            continue
        jobs |= {j for f in faces for j in jobs_of.get(f, ())} | set(near_rim[n])
        if len(kept) > 1:
            drops |= {(twin_of[f], f) for f in faces - kept}
    shared: dict[int, list[int]] = {}
    for n, lines_along in enumerate(near_input):
        for i in lines_along[:1]:
            shared.setdefault(i, []).append(n)
    pieces = [group for group in shared.values() if len(group) > 1]

    def undirected(js):
        return {j for j in js if done[j][0].origin.kind != "directed"}
    return _Blame(undirected(jobs), drops, revealed, sum(len(g) - 1 for g in pieces),
                  undirected({j for g in pieces for n in g for j in near_rim[n]}))


def _rim(surface, samples: int = 129) -> list:
    """The four sides of ``surface`` as polylines ``(samples, 3)``."""
    t = np.linspace(0.0, 1.0, samples)
    u0, u1, v0, v1 = surface.domain
    u, v = u0 + (u1 - u0) * t, v0 + (v1 - v0) * t
    return [surface.evaluate(u, np.full_like(u, v0)), surface.evaluate(u, np.full_like(u, v1)),
            surface.evaluate(np.full_like(v, u0), v), surface.evaluate(np.full_like(v, u1), v)]


def _polylines_along(lines: list, free: list, gap_tol: float, pieces: list | None = None
                     ) -> list[list[int]]:
    """Per free edge (its points ``(k, 3)``), the indices of the polylines (``(m, 3)``
    each; or made of ``pieces[i]``, several polylines) it runs along: every point
    within ``gap_tol``. Polylines whose box grown by ``gap_tol`` misses a point are
    not measured."""
    lo = np.stack([q.min(axis=0) for q in lines]) - gap_tol
    hi = np.stack([q.max(axis=0) for q in lines]) + gap_tol
    out = []
    for points in free:
        fits = np.flatnonzero(np.all(lo <= points.min(axis=0), axis=1)
                              & np.all(points.max(axis=0) <= hi, axis=1))
        out.append([int(i) for i in fits if SegmentTree.from_polylines(
            pieces[i] if pieces is not None else [lines[i]]).distance(points).max() <= gap_tol])
    return out


def _rolled_back(done, opening: set[int], undropped: set, result: HealResult) -> str:
    what = sorted({f"{done[k][0].origin.kind} {done[k][0].origin.index}" for k in opening})
    what += [f"face {b} (duplicate of face {a})" for a, b in sorted(undropped)]
    return (f"free edges {result.free_edges_before} -> {result.free_edges_after}: more after "
            f"than before, so taken back (faces kept as they were, holes and rings left open, "
            f"duplicates kept): {', '.join(what)}")


def without_jobs(done, opening: set[int]) -> list:
    """``done`` without the jobs in ``opening``; a face, hole or ring split into sub-patches
    goes whole."""
    whole = {(done[k][0].origin.kind, done[k][0].origin.index) for k in opening
             if done[k][0].origin.kind in ("face", *FILLS)}
    return [(job, la) for k, (job, la) in enumerate(done) if k not in opening
            and (job.origin.kind, job.origin.index) not in whole]


def _deviations(done, network, inputs: InputFaces, gap_tol: float, skipped: list[str]
                ) -> list[float]:
    """Per patch of ``done``, joined as ``network`` holds it: its largest distance from
    the input faces (dense; a hole's along its four sides). Joining moves a patch by
    up to the gap it closes (at most ``gap_tol``) beyond its tol; patches off by more
    than their tol are named in one note, and those off by more than that in
    another."""
    out, moved, off = [], [], []
    for (job, la), surface in zip(done, network.patches if network else ()):
        deviation = surface_deviation(surface, inputs, tol=INPUT_CHECK_TOL * la.tol,
                                      rim_only=job.origin.kind in FILLS and job.rim_sides
                                      ).max_distance
        if job.origin.kind != "directed" and deviation > la.tol:
            (moved if deviation <= la.tol + gap_tol else off).append((job, deviation, la.tol))
        out.append(deviation)
    joined = f"the joins moved them to close gaps (up to gap_tol {gap_tol:.3g} beyond tol)"
    for group, why in ((moved, joined), (off, f"more than tol + gap_tol ({gap_tol:.3g}) off")):
        if group:
            names = ", ".join(f"{job.origin.kind} {job.origin.index}"
                              + (f" ({job.name})" if job.name else "") for job, _, _ in group)
            worst = max(group, key=lambda g: g[1])
            skipped.append(f"{len(group)} patches lie farther than their tol from the input "
                           f"faces after the joins, up to {worst[1]:.3g} (tol {worst[2]:.3g}): "
                           f"{why}: {names}")
    return out


#: ``HealResult.extra`` key of the result's free edges in the geometry: (polylines,
#: owner faces, sides of open shared edges) of :func:`~surfprep.plugin.occ.gaps.gaps_in_geometry`, measured on the
#: shape the result holds
FREE_LINES = "tight_free_lines"
#: ... with this many points along each (their chords a 32nd of the edge: a gap's width
#: measured to them is off by their sagitta at most)
FREE_SAMPLES = 33


@dataclass(frozen=True)
class Before:
    """The input's figures: free edges sewn at ``gap_tol``, in the geometry at
    ``TIGHT_FACTOR`` x size (:func:`~surfprep.plugin.occ.gaps.gaps_in_geometry`),
    validity."""

    free_edges: int
    tight_free_edges: int
    valid: bool
    free_lines: list = field(default_factory=list)   # the free edges at gap_tol, (129, 3) each
    tight_lines: list = field(default_factory=list)  # ... at TIGHT_FACTOR x size
    tight_owners: tuple = ()                         # the face of each of tight_lines
    tight_sewn: tuple = ()                           # ... and whether it is an open edge's side

    @classmethod
    def of(cls, model: CadModel, gap_tol: float) -> Before:
        sewn, _ = sew(list(model.faces), gap_tol)
        tight = gaps_in_geometry(sewn, TIGHT_FACTOR * model.size, samples=129)
        return cls(count_free_edges(sewn), tight.free_in_geometry, is_valid(model.shape),
                   boundary_edge_points(sewn, 129), list(tight.polylines), tight.owners,
                   tight.sewn)


def _assemble(model, work, done, network, dropped, skipped, gap_tol, tol, continuity, start,
              deviations, before: Before) -> HealResult:
    """The output from ``work`` (the input with faces under directed patches cut) and the
    approximants; ``before``: the figures of ``model`` (the input)."""
    originals, new_faces, names = _output_faces(work, done, network, dropped)
    shape, sewing = sew(originals + new_faces, gap_tol)
    out_faces = all_faces(shape)
    out_names = tuple(_sewn_name(f, sewing, names, originals + new_faces) for f in out_faces)
    result_model = CadModel(shape, out_faces, out_names, (None,) * len(out_faces),
                            model.length_unit, None, model.file_format)

    reports = tuple(PatchReport(job.origin, job.name, la.resolution, la.max_error, la.rms_error,
                                la.artificial_share, la.converged, la.tol, deviation)
                    for (job, la), deviation in zip(done, deviations))
    gaps = gaps_in_geometry(shape, TIGHT_FACTOR * model.size, samples=FREE_SAMPLES)
    return HealResult(
        model=result_model, patches=reports, approximants=tuple(la for _, la in done),
        network=network, dropped=tuple(dropped), skipped=tuple(skipped),
        free_edges_before=before.free_edges, free_edges_after=count_free_edges(shape),
        tight_free_edges_before=before.tight_free_edges,
        tight_free_edges_after=gaps.free_in_geometry,
        valid_before=before.valid, valid_after=is_valid(shape),
        max_edge_tolerance=max_edge_tolerance(shape), tol=tol, gap_tol=gap_tol,
        continuity=continuity, time_s=time.perf_counter() - start,
        extra={"faces_in": model.n_faces, FREE_LINES: (gaps.polylines, gaps.owners, gaps.sewn)})


def _output_faces(work, done, network, dropped) -> tuple[list, list, FaceNames]:
    """The faces of the result before sewing: the untouched ones of ``work``, the
    approximants (oriented as the faces they replace), and their names."""
    gone = replaced_faces(done) | {b for _, b in dropped}
    untouched = [i for i in range(work.n_faces) if i not in gone]
    new_faces, names = [], FaceNames()
    for (job, _), surface in zip(done, network.patches if network else ()):
        face = _oriented_face(surface, job.reference)
        new_faces.append(face)
        if job.name:
            names.add(face, job.name)
    originals = [work.faces[i] for i in untouched]
    for i in untouched:
        if work.face_names[i] is not None:
            names.add(work.faces[i], work.face_names[i])
    return originals, new_faces, names


def _opened_in_geometry(shape, done, network, before: Before, model, gap_tol: float
                        ) -> set[int]:
    """The approximants (indices of ``done``) along free edges in the geometry (at
    ``TIGHT_FACTOR`` x size, :func:`~surfprep.plugin.occ.gaps.gaps_in_geometry`) that the
    result ``shape`` has and the input has not: gaps the approximants opened in the
    geometry (a corner off a neighbour's short edge) where sewing at ``gap_tol`` hides
    them."""
    if network is None:
        return set()
    free = list(gaps_in_geometry(shape, TIGHT_FACTOR * model.size).polylines)
    if not free:
        return set()
    known = (_polylines_along(before.tight_lines, free, gap_tol) if before.tight_lines
             else [[] for _ in free])
    opened = [f for f, along in zip(free, known) if not along]
    if not opened:
        return set()
    rims = [_rim(surface) for surface in network.patches]
    near = _polylines_along([np.concatenate(r) for r in rims], opened, gap_tol, pieces=rims)
    return {k for ks in near for k in ks if done[k][0].origin.kind != "directed"}


def _sewn_name(face: TopoDS_Face, sewing, names: FaceNames, inputs: list) -> str | None:
    name = names.get(face)
    if name is not None:
        return name
    for original in inputs:
        if sewing.IsModified(original) and sewing.Modified(original).IsSame(face):
            return names.get(original)
    return None
