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
2. edges of different faces within ``gap_tol`` of each other are paired; free
   edges chained into loops from two or more faces are classified by their
   surroundings (:mod:`.loops`): holes (the surroundings continue across them) are
   filled, open boundaries (a sheet's edge) are not, unless ``fill`` says otherwise;
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
   ``tol``, e.g. the mouth of a slot, stays open);
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
   ``heal_hole_<k>_<n>``).

The building blocks are :mod:`surfprep.algorithms.healing`
(``local_approximant``, ``connect``, ``Continuity``, ``Side``); the approximants
to build are planned in :mod:`.jobs`.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape
from scipy.spatial import cKDTree

from ...algorithms.face_region import SegmentTree
from ...algorithms.healing import Continuity, JoinReport, LocalApproximant, Network, connect
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
from ...algorithms.healing.fidelity import InputFaces, surface_deviation
from ...algorithms.healing.snap import snap_to_originals
from ...algorithms.healing.strip_overlap import OverlapRepair, find_overlaps, overlap_boundaries
from ...algorithms.projection import project_to_surface
from ...algorithms.tolerance import check_tolerance
from ...algorithms.trimmed import TrimmedFace
from ...errors import ConversionError, InvalidGeometryError, SurfprepError
from ...inputs import ShapeLike
from ..io import CadModel, read, to_shape
from ..occ.faces import face_to_nurbs, make_face
from ..occ.shapes import (
    FaceNames,
    all_faces,
    boundary_edge_points,
    count_free_edges,
    is_valid,
    max_edge_tolerance,
    sew,
)
from .cut import covered_holes_dropped, cut_under_patches
from .jobs import (
    INPUT_CHECK_TOL,
    PatchOrigin,
    approximate,
    directed_jobs,
    plan_jobs,
    replaced_faces,
)
from .loops import plan_loops
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
#: free edges are also counted after sewing at this times the diagonal (geometric closure)
TIGHT_FACTOR = 1e-7
#: times heal takes back the approximants and drops that opened free edges and joins the
#: rest again, before it takes back all of them
ROLLBACK_ROUNDS = 2
#: smallest accepted ``tol`` and ``gap_tol``: this times the model's diagonal (double
#: precision resolves about 2e-16 of it; the approximants' measures need room above)
MIN_TOL_FACTOR = 1e-12


@dataclass(frozen=True)
class PatchReport:
    """One approximant: origin, name, resolution ``(M, N)``, errors of §7 (model
    units), artificial share, whether ``tol`` was met, and ``deviation``: the largest
    distance of the joined patch from the input faces on a dense sample (its
    four sides only for a hole; :mod:`surfprep.algorithms.healing.fidelity`)."""

    origin: PatchOrigin
    name: str | None
    resolution: tuple[int, int]
    max_error: float
    rms_error: float
    artificial_share: float
    converged: bool
    tol: float = float("nan")
    deviation: float = float("nan")

    def as_dict(self) -> dict:
        return {"kind": self.origin.kind, "faces": list(self.origin.faces),
                "index": self.origin.index, "name": self.name,
                "resolution": list(self.resolution), "max_error": self.max_error,
                "rms_error": self.rms_error, "artificial_share": self.artificial_share,
                "converged": self.converged, "tol": self.tol,
                "deviation_from_input": self.deviation}


@dataclass(frozen=True, eq=False)
class HealResult:
    """What :func:`heal` built and measured.

    Attributes
    ----------
    model : CadModel
        The healed shape with face names.
    patches : tuple of PatchReport
    approximants : tuple of LocalApproximant
        Same order as :attr:`patches` (deviation maps in ``.error``).
    network : Network or None
        The joined patches, their connectivity and measured joins.
    dropped : tuple of (int, int)
        ``(kept, dropped)`` overlapping face pairs.
    skipped : tuple of str
        Faces or holes left as they were, and why.
    free_edges_before, free_edges_after : int
        Free edges after sewing at ``gap_tol`` (input) and in the result.
    tight_free_edges_before, tight_free_edges_after : int
        Free edges when the input faces, and the output faces before sewing, are
        sewn at ``TIGHT_FACTOR`` x size: edges not closed in the geometry.
    valid_before, valid_after : bool
        ``BRepCheck_Analyzer`` on the input shape and on the result.
    max_edge_tolerance : float
        Largest edge tolerance of the result (sewing raises it where it closes
        a gap by tolerance instead of geometry).
    tol, gap_tol : float
    continuity : Continuity
    time_s : float
    """

    model: CadModel
    patches: tuple[PatchReport, ...]
    approximants: tuple[LocalApproximant, ...]
    network: Network | None
    dropped: tuple[tuple[int, int], ...]
    skipped: tuple[str, ...]
    free_edges_before: int
    free_edges_after: int
    tight_free_edges_before: int
    tight_free_edges_after: int
    valid_before: bool
    valid_after: bool
    max_edge_tolerance: float
    tol: float | None
    gap_tol: float
    continuity: Continuity
    time_s: float
    extra: dict = field(default_factory=dict)

    @property
    def shape(self) -> TopoDS_Shape:
        return self.model.shape

    @property
    def geometry(self) -> CadModel:
        """The healed model, as every verb's result has its geometry."""
        return self.model

    @property
    def joins(self) -> tuple[JoinReport, ...]:
        return () if self.network is None else self.network.joins

    def report(self) -> dict:
        """Plain-JSON report (per patch, per shared edge, free edges, validity)."""
        net = self.network
        return {
            "continuity": self.continuity.value, "tol": self.tol, "gap_tol": self.gap_tol,
            "time_s": self.time_s, "faces_in": self.extra.get("faces_in"),
            "faces_out": self.model.n_faces,
            "patches": [p.as_dict() for p in self.patches],
            "shared_edges": [j.as_dict() for j in self.joins],
            "shared_edges_before": [] if net is None else [j.as_dict() for j in
                                                           net.joins_before],
            "topology_violations": [] if net is None else list(net.connectivity.violations),
            "dropped_overlaps": [{"kept": a, "dropped": b} for a, b in self.dropped],
            "trimmed_overlaps": self.extra.get("trimmed_overlaps", []),
            "cuts": self.extra.get("cuts", []),
            "partial_overlaps": self.extra.get("partial_overlaps", []),
            "snapped_sides": self.extra.get("snapped_sides", 0),
            "skipped": list(self.skipped),
            "free_edges": {"before": self.free_edges_before, "after": self.free_edges_after,
                           "tight_before": self.tight_free_edges_before,
                           "tight_after": self.tight_free_edges_after},
            "valid": {"before": self.valid_before, "after": self.valid_after},
            "max_edge_tolerance": self.max_edge_tolerance,
            "replace": self.extra.get("replace"),
            "free_loops": self.extra.get("free_loops", []),
        }


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
         replace: str = "defects", meshes: Any = (), fill: str = "holes", progress=None,
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
        edges: four corners give one patch, others quads around a centre. The
        report's ``free_loops`` says what each loop is and what was done.
    progress : callable(done, total), optional
        Called before each approximant and after the last.
    stage : callable(str), optional
        Called as each stage begins ("reading the faces", "finding gaps, holes and
        overlaps", "approximants", "joining, sewing and checking").

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
    >>> free = healed.report()["free_edges"]     # sewn at 1e-7 x size: open before, closed after
    >>> free["tight_before"], free["tight_after"]
    (8, 6)
    >>> join = healed.report()["shared_edges"][0]   # measured on the surfaces
    >>> join["max_gap"] <= 1e-7, join["max_angle_deg"] < 0.1
    (True, True)
    """
    start = time.perf_counter()
    say = stage if stage is not None else (lambda what: None)
    continuity = Continuity.parse(continuity)
    say("reading the faces")
    model = _as_model(shape)
    faces, skipped = _read_faces(model)
    edges = face_edges(faces)
    low, high = MIN_TOL_FACTOR * model.size, model.size
    gap_tol = (_default_gap_tol(model, edges) if gap_tol is None
               else check_tolerance(gap_tol, "gap_tol", low=low, high=high))
    if tol is not None:
        tol = check_tolerance(tol, "tol", low=low, high=high)
    say("finding gaps, holes and overlaps")
    directed = read_patch_spec(patches, faces) if patches is not None else []
    cut = cut_under_patches(model, faces, directed, [face_source(f) for f in faces if f],
                            tol=tol, gap_tol=gap_tol, tight=TIGHT_FACTOR * model.size,
                            skipped=skipped)
    work, faces = cut.model, cut.faces
    work, faces, partial = trim_overlaps_of(work, faces, gap_tol=gap_tol,
                                            tight=TIGHT_FACTOR * model.size, skipped=skipped)
    if cut.cuts or partial:
        edges = face_edges(faces)
    pairs = pair_edges(edges, gap_tol)
    dropped = duplicate_faces(faces, edges, pairs, gap_tol)
    gone = {b for _, b in dropped}
    kept = [i for i, f in enumerate(faces) if f is not None and i not in gone]
    every_edge = edges                      # the dropped faces' too: a drop may be taken back
    edges, pairs = _without_faces(edges, pairs, gone)
    paired = {k for pair in pairs for k in pair}
    free = [k for k in range(len(edges)) if k not in paired]
    rims = covered_holes_dropped(hole_loops(edges, free, gap_tol), cut, gap_tol)
    loops = plan_loops(rims, faces, fill=fill)
    holes = [loop for loop in loops if loop.fill]
    four = [i for i in kept if four_sided_boundary(faces[i]) is not None]
    overlaps = find_overlaps(faces, four, gap_tol)
    trimmed, unions = overlap_boundaries(faces, overlaps, OverlapRepair.parse(overlap),
                                          gap_tol)
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
                     gap_tol=gap_tol, skipped=skipped)
    inputs = InputFaces.of(faces)
    say("approximants")
    done = approximate(jobs, sources, {i: k for k, i in enumerate(kept)}, tol, gap_tol,
                       skipped, inputs, progress)
    done += directed_jobs(directed, cut)
    say("joining, sewing and checking")
    before = _Before.of(model, gap_tol)
    again = functools.partial(
        _no_worse_than_before, skipped=skipped, before=before, every_edge=every_edge,
        model=model, work=work, inputs=inputs, gap_tol=gap_tol, tol=tol,
        continuity=continuity, start=start, keep_split=replace == "all")
    notes_so_far = list(skipped)
    result, done, snapped = again(done, dropped)
    if result.tight_free_edges_after > result.tight_free_edges_before:
        result, done, snapped = _tight_round(
            result, done, snapped, dropped, functools.partial(again, skipped=notes_so_far),
            before, work=work, model=model, gap_tol=gap_tol)
    result.extra["replace"] = replace
    result.extra["free_loops"] = [loop.as_dict() for loop in loops]
    result.extra["cuts"] = [c.as_dict() for c in cut.cuts]
    result.extra["partial_overlaps"] = [o.as_dict() for o in partial]
    result.extra["snapped_sides"] = snapped
    result.extra["trimmed_overlaps"] = [
        {"kept": o.kept, "trimmed": o.trimmed, "replaced": o.trimmed in replaced_faces(done),
         "action": "union" if o.kept in unions else "trimmed back"} for o in overlaps]
    return result


def _tight_round(result, done, snapped, dropped, again, before: _Before, *, work, model,
                 gap_tol: float):
    """With more free edges in the geometry (sewn at ``TIGHT_FACTOR`` x size) than the
    input had, the approximants along the new ones (:func:`_opened_in_geometry`) taken
    back and the rest joined again (``again``, :func:`_no_worse_than_before`, from the
    same drops, so its notes say again what it takes back); kept when that leaves
    fewer, with a note."""
    network = result.network
    kept_drops = [d for d in dropped if d in set(result.dropped)]
    blame = _opened_in_geometry(work, done, network, kept_drops, before, model, gap_tol)
    if not blame:
        return result, done, snapped
    retry, retry_done, retry_snapped = again(_without_jobs(done, blame), dropped)
    if retry.tight_free_edges_after >= result.tight_free_edges_after:
        return result, done, snapped
    what = sorted({f"{done[k][0].origin.kind} {done[k][0].origin.index}" for k in blame})
    note = (f"free edges in the geometry (sewn at {TIGHT_FACTOR:g} x size) "
            f"{result.tight_free_edges_before} -> {result.tight_free_edges_after} with them, "
            f"{retry.tight_free_edges_after} without: taken back (faces kept as they were): "
            f"{', '.join(what)}")
    return (dataclasses.replace(retry, skipped=retry.skipped + (note,)), retry_done,
            retry_snapped)


def _no_worse_than_before(done, dropped, skipped: list[str], before: _Before, *, every_edge,
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
        done = _without_jobs(done, jobs)
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
            f"than before, so taken back (faces kept as they were, holes left open, "
            f"duplicates kept): {', '.join(what)}")


def _without_jobs(done, opening: set[int]) -> list:
    """``done`` without the jobs in ``opening``; a face or a hole split into sub-patches
    goes whole."""
    whole = {(done[k][0].origin.kind, done[k][0].origin.index) for k in opening
             if done[k][0].origin.kind in ("face", "hole")}
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
                                      rim_only=job.origin.kind == "hole" and job.rim_sides
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


@dataclass(frozen=True)
class _Before:
    """The input's figures: free edges sewn at ``gap_tol`` and at ``TIGHT_FACTOR`` x size,
    validity."""

    free_edges: int
    tight_free_edges: int
    valid: bool
    free_lines: list = field(default_factory=list)   # the free edges at gap_tol, (129, 3) each
    tight_lines: list = field(default_factory=list)  # ... at TIGHT_FACTOR x size

    @classmethod
    def of(cls, model: CadModel, gap_tol: float) -> _Before:
        sewn, _ = sew(list(model.faces), gap_tol)
        tight, _ = sew(list(model.faces), TIGHT_FACTOR * model.size)
        return cls(count_free_edges(sewn), count_free_edges(tight), is_valid(model.shape),
                   boundary_edge_points(sewn, 129), boundary_edge_points(tight, 129))


def _assemble(model, work, done, network, dropped, skipped, gap_tol, tol, continuity, start,
              deviations, before: _Before) -> HealResult:
    """The output from ``work`` (the input with faces under directed patches cut) and the
    approximants; ``before``: the figures of ``model`` (the input)."""
    originals, new_faces, names = _output_faces(work, done, network, dropped)
    shape, sewing = sew(originals + new_faces, gap_tol)
    out_faces = all_faces(shape)
    out_names = tuple(_sewn_name(f, sewing, names, originals + new_faces) for f in out_faces)
    result_model = CadModel(shape, out_faces, out_names, (None,) * len(out_faces),
                            model.length_unit, None, model.file_format)
    tight_after, _ = sew(originals + new_faces, TIGHT_FACTOR * model.size)   # unsewn output
    reports = tuple(PatchReport(job.origin, job.name, la.resolution, la.max_error, la.rms_error,
                                la.artificial_share, la.converged, la.tol, deviation)
                    for (job, la), deviation in zip(done, deviations))
    return HealResult(
        model=result_model, patches=reports, approximants=tuple(la for _, la in done),
        network=network, dropped=tuple(dropped), skipped=tuple(skipped),
        free_edges_before=before.free_edges, free_edges_after=count_free_edges(shape),
        tight_free_edges_before=before.tight_free_edges,
        tight_free_edges_after=count_free_edges(tight_after),
        valid_before=before.valid, valid_after=is_valid(shape),
        max_edge_tolerance=max_edge_tolerance(shape), tol=tol, gap_tol=gap_tol,
        continuity=continuity, time_s=time.perf_counter() - start,
        extra={"faces_in": model.n_faces})


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


def _opened_in_geometry(work, done, network, dropped, before: _Before, model, gap_tol: float
                        ) -> set[int]:
    """The approximants (indices of ``done``) along free edges that the result's faces
    sewn at ``TIGHT_FACTOR`` x size have and the input's have not: gaps the approximants
    opened in the geometry (a corner off a neighbour's short edge) where sewing at
    ``gap_tol`` hides them."""
    if network is None:
        return set()
    originals, new_faces, _ = _output_faces(work, done, network, dropped)
    tight, _ = sew(originals + new_faces, TIGHT_FACTOR * model.size)
    free = boundary_edge_points(tight, 9)
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

