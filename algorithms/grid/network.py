"""Point-matched structured grids over a network of four-sided surfaces.

A network is a list of surfaces (the faces of a healed model, one block each)
whose sides meet edge to edge. :func:`grid_network`

0. cuts the blocks whose sides hold another block's corner through that point
   (:mod:`.conforming`), so every edge two blocks share is a whole side of both;
1. finds the sides two surfaces share (:func:`match_sides`: ends and samples
   within ``gap`` of each other, in either direction);
2. gives every set of sides linked through the blocks (opposite sides of a
   block, matched sides of two blocks) one node count, from ``dims`` or from
   the longest side of the set over ``size``;
3. places the nodes of a shared side once, on the first block that has it, and
   gives the other block the same nodes (the first block's nodes projected on
   its side, so both grids stand on their own surfaces);
4. grids every block (:func:`.structured.grid_surface`);
5. with elliptic smoothing, lets the interface nodes slide along their edge
   until the grid lines cross it smoothly (:mod:`.sliding`: the Winslow stencil of
   both blocks together moves them; the blocks are refined again around them);
6. copies the first block's coordinates onto the other's side, so matched nodes
   are identical to the bit, and reports how far that moved them (the gap
   between the surfaces);
7. measures the kink of the grid lines that cross each interface: the angle
   between the last cell leg in one block and the first in the other.

Blocks are in the surfaces' order; each block's sides are ``"i0"`` (u = u0),
``"i1"``, ``"j0"`` (v = v0), ``"j1"`` as in :mod:`.structured`. A block on a region
of a pole cap's chart (:mod:`.polar`) is returned with its parameters in the cap's
``(u, v)``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError, SurfprepError
from ..surface import NurbsSurface
from .conforming import conforming
from .edges import SMOOTH_INTERFACE, crease, inner_line, side_parameters, transfer
from .io.blocks import Interface, side_nodes
from .polar import PoleChart
from .region import Region
from .sliding import slide_interfaces
from .structured import (
    DEFAULT_CELLS,
    SIDES,
    Spacing,
    SurfaceGrid,
    grid_region,
)

__all__ = ["NetworkGrid", "grid_network", "match_sides"]

#: a block side longer than this many times its surface's box diagonal is refused (its
#: pcurve runs off the domain, where the surface is extrapolated: 1.3e7 mm on a 304 mm part)
LONG_SIDE = 10.0
#: samples compared along two sides to call them one edge
MATCH_SAMPLES = 9


@dataclass(frozen=True)
class NetworkGrid:
    """Grids of a network of surfaces, one block per surface.

    Attributes
    ----------
    blocks : tuple of SurfaceGrid
    interfaces : tuple of Interface
        Matched sides (their nodes are identical).
    snap : float
        Largest move of a node copied from one block onto its neighbour's side.
    kink : float
        Largest angle (degrees) between the grid lines on the two sides of a smooth
        interface (one whose surfaces' normals agree within :data:`SMOOTH_INTERFACE`).
    interface_rounds : int
        Rounds of sliding the interface nodes (0 without elliptic smoothing).
    interface_angles : tuple of (float, float)
        Per interface: the kink of the grid lines and the crease (normals' angle), degrees.
    indices : tuple of int
        The position of each block's surface in the list given (the pieces of a surface
        cut to conform share it).
    failed : tuple of (int, str)
        Surfaces that could not be gridded (a degenerate surface...), with the reason;
        the others are gridded without them.
    dims_changed : tuple of (int, str, int)
        With ``dims`` (NI != NJ): ``(block, "i" | "j", count)`` for each direction that
        got the other count, because a shared edge links it to a direction of the
        other kind.
    cuts : int
        Cuts made through blocks so that no block corner lies inside another block's
        side (:mod:`.conforming`); the pieces of a surface share its index.
    t_junctions_left : int
        Block corners still inside another block's side (their grids do not meet there).
    """

    blocks: tuple[SurfaceGrid, ...]
    interfaces: tuple[Interface, ...]
    snap: float = 0.0
    kink: float = 0.0
    interface_rounds: int = 0
    interface_angles: tuple[tuple[float, float], ...] = ()
    indices: tuple[int, ...] = ()
    failed: tuple[tuple[int, str], ...] = ()
    time_s: float = field(default=0.0, compare=False)
    dims_changed: tuple[tuple[int, str, int], ...] = ()
    cuts: int = 0
    t_junctions_left: int = 0

    def report(self) -> dict:
        return {"blocks": [b.report() for b in self.blocks],
                "interfaces": [{"block": f.block, "side": f.side, "other": f.other,
                                "other_side": f.other_side, "reversed": f.reversed,
                                "kink_deg": k, "crease_deg": c}
                               for f, (k, c) in zip(self.interfaces, self.interface_angles, strict=True)],
                "snap": self.snap, "kink_deg": self.kink, "interface_rounds": self.interface_rounds,
                "dims_changed": [{"block": b, "direction": d, "nodes": n} for b, d, n in self.dims_changed],
                "cuts": self.cuts, "t_junctions_left": self.t_junctions_left, "time_s": self.time_s}


def _direction(side: str) -> int:
    """0 for the sides that run in i (``j0``, ``j1``), 1 for those that run in j."""
    return 0 if side in ("j0", "j1") else 1


def match_sides(regions: list[NurbsSurface | Region], *, gap: float) -> list[Interface]:
    """Sides of different blocks (or of one closed surface) that are one edge.

    Two sides match when their samples at equal fractions of their arc length (in
    the same or the opposite direction) are within ``gap`` of each other: equal
    fractions of the *parameters* would put the samples of one edge at different
    places on two faces parametrized differently along it (a reparametrized face
    beside one that is not). Collapsed sides never match. Each side matches at most once (the
    first one found, in block order).

    Parameters
    ----------
    regions : list of NurbsSurface (their whole rectangles) or Region

    Returns
    -------
    list of Interface
    """
    regions = [_as_region(r) for r in regions]
    samples, lengths = {}, {}
    for b, region in enumerate(regions):
        for name, side in region.sides.items():
            pts = side.points(side.at_fractions(np.linspace(0.0, 1.0, MATCH_SAMPLES)))
            samples[b, name] = pts
            lengths[b, name] = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
    keys = [k for k in samples if lengths[k] > gap]
    used: set[tuple[int, str]] = set()
    out = []
    if not keys:
        return out
    # candidates by their ends: a side's first sample within gap of the other's first or last
    from scipy.spatial import cKDTree
    firsts = cKDTree(np.array([samples[k][0] for k in keys]))
    for x, key_a in enumerate(keys):
        if key_a in used:
            continue
        a = samples[key_a]
        near = sorted(set(firsts.query_ball_point(a[0], gap)) | set(firsts.query_ball_point(a[-1], gap)))
        for key_b in (keys[y] for y in near if y > x):
            if key_b in used:
                continue
            b = samples[key_b]
            for reverse in (False, True):
                other = b[::-1] if reverse else b
                if np.max(np.linalg.norm(a - other, axis=1)) <= gap:
                    out.append(Interface(key_a[0], key_a[1], key_b[0], key_b[1], reverse))
                    used.update((key_a, key_b))
                    break
            if key_a in used:
                break
    return out


def _as_region(item: NurbsSurface | Region) -> Region:
    return item if isinstance(item, Region) else Region.rectangle(item)


class _Classes:
    """Union-find over the directions ``(block, 0 | 1)``."""

    def __init__(self, n: int) -> None:
        self.parent = {(b, d): (b, d) for b in range(n) for d in (0, 1)}

    def find(self, x):
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def union(self, a, b) -> None:
        self.parent[self.find(a)] = self.find(b)


def _refused(region: Region) -> str | None:
    """Why a block cannot be gridded (a side of no finite length, or one far longer than its
    surface is wide: :data:`LONG_SIDE`), or None."""
    try:
        lengths = [side.length for side in region.sides.values()]
        if not all(np.isfinite(lengths)):
            return "a side of no finite length"
        across = float(np.linalg.norm(np.ptp(region.surface.bounding_box(), axis=0)))
    except SurfprepError as exc:
        return str(exc)
    if max(lengths) > LONG_SIDE * across:
        return (f"a side {max(lengths):.3g} long on a surface {across:.3g} across: the region's "
                "sides leave the surface's domain (a split gone astray)")
    return None


def _longest(region: Region) -> float:
    """The longest side of a region (NaN where a side has no length)."""
    try:
        return max(side.length for side in region.sides.values())
    except SurfprepError:
        return math.nan


def _counts(surfaces, interfaces, dims, size, skip: set[int] = frozenset()) -> dict[tuple[int, int], int]:
    """Node count of every direction ``(block, 0 | 1)``: one per linked set (blocks in
    ``skip`` get none)."""
    classes = _Classes(len(surfaces))
    for f in interfaces:
        classes.union((f.block, _direction(f.side)), (f.other, _direction(f.other_side)))
    if dims is not None:
        # a set of linked directions holding i's and j's (a face split into blocks round
        # a centre, faces of a box) takes the larger count: no side gets fewer nodes than
        # asked (NetworkGrid.dims_changed names the directions that got more)
        ni, nj = dims
        counts: dict = {}
        for key in classes.parent:
            if key[0] in skip:
                continue
            root = classes.find(key)
            counts[root] = max(counts.get(root, 0), ni if key[1] == 0 else nj)
        return {key: counts[classes.find(key)] for key in classes.parent if key[0] not in skip}
    longest: dict = {}
    for b, region in enumerate(surfaces):
        if b in skip:
            continue
        for name, side in region.sides.items():
            root = classes.find((b, _direction(name)))
            longest[root] = max(longest.get(root, 0.0), side.length)
    size = float(size)
    return {key: max(2, math.ceil(longest[classes.find(key)] / size - 1e-9) + 1)
            for key in classes.parent if key[0] not in skip}


def grid_network(surfaces: list[NurbsSurface | Region], *, gap: float, dims: tuple[int, int] | None = None,
                 size: float | None = None, spacing: Spacing | tuple[Spacing, Spacing] | None = None,
                 smooth: str = "elliptic", orthogonal: bool = True, tol: float = 1e-4,
                 max_sweeps: int = 2000, hold: dict[int, list] | None = None,
                 conform: bool = True, progress=None) -> NetworkGrid:
    """Point-matched grids over a network of four-sided surfaces (see the module doc).

    Parameters
    ----------
    surfaces : list of NurbsSurface (their whole rectangles) or Region (a trimmed face's)
    gap : float
        Largest distance between two sides called one edge (model units).
    dims : (int, int), optional
        Nodes along i and j of every block. Where shared edges link an i direction to a
        j direction (a face split into blocks round a centre, the faces of a box), the
        linked directions all take the larger of the two (``dims_changed`` lists them).
    size : float, optional
        Target cell size; default the median over the blocks of their longest side
        over :data:`~.structured.DEFAULT_CELLS`.
    spacing, smooth, orthogonal, tol, max_sweeps
        As in :func:`~.structured.grid_surface` (default spacing: uniform in arc length).
    hold : dict, optional
        Surface index to the curves held as grid lines on it (see
        :func:`~.structured.grid_surface`; tolerance ``gap``).
    conform : bool
        Cut blocks whose sides hold another block's corner (a T-junction) through that
        point, so every shared edge is a whole side of both blocks and is matched
        (:func:`.conforming.conforming`; a surface with held curves is not cut).
    progress : callable(done, total), optional

    Returns
    -------
    NetworkGrid
    """
    started = time.perf_counter()
    if not surfaces:
        raise InvalidGeometryError("a network needs at least one surface")
    if dims is not None and size is not None:
        raise InvalidGeometryError("give dims or size, not both")
    spacing = Spacing() if spacing is None else spacing
    surfaces = [_as_region(s) for s in surfaces]
    given = len(surfaces)
    origin: tuple[int, ...] = tuple(range(given))
    cuts = left = 0
    if dims is None and size is None:
        # from the blocks given (their pieces are shorter)
        size = float(np.median([_longest(r) for r in surfaces if np.isfinite(_longest(r))] or [1.0])) \
            / DEFAULT_CELLS

    if conform:
        # (blocks refused below are not cut)
        fixed = frozenset(hold or {}) | {b for b, r in enumerate(surfaces) if _refused(r) is not None}
        made = conforming(surfaces, gap=gap, fixed=fixed)
        surfaces, origin, cuts, left = list(made.surfaces), made.origin, made.cuts, made.left
        hold = {b: (hold or {})[k] for b, k in enumerate(origin) if k in (hold or {})}
    failed = {b: why for b, why in ((b, _refused(r)) for b, r in enumerate(surfaces)) if why is not None}
    usable = [b for b in range(len(surfaces)) if b not in failed]
    interfaces = [Interface(usable[f.block], f.side, usable[f.other], f.other_side, f.reversed)
                  for f in match_sides([surfaces[b] for b in usable], gap=gap)]
    counts = _counts(surfaces, interfaces, dims, size, skip=set(failed))
    partner = {}
    for f in interfaces:
        partner[f.block, f.side] = (f.other, f.other_side, f.reversed)
        partner[f.other, f.other_side] = (f.block, f.side, f.reversed)
    blocks: list[SurfaceGrid | None] = []
    if progress is not None:
        progress(0, len(surfaces))
    for b, surface in enumerate(surfaces):
        if b in failed:
            blocks.append(None)
            continue
        try:
            given = {}
            for side in SIDES:
                if (b, side) in partner and partner[b, side][0] < b \
                        and blocks[partner[b, side][0]] is not None:
                    a, side_a, reverse = partner[b, side]
                    fractions = side_parameters(blocks[a], side_a)
                    given[side] = transfer(surfaces[a], side_a, fractions, surface, side, reverse)
            blocks.append(grid_region(surface, dims=(counts[b, 0], counts[b, 1]), spacing=spacing,
                                      smooth=smooth, tol=tol, max_sweeps=max_sweeps, sides=given,
                                      # square to the network's open sides, not across its
                                      # interfaces (there the lines are made to run on smoothly)
                                      orthogonal=orthogonal and tuple(
                                          side for side in SIDES if (b, side) not in partner),
                                      hold=(hold or {}).get(b, ()), hold_tol=gap))
        except SurfprepError as exc:
            failed[b] = str(exc)
            blocks.append(None)
        if progress is not None:
            progress(b + 1, len(surfaces))
    if len(failed) == len(surfaces):
        raise InvalidGeometryError("no surface could be gridded: " + "; ".join(
            f"surface {b}: {why}" for b, why in sorted(failed.items())[:3]))
    keep = [b for b in range(len(surfaces)) if b not in failed]
    index = {b: k for k, b in enumerate(keep)}
    interfaces = [Interface(index[f.block], f.side, index[f.other], f.other_side, f.reversed)
                  for f in interfaces if f.block in index and f.other in index]
    surfaces = [surfaces[b] for b in keep]
    blocks = [blocks[b] for b in keep]
    rounds = 0
    if smooth == "elliptic" and interfaces:
        budget = time.perf_counter() - started          # sliding may at most double the work
        blocks, rounds = slide_interfaces(surfaces, blocks, interfaces, tol=tol,
                                           max_sweeps=max_sweeps, budget=budget,
                                           orthogonal=orthogonal)
    net = _snapped(surfaces, blocks, interfaces, started, rounds)
    net = replace(net, blocks=tuple(_in_surface_parameters(b, r) for b, r in zip(net.blocks, surfaces, strict=True)))
    changed = () if dims is None else tuple(
        (index[b], "ij"[d], counts[b, d]) for (b, d) in sorted(counts) if b in index and counts[b, d] != dims[d])
    lost = {}
    for b, why in failed.items():
        lost.setdefault(origin[b], why)
    return replace(net, indices=tuple(origin[b] for b in keep), failed=tuple(sorted(lost.items())),
                   dims_changed=changed, cuts=cuts, t_junctions_left=left)


def _in_surface_parameters(block: SurfaceGrid, region: Region) -> SurfaceGrid:
    """A block on a region of a pole cap's chart with its parameters the cap's ``(u, v)``
    (:meth:`.polar.PoleChart.to_surface`); any other block as it is."""
    chart = region.surface
    if not isinstance(chart, PoleChart):
        return block
    start = None if block.start_parameters is None else chart.to_surface(block.start_parameters)
    return replace(block, parameters=chart.to_surface(block.parameters), start_parameters=start)


def _snapped(surfaces, blocks: list[SurfaceGrid], interfaces: list[Interface], started: float,
             rounds: int) -> NetworkGrid:
    """Give every set of matched nodes (across all interfaces: a corner where several
    blocks meet is one set) the coordinates of its first block's node; measure the
    moves and the kinks."""
    from .polar import surface_normals as normals
    points = [b.points.copy() for b in blocks]
    parent: dict = {}

    def find(key):
        parent.setdefault(key, key)
        while parent[key] != key:
            parent[key] = parent[parent[key]]
            key = parent[key]
        return key

    for f in interfaces:
        a = _side_keys(f.block, f.side, blocks[f.block].dims)
        b = _side_keys(f.other, f.other_side, blocks[f.other].dims)
        if f.reversed:
            b = b[::-1]
        for ka, kb in zip(a, b, strict=True):
            ra, rb = find(ka), find(kb)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)         # the first block's node leads
    snap = 0.0
    for key in list(parent):
        root = find(key)
        if root != key:
            target = points[root[0]][root[1], root[2]]
            snap = max(snap, float(np.linalg.norm(points[key[0]][key[1], key[2]] - target)))
            points[key[0]][key[1], key[2]] = target
    kink = 0.0
    figures: list[tuple[float, float]] = []
    for f in interfaces:
        a, b = points[f.block], points[f.other]
        uv = side_nodes(blocks[f.block].parameters, f.side)
        k = _kink(a, f.side, b, f.other_side, f.reversed,
                  blocks[f.block].orientation * normals(surfaces[f.block].surface, uv[:, 0], uv[:, 1]))
        c = crease(surfaces, blocks, f)
        figures.append((k, c))
        if c <= SMOOTH_INTERFACE:
            kink = max(kink, k)
    out = tuple(replace(g, points=p) for p, g in zip(points, blocks, strict=True))
    return NetworkGrid(out, tuple(interfaces), snap, kink, rounds, tuple(figures),
                       time.perf_counter() - started)


def _side_keys(block: int, side: str, dims: tuple[int, int]) -> list[tuple[int, int, int]]:
    """``(block, i, j)`` of a side's nodes in the order of the index running along it."""
    ni, nj = dims
    return {"i0": [(block, 0, j) for j in range(nj)], "i1": [(block, ni - 1, j) for j in range(nj)],
            "j0": [(block, i, 0) for i in range(ni)], "j1": [(block, i, nj - 1) for i in range(ni)]}[side]


def _turn(a: NDArray, b: NDArray, c: NDArray, normals: NDArray) -> NDArray:
    """Signed turning angle (radians) of the polylines ``a -> b -> c`` about ``normals``."""
    d1, d2 = b - a, c - b
    return np.arctan2(np.einsum("ij,ij->i", np.cross(d1, d2), normals), np.einsum("ij,ij->i", d1, d2))


def _kink(a: NDArray, side_a: str, b: NDArray, side_b: str, reverse: bool,
          normals: NDArray) -> float:
    """Largest kink (degrees) of the lines crossing an interface, ends left out.

    The turning of each crossing line at the interface node, in the tangent plane
    (about the surface normal ``normals`` (n, 3)), less the mean of its turning at
    the nodes just before and after: a line that bends as it did inside both
    blocks (a ring round a pole turns at every node) has no kink; a line that
    breaks at the interface has one. Blocks of fewer than 3 lines across count the
    turning alone.
    """
    edge = side_nodes(a, side_a)
    before = inner_line(a, side_a)
    after = inner_line(b, side_b)
    if reverse:
        after = after[::-1]
    turn = _turn(before, edge, after, normals)
    deep = min(a.shape[0 if side_a[0] == "i" else 1], b.shape[0 if side_b[0] == "i" else 1]) >= 3
    if deep:
        before2 = inner_line(a, side_a, 2)
        after2 = inner_line(b, side_b, 2)
        if reverse:
            after2 = after2[::-1]
        turn = turn - 0.5 * (_turn(before2, before, edge, normals) + _turn(edge, after, after2, normals))
    inner = np.abs(turn[1:-1])
    inner = inner[np.isfinite(inner)]
    return float(np.degrees(inner.max())) if inner.size else 0.0
