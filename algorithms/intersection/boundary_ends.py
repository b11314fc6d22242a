"""Curve ends on a domain side, solved on that side (step 5 of :mod:`.pipeline`, 000 §29.4.6).

An intersection curve that leaves a surface's domain ends on one of its four
sides. The auxiliary-plane refinement (:mod:`.refine`) does not know that: it
lets such an end slide inward by up to the mesh error. Here the end is solved
again with the side's parameter held (:func:`solve_on_side`: Newton on
``S_a(uv_a) = S_b(uv_b)``, three equations in the three free parameters), for
the ends the topology found on a side (:func:`close_boundary_gaps`) and for the
hanging ends :mod:`.extend` marches to a side (:func:`side_constraint` tells
which side a parameter point lies on).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from .refine import RefinedCurve
from .topology import Chain, EndKind

__all__ = ["close_boundary_gaps", "side_constraint", "solve_on_side"]


def side_constraint(uv: NDArray, domain, rel: float = 1e-9) -> tuple[int, float] | None:
    """``(coordinate, value)`` of the domain side ``uv (2,)`` lies on, or None."""
    sides = ((0, domain[0]), (0, domain[1]), (1, domain[2]), (1, domain[3]))
    extent = (domain[1] - domain[0], domain[3] - domain[2])
    for coord, value in sides:
        if abs(uv[coord] - value) <= rel * extent[coord]:
            return coord, value
    return None


def solve_on_side(surface_a: NurbsSurface, surface_b: NurbsSurface, uv_a: NDArray,
                   uv_b: NDArray, side: NDArray, coord: NDArray, value: NDArray, tol: float,
                   iterations: int = 30) -> tuple[NDArray, NDArray, NDArray]:
    """Newton on ``S_a(uv_a) = S_b(uv_b)`` with one parameter held on a domain side.

    Batched over ``k`` ends: ``side (k,)`` 0 holds a coordinate of ``uv_a``, 1 of
    ``uv_b``; ``coord (k,)`` which one; ``value (k,)`` its value. Three equations,
    three free parameters: the other parameter of the held surface and both of
    the other. Returns ``uv_a, uv_b (k, 2)`` and ``converged (k,) bool``
    (``|S_a - S_b| <= tol``).
    """
    ua, ub = uv_a.copy(), uv_b.copy()
    rows = np.arange(ua.shape[0])
    held = np.where(side == 0, 0, 1)
    for target, s in ((ua, 0), (ub, 1)):
        m = held == s
        target[rows[m], coord[m]] = value[m]
    lo_a, hi_a = np.array(surface_a.domain[0::2]), np.array(surface_a.domain[1::2])
    lo_b, hi_b = np.array(surface_b.domain[0::2]), np.array(surface_b.domain[1::2])
    converged = np.zeros(rows.size, dtype=bool)
    for _ in range(iterations):
        da = surface_a.derivatives(ua[:, 0], ua[:, 1], 1)
        db = surface_b.derivatives(ub[:, 0], ub[:, 1], 1)
        gap = da[:, 0, 0] - db[:, 0, 0]                                   # (k, 3)
        converged = np.linalg.norm(gap, axis=1) <= tol
        if converged.all():
            break
        jac_a = np.stack([da[:, 1, 0], da[:, 0, 1]], axis=2)              # (k, 3, 2)
        jac_b = -np.stack([db[:, 1, 0], db[:, 0, 1]], axis=2)
        free_a = np.where((held == 0)[:, None], (1 - coord)[:, None] == np.arange(2), True)
        free_b = np.where((held == 1)[:, None], (1 - coord)[:, None] == np.arange(2), True)
        # three columns: the free ones of a's and b's (4 minus the held one)
        cols = np.concatenate([jac_a, jac_b], axis=2)                     # (k, 3, 4)
        free = np.concatenate([free_a, free_b], axis=1)                   # (k, 4)
        order = np.argsort(~free, axis=1, kind="stable")[:, :3]
        jac = np.take_along_axis(cols, order[:, None, :], axis=2)         # (k, 3, 3)
        ok = np.abs(np.linalg.det(jac)) > 1e-300
        step = np.zeros((rows.size, 3))
        if ok.any():
            step[ok] = np.linalg.solve(jac[ok], -gap[ok][..., None])[..., 0]
        full = np.zeros((rows.size, 4))
        np.put_along_axis(full, order, step, axis=1)
        ua = np.clip(ua + full[:, :2], lo_a, hi_a)
        ub = np.clip(ub + full[:, 2:], lo_b, hi_b)
    return ua, ub, converged


def close_boundary_gaps(curves: list[RefinedCurve], chains: list[Chain], ends_uv: list,
                         surface_a, surface_b, tol: float, reach: float
                         ) -> tuple[list[RefinedCurve], set[tuple[int, int]]]:
    """Put every BOUNDARY end of the densely refined curves back on the domain side its
    traced end was on.

    The auxiliary-plane refinement anchors ``F_n`` at the midpoint of the two
    start images; at an end on a domain side that midpoint is off the side by
    the mesh error, so the refined end slides along the curve, inside the
    domain, by up to about ``mesh_tol``: a gap in coverage. Each such end is
    solved again with its side parameter held (:func:`solve_on_side`) and
    becomes a new end sample (replacing the old one when closer than ``tol / 16``
    or than half the old end's dense spacing).
    ``ends_uv[i]`` holds the traced ``(uv_a, uv_b)`` of curve ``i``'s two ends.
    Runs before :func:`.sampling.cubic_samples`, which then samples the closed
    ends like any other part of the curve.

    Returns the curves and the ``(curve, end)`` (end 0 or -1) left open: the solve
    on the side did not converge, or its point lies farther than ``reach`` (the
    traced end met the side away from where the curve does, as near a corner of
    the domain, cornetta faces 3 x 39: 0.05 mm short); those are marched to the
    side like hanging ends (:mod:`.extend`).
    """
    jobs = []            # (curve, end (0 start / -1 end), side, coord, value)
    for i, (curve, chain, ends) in enumerate(zip(curves, chains, ends_uv)):
        if curve.closed:
            continue
        for end, kind in ((0, chain.start_kind), (-1, chain.end_kind)):
            if kind is not EndKind.BOUNDARY:
                continue
            traced_a, traced_b = ends[0 if end == 0 else 1]
            for side, (traced, surface) in enumerate(((traced_a, surface_a),
                                                       (traced_b, surface_b))):
                held = side_constraint(traced, surface.domain)
                if held is not None:
                    jobs.append((i, end, side, held[0], held[1]))
                    break
    if not jobs:
        return curves, set()
    idx = np.array([j[0] for j in jobs])
    end = np.array([j[1] for j in jobs])
    uv_a = np.stack([curves[i].uv_a[e] for i, e in zip(idx, end)])
    uv_b = np.stack([curves[i].uv_b[e] for i, e in zip(idx, end)])
    ua, ub, ok = solve_on_side(surface_a, surface_b, uv_a, uv_b, np.array([j[2] for j in jobs]),
                                np.array([j[3] for j in jobs]), np.array([j[4] for j in jobs]),
                                tol / 16)
    pa, pb = surface_a.evaluate(ua[:, 0], ua[:, 1]), surface_b.evaluate(ub[:, 0], ub[:, 1])
    new_points = 0.5 * (pa + pb)
    out = list(curves)
    left = {(int(i), int(e)) for i, e in zip(idx[~ok], end[~ok])}
    for k in np.flatnonzero(ok):
        i, e = int(idx[k]), int(end[k])
        c = out[i]
        moved = float(np.linalg.norm(new_points[k] - c.points[e]))
        if moved > reach:
            left.add((i, e))    # not the same end: march it to the side instead
            continue
        fields = [c.points, c.uv_a, c.uv_b, c.converged, c.singular]
        values = [new_points[k], ua[k], ub[k], True, False]
        beside = 1 if e == 0 else -2                # the old end's dense neighbour
        spacing = float(np.linalg.norm(c.points[beside] - c.points[e])) \
            if c.points.shape[0] > 2 else np.inf
        if moved <= tol / 16 or moved < 0.5 * spacing:       # replace: no tiny end span
            fields = [f.copy() for f in fields]
            for f, v in zip(fields, values):
                f[e] = v
        elif e == 0:
            fields = [np.concatenate([np.atleast_1d(np.asarray(v, dtype=f.dtype))[None]
                                      if f.ndim == 2 else [v], f]) for f, v in zip(fields, values)]
        else:
            fields = [np.concatenate([f, np.atleast_1d(np.asarray(v, dtype=f.dtype))[None]
                                      if f.ndim == 2 else [v]]) for f, v in zip(fields, values)]
        out[i] = RefinedCurve(fields[0], fields[1], fields[2], False, fields[3], fields[4])
    return out, left
