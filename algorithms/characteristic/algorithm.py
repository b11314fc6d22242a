"""The algorithm of 002 §6.3 end to end, and the certificate for the triangle method.

:func:`characteristic_analysis` (the *characteristic stage*):

0. ``phi`` on a grid of ``r``'s domain (which surface is ``r`` is chosen by
   :func:`choose_field`); samples with ``|phi| <= tol`` over a patch of the
   grid mean the surfaces coincide there (:class:`CoincidentRegion`: reported,
   nothing traced there: a clear answer instead of a hang);
1. border points (:func:`.points.border_points`);
2. roots of ``phi_u`` and ``phi_v`` on the sides of ``r``'s domain
   (:func:`.points.edge_roots`);
3. the u- and v-characteristic curves traced from them (:mod:`.curves`); a
   sign change of the *other* derivative along one gives a critical point (by
   Newton, :func:`.points.critical_points`), a sign change of ``phi`` a turning
   point, i.e. a start on the intersection. Critical points are also sought
   from a seed grid (the paper's remedy when no side root exists, §5), and the
   characteristic curves through every critical point are traced too, until no
   new critical point appears (capped rounds);
4. from every maximum with ``phi > tol`` and minimum with ``phi < -tol`` (the
   extrema a closed loop must encircle, §4.2), rays along the Hessian's
   eigenvectors, started at the quadratic model's zero distance ``sqrt(2 |phi|
   / |lambda|)``, find a start on the loop around it however small it is;
5. critical points with ``|phi| <= tol`` are singular (eq. 8): an isolated
   point (tangential contact) when ``det H > 0``.

:func:`characteristic_intersection` adds step 4 of §6.3: the intersection
curves traced from every start (:mod:`.trace`). :func:`certify` is the
``auto`` mode: the characteristic stage checks curves found by the triangle
method: every start must lie on one of them; the loops through starts that do
not are traced and added (``FoundBy.CHARACTERISTIC``), and tiny curves around a
tangential contact point are replaced by the isolated point.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..intersection import IntersectionCurve
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from .curves import CurveKind, TracedCurve, curve_value
from .distance import DistanceField, DistanceJet
from .grid import GRID_MAX, GRID_MIN, StageGrid, choose_field, stage_grid
from .points import (
    DEGENERATE_SHARE,
    CharacteristicPoint,
    PointKind,
    border_points,
    classify_critical,
    critical_points,
    grid_seeds,
    make_points,
)
from .poles import pole_contacts
from .projector import ProjectionStatus, Projector
from .ridges import Ridge, ridge_refiner, ridge_starts, trace_ridges
from .starts import (
    Start,
    away_from,
    border_keys,
    loop_keys,
    ray_starts,
    trace_uncovered,
)
from .sweep import from_critical, sweep
from .trace import dense_polyline, polyline_gap, to_intersection_curves

__all__ = [
    "GRID_MAX",
    "GRID_MIN",
    "CharacteristicAnalysis",
    "CharacteristicRecord",
    "CoincidentRegion",
    "FoundBy",
    "certify",
    "characteristic_analysis",
    "characteristic_intersection",
    "choose_field",
    "tangential_curves",
]

#: derivatives of phi below this share of its largest gradient on the grid are rounding
NOISE_SHARE = 1e-9
#: rounds of "trace through new critical points" at most
MAX_ROUNDS = 3
#: a grid share of |phi| <= tol above this means the surfaces coincide over a region
COINCIDENT_SHARE = 0.01


class FoundBy(str, enum.Enum):
    """How an intersection curve was found."""

    MESH = "mesh"
    CHARACTERISTIC = "characteristic"


@dataclass(frozen=True)
class CoincidentRegion:
    """Where two surfaces coincide within ``tol``.

    Attributes
    ----------
    box_a, box_b : (2, 2) float
        ``[[u_min, v_min], [u_max, v_max]]`` of the grid samples with
        ``|phi| <= tol`` on each surface.
    share : float
        Share of ``r``'s grid samples with a regular projection that coincide.
    max_distance : float
        Largest ``|phi|`` among them.
    """

    box_a: NDArray
    box_b: NDArray
    share: float
    max_distance: float


@dataclass(frozen=True)
class CharacteristicAnalysis:
    """What the characteristic stage found (steps 0-5 of the module docstring)."""

    field: DistanceField
    points: tuple[CharacteristicPoint, ...]
    characteristic_curves: tuple[TracedCurve, ...]
    starts: Start
    coincident: tuple[CoincidentRegion, ...]
    time_s: float
    ridges: tuple[Ridge, ...] = ()
    #: smallest sine of the angle between the normals beside a sign change of phi on
    #: the grid (:func:`.crossing.grid_crossing_sine`; inf: phi changes sign nowhere)
    crossing_sine: float = float("inf")

    def of_kind(self, *kinds: PointKind) -> tuple[CharacteristicPoint, ...]:
        return tuple(p for p in self.points if p.kind in kinds)


@dataclass(frozen=True)
class CharacteristicRecord:
    """The answer of :func:`characteristic_intersection` or :func:`certify`, with its record.

    Attributes
    ----------
    curves : tuple of IntersectionCurve
    found_by : tuple of FoundBy
        One per curve.
    isolated_points : tuple of CharacteristicPoint
        Tangential contact points (kind ``ISOLATED``): not curves.
    coincident : tuple of CoincidentRegion
    points : tuple of CharacteristicPoint
        Every characteristic point, all kinds.
    characteristic_curves : tuple of TracedCurve
    phi_on : str
        ``"a"`` or ``"b"``: the surface whose domain ``phi`` lives on.
    characteristic_time_s, intersection_time_s : float
        Time of the characteristic stage and of tracing + refining the curves.
    dropped : int
        Curves of the triangle method replaced by an isolated point.
    """

    curves: tuple[IntersectionCurve, ...]
    found_by: tuple[FoundBy, ...]
    isolated_points: tuple[CharacteristicPoint, ...]
    coincident: tuple[CoincidentRegion, ...]
    points: tuple[CharacteristicPoint, ...]
    characteristic_curves: tuple[TracedCurve, ...]
    phi_on: str
    characteristic_time_s: float
    intersection_time_s: float
    dropped: int = 0
    extra: dict = field(default_factory=dict, repr=False)

    def of_kind(self, *kinds: PointKind) -> tuple[CharacteristicPoint, ...]:
        return tuple(p for p in self.points if p.kind in kinds)

    def counts(self) -> dict[str, int]:
        """Characteristic points per kind (``PointKind.value``)."""
        out: dict[str, int] = {}
        for p in self.points:
            out[p.kind.value] = out.get(p.kind.value, 0) + 1
        return out

    @property
    def added(self) -> tuple[IntersectionCurve, ...]:
        """Curves found only by the characteristic method."""
        return tuple(c for c, f in zip(self.curves, self.found_by) if f is FoundBy.CHARACTERISTIC)


def _coincident(field: DistanceField, jet: DistanceJet, shape: tuple[int, int], tol: float
                ) -> tuple[CoincidentRegion, ...]:
    """The grid cells whose four corners all have a regular projection and ``|phi| <= tol``:
    when they are more than ``COINCIDENT_SHARE`` of the valid cells, the surfaces
    coincide over a region (a curve through grid samples is not a region)."""
    nu, nv = shape
    valid = (jet.status == ProjectionStatus.UNIQUE).reshape(nu, nv)
    near = valid & (np.abs(jet.phi) <= tol).reshape(nu, nv)
    corners = [(slice(0, -1), slice(0, -1)), (slice(1, None), slice(0, -1)),
               (slice(0, -1), slice(1, None)), (slice(1, None), slice(1, None))]
    valid_cells = np.logical_and.reduce([valid[c] for c in corners])
    near_cells = np.logical_and.reduce([near[c] for c in corners])
    if valid_cells.sum() == 0 or near_cells.sum() <= COINCIDENT_SHARE * valid_cells.sum():
        return ()
    mask = np.zeros((nu, nv), dtype=bool)
    for c in corners:
        mask[c] |= near_cells
    mask = mask.ravel()
    ua, ub = field.ab(jet.uv[mask], jet.st[mask])
    box = lambda x: np.stack([x.min(axis=0), x.max(axis=0)])
    return (CoincidentRegion(box(ua), box(ub), float(near_cells.sum() / valid_cells.sum()),
                             float(np.abs(jet.phi[mask]).max())),)


def _sign_changes(curve: TracedCurve, values: NDArray) -> NDArray:
    """Indices ``i`` with a sign change between samples ``i`` and ``i + 1``."""
    s = np.sign(values)
    return np.flatnonzero(s[:-1] * s[1:] < 0)


def _turning_points(field: DistanceField, uv: NDArray, st: NDArray, kind: CurveKind,
                    iterations: int = 12) -> tuple[DistanceJet, NDArray]:
    """Newton on ``(phi, g) = 0`` (g the curve's function): exact turning points (eq. 7)."""
    x = uv.copy()
    jet = field.jet(x, st)
    for _ in range(iterations):
        g, dg = curve_value(jet, kind)
        jac = np.stack([jet.grad, dg], axis=1)                        # (m, 2, 2)
        rhs = -np.stack([jet.phi, g], -1)
        det = np.linalg.det(jac)
        ok = np.abs(det) > 1e-300
        step = np.zeros_like(x)
        if ok.any():
            step[ok] = np.linalg.solve(jac[ok], rhs[ok][..., None])[..., 0]
        x = np.clip(x + step, field.lower, field.upper)
        jet = field.jet(x, jet.st)
        if np.all(np.linalg.norm(step, axis=1) <= 1e-13 * field.diagonal):
            break
    g, _ = curve_value(jet, kind)
    ok = (jet.status == ProjectionStatus.UNIQUE) & (np.abs(g) <= 1e-8 * np.abs(jet.hess).max(
        axis=(1, 2)).clip(1e-300)) & np.all(np.linalg.norm(x - uv, axis=1)[:, None] < 0.1
                                            * field.diagonal, axis=1)
    return jet, ok


# ------------------------------------------------------------------ the stage
def characteristic_analysis(a: NurbsSurface, b: NurbsSurface, *, tol: float,
                            phi_on: str | None = None, trace_critical: bool = True,
                            borders: bool = True, grid: StageGrid | None = None
                            ) -> CharacteristicAnalysis:
    """The characteristic stage (module docstring, steps 0-5).

    ``trace_critical`` False is the ``auto`` certificate's lighter stage: only
    the u-characteristic curves from the sides are traced (a critical point on
    them shows as a sign change of ``phi_v``), none through the critical points
    (those from the seed grid are known already). ``borders`` False skips the
    border points (the certificate checks closed loops). ``grid``: the stage's
    grid when already made (:func:`.grid.stage_grid` with the same ``tol`` and
    ``phi_on``).
    """
    start_time = time.perf_counter()
    tol = check_tolerance(tol)
    staged = grid if grid is not None else stage_grid(a, b, tol=tol, phi_on=phi_on)
    fld, grid, shape = staged.field, staged.jet, staged.shape
    other = DistanceField(fld.q, fld._cache.get("other_projector")
                          or Projector(fld.r, tol=fld.projector.tol), not fld.swapped)
    h_max = 0.15 * fld.diagonal
    coincident = _coincident(fld, grid, shape, tol)
    regular = grid.status == ProjectionStatus.UNIQUE
    noise = NOISE_SHARE * float(np.abs(grid.grad[regular]).max()) if regular.any() else 0.0
    points: list[CharacteristicPoint] = []
    starts: list[Start] = []
    border_start = Start.empty()
    # step 1: border points (starts of open curves; the certificate checks loops only)
    pair = (fld, other) if not fld.swapped else (other, fld)
    bp, bua, bub = border_points(pair, tol) if borders else (np.zeros((0, 3)),) * 3
    if bp.shape[0]:
        uv_r, st_q = (bub, bua) if fld.swapped else (bua, bub)
        points += make_points(fld, PointKind.BORDER, uv_r, st_q, bp, np.zeros(bp.shape[0]))
        border_start = Start(uv_r, st_q, np.full(bp.shape[0], 0.1 * fld.diagonal),
                             np.arange(bp.shape[0]))
    crossing = staged.crossing_sine
    if coincident:
        return CharacteristicAnalysis(fld, tuple(points), (), border_keys(border_start),
                                      coincident, time.perf_counter() - start_time,
                                      crossing_sine=crossing)
    # step 2: roots of phi_u (phi_v) on the sides; step 3: characteristic curves,
    # complete to the grid (sweep.py)
    side_points, swept = sweep(fld, grid, shape, noise, h_max, both=trace_critical)
    points += side_points
    curves: list[TracedCurve] = list(swept)
    # critical points: seed grid, then along the characteristic curves, in rounds
    hess_scale = float(np.abs(grid.hess[regular]).max()) if regular.any() else 0.0
    crit = critical_points(fld, grid_seeds(grid, shape, noise=noise), hess_scale=hess_scale)
    traced_from = 0 if trace_critical else (0 if crit is None else crit.uv.shape[0])
    for _ in range(MAX_ROUNDS):
        seeds = []
        for c in curves:
            other_comp = 1 if c.kind is CurveKind.U_CHARACTERISTIC else 0
            for i in _sign_changes(c, c.grad[:, other_comp]):
                g0, g1 = c.grad[i, other_comp], c.grad[i + 1, other_comp]
                w = g0 / (g0 - g1)
                seeds.append(c.uv[i] + w * (c.uv[i + 1] - c.uv[i]))
        found = critical_points(fld, np.array(seeds), hess_scale=hess_scale) if seeds else None
        merged = _merge_critical(fld, crit, found)
        crit = merged
        if crit is None:
            break
        new = crit.uv.shape[0] - traced_from
        if new <= 0 or not trace_critical:
            break
        rows = np.arange(traced_from, crit.uv.shape[0])
        traced_from = crit.uv.shape[0]
        # through isolated critical points only: a degenerate one lies on a ridge
        # (a curve of critical points, traced by ridges.py), where every point is one
        rows = rows[np.abs(crit.det_hess[rows]) > DEGENERATE_SHARE * np.einsum(
            "mij,mij->m", crit.hess[rows], crit.hess[rows])]
        if rows.size:
            curves += from_critical(fld, _subset(fld, crit, rows), h_max)
    # turning points: sign changes of phi along the characteristic curves
    turning_uv, turning_st, turning_kind, scale = [], [], [], []
    for c in curves:
        for i in _sign_changes(c, c.phi):
            w = c.phi[i] / (c.phi[i] - c.phi[i + 1])
            turning_uv.append(c.uv[i] + w * (c.uv[i + 1] - c.uv[i]))
            turning_st.append(c.st[i])
            turning_kind.append(c.kind)
            scale.append(5 * np.linalg.norm(c.uv[i + 1] - c.uv[i]))
    for kind, pk in ((CurveKind.U_CHARACTERISTIC, PointKind.TURNING_V),
                     (CurveKind.V_CHARACTERISTIC, PointKind.TURNING_U)):
        rows = [i for i, k in enumerate(turning_kind) if k is kind]
        if not rows:
            continue
        jet, ok = _turning_points(fld, np.array([turning_uv[i] for i in rows]),
                                  np.array([turning_st[i] for i in rows]), kind)
        if ok.any():
            points += make_points(fld, pk, jet.uv[ok], jet.st[ok], jet.point[ok], jet.phi[ok])
            n = int(ok.sum())
            starts.append(Start(jet.uv[ok], jet.st[ok], np.array(scale)[rows][ok], np.arange(n)))
    # critical points: classify; rays from the extrema a loop must encircle and
    # across the ridges of degenerate ones (curves of critical points)
    ridges: list[Ridge] = []
    if crit is not None:
        kinds = classify_critical(crit.phi, crit.hess, tol)
        points += make_points(fld, kinds, crit.uv, crit.st, crit.point, crit.phi)
        starts.append(ray_starts(fld, crit, kinds, tol))
        ridges = trace_ridges(fld, crit, kinds, noise / NOISE_SHARE, h_max)
        starts.append(ridge_starts(fld, ridges, tol))
    points += _pole_points(fld, a, b, tol, points)
    start = Start.concat(starts)
    start = Start.stack([Start(start.uv, start.st, start.scale, loop_keys(fld, grid, shape, start)),
                         border_keys(border_start)])
    return CharacteristicAnalysis(fld, tuple(points), tuple(curves), start, (),
                                  time.perf_counter() - start_time, tuple(ridges), crossing)


def _pole_points(fld: DistanceField, a: NurbsSurface, b: NurbsSurface, tol: float,
                 known: list[CharacteristicPoint]) -> list[CharacteristicPoint]:
    """Isolated contacts at collapsed sides (:mod:`.poles`) not already among ``known``."""
    contacts = pole_contacts(a, b, tol=tol)
    radius = max(1e3 * tol, 1e-6 * _size(a, b))
    contacts = [c for c in contacts if not any(
        p.kind is PointKind.ISOLATED and np.linalg.norm(p.point - c.point) <= radius
        for p in known)]
    if not contacts:
        return []
    ua = np.array([c.uv_a for c in contacts])
    ub = np.array([c.uv_b for c in contacts])
    uv_r, st_q = (ub, ua) if fld.swapped else (ua, ub)
    return make_points(fld, PointKind.ISOLATED, uv_r, st_q, np.array([c.point for c in contacts]),
                       np.array([c.distance for c in contacts]))


def _subset(field: DistanceField, jet: DistanceJet, rows: NDArray) -> DistanceJet:
    return field.jet(jet.uv[rows], jet.st[rows])


def _merge_critical(field: DistanceField, old: DistanceJet | None, new: DistanceJet | None
                    ) -> DistanceJet | None:
    """Critical points of ``old`` then the ones of ``new`` not already there."""
    if new is None:
        return old
    if old is None:
        return new
    d = np.linalg.norm(new.uv[:, None] - old.uv[None], axis=-1).min(axis=1)
    fresh = np.flatnonzero(d > 1e-7 * field.diagonal)
    if fresh.size == 0:
        return old
    return field.jet(np.concatenate([old.uv, new.uv[fresh]]),
                     np.concatenate([old.st, new.st[fresh]]))


# ------------------------------------------------------------------ curves
def _size(a: NurbsSurface, b: NurbsSurface) -> float:
    boxes = np.stack([a.bounding_box(), b.bounding_box()])
    return float(np.linalg.norm(boxes[:, 1].max(axis=0) - boxes[:, 0].min(axis=0)))


def characteristic_intersection(a: NurbsSurface, b: NurbsSurface, *, tol: float = 1e-7,
                                phi_on: str | None = None, grid: StageGrid | None = None
                                ) -> CharacteristicRecord:
    """Intersection of two surfaces by the characteristic method alone (§6.3 steps 1-4).

    Returns
    -------
    CharacteristicRecord
        Curves (all ``FoundBy.CHARACTERISTIC``) within ``tol`` of both surfaces,
        isolated (tangential contact) points, coincident regions and the record.
        ``grid`` as in :func:`characteristic_analysis`.
    """
    analysis = characteristic_analysis(a, b, tol=tol, phi_on=phi_on, grid=grid)
    return _finish(analysis, [], tol, a, b)


def certify(a: NurbsSurface, b: NurbsSurface, curves: Sequence[IntersectionCurve], *,
            tol: float = 1e-7, phi_on: str | None = None,
            analysis: CharacteristicAnalysis | None = None, open_curves: bool = False,
            tangential: Sequence[IntersectionCurve] | None = None) -> CharacteristicRecord:
    """The ``auto`` certificate: check ``curves`` (the triangle method's) against the
    characteristic points; trace and add the loops they miss (module docstring).

    Parameters
    ----------
    analysis : CharacteristicAnalysis, optional
        The characteristic stage, when already run (e.g. to learn before the
        triangle method whether the surfaces coincide).
    open_curves : bool
        Also check the border points (open curves); by default only the loops
        the critical points imply (the triangle method does not miss curves
        that cross the boundary unless they are tiny).
    tangential : sequence of IntersectionCurve, optional
        :func:`tangential_curves` of ``analysis``, when already made (e.g. to
        leave their fragments out of the triangle method,
        ``intersect_surfaces(tangential=...)``).
    """
    if analysis is None:
        analysis = characteristic_analysis(a, b, tol=tol, phi_on=phi_on, trace_critical=False,
                                           borders=open_curves)
    return _finish(analysis, list(curves), tol, a, b, borders=open_curves,
                   tangential=tangential)


def _near_isolated(curve: IntersectionCurve, isolated: Sequence[CharacteristicPoint],
                   radius: float) -> bool:
    return any(np.linalg.norm(curve.points - p.point, axis=1).max() <= radius for p in isolated)


def _inside_region(curve: IntersectionCurve, regions: Sequence[CoincidentRegion]) -> bool:
    """True when all samples of ``curve`` lie in the boxes of a coincident region."""
    for reg in regions:
        ok = True
        for uv, box in ((curve.uv_a, reg.box_a), (curve.uv_b, reg.box_b)):
            if uv is None:
                continue
            pad = 1e-6 * np.maximum(box[1] - box[0], 1e-12)
            ok &= bool(np.all((uv >= box[0] - pad) & (uv <= box[1] + pad)))
        if ok:
            return True
    return False


def tangential_curves(analysis: CharacteristicAnalysis, tol: float) -> list[IntersectionCurve]:
    """The ridges with ``|phi| <= tol`` all along (tangential contact along a curve,
    :mod:`.ridges`) as intersection curves."""
    out = []
    ridges = [r for r in analysis.ridges if r.is_tangential(tol)]
    for kind in dict.fromkeys(r.curve.kind for r in ridges):       # new samples on the ridge
        traced = [r.curve for r in ridges if r.curve.kind is kind]
        out += [c for c in to_intersection_curves(analysis.field, traced, tol,
                                                  refiner=ridge_refiner(analysis.field, kind))
                if c is not None]
    return out


def _along(curves: Sequence[IntersectionCurve], tangential: Sequence[IntersectionCurve],
           radius: float) -> NDArray:
    """``(len(curves),) bool``: every sample of the curve lies within ``radius`` of one
    tangential curve (its 3D interpolant as a polyline of 4 chords per span, which sag
    far below ``radius``; distances to its segments, :func:`.trace.polyline_gap`, all
    samples at once): the fragments a triangle method leaves along a tangential
    contact. (Densifying to points ``radius / 4`` apart cost ~0.2 s on a torus's top
    circle.)"""
    out = np.zeros(len(curves), dtype=bool)
    if not curves or not tangential:
        return out
    points = np.concatenate([c.points for c in curves])
    owner = np.repeat(np.arange(len(curves)), [c.points.shape[0] for c in curves])
    for t in tangential:
        far = polyline_gap(points, [dense_polyline(t, per_span=4)], [bool(t.closed)]) > radius
        out |= np.bincount(owner[far], minlength=len(curves)) == 0
    return out


def _finish(analysis: CharacteristicAnalysis, known: list[IntersectionCurve], tol: float,
            a: NurbsSurface, b: NurbsSurface, borders: bool = True,
            tangential: Sequence[IntersectionCurve] | None = None) -> CharacteristicRecord:
    start = time.perf_counter()
    fld = analysis.field
    size = _size(a, b)
    isolated = analysis.of_kind(PointKind.ISOLATED)
    # a tangential contact is a point: tiny curves around it are not curves
    radius = max(1e3 * tol, 1e-4 * size)
    tangential = tangential_curves(analysis, tol) if tangential is None else list(tangential)
    along = _along(known, tangential, radius)
    kept = [c for c, on in zip(known, along) if not on
            and not _near_isolated(c, isolated, radius)
            and not _inside_region(c, analysis.coincident)]
    dropped = len(known) - len(kept)
    added: list[IntersectionCurve] = list(tangential)
    kept += added
    starts = away_from(analysis.starts, isolated, fld)
    if not borders:
        loop = starts.group >= 0
        starts = Start(starts.uv[loop], starts.st[loop], starts.scale[loop], starts.group[loop])
    if not analysis.coincident:
        traced = trace_uncovered(fld, starts, kept, tol, size)
        added += traced                   # within tol (trace_uncovered's check)
    kept = kept[:len(kept) - len(tangential)]
    curves = tuple(kept) + tuple(added)
    found = (FoundBy.MESH,) * len(kept) + (FoundBy.CHARACTERISTIC,) * len(added)
    return CharacteristicRecord(curves, found, isolated, analysis.coincident, analysis.points,
                                analysis.characteristic_curves, "b" if fld.swapped else "a",
                                analysis.time_s, time.perf_counter() - start, dropped)
