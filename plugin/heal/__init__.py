"""Healing of a CAD model: :func:`heal` (001, 003, 000 §29.3) without clicks.

Steps, on anything that holds faces (file path, :class:`CadModel`,
``TopoDS_Shape``, cadquery / build123d object):

1. every face is read as a :class:`TrimmedFace`; each directed patch
   (``patches``, :mod:`.spec`) is approximated over the original faces,
   which are then cut away under it (:mod:`.cut`): it replaces what it
   covers; of two faces overlapping partially (any sides, trimmed or not) the
   later is trimmed back to the other's boundary (:mod:`.trim_back`);
   faces lying on another within ``gap_tol`` (exact duplicates as in
   overture_marscapsule_proe.igs) are dropped; of two four-sided faces
   overlapping over a strip the later one is trimmed back to the other's side,
   or both replaced by one approximant over the union (``overlap="union"``,
   :mod:`surfprep.algorithms.healing.strip_overlap`): no doubled area is left;
2. edges of different faces within ``gap_tol`` of each other are paired; a face
   whose free edges run beside its neighbours' free edges (farther than ``gap_tol``,
   within a fifth of their length; one long edge along a chain of short ones, a
   T-junction, too), or that no approximant will replace (not
   four-sided, not split) and whose paired edges are apart in the geometry from a
   neighbour no approximant will replace either, is
   re-trimmed to those neighbours' edges where they lie on its surface (within
   ``tol`` and a tenth of the gap), its surface untouched (:mod:`.retrim`: a loop
   written off by the exporter, not a gap in the geometry); free
   edges chained into loops from two or more faces are classified by their
   surroundings (:mod:`.loops`): holes (the surroundings continue across them) are
   filled, open boundaries (a sheet's edge) are not, unless ``fill`` says otherwise;
   two closed loops (of one face or several) that run beside each other all round,
   wider apart than ``gap_tol`` (the missing end face of a tube with two skins), are a
   ring (:mod:`.rings`), bridged by four-sided strips unless ``fill="none"``;
3. every four-sided face with a defect (``replace="defects"``, the default: an
   edge paired with another face's but not closed in the geometry, an edge on a
   hole, an overlap; every face with ``replace="all"``) gets a
   :func:`~surfprep.algorithms.healing.local_approximant` over its own four
   edges, projected onto all original faces (trimmed faces as the part inside
   their loops, :func:`~surfprep.algorithms.healing.clipping.face_source`; the
   face itself preferred over other faces crossing the segments; a face whose
   approximant misses ``tol`` at the largest resolution is kept as it is, and
   the report says so); a face that is not four-sided is split into four-sided
   sub-patches (``split_faces``, default) and replaced when all of them fit;
   every hole one over its four free edges, or, with another number of edges,
   four-sided sub-patches of its cap (a loop whose patch lands on faces off
   ``tol``, e.g. the mouth of a slot, stays open); every ring one per strip, its
   inside on the ruled surface between the loops' pieces;
4. the approximants are joined by :func:`~surfprep.algorithms.healing.connect` (G0 or G1, topology
   violations left unconnected and reported); a side that meets a face kept
   as it was (not re-approximated) is fitted to that face's edge or edges, or
   to the part of an edge it meets (with the shared corners moved onto the
   ends), and a side along part of a longer approximant side (a T-junction
   :func:`connect` does not join) to that part, so those gaps close up to the
   fit error too (:mod:`surfprep.algorithms.healing.snap`);
5. approximant faces and the untouched faces are sewn at ``gap_tol`` into a
   shell (a solid when closed) and checked with ``BRepCheck_Analyzer``; every
   joined patch is measured densely against the input faces
   (:mod:`surfprep.algorithms.healing.fidelity`), and when the result has more
   free edges (at ``gap_tol``) than the input, what left the new ones is taken back
   and the rest joined again (:func:`_opening`): the approximants and duplicate
   drops along a free edge that runs along no free edge of the input, else the
   approximants cutting one of the input's free edges into several; after
   ``ROLLBACK_ROUNDS`` rounds, or with nothing to blame, every approximant and drop
   (the caller's directed patches stay). More free edges than the input are left only
   with a note saying why: edges only a dropped duplicate of their own face closed in
   the input, a free border cut into the sides of sub-patches with ``replace="all"``,
   or directed patches;
   untouched faces keep their names (a replaced face passes its name to its
   approximant; holes are named ``heal_hole_<k>``, their sub-patches
   ``heal_hole_<k>_<n>``, the strips of a ring ``heal_ring_<k>_<n>``);
6. shared edges whose faces still lie farther apart than ``TIGHT_FACTOR`` x size
   (sewing closed them by raising the edge's tolerance: faces kept as they were, gaps
   the file hid in its tolerances) are closed in the geometry (:mod:`.close_gaps`):
   the B-spline faces along them are moved the least, by at most ``tol`` (default
   ``gap_tol``), onto one common curve per edge, their pcurves re-projected, analytic
   faces kept exact; the report's ``closed_gaps`` says which faces moved and how far.

Free edges "in the geometry" (``tight_free_edges_before/after``) are measured on the
faces, each face's pcurves through its surface (:mod:`surfprep.plugin.occ.gaps`), not
on the edge curves a file carries. The report's ``free_boundary`` says what those of
the input and of the result are
(:func:`surfprep.algorithms.healing.free_boundary.classify_free_edges`): sides of gaps
(another face's free edge runs beside them), rims of holes (loops classed as holes and
left open), or the model's open boundary (a sheet's edge, a pipe's mouth: nothing
beside them, not a defect); ``interior`` counts the first two.

The building blocks are :mod:`surfprep.algorithms.healing`
(``local_approximant``, ``connect``, ``Continuity``, ``Side``); the approximants
to build are planned in :mod:`.jobs`, the loops of free edges classed in :mod:`.loops`
and paired into rings in :mod:`.rings`,
the result put together and what made it worse taken back in :mod:`.rollback`; the
result types are in :mod:`.result`.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from ...algorithms.healing import Continuity
from ...algorithms.healing.adjacency import (
    dense_edge,
    duplicate_faces,
    face_edges,
    four_sided_boundary,
    hole_loops,
    pair_edges,
    pair_gaps,
)
from ...algorithms.healing.clipping import face_source
from ...algorithms.healing.decompose import quad_boundaries
from ...algorithms.healing.fidelity import InputFaces
from ...algorithms.healing.free_boundary import classify_free_edges
from ...algorithms.healing.strip_overlap import OverlapRepair, find_overlaps, overlap_boundaries
from ...algorithms.tolerance import check_tolerance
from ...algorithms.trimmed import TrimmedFace
from ...errors import ConversionError, InvalidGeometryError, SurfprepError
from ...inputs import ShapeLike
from ..io import CadModel, read, to_shape
from ..occ.faces import face_to_nurbs
from .close_gaps import closed_in_geometry
from .crossings import trim_crossings as trim_crossings_of
from .cut import covered_holes_dropped, cut_under_patches
from .jobs import (
    PatchOrigin,
    approximate,
    directed_jobs,
    plan_jobs,
    replaced_faces,
)
from .loops import plan_loops
from .result import HealResult, PatchReport, StageClock
from .retrim import retrim_to_neighbours
from .rings import mark_ring_loops, plan_rings
from .rollback import FREE_LINES, TIGHT_FACTOR, Before, no_worse_than_before, tight_round
from .spec import read_patch_spec
from .trim_back import trim_overlaps_of

__all__ = [
    "DEFAULT_GAP_FACTOR",
    "MIN_TOL_FACTOR",
    "TIGHT_FACTOR",
    "HealResult",
    "PatchOrigin",
    "PatchReport",
    "heal",
]

#: default ``gap_tol``: this times the model's box diagonal ...
DEFAULT_GAP_FACTOR = 1e-3
#: ... and at most this times the median edge length
_GAP_FACTOR_EDGE = 0.01
#: smallest accepted ``tol`` and ``gap_tol``: this times the model's diagonal (double
#: precision resolves about 2e-16 of it; the approximants' measures need room above)
MIN_TOL_FACTOR = 1e-12




# --------------------------------------------------------------------- input
def _as_model(shape: Any) -> CadModel:
    if isinstance(shape, CadModel):
        return shape
    if isinstance(shape, (str, os.PathLike)):
        return read(shape)
    return CadModel.from_shape(to_shape(shape))


def _read_faces(model: CadModel) -> tuple[list[TrimmedFace | None], list[str]]:
    faces, skipped = [], []
    for i, (f, name) in enumerate(zip(model.faces, model.face_names)):
        try:
            faces.append(face_to_nurbs(f, name))
        except SurfprepError as exc:
            faces.append(None)
            skipped.append(f"face {i}: not readable as NURBS ({exc}); kept as it is")
    return faces, skipped


def _default_gap_tol(model: CadModel, edges) -> float:
    lengths = [float(np.sum(np.linalg.norm(np.diff(e.samples, axis=0), axis=1))) for e in edges]
    bound = _GAP_FACTOR_EDGE * float(np.median(lengths)) if lengths else np.inf
    return float(min(DEFAULT_GAP_FACTOR * model.size, bound))




# ---------------------------------------------------------------------- heal
def _mesh_sources(meshes) -> list:
    """The ``meshes`` argument of :func:`heal` as triangle meshes (paths read)."""
    from ...algorithms.intersection import TriangleMesh
    out = []
    for item in (meshes,) if isinstance(meshes, (str, os.PathLike, TriangleMesh)) else meshes:
        if isinstance(item, TriangleMesh):
            out.append(item)
        elif isinstance(item, (str, os.PathLike)):
            from ..intersect.mesh_operand import read_mesh
            out.append(read_mesh(item))
        else:
            raise ConversionError(f"a healing mesh must be a TriangleMesh or the path of an STL, "
                                  f"OBJ or Plot3D file, got {type(item).__name__}")
    return out


def heal(shape: ShapeLike, *, tol: float | None = None, continuity: Continuity | str = "G0",
         gap_tol: float | None = None, patches: Any = None,
         overlap: OverlapRepair | str = "trim", split_faces: bool = True,
         replace: str = "defects", meshes: Any = (), fill: str = "holes",
         close_gaps: bool = True, trim_crossings: bool = True, progress=None,
         stage: Callable[[str], None] | None = None) -> HealResult:
    """Replace faulty regions by four-sided bicubic approximants joined G0/G1.

    Parameters
    ----------
    shape
        Path of a STEP/IGES file, :class:`CadModel`, ``TopoDS_Shape``,
        cadquery or build123d object.
    tol : float, optional
        Largest error of each approximant (001 §7), model units; default that
        of :func:`~surfprep.algorithms.healing.local_approximant` (relative to
        each patch's size).
    continuity : "G0" or "G1"
    gap_tol : float, optional
        Model units: edges closer than this are one edge (neighbours, gaps to
        close, duplicates). Default ``min(1e-3 x model diagonal, 0.01 x median
        edge length)``.
    patches : path, dict or list, optional
        Directed patches (:func:`.spec.read_patch_spec`); each replaces the
        region it covers (the faces under it are cut away, :mod:`.cut`).
    overlap : "trim" or "union"
        A strip overlap of two four-sided faces: the later face trimmed back, or
        one approximant over the union's outline replacing both.
    split_faces : bool
        Faces that are not four-sided are split into four-sided sub-patches on the
        face (:func:`surfprep.algorithms.healing.decompose.quad_boundaries`) and
        replaced when every sub-patch fits (sides checked against the edges too);
        their sides are fitted to the parts of kept neighbours' edges and of
        longer approximant sides they meet (:mod:`surfprep.algorithms.healing.snap`).
        On by default; False keeps every face that is not four-sided as it is
        (faster: its sub-patches are not built).
    replace : "defects" or "all"
        Which faces are re-approximated: "defects" (default) those with a defect,
        an edge paired with another face's edge (within ``gap_tol``) but not closed
        in the geometry (the two 3D curves farther apart than ``TIGHT_FACTOR`` x
        size), an edge on a hole, or an overlap (with G1 also the faces with a
        corner at such an edge's end); the others keep their exact geometry (an
        approximant in their place could only open gaps that were closed). "all": every face, as 001's network of approximants (also what
        "defects" does when directed patches or trimmed-back overlaps cut faces).
    meshes : sequence of TriangleMesh or paths, optional
        Discrete geometry the approximants may also be projected onto (001 takes
        triangles as input): a scan or an STL / OBJ / Plot3D grid covering a hole
        makes the patch over it follow the data instead of the multiquadric fill of
        the neighbours' shape. The faces stay each face's preferred source.
    fill : "holes", "all" or "none"
        Which loops of free edges (from two or more faces) are filled
        (:mod:`.loops`): "holes" (default) those whose surroundings continue across
        them; "all" also open boundaries (a sheet's edge, a pipe's end: capped by
        the smoothest surface through the rim); "none" none. Loops of any number of
        edges: four corners give one patch, others quads around a centre. Rings (two
        loops beside each other all round, a gap wider than ``gap_tol``) are bridged
        by strips unless "none". The report's ``free_loops`` says what each loop is
        and what was done, ``rings`` what each ring is and whether it was bridged.
    close_gaps : bool
        Close in the geometry the edges sewing closed only by raising their tolerance:
        the B-spline faces along them moved onto one common curve per edge (step 6 of
        the module doc; default). False leaves them as sewing does (faster on large
        models: ``overture_asmo_icem.igs`` 101 s with it, 35 s without).
    trim_crossings : bool
        Faces that cut through each other, each running on past the curve where they
        meet (found where a face's free edges come near another face, :mod:`.crossings`),
        are cut along that curve and the overshooting pieces dropped (default); the
        report's ``crossings`` lists each curve, the areas cut away, or why it was left.
        False leaves them (a directed patch in ``patches`` replaces a crossing instead).
    progress : callable(done, total), optional
        Called before each approximant and after the last.
    stage : callable(str), optional
        Called as each stage begins ("reading the faces", "directed patches and
        overlaps", "finding gaps, holes and crossings", "triangulating the faces as
        sources", "approximants", "joining, sewing and checking", "closing gaps in the
        geometry", "classifying the free edges"); the report's ``stage_times_s`` gives
        the seconds of each.

    Returns
    -------
    HealResult
        ``.model`` (also ``.geometry``) is the healed model; ``.report()`` the
        JSON report.

    Examples
    --------
    Two bicubic patches of ``z = sin(x) cos(y)`` with a gap of 1e-3 between them:

    >>> import numpy as np, surfprep
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> def patch(x0, x1):
    ...     x, y = np.meshgrid(np.linspace(x0, x1, 6), np.linspace(0, 1, 6), indexing="ij")
    ...     return interpolate_surface(np.stack([x, y, np.sin(x) * np.cos(y)], axis=-1))
    >>> faces = [surfprep.make_face(patch(0.0, 1.0)), surfprep.make_face(patch(1.001, 2.0))]
    >>> healed = surfprep.heal(faces, gap_tol=0.01, continuity="G1")
    >>> free = healed.report()["free_edges"]     # in the geometry at 1e-7 x size: open, closed
    >>> free["tight_before"], free["tight_after"]
    (8, 6)
    >>> kinds = healed.report()["free_boundary"]     # the gap's two sides were interior
    >>> kinds["before"]["interior"], kinds["after"]["interior"], kinds["after"]["edges"]
    (2, 0, {'gap': 0, 'open boundary': 6, 'hole': 0})
    >>> join = healed.report()["shared_edges"][0]   # measured on the surfaces
    >>> join["max_gap"] <= 1e-7, join["max_angle_deg"] < 0.1
    (True, True)
    """
    start = time.perf_counter()
    say = StageClock(stage)
    continuity = Continuity.parse(continuity)
    say("reading the faces")
    # on a copy: sewing keeps a closed shell's own faces and edges, and the steps below
    # change them in place (pcurves for new faces added to the input's edges, faces
    # moved onto common curves), which changed the caller's model
    model = _as_model(shape).copy()
    faces, skipped = _read_faces(model)
    edges = face_edges(faces)
    low, high = MIN_TOL_FACTOR * model.size, model.size
    gap_tol = (_default_gap_tol(model, edges) if gap_tol is None
               else check_tolerance(gap_tol, "gap_tol", low=low, high=high))
    if tol is not None:
        tol = check_tolerance(tol, "tol", low=low, high=high)
    say("directed patches and overlaps")
    directed = read_patch_spec(patches, faces) if patches is not None else []
    # the faces as sources only for directed patches (the one use): triangulating them
    # all, which sources = ... below does again for the kept faces, cost 3 s of 12 on
    # occt_k1_catia_theorem.stp
    under = [face_source(f) for f in faces if f] if directed else []
    cut = cut_under_patches(model, faces, directed, under,
                            tol=tol, gap_tol=gap_tol, tight=TIGHT_FACTOR * model.size,
                            skipped=skipped)
    work, faces = cut.model, cut.faces
    if cut.cuts:
        edges = face_edges(faces)
    pairs = pair_edges(edges, gap_tol)
    work, faces, partial, duplicates = trim_overlaps_of(
        work, faces, edges, pairs, gap_tol=gap_tol, tight=TIGHT_FACTOR * model.size,
        skipped=skipped)
    changed = bool(partial)                 # since the duplicates were found
    if partial:
        edges = face_edges(faces)
        pairs = pair_edges(edges, gap_tol)
    say("finding gaps, holes and crossings")
    crossings = []
    if trim_crossings:
        work, faces, crossings = trim_crossings_of(work, faces, edges, pairs, gap_tol=gap_tol,
                                                   tight=TIGHT_FACTOR * model.size,
                                                   skipped=skipped)
        if any(c.left is None for c in crossings):
            if continuity is Continuity.G1:
                skipped.append("faces trimmed back to the curve where they cut through each "
                               "other meet there at the angle they cross at, not G1: a "
                               "directed patch over the crossing (patches=) blends it")
            changed = True
            edges = face_edges(faces)
            pairs = pair_edges(edges, gap_tol)
    whole = {i for i, f in enumerate(faces) if f is not None
             and four_sided_boundary(f) is None
             and (not split_faces or quad_boundaries(f, gap_tol=gap_tol) is None)}
    work, faces, retrims = retrim_to_neighbours(work, faces, edges, pairs, tol=tol,
                                                tight=TIGHT_FACTOR * model.size,
                                                kept=whole, skipped=skipped)
    if retrims:
        edges = face_edges(faces)
        pairs = pair_edges(edges, gap_tol)
    dropped = (duplicate_faces(faces, edges, pairs, gap_tol) if changed or retrims
               else duplicates)
    gone = {b for _, b in dropped}
    kept = [i for i, f in enumerate(faces) if f is not None and i not in gone]
    every_edge = edges                      # the dropped faces' too: a drop may be taken back
    edges, pairs = _without_faces(edges, pairs, gone)
    paired = {k for pair in pairs for k in pair}
    free = [k for k in range(len(edges)) if k not in paired]
    closed_loops = hole_loops(edges, free, gap_tol, min_faces=1)
    rims = covered_holes_dropped([lp for lp in closed_loops if len({e.face for e in lp}) >= 2],
                                 cut, gap_tol)
    loops = plan_loops(rims, faces, fill=fill, gap_tol=gap_tol, free=[edges[k] for k in free])
    rings = plan_rings(closed_loops, gap_tol=gap_tol, fill=fill)
    loops = mark_ring_loops(loops, rims, rings)
    holes = [loop for loop in loops if loop.fill]
    four = [i for i in kept if four_sided_boundary(faces[i]) is not None]
    overlaps = find_overlaps(faces, four, gap_tol)
    trimmed, unions = overlap_boundaries(faces, overlaps, OverlapRepair.parse(overlap),
                                          gap_tol)
    say("triangulating the faces as sources")
    sources = [face_source(faces[i]) for i in kept] + _mesh_sources(meshes)
    if not sources and not directed:
        raise InvalidGeometryError("heal: no face of the input could be read")
    if replace not in ("defects", "all"):
        raise InvalidGeometryError(f"replace must be 'defects' or 'all', got {replace!r}")
    if replace == "defects" and (cut.cuts or partial):
        # the pieces of cut faces are not traced back to the input's edges yet
        skipped.append("faces were cut under directed patches or trimmed back: every face "
                       "is re-approximated (replace='all')")
        replace = "all"
    defective = kept if replace == "all" else _defective(
        kept, edges, pairs, [rims[h.index] for h in holes if h.edges == 4], {o.kept for o in overlaps} | set(trimmed) | set(unions)
        | {j for j, _ in unions.values()}, TIGHT_FACTOR * model.size, gap_tol, continuity,
        skipped)
    jobs = plan_jobs(faces, defective, holes, trimmed, unions, split_faces=split_faces,
                     gap_tol=gap_tol, skipped=skipped, rings=rings)
    inputs = InputFaces.of(faces)
    say("approximants")
    done = approximate(jobs, sources, {i: k for k, i in enumerate(kept)}, tol, gap_tol,
                       skipped, inputs, progress)
    done += directed_jobs(directed, cut)
    if replace == "defects" and not directed:
        # faces whose approximant failed are kept as they are: a gap between two of
        # them that is only in their trims is closed by re-trimming
        work, faces, late = retrim_to_neighbours(
            work, faces, edges, pairs, tol=tol, tight=TIGHT_FACTOR * model.size,
            kept=set(kept) - replaced_faces(done), skipped=skipped, wide=False)
        retrims += late
    say("joining, sewing and checking")
    before = Before.of(model, gap_tol)
    again = functools.partial(
        no_worse_than_before, skipped=skipped, before=before, every_edge=every_edge,
        model=model, work=work, inputs=inputs, gap_tol=gap_tol, tol=tol,
        continuity=continuity, start=start, keep_split=replace == "all")
    notes_so_far = list(skipped)
    result, done, snapped = again(done, dropped)
    if result.tight_free_edges_after > result.tight_free_edges_before:
        result, done, snapped = tight_round(
            result, done, snapped, dropped, functools.partial(again, skipped=notes_so_far),
            before, model=model, gap_tol=gap_tol)
    if close_gaps:
        say("closing gaps in the geometry")
        result = closed_in_geometry(result, size=model.size,
                                    allowed=tol if tol is not None else gap_tol)
    say("classifying the free edges")
    unfilled = [[dense_edge(e) for e in rims[lp.index]] for lp in loops
                if lp.kind in ("hole", "not capped")]
    lines, owners, sewn = result.extra.pop(FREE_LINES)
    result.extra["free_boundary"] = {
        "before": classify_free_edges(before.tight_lines, before.tight_owners, join=gap_tol,
                                      holes=unfilled, sewn=before.tight_sewn).as_dict(),
        "after": classify_free_edges(lines, owners, join=gap_tol, holes=unfilled,
                                     sewn=sewn).as_dict()}
    stage_times = say.times()           # (the last stage ends before the whole does)
    result = dataclasses.replace(result, time_s=time.perf_counter() - start)
    result.extra["stage_times_s"] = stage_times
    result.extra["replace"] = replace
    result.extra["free_loops"] = [loop.as_dict() for loop in loops]
    bridged = {job.origin.index for job, _ in done if job.origin.kind == "ring"}
    result.extra["rings"] = [r.as_dict(bridged=r.index in bridged) for r in rings]
    result.extra["cuts"] = [c.as_dict() for c in cut.cuts]
    result.extra["partial_overlaps"] = [o.as_dict() for o in partial]
    result.extra["crossings"] = [c.as_dict() for c in crossings]
    result.extra["retrimmed"] = [r.as_dict() for r in retrims]
    result.extra["snapped_sides"] = snapped
    result.extra["trimmed_overlaps"] = [
        {"kept": o.kept, "trimmed": o.trimmed, "replaced": o.trimmed in replaced_faces(done),
         "action": "union" if o.kept in unions else "trimmed back"} for o in overlaps]
    return result




def _defective(kept: list[int], edges, pairs, holes, overlapping: set[int], tight: float,
               gap_tol: float, continuity: Continuity, skipped: list[str]) -> list[int]:
    """The kept faces with a defect: an edge paired with another face's edge but not
    closed in the geometry (:func:`pair_gaps` above ``tight``), an edge on a hole, or
    an overlap to repair (``overlapping``); with G1 also the faces with a corner at an
    end of such an edge (the tangent plane there is shared: a hole's diagonal
    neighbours); a note counts the others."""
    gaps = pair_gaps(edges, pairs)
    bad = {k for pair, gap in zip(pairs, gaps) if gap > tight for k in pair}
    on_holes = {id(e) for loop in holes for e in loop}
    bad |= {k for k, e in enumerate(edges) if id(e) in on_holes}
    faulty = {edges[k].face for k in bad} | overlapping
    if continuity == Continuity.G1 and bad:
        ends = cKDTree(np.concatenate([edges[k].ends for k in sorted(bad)]))
        near = ends.query(np.concatenate([e.ends for e in edges]))[0].reshape(-1, 2)
        faulty |= {e.face for e, d in zip(edges, near) if d.min() <= gap_tol}
    out = [i for i in kept if i in faulty]
    if len(out) < len(kept):
        skipped.append(f"{len(kept) - len(out)} faces without a gap, hole or overlap at their "
                       "edges kept as they are (replace='all' re-approximates them too)")
    return out


def _without_faces(edges: list, pairs: list[tuple[int, int]], gone: set[int]
                   ) -> tuple[list, list[tuple[int, int]]]:
    """``edges`` of faces not in ``gone`` and their pairs (renumbered): pairing is
    edge by edge, so this is what :func:`pair_edges` gives on the kept edges."""
    keep = [k for k, e in enumerate(edges) if e.face not in gone]
    new = {k: n for n, k in enumerate(keep)}
    return ([edges[k] for k in keep],
            [(new[a], new[b]) for a, b in pairs if a in new and b in new])


