"""The auxiliary-plane iteration of :func:`.refine.refine_points` (000 eqs. 29.18-29.26),
compiled (numba).

Each point iterates on its own (eqs. 29.18-29.26, the same steps and order as the
numpy loop in :mod:`.refine`), so the iteration is a true per-point loop: the
numpy form pays two surface evaluations and some forty array operations per
iteration for all still active points, most of it fixed overhead when only a few
hundred points are refined (the sampling rounds refine tens of points at a time).

A point whose frame degenerates (``|S_u x S_v|`` vanishing at a pole, where the
numpy form takes the limit normal and a pseudo-inverse step) is flagged and left
to the numpy form, which then refines it from its start again.

``AVAILABLE`` is False without numba (the numpy loop is used then).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..basis import span_range
from ..basis_kernels import ders_one
from ..jit import AVAILABLE, jit
from ..surface import NurbsSurface

__all__ = ["AVAILABLE", "refine_compiled"]


@jit
def _span(knots, t, first, last):
    s = np.searchsorted(knots, t, side="right") - 1
    return min(max(s, first), last)


@jit
def _frame(ku, kv, p, q, net, rational, spans, u, v, du, dv, ndu_u, ndu_v, a_u, a_v,
           lu, ru, lv, rv, h, out):
    """Point, S_u, S_v (rows of ``out (3, 3)``) at ``(u, v)``; ``h (3, 4)`` scratch."""
    su_i = _span(ku, u, spans[0], spans[1])
    sv_i = _span(kv, v, spans[2], spans[3])
    du[:, :] = 0.0
    dv[:, :] = 0.0
    ders_one(ku, p, u, su_i, 1, ndu_u, a_u, lu, ru, du)
    ders_one(kv, q, v, sv_i, 1, ndu_v, a_v, lv, rv, dv)
    iu0, iv0 = su_i - p, sv_i - q
    # h rows: value, d/du, d/dv of the homogeneous point (x, y, z, w)
    for c in range(4):
        s00 = 0.0
        s10 = 0.0
        s01 = 0.0
        for jj in range(q + 1):
            t0 = 0.0
            t1 = 0.0
            for ii in range(p + 1):
                x = net[iu0 + ii, iv0 + jj, c]
                t0 += du[0, ii] * x
                t1 += du[1, ii] * x
            s00 += dv[0, jj] * t0
            s10 += dv[0, jj] * t1
            s01 += dv[1, jj] * t0
        h[0, c] = s00
        h[1, c] = s10
        h[2, c] = s01
    for c in range(3):
        if rational:
            w = h[0, 3]
            pt = h[0, c] / w
            out[0, c] = pt
            out[1, c] = (h[1, c] - h[1, 3] * pt) / w
            out[2, c] = (h[2, c] - h[2, 3] * pt) / w
        else:
            out[0, c] = h[0, c]
            out[1, c] = h[1, c]
            out[2, c] = h[2, c]


@jit
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@jit
def _norm(a):
    return np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@jit
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit
def _normal(fr, n, degenerate):
    """Unit normal of frame ``fr`` into ``n``; False at a degenerate frame (a pole)."""
    _cross(fr[1], fr[2], n)
    size = _norm(n)
    if size <= degenerate * _norm(fr[1]) * _norm(fr[2]):
        return False
    if size > 0:
        for c in range(3):
            n[c] /= size
    return True


@jit
def _increment(fr, n, delta, degenerate, tmp_u, tmp_v, step):
    """Eqs. 29.22-29.25 into ``step (2,)``; False where the 2x2 system is singular."""
    _cross(fr[1], n, tmp_u)                 # su_p
    _cross(fr[2], n, tmp_v)                 # sv_p
    den_u, den_v = _dot(tmp_v, fr[1]), _dot(tmp_u, fr[2])
    scale = _norm(fr[1]) * _norm(fr[2])
    if not (abs(den_u) > degenerate * scale):
        return False
    step[0] = _dot(tmp_v, delta) / den_u
    step[1] = _dot(tmp_u, delta) / den_v
    return True


@jit
def _refine_all(ka_u, ka_v, pa, qa, net_a, rat_a, spans_a, dom_a,
                kb_u, kb_v, pb, qb, net_b, rat_b, spans_b, dom_b,
                ua, ub, anchor, has_anchor, tol, max_iter, tangent_sin, degenerate,
                img_a, img_b, nrm_a, nrm_b, iterations, singular, fallback):
    n = ua.shape[0]
    du_a, dv_a = np.zeros((2, pa + 1)), np.zeros((2, qa + 1))
    du_b, dv_b = np.zeros((2, pb + 1)), np.zeros((2, qb + 1))
    ndu_ua, ndu_va = np.empty((pa + 1, pa + 1)), np.empty((qa + 1, qa + 1))
    ndu_ub, ndu_vb = np.empty((pb + 1, pb + 1)), np.empty((qb + 1, qb + 1))
    a_ua, a_va = np.zeros((2, pa + 1)), np.zeros((2, qa + 1))
    a_ub, a_vb = np.zeros((2, pb + 1)), np.zeros((2, qb + 1))
    lua, rua, lva, rva = np.empty(pa + 1), np.empty(pa + 1), np.empty(qa + 1), np.empty(qa + 1)
    lub, rub, lvb, rvb = np.empty(pb + 1), np.empty(pb + 1), np.empty(qb + 1), np.empty(qb + 1)
    fa, fb, h = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 4))
    n_p, n_q, cr, x, anc = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    t1, t2, t3, d = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    step_a, step_b = np.empty(2), np.empty(2)
    for i in range(n):
        held_a = False
        held_b = False
        while True:
            _frame(ka_u, ka_v, pa, qa, net_a, rat_a, spans_a, ua[i, 0], ua[i, 1], du_a, dv_a,
                   ndu_ua, ndu_va, a_ua, a_va, lua, rua, lva, rva, h, fa)
            _frame(kb_u, kb_v, pb, qb, net_b, rat_b, spans_b, ub[i, 0], ub[i, 1], du_b, dv_b,
                   ndu_ub, ndu_vb, a_ub, a_vb, lub, rub, lvb, rvb, h, fb)
            if not (_normal(fa, n_p, degenerate) and _normal(fb, n_q, degenerate)):
                fallback[i] = True
                break
            for c in range(3):
                img_a[i, c], img_b[i, c] = fa[0, c], fb[0, c]
                nrm_a[i, c], nrm_b[i, c] = n_p[c], n_q[c]
                d[c] = fa[0, c] - fb[0, c]
            if _norm(d) <= tol or iterations[i] >= max_iter:
                break
            for c in range(3):
                x[c] = 0.5 * (fa[0, c] + fb[0, c])
            _cross(n_p, n_q, cr)
            sin = _norm(cr)
            near = sin < tangent_sin
            if not near:                                    # eqs. 29.18-29.21
                for c in range(3):
                    if held_a and held_b:
                        anc[c] = x[c]
                    elif held_a:
                        anc[c] = fa[0, c]
                    elif held_b:
                        anc[c] = fb[0, c]
                    else:
                        anc[c] = anchor[i, c] if has_anchor else x[c]
                d_p, d_q = _dot(n_p, fa[0]), _dot(n_q, fb[0])
                for c in range(3):
                    t3[c] = cr[c] / sin                       # n_n
                d_n = _dot(t3, anc)
                _cross(n_q, t3, t1)
                _cross(t3, n_p, t2)
                for c in range(3):
                    x[c] = (d_p * t1[c] + d_q * t2[c] + d_n * cr[c]) / sin
            for c in range(3):
                d[c] = x[c] - fa[0, c]
            ok = _increment(fa, n_p, d, degenerate, t1, t2, step_a)
            for c in range(3):
                d[c] = x[c] - fb[0, c]
            ok = _increment(fb, n_q, d, degenerate, t1, t2, step_b) and ok
            if not ok:
                fallback[i] = True
                break
            held_a = False
            held_b = False
            for c in range(2):                                 # eq. 29.26, clamped
                lo_a, hi_a = dom_a[2 * c], dom_a[2 * c + 1]
                lo_b, hi_b = dom_b[2 * c], dom_b[2 * c + 1]
                s = ua[i, c] + step_a[c]
                ua[i, c] = min(max(s, lo_a), hi_a)
                held_a = held_a or ua[i, c] != s
                s = ub[i, c] + step_b[c]
                ub[i, c] = min(max(s, lo_b), hi_b)
                held_b = held_b or ub[i, c] != s
            singular[i] = near
            iterations[i] += 1


def _surface_args(surface: NurbsSurface) -> tuple:
    spans = np.array([*span_range(surface.knots_u, surface.degree_u),
                      *span_range(surface.knots_v, surface.degree_v)], dtype=np.int64)
    return (np.ascontiguousarray(surface.knots_u, dtype=float),
            np.ascontiguousarray(surface.knots_v, dtype=float), int(surface.degree_u),
            int(surface.degree_v), np.ascontiguousarray(surface.homogeneous_net),
            surface.weights is not None, spans, np.array(surface.domain, dtype=float))


def refine_compiled(surface_a: NurbsSurface, surface_b: NurbsSurface, ua: NDArray, ub: NDArray,
                    anchor: NDArray | None, tol: float, max_iter: int, tangent_sin: float,
                    degenerate: float) -> tuple[NDArray, ...]:
    """Run the iteration on every point; ``ua``, ``ub (n, 2)`` are updated in place.

    Returns ``img_a, img_b, nrm_a, nrm_b (n, 3)``, ``iterations (n,) int``,
    ``singular (n,) bool`` (midpoint fallback in the last iteration) and
    ``fallback (n,) bool`` (a degenerate frame or step: refine with the numpy form).
    """
    n = ua.shape[0]
    img_a, img_b, nrm_a, nrm_b = (np.zeros((n, 3)) for _ in range(4))
    iterations = np.zeros(n, dtype=np.int64)
    singular = np.zeros(n, dtype=bool)
    fallback = np.zeros(n, dtype=bool)
    has_anchor = anchor is not None
    anc = np.ascontiguousarray(anchor, dtype=float) if has_anchor else np.zeros((n, 3))
    _refine_all(*_surface_args(surface_a), *_surface_args(surface_b), ua, ub, anc, has_anchor,
                float(tol), int(max_iter), float(tangent_sin), float(degenerate),
                img_a, img_b, nrm_a, nrm_b, iterations, singular, fallback)
    return img_a, img_b, nrm_a, nrm_b, iterations, singular, fallback
