"""Graded samples where an intersection curve crosses a C1 knot line of a surface (the
sampling of 000 §29.4 step 6).

A surface converted from a rational analytic one (a sphere, cylinder or torus
as OpenCascade writes it: rational quadratic arcs) is parametrized only C1 at
its interior knot lines: the pcurve's second derivative, taken along the
curve, jumps there by some ``J`` (model units, the parameter-space part scaled
to model units as in :mod:`.sampling`). The C2 cubic interpolant of
:mod:`.sampling` cannot follow the jump: near the crossing its error falls only
as ``h^2`` (measured for ``f = max(x, 0)^2 / 2``: ``0.0067 J h^2`` with the
kink in the middle of a span, ``0.025 J h^2`` with a sample on it, decaying by
``2 - sqrt(3) = 0.27`` per span away from it), where elsewhere it falls as
``h^4``. The verification rounds then split the spans at the crossing over and
over (4-12 rounds at 1e-10).

:func:`crossing_positions` places the samples there at once: a span of width
``h_c = 0.8 sqrt(target / (0.0067 J))`` centred on the crossing (0.4 times that
on an open curve, whose interpolant's averaged knots let the kink's error
spread over the zone), then spans growing by ``_GROWTH`` per span outwards
until they reach the regular spacing; the regular positions inside that zone
are dropped.

Where a surface is C2 but not C3 across a knot line (a bicubic with simple
knots), the pcurve's third derivative jumps there. A C2 cubic cannot follow
that between samples either (its error near the crossing falls as ``h^3``;
on a bicubic bump the failing spans of the first round all lay next to such a
crossing), but it can at a sample: a cubic spline with a knot on the crossing
reproduces ``max(t - t*, 0)^3`` exactly (measured for ``f = max(x, 0)^3 / 6``:
``0.011 J3 h^3`` with the kink mid-span, ``0.0072 J3 h^3`` at a quarter, 0 on a
sample). :func:`on_c2_crossings` puts one sample on each such crossing.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface

__all__ = ["c1_knots", "c2_knots", "crossing_chords", "crossing_positions", "on_c2_crossings"]

#: C2 cubic error next to a jump J in the second derivative, kink mid-span: K J h^2
_KINK_CONSTANT = 0.0067
#: the centre span is this share of what the constant allows
_MARGIN = 0.8
#: the centre span of an open curve is this share of a closed curve's. The constant above
#: holds for interpolants with knots at the samples (closed curves); the averaged knots
#: of an open curve's interpolant spread the kink's error over the whole zone with
#: little decay (near-coincident quadratics at tol 1e-9: 1.2-2.3 x target on all 28
#: spans of two zones, about 0.95 per span outwards), so it is bounded by the centre
#: span: 0.4^2 of it puts the zones at about 0.4 x target (the 6 SSI benchmark pairs at
#: 1e-7 and 1e-10 and the 14 characteristic pairs: 50 -> 48 rounds, 3 % fewer samples)
_OPEN_MARGIN = 0.4
#: graded spans grow by this factor per span away from the crossing (the error decays
#: by 0.27 per span, so sqrt(1 / 0.27) = 1.9 would just hold)
_GROWTH = 1.7
#: graded spans per side at most
_MAX_STEPS = 40
#: a uv step longer than this share of the domain is a seam jump, not a crossing
_SEAM_SHARE = 0.25
#: a regular position nearer a C2 crossing than this share of its spacing is moved off
#: it (no span shorter than a third of a neighbour: the rounds grade spans over 4 times
#: a neighbour, and with a quarter the spacing's own variation left one 4.3 times its
#: neighbour on the bumpy bicubic, a round for the grading alone)
_C2_NEAR = 1.0 / 3.0


def c1_knots(surface: NurbsSurface) -> tuple[NDArray, NDArray]:
    """Interior knots ``(u_knots, v_knots)`` where the surface is at most C1 in that
    direction (multiplicity at least ``degree - 1``); empty for a bicubic with simple
    knots."""
    out = []
    for knots, degree, lo, hi in ((surface.knots_u, surface.degree_u, *surface.domain[:2]),
                                  (surface.knots_v, surface.degree_v, *surface.domain[2:])):
        values, counts = np.unique(np.asarray(knots), return_counts=True)
        inner = (values > lo) & (values < hi) & (counts >= max(degree - 1, 1))
        out.append(values[inner])
    return out[0], out[1]


def c2_knots(surface: NurbsSurface) -> tuple[NDArray, NDArray]:
    """Interior knots ``(u_knots, v_knots)`` where the surface is C2 but not C3 in that
    direction (multiplicity ``degree - 2``, degree 3 or more): simple knots of a
    bicubic."""
    out = []
    for knots, degree, lo, hi in ((surface.knots_u, surface.degree_u, *surface.domain[:2]),
                                  (surface.knots_v, surface.degree_v, *surface.domain[2:])):
        values, counts = np.unique(np.asarray(knots), return_counts=True)
        inner = (values > lo) & (values < hi) & (counts == degree - 2) & (degree >= 3)
        out.append(values[inner])
    return out[0], out[1]


def crossing_chords(uv_a: NDArray, uv_b: NDArray, t: NDArray, knots_a, knots_b, domain_a,
                    domain_b, closed: bool) -> NDArray:
    """Dense chords ``(k,)`` crossing a C1 knot line of either surface (:func:`c1_knots`)."""
    return np.concatenate([_crossings(uv, t, knots, domain, closed)[0] for uv, knots, domain
                           in ((uv_a, knots_a, domain_a), (uv_b, knots_b, domain_b))])


def _second_difference(values: NDArray, t: NDArray) -> NDArray:
    """``2 f[t0, t1, t2]`` of rows ``values (k, 3, d)`` at ``t (k, 3)``: ``(k, d)``."""
    d1 = (values[:, 1:] - values[:, :-1]) / (t[:, 1:] - t[:, :-1])[..., None]
    return 2.0 * (d1[:, 1] - d1[:, 0]) / (t[:, 2] - t[:, 0])[:, None]


def _crossings(uv: NDArray, t: NDArray, knots: tuple[NDArray, NDArray], domain,
               closed: bool) -> tuple[NDArray, NDArray]:
    """Dense chords ``i (k,)`` whose ``uv`` crosses a knot line, and the crossing's
    parameter ``t* (k,)`` (linear in the chord)."""
    n = uv.shape[0]
    nxt = np.roll(uv, -1, axis=0) if closed else uv[1:]
    here = uv if closed else uv[:-1]
    chords, where = [], []
    for q, values in enumerate(knots):
        if values.size == 0:
            continue
        extent = domain[2 * q + 1] - domain[2 * q]
        a, b = here[:, q], nxt[:, q]
        ok = np.abs(b - a) <= _SEAM_SHARE * extent
        # chord i crosses knot c: (a - c) and (b - c) of opposite signs (or b on it)
        side_a = np.searchsorted(values, a, side="right")
        side_b = np.searchsorted(values, b, side="right")
        hit = np.flatnonzero(ok & (side_a != side_b))
        lo = np.minimum(side_a[hit], side_b[hit])
        count = np.abs(side_b[hit] - side_a[hit])          # knots values[lo:lo + count]
        i = np.repeat(hit, count)
        c = values[np.repeat(lo, count) + np.arange(count.sum())
                   - np.repeat(np.cumsum(count) - count, count)]
        da = b[i] - a[i]
        frac = np.where(da != 0, (c - a[i]) / np.where(da != 0, da, 1.0), 0.5)
        chords.append(i)
        where.append(t[i] + np.clip(frac, 0.0, 1.0) * (t[i + 1] - t[i]))
    chords = np.concatenate(chords) if chords else np.zeros(0, dtype=np.int64)
    if chords.size == 0 or n < 6:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    return chords.astype(np.int64), np.concatenate(where)


def _jumps(stacked: NDArray, t: NDArray, chords: NDArray, closed: bool) -> NDArray:
    """Jump ``J (k,)`` of the second derivative across dense chords ``chords``: second
    differences of the three samples on each side (``stacked (n, d)`` already in model
    units); NaN where a side runs off an open curve."""
    n = stacked.shape[0]
    if closed:
        ext = np.vstack([stacked, stacked[:1]])
        period = t[-1]
        left = (chords[:, None] + np.arange(-2, 1)[None, :])
        right = (chords[:, None] + np.arange(1, 4)[None, :])
        idx = np.concatenate([left, right], axis=1)
        wraps = np.floor_divide(idx, n)
        idx = np.mod(idx, n)
        tt = t[idx] + wraps * period
        vals = ext[idx]
    else:
        idx = np.concatenate([chords[:, None] + np.arange(-2, 1)[None, :],
                              chords[:, None] + np.arange(1, 4)[None, :]], axis=1)
        bad = (idx[:, 0] < 0) | (idx[:, -1] >= n)
        idx = np.clip(idx, 0, n - 1)
        tt, vals = t[idx], stacked[idx]
    with np.errstate(divide="ignore", invalid="ignore"):     # the clipped rows: NaN below
        left = _second_difference(vals[:, :3], tt[:, :3])
        right = _second_difference(vals[:, 3:], tt[:, 3:])
    jump = np.linalg.norm(right - left, axis=1)
    if not closed:
        jump[bad] = np.nan
    return jump


def _merged(where: NDArray, jump: NDArray, target: float) -> tuple[NDArray, NDArray]:
    """Crossings closer than two centre spans merged into one (both surfaces crossing a
    knot line at about the same point: two interleaved zones would leave spans far
    shorter than their neighbours, which the rounds then grade one by one): the mean
    position and the larger jump."""
    order = np.argsort(where)
    where, jump = where[order], jump[order]
    width = 2.0 * _MARGIN * np.sqrt(target / (_KINK_CONSTANT * jump))
    xs, js = [where[0]], [jump[0]]
    members = 1
    for x, j, w in zip(where[1:], jump[1:], width[1:]):
        if x - xs[-1] <= max(w, 2.0 * _MARGIN * np.sqrt(target / (_KINK_CONSTANT * js[-1]))):
            xs[-1] = (xs[-1] * members + x) / (members + 1)
            js[-1] = max(js[-1], j)
            members += 1
        else:
            xs.append(x)
            js.append(j)
            members = 1
    return np.array(xs), np.array(js)


def crossing_positions(positions: NDArray, t: NDArray, regular: NDArray, stacked: NDArray,
                       uv_a: NDArray, uv_b: NDArray, knots_a, knots_b, domain_a, domain_b,
                       closed: bool, target: float) -> NDArray:
    """Sample positions with graded zones at the C1 knot-line crossings (module docstring).

    Parameters
    ----------
    positions : (p,) float
        Regular interior positions (chord-length parameters) of the first subset.
    t : (n,) float, or (n + 1,) when closed
        Chord-length parameters of the dense samples.
    regular : (chords,) float
        Regular spacing at each dense chord (model units).
    stacked : (n, 7) float
        Dense ``points | uv_a | uv_b``, the parameter-space parts scaled to model units.
    uv_a, uv_b : (n, 2) float
        Dense parameters (unscaled), to find the crossings.
    knots_a, knots_b : (u_knots, v_knots)
        :func:`c1_knots` of each surface.
    target : float
        Model units: the interpolants' error allowed at the check points.

    Returns
    -------
    (p',) float, sorted, strictly inside ``(0, t[-1])``.
    """
    found = [_crossings(uv, t, knots, domain, closed)
             for uv, knots, domain in ((uv_a, knots_a, domain_a), (uv_b, knots_b, domain_b))]
    chords = np.concatenate([f[0] for f in found])
    if chords.size == 0:
        return positions
    where = np.concatenate([f[1] for f in found])
    jump = _jumps(stacked, t, chords, closed)
    keep = np.isfinite(jump) & (jump > 0)
    chords, where, jump = chords[keep], where[keep], jump[keep]
    if chords.size == 0:
        return positions
    where, jump = _merged(where, jump, target)
    margin = _MARGIN if closed else _OPEN_MARGIN * _MARGIN
    centre = margin * np.sqrt(target / (_KINK_CONSTANT * jump))
    chords = np.clip(np.searchsorted(t, where, side="right") - 1, 0, regular.size - 1)
    reach = regular[chords]
    period = t[-1]
    extra, zones = [], []
    edges, sides, spacing = [], [], []         # outermost zone samples, outwards, regular h
    for x, h, r in zip(where, centre, reach):
        if h >= r:                              # the regular spacing is fine enough
            continue
        steps = [0.5 * h]
        while h * _GROWTH ** len(steps) < r and len(steps) < _MAX_STEPS:
            steps.append(steps[-1] + h * _GROWTH ** len(steps))
        half = np.array(steps)
        extra.append(np.concatenate([x - half[::-1], x + half]))
        zones.append((x, half[-1] + 0.5 * r))
        edges += [x - half[-1], x + half[-1]]
        sides += [-1, 1]
        spacing += [r, r]
    if not extra:
        return positions
    extra = np.concatenate(extra)
    inside = np.zeros(positions.size, dtype=bool)
    for x, width in zones:
        d = np.abs(positions - x)
        if closed:
            d = np.minimum(d, period - d)
        inside |= d < width
    out = np.concatenate([positions[~inside], extra])
    if closed:
        out = np.mod(out, period)
    lo, hi = 1e-9 * period, period * (1 - 1e-9)
    out = np.sort(out[(out > lo) & (out < hi)])
    small = 1e-3 * float(centre.min())
    out = out[np.concatenate([[True], np.diff(out) > small])]
    return _filled(out, np.array(edges), np.array(sides), np.array(spacing), closed, period)


def _filled(out: NDArray, edges: NDArray, sides: NDArray, spacing: NDArray, closed: bool,
            period: float) -> NDArray:
    """``out`` with a sample in the middle of each span from a zone's outermost sample
    (``edges``, going outwards in direction ``sides`` = +1 / -1) to the next position
    beyond, where that span is longer than the regular ``spacing`` there: the regular
    positions dropped inside the zone leave a gap of 0.5 to 1.5 regular spans, and a
    cubic span 1.5 times too long is off by 1.5^4 = 5 times as much."""
    if closed:
        edges = np.mod(edges, period)
    i = np.searchsorted(out, edges)
    found = (i < out.size) & (out[np.minimum(i, out.size - 1)] == edges)
    j = i + sides
    beyond = found & (j >= 0) & (j < out.size)
    if closed:
        j, beyond = np.mod(j, out.size), found
    i, j, spacing = i[beyond], j[beyond], spacing[beyond]
    gap = np.abs(out[j] - out[i])
    if closed:
        gap = np.minimum(gap, period - gap)
    long = gap > spacing
    if not long.any():
        return out
    middle = out[i[long]] + 0.5 * sides[beyond][long] * gap[long]
    if closed:
        middle = np.mod(middle, period)
    return np.sort(np.concatenate([out, middle]))


def _merged_crossings(where: NDArray, grid: NDArray) -> NDArray:
    """Sorted crossings ``where`` with those closer than ``_C2_NEAR`` of the spacing of
    ``grid`` there merged into their mean (both surfaces, or a u and a v knot line,
    crossed at about one point: two samples there would leave a span far shorter
    than its neighbours, which the rounds then grade)."""
    i = np.clip(np.searchsorted(grid, where), 1, grid.size - 1)
    near = np.diff(where) < _C2_NEAR * (grid[i] - grid[i - 1])[1:]
    first = np.flatnonzero(np.concatenate([[True], ~near]))
    return np.add.reduceat(where, first) / np.diff(np.append(first, where.size))


def on_c2_crossings(positions: NDArray, t: NDArray, uv_a: NDArray, uv_b: NDArray,
                    knots_a, knots_b, domain_a, domain_b, closed: bool) -> NDArray:
    """Sample positions with one on every crossing of a C2 knot line (module docstring).

    ``positions (p,)``: interior chord-length parameters of the first subset;
    ``t``, ``uv_a``, ``uv_b`` as in :func:`crossing_positions`; ``knots_a``,
    ``knots_b``: :func:`c2_knots` of each surface. Every crossing is taken: the jump
    cannot be told from the dense samples (their third differences are noise at the
    spacing of a refined trace), and one sample per crossing costs little. A position
    nearer a crossing than ``_C2_NEAR`` of the spacing there is moved to the middle
    between the crossing and its next position beyond (no span gets longer, none
    shorter than a third of its neighbour); a crossing that near an end sample of
    the curve (which stays) takes no sample of its own. Returns ``(p',) float``,
    sorted, strictly inside ``(0, t[-1])``.
    """
    where = np.concatenate([_crossings(uv, t, knots, domain, closed)[1] for uv, knots, domain
                            in ((uv_a, knots_a, domain_a), (uv_b, knots_b, domain_b))])
    if where.size == 0 or positions.size == 0:
        return positions
    period = t[-1]
    grid = np.concatenate([[0.0], positions, [period]])
    x = _merged_crossings(np.sort(where), grid)
    i = np.clip(np.searchsorted(grid, x), 1, grid.size - 1)     # grid[i-1] < x <= grid[i]
    left, right = x - grid[i - 1], grid[i] - x
    near = np.minimum(left, right) < _C2_NEAR * (grid[i] - grid[i - 1])
    j = np.where(right <= left, i, i - 1)                   # the position to move off
    beyond = np.where(right <= left, i + 1, i - 2)          # and the next one past it
    at_end = near & ((j == 0) | (j == grid.size - 1))       # the end sample stays: near enough
    move = near & ~at_end
    out = grid.copy()
    out[j[move]] = 0.5 * (x[move] + grid[beyond[move]])
    out = np.concatenate([out[1:-1], x[~at_end]])
    lo, hi = 1e-9 * period, period * (1 - 1e-9)
    out = np.sort(out[(out > lo) & (out < hi)])
    return out[np.concatenate([[True], np.diff(out) > 1e-9 * period])]
