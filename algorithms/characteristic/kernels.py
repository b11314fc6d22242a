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

from ..basis_kernels import AVAILABLE, _jit

__all__ = ["AVAILABLE", "patch_derivatives", "project_points"]


@_jit
def _span(breaks, x):
    """Index of the patch holding ``x``: interior breakpoints ``<= x`` (ends extend)."""
    k = 0                                        # breaks: start of every patch, rising
    for i in range(1, breaks.shape[0]):
        if breaks[i] <= x:
            k = i
        else:
            break
    return k


@_jit
def _powers(x, scale, degree, out):
    """``out (3, degree + 1)``: ``d^o/du^o x^k`` for ``o <= 2``, ``x = (u - a) scale``."""
    for k in range(degree + 1):
        out[0, k] = x ** k
        out[1, k] = k * x ** (k - 1) * scale if k >= 1 else 0.0
        out[2, k] = k * (k - 1) * x ** (k - 2) * scale * scale if k >= 2 else 0.0


@_jit
def _point_derivatives(coef, iu, iv, du, dv, rational, u, v, hom, out):
    """Derivatives to order 2 in each direction at one point: ``out (3, 3, 3)``."""
    su = _span(iu[:, 0], u)
    sv = _span(iv[:, 0], v)
    scale_u = 1.0 / (iu[su, 1] - iu[su, 0])
    scale_v = 1.0 / (iv[sv, 1] - iv[sv, 0])
    p, q = coef.shape[2] - 1, coef.shape[3] - 1
    _powers((u - iu[su, 0]) * scale_u, scale_u, p, du)
    _powers((v - iv[sv, 0]) * scale_v, scale_v, q, dv)
    dim = coef.shape[4]
    for k in range(3):
        for m in range(3):
            for c in range(dim):
                s = 0.0
                for i in range(p + 1):
                    t = 0.0
                    for j in range(q + 1):
                        t += dv[m, j] * coef[su, sv, i, j, c]
                    s += du[k, i] * t
                hom[k, m, c] = s
    if not rational:
        for k in range(3):
            for m in range(3):
                for c in range(3):
                    out[k, m, c] = hom[k, m, c]
        return
    # quotient rule (eq. 4.20 of Piegl & Tiller), as evaluator._rational_to_second_order
    inv = 1.0 / hom[0, 0, 3]
    for k in range(3):
        for m in range(3):
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


@_jit
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


@_jit
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
    st = st0.copy()
    qd = np.empty((n, 3, 3, 3))
    moved = np.full(n, np.inf)
    before = np.full(n, np.inf)
    du = np.empty((3, coef.shape[2]))
    dv = np.empty((3, coef.shape[3]))
    hom = np.empty((3, 3, coef.shape[4]))
    d = np.empty((3, 3, 3))
    for i in range(n):
        s0 = min(max(st[i, 0], lo[0]), hi[0])
        t0 = min(max(st[i, 1], lo[1]), hi[1])
        for _ in range(max_iter):
            _point_derivatives(coef, iu, iv, du, dv, rational, s0, t0, hom, d)
            off0 = x[i, 0] - d[0, 0, 0]
            off1 = x[i, 1] - d[0, 0, 1]
            off2 = x[i, 2] - d[0, 0, 2]
            f0 = off0 * d[1, 0, 0] + off1 * d[1, 0, 1] + off2 * d[1, 0, 2]
            f1 = off0 * d[0, 1, 0] + off1 * d[0, 1, 1] + off2 * d[0, 1, 2]
            ss = d[1, 0, 0] ** 2 + d[1, 0, 1] ** 2 + d[1, 0, 2] ** 2
            sm = d[1, 0, 0] * d[0, 1, 0] + d[1, 0, 1] * d[0, 1, 1] + d[1, 0, 2] * d[0, 1, 2]
            tt = d[0, 1, 0] ** 2 + d[0, 1, 1] ** 2 + d[0, 1, 2] ** 2
            k00 = ss - (off0 * d[2, 0, 0] + off1 * d[2, 0, 1] + off2 * d[2, 0, 2])
            k01 = sm - (off0 * d[1, 1, 0] + off1 * d[1, 1, 1] + off2 * d[1, 1, 2])
            k11 = tt - (off0 * d[0, 2, 0] + off1 * d[0, 2, 1] + off2 * d[0, 2, 2])
            if not (k00 * k11 - k01 * k01 > 0 and k00 > 0):
                k00, k01, k11 = ss, sm, tt            # Gauss-Newton off the minimum
            det = k00 * k11 - k01 * k01
            if abs(det) <= 1e-300:
                det = 1e-300
            step0 = (k11 * f0 - k01 * f1) / det
            step1 = (k00 * f1 - k01 * f0) / det
            scale = max(abs(step0) / quarter[0], abs(step1) / quarter[1], 1.0)
            step0 /= scale
            step1 /= scale
            n0 = min(max(s0 + step0, lo[0]), hi[0])
            n1 = min(max(t0 + step1, lo[1]), hi[1])
            e0, e1 = n0 - s0, n1 - t0
            before[i] = moved[i]
            m = np.sqrt((d[1, 0, 0] * e0 + d[0, 1, 0] * e1) ** 2
                        + (d[1, 0, 1] * e0 + d[0, 1, 1] * e1) ** 2
                        + (d[1, 0, 2] * e0 + d[0, 1, 2] * e1) ** 2)
            moved[i] = m
            s0, t0 = n0, n1
            b = before[i]
            nxt = m ** 3 / max(b, 1e-300) ** 2 if (m < b and np.isfinite(b)) else np.inf
            if m <= tol or nxt <= tol:
                break
        st[i, 0], st[i, 1] = s0, t0
        _point_derivatives(coef, iu, iv, du, dv, rational, s0, t0, hom, qd[i])
    return st, qd, moved, before


def evaluator_arrays(coef: NDArray, iu: NDArray, iv: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Contiguous float arrays for the kernels from a :class:`.evaluator.PatchEvaluator`'s data."""
    return (np.ascontiguousarray(coef, dtype=float), np.ascontiguousarray(iu, dtype=float),
            np.ascontiguousarray(iv, dtype=float))
