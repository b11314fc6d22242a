"""Chains cut where they cross a seam of a closed surface (000 §29.4.1, step 4).

A closed surface converted to a B-spline (a sphere, a cylinder, a torus) has
two parameter lines that are one curve in space. The soup's ends on both sides
of it are one 3D point, so the topology merges them and a chain crosses the
seam with a jump of almost the whole period in ``u`` (or ``v``); refining
across that chord would average the parameters of the two sides. Chains are
therefore cut at every step whose parameter change exceeds half the domain on
a side where the surface is closed (the point moved to the opposite side of
the domain is the same point in space); the cut point is duplicated and each
copy gets the parameter of the side it continues on (the domain end opposite
to the one the merged point kept). A loop crossing a seam once comes out as
one open curve whose two ends coincide in space.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from .topology import Chain, EndKind, SegmentTopology

__all__ = ["closed_directions", "cut_at_seams", "other_side", "seam_jumps", "seam_restarts"]


def seam_jumps(uv: NDArray | None, surface: NurbsSurface | None, closed: bool,
           closure_tol: float) -> NDArray:
    """Steps ``(s,) bool`` of a chain that cross a seam of ``surface``.

    ``uv`` is the chain's ``(n, 2)`` parameters; step ``i`` goes from sample
    ``i`` to ``i + 1`` (the last step of a closed chain back to sample 0). A step
    crosses a seam when its (u, v) change by more than half the domain and one
    of its ends, moved to the opposite side of the domain in that coordinate,
    is the same point in space (within ``closure_tol``): the surface is closed
    there. A curve that merely spans an open surface with few samples has the
    large change but not the closure.
    """
    if uv is None or surface is None:
        n = 0 if uv is None else uv.shape[0]
        return np.zeros(max(n - (not closed), 0), dtype=bool)
    domain = surface.domain
    nxt = np.roll(uv, -1, axis=0) if closed else uv[1:]
    here = uv[: nxt.shape[0]]
    half = 0.5 * np.array([domain[1] - domain[0], domain[3] - domain[2]])
    jump = np.any(np.abs(nxt - here) > half, axis=1)
    steps = np.flatnonzero(jump)
    if steps.size:
        ends = np.concatenate([here[steps], nxt[steps]])              # (2c, 2)
        toward = np.concatenate([nxt[steps], here[steps]])
        moved = np.stack([other_side(e, t, domain) for e, t in zip(ends, toward)])
        gap = np.linalg.norm(surface.evaluate(moved[:, 0], moved[:, 1])
                             - surface.evaluate(ends[:, 0], ends[:, 1]), axis=1)
        seam = np.minimum(gap[: steps.size], gap[steps.size:]) <= closure_tol
        jump[steps[~seam]] = False
    return jump


def other_side(uv: NDArray, toward: NDArray, domain) -> NDArray:
    """``uv (2,)`` moved to the domain end nearer to ``toward`` in each coordinate
    whose difference exceeds half the domain (the seam's other parameter line)."""
    lo = np.array([domain[0], domain[2]])
    hi = np.array([domain[1], domain[3]])
    out = uv.copy()
    far = np.abs(toward - uv) > 0.5 * (hi - lo)
    out[far] = np.where(toward[far] > uv[far], hi[far], lo[far])
    return out


def _on_side(uv: NDArray, domain, rel: float = 1e-9) -> bool:
    """True when ``uv (2,)`` lies on a side of the domain (within ``rel`` of its size)."""
    lo = np.array([domain[0], domain[2]])
    hi = np.array([domain[1], domain[3]])
    eps = rel * (hi - lo)
    return bool(np.any((uv <= lo + eps) | (uv >= hi - eps)))


def _seam_point(j: int, uv_a: NDArray | None, uv_b: NDArray | None, domain_a, domain_b,
                jump_a: NDArray, jump_b: NDArray) -> int:
    """Which end of jump step ``j -> j + 1`` is the seam point: ``j`` or ``j + 1``
    (the one on a side of the domain of the surface that jumps)."""
    n = (uv_a if uv_a is not None else uv_b).shape[0]
    for uv, domain, jump in ((uv_a, domain_a, jump_a), (uv_b, domain_b, jump_b)):
        if uv is not None and domain is not None and jump[j]:
            return j if _on_side(uv[j], domain) else (j + 1) % n
    return j


def cut_at_seams(topology: SegmentTopology, surface_a: NurbsSurface | None,
                  surface_b: NurbsSurface | None, closure_tol: float) -> SegmentTopology:
    """Cut every chain at its seam jumps, duplicating the seam points (module docstring).

    Per chain (not per point) in Python; the samples themselves are numpy arrays.
    """
    domain_a = None if surface_a is None else surface_a.domain
    domain_b = None if surface_b is None else surface_b.domain
    points = [topology.points]
    uv_a = None if topology.uv_a is None else [topology.uv_a]
    uv_b = None if topology.uv_b is None else [topology.uv_b]
    count = topology.points.shape[0]
    chains: list[Chain] = []
    for chain in topology.chains:
        ids = chain.point_ids
        ca = None if uv_a is None else topology.uv_a[ids]
        cb = None if uv_b is None else topology.uv_b[ids]
        steps = max(ids.size - (not chain.closed), 0)         # a mesh side has no seam
        jump_a = (seam_jumps(ca, surface_a, chain.closed, closure_tol) if ca is not None
                  else np.zeros(steps, dtype=bool))
        jump_b = (seam_jumps(cb, surface_b, chain.closed, closure_tol) if cb is not None
                  else np.zeros(steps, dtype=bool))
        jump = jump_a | jump_b
        if not jump.any():
            chains.append(chain)
            continue
        n = ids.size
        cuts = np.flatnonzero(jump)
        if chain.closed:          # start right after the first jump, end at it
            order = np.roll(np.arange(n), -(int(cuts[0]) + 1))
        else:
            order = np.arange(n)
        pieces: list[list[int]] = [[int(order[0])]]
        # the jump step each piece starts / ends at (None: a chain end)
        starts: list[int | None] = [None]
        stops: list[int | None] = []
        for k in range(1, n):
            step = int(order[k - 1])              # the step from order[k-1] to order[k]
            if jump[step]:
                seam = _seam_point(step, ca, cb, domain_a, domain_b, jump_a, jump_b)
                if seam == step:
                    pieces.append([step, int(order[k])])
                else:
                    pieces[-1].append(int(order[k]))
                    pieces.append([int(order[k])])
                stops.append(step)
                starts.append(step)
            else:
                pieces[-1].append(int(order[k]))
        stops.append(None)
        if chain.closed:          # the closing step is the first jump
            step = int(order[-1])
            seam = _seam_point(step, ca, cb, domain_a, domain_b, jump_a, jump_b)
            if seam == step:
                pieces[0].insert(0, step)
            else:
                pieces[-1].append(int(order[0]))
            starts[0], stops[-1] = step, step
        for k, local in enumerate(pieces):
            if len(local) < 2:
                continue
            local = np.asarray(local)
            piece_uv = []
            for cuv, domain, jumps in ((ca, domain_a, jump_a), (cb, domain_b, jump_b)):
                if cuv is None:
                    piece_uv.append(None)
                    continue
                part = cuv[local].copy()
                # only the surface that jumps there is moved to its seam's other side
                # (the other's (u, v) may change by much between two sparse samples)
                if domain is not None and starts[k] is not None and jumps[starts[k]]:
                    part[0] = other_side(part[0], part[1], domain)
                if domain is not None and stops[k] is not None and jumps[stops[k]]:
                    part[-1] = other_side(part[-1], part[-2], domain)
                piece_uv.append(part)
            fresh = np.arange(count, count + local.size)
            count += local.size
            points.append(topology.points[ids[local]])
            if uv_a is not None:
                uv_a.append(piece_uv[0])
            if uv_b is not None:
                uv_b.append(piece_uv[1])
            first = k == 0 and not chain.closed
            last = k == len(pieces) - 1 and not chain.closed
            chains.append(Chain(fresh, np.zeros(local.size - 1, dtype=np.int64), False,
                                chain.start_kind if first else EndKind.BOUNDARY,
                                chain.end_kind if last else EndKind.BOUNDARY))
    return replace(topology, points=np.concatenate(points),
                   uv_a=None if uv_a is None else np.concatenate(uv_a),
                   uv_b=None if uv_b is None else np.concatenate(uv_b),
                   chains=tuple(chains))


def closed_directions(surface: NurbsSurface, tol: float) -> tuple[bool, bool]:
    """Whether the surface closes in ``u`` (``S(u_min, v) = S(u_max, v)`` within ``tol`` on
    17 values of ``v``) and in ``v``: a seam a foot point may cross."""
    u0, u1, v0, v1 = surface.domain
    s = np.linspace(0.0, 1.0, 17)
    u, v = u0 + (u1 - u0) * s, v0 + (v1 - v0) * s
    in_u = np.linalg.norm(surface.evaluate(np.full(17, u0), v) - surface.evaluate(np.full(17, u1), v), axis=1)
    in_v = np.linalg.norm(surface.evaluate(u, np.full(17, v0)) - surface.evaluate(u, np.full(17, v1)), axis=1)
    return bool(np.all(in_u <= tol)), bool(np.all(in_v <= tol))


def seam_restarts(surface: NurbsSurface, uv: NDArray, closed: tuple[bool, bool],
                  candidates: NDArray | None = None) -> list[tuple[NDArray, NDArray]]:
    """Where a Newton search held on a side of a closed direction should start again:
    per closed direction, the rows of ``uv (n, 2)`` (among ``candidates``, a mask) lying
    on one of its two sides and their parameters moved to the other side (the seam's
    other parameter line, the same points in space). ``closed``: as
    :func:`closed_directions` gives it."""
    lo, hi = np.array(surface.domain[0::2]), np.array(surface.domain[1::2])
    eps = 1e-9 * (hi - lo)
    out = []
    for axis in (0, 1):
        if not closed[axis]:
            continue
        at_lo, at_hi = uv[:, axis] <= lo[axis] + eps[axis], uv[:, axis] >= hi[axis] - eps[axis]
        held = at_lo | at_hi if candidates is None else candidates & (at_lo | at_hi)
        rows = np.flatnonzero(held)
        if rows.size:
            start = uv[rows].copy()
            start[:, axis] = np.where(at_lo[rows], hi[axis], lo[axis])
            out.append((rows, start))
    return out
