"""Hanging ends of traced curves continued on the exact surfaces (marching).

An intersection curve of two surfaces ends only on a domain side (or closes,
or meets a singular point). A traced chain that ends OPEN -- away from every
side -- stopped where the tessellations found no more segments: near a pole
(a side collapsed to a point, where the triangles are slivers, as at the nose
of a fuselage) or where the surfaces meet at a small angle. Such an end is
continued here by marching on the exact surfaces (000 §29.4.6's refinement
used as the corrector):

* predictor: a step ``h`` along the curve's tangent ``n_a x n_b`` (oriented
  away from the curve), mapped to both parameter domains by the least-squares
  inverse of each surface's Jacobian;
* corrector: :func:`.refine.refine_points` (auxiliary plane through the
  predicted point, eqs. 29.18-29.26) to ``tol / 16``;
* a step is accepted when the corrector converged, moved forward, and the
  tangent turned by less than ``_MAX_TURN``; otherwise ``h`` is halved.

A march stops on a domain side (the prediction leaves the domain: the last
point is solved with that side parameter held and the end becomes BOUNDARY),
when it comes back near the curve's own other end or another curve's end
(within the step), after ``_MAX_STEPS`` steps, or when ``h`` falls below
``tol``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from .boundary_ends import side_constraint, solve_on_side
from .refine import RefinedCurve, refine_points

__all__ = ["extend_open_ends"]

_MAX_STEPS = 400
#: largest tangent turn of one accepted step (radians)
_MAX_TURN = 0.1
_GROW = 1.5


def _tangent(surface_a: NurbsSurface, surface_b: NurbsSurface, ua: NDArray, ub: NDArray
             ) -> tuple[NDArray, NDArray, NDArray]:
    """Unit tangent ``n_a x n_b`` and the first derivatives ``(3, 2)`` of both surfaces."""
    da = surface_a.derivatives(ua[:1, 0], ua[:1, 1], 1)[0]
    db = surface_b.derivatives(ub[:1, 0], ub[:1, 1], 1)[0]
    ja = np.stack([da[1, 0], da[0, 1]], axis=1)
    jb = np.stack([db[1, 0], db[0, 1]], axis=1)
    t = np.cross(np.cross(ja[:, 0], ja[:, 1]), np.cross(jb[:, 0], jb[:, 1]))
    norm = np.linalg.norm(t)
    return (t / norm if norm > 0 else t), ja, jb


def _domain_box(surface: NurbsSurface) -> tuple[NDArray, NDArray]:
    d = surface.domain
    return np.array([d[0], d[2]]), np.array([d[1], d[3]])


def _leaves(uv: NDArray, lo: NDArray, hi: NDArray) -> bool:
    return bool(np.any(uv < lo) or np.any(uv > hi))


def _onto_side(surface_a: NurbsSurface, surface_b: NurbsSurface, ua: NDArray, ub: NDArray,
               side: int, tol: float) -> tuple | None:
    """``(p, uv_a, uv_b)`` solved with the side parameter of surface ``side`` held
    (``ua`` / ``ub`` already clipped onto the domain), or None."""
    held = side_constraint(ua if side == 0 else ub,
                           (surface_a if side == 0 else surface_b).domain)
    if held is None:
        return None
    ra, rb, ok = solve_on_side(surface_a, surface_b, ua[None], ub[None], np.array([side]),
                               np.array([held[0]]), np.array([held[1]]), tol / 16)
    if not ok[0]:
        return None
    q = 0.5 * (surface_a.evaluate(ra[:, 0], ra[:, 1])[0]
               + surface_b.evaluate(rb[:, 0], rb[:, 1])[0])
    return q, ra[0], rb[0]


def _march(surface_a: NurbsSurface, surface_b: NurbsSurface, start: tuple, back: NDArray,
           h0: float, tol: float, stops: NDArray) -> tuple[list, bool]:
    """Points ``[(p, uv_a, uv_b)]`` marched from ``start`` away from ``back``; and
    whether the march ended on a domain side (the last point then lies on it)."""
    p, ua, ub = (np.asarray(x, dtype=float) for x in start)
    lo_a, hi_a = _domain_box(surface_a)
    lo_b, hi_b = _domain_box(surface_b)
    direction = p - back
    h, out = h0, []
    t_prev = None
    for _ in range(_MAX_STEPS):
        if h < tol:
            break
        t, ja, jb = _tangent(surface_a, surface_b, ua[None], ub[None])
        if not np.any(t):
            break
        if np.dot(t, direction) < 0:
            t = -t
        if t_prev is not None and np.arccos(np.clip(np.dot(t, t_prev), -1, 1)) > _MAX_TURN:
            h *= 0.5
        step = h * t
        pa = ua + np.linalg.lstsq(ja, step, rcond=None)[0]
        pb = ub + np.linalg.lstsq(jb, step, rcond=None)[0]
        left = [_leaves(pa, lo_a, hi_a), _leaves(pb, lo_b, hi_b)]
        if any(left):
            end = _onto_side(surface_a, surface_b, np.clip(pa, lo_a, hi_a),
                             np.clip(pb, lo_b, hi_b), 0 if left[0] else 1, tol)
            if end is not None and np.dot(end[0] - p, t) > 0 \
                    and np.linalg.norm(end[0] - p) <= 2 * h:
                out.append(end)
                return out, True
            h *= 0.5
            continue
        r = refine_points(surface_a, surface_b, pa[None], pb[None], tol=tol / 16,
                          anchors=(p + step)[None])
        q = r.points[0]
        moved = q - p
        if not r.converged[0] or np.dot(moved, t) <= 0.25 * h or np.linalg.norm(moved) > 2 * h:
            h *= 0.5
            continue
        if stops.size and np.min(np.linalg.norm(stops - q, axis=1)) <= h:
            out.append((q, r.uv_a[0], r.uv_b[0]))
            break
        out.append((q, r.uv_a[0], r.uv_b[0]))
        direction, t_prev = moved, t
        p, ua, ub = q, r.uv_a[0], r.uv_b[0]
        h = min(h * _GROW, 4 * h0)
    return out, False


def extend_open_ends(curves: list[RefinedCurve], open_ends: list[tuple[bool, bool]],
                     surface_a: NurbsSurface, surface_b: NurbsSurface, *, tol: float,
                     step: float) -> tuple[list[RefinedCurve], list[tuple[bool, bool]]]:
    """Continue every OPEN end of the dense refined curves on the exact surfaces.

    Parameters
    ----------
    curves : list of RefinedCurve
    open_ends : list of (bool, bool)
        Per curve, whether its start / end is OPEN (a hanging end).
    tol : float
        Model units; marched points lie within ``tol / 16`` of both surfaces.
    step : float
        First step length (model units), e.g. a fraction of the mesh tolerance.

    Returns
    -------
    (curves, reached)
        The curves with marched points added at their open ends, and per curve
        whether each such end reached a domain side (it is then a BOUNDARY end).
    """
    ends = [c.points[[0, -1]] for c in curves if not c.closed]
    all_ends = np.concatenate(ends) if ends else np.zeros((0, 3))
    out, reached = [], []
    for c, (open_start, open_end) in zip(curves, open_ends):
        flags = [False, False]
        if c.closed or c.points.shape[0] < 2 or not (open_start or open_end):
            out.append(c)
            reached.append((False, False))
            continue
        for k, is_open in ((0, open_start), (1, open_end)):
            if not is_open:
                continue
            e, nb = (0, 1) if k == 0 else (-1, -2)
            here = c.points[e]
            stops = all_ends[np.linalg.norm(all_ends - here, axis=1) > step]
            marched, on_side = _march(surface_a, surface_b, (here, c.uv_a[e], c.uv_b[e]),
                                      c.points[nb], step, tol, stops)
            if not marched:
                continue
            flags[k] = on_side
            p = np.array([m[0] for m in marched])
            ua = np.array([m[1] for m in marched])
            ub = np.array([m[2] for m in marched])
            n = p.shape[0]
            if k == 0:
                p, ua, ub = p[::-1], ua[::-1], ub[::-1]
                c = RefinedCurve(np.concatenate([p, c.points]), np.concatenate([ua, c.uv_a]),
                                 np.concatenate([ub, c.uv_b]), False,
                                 np.concatenate([np.ones(n, bool), c.converged]),
                                 np.concatenate([np.zeros(n, bool), c.singular]))
            else:
                c = RefinedCurve(np.concatenate([c.points, p]), np.concatenate([c.uv_a, ua]),
                                 np.concatenate([c.uv_b, ub]), False,
                                 np.concatenate([c.converged, np.ones(n, bool)]),
                                 np.concatenate([c.singular, np.zeros(n, bool)]))
        out.append(c)
        reached.append(tuple(flags))
    return out, reached
