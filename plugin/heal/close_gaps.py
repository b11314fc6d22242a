"""Gaps that sewing closed only by tolerance, closed in the geometry (:func:`close_gaps`).

After :func:`surfprep.heal` has sewn its faces at ``gap_tol``, an edge two faces share
may still lie between two faces that miss each other along it by up to ``gap_tol``:
the edge's tolerance was raised to cover the gap. Faces that no approximant replaced
(trimmed faces, faces that are not four-sided) keep such gaps; files carry them too,
hidden in their edge tolerances (occt_s1_ideas.stp is valid and sews at 1e-7 x size by
its edge curves, while two of its faces lie 0.1 mm apart). Here every B-spline face
along an edge open at ``tight`` (its faces' points ``S_F(pc_F(t))`` farther apart than
that at equal parameters) is moved the least so that its sides run along one common
curve per edge (:func:`~surfprep.algorithms.healing.edge_fit.fit_to_edges`):

* a vertex goes to the mean of its faces' corners (of the faces that do not move, if
  any: analytic faces, and B-spline faces whose move failed);
* an open edge's common curve is the image of a face that does not move; else the image
  of the face lying nearest the others' surfaces and smoothest, or the mean of it and
  its feet on them; its ends pulled onto the vertices. Each moving face gets as its new
  pcurve the common curve's closest points on it (sliding along the iso-curve for a side
  of an untrimmed face) and goes to the common curve there, so a boundary that only runs
  beside its neighbour within its own surface is re-trimmed, not bent;
* a face that does not move keeps its surface, not its trimming: where the other face's
  points along an open edge lie on its surface, or its feet there lie nearer the other
  face than its own boundary does (and smoother), the common curve is those points or
  feet and the face is re-trimmed to them (its new pcurve their parameters, its ends
  where they were). Two faces meeting at an angle whose trimming curves run apart within
  their surfaces (an exporter's wavy pcurve on a plane) then meet without either
  surface moving, even where neither is a B-spline;
* a free edge, or a shared one closed already, is held: each moving face keeps its side
  there (its ends follow the vertices), the edge's curve is the mean of its faces';
* a face whose fit misses by more than ``_FIT_SHARE`` x ``tight``, would move farther
  than ``allowed`` within its parameter box, or fails ``BRepCheck`` once moved (or makes
  a neighbour fail it) is kept as it was and the others fitted again with it fixed; a
  re-trimmed face that fails so keeps its trimming too.

The faces are updated in place (``BRep_Builder.UpdateFace`` with the new pcurves on the
new surface, the edges' 3D curves the common curves, the vertices moved), so the shell's
topology and the faces' identities and names stay, and a face whose sides are on it
already keeps its surface (only its pcurves change). Every edge touched gets as its
tolerance what is measured between its curve and its faces on ``CHECK_SAMPLES`` points;
what fails is put back as it was.
"""

from __future__ import annotations

import hashlib
from collections import Counter
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.BRepTools import BRepTools
from OCP.gp import gp_Pnt
from OCP.ShapeFix import ShapeFix_ShapeTolerance
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from ...algorithms.curve import NurbsCurve
from ...algorithms.fitting import interpolate_curve
from ...algorithms.healing.edge_fit import EdgeFit, EdgeTarget, fit_to_edges
from ...algorithms.healing.edge_targets import on_surface, pinned_ends, roughness, spread_ends
from ...algorithms.projection import project_to_surface
from ...algorithms.surface import NurbsSurface
from ...errors import SurfprepError
from ..occ.failures import is_occ_failure
from ..occ.gaps import gaps_in_geometry
from ..occ.geom import curve2d_to_occ, curve_to_occ, surface_to_occ
from ..occ.shapes import is_valid, max_edge_tolerance
from .result import HealResult
from .rollback import TIGHT_FACTOR
from .shared_edges import (
    SharedEdge,
    edges_by_face,
    feet_on_face,
    images_on_face,
    pcurve,
    pcurve_points,
    read_edge,
    same_surface,
)

__all__ = ["CHECK_SAMPLES", "FIT_SAMPLES", "ClosedGaps", "close_gaps", "closed_in_geometry"]

#: samples per edge where the gap is first measured (this many evenly and as many
#: clustered at the ends, where an exporter's pcurves wave most: catia theorem's planes
#: lie 2e-5 beside their neighbours at s = 0.003 and within 1.2e-5 at every 1/64) ...
PROBE_SAMPLES = 65
#: ... where a moving face is fitted (this many evenly and as many clustered at the ends;
#: knot spans are split while one holds 12 of them) ...
FIT_SAMPLES = 513
#: ... and where the result is measured (the edges' tolerances)
CHECK_SAMPLES = 1025
#: a face whose fit misses at its samples, or whose moved edges are measured wider than
#: they were (its surface waving between the samples), is fitted again on this many
#: times as many samples along the same common curves (t4m's faces, whose neighbours'
#: edges wave 1e-3 off them with a period of ten samples, fitted to 1.5e-4..2.4e-4 on
#: FIT_SAMPLES and to 5e-5 on four times as many)
_DENSER = 4
#: rounds of fitting, faces whose fit failed or that fail BRepCheck once moved fixed for
#: the next, or fitted on more samples (fits and common curves are remembered, so a
#: round costs what changed; a last round that still fails puts everything back: asmo
#: needs 5, kcs 9 since faces get a second fit and fixed faces may be re-trimmed)
_ROUNDS = 16
#: a face moves when its fit leaves at most this share of the tight tolerance (two faces
#: then meet within it)
_FIT_SHARE = 0.4
#: a face whose edges all lie within this share of the tight tolerance of their common
#: curves keeps its surface (only its pcurves change)
_STILL = 1e-3
#: weight of an image's waves (:func:`~surfprep.algorithms.healing.edge_targets.roughness`)
#: against its distance from the other faces in choosing the common curve
_ROUGHNESS_WEIGHT = 2.0
#: an edge measured wider than this times its gap before (or ``tight``) after the move
#: takes its moved faces back
_WIDER = 2.0
#: passes of close_gaps at most (closed_in_geometry)
_PASSES = 3
#: smallest edge tolerance set
_MIN_TOLERANCE = 1e-7
#: points per direction of the parameter box where a moved face's change is measured
_MOVE_GRID = 41


@dataclass(frozen=True)
class ClosedGaps:
    """What :func:`close_gaps` did.

    Attributes
    ----------
    open_before, open_after : int
        Shared edges whose faces lie farther apart than ``tight`` along them (at equal
        parameters on ``PROBE_SAMPLES`` points before, on ``CHECK_SAMPLES`` after).
    largest_before, largest_after : float
        The largest distance over those edges before, and over them and every edge the
        moved faces have after, model units (measured on the surfaces).
    moved : tuple of dict
        Per face moved: its index in the shape, how far it moved (in its parameter box),
        the fit's residual, the knots inserted.
    retrimmed : tuple of dict
        Per face re-trimmed without moving its surface: its index, how far its boundary
        moved along the edges re-trimmed (largest over them).
    notes : tuple of str
    """

    open_before: int = 0
    open_after: int = 0
    largest_before: float = 0.0
    largest_after: float = 0.0
    moved: tuple = ()
    retrimmed: tuple = ()
    notes: tuple = ()

    def as_dict(self) -> dict:
        return {"open_edges_before": self.open_before, "open_edges_after": self.open_after,
                "largest_gap_before": self.largest_before, "largest_gap_after": self.largest_after,
                "faces_moved": list(self.moved), "faces_retrimmed": list(self.retrimmed)}


@dataclass
class _Journal:
    """What was changed, to put it back."""

    faces: list = field(default_factory=list)      # (face, surface, location, tol, pcurves)
    edges: list = field(default_factory=list)      # (edge, curve, location, first, last, tol)
    vertices: list = field(default_factory=list)   # (vertex, point, tol)


def close_gaps(shape, *, tight: float, allowed: float, fitted: dict | None = None,
               retrim: bool = True) -> ClosedGaps:
    """Close in the geometry the gaps of ``shape`` (a sewn shell, solid or compound)
    wider than ``tight``, moving B-spline faces by at most ``allowed`` (the module doc),
    and re-trimming the faces that do not move where that closes an edge (unless
    ``retrim`` is False). ``shape`` is changed in place. ``fitted`` keeps the fits by
    face, surface and targets across calls on the same shape (the passes of
    :func:`closed_in_geometry`)."""
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    vertices = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_VERTEX, vertices)
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    shared: dict = {}                   # the faces' surfaces, read once
    edges = [read_edge(edge_faces, k, faces, vertices, shared)
             for k in range(1, edge_faces.Extent() + 1)]
    probe = np.union1d(np.linspace(0.0, 1.0, PROBE_SAMPLES),
                       0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, PROBE_SAMPLES)))
    for e in edges:
        if len(e.faces) >= 2:
            images = [images_on_face(e, i, faces, probe) for i in range(len(e.faces))]
            e.gap = max(float(np.max(np.linalg.norm(a - b, axis=1)))
                        for a in images for b in images)
    open_ = [e for e in edges if e.gap > tight]
    if not open_:
        return ClosedGaps()
    largest = max(e.gap for e in open_)
    notes: list[str] = []
    candidates = sorted({f for e in open_ for f in e.faces})
    surfaces = {f: s for f in candidates if (s := same_surface(faces, f, edges)) is not None}
    of_face = edges_by_face(edges)
    fixed: set[int] = set()
    dense: set[int] = set()             # faces fitted on _DENSER times the samples
    rigid: set[int] = set()             # faces whose re-trimming was taken back
    fits: dict = {}
    retrimmed: dict = {}
    done: dict = {}                     # common curves: a later round asks most again
    fitted = {} if fitted is None else fitted
    for _round in range(_ROUNDS):
        moving = [f for f in candidates if f in surfaces and f not in fixed]
        trimmable = set(candidates) - set(moving) - rigid if retrim else set()
        if not moving and not any(f in trimmable for e in open_ for f in e.faces):
            break
        fits, commons, positions, failed, retrimmed = _fit_round(
            moving, trimmable, dense, surfaces, edges, of_face, faces, tight, allowed, notes,
            done, fitted)
        fixed |= failed
        if failed and _round < _ROUNDS - 1 or not (fits or retrimmed):
            continue                # the others fitted again with these where they are
        # (in the last round the faces that fit move, their gaps to the others narrowed)
        journal = _Journal()
        changed = set(fits) | set(retrimmed)
        try:
            after, apart = _apply(fits, retrimmed, commons, edges, of_face, faces, vertices,
                                  positions, journal, surfaces)
            # a face whose edge ends farther from its neighbour than before (its surface
            # waving between the fit's samples) is not moved either
            invalid = _invalid(changed, of_face, faces, edges,
                               _moved_vertices(commons, {id(e): e for e in edges}))
            bad = invalid | _widening(edges, changed, after, apart, tight)
        except Exception as exc:
            if not (isinstance(exc, SurfprepError) or is_occ_failure(exc)):
                raise
            _undo(journal, shape)
            notes.append(f"moving faces onto common edges failed ({exc}): put back as they were")
            fits, retrimmed = {}, {}
            break
        if not bad:
            break
        _undo(journal, shape)
        # a moved face that widened an edge fitted on few samples gets one more chance on
        # many; the others are fitted again with these where they are, and a face that
        # failed BRepCheck is not re-trimmed either
        again = (bad & set(fits)) - dense - invalid
        if bad - again:
            notes.append(f"faces {sorted(f - 1 for f in bad - again)} fail BRepCheck, or leave an "
                         "edge wider than it was, once moved onto (or re-trimmed to) their "
                         "neighbours' edges: kept as they are")
        dense |= again
        fixed |= (bad & set(fits)) - again
        rigid |= invalid | (bad - set(fits))
        fits, retrimmed = {}, {}
    if not fits and not retrimmed:
        return _unchanged(open_, largest, notes, f"{len(open_)} edges between faces that cannot "
                          "move (not B-spline, or their fit failed) nor be re-trimmed to each "
                          "other left open")
    BRepTools.RemoveUnusedPCurves_s(shape)
    moved = tuple({"face": int(f) - 1, "moved": fits[f][1], "residual": fits[f][0].residual,
                   "knots_inserted": fits[f][0].inserted} for f in sorted(fits)
                  if fits[f][0].surface is not surfaces[f])
    trimmed = tuple({"face": int(f) - 1, "moved": retrimmed[f]} for f in sorted(retrimmed))
    remaining = sum(1 for e in open_ if after.get(id(e), e.gap) > tight)
    return ClosedGaps(len(open_), remaining, largest,
                      max([after.get(id(e), e.gap) for e in open_] + list(after.values())),
                      moved, trimmed, tuple(notes))


def closed_in_geometry(result: HealResult, *, size: float, allowed: float) -> HealResult:
    """``result`` with its gaps closed in the geometry (:func:`close_gaps` on its shape,
    ``tight`` = ``TIGHT_FACTOR`` x ``size``) and its figures measured again: free edges in
    the geometry (:func:`~surfprep.plugin.occ.gaps.gaps_in_geometry`), validity and the
    largest edge tolerance; ``extra["closed_gaps"]`` says what moved. Passes are
    repeated (at most ``_PASSES``) while one moves a face and leaves an edge open: faces
    kept in one pass meet neighbours that have moved in the next. Faces that do not move
    are re-trimmed only in one more pass after those, on the edges still open: a round
    that fails then (a re-trim, or a move next to one, failing BRepCheck) costs none of
    what the moves closed (spaceship: 62 free edges in the geometry, 82 with re-trims
    from the first pass)."""
    passes = []
    fitted: dict = {}                   # a face kept in one pass meets mostly the same targets
    tight = TIGHT_FACTOR * size
    for _ in range(_PASSES):
        closed = close_gaps(result.model.shape, tight=tight, allowed=allowed, fitted=fitted,
                            retrim=False)
        passes.append(closed)
        if not closed.moved or closed.open_after == 0 or closed.open_after >= closed.open_before:
            break                       # (a pass that closed nothing repeats itself: t4m 18 s)
    if passes[-1].open_after:
        passes.append(close_gaps(result.model.shape, tight=tight, allowed=allowed, fitted=fitted))
    first, last = passes[0], passes[-1]
    out = replace(result, skipped=result.skipped + last.notes)
    out.extra["closed_gaps"] = {
        **last.as_dict(), "open_edges_before": first.open_before,
        "largest_gap_before": first.largest_before, "passes": len(passes),
        "faces_moved": [m for p in passes for m in p.moved],
        "faces_retrimmed": [m for p in passes for m in p.retrimmed]}
    if not any(p.moved or p.retrimmed for p in passes):
        return out
    shape = result.model.shape
    return replace(out, tight_free_edges_after=gaps_in_geometry(shape, TIGHT_FACTOR * size).free_in_geometry,
                   valid_after=is_valid(shape), max_edge_tolerance=max_edge_tolerance(shape))


def _unchanged(open_: list, largest: float, notes: list[str], why: str) -> ClosedGaps:
    return ClosedGaps(len(open_), len(open_), largest, largest, notes=(*notes, why))


# ------------------------------------------------------------------ fitting
@dataclass
class _Common:
    """An edge's common curve: ``points`` C(t) at ``t`` (the reference face's pcurve
    parameters), and per (face, seam side) of a moving face its new pcurve's samples and,
    where it does not go to C, where its side goes."""

    t: NDArray
    points: NDArray
    even: NDArray                                 # indices of the evenly spaced samples
    curve: NurbsCurve | None = None               # C: the cubic through the even samples
    uv: dict = field(default_factory=dict)        # (face, seam side) -> (m, 2)
    goals: dict = field(default_factory=dict)     # (face, seam side) -> (m, 3), else points
    retrimmed: dict = field(default_factory=dict)  # fixed face re-trimmed -> its boundary's shift


def _fit_round(moving: list[int], trimmable: set[int], dense: set[int], surfaces,
               edges: list[SharedEdge], of_face, faces, tight: float, allowed: float,
               notes: list[str], done: dict, fitted: dict):
    """Fit every face of ``moving`` onto the common curves of its edges, the other faces
    fixed (those of ``trimmable`` re-trimmed where that closes an edge better); the
    faces of ``dense``, and those whose fit misses, on ``_DENSER`` times the samples:
    ``({face: (EdgeFit, moved)}, {id(edge): _Common}, {vertex: position}, failed faces,
    {re-trimmed face: how far its boundary moved})``. ``done`` holds the common curves
    of earlier rounds, by edge, the faces that move or may be re-trimmed and the
    vertices; ``fitted`` the fits, by face, surface and targets (a face whose neighbours
    all stayed as they were gets the same targets again)."""
    moving_set = set(moving)
    s = _samples()
    touched = {id(e): e for f in moving for e in of_face[f]}
    # open edges between faces that do not move, one of which may be re-trimmed
    touched.update((id(e), e) for e in edges
                   if e.gap > tight and not any(f in moving_set for f in e.faces)
                   and any(f in trimmable for f in e.faces))
    images: dict[tuple[int, int], NDArray] = {}

    def image(e: SharedEdge, i: int, at: NDArray, reverse: bool = False) -> NDArray:
        f = e.faces[i]
        if f in moving_set:
            uv = pcurve_points(e, i, faces, at, reverse)
            return surfaces[f].evaluate(uv[:, 0], uv[:, 1])
        return images_on_face(e, i, faces, at, reverse)

    for e in touched.values():
        for i in range(len(e.faces)):
            images[id(e), i] = image(e, i, s)
    position = _vertex_positions(touched.values(), edges, moving_set, images, image)
    commons = {}
    for key, e in touched.items():
        # the same when its faces move, may be re-trimmed or stay as in an earlier round
        # and its vertices are where they were
        seen = (key, tuple(f in moving_set for f in e.faces), tuple(f in trimmable for f in e.faces),
                position[e.first].tobytes(), position[e.last].tobytes())
        if seen not in done:
            done[seen] = _common(e, s, images, position, moving_set, trimmable, surfaces, faces,
                                 tight, allowed)
        if done[seen] is not None:
            commons[key] = done[seen]
    retrimmed: dict[int, float] = {}
    for common in commons.values():
        for f, shift in common.retrimmed.items():
            retrimmed[f] = max(retrimmed.get(f, 0.0), shift)
    fits, failed = {}, set()
    many = _samples(_DENSER)
    for f in moving:
        targets = _targets(f, of_face, commons, surfaces, faces, position, s)
        offset = max(float(np.max(np.linalg.norm(
            surfaces[f].evaluate(t.uv[:, 0], t.uv[:, 1]) - t.points, axis=1))) for t in targets)
        if offset <= _STILL * tight:        # its edges are on it already: the surface stays
            fits[f] = (EdgeFit(surfaces[f], offset, 0.0, 0, True), 0.0)
            continue
        if offset > allowed + _FIT_SHARE * tight:
            # a point of its edges would move farther than allowed: no fit can pass
            failed.add(f)
            notes.append(f"face {f - 1}: not moved onto its neighbours' edges (it would move "
                         f"at least {offset:.3g} > {allowed:.3g}: its edges lie that far from "
                         "them); kept as it is")
            continue
        try:
            fit, moved = _fit(f, targets, surfaces, faces, tight, fitted)
            if f in dense or not fit.converged and moved <= allowed:
                # on many samples, from the knots the few found (t4m: 14 -> s)
                fit, moved = _fit(f, _targets(f, of_face, commons, surfaces, faces, position, many),
                                  surfaces, faces, tight, fitted, like=fit.surface)
        except (SurfprepError, np.linalg.LinAlgError, RuntimeError) as exc:
            # (a least-squares or factorization failure of scipy/numpy on this
            # face's system is this face's failure, not the model's)
            failed.add(f)
            notes.append(f"face {f - 1}: not moved onto its neighbours' edges "
                         f"({type(exc).__name__}: {exc}); kept as it is")
            continue
        if fit.converged and moved <= allowed:
            fits[f] = (fit, moved)
            continue
        failed.add(f)
        why = (f"it would move {moved:.3g} > {allowed:.3g}" if moved > allowed
               else f"its fit leaves {fit.residual:.3g} > {_FIT_SHARE * tight:.3g}")
        notes.append(f"face {f - 1}: not moved onto its neighbours' edges ({why}); kept as it is")
    return fits, commons, position, failed, retrimmed


def _samples(density: int = 1) -> NDArray:
    """Where the edges are sampled in [0, 1]: ``density`` x (``FIT_SAMPLES`` - 1) + 1 even
    samples and as many Chebyshev-Lobatto points, dense at the vertices too, where two
    edges' targets meet in a kink the fit resolves only with short knot spans (each
    holding enough samples)."""
    n = density * (FIT_SAMPLES - 1) + 1
    return np.union1d(np.linspace(0.0, 1.0, n), 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, n)))


def _targets(f: int, of_face, commons, surfaces, faces, position, at: NDArray) -> list[EdgeTarget]:
    """Where moving face ``f``'s edges must go, sampled at ``at``: the common curves' own
    samples when ``at`` is theirs, else each common curve evaluated at ``at`` and
    projected onto the face as :func:`_common` does (a closed edge: the face's own
    side, its ends at the vertices)."""
    targets = []
    for e in of_face[f]:
        common = commons.get(id(e))
        if common is None:          # (an edge of a fixed face only re-trimmed)
            continue
        i = e.faces.index(f)
        own = at.size == common.t.size     # (the samples of one density are one array)
        for side in ((False, True) if e.seam else (False,)):
            if own:
                uv = common.uv.get((f, side))
                if uv is None:      # a pole: the old pcurve, every point to the vertex
                    uv = pcurve_points(e, i, faces, at, side)
                targets.append(EdgeTarget(uv, common.goals.get((f, side), common.points)))
                continue
            guess = pcurve_points(e, i, faces, at, side)
            if common.curve is None:            # a pole
                targets.append(EdgeTarget(guess, np.repeat(position[e.first][None], at.size, axis=0)))
            elif (f, side) in common.goals:     # a closed edge: the face keeps its side
                own_side = surfaces[f].evaluate(guess[:, 0], guess[:, 1])
                targets.append(EdgeTarget(guess, _to_vertices(own_side, at, position[e.first],
                                                              position[e.last])))
            else:
                t = common.t[0] + at * (common.t[-1] - common.t[0])
                points = common.curve.evaluate(t)
                targets.append(EdgeTarget(_uv_on(surfaces[f], points, guess, at), points))
    return targets


def _fit(f: int, targets: list[EdgeTarget], surfaces, faces, tight: float, fitted: dict,
         like: NurbsSurface | None = None):
    """``(EdgeFit, how far it moved)`` of face ``f`` onto ``targets``, remembered in
    ``fitted`` by face, surface and targets; with ``like`` (an earlier fit's surface)
    started from the face's surface refined to its degrees and knots."""
    key = (f, _digest(targets, surfaces[f]))
    if key not in fitted:
        start = surfaces[f] if like is None else _refined_like(surfaces[f], like)
        fit = fit_to_edges(start, targets, tol=_FIT_SHARE * tight)
        fitted[key] = fit, _moved(surfaces[f], fit.surface, faces, f)
    return fitted[key]


def _refined_like(surface: NurbsSurface, like: NurbsSurface) -> NurbsSurface:
    """``surface`` (the same geometry) with the degrees and knots of ``like``, a fit of
    it: degrees raised to ``like``'s, then the knots ``like`` has more inserted."""
    out = surface.elevate_degree(like.degree_u - surface.degree_u, like.degree_v - surface.degree_v)
    for direction, have, want in (("u", out.knots_u, like.knots_u), ("v", out.knots_v, like.knots_v)):
        more = Counter(want.tolist()) - Counter(have.tolist())
        if more:
            out = out.refine(np.array(sorted(more.elements())), direction)
    return out


def _to_vertices(curve: NDArray, s: NDArray, start: NDArray, end: NDArray) -> NDArray:
    """``curve`` (m, 3) at ``s`` (m,) with its ends' shifts onto the vertices ``start``
    and ``end`` blended by ``3 s^2 - 2 s^3``: level at both ends, so the targets of two
    edges in line keep one slope through their vertex (a kink there the fit resolves
    only with ever shorter knot spans)."""
    w = (s * s * (3.0 - 2.0 * s))[:, None]
    return curve + (1.0 - w) * (start - curve[0]) + w * (end - curve[-1])


def _uv_on(surface: NurbsSurface, points: NDArray, guess: NDArray, s: NDArray) -> NDArray:
    """Parameters of a moving face's new pcurve: ``points`` (m, 3) at ``s`` projected onto
    ``surface`` from its old pcurve ``guess`` (m, 2), its ends where they were, within the
    domain."""
    uv = pinned_ends(spread_ends(on_surface(surface, points, guess, s), s), guess, s)
    u0, u1, v0, v1 = surface.domain
    return np.stack([np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)], axis=1)


def _digest(targets: list[EdgeTarget], surface: NurbsSurface) -> bytes:
    """A fingerprint of ``targets`` and ``surface`` (their arrays' bytes)."""
    h = hashlib.blake2b(digest_size=16)
    for array in (surface.control_points, surface.knots_u, surface.knots_v, surface.weights):
        if array is not None:
            h.update(np.ascontiguousarray(array).tobytes())
    for t in targets:
        h.update(t.uv.tobytes())
        h.update(t.points.tobytes())
    return h.digest()


def _common(e: SharedEdge, s: NDArray, images, position, moving: set[int], trimmable: set[int],
            surfaces, faces, tight: float, allowed: float) -> _Common | None:
    """The common curve of ``e`` (the module doc), its ends pulled onto the vertices.
    An edge open at ``tight``: where a fixed face may be re-trimmed, the other face's image
    or its feet on the fixed face's surface when :func:`_retrim` finds them better (None
    when no face of ``e`` moves and none can be re-trimmed so); else a fixed face's image
    if it has one, else the image of the
    face whose boundary lies nearest the other faces' surfaces and is smoothest
    (:func:`~surfprep.algorithms.healing.edge_targets.roughness`: a wavy pcurve
    beside a smooth one loses), as it is when it lies
    on them within ``_FIT_SHARE`` x ``tight``, or midway to its feet on them; projected
    onto every moving face, which goes to it. A free edge, or one already closed at
    ``tight``: the mean of its faces' images, each moving face holding its own side
    (only its ends follow the vertices)."""
    still = [i for i, f in enumerate(e.faces) if f not in moving]
    if e.degenerated:
        a, b = e.ranges[0]
        return _Common(a + s * (b - a), np.repeat(position[e.first][None], s.size, axis=0),
                       _even(s))
    def to_vertices(curve: NDArray) -> NDArray:
        return _to_vertices(curve, s, position[e.first], position[e.last])

    closed = len(e.faces) == 1 or e.gap <= tight
    trimmed = None
    if closed:
        ref = still[0] if still else 0
        mean = np.mean([images[id(e), i] for i in range(len(e.faces))], axis=0)
    elif still:
        ref = still[0]
        mean = images[id(e), ref]
        option = _retrim(e, s, images, position, moving, trimmable, surfaces, faces, tight,
                         allowed)
        retrim = None if option is None else _on_retrimmed(e, s, option, position, faces, tight)
        if retrim is not None:
            ref, mean, trimmed = option
        elif not any(f in moving for f in e.faces):
            return None
    else:
        best = None
        for ref in range(len(e.faces)):
            base = images[id(e), ref]
            feet = [_feet(e, i, base, images, surfaces, faces, s)
                    for i in range(len(e.faces)) if i != ref]
            score = (max(float(np.max(np.linalg.norm(foot - base, axis=1))) for foot in feet)
                     + _ROUGHNESS_WEIGHT * roughness(base, s))
            if best is None or score < best[0]:
                best = (score, ref, base, feet)
        score, ref, base, feet = best
        mean = base if score <= _FIT_SHARE * tight else np.mean([base, *feet], axis=0)
    a, b = e.ranges[ref]
    t, even = a + s * (b - a), _even(s)
    # the targets are the edge's curve (the cubic through the even samples) at every
    # sample: points mixing feet and images can wave between the even samples, and a
    # face fitted to them would lie off its edge there
    if trimmed is not None:
        curve, uv = retrim
        common = _Common(t, curve.evaluate(t), even, curve)
        common.uv[e.faces[trimmed], False] = uv
        common.retrimmed[e.faces[trimmed]] = float(np.max(np.linalg.norm(
            curve.evaluate(t) - images[id(e), trimmed], axis=1)))
    else:
        curve = _through(t, to_vertices(mean), even)
        common = _Common(t, curve.evaluate(t), even, curve)
    for i, f in enumerate(e.faces):
        if f not in moving:
            continue
        for side in ((False, True) if e.seam else (False,)):
            guess = pcurve_points(e, i, faces, s, side)
            if closed:          # each face keeps its own side, its ends at the vertices
                common.uv[f, side] = guess
                common.goals[f, side] = to_vertices(images[id(e), i])
                continue
            common.uv[f, side] = _uv_on(surfaces[f], common.points, guess, s)
    return common


def _retrim(e: SharedEdge, s: NDArray, images, position, moving: set[int], trimmable: set[int],
            surfaces, faces, tight: float, allowed: float) -> tuple[int, NDArray, int] | None:
    """A common curve for the open two-face edge ``e`` lying on the surface of a face
    that does not move but may be re-trimmed (``trimmable``), as ``(ref, points, j)``:
    the other face ``ref``'s image, or its feet on face ``j``'s surface, to which ``j``
    is re-trimmed. A fixed ``ref`` qualifies when its image lies on ``j``'s surface
    within ``_FIT_SHARE`` x ``tight`` (the two surfaces meet along it); a moving one
    when its feet lie within ``allowed``, and it wins against ``j``'s own boundary
    (the common curve otherwise) when its distance plus its waves
    (:func:`~surfprep.algorithms.healing.edge_targets.roughness`) are smaller. The
    re-trimmed boundary may shift by ``allowed`` at most, and its ends stay: ``j``'s
    corners must be at the vertices (within ``_FIT_SHARE`` x ``tight``; its other edges
    end there). None when nothing qualifies."""
    if len(e.faces) != 2 or e.seam or e.degenerated:
        return None
    best = None
    for j in (0, 1):
        if e.faces[j] not in trimmable:
            continue
        i = 1 - j
        own = images[id(e), j]
        if max(float(np.linalg.norm(own[0] - position[e.first])),
               float(np.linalg.norm(own[-1] - position[e.last]))) > _FIT_SHARE * tight:
            continue
        base = images[id(e), i]
        _, feet = feet_on_face(e, j, faces, base, s)
        off = float(np.max(np.linalg.norm(feet - base, axis=1)))
        if float(np.max(np.linalg.norm(feet - own, axis=1))) > allowed:
            continue
        if e.faces[i] not in moving:
            if off <= _FIT_SHARE * tight and (best is None or off < best[0]):
                best = (off, i, base, j)
            continue
        if off > allowed:
            continue
        points = base if off <= _FIT_SHARE * tight else feet
        score = off + _ROUGHNESS_WEIGHT * roughness(points, s)
        kept = (float(np.max(np.linalg.norm(_feet(e, i, own, images, surfaces, faces, s) - own,
                                            axis=1)))
                + _ROUGHNESS_WEIGHT * roughness(own, s))
        if score < kept and (best is None or score < best[0]):
            best = (score, i, points, j)
    return None if best is None else best[1:]


def _on_retrimmed(e: SharedEdge, s: NDArray, option: tuple[int, NDArray, int], position,
                  faces, tight: float):
    """The common curve of ``e`` for a :func:`_retrim` option ``(ref, points, j)`` and face
    ``j``'s new pcurve samples: ``points`` with their ends' shifts onto the vertices
    (:func:`_to_vertices`), put back onto ``j``'s surface (off a plane the shifts,
    faded over the whole edge, take the curve off it: kcs by up to 5e-3), the cubic
    through them, its feet on ``j`` with ``j``'s ends where they were. None when that
    curve lies off ``j``'s surface by more than ``_FIT_SHARE`` x ``tight`` (beyond the
    border of its domain, where the feet stop)."""
    ref, points, j = option
    a, b = e.ranges[ref]
    t = a + s * (b - a)
    goal = feet_on_face(e, j, faces, _to_vertices(points, s, position[e.first], position[e.last]),
                        s)[1]
    curve = _through(t, goal, _even(s))
    on = curve.evaluate(t)
    uv, feet = feet_on_face(e, j, faces, on, s)
    if float(np.max(np.linalg.norm(feet - on, axis=1))) > _FIT_SHARE * tight:
        return None
    return curve, pinned_ends(uv, pcurve_points(e, j, faces, s), s)


def _even(s: NDArray) -> NDArray:
    """Indices of the evenly spaced samples among ``s`` (:data:`FIT_SAMPLES` of them)."""
    return np.searchsorted(s, np.linspace(0.0, 1.0, FIT_SAMPLES))


def _through(t: NDArray, points: NDArray, even: NDArray):
    """The cubic interpolating ``points`` at the evenly spaced ``t`` (the samples
    clustered at the ends would make the interpolation ill-conditioned)."""
    return interpolate_curve(points[even], parameters=t[even])


def _feet(e: SharedEdge, i: int, points: NDArray, images, surfaces, faces, s: NDArray) -> NDArray:
    """Closest points of moving face ``e.faces[i]``'s surface to ``points`` (started from
    its pcurve at the same parameters); where one lands farther than twice the edge's
    gap (a wrong local minimum), the face's own point there."""
    foot = project_to_surface(surfaces[e.faces[i]], points, guess=pcurve_points(e, i, faces, s)).points
    far = np.linalg.norm(foot - points, axis=1) > 2.0 * e.gap + 1e-12
    foot[far] = images[id(e), i][far]
    return foot


def _vertex_positions(around, edges: list[SharedEdge], moving: set[int], images, image
                      ) -> dict[int, NDArray]:
    """Per vertex of an edge of ``around``: the mean of its faces' corners there (of the
    fixed faces' if any)."""
    wanted = {v for e in around for v in (e.first, e.last)}
    corners: dict[int, list[tuple[bool, NDArray]]] = {v: [] for v in wanted}
    ends = np.array([0.0, 1.0])
    for e in edges:
        if e.first not in wanted and e.last not in wanted:
            continue
        for i, f in enumerate(e.faces):
            got = images.get((id(e), i))
            pts = got[[0, -1]] if got is not None else image(e, i, ends)
            for v, p in ((e.first, pts[0]), (e.last, pts[1])):
                if v in corners:
                    corners[v].append((f not in moving, p))
    out = {}
    for v, items in corners.items():
        fixed = [p for still, p in items if still]
        out[v] = np.mean(fixed if fixed else [p for _, p in items], axis=0)
    return out


def _moved(before: NurbsSurface, after: NurbsSurface, faces, f: int) -> float:
    """Largest distance between ``before`` and ``after`` at equal parameters over the
    face's parameter box (a grid of ``_MOVE_GRID``^2)."""
    u0, u1, v0, v1 = BRepTools.UVBounds_s(TopoDS.Face_s(faces.FindKey(f)))
    a0, a1, b0, b1 = before.domain
    u = np.clip(np.linspace(u0, u1, _MOVE_GRID), a0, a1)
    v = np.clip(np.linspace(v0, v1, _MOVE_GRID), b0, b1)
    return float(np.max(np.linalg.norm(after.evaluate_grid(u, v) - before.evaluate_grid(u, v),
                                       axis=-1)))


# ------------------------------------------------------------------ applying
def _apply(fits, retrimmed, commons, edges: list[SharedEdge], of_face, faces, vertices, positions,
           journal: _Journal, surfaces) -> tuple[dict[int, float], dict[tuple[int, int], float]]:
    """Put the moved surfaces, their pcurves (the common curves' projections), the
    re-trimmed faces' new pcurves, the common curves and the vertices into the shape,
    recording in ``journal`` what they
    replace; returns per edge touched twice the largest distance, on ``CHECK_SAMPLES``
    points, between its curve and its faces' surfaces (a bound on how far apart two of
    its faces' points are; its tolerance is set to 1.1 times that distance), and that
    distance per edge and face."""
    builder = BRep_Builder()
    by_id = {id(e): e for e in edges}
    # the faces' surfaces as they are now (the fixed ones' as read, the moved ones' put)
    fresh = {f: pair for f, pair in (edges[0].surfaces if edges else {}).items() if f not in fits}
    for f in [*fits, *sorted(retrimmed)]:
        fit = fits[f][0] if f in fits else None
        face = TopoDS.Face_s(faces.FindKey(f))
        location = TopLoc_Location()
        raw = BRep_Tool.Surface_s(face, location)
        old, new = [], []
        for e in of_face[f]:
            i = e.faces.index(f)
            tol = BRep_Tool.Tolerance_s(e.edge)
            old.append((e, pcurve(e, i, faces), pcurve(e, i, faces, True) if e.seam else None, tol,
                        BRep_Tool.Range_s(e.edge, face)))
            common = commons.get(id(e))
            if common is None or (f, False) not in common.uv:
                new.append(old[-1])             # a pole, or an edge not re-trimmed
                continue
            pcurves = [curve2d_to_occ(_through(common.t, common.uv[f, side], common.even))
                       for side in ((False, True) if e.seam else (False,))]
            new.append((e, pcurves[0], pcurves[1] if e.seam else None, tol,
                        (float(common.t[0]), float(common.t[-1]))))
        journal.faces.append((face, raw, location, BRep_Tool.Tolerance_s(face), old))
        if fit is not None and fit.surface is not surfaces[f]:     # else only its pcurves change
            put = surface_to_occ(fit.surface)
            builder.UpdateFace(face, put, TopLoc_Location(), BRep_Tool.Tolerance_s(face))
            fresh[f] = (put, fit.surface)
        _put_pcurves(builder, face, new)
    check = np.linspace(0.0, 1.0, CHECK_SAMPLES)
    after: dict[int, float] = {}
    apart: dict[tuple[int, int], float] = {}
    fixer = ShapeFix_ShapeTolerance()
    for key, common in commons.items():
        e = by_id[key]
        location = TopLoc_Location()
        t0, t1 = BRep_Tool.Range_s(e.edge)
        journal.edges.append((e.edge, None if e.degenerated else BRep_Tool.Curve_s(e.edge, location, 0.0, 0.0),
                              location, t0, t1, BRep_Tool.Tolerance_s(e.edge)))
        deviation = 0.0
        if not e.degenerated:
            curve = common.curve
            builder.UpdateEdge(e.edge, curve_to_occ(curve), TopLoc_Location(), BRep_Tool.Tolerance_s(e.edge))
            a, b = float(common.t[0]), float(common.t[-1])
            builder.Range(e.edge, a, b, True)
            now = replace(e, ranges=[BRep_Tool.Range_s(e.edge, TopoDS.Face_s(faces.FindKey(f)))
                                     for f in e.faces], curves={}, surfaces=fresh)
            on_curve = curve.evaluate(a + check * (b - a))
            for i, f in enumerate(e.faces):
                for side in ((False, True) if e.seam else (False,)):
                    off = float(np.max(np.linalg.norm(images_on_face(now, i, faces, check, side)
                                                      - on_curve, axis=1)))
                    apart[key, f] = max(apart.get((key, f), 0.0), off)
                    deviation = max(deviation, off)
        after[key] = 2.0 * deviation
        fixer.SetTolerance(e.edge, max(1.1 * deviation, _MIN_TOLERANCE), TopAbs_EDGE)
    moved = _moved_vertices(commons, by_id)
    for v, p in positions.items():
        if v not in moved:          # (a vertex of an edge no face was fitted or re-trimmed to)
            continue
        vertex = TopoDS.Vertex_s(vertices.FindKey(v))
        journal.vertices.append((vertex, BRep_Tool.Pnt_s(vertex), BRep_Tool.Tolerance_s(vertex)))
        builder.UpdateVertex(vertex, gp_Pnt(*p), BRep_Tool.Tolerance_s(vertex))
        fixer.SetTolerance(vertex, _MIN_TOLERANCE, TopAbs_VERTEX)
    # the vertices hold every curve's end there, on the fixed faces' edges too
    for g in _around(set(fits) | set(retrimmed), of_face, edges, moved):
        BRepLib.UpdateTolerances_s(faces.FindKey(g), False)
    return after, apart


def _widening(edges: list[SharedEdge], fits, after: dict[int, float],
              apart: dict[tuple[int, int], float], tight: float) -> set[int]:
    """The faces of ``fits`` (moved or re-trimmed) to blame for the edges that end wider
    than ``_WIDER`` times their gap (or ``tight``): those lying alone far enough from
    the edge's curve to widen it, else all its changed faces (a closed edge next to one
    waving face keeps its other, well-fitted face moving)."""
    blamed: set[int] = set()
    for e in edges:
        limit = _WIDER * max(e.gap, tight)
        if after.get(id(e), 0.0) <= limit:
            continue
        moving = [f for f in e.faces if f in fits]
        alone = {f for f in moving if 2.0 * apart.get((id(e), f), 0.0) > limit}
        blamed |= alone or set(moving)
    return blamed


def _invalid(fits, of_face, faces, edges: list[SharedEdge], vertices: set[int]) -> set[int]:
    """The faces of ``fits`` (moved or re-trimmed) that fail ``BRepCheck``, and those
    next to another face that fails it once they changed (its vertices moved with
    them: ``vertices``)."""
    bad = set()
    for g in _around(fits, of_face, edges, vertices):
        if BRepCheck_Analyzer(faces.FindKey(g)).IsValid():
            continue
        if g in fits:
            bad.add(g)
            continue
        near = {h for e in of_face[g] for h in e.faces if h in fits}
        if not near:                # it meets the changed faces at a moved vertex only
            ends = {v for e in of_face[g] for v in (e.first, e.last)} & vertices
            near = {h for e in edges if e.first in ends or e.last in ends
                    for h in e.faces if h in fits}
        bad |= near
    return bad


def _moved_vertices(commons, by_id) -> set[int]:
    """The vertices of the edges given common curves (those :func:`_apply` moves)."""
    return {v for key in commons for v in (by_id[key].first, by_id[key].last)}


def _around(fits, of_face, edges: list[SharedEdge] = (), vertices: set[int] = frozenset()
            ) -> set[int]:
    """The faces of ``fits`` (moved or re-trimmed), the faces sharing an edge with one and
    those with an edge ending at one of ``vertices`` (moved)."""
    return ({g for f in fits for e in of_face[f] for g in e.faces}
            | {g for e in edges if e.first in vertices or e.last in vertices for g in e.faces})


def _put_pcurves(builder, face, pcurves) -> None:
    """Each edge's pcurve(s) on ``face`` (its surface as it now is) over its range (a new
    pcurve takes the 3D curve's range, or a line's infinite one on a pole)."""
    for e, forward, backward, tol, (first, last) in pcurves:
        if backward is not None:
            builder.UpdateEdge(TopoDS.Edge_s(e.edge.Oriented(TopAbs_FORWARD)), forward, backward,
                               face, tol)
        else:
            builder.UpdateEdge(e.edge, forward, face, tol)
        builder.Range(e.edge, face, first, last)


def _undo(journal: _Journal, shape) -> None:
    """Everything :func:`_apply` changed, put back (and the pcurves on the surfaces no
    face has any more dropped)."""
    builder, fixer = BRep_Builder(), ShapeFix_ShapeTolerance()
    for vertex, point, tol in reversed(journal.vertices):
        builder.UpdateVertex(vertex, point, tol)
        fixer.SetTolerance(vertex, tol, TopAbs_VERTEX)
    for edge, curve, location, t0, t1, tol in reversed(journal.edges):
        if curve is not None:
            builder.UpdateEdge(edge, curve, location, tol)
            builder.Range(edge, t0, t1, True)
        fixer.SetTolerance(edge, tol, TopAbs_EDGE)
    for face, raw, location, tol, pcurves in reversed(journal.faces):
        builder.UpdateFace(face, raw, location, tol)
        _put_pcurves(builder, face, pcurves)
    BRepTools.RemoveUnusedPCurves_s(shape)
