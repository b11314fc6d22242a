"""Compiled kernels of the characteristic stage: power-basis surface derivatives to
second order and the orthogonal projection's Newton iteration (002 eqs. 3-4, 22).

The tracers of this package evaluate ``phi`` hundreds of times at a few dozen
points each. In numpy a jet costs about a millisecond of per-operation overhead
whatever the batch size (a Newton projection of four iterations is some hundred
small array operations). These numba kernels run the same formulas point by
point (the same power-basis patches as :class:`.evaluator.PatchEvaluator`, the
same Newton steps, stops and §6.2 cases as
:meth:`.projection.Projector.project_with_derivatives`), for a fixed call cost
of microseconds. ``AVAILABLE`` is False without numba; the callers keep their
numpy forms then. Compiled on first use and cached on disk (``cache=True``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..jit import AVAILABLE, jit

__all__ = ["AVAILABLE", "distance_points", "jet_rows", "patch_derivatives", "project_points"]


@jit
def _span(breaks, x):
    """Index of the patch holding ``x``: interior breakpoints ``<= x`` (ends extend)."""
    k = 0                                        # breaks: start of every patch, rising
    for i in range(1, breaks.shape[0]):
        if breaks[i] <= x:
            k = i
        else:
            break
    return k


@jit
def _powers(x, scale, degree, out):
    """``out (3, degree + 1)``: ``d^o/du^o x^k`` for ``o <= 2``, ``x = (u - a) scale``."""
    for k in range(degree + 1):
        out[0, k] = x ** k
        out[1, k] = k * x ** (k - 1) * scale if k >= 1 else 0.0
        out[2, k] = k * (k - 1) * x ** (k - 2) * scale * scale if k >= 2 else 0.0


@jit
def _point_derivatives(coef, iu, iv, du, dv, rational, u, v, hom, out, full=True):
    """Derivatives to order 2 in each direction at one point: ``out (3, 3, 3)``.

    ``full`` False: only the entries of total order <= 2 (what the projection and
    the distance jet read); the mixed third and fourth ones are set to zero.
    """
    su = _span(iu[:, 0], u)
    sv = _span(iv[:, 0], v)
    scale_u = 1.0 / (iu[su, 1] - iu[su, 0])
    scale_v = 1.0 / (iv[sv, 1] - iv[sv, 0])
    p, q = coef.shape[2] - 1, coef.shape[3] - 1
    _powers((u - iu[su, 0]) * scale_u, scale_u, p, du)
    _powers((v - iv[sv, 0]) * scale_v, scale_v, q, dv)
    dim = coef.shape[4]
    hom[:] = 0.0                             # the v-sums first: sum_j dv[m, j] coef[i, j]
    for i in range(p + 1):                   # (no scratch array: this runs per Newton step)
        for m in range(3):
            for c in range(dim):
                t = 0.0
                for j in range(q + 1):
                    t += dv[m, j] * coef[su, sv, i, j, c]
                for k in range(3):
                    if full or k + m <= 2:
                        hom[k, m, c] += du[k, i] * t
    for k in range(3):
        for m in range(3):
            if not full and k + m > 2:
                for c in range(3):
                    out[k, m, c] = 0.0
                continue
            if not rational:
                for c in range(3):
                    out[k, m, c] = hom[k, m, c]
                continue
            # quotient rule (eq. 4.20 of Piegl & Tiller), as evaluator._rational_to_second_order
            inv = 1.0 / hom[0, 0, 3]
            for c in range(3):
                acc = hom[k, m, c]
                for i in range(k + 1):
                    ci = 1.0 if i == 0 or i == k else 2.0
                    for j in range(m + 1):
                        if i == 0 and j == 0:
                            continue
                        cj = 1.0 if j == 0 or j == m else 2.0
                        acc -= ci * cj * hom[i, j, 3] * out[k - i, m - j, c]
                out[k, m, c] = acc * inv


@jit
def patch_derivatives(coef, iu, iv, rational, u, v):
    """``(n, 3, 3, 3)`` derivatives to order 2 in each direction at ``u, v (n,)``."""
    n = u.shape[0]
    res = np.empty((n, 3, 3, 3))
    du = np.empty((3, coef.shape[2]))
    dv = np.empty((3, coef.shape[3]))
    hom = np.empty((3, 3, coef.shape[4]))
    for i in range(n):
        _point_derivatives(coef, iu, iv, du, dv, rational, u[i], v[i], hom, res[i])
    return res


@jit
def _project_one(coef, iu, iv, rational, x0, x1, x2, s0, t0, lo, hi, quarter, tol, max_iter,
                 du, dv, hom, d, qd):
    """Newton on eqs. (3)-(4) for one point; ``qd (3, 3, 3)`` filled at the foot.
    Returns ``(s, t, moved, before)``: the foot and its last two moves."""
    s0 = min(max(s0, lo[0]), hi[0])
    t0 = min(max(t0, lo[1]), hi[1])
    moved, before = np.inf, np.inf
    for _ in range(max_iter):
        _point_derivatives(coef, iu, iv, du, dv, rational, s0, t0, hom, d, False)
        off0, off1, off2 = x0 - d[0, 0, 0], x1 - d[0, 0, 1], x2 - d[0, 0, 2]
        f0 = off0 * d[1, 0, 0] + off1 * d[1, 0, 1] + off2 * d[1, 0, 2]
        f1 = off0 * d[0, 1, 0] + off1 * d[0, 1, 1] + off2 * d[0, 1, 2]
        ss = d[1, 0, 0] ** 2 + d[1, 0, 1] ** 2 + d[1, 0, 2] ** 2
        sm = d[1, 0, 0] * d[0, 1, 0] + d[1, 0, 1] * d[0, 1, 1] + d[1, 0, 2] * d[0, 1, 2]
        tt = d[0, 1, 0] ** 2 + d[0, 1, 1] ** 2 + d[0, 1, 2] ** 2
        k00 = ss - (off0 * d[2, 0, 0] + off1 * d[2, 0, 1] + off2 * d[2, 0, 2])   # eq. (22)
        k01 = sm - (off0 * d[1, 1, 0] + off1 * d[1, 1, 1] + off2 * d[1, 1, 2])
        k11 = tt - (off0 * d[0, 2, 0] + off1 * d[0, 2, 1] + off2 * d[0, 2, 2])
        if not (k00 * k11 - k01 * k01 > 0 and k00 > 0):
            k00, k01, k11 = ss, sm, tt                # Gauss-Newton off the minimum
        det = k00 * k11 - k01 * k01
        if abs(det) <= 1e-300:
            det = 1e-300
        step0 = (k11 * f0 - k01 * f1) / det
        step1 = (k00 * f1 - k01 * f0) / det
        # a coordinate held at a side of the clip box while the step pushes it out:
        # Newton in the other one alone (the coupled step, clipped, converges slowly)
        hold_s = (s0 >= hi[0] and step0 > 0) or (s0 <= lo[0] and step0 < 0)
        hold_t = (t0 >= hi[1] and step1 > 0) or (t0 <= lo[1] and step1 < 0)
        if hold_s:
            step0, step1 = 0.0, (0.0 if hold_t else f1 / max(k11, 1e-300))
        elif hold_t:
            step0, step1 = f0 / max(k00, 1e-300), 0.0
        scale = max(abs(step0) / quarter[0], abs(step1) / quarter[1], 1.0)
        n0 = min(max(s0 + step0 / scale, lo[0]), hi[0])
        n1 = min(max(t0 + step1 / scale, lo[1]), hi[1])
        e0, e1 = n0 - s0, n1 - t0
        before = moved
        moved = np.sqrt((d[1, 0, 0] * e0 + d[0, 1, 0] * e1) ** 2
                        + (d[1, 0, 1] * e0 + d[0, 1, 1] * e1) ** 2
                        + (d[1, 0, 2] * e0 + d[0, 1, 2] * e1) ** 2)
        s0, t0 = n0, n1
        nxt = np.inf
        if moved < before and np.isfinite(before):
            nxt = moved ** 3 / max(before, 1e-300) ** 2
        if moved <= tol or nxt <= tol:
            break
    _point_derivatives(coef, iu, iv, du, dv, rational, s0, t0, hom, qd, False)
    return s0, t0, moved, before


@jit
def project_points(coef, iu, iv, rational, x, st0, lo, hi, quarter, tol, max_iter):
    """Newton on eqs. (3)-(4) for every row of ``x (n, 3)`` from ``st0 (n, 2)``.

    The steps, the step limit (``quarter`` of the domain per step), the clip to
    ``[lo, hi]`` (the domain and its extension) and the stop (the step moves the
    foot by ``tol`` or less, or quadratic convergence predicts so) are those of
    :meth:`.projection.Projector.project_with_derivatives`.

    Returns
    -------
    st : (n, 2) float
    qd : (n, 3, 3, 3) float
        ``q``'s derivatives at the feet.
    moved, before : (n,) float
        The last two foot moves (for the caller's convergence test).
    """
    n = x.shape[0]
    st = np.empty((n, 2))
    qd = np.empty((n, 3, 3, 3))
    moved = np.empty(n)
    before = np.empty(n)
    du = np.empty((3, coef.shape[2]))
    dv = np.empty((3, coef.shape[3]))
    hom = np.empty((3, 3, coef.shape[4]))
    d = np.empty((3, 3, 3))
    for i in range(n):
        st[i, 0], st[i, 1], moved[i], before[i] = _project_one(
            coef, iu, iv, rational, x[i, 0], x[i, 1], x[i, 2], st0[i, 0], st0[i, 1], lo, hi,
            quarter, tol, max_iter, du, dv, hom, d, qd[i])
    return st, qd, moved, before


@jit
def _status(s, t, k00, k01, k11, moved, before, lower, upper, tol):
    """The §6.2 case of one foot, as :meth:`.projection.Projector.status`:
    0 unique, 1 multiple (``K`` not positive definite), 2 none (outside ``q``'s
    domain, or Newton did not converge)."""
    eps0 = 1e-9 * (upper[0] - lower[0])
    eps1 = 1e-9 * (upper[1] - lower[1])
    if s < lower[0] - eps0 or s > upper[0] + eps0 or t < lower[1] - eps1 or t > upper[1] + eps1:
        return 2
    if moved > 10 * tol:
        fast = (moved < before and np.isfinite(before)
                and moved ** 3 / max(before, 1e-300) ** 2 <= tol)
        if not fast:
            return 2
    det = k00 * k11 - k01 * k01
    if det <= 1e-12 * (k00 + k11) ** 2 or k00 <= 0:
        return 1
    return 0


@jit
def _project_affine(frame, x0, x1, x2, lo, hi, lower, qd):
    """The foot on a parallelogram ``q`` in closed form (as
    :meth:`.projection.Projector._project_affine`): ``frame (5, 3)`` from
    :meth:`.projection.Projector.kernel_frame`; ``qd (3, 3, 3)`` filled (second
    derivatives zero). Returns ``(s, t, moved, before)`` as :func:`_project_one`
    (no Newton move: the §6.2 case is decided by the domain alone)."""
    e0, e1, e2 = x0 - frame[0, 0], x1 - frame[0, 1], x2 - frame[0, 2]
    r0 = e0 * frame[1, 0] + e1 * frame[1, 1] + e2 * frame[1, 2]
    r1 = e0 * frame[2, 0] + e1 * frame[2, 1] + e2 * frame[2, 2]
    s = min(max(lower[0] + frame[3, 0] * r0 + frame[3, 1] * r1, lo[0]), hi[0])
    t = min(max(lower[1] + frame[3, 1] * r0 + frame[3, 2] * r1, lo[1]), hi[1])
    qd[:] = 0.0
    for c in range(3):
        qd[0, 0, c] = frame[0, c] + (s - lower[0]) * frame[1, c] + (t - lower[1]) * frame[2, c]
        qd[1, 0, c] = frame[1, c]
        qd[0, 1, c] = frame[2, c]
    return s, t, 0.0, np.inf


@jit
def jet_rows(r_coef, r_iu, r_iv, r_rational, q_coef, q_iu, q_iv, q_rational, uv, st0,
              lo, hi, quarter, tol, max_iter, lower, upper, frame, point, foot, normal, st,
              phi, grad, hess, jac, status, det_k, du, dv, hom, d, rd, qd, big, c1, c2, n_s, n_t):
    """The rows of :func:`distance_points`' outputs at ``uv (n, 2)``, feet seeded at
    ``st0``; the trailing arrays are scratch (see :func:`distance_points`). One call
    for all rows: a numba call passing some forty arrays costs about a microsecond
    (reference counts of every argument), more than the body for a plane ``q``."""
    for i in range(uv.shape[0]):
        u, v, s0, t0 = uv[i, 0], uv[i, 1], st0[i, 0], st0[i, 1]
        _point_derivatives(r_coef, r_iu, r_iv, du[:, :r_coef.shape[2]], dv[:, :r_coef.shape[3]],
                           r_rational, u, v, hom[:, :, :r_coef.shape[4]], rd, False)
        for c in range(3):
            point[i, c] = rd[0, 0, c]
        if frame[4, 0] > 0:
            st[i, 0], st[i, 1], moved, before = _project_affine(
                frame, rd[0, 0, 0], rd[0, 0, 1], rd[0, 0, 2], lo, hi, lower, qd)
        else:
            st[i, 0], st[i, 1], moved, before = _project_one(
                q_coef, q_iu, q_iv, q_rational, rd[0, 0, 0], rd[0, 0, 1], rd[0, 0, 2],
                s0, t0, lo, hi, quarter, tol, max_iter, du[:, :q_coef.shape[2]],
                dv[:, :q_coef.shape[3]], hom[:, :, :q_coef.shape[4]], d, qd)
        # written on indices, without array views: every view of a numba array costs a
        # reference count (atomic) and this body runs for every point of every jet
        for c in range(3):
            a, b = (c + 1) % 3, (c + 2) % 3
            big[c] = qd[1, 0, a] * qd[0, 1, b] - qd[1, 0, b] * qd[0, 1, a]      # q_s x q_t
            # d(q_s x q_t)/ds = q_ss x q_t + q_s x q_st, d/dt = q_st x q_t + q_s x q_tt
            c1[c] = (qd[2, 0, a] * qd[0, 1, b] - qd[2, 0, b] * qd[0, 1, a]
                     + qd[1, 0, a] * qd[1, 1, b] - qd[1, 0, b] * qd[1, 1, a])
            c2[c] = (qd[1, 1, a] * qd[0, 1, b] - qd[1, 1, b] * qd[0, 1, a]
                     + qd[1, 0, a] * qd[0, 2, b] - qd[1, 0, b] * qd[0, 2, a])
        length = max(np.sqrt(big[0] ** 2 + big[1] ** 2 + big[2] ** 2), 1e-300)
        dot_s = dot_t = 0.0
        for c in range(3):
            normal[i, c] = big[c] / length
            foot[i, c] = qd[0, 0, c]
            dot_s += normal[i, c] * c1[c]
            dot_t += normal[i, c] * c2[c]
        for c in range(3):                       # the unit normal's derivatives (Weingarten)
            n_s[c] = (c1[c] - normal[i, c] * dot_s) / length
            n_t[c] = (c2[c] - normal[i, c] * dot_t) / length
        p_ = 0.0
        gu = 0.0
        gv = 0.0
        g00 = g01 = g10 = g11 = 0.0
        k00 = k01 = k11 = 0.0
        for c in range(3):
            off = rd[0, 0, c] - qd[0, 0, c]
            nc, ru, rv, qs, qt = normal[i, c], rd[1, 0, c], rd[0, 1, c], qd[1, 0, c], qd[0, 1, c]
            p_ += nc * off
            gu += nc * ru
            gv += nc * rv
            g00 += ru * qs                                                 # eq. (23)
            g01 += rv * qs
            g10 += ru * qt
            g11 += rv * qt
            k00 += qs * qs - off * qd[2, 0, c]                             # eq. (22)
            k01 += qs * qt - off * qd[1, 1, c]
            k11 += qt * qt - off * qd[0, 2, c]
        phi[i] = p_
        grad[i, 0], grad[i, 1] = gu, gv                                    # (24)-(25)
        status[i] = _status(st[i, 0], st[i, 1], k00, k01, k11, moved, before, lower, upper,
                            tol)
        det = k00 * k11 - k01 * k01
        det_k[i] = det
        j00 = j01 = j10 = j11 = 0.0
        if abs(det) > 1e-300:                                              # eq. (21)
            j00 = (k11 * g00 - k01 * g10) / det
            j01 = (k11 * g01 - k01 * g11) / det
            j10 = (k00 * g10 - k01 * g00) / det
            j11 = (k00 * g11 - k01 * g01) / det
        jac[i, 0, 0], jac[i, 0, 1], jac[i, 1, 0], jac[i, 1, 1] = j00, j01, j10, j11
        huu = huv = hvu = hvv = 0.0
        for c in range(3):
            nu_c = n_s[c] * j00 + n_t[c] * j10                             # (30)
            nv_c = n_s[c] * j01 + n_t[c] * j11                             # (31)
            nc, ru, rv = normal[i, c], rd[1, 0, c], rd[0, 1, c]
            huu += nu_c * ru + nc * rd[2, 0, c]                            # (26)
            huv += nv_c * ru + nc * rd[1, 1, c]                            # (27)
            hvu += nu_c * rv + nc * rd[1, 1, c]                            # (28)
            hvv += nv_c * rv + nc * rd[0, 2, c]                            # (29)
        mixed = 0.5 * (huv + hvu)
        hess[i, 0, 0], hess[i, 0, 1], hess[i, 1, 0], hess[i, 1, 1] = huu, mixed, mixed, hvv


@jit
def distance_points(r_coef, r_iu, r_iv, r_rational, q_coef, q_iu, q_iv, q_rational, uv, st0,
                    lo, hi, quarter, tol, max_iter, lower, upper, frame):
    """``phi``, its gradient and Hessian (002 eqs. 2, 24-31) at ``uv (n, 2)`` of ``r``.

    Per point: ``r``'s derivatives, the foot on ``q`` (:func:`_project_one`), the
    unit normal ``n_q`` and its derivatives (Weingarten), ``K`` (eq. 22), the map
    ``K^{-1} G`` (eqs. 21, 23) and the derivatives of eqs. (24)-(31), as
    :func:`.distance.distance_jet` computes them with numpy.

    Returns
    -------
    point, foot, normal : (n, 3) float
    st : (n, 2) float
    phi : (n,) float
    grad : (n, 2) float
    hess, jac : (n, 2, 2) float
        Hessian of phi, ``K^{-1} G``.
    status : (n,) int8
        §6.2 case of each foot (:func:`_status`; ``lower``, ``upper``: ``q``'s domain).
    det_k : (n,) float

    ``frame (5, 3)``: :meth:`.projection.Projector.kernel_frame` (a parallelogram
    ``q`` is projected in closed form, ``st0`` unread).
    """
    n = uv.shape[0]
    point = np.empty((n, 3))
    foot = np.empty((n, 3))
    normal = np.empty((n, 3))
    st = np.empty((n, 2))
    phi = np.empty(n)
    grad = np.empty((n, 2))
    hess = np.empty((n, 2, 2))
    jac = np.empty((n, 2, 2))
    status = np.empty(n, dtype=np.int8)
    det_k = np.empty(n)
    du = np.empty((3, max(r_coef.shape[2], q_coef.shape[2])))
    dv = np.empty((3, max(r_coef.shape[3], q_coef.shape[3])))
    hom = np.empty((3, 3, 4))
    d = np.empty((3, 3, 3))
    rd = np.empty((3, 3, 3))
    qd = np.empty((3, 3, 3))
    big = np.empty(3)
    c1 = np.empty(3)
    c2 = np.empty(3)
    n_s = np.empty(3)
    n_t = np.empty(3)
    jet_rows(r_coef, r_iu, r_iv, r_rational, q_coef, q_iu, q_iv, q_rational, uv, st0, lo, hi,
              quarter, tol, max_iter, lower, upper, frame, point, foot, normal, st, phi, grad,
              hess, jac, status, det_k, du, dv, hom, d, rd, qd, big, c1, c2, n_s, n_t)
    return point, foot, normal, st, phi, grad, hess, jac, status, det_k


def evaluator_arrays(coef: NDArray, iu: NDArray, iv: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Contiguous float arrays for the kernels from a :class:`.evaluator.PatchEvaluator`'s data."""
    return (np.ascontiguousarray(coef, dtype=float), np.ascontiguousarray(iu, dtype=float),
            np.ascontiguousarray(iv, dtype=float))
