"""Block layouts made conforming: no block corner inside another block's side.

Faces split into blocks (round a hole, at the corners of an n-sided face, a pole
cap's butterfly) and faces whose edges are split differently on their two sides
meet their neighbours at T-junctions: a corner of one block lies inside a side of
another. Two sides are matched node for node only when they are one edge from end
to end (:func:`.network.match_sides`), so at a T-junction the grids do not meet:
on the real files most shared edges that do not match are of this kind (k1 debis:
55 sides inside a longer one, 27 holding a shorter one, 110 overlapping part of
one, of 214 unmatched).

:func:`conforming` cuts every block whose side holds such a corner, from that
point across to its opposite side, along the line of the block's transfinite
interpolation (in its surface's parameters, blended by normalized arc length as
the start grid is): a whole surface rectangle cut at a parameter value is two
rectangles (:meth:`~..surface.NurbsSurface.split`), any other region two regions
sharing the cut. The cut's far end is a new corner, which may lie inside the side
of the next block: the cuts propagate, round by round, until no corner lies
inside a side, a cut ends at a corner already there (a far end within
:data:`SNAP` of the side's length from one is moved onto it), or
:data:`MAX_ROUNDS` rounds or :data:`MAX_GROWTH` times the blocks given are
reached; the round with the fewest corners left inside sides is kept (a cascade of
cuts can make more than it resolves), and what is left is counted.

This is the usual way of a multi-block topology (a cut through a block rather
than a sub-range of a side matched to a whole side): every shared edge is then a
whole side of both its blocks, and the node counts stay classes of equal sides.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import SurfprepError
from ..curve import NurbsCurve
from ..fitting import interpolate_curve
from ..surface import NurbsSurface
from .elliptic_kernels import corner_jacobians
from .region import SIDE_NAMES, Region, Side
from .tfi import transfinite

__all__ = ["MAX_GROWTH", "MAX_ROUNDS", "SNAP", "Conforming", "conforming", "t_junctions"]

#: a cut whose far end comes within this fraction of the opposite side's length of a
#: corner already on that side ends there (cuts do not multiply into slivers)
SNAP = 0.25
#: rounds of cutting at most
MAX_ROUNDS = 8
#: the cuts stop once the blocks are this many times those given
MAX_GROWTH = 4.0
#: cuts closer than this fraction of a side (to each other or to its ends) are one
_APART = 1e-9
#: nodes a side of the coarse grid that checks a piece for folds
_CHECK = 9
#: points of a cut's transfinite line interpolated by its pcurve
CUT_SAMPLES = 17
#: a side of the rectangle: its name, the direction it runs in, and the parameter it holds
_ACROSS = {"j0": "u", "j1": "u", "i0": "v", "i1": "v"}


@dataclass(frozen=True)
class Conforming:
    """Blocks cut so that no corner lies inside another block's side.

    Attributes
    ----------
    surfaces : tuple of NurbsSurface or Region
        The blocks: those given that needed no cut, the pieces of the others.
    origin : tuple of int
        The index in the list given of the block each piece comes from.
    cuts : int
        Cuts made.
    left : int
        Corners still inside another block's side (the rounds or the growth ran out).
    """

    surfaces: tuple
    origin: tuple[int, ...]
    cuts: int = 0
    left: int = 0


def _as_region(item: NurbsSurface | Region) -> Region:
    return item if isinstance(item, Region) else Region.rectangle(item)


def _corners(region: Region) -> NDArray:
    """``(4, 3)`` the region's corners: the ends of ``j0`` and of ``j1``."""
    return np.concatenate([region.sides["j0"].points(np.array([0.0, 1.0])),
                           region.sides["j1"].points(np.array([0.0, 1.0]))])


def t_junctions(surfaces: list[NurbsSurface | Region], *, gap: float, blocks=None,
                corners=None) -> dict[tuple[int, str], NDArray]:
    """Corners of blocks that lie inside a side of another block.

    Parameters
    ----------
    surfaces : list of NurbsSurface (their whole rectangles) or Region
    gap : float
        Model units: a corner within ``gap`` of a side, and farther than ``gap`` from
        both its ends, lies inside it.
    blocks, corners : iterable of int, optional
        Look only at the sides of ``blocks`` and only for the corners of ``corners``
        (default: all of them).

    Returns
    -------
    dict of (int, str) to (k,) float
        Per block and side (``"j0"``...), the arc-length fractions along the side of
        the corners inside it, increasing (corners closer than ``gap`` are one).
    """
    from scipy.spatial import cKDTree
    regions = [_as_region(s) for s in surfaces]
    owners = np.arange(len(regions)) if corners is None else np.unique(np.fromiter(corners, dtype=int))
    if not regions or owners.size == 0:
        return {}
    corners = np.concatenate([_corners(regions[k]) for k in owners])
    corners[~np.isfinite(corners)] = np.inf
    owner = np.repeat(owners, 4)
    tree = cKDTree(corners)
    out = {}
    for r in (range(len(regions)) if blocks is None else blocks):
        region = regions[r]
        for name in SIDE_NAMES:
            side = region.sides[name]
            try:
                length = side.length
            except SurfprepError:
                continue                                        # the network says why
            if not length > gap:
                continue                                        # a pole, or no finite length
            samples = side.points(np.linspace(0.0, 1.0, 9))
            centre = samples.mean(axis=0)
            radius = float(np.linalg.norm(samples - centre, axis=1).max()) + 0.1 * length + gap
            found = np.array([c for c in tree.query_ball_point(centre, radius) if owner[c] != r], dtype=int)
            if found.size == 0:
                continue
            p = corners[found]
            ends = samples[[0, -1]]
            inner = np.minimum(np.linalg.norm(p - ends[0], axis=1), np.linalg.norm(p - ends[1], axis=1)) > gap
            p = p[inner]
            if p.shape[0] == 0:
                continue
            try:
                x = side.locate(p)
                on = np.linalg.norm(side.points(x) - p, axis=1) <= gap
            except SurfprepError:
                continue
            if not on.any():
                continue
            f = np.sort(side.fractions_of(x[on]))
            keep = np.concatenate([[True], np.diff(f) * length > gap])
            f = f[keep & (f * length > gap) & ((1.0 - f) * length > gap)]
            if f.size:
                out[r, name] = f
    return out


def _paired(near: NDArray, far: NDArray) -> list[tuple[float, float]]:
    """Cuts from the fractions on one side to the other: each corner on the near side
    (``near``) to the nearest corner on the far side within :data:`SNAP`, else straight
    across (the same fraction); the far side's corners left over straight back; crossing
    cuts dropped (they are found again next round)."""
    cuts, used = [], set()
    for f in near:
        free = [k for k in range(far.size) if k not in used and abs(far[k] - f) <= SNAP]
        if free:
            k = min(free, key=lambda k: abs(far[k] - f))
            used.add(k)
            cuts.append((float(f), float(far[k])))
        else:
            cuts.append((float(f), float(f)))
    cuts += [(float(g), float(g)) for k, g in enumerate(far) if k not in used]
    cuts.sort()
    out: list[tuple[float, float]] = []
    for f, g in cuts:
        if not (_APART < f < 1.0 - _APART and _APART < g < 1.0 - _APART):
            continue
        if out and (f <= out[-1][0] + _APART or g <= out[-1][1] + _APART):
            continue
        out.append((f, g))
    return out


def _piece(side: Side, a: float, b: float) -> Side:
    """The part of a side between its normalized parameters ``a`` and ``b``."""
    return Side(side.surface, side.pcurve, float(side.t(a)), float(side.t(b)))


def _cut_line(region: Region, f: float, g: float) -> Side:
    """The side of a cut from ``j0`` at arc-length fraction ``f`` to ``j1`` at ``g``: the
    transfinite line ``xi = f + (g - f) eta`` of the region in its surface's parameters,
    interpolated by a cubic."""
    j0, j1, i0, i1 = (region.sides[n] for n in ("j0", "j1", "i0", "i1"))
    eta = np.linspace(0.0, 1.0, CUT_SAMPLES)
    xi = f + (g - f) * eta
    bottom, top = j0.uv(j0.at_fractions(xi)), j1.uv(j1.at_fractions(xi))
    left, right = i0.uv(i0.at_fractions(eta)), i1.uv(i1.at_fractions(eta))
    c00, c10 = j0.uv(np.array([0.0, 1.0]))
    c01, c11 = j1.uv(np.array([0.0, 1.0]))
    e, x = eta[:, None], xi[:, None]
    uv = ((1 - e) * bottom + e * top + (1 - x) * left + x * right
          - ((1 - x) * (1 - e) * c00 + x * (1 - e) * c10 + (1 - x) * e * c01 + x * e * c11))
    uv[0], uv[-1] = bottom[0], top[-1]
    curve: NurbsCurve = interpolate_curve(uv, degree=3)
    lo, hi = curve.domain
    return Side(region.surface, curve, lo, hi)


def _cut_region(region: Region, cuts: list[tuple[float, float]]) -> list[Region]:
    """The region cut from ``j0`` to ``j1`` at each ``(f, g)`` of ``cuts`` (arc-length
    fractions, increasing): the pieces in order along i."""
    j0, j1 = region.sides["j0"], region.sides["j1"]
    x0 = np.concatenate([[0.0], j0.at_fractions(np.array([f for f, _ in cuts])), [1.0]])
    x1 = np.concatenate([[0.0], j1.at_fractions(np.array([g for _, g in cuts])), [1.0]])
    walls = [region.sides["i0"]] + [_cut_line(region, f, g) for f, g in cuts] + [region.sides["i1"]]
    return [Region(region.surface, {"j0": _piece(j0, x0[k], x0[k + 1]), "j1": _piece(j1, x1[k], x1[k + 1]),
                                    "i0": walls[k], "i1": walls[k + 1]})
            for k in range(len(walls) - 1)]


def _transposed(region: Region) -> Region:
    """The same region with i and j exchanged (``j0`` <-> ``i0``, ``j1`` <-> ``i1``: each
    side keeps its direction)."""
    s = region.sides
    return Region(region.surface, {"j0": s["i0"], "j1": s["i1"], "i0": s["j0"], "i1": s["j1"]})


def _split_rectangle(surface: NurbsSurface, fractions: NDArray, direction: str) -> list[NurbsSurface]:
    """A rectangle cut along iso-lines at the given fractions of its domain in ``direction``."""
    u0, u1, v0, v1 = surface.domain
    lo, hi = (u0, u1) if direction == "u" else (v0, v1)
    f = np.sort(fractions)
    f = f[(f > _APART) & (f < 1.0 - _APART)]
    f = f[np.concatenate([[True], np.diff(f) > _APART])]        # one cut where two nearly coincide
    pieces, rest = [], surface
    for value in lo + f * (hi - lo):
        low, rest = rest.split(float(value), direction)
        pieces.append(low)
    return pieces + [rest]


def _folded(region: Region) -> bool:
    """A coarse (9 x 9) transfinite grid of the region in its surface's parameters has cells
    turned against the others (a cut leaving a very non-convex region)."""
    x = np.linspace(0.0, 1.0, _CHECK)
    uv = region.sides_uv(dict.fromkeys(SIDE_NAMES, x))
    st = transfinite(uv["j0"], uv["j1"], uv["i0"], uv["i1"])
    turn = corner_jacobians(st[..., 0], st[..., 1])
    return not (np.all(turn > 0.0) or np.all(turn < 0.0))


def _cut(item: NurbsSurface | Region, found: dict[str, NDArray]) -> list[tuple] | None:
    """One round's cuts of a block: across i where its ``j`` sides hold corners, else across
    j; None when none can be made, or when a piece would fold in the surface's
    parameters (a coarse transfinite grid of it, :func:`_folded`) where the block does
    not. A rectangle is split along iso-lines (its pieces are rectangles) unless a corner
    on one side has one on the other nearly across (within :data:`SNAP`, not exactly):
    then it is cut as any region is, the cut slanted from one to the other. Returns the
    pieces, each with its region."""
    region = _as_region(item)
    pieces = _pieces(item, region, found)
    if pieces is None:
        return None
    cut = [_as_region(p) for p in pieces]
    if not all(p.is_rectangle for p in cut) and any(_folded(p) for p in cut) and not _folded(region):
        return None                           # a cut that would fold a block is not made
    return list(zip(pieces, cut, strict=True))


def _pieces(item: NurbsSurface | Region, region: Region, found: dict[str, NDArray]) -> list | None:
    """The pieces of :func:`_cut`, unchecked."""
    empty = np.zeros(0)
    for near, far, transpose in (("j0", "j1", False), ("i0", "i1", True)):
        on_near, on_far = found.get(near, empty), found.get(far, empty)
        if on_near.size == 0 and on_far.size == 0:
            continue
        if region.is_rectangle:
            a = region.sides[near].at_fractions(on_near)
            b = region.sides[far].at_fractions(on_far)
            slanted = any(1e-9 < abs(x - y) <= SNAP for x in a for y in b)
            if not slanted:
                pieces = _split_rectangle(region.surface, np.concatenate([a, b]), _ACROSS[near])
                if len(pieces) == 1:
                    continue
                return pieces if isinstance(item, NurbsSurface) else [Region.rectangle(p) for p in pieces]
        cuts = _paired(on_near, on_far)
        if not cuts:
            continue
        if transpose:
            return [_transposed(p) for p in _cut_region(_transposed(region), cuts)]
        return _cut_region(region, cuts)
    return None


def conforming(surfaces: list[NurbsSurface | Region], *, gap: float,
               fixed: frozenset[int] = frozenset()) -> Conforming:
    """The blocks cut until no corner lies inside another block's side (see the module doc).

    Parameters
    ----------
    surfaces : list of NurbsSurface (their whole rectangles) or Region
    gap : float
        Model units (as :func:`t_junctions`).
    fixed : set of int
        Blocks not to cut (a block holding curves as grid lines).

    Returns
    -------
    Conforming
    """
    items = list(surfaces)
    regions = [_as_region(s) for s in items]          # kept: their sides' lengths are cached
    origin = list(range(len(items)))
    cuts = 0
    found = t_junctions(regions, gap=gap)
    # the state with the fewest corners left inside sides (a cascade of cuts can make more
    # than it resolves: occt_cornetta.stp 104 -> 1055 at the growth limit)
    best = (sum(f.size for f in found.values()), 0, tuple(items), tuple(origin))
    for _ in range(MAX_ROUNDS):
        if not found or len(items) >= MAX_GROWTH * max(len(surfaces), 1):
            break
        by_block: dict[int, dict[str, NDArray]] = {}
        for (b, name), f in found.items():
            if origin[b] not in fixed:
                by_block.setdefault(b, {})[name] = f
        if not by_block:
            break
        out, out_regions, out_origin, moved, fresh = [], [], [], {}, []
        for b, item in enumerate(items):
            try:
                pieces = _cut(item, by_block[b]) if b in by_block else None
            except SurfprepError:
                pieces = None                 # a cut that cannot be made (a degenerate line): the T stays
            if pieces is None:
                moved[b] = len(out)
                out.append(item)
                out_regions.append(regions[b])
                out_origin.append(origin[b])
                continue
            fresh.extend(range(len(out), len(out) + len(pieces)))
            out.extend(p for p, _ in pieces)
            out_regions.extend(r for _, r in pieces)
            out_origin.extend([origin[b]] * len(pieces))
        if not fresh:
            break
        cuts += len(fresh) - (len(items) - len(moved))
        items, regions, origin = out, out_regions, out_origin
        # the blocks not cut keep what was found on them; the pieces are looked at whole,
        # and the others only for the pieces' corners
        found = {(moved[b], name): f for (b, name), f in found.items() if b in moved}
        new = t_junctions(regions, gap=gap, blocks=fresh)
        for key, f in t_junctions(regions, gap=gap, blocks=sorted(moved.values()), corners=fresh).items():
            both = np.sort(np.concatenate([found.get(key, np.zeros(0)), f]))
            length = regions[key[0]].sides[key[1]].length
            found[key] = both[np.concatenate([[True], np.diff(both) * length > gap])]
        found.update(new)
        left = sum(f.size for f in found.values())
        if left < best[0]:
            best = (left, cuts, tuple(items), tuple(origin))
    left, cuts, items, origin = best
    return Conforming(items, origin, cuts, left)
