"""Intersections that run along a side of a surface's parameter domain.

CAD systems that write every face as a surface ending exactly at the face's
edges (I-DEAS, for instance) make the intersection of two neighbouring faces'
surfaces run *along* a domain side of one of them: the side curve
``S(u, v_0)`` lies on the other surface. The tessellations then touch along
the boundary chords instead of crossing them (often exactly: the chords of a
planar side lie in the plane they touch), so the triangle-triangle step finds
only scattered pieces with gaps (000 §29.4.3 handles crossings, not contact).

Such a stretch is found here directly on the side: the side curve is sampled
densely (``SIDE_SAMPLES_PER_SPAN`` per knot span), every sample projected onto
the other surface, and runs of consecutive samples within ``tol / 8`` of it
become curves (their points halfway to the feet: within ``tol / 16`` of both).
Each run's ends are located by bisection along the side (where the side leaves
the other surface), and every sample keeps its side parameter exactly: the side
curve is the intersection there, so no refinement is needed (nor possible: the
auxiliary-plane step would slide the points into the domain; the constrained
solve of a point on a side has a one-parameter family of solutions along a side
that lies on the other surface).

Only sides on which the traced soup has an end are examined, so pairs that
cross transversally pay nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..projection import project_to_surface
from ..surface import NurbsSurface
from .refine import RefinedCurve
from .seams import other_side, seam_jumps

__all__ = ["SIDE_SAMPLES_PER_SPAN", "DomainSide", "box_sides", "covered_samples",
           "may_run_along", "may_run_along_many", "side_curves",
           "uncovered_pieces"]

#: samples of a side curve per knot span (at least ``_MIN_SAMPLES`` in all)
SIDE_SAMPLES_PER_SPAN = 16
_MIN_SAMPLES = 64
#: a run must hold this many consecutive samples on the other surface
_MIN_RUN = 3
#: samples added between the neighbours of a stretch of near samples shorter than a run,
#: and the least number of samples of a run's curve
_DENSE = 16
#: bisection steps locating a run's ends along the side
_BISECTIONS = 40
#: seed grid of the projections onto the other surface, per knot span and direction
#: (the default grid of project_to_surface cost 2/3 of the whole pair here)
_SEED_PER_SPAN = 6
#: share of tol within which side samples count as lying on the other surface; a curve's
#: points are the midpoints of a side point and its foot, within half that of both
#: surfaces (tol / 16, as dense samples). (With tol / 16 here, a side 1e-5..3e-5 from
#: the other surface, tol 3e-4, b1_euclid faces 28 x 37, stopped its run half-way.)
_SHARE = 1.0 / 8


@dataclass(frozen=True)
class DomainSide:
    """A side of a surface's domain: ``owner`` 0 (surface a) or 1 (b), the held
    ``coord`` (0: u, 1: v) and its ``value``."""

    owner: int
    coord: int
    value: float


@dataclass(frozen=True)
class SideRun:
    """A stretch of a side lying on the other surface: free parameter range ``[t0, t1]``."""

    side: DomainSide
    t0: float
    t1: float


def _uv_on_side(side: DomainSide, t: NDArray) -> NDArray:
    uv = np.empty((t.size, 2))
    uv[:, side.coord] = side.value
    uv[:, 1 - side.coord] = t
    return uv


def _free_range(surface: NurbsSurface, coord: int) -> tuple[float, float, NDArray]:
    """Free parameter range of a side holding ``coord``, and the distinct knots inside."""
    d = surface.domain
    lo, hi = (d[2], d[3]) if coord == 0 else (d[0], d[1])
    knots = surface.knots_v if coord == 0 else surface.knots_u
    return lo, hi, np.unique(knots[(knots >= lo) & (knots <= hi)])


def _side_samples(surface: NurbsSurface, coord: int) -> NDArray:
    """``(m,)`` free parameters: ``SIDE_SAMPLES_PER_SPAN`` per knot span, ends included."""
    lo, hi, breaks = _free_range(surface, coord)
    breaks = np.unique(np.concatenate([[lo, hi], breaks]))
    per = max(SIDE_SAMPLES_PER_SPAN, int(np.ceil(_MIN_SAMPLES / (breaks.size - 1))))
    s = np.arange(per) / per
    inner = (breaks[:-1, None] + s * np.diff(breaks)[:, None]).ravel()
    return np.append(inner, hi)


def _gap(own: NurbsSurface, other: NurbsSurface, side: DomainSide, t: NDArray, tol: float,
         guess: NDArray | None = None):
    """Points of the side at ``t``, their projections onto ``other`` and the distances."""
    uv = _uv_on_side(side, t)
    p = own.evaluate(uv[:, 0], uv[:, 1])
    kw = {"guess": guess} if guess is not None else {"n_seeds": 2,
                                                     "samples_per_span": _SEED_PER_SPAN}
    found = project_to_surface(other, p, tol=1e-3 * tol, **kw)
    return uv, p, found


def may_run_along(own: NurbsSurface, other: NurbsSurface, side: DomainSide, t: NDArray,
                  guess: NDArray, *, tol: float) -> bool:
    """Cheap necessary test before a side is scanned: False when none of the side
    points half a sample spacing either side of the traced points at free
    parameters ``t (k,)`` lies on ``other`` (within ``tol / 16``, projected from
    ``guess (k, 2)``, their parameters on ``other``).

    A run of :func:`side_curves` holds ``_MIN_RUN`` consecutive samples, so it is
    at least two spacings long and a traced point on it has a probe inside it; a
    curve merely crossing the side (a seam, a trimmed end) is off ``other``
    there by about the spacing times the crossing angle. Probes beyond the
    side's ends are left out (a run reaching an end has the inner one inside).
    """
    return may_run_along_many(own, other, [side], [t], [guess], tol=tol)[0]


def may_run_along_many(own: NurbsSurface, other: NurbsSurface, sides: list[DomainSide],
                       ts: list[NDArray], guesses: list[NDArray], *, tol: float) -> list[bool]:
    """:func:`may_run_along` for several sides of ``own`` at once: their probes are
    projected onto ``other`` in one batch (each from its own guess)."""
    uv, guess, owner, answer = [], [], [], [True] * len(sides)
    for i, (side, t, g) in enumerate(zip(sides, ts, guesses)):
        t = np.asarray(t, dtype=float)
        lo, hi, _ = _free_range(own, side.coord)
        delta = 0.5 * float(np.min(np.diff(_side_samples(own, side.coord))))
        probes = np.concatenate([t - delta, t + delta])
        inside = (probes >= lo) & (probes <= hi)  # a run at the side's end: the inner probe
        if not np.any(inside):
            continue                               # True, as may_run_along says
        uv.append(_uv_on_side(side, probes[inside]))
        guess.append(np.concatenate([g, g])[inside])
        owner.append(np.full(int(inside.sum()), i))
        answer[i] = False
    if uv:
        uv = np.concatenate(uv)
        p = own.evaluate(uv[:, 0], uv[:, 1])
        found = project_to_surface(other, p, tol=1e-3 * tol,
                                   guess=np.asarray(np.concatenate(guess), dtype=float))
        near = np.concatenate(owner)[found.distance <= _SHARE * tol]
        for i in np.unique(near):
            answer[int(i)] = True
    return answer


def _stretches(near: NDArray) -> tuple[NDArray, NDArray]:
    """First and last indices ``(k,), (k,)`` of every stretch of consecutive True entries."""
    edges = np.diff(np.concatenate([[0], near.astype(np.int8), [0]]))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1


def _runs(near: NDArray) -> list[tuple[int, int]]:
    """``[(first, last)]`` index ranges of consecutive True entries, ``_MIN_RUN`` long at least."""
    starts, stops = _stretches(near)
    return [(int(a), int(b)) for a, b in zip(starts, stops) if b - a + 1 >= _MIN_RUN]


def _bisect_ends(own, other, side, inside: NDArray, outside: NDArray, guess: NDArray,
                 limit: float, tol: float) -> NDArray:
    """Free parameters ``(k,)`` where the side leaves ``other``: bisection between
    samples ``inside`` (within ``limit``) and ``outside`` (not)."""
    a, b = inside.astype(float), outside.astype(float)
    for _ in range(_BISECTIONS):
        mid = 0.5 * (a + b)
        _, _, found = _gap(own, other, side, mid, tol, guess)
        ok = found.distance <= limit
        a, b = np.where(ok, mid, a), np.where(ok, b, mid)
    return a


def _densified(own: NurbsSurface, other: NurbsSurface, side: DomainSide, t: NDArray,
               dist: NDArray, foot: NDArray, tol: float
               ) -> tuple[NDArray, NDArray, NDArray]:
    """The side samples with ``_DENSE`` more between the neighbours of every stretch of
    near samples shorter than ``_MIN_RUN``: a run shorter than two sample spacings (the
    other surface a narrow strip across the side, as a 3 mm plane under a 19 mm arc)
    holds only one or two of the regular samples. Returns ``(t, distance, foot uv)``."""
    starts, stops = _stretches(dist <= _SHARE * tol)
    short = (stops - starts + 1) < _MIN_RUN
    if not np.any(short):
        return t, dist, foot
    lo = t[np.maximum(starts[short] - 1, 0)]
    hi = t[np.minimum(stops[short] + 1, t.size - 1)]
    extra = (lo[:, None] + np.linspace(0, 1, _DENSE + 2)[None, 1:-1] * (hi - lo)[:, None]).ravel()
    found = _gap(own, other, side, extra, tol)[2]
    t_all = np.concatenate([t, extra])
    order = np.argsort(t_all, kind="stable")
    return (t_all[order], np.concatenate([dist, found.distance])[order],
            np.concatenate([foot, found.uv])[order])


def _near_boxes(points: NDArray, boxes: NDArray, pad: float) -> bool:
    """True when some point ``(n, 3)`` lies within ``pad`` of some box ``(m, 2, 3)``."""
    lo, hi = boxes[:, 0] - pad, boxes[:, 1] + pad
    return bool(np.any(np.all((points[:, None] >= lo[None]) & (points[:, None] <= hi[None]), axis=2)))


def _side_runs(own: NurbsSurface, other: NurbsSurface, side: DomainSide, tol: float,
               boxes: NDArray | None = None) -> list[SideRun]:
    t = _side_samples(own, side.coord)
    if boxes is not None:
        # a run holds samples on ``other``, which lie in its Bezier patches' control-net
        # boxes: none near a box, no run (the projections would all come back far)
        uv = _uv_on_side(side, t)
        if not _near_boxes(own.evaluate(uv[:, 0], uv[:, 1]), boxes, tol):
            return []
    found = _gap(own, other, side, t, tol)[2]
    limit = _SHARE * tol
    t, dist, foot = _densified(own, other, side, t, found.distance, found.uv, tol)
    runs = _runs(dist <= limit)
    if not runs:
        return []
    lo_i = np.array([r[0] for r in runs])
    hi_i = np.array([r[1] for r in runs])
    t0, t1 = t[lo_i], t[hi_i]
    # extend each end that is not the side's end up to where the side leaves the surface
    low = lo_i > 0
    if low.any():
        t0[low] = _bisect_ends(own, other, side, t[lo_i[low]], t[lo_i[low] - 1],
                               foot[lo_i[low]], limit, tol)
    high = hi_i < t.size - 1
    if high.any():
        t1[high] = _bisect_ends(own, other, side, t[hi_i[high]], t[hi_i[high] + 1],
                                foot[hi_i[high]], limit, tol)
    return [SideRun(side, float(a), float(b)) for a, b in zip(t0, t1) if b > a]


def _run_curve(own: NurbsSurface, other: NurbsSurface, run: SideRun, tol: float
               ) -> RefinedCurve | None:
    """Dense samples of a run: side points, their feet on ``other``. A whole side
    that closes in space stays an open curve whose ends coincide (the convention
    of a loop through a seam, :func:`.pipeline.closed_in_space`): its own
    parameter jumps there."""
    t_all = np.concatenate([_side_samples(own, run.side.coord),
                            np.linspace(run.t0, run.t1, _DENSE + 2)])    # a short run too
    t = np.unique(np.concatenate([[run.t0], t_all[(t_all > run.t0) & (t_all < run.t1)],
                                  [run.t1]]))
    uv, p, found = _gap(own, other, run.side, t, tol)
    if np.any(found.distance > _SHARE * tol):
        return None
    points = 0.5 * (p + found.points)
    found_uv = _ends_off_the_seam(other, found.uv, tol)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > 0])
    uv, points, found_uv = uv[keep], points[keep], found_uv[keep]
    if points.shape[0] < 2:
        return None
    uv_a, uv_b = (uv, found_uv) if run.side.owner == 0 else (found_uv, uv)
    n = points.shape[0]
    return RefinedCurve(points, uv_a, uv_b, False, np.ones(n, bool), np.zeros(n, bool))


def _ends_off_the_seam(surface: NurbsSurface, uv: NDArray, tol: float) -> NDArray:
    """``uv (n, 2)`` with an end moved across a seam of ``surface`` where its projection
    landed on the seam's far parameter line (a side running into the seam of a closed
    surface: both lines are the end's foot, and the projection may pick either; the
    jump of the whole period to the next sample wrecks the pcurve's interpolant)."""
    if uv.shape[0] < 2:
        return uv
    uv = uv.copy()
    jumps = seam_jumps(uv, surface, False, tol)
    for end, nxt, step in ((0, 1, 0), (-1, -2, -1)):
        if jumps[step]:
            uv[end] = other_side(uv[end], uv[nxt], surface.domain)
    return uv


def _side_rows(surface: NurbsSurface, coord: int, high: bool) -> NDArray:
    """``(m, 3)`` control points whose hull holds the side (its row when clamped,
    else the ``degree + 1`` rows next to it)."""
    knots = surface.knots_u if coord == 0 else surface.knots_v
    degree = surface.degree_u if coord == 0 else surface.degree_v
    net = surface.control_points if coord == 0 else np.swapaxes(surface.control_points, 0, 1)
    ends = knots[-degree - 1:] if high else knots[:degree + 1]
    rows = 1 if np.all(ends == ends[0]) else degree + 1
    picked = net[-rows:] if high else net[:rows]
    return picked.reshape(-1, net.shape[-1])


def box_sides(surface_a: NurbsSurface, surface_b: NurbsSurface, tol: float
              ) -> list[DomainSide]:
    """Sides of either surface whose control hull meets the other's box (widened by
    ``tol``): the candidates when the tessellations found nothing at all (touching
    along a side only)."""
    out = []
    surfaces = (surface_a, surface_b)
    for owner, own in enumerate(surfaces):
        box = np.asarray(surfaces[1 - owner].bounding_box(), dtype=float)
        lo, hi = box[0] - tol, box[1] + tol
        d = own.domain
        for coord, high, value in ((0, False, d[0]), (0, True, d[1]), (1, False, d[2]),
                                   (1, True, d[3])):
            rows = _side_rows(own, coord, high)
            if np.all(rows.max(axis=0) >= lo) and np.all(rows.min(axis=0) <= hi):
                out.append(DomainSide(owner, coord, float(value)))
    return out


def _all_on_a_side(surface: NurbsSurface, uv: NDArray, rel: float = 1e-9) -> bool:
    u0, u1, v0, v1 = surface.domain
    eu, ev = rel * (u1 - u0), rel * (v1 - v0)
    for coord, value, eps in ((0, u0, eu), (0, u1, eu), (1, v0, ev), (1, v1, ev)):
        if np.all(np.abs(uv[:, coord] - value) <= eps):
            return True
    return False


def side_curves(surface_a: NurbsSurface, surface_b: NurbsSurface, sides: list[DomainSide],
                *, tol: float) -> tuple[list[RefinedCurve], list[SideRun]]:
    """Dense curves along the given domain sides where they lie on the other surface.

    Parameters
    ----------
    surface_a, surface_b : NurbsSurface
    sides : list of DomainSide
        Sides to examine (those the traced soup has ends on).
    tol : float
        Model units; samples lie within ``tol / 16`` of both surfaces.

    Returns
    -------
    (curves, runs)
        ``RefinedCurve`` per stretch (as :func:`.refine.refine_curves` gives them),
        and the runs they came from. A stretch along a side of both surfaces is
        returned once (from surface a's side).
    """
    from .culling import surface_patch_boxes
    surfaces = (surface_a, surface_b)
    boxes = [None, None]
    curves, runs = [], []
    for side in dict.fromkeys(sides):
        own, other = surfaces[side.owner], surfaces[1 - side.owner]
        if boxes[1 - side.owner] is None:
            boxes[1 - side.owner] = surface_patch_boxes(other)[0]
        for run in _side_runs(own, other, side, tol, boxes[1 - side.owner]):
            curve = _run_curve(own, other, run, tol)
            if curve is None:
                continue
            if side.owner == 1 and _all_on_a_side(surface_a, curve.uv_a):
                continue                  # a's side too: found (or to be found) from a
            curves.append(curve)
            runs.append(run)
    return curves, runs


def covered_samples(curve: RefinedCurve, runs: list[SideRun], surface_a: NurbsSurface,
                    surface_b: NurbsSurface, tol: float) -> NDArray:
    """``(n,) bool``: which samples of ``curve`` lie on a run (within ``tol`` of the side
    point at their own free parameter, inside the run's range)."""
    surfaces = (surface_a, surface_b)
    covered = np.zeros(curve.points.shape[0], dtype=bool)
    for run in runs:
        side = run.side
        uv = curve.uv_a if side.owner == 0 else curve.uv_b
        t = uv[:, 1 - side.coord]
        span = 1e-9 * max(abs(run.t1 - run.t0), 1.0)
        inside = (t >= run.t0 - span) & (t <= run.t1 + span)
        if not inside.any():
            continue
        on = _uv_on_side(side, t[inside])
        q = surfaces[side.owner].evaluate(on[:, 0], on[:, 1])
        hit = np.flatnonzero(inside)[np.linalg.norm(q - curve.points[inside], axis=1) <= tol]
        covered[hit] = True
    return covered


def uncovered_pieces(curve: RefinedCurve, covered: NDArray) -> list[tuple[RefinedCurve, bool, bool]]:
    """The stretches of an open ``curve`` off the side runs: each maximal run of samples
    not ``covered``, with the covered sample on either side of it (the point where the
    curve leaves the side: on the domain's boundary). Returns ``(piece, starts at a
    junction, ends at a junction)`` for pieces of at least two samples."""
    n = covered.size
    edges = np.diff(np.concatenate([[0], (~covered).astype(np.int8), [0]]))
    out = []
    for lo, hi in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
        a, b = max(lo - 1, 0), min(hi + 1, n)
        if b - a < 2:
            continue
        sl = slice(a, b)
        out.append((RefinedCurve(curve.points[sl], curve.uv_a[sl], curve.uv_b[sl], False,
                                 curve.converged[sl], curve.singular[sl]), a < lo, b > hi))
    return out
