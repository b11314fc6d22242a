"""Derivatives of rational curves and surfaces from those of their homogeneous form.

A NURBS object is the projection of a polynomial B-spline in homogeneous
coordinates ``(w x, w y, w z, w)``. Given the derivatives of the numerator
``A`` and the weight function ``w``, the quotient rule applied repeatedly gives
the derivatives of ``C = A / w`` (equations (4.8) and (4.20) of [PT]).

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., 1997, A4.2 and A4.4.
"""

from __future__ import annotations

from math import comb

import numpy as np
from numpy.typing import NDArray

__all__ = ["curve_derivatives_from_homogeneous", "surface_derivatives_from_homogeneous"]


def curve_derivatives_from_homogeneous(a_ders: NDArray, w_ders: NDArray) -> NDArray:
    """Rational curve derivatives (A4.2 of [PT]).

    .. math:: C^{(k)} = \\Big(A^{(k)} - \\sum_{i=1}^{k} \\binom{k}{i} w^{(i)} C^{(k-i)}\\Big) / w

    Parameters
    ----------
    a_ders : (m, order + 1, d) float
        Derivatives of the weighted numerator.
    w_ders : (m, order + 1) float
        Derivatives of the weight function.

    Returns
    -------
    (m, order + 1, d) float
    """
    order = a_ders.shape[1] - 1
    out = np.empty_like(a_ders)
    w0 = w_ders[:, 0, None]
    for k in range(order + 1):
        v = a_ders[:, k, :].copy()
        for i in range(1, k + 1):
            v -= comb(k, i) * w_ders[:, i, None] * out[:, k - i, :]
        out[:, k, :] = v / w0
    return out


def surface_derivatives_from_homogeneous(a_ders: NDArray, w_ders: NDArray) -> NDArray:
    """Rational surface derivatives (A4.4 of [PT], eq. 4.20).

    .. math:: S_{kl} = \\Big(A_{kl} - \\sum_{(i,j) \\ne (0,0)}^{i \\le k,\\, j \\le l}
              \\binom{k}{i}\\binom{l}{j}\\, w_{ij}\\, S_{k-i,\\,l-j}\\Big) / w

    The work runs on a copy with the point axis last, so every operation is one
    contiguous sweep over all points.

    Parameters
    ----------
    a_ders : (m, order + 1, order + 1, d) float
        ``a_ders[:, k, l]`` is the k-th u- and l-th v-derivative of the numerator.
    w_ders : (m, order + 1, order + 1) float

    Returns
    -------
    (m, order + 1, order + 1, d) float
    """
    order = a_ders.shape[1] - 1
    a = np.ascontiguousarray(np.moveaxis(a_ders, 0, -1))      # (o+1, o+1, d, m)
    w = np.ascontiguousarray(np.moveaxis(w_ders, 0, -1))      # (o+1, o+1, m)
    inv_w = 1.0 / w[0, 0]
    out = np.empty_like(a)
    for k in range(order + 1):
        for l in range(order + 1):
            v = a[k, l].copy()
            for i in range(k + 1):
                for j in range(l + 1):
                    if i or j:
                        coef = comb(k, i) * comb(l, j)
                        v -= (coef * w[i, j]) * out[k - i, l - j]
            out[k, l] = v * inv_w
    return np.moveaxis(out, -1, 0)
