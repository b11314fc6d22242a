"""Nodes of the edges two blocks share, slid along them until the grid lines cross smoothly.

Each round moves the inner nodes of every smooth shared edge (not a crease, not a
block's own seam) by the Winslow stencil of its two blocks together, the lines across
the edge taken as one (:func:`_edge_moves`), limited so that no interval of the edge
grows or shrinks by more than :data:`SLIDE_STRETCH` against the distribution it was
given; gives both blocks the new side nodes (the second block's by projection,
:func:`.edges.transfer`), carries the sides' moves into the blocks and refines them
again from where they were. See :func:`slide_interfaces`.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError
from .edges import (
    SMOOTH_INTERFACE,
    crease,
    inner_line,
    on_seam,
    set_side_parameters,
    side_parameters,
    transfer,
)
from .io.blocks import Interface, side_nodes
from .region import Region
from .structured import SIDES, SurfaceGrid, plain_kept, squeezes_corners

__all__ = ["INTERFACE_PROGRESS", "INTERFACE_RELAXATION", "INTERFACE_ROUNDS", "INTERFACE_TOL", "SLIDE_STRETCH",
           "slide_interfaces"]

#: rounds of sliding interface nodes at most, the move (in cells) they stop at, and
#: the share of each move taken
INTERFACE_ROUNDS = 12
INTERFACE_TOL = 1e-3
INTERFACE_RELAXATION = 0.8
#: a slide changes no interval of a shared edge by more than this factor against the
#: distribution it was given (the Winslow stencil across an edge pulls its nodes toward
#: a corner where three blocks meet, crowding the cells there: growth ratios of 2)
SLIDE_STRETCH = 1.15
#: the rounds stop when the largest move has not shrunk below this share of the round before
INTERFACE_PROGRESS = 0.95


def _edge_stencil(blocks: list[SurfaceGrid], f: Interface) -> tuple[NDArray, ...]:
    """Nodes of an interface and of the lines beside it in both blocks, in block a's order."""
    a, b = blocks[f.block].points, blocks[f.other].points
    edge = side_nodes(a, f.side)
    before = inner_line(a, f.side)
    after = inner_line(b, f.other_side)
    if f.reversed:
        after = after[::-1]
    return edge, before, after


def _stretch_limited(t: NDArray, given: NDArray) -> NDArray:
    """Side parameters ``t`` (increasing, ends fixed) with no interval more than
    :data:`SLIDE_STRETCH` times longer or shorter than in ``given``: the intervals
    clipped and rescaled to the same total until they hold."""
    d0 = np.diff(given)
    d = np.diff(t)
    lo, hi = d0 / SLIDE_STRETCH, d0 * SLIDE_STRETCH
    for _ in range(50):
        d = np.clip(d, lo, hi)
        d *= (given[-1] - given[0]) / d.sum()
        if np.all(d >= lo * (1 - 1e-9)) and np.all(d <= hi * (1 + 1e-9)):
            break
    out = given[0] + np.concatenate([[0.0], np.cumsum(d)])
    out[-1] = given[-1]
    return out


def _edge_moves(edge: NDArray, before: NDArray, after: NDArray) -> NDArray:
    """Jacobi moves of the inner nodes of an interface along it (model units), from the
    Winslow stencil of the two blocks together (:mod:`.elliptic_kernels`'s update, with
    xi across the interface and eta along it), ``(n - 2,)``."""
    r_xi = 0.5 * (after[1:-1] - before[1:-1])
    r_eta = 0.5 * (edge[2:] - edge[:-2])
    r_xe = 0.25 * (after[2:] - after[:-2] - before[2:] + before[:-2])
    g11 = np.einsum("ij,ij->i", r_xi, r_xi)
    g22 = np.einsum("ij,ij->i", r_eta, r_eta)
    g12 = np.einsum("ij,ij->i", r_xi, r_eta)
    diag = 2.0 * (g11 + g22)
    diag = np.where(diag > 0, diag, 1.0)
    move = (g22[:, None] * (after[1:-1] + before[1:-1]) + g11[:, None] * (edge[2:] + edge[:-2])
            - 2.0 * g12[:, None] * r_xe) / diag[:, None] - edge[1:-1]
    tangent = r_eta / np.maximum(np.linalg.norm(r_eta, axis=1), 1e-300)[:, None]
    return np.einsum("ij,ij->i", move, tangent)


def slide_interfaces(surfaces: list[Region], blocks: list[SurfaceGrid], interfaces: list[Interface], *,
                      tol: float, max_sweeps: int, budget: float = math.inf,
                      orthogonal: bool = False) -> tuple[list[SurfaceGrid], int]:
    """Let the nodes of every interface slide along it until the grid lines cross it
    smoothly: each round moves them by the Winslow stencil of both blocks together
    (:func:`_edge_moves`), gives both blocks the new side nodes and refines the
    blocks again from where they were. Stops when no node would move more than
    :data:`INTERFACE_TOL` of its cell, when the moves stop shrinking
    (:data:`INTERFACE_PROGRESS`), after :data:`INTERFACE_ROUNDS` rounds, or once the
    rounds took ``budget`` seconds (the caller's: as long as gridding the blocks did)."""
    from .elliptic import refine
    from .elliptic_kernels import folds
    from .polar import surface_normals as normals
    from .quality import grid_quality
    from .tfi import carried_inward
    params = [b.parameters.copy() for b in blocks]
    side_params = [dict(b.side_params) for b in blocks]
    grids = list(blocks)
    # creases do not slide, nor do blocks that kept their algebraic grid or hold curves
    # (refined piece by piece between them)
    still = {k for k, b in enumerate(blocks) if b.kept_start is not None or b.held}
    # the sides the lines leave at right angles: those that are no interface (of any kind)
    shared = {(f.block, f.side) for f in interfaces} | {(f.other, f.other_side) for f in interfaces}
    open_sides = [tuple(side for side in SIDES if (k, side) not in shared) for k in range(len(blocks))]
    interfaces = [f for f in interfaces if crease(surfaces, blocks, f) <= SMOOTH_INTERFACE
                  and f.block not in still and f.other not in still and not on_seam(blocks, f)]
    # the distributions the shared edges were given, which a slide may stretch only so far
    given = {(f.block, f.side): side_parameters(grids[f.block], f.side) for f in interfaces}
    touched: set[int] = set()
    rounds = 0
    previous = math.inf
    began = time.perf_counter()
    for rounds in range(1, INTERFACE_ROUNDS + 1):
        worst = 0.0
        changed: set[int] = set()
        for f in interfaces:
            edge, before, after = _edge_stencil(grids, f)
            if edge.shape[0] < 3:
                continue
            move = _edge_moves(edge, before, after)
            legs = np.linalg.norm(np.diff(edge, axis=0), axis=1)
            cell = np.maximum(np.minimum(legs[1:], legs[:-1]), 1e-300)
            worst = max(worst, float(np.max(np.abs(move) / cell)))
            # along block a's side curve: arc length to parameter by the local chord
            t = side_parameters(grids[f.block], f.side)
            dt = np.diff(t)
            step = move / np.where(move > 0, legs[1:], legs[:-1]) * np.where(move > 0, dt[1:], dt[:-1])
            step = np.clip(INTERFACE_RELAXATION * step, -0.5 * dt[:-1], 0.5 * dt[1:])
            t_new = t.copy()
            t_new[1:-1] += step
            t_new = _stretch_limited(t_new, given[f.block, f.side])
            try:
                t_b = transfer(surfaces[f.block], f.side, t_new, surfaces[f.other], f.other_side,
                                f.reversed)
            except InvalidGeometryError:
                continue                      # this edge's nodes stay where they are this round
            for block, side, values in ((f.block, f.side, t_new), (f.other, f.other_side, t_b)):
                set_side_parameters(params[block], surfaces[block], side, values)
                side_params[block][side] = values
                changed.add(block)
        if worst < INTERFACE_TOL or worst > INTERFACE_PROGRESS * previous \
                or time.perf_counter() - began > budget:
            break                             # converged, the moves no longer shrink, or out of time
        previous = worst
        for k in changed:
            # the sides' slide carried into the block (unless that folds a cell): the warm
            # solve then starts without the slide's long-wave error
            if grids[k].seam is None:
                moved = carried_inward(grids[k].parameters, params[k])
                if not folds(moved[..., 0], moved[..., 1], grids[k].orientation):
                    params[k] = moved
            squared = orthogonal and grids[k].orthogonal_dropped is None and open_sides[k]
            seam = grids[k].seam
            earlier = grids[k].elliptic
            result = refine(surfaces[k].surface, params[k], tol=tol, max_sweeps=max_sweeps, warm=True,
                            orthogonal=squared, seam=seam,
                            resume=earlier.control if earlier is not None else None)
            if squared and not result.nearly_converged(tol):      # as grid_region: the plain grid
                plain = refine(surfaces[k].surface, params[k], tol=tol, max_sweeps=max_sweeps, warm=True,
                               seam=seam)
                if result.yields_to(plain):
                    result = plain
                    grids[k] = replace(grids[k], orthogonal_dropped=(
                        "the sides' orthogonality was not reached after the shared edges' nodes "
                        "slid; the grid without it is kept"))
            params[k] = result.parameters.copy()
            points = surfaces[k].surface.evaluate(params[k][..., 0], params[k][..., 1])
            grids[k] = replace(grids[k], points=points, parameters=params[k], elliptic=result,
                               side_params=dict(side_params[k]))
            touched.add(k)
    for k in touched:
        # the parameters its points were evaluated at (params[k] may hold a last round's side
        # moves that were never refined: the loop stops once they are small)
        g = grids[k]
        p = g.elliptic.parameters
        quality = grid_quality(g.points, g.orientation * normals(surfaces[k].surface, p[..., 0], p[..., 1]))
        grids[k] = replace(g, parameters=p.copy(), quality=quality)
        if orthogonal and g.orthogonal_dropped is None and open_sides[k] and squeezes_corners(quality, g.points):
            # as grid_region: squared sides that squeeze a sharp corner's cells are given up
            plain = refine(surfaces[k].surface, p, tol=tol, max_sweeps=max_sweeps, warm=True, seam=g.seam)
            pp = plain.parameters
            points = surfaces[k].surface.evaluate(pp[..., 0], pp[..., 1])
            plain_quality = grid_quality(points, g.orientation * normals(surfaces[k].surface, pp[..., 0],
                                                                         pp[..., 1]))
            why = plain_kept(quality, plain, plain_quality, tol)
            if why is not None:
                grids[k] = replace(g, points=points, parameters=pp.copy(), elliptic=plain,
                                   quality=plain_quality, orthogonal_dropped=why)
    return grids, rounds
