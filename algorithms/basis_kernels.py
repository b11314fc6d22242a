"""Compiled kernels of the B-spline basis (A2.3 of [PT]) and of scattered surface points.

The numpy forms in :mod:`.basis` and :meth:`.surface.NurbsSurface.derivatives`
loop over the degree and spend most of a small call (tens to hundreds of
points, as intersection refinement makes thousands of times) in per-operation
overhead. These numba kernels run the same recurrences point by point: the
same sums in the same order (results agree to the last bit or one rounding),
with a fixed call cost of a few microseconds.

``AVAILABLE`` is False when numba cannot be imported; the callers keep their
numpy forms then (:mod:`.jit`). :func:`ders_one` is the kernel other compiled
modules call inside their own loops.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   algorithms A2.3 (basis derivatives), A3.6 (surface derivatives).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .jit import AVAILABLE, jit

__all__ = ["AVAILABLE", "basis_derivatives_compiled", "ders_one", "surface_derivatives_compiled"]


@jit
def ders_one(knots, p, t, span, order, ndu, a, left, right, out):
    """A2.3 of [PT] at one parameter: ``out (order + 1, p + 1)`` (``order <= p``)."""
    ndu[0, 0] = 1.0
    for j in range(1, p + 1):
        left[j] = t - knots[span + 1 - j]
        right[j] = knots[span + j] - t
        saved = 0.0
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]
            den = ndu[j, r]
            temp = ndu[r, j - 1] / den if den != 0.0 else 0.0
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved
    for j in range(p + 1):
        out[0, j] = ndu[j, p]
    for r in range(p + 1):
        s1, s2 = 0, 1
        a[0, 0] = 1.0
        for k in range(1, order + 1):
            d = 0.0
            rk, pk = r - k, p - k
            if r >= k:
                den = ndu[pk + 1, rk]
                a[s2, 0] = a[s1, 0] * (1.0 / den if den != 0.0 else 0.0)
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for jj in range(j1, j2 + 1):
                den = ndu[pk + 1, rk + jj]
                a[s2, jj] = (a[s1, jj] - a[s1, jj - 1]) * (1.0 / den if den != 0.0 else 0.0)
                d += a[s2, jj] * ndu[rk + jj, pk]
            if r <= pk:
                den = ndu[pk + 1, r]
                a[s2, k] = -a[s1, k - 1] * (1.0 / den if den != 0.0 else 0.0)
                d += a[s2, k] * ndu[r, pk]
            out[k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, order + 1):
        for j in range(p + 1):
            out[k, j] *= factor
        factor *= p - k


@jit
def _basis_ders(knots, p, t, span, order):
    m = t.size
    top = min(order, p)
    out = np.zeros((m, order + 1, p + 1))
    ndu = np.empty((p + 1, p + 1))
    a = np.zeros((2, p + 1))
    left = np.empty(p + 1)
    right = np.empty(p + 1)
    for i in range(m):
        ders_one(knots, p, t[i], span[i], top, ndu, a, left, right, out[i])
    return out


def basis_derivatives_compiled(knots: NDArray, p: int, t: NDArray, span: NDArray,
                               order: int) -> NDArray:
    """``ders (m, order + 1, p + 1)`` as :func:`.basis.basis_derivatives` returns them.

    ``knots`` float, ``t (m,)`` float, ``span (m,)`` int (:func:`.basis.find_span`).
    """
    return _basis_ders(np.ascontiguousarray(knots, dtype=np.float64), int(p),
                       np.ascontiguousarray(t, dtype=np.float64),
                       np.ascontiguousarray(span, dtype=np.int64), int(order))


@jit
def _binomials(order):
    comb = np.zeros((order + 1, order + 1))
    for n in range(order + 1):
        comb[n, 0] = 1.0
        for r in range(1, n + 1):
            comb[n, r] = comb[n - 1, r - 1] + (comb[n - 1, r] if r <= n - 1 else 0.0)
    return comb


@jit
def _rational_inplace(hom, order, comb):
    """A4.4 of [PT] on one point's ``hom (order + 1, order + 1, d + 1)``, in place: the
    Cartesian derivatives into ``hom[..., :d]`` (the loop of
    :func:`.rational.surface_derivatives_from_homogeneous`, same operations);
    ``comb`` the binomial coefficients (:func:`_binomials`)."""
    d = hom.shape[2] - 1
    inv_w = 1.0 / hom[0, 0, d]
    for k in range(order + 1):
        for l in range(order + 1):
            for c in range(d):
                v = hom[k, l, c]
                for i in range(k + 1):
                    for j in range(l + 1):
                        if i or j:
                            v -= (comb[k, i] * comb[l, j] * hom[i, j, d]) * hom[k - i, l - j, c]
                hom[k, l, c] = v * inv_w


@jit
def _surface_hom(knots_u, knots_v, p, q, net, u, v, su, sv, order, rational):
    m = u.size
    c = net.shape[2]
    tu, tv = min(order, p), min(order, q)
    du = np.zeros((order + 1, p + 1))
    dv = np.zeros((order + 1, q + 1))
    ndu_u, ndu_v = np.empty((p + 1, p + 1)), np.empty((q + 1, q + 1))
    a_u, a_v = np.zeros((2, p + 1)), np.zeros((2, q + 1))
    lu, ru = np.empty(p + 1), np.empty(p + 1)
    lv, rv = np.empty(q + 1), np.empty(q + 1)
    tmp = np.empty((order + 1, q + 1, c))
    out = np.zeros((m, order + 1, order + 1, c))
    comb = _binomials(order)
    for i in range(m):
        du[:, :] = 0.0
        dv[:, :] = 0.0
        ders_one(knots_u, p, u[i], su[i], tu, ndu_u, a_u, lu, ru, du)
        ders_one(knots_v, q, v[i], sv[i], tv, ndu_v, a_v, lv, rv, dv)
        iu0, iv0 = su[i] - p, sv[i] - q
        # the u sums first, then the v sums (as the numpy form's two matmuls)
        for k in range(order + 1):
            for jj in range(q + 1):
                for cc in range(c):
                    s = 0.0
                    for ii in range(p + 1):
                        s += du[k, ii] * net[iu0 + ii, iv0 + jj, cc]
                    tmp[k, jj, cc] = s
        for k in range(order + 1):
            for ll in range(order + 1):
                for cc in range(c):
                    s = 0.0
                    for jj in range(q + 1):
                        s += dv[ll, jj] * tmp[k, jj, cc]
                    out[i, k, ll, cc] = s
        if rational:
            _rational_inplace(out[i], order, comb)
    return out


def surface_derivatives_compiled(knots_u: NDArray, knots_v: NDArray, p: int, q: int,
                                 net: NDArray, u: NDArray, v: NDArray, su: NDArray,
                                 sv: NDArray, order: int, rational: bool) -> NDArray:
    """Partial derivatives ``(m, order + 1, order + 1, d)`` (A3.6 and A4.4 of [PT]).

    ``net (n_u, n_v, d + 1)`` the homogeneous control net, ``u, v (m,)``, ``su, sv (m,)``
    their spans; ``[i, k, l]`` is the k-th u- and l-th v-derivative at point ``i``
    (of the homogeneous numerator divided out when ``rational``).
    """
    return _surface_hom(np.ascontiguousarray(knots_u, dtype=np.float64),
                        np.ascontiguousarray(knots_v, dtype=np.float64), int(p), int(q),
                        np.ascontiguousarray(net, dtype=np.float64),
                        np.ascontiguousarray(u, dtype=np.float64),
                        np.ascontiguousarray(v, dtype=np.float64),
                        np.ascontiguousarray(su, dtype=np.int64),
                        np.ascontiguousarray(sv, dtype=np.int64), int(order),
                        bool(rational))[..., :-1]
