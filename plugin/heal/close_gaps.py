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
  any: analytic faces, and B-spline faces whose move failed); where those fixed
  corners lie apart (a gap between two fixed faces that stays open), the faces there
  are grouped along their narrowest edges and each group's edges end at its own fixed
  corners' mean, the vertex's tolerance covering the groups;
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
* where no face of an open edge moves (neither is a B-spline, or the B-spline's move
  failed), one that is not a B-spline is approximated in its own parameters (a bicubic
  interpolant within ``ANALYTIC_SHARE`` x ``tight`` of it, so its pcurves stay valid)
  and moved, in a last pass after re-trimming, which keeps it exact, was tried (the two
  tori of occt_k1geo_microstation.stp, 2e-4 mm apart);
* a free edge, or a shared one closed already, is held: each moving face keeps its side
  there (its ends follow the vertices), the edge's curve is the mean of its faces';
* a face whose fit misses by more than ``FIT_SHARE`` x ``tight``, would move farther
  than ``allowed`` within its parameter box (its shape, by closest points: a corner
  keeps its parameters, so a vertex that slid along the boundary stretches the surface
  along itself, which moves the shape far less), or fails ``BRepCheck`` once moved (or
  makes a neighbour fail it) is kept as it was and the others fitted again with it
  fixed; a re-trimmed face that fails so keeps its trimming too.

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
from OCP.Geom import Geom_BSplineSurface
from OCP.gp import gp_Pnt
from OCP.ShapeFix import ShapeFix_ShapeTolerance
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from ...algorithms.face_region import FaceRegion
from ...algorithms.healing.edge_fit import EdgeFit, EdgeTarget, fit_to_edges
from ...algorithms.measure import normal_turn
from ...algorithms.projection import project_to_surface
from ...algorithms.surface import NurbsSurface
from ...errors import SurfprepError
from ..occ.faces import face_to_nurbs
from ..occ.failures import is_occ_failure
from ..occ.gaps import gaps_in_geometry
from ..occ.geom import curve2d_to_occ, curve_to_occ, surface_to_occ
from ..occ.shapes import check_failures, is_valid, max_edge_tolerance
from .common_curves import (
    FIT_SAMPLES,
    FIT_SHARE,
    FaceCorners,
    common_curve,
    cornered,
    through,
    to_vertices,
    uv_on,
    vertex_positions,
)
from .result import HealResult
from .rollback import FREE_LINES, FREE_SAMPLES, TIGHT_FACTOR
from .shared_edges import (
    SharedEdge,
    analytic_as_nurbs,
    edges_by_face,
    images_on_face,
    pcurve,
    pcurve_points,
    read_edge,
    same_surface,
)

__all__ = ["CHECK_SAMPLES", "FIT_SAMPLES", "FOLD_DEG", "ClosedGaps", "Fitted", "close_gaps",
           "closed_in_geometry"]

#: samples per edge where the gap is first measured (this many evenly and as many
#: clustered at the ends, where an exporter's pcurves wave most: catia theorem's planes
#: lie 2e-5 beside their neighbours at s = 0.003 and within 1.2e-5 at every 1/64) ...
PROBE_SAMPLES = 65
#: ... and where the result is measured (the edges' tolerances; the faces are fitted on
#: :data:`~.common_curves.FIT_SAMPLES`)
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
#: a face whose edges all lie within this share of the tight tolerance of their common
#: curves keeps its surface (only its pcurves change)
_STILL = 1e-3
#: a face that is not a B-spline, moved where no face of an open edge is one, is first
#: approximated in its own parameters within this times ``tight``
ANALYTIC_SHARE = 0.1
#: what the note on the edges no face closes says (a later pass may close some)
_CANNOT = "edges between faces that cannot move"
#: an edge measured wider than this times its gap before (or ``tight``) after the move
#: takes its moved faces back
_WIDER = 2.0
#: passes of close_gaps at most (closed_in_geometry)
_PASSES = 3
#: smallest edge tolerance set
_MIN_TOLERANCE = 1e-7
#: points per direction of the parameter box where a moved face's change is measured
_MOVE_GRID = 41
#: ... and where the angle its tangent planes turned by is measured (and as many
#: again graded towards its sides)
_TURN_GRID = 129
#: faces turned by more than this are said in a note (degrees)
_TURN_NOTED_DEG = 1.0
#: a move that turns a face's tangent planes by more than this (degrees) folds it over:
#: the face is kept as it is (asmo's faces 140, 142 and 188 turned by 93 to 180 degrees
#: where a neighbour's boundary hooks back at a vertex)
FOLD_DEG = 90.0


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
        Per face moved: its index in the shape, how far it moved (over its parameter
        box, :func:`_moved`),
        the fit's residual, the knots inserted, and the largest angle its tangent
        planes turned by inside the face (degrees, :func:`_turned`).
    retrimmed : tuple of dict
        Per face re-trimmed without moving its surface: its index, how far its boundary
        moved along the edges re-trimmed (largest over them).
    notes : tuple of str
    stuck : int
        Edges left open none of whose faces moved, one of them not a B-spline (a call
        with ``stuck=True`` may move that one).
    """

    open_before: int = 0
    open_after: int = 0
    largest_before: float = 0.0
    largest_after: float = 0.0
    moved: tuple = ()
    retrimmed: tuple = ()
    notes: tuple = ()
    stuck: int = 0

    def as_dict(self) -> dict:
        return {"open_edges_before": self.open_before, "open_edges_after": self.open_after,
                "largest_gap_before": self.largest_before, "largest_gap_after": self.largest_after,
                "faces_moved": list(self.moved), "faces_retrimmed": list(self.retrimmed)}


@dataclass
class Fitted:
    """The fits of :func:`close_gaps`, kept across its calls on one shape (the passes of
    :func:`closed_in_geometry`: a face kept in one pass meets mostly the same targets in
    the next, and a fit that failed once applied would fail the same way)."""

    fits: dict = field(default_factory=dict)       # (face, digest of surface, targets) -> (EdgeFit, moved)
    rejected: dict = field(default_factory=dict)   # id(EdgeFit) -> (the fit, why)

    def verdict(self, fit: EdgeFit) -> str | None:
        """Why ``fit`` was taken back once applied: ``"invalid"`` (a face failed
        BRepCheck), ``"folded"`` (its face turned by more than :data:`FOLD_DEG`),
        ``"wider"`` (an edge came out wider than it was), or None."""
        got = self.rejected.get(id(fit))
        return None if got is None else got[1]

    def reject(self, fit: EdgeFit, why: str) -> None:
        self.rejected[id(fit)] = (fit, why)        # (the fit kept: its id stays its own)


@dataclass
class _Remembered:
    """What one :func:`close_gaps` call computes once for all its rounds (a round changes
    a few faces; the rest is asked again)."""

    commons: dict = field(default_factory=dict)    # common curves, by edge, faces' roles, vertices
    images: dict = field(default_factory=dict)     # (edge, i, moving) -> the face's image on the samples
    dense: dict = field(default_factory=dict)      # (face, its edges' common curves) -> dense targets
    # (common curve, face, side) -> (Geom2d pcurve, NurbsCurve); (common curve, None, None) -> Geom curve
    occ: dict = field(default_factory=dict)
    corners: FaceCorners | None = None             # where the faces' edges end in their parameters


@dataclass
class _Turns:
    """How far each fit, once applied, turned its face (:func:`_turned`), measured once
    per fit: a fit kept over several rounds is measured in the first. The samples inside
    a face (:func:`_inside`) are found once per state of its trimming: the common curves
    its edges were put on, ``commons`` of the round (reading a moved face, its pcurves
    interpolants of 1 000 poles, cost 7 of 12 s of asmo's turns; the state matters: the
    KCS hull's face 13 turns by 53 degrees inside its final trimming, by 62 inside the
    trimming of an earlier round)."""

    turned: dict = field(default_factory=dict)     # id(EdgeFit) -> (the fit, degrees)
    inside: dict = field(default_factory=dict)     # (face, its commons) -> (k, 2) inside it

    def of(self, f: int, fit: EdgeFit, before: NurbsSurface, faces, commons: dict,
           of_face) -> float:
        got = self.turned.get(id(fit))
        if got is None:
            # (the common curves are kept alive by the pass's memo: their ids are stable)
            state = (f, tuple(id(commons.get(id(e))) for e in of_face[f]))
            if state not in self.inside:
                self.inside[state] = _inside(faces, f)
            got = self.turned[id(fit)] = (fit, _turned(before, fit.surface, self.inside[state]))
        return got[1]


@dataclass
class _Journal:
    """What was changed, to put it back."""

    faces: list = field(default_factory=list)      # (face, surface, location, tol, pcurves)
    edges: list = field(default_factory=list)      # (edge, curve, location, first, last, tol)
    vertices: list = field(default_factory=list)   # (vertex, point, tol)


def close_gaps(shape, *, tight: float, allowed: float, fitted: Fitted | None = None,
               retrim: bool = True, stuck: bool = False) -> ClosedGaps:
    """Close in the geometry the gaps of ``shape`` (a sewn shell, solid or compound)
    wider than ``tight``, moving B-spline faces by at most ``allowed`` (the module doc),
    and re-trimming the faces that do not move where that closes an edge (unless
    ``retrim`` is False); with ``stuck``, where no face of an open edge can move, one
    that is not a B-spline moves, approximated in its own parameters first
    (:func:`_stuck_movers`). ``shape`` is changed in place. ``fitted`` keeps the fits by
    face, surface and targets across calls on the same shape (the passes of
    :func:`closed_in_geometry`), and those taken back once applied."""
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
    every_open = [e for e in edges if e.gap > tight]
    if not every_open:
        return ClosedGaps()
    largest = max(e.gap for e in every_open)
    # a stuck pass works only along the edges with a face that is not a B-spline (the
    # B-spline faces elsewhere had their passes: on the impeller a whole pass more)
    open_ = [e for e in every_open
             if not stuck or any(not _is_bspline(faces, f) for f in e.faces)]
    if not open_:
        return ClosedGaps(len(every_open), len(every_open), largest, largest)
    notes: list[str] = []
    candidates = sorted({f for e in open_ for f in e.faces})
    surfaces = {f: s for f in candidates if (s := same_surface(faces, f, edges)) is not None}
    of_face = edges_by_face(edges)
    fixed: set[int] = set()
    dense: set[int] = set()             # faces fitted on _DENSER times the samples
    rigid: set[int] = set()             # faces whose re-trimming was taken back
    fits: dict = {}
    retrimmed: dict = {}
    memo = _Remembered()
    fitted = Fitted() if fitted is None else fitted
    failing_before: dict[int, frozenset] = {}   # BRepCheck's findings on the shape as given
    turn = _Turns()
    tried: set[int] = set()             # faces not B-splines approximated to move them
    for _round in range(_ROUNDS):
        more = (_stuck_movers(open_, {f for f in surfaces if f not in fixed}, tried, faces,
                              tight) if stuck else {})
        if more:
            surfaces.update(more)
            memo.corners = None             # (kept per face of ``surfaces``)
        moving = [f for f in candidates if f in surfaces and f not in fixed]
        trimmable = set(candidates) - set(moving) - rigid if retrim else set()
        if not moving and not any(f in trimmable for e in open_ for f in e.faces):
            break
        fits, commons, positions, failed, retrimmed = _fit_round(
            moving, trimmable, dense, surfaces, edges, of_face, faces, tight, allowed, notes,
            memo, fitted)
        fixed |= failed
        if failed and _round < _ROUNDS - 1 or not (fits or retrimmed):
            continue                # the others fitted again with these where they are
        # (in the last round the faces that fit move, their gaps to the others narrowed)
        journal = _Journal()
        changed = set(fits) | set(retrimmed)
        # what BRepCheck finds on the faces around before they change (a face read
        # invalid, its wire not closed across a file's gap, may still move)
        ends = {v for f in changed for e in of_face[f] for v in (e.first, e.last)}
        for g in _around(changed, of_face, edges, ends) - set(failing_before):
            failing_before[g] = check_failures(faces.FindKey(g))
        try:
            after, apart, moved_vertices = _apply(fits, retrimmed, commons, edges, of_face,
                                                  faces, vertices, positions, journal, surfaces,
                                                  memo.occ)
            # a face whose edge ends farther from its neighbour than before (its surface
            # waving between the fit's samples) is not moved either
            invalid = _invalid(changed, of_face, faces, edges, moved_vertices, failing_before)
            folded = {f for f in fits if fits[f][0].surface is not surfaces[f]
                      and turn.of(f, fits[f][0], surfaces[f], faces, commons, of_face)
                      > FOLD_DEG}
            bad = invalid | folded | _widening(edges, changed, after, apart, tight)
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
        again = (bad & set(fits)) - dense - invalid - folded
        for f in bad & set(fits):
            if fits[f][0].surface is not surfaces[f]:      # (a fit, kept in fitted)
                fitted.reject(fits[f][0], "invalid" if f in invalid else
                              "folded" if f in folded else "wider")
        if folded:
            notes.append(f"faces {sorted(f - 1 for f in folded)} would fold over (their tangent "
                         f"planes turned by more than {FOLD_DEG:g} degrees) once moved onto "
                         "their neighbours' edges: kept as they are")
        if bad - again - folded:
            notes.append(f"faces {sorted(f - 1 for f in bad - again - folded)} fail BRepCheck, "
                         "or leave an edge wider than it was, once moved onto (or re-trimmed "
                         "to) their neighbours' edges: kept as they are")
        dense |= again
        fixed |= (bad & set(fits)) - again
        rigid |= invalid | (bad - set(fits))
        fits, retrimmed = {}, {}
    if not fits and not retrimmed:
        return replace(_unchanged(every_open, largest, notes, f"{len(open_)} {_CANNOT} (not "
                                  "B-spline, or their fit failed) nor be re-trimmed to each "
                                  "other left open"),
                       stuck=_stuck_count(every_open, set(), faces))
    BRepTools.RemoveUnusedPCurves_s(shape)
    moved = tuple({"face": int(f) - 1, "moved": fits[f][1], "residual": fits[f][0].residual,
                   "knots_inserted": fits[f][0].inserted,
                   "turned_deg": turn.of(f, fits[f][0], surfaces[f], faces, commons, of_face)}
                  for f in sorted(fits) if fits[f][0].surface is not surfaces[f])
    trimmed = tuple({"face": int(f) - 1, "moved": retrimmed[f]} for f in sorted(retrimmed))
    converted = sorted(f - 1 for f in tried & set(fits) if fits[f][0].surface is not surfaces[f])
    if converted:
        notes.append(f"faces {converted} (not B-splines) approximated as B-splines in their own "
                     "parameters and moved: no other face closed their open edges")
    left = [e for e in every_open if after.get(id(e), e.gap) > tight]
    return ClosedGaps(len(every_open), len(left), largest,
                      max([after.get(id(e), e.gap) for e in every_open] + list(after.values())),
                      moved, trimmed, tuple(notes),
                      _stuck_count(left, {f for f in fits if fits[f][0].surface is not surfaces[f]},
                                   faces))


def closed_in_geometry(result: HealResult, *, size: float, allowed: float) -> HealResult:
    """``result`` with its gaps closed in the geometry (:func:`close_gaps` on its shape,
    ``tight`` = ``TIGHT_FACTOR`` x ``size``) and its figures measured again: free edges in
    the geometry (:func:`~surfprep.plugin.occ.gaps.gaps_in_geometry`), validity and the
    largest edge tolerance; ``extra["closed_gaps"]`` says what moved. Passes are
    repeated (at most ``_PASSES``) while one moves a face and leaves fewer edges open than
    the one before, but not none: faces kept in one pass meet neighbours that have moved
    in the next. Faces that do not move
    are re-trimmed only in one more pass after those, on the edges still open: a round
    that fails then (a re-trim, or a move next to one, failing BRepCheck) costs none of
    what the moves closed (spaceship: 62 free edges in the geometry, 82 with re-trims
    from the first pass). Where edges stay open with no face moving and one that is not a
    B-spline (``ClosedGaps.stuck``), one more pass moves such faces (``stuck=True``).

    The faces of ``result.model`` are moved in place: ``result`` is the healing's own
    (:func:`~surfprep.plugin.heal.heal` works on a copy of the model it is given, so
    faces that sewing kept as they were are not the caller's)."""
    passes = []
    fitted = Fitted()
    tight = TIGHT_FACTOR * size
    model = result.model
    shape = model.shape
    for _ in range(_PASSES):
        closed = close_gaps(shape, tight=tight, allowed=allowed, fitted=fitted,
                            retrim=False)
        passes.append(closed)
        # (a pass that closed nothing repeats itself: t4m 18 s; and one closing nothing the
        # last left open found nothing new: asmo's second pass, 215 -> 214 after 291 -> 214)
        before = passes[-2].open_after if len(passes) > 1 else closed.open_before
        if not closed.moved or closed.open_after == 0 or closed.open_after >= before:
            break
    if passes[-1].open_after:
        passes.append(close_gaps(shape, tight=tight, allowed=allowed, fitted=fitted))
    notes = passes[-1].notes
    if passes[-1].stuck:
        # where nothing else moves, a face that is not a B-spline does (approximated in its
        # own parameters), after re-trimming, which keeps it exact, was tried; the notes
        # are the last full pass's, but for the count of edges it left open
        passes.append(close_gaps(shape, tight=tight, allowed=allowed, fitted=fitted,
                                 stuck=True))
        notes = tuple(n for n in notes if _CANNOT not in n) + passes[-1].notes
    first, last = passes[0], passes[-1]
    # a face moved in several passes turned by at most the sum of its turns (and by
    # 180 degrees at most)
    turned: dict[int, float] = {}
    for m in (m for p in passes for m in p.moved):
        turned[m["face"]] = min(turned.get(m["face"], 0.0) + m["turned_deg"], 180.0)
    out = replace(result, model=model, skipped=result.skipped + notes + _turn_note(turned))
    out.extra["closed_gaps"] = {
        **last.as_dict(), "open_edges_before": first.open_before,
        "largest_gap_before": first.largest_before, "passes": len(passes),
        "faces_moved": [m for p in passes for m in p.moved],
        "faces_retrimmed": [m for p in passes for m in p.retrimmed],
        "largest_turn_deg": max(turned.values(), default=0.0)}
    if not any(p.moved or p.retrimmed for p in passes):
        return out
    gaps = gaps_in_geometry(shape, TIGHT_FACTOR * size, samples=FREE_SAMPLES)
    out.extra[FREE_LINES] = (gaps.polylines, gaps.owners, gaps.sewn)
    return replace(out, tight_free_edges_after=gaps.free_in_geometry,
                   valid_after=is_valid(shape), max_edge_tolerance=max_edge_tolerance(shape))


def _turn_note(turned: dict[int, float]) -> tuple[str, ...]:
    """The note on the faces whose tangent planes turned by more than
    ``_TURN_NOTED_DEG`` degrees (``turned``: face -> degrees), or none."""
    many = sorted(f for f, angle in turned.items() if angle > _TURN_NOTED_DEG)
    if not many:
        return ()
    worst = max(many, key=turned.__getitem__)
    note = (f"faces {many} turn their tangent planes by more than {_TURN_NOTED_DEG:g} degrees "
            f"where they were moved onto their neighbours' edges (face {worst}: up to "
            f"{turned[worst]:.3g})")
    return (note,)


def _unchanged(open_: list, largest: float, notes: list[str], why: str) -> ClosedGaps:
    return ClosedGaps(len(open_), len(open_), largest, largest, notes=(*notes, why))


# ------------------------------------------------------------------ fitting
def _fit_round(moving: list[int], trimmable: set[int], dense: set[int], surfaces,
               edges: list[SharedEdge], of_face, faces, tight: float, allowed: float,
               notes: list[str], memo: _Remembered, fitted: Fitted):
    """Fit every face of ``moving`` onto the common curves of its edges, the other faces
    fixed (those of ``trimmable`` re-trimmed where that closes an edge better); the
    faces of ``dense``, and those whose fit misses, on ``_DENSER`` times the samples:
    ``({face: (EdgeFit, moved)}, {id(edge): CommonCurve}, VertexPositions, failed faces,
    {re-trimmed face: how far its boundary moved})``. ``memo`` holds what earlier rounds
    computed (the common curves, by edge, the faces that move or may be re-trimmed and
    the vertices; the faces' images; the dense targets); ``fitted`` the fits, by face,
    surface and targets (a face whose neighbours all stayed as they were gets the same
    targets again), and those taken back in an earlier pass: one widening an edge is
    fitted on more samples at once, one failing BRepCheck (or fitted on more samples
    already) leaves its face fixed without being applied again."""
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
        for i, f in enumerate(e.faces):
            # (a moving face's image is its own surface's, as read: the same every round)
            key = (id(e), i, f in moving_set)
            if key not in memo.images:
                memo.images[key] = image(e, i, s)
                memo.images[key].flags.writeable = False
            images[id(e), i] = memo.images[key]
    if memo.corners is None:            # (the faces' pcurves stay as read until applied)
        memo.corners = FaceCorners.of(surfaces, of_face, faces, surfaces)
    position = replace(vertex_positions(touched.values(), edges, moving_set, images, image, tight),
                       corners=memo.corners)
    commons = {}
    for key, e in touched.items():
        # the same when its faces move, may be re-trimmed or stay as in an earlier round
        # and its vertices are where they were
        seen = (key, tuple(f in moving_set for f in e.faces), tuple(f in trimmable for f in e.faces),
                *(p.tobytes() for p in position.ends(e)))
        if seen not in memo.commons:
            memo.commons[seen] = common_curve(e, s, images, position, moving_set, trimmable,
                                              surfaces, faces, tight, allowed)
        if memo.commons[seen] is not None:
            commons[key] = memo.commons[seen]
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
        if offset > allowed + FIT_SHARE * tight:
            # the corners keep their parameters, so a vertex that slid along the face's
            # boundary reads as a move; how far the shape must move is the targets'
            # distance from the surface
            offset = _off_surface(surfaces[f], targets)
        if offset > allowed + FIT_SHARE * tight:
            # a point of its edges would move farther than allowed: no fit can pass
            failed.add(f)
            notes.append(f"face {f - 1}: not moved onto its neighbours' edges (it would move "
                         f"at least {offset:.3g} > {allowed:.3g}: its edges lie that far from "
                         "them); kept as it is")
            continue
        try:
            fit, moved = _fit(f, targets, surfaces, faces, tight, allowed, fitted)
            if (f in dense or fitted.verdict(fit) == "wider"
                    or not fit.converged and moved <= allowed):
                # on many samples, from the knots the few found (t4m: 14 s -> 1 s); the
                # same common curves give the same targets (memo.commons keeps them alive,
                # so their ids are theirs)
                key = (f, tuple(id(commons.get(id(e))) for e in of_face[f]))
                if key not in memo.dense:
                    memo.dense[key] = _targets(f, of_face, commons, surfaces, faces, position, many)
                fit, moved = _fit(f, memo.dense[key], surfaces, faces, tight, allowed, fitted,
                                  like=fit.surface)
        except (SurfprepError, np.linalg.LinAlgError, RuntimeError) as exc:
            # (a least-squares or factorization failure of scipy/numpy on this
            # face's system is this face's failure, not the model's)
            failed.add(f)
            notes.append(f"face {f - 1}: not moved onto its neighbours' edges "
                         f"({type(exc).__name__}: {exc}); kept as it is")
            continue
        verdict = fitted.verdict(fit)
        if verdict is not None:
            failed.add(f)
            why = {"invalid": "failed BRepCheck", "folded": "folded the face over"}.get(
                verdict, "left an edge wider than it was")
            notes.append(f"face {f - 1}: not moved onto its neighbours' edges (the same fit {why} "
                         "in an earlier pass); kept as it is")
            continue
        if fit.converged and moved <= allowed:
            fits[f] = (fit, moved)
            continue
        failed.add(f)
        why = (f"it would move {moved:.3g} > {allowed:.3g}" if moved > allowed
               else f"its fit leaves {fit.residual:.3g} > {FIT_SHARE * tight:.3g}")
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
    projected onto the face as :func:`common_curve` does (a closed edge: the face's own
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
                    uv = cornered(e, i, faces, at, side, position)
                targets.append(EdgeTarget(uv, common.goals.get((f, side), common.points)))
                continue
            guess = cornered(e, i, faces, at, side, position)
            if common.curve is None:            # a pole
                targets.append(EdgeTarget(guess, np.repeat(position.ends(e)[0][None], at.size, axis=0)))
            elif (f, side) in common.goals:     # a closed edge: the face keeps its side
                own_side = surfaces[f].evaluate(guess[:, 0], guess[:, 1])
                targets.append(EdgeTarget(guess, to_vertices(own_side, at, *position.ends(e))))
            else:
                t = common.t[0] + at * (common.t[-1] - common.t[0])
                points = common.curve.evaluate(t)
                targets.append(EdgeTarget(uv_on(surfaces[f], points, guess, at), points))
    return targets


def _fit(f: int, targets: list[EdgeTarget], surfaces, faces, tight: float, allowed: float,
         fitted: Fitted, like: NurbsSurface | None = None):
    """``(EdgeFit, how far it moved)`` of face ``f`` onto ``targets`` (:func:`_moved`,
    measured in the shape when farther than ``allowed`` at equal parameters), remembered
    in ``fitted`` by face, surface and targets; with ``like`` (an earlier fit's surface)
    started from the face's surface refined to its degrees and knots."""
    key = (f, _digest(targets, surfaces[f]))
    if key not in fitted.fits:
        start = surfaces[f] if like is None else _refined_like(surfaces[f], like)
        fit = fit_to_edges(start, targets, tol=FIT_SHARE * tight)
        fitted.fits[key] = fit, _moved(surfaces[f], fit.surface, faces, f, within=allowed)
    return fitted.fits[key]


def _stuck_count(left: list[SharedEdge], moved: set[int], faces) -> int:
    """How many of the edges ``left`` open have no face in ``moved`` and one face that is
    not a B-spline."""
    return sum(1 for e in left if not moved & set(e.faces)
               and any(not _is_bspline(faces, f) for f in e.faces))


def _is_bspline(faces, f: int) -> bool:
    return isinstance(BRep_Tool.Surface_s(TopoDS.Face_s(faces.FindKey(f))), Geom_BSplineSurface)


def _stuck_movers(open_: list[SharedEdge], movable: set[int], tried: set[int], faces,
                  tight: float) -> dict[int, NurbsSurface]:
    """For each open edge none of whose faces can move (not B-splines: two tori of
    occt_k1geo_microstation.stp 2e-4 mm apart; or a B-spline whose move failed, beside
    one), one face not tried yet (added to ``tried``) that is not a B-spline, as a
    B-spline in its own parameters (:func:`.shared_edges.analytic_as_nurbs`, within
    ``ANALYTIC_SHARE`` x ``tight``): the face on the most open edges first, so that one
    moves, not both."""
    out: dict[int, NurbsSurface] = {}
    on_open = Counter(f for e in open_ for f in e.faces)
    for e in open_:
        if any(f in movable or f in out for f in e.faces):
            continue
        for f in sorted(e.faces, key=lambda g: (-on_open[g], g)):
            if f in tried or _is_bspline(faces, f):
                continue
            tried.add(f)
            nurbs = analytic_as_nurbs(faces, f, ANALYTIC_SHARE * tight)
            if nurbs is not None:
                out[f] = nurbs
                break
    return out


def _off_surface(surface: NurbsSurface, targets: list[EdgeTarget]) -> float:
    """Largest distance of the targets' points from ``surface`` (closest points, from
    the targets' parameters): no fit onto them moves the face less."""
    return max(float(np.max(project_to_surface(surface, t.points, guess=t.uv).distance))
               for t in targets)


def _refined_like(surface: NurbsSurface, like: NurbsSurface) -> NurbsSurface:
    """``surface`` (the same geometry) with the degrees and knots of ``like``, a fit of
    it: degrees raised to ``like``'s, then the knots ``like`` has more inserted."""
    out = surface.elevate_degree(like.degree_u - surface.degree_u, like.degree_v - surface.degree_v)
    for direction, have, want in (("u", out.knots_u, like.knots_u), ("v", out.knots_v, like.knots_v)):
        more = Counter(want.tolist()) - Counter(have.tolist())
        if more:
            out = out.refine(np.array(sorted(more.elements())), direction)
    return out


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


def _inside(faces, f: int) -> NDArray:
    """Parameters ``(k, 2)`` inside face ``f``: a grid of ``_TURN_GRID``^2 over its
    parameter box, graded towards the box's sides (where the edges pulled it)."""
    trimmed = face_to_nurbs(TopoDS.Face_s(faces.FindKey(f)))
    u0, u1, v0, v1 = trimmed.parameter_box()
    ends = np.geomspace(1e-6, 1e-2, _TURN_GRID // 8)
    t = np.unique(np.concatenate([np.linspace(0.0, 1.0, _TURN_GRID), ends, 1.0 - ends]))
    u, v = np.meshgrid(u0 + t * (u1 - u0), v0 + t * (v1 - v0), indexing="ij")
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    return uv[FaceRegion(trimmed).contains(uv)]


def _turned(before: NurbsSurface, after: NurbsSurface, uv: NDArray) -> float:
    """Largest angle, in degrees, by which moving a face from ``before`` to ``after``
    turned its tangent planes (:func:`~surfprep.algorithms.measure.normal_turn`) at the
    parameters ``uv`` (k, 2) inside it (:func:`_inside`), poles left out; 0 when there
    is none."""
    if not uv.size:
        return 0.0
    angle = normal_turn(before, after, uv[:, 0], uv[:, 1])
    return float(np.degrees(np.nanmax(angle))) if np.any(np.isfinite(angle)) else 0.0


def _moved(before: NurbsSurface, after: NurbsSurface, faces, f: int, *,
           within: float = np.inf) -> float:
    """How far the face's shape moved from ``before`` to ``after`` over its parameter box
    (a grid of ``_MOVE_GRID``^2): the largest distance at equal parameters, or, when that
    is above ``within``, the larger of the two ways' closest-point distances (each
    sample of one surface to the other, from its own parameters). A fit that keeps a
    corner's parameters while its vertex slid along the boundary stretches the surface
    along itself: two trimmed sheets whose vertices slid 0.015 read that far at equal
    parameters, their shapes within 8e-4 of where they were. (The impeller's faces 5,
    32 and 42, whose edges lie within 0.004 of their common curves but whose corners
    are 0.11 to 0.15 from the vertices, still cannot be stretched there: their fits
    move the shape by 0.7.)"""
    u0, u1, v0, v1 = BRepTools.UVBounds_s(TopoDS.Face_s(faces.FindKey(f)))
    a0, a1, b0, b1 = before.domain
    u = np.clip(np.linspace(u0, u1, _MOVE_GRID), a0, a1)
    v = np.clip(np.linspace(v0, v1, _MOVE_GRID), b0, b1)
    old, new = before.evaluate_grid(u, v).reshape(-1, 3), after.evaluate_grid(u, v).reshape(-1, 3)
    apart = np.linalg.norm(new - old, axis=1)
    if apart.max() <= within:
        return float(apart.max())
    uv = np.stack(np.meshgrid(u, v, indexing="ij"), axis=-1).reshape(-1, 2)
    # (a sample's own point on the other surface bounds its closest point's distance)
    return float(max(np.minimum(project_to_surface(to, p, guess=uv).distance, apart).max()
                     for to, p in ((before, new), (after, old))))


# ------------------------------------------------------------------ applying
def _apply(fits, retrimmed, commons, edges: list[SharedEdge], of_face, faces, vertices, positions,
           journal: _Journal, surfaces, occ: dict
           ) -> tuple[dict[int, float], dict[tuple[int, int], float], set[int]]:
    """Put the moved surfaces, their pcurves (the common curves' projections), the
    re-trimmed faces' new pcurves, the common curves and the vertices into the shape,
    recording in ``journal`` what they
    replace; returns per edge touched twice the largest distance, on ``CHECK_SAMPLES``
    points, between its curve and its faces' surfaces (a bound on how far apart two of
    its faces' points are; its tolerance is set to 1.1 times that distance), and that
    distance per edge and face, and the vertices it moved (those of the edges given a
    common curve). ``occ`` keeps the curves converted for OpenCascade across rounds,
    by common curve, face and seam side (a round puts back mostly the same)."""
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
            pcurves = [_pcurve_to_occ(common, f, side, occ)[0]
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
            if (id(common), None, None) not in occ:
                occ[id(common), None, None] = curve_to_occ(curve)
            builder.UpdateEdge(e.edge, occ[id(common), None, None], TopLoc_Location(),
                               BRep_Tool.Tolerance_s(e.edge))
            a, b = float(common.t[0]), float(common.t[-1])
            builder.Range(e.edge, a, b, True)
            # its pcurves as now put: a new one as converted, an old one as read
            curves = {}
            for i, f in enumerate(e.faces):
                for side in ((False, True) if e.seam else (False,)):
                    if (f, side) in common.uv and (f in fits or f in retrimmed):
                        curves[i, side] = _pcurve_to_occ(common, f, side, occ)[1]
                    elif (i, side) in e.curves:
                        curves[i, side] = e.curves[i, side]
            now = replace(e, ranges=[BRep_Tool.Range_s(e.edge, TopoDS.Face_s(faces.FindKey(f)))
                                     for f in e.faces], curves=curves, surfaces=fresh,
                          feet={})
            on_curve = curve.evaluate(a + check * (b - a))
            for i, f in enumerate(e.faces):
                for side in ((False, True) if e.seam else (False,)):
                    off = float(np.max(np.linalg.norm(images_on_face(now, i, faces, check, side)
                                                      - on_curve, axis=1)))
                    apart[key, f] = max(apart.get((key, f), 0.0), off)
                    deviation = max(deviation, off)
        after[key] = 2.0 * deviation
        fixer.SetTolerance(e.edge, max(1.1 * deviation, _MIN_TOLERANCE), TopAbs_EDGE)
    moved = {v for key in commons for v in (by_id[key].first, by_id[key].last)}
    for v, p in positions.at.items():
        if v not in moved:          # (a vertex of an edge no face was fitted or re-trimmed to)
            continue
        vertex = TopoDS.Vertex_s(vertices.FindKey(v))
        journal.vertices.append((vertex, BRep_Tool.Pnt_s(vertex), BRep_Tool.Tolerance_s(vertex)))
        builder.UpdateVertex(vertex, gp_Pnt(*p), BRep_Tool.Tolerance_s(vertex))
        fixer.SetTolerance(vertex, _MIN_TOLERANCE, TopAbs_VERTEX)
    # the vertices hold every curve's end there, on the fixed faces' edges too
    for g in _around(set(fits) | set(retrimmed), of_face, edges, moved):
        BRepLib.UpdateTolerances_s(faces.FindKey(g), False)
    return after, apart, moved


def _pcurve_to_occ(common, f: int, side: bool, occ: dict):
    """``(Geom2d_BSplineCurve, NurbsCurve)``: face ``f``'s new pcurve along ``common``
    (the cubic through its samples), converted once (kept in ``occ``)."""
    key = (id(common), f, side)
    if key not in occ:
        curve = through(common.t, common.uv[f, side], common.even)
        occ[key] = (curve2d_to_occ(curve), curve)
    return occ[key]


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


def _invalid(fits, of_face, faces, edges: list[SharedEdge], vertices: set[int],
             failing_before: dict[int, frozenset]) -> set[int]:
    """The faces of ``fits`` (moved or re-trimmed) that ``BRepCheck`` finds something new
    wrong with (not in ``failing_before``, face -> :func:`check_failures` before the
    change; a face missing there was valid), and those next to another face with a new
    failure once they changed (its vertices moved with them: ``vertices``)."""
    bad = set()
    for g in _around(fits, of_face, edges, vertices):
        if BRepCheck_Analyzer(faces.FindKey(g)).IsValid():
            continue
        if not check_failures(faces.FindKey(g)) - failing_before.get(g, frozenset()):
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
