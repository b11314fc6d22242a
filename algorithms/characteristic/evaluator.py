"""Fast evaluation of a surface and its derivatives to second order at a few points (for the
tracers of the characteristic curves of 002).

The curve tracers of this package evaluate both surfaces hundreds of times at
a few dozen points each; :meth:`NurbsSurface.derivatives` spends most of such a
call on per-call set-up (basis triangles, einsum path search). Here every
polynomial piece (Bézier patch) is written once in the power basis of its local
coordinates, straight from the B-spline by Taylor rows at the span starts
(:func:`_power_patches`), so one evaluation is a span
lookup, the monomials and two batched matrix products; rational surfaces go
through :func:`surfprep.algorithms.rational.surface_derivatives_from_homogeneous`.
Outside the domain the end patches' polynomials continue (the same extension
as :meth:`NurbsSurface.derivatives`). Same results as
:meth:`NurbsSurface.derivatives` to rounding (tested).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from math import factorial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..basis import basis_derivatives
from ..rational import surface_derivatives_from_homogeneous
from ..surface import NurbsSurface
from . import distance_kernels

__all__ = ["PatchEvaluator"]


@lru_cache(maxsize=64)
def _monomial_table(degree: int, order: int) -> tuple[NDArray, NDArray]:
    """``coef (o+1, p+1)`` and exponent ``index (o+1, p+1)`` of ``d^o/dx^o x^k``."""
    coef = np.zeros((order + 1, degree + 1))
    index = np.zeros((order + 1, degree + 1), dtype=int)
    for o in range(order + 1):
        for k in range(o, degree + 1):
            coef[o, k] = factorial(k) / factorial(k - o)
            index[o, k] = k - o
    return coef, index


@lru_cache(maxsize=64)
def _exponents(n: int) -> NDArray:
    return np.arange(n)


def _monomials(x: NDArray, degree: int, order: int, scale: NDArray) -> NDArray:
    """``(m, order + 1, degree + 1)``: ``d^o/du^o x^k`` with ``x = (u - a) * scale``."""
    coef, index = _monomial_table(degree, order)
    powers = x[:, None] ** _exponents(degree + 1)                         # (m, p+1)
    if order == 0:
        return powers[:, None, :]
    chain = scale[:, None] ** _exponents(order + 1)                       # (m, o+1)
    return powers[:, index] * coef * chain[:, :, None]


def _rational_to_second_order(hom: NDArray, order: int) -> NDArray:
    """Quotient rule (eq. 4.20 of Piegl & Tiller) written out for ``order <= 2``."""
    a, w = hom[..., :-1], hom[..., -1:]
    out = np.empty_like(a)
    inv = 1.0 / w[:, 0, 0]
    out[:, 0, 0] = a[:, 0, 0] * inv
    if order >= 1:
        s = out[:, 0, 0]
        out[:, 1, 0] = (a[:, 1, 0] - w[:, 1, 0] * s) * inv
        out[:, 0, 1] = (a[:, 0, 1] - w[:, 0, 1] * s) * inv
    if order >= 1:
        out[:, 1, 1] = (a[:, 1, 1] - w[:, 1, 0] * out[:, 0, 1] - w[:, 0, 1] * out[:, 1, 0]
                        - w[:, 1, 1] * s) * inv
    if order >= 2:
        out[:, 2, 0] = (a[:, 2, 0] - 2 * w[:, 1, 0] * out[:, 1, 0] - w[:, 2, 0] * s) * inv
        out[:, 0, 2] = (a[:, 0, 2] - 2 * w[:, 0, 1] * out[:, 0, 1] - w[:, 0, 2] * s) * inv
        out[:, 2, 1] = (a[:, 2, 1] - w[:, 2, 0] * out[:, 0, 1] - w[:, 0, 1] * out[:, 2, 0]
                        - 2 * w[:, 1, 0] * out[:, 1, 1]
                        - 2 * w[:, 1, 1] * out[:, 1, 0] - w[:, 2, 1] * s) * inv
        out[:, 1, 2] = (a[:, 1, 2] - w[:, 0, 2] * out[:, 1, 0] - w[:, 1, 0] * out[:, 0, 2]
                        - 2 * w[:, 0, 1] * out[:, 1, 1]
                        - 2 * w[:, 1, 1] * out[:, 0, 1] - w[:, 1, 2] * s) * inv
        out[:, 2, 2] = (a[:, 2, 2] - w[:, 2, 0] * out[:, 0, 2] - w[:, 0, 2] * out[:, 2, 0]
                        - 2 * w[:, 1, 0] * out[:, 1, 2] - 2 * w[:, 0, 1] * out[:, 2, 1]
                        - 4 * w[:, 1, 1] * out[:, 1, 1] - 2 * w[:, 2, 1] * out[:, 0, 1]
                        - 2 * w[:, 1, 2] * out[:, 1, 0] - w[:, 2, 2] * s) * inv
    return out


def _taylor_rows(knots: NDArray, degree: int, count: int) -> tuple[NDArray, NDArray, NDArray]:
    """Per non-empty span ``[a, b]`` of the domain: ``M (k, p+1, p+1)`` with the piece's
    power-basis coefficient ``x^i`` (``x = (u - a) / (b - a)``) of basis function
    ``span - p + j`` in ``M[s, i, j]`` (Taylor at ``a``: ``N^(i)(a) (b - a)^i / i!``,
    the derivatives by A2.3), the spans and the intervals ``(k, 2)``."""
    spans = np.flatnonzero(knots[degree:count] < knots[degree + 1:count + 1]) + degree
    a, b = knots[spans], knots[spans + 1]
    ders, _ = basis_derivatives(knots, degree, a, degree, spans)      # (k, p+1, p+1)
    i = np.arange(degree + 1)
    scale = (b - a)[:, None] ** i / np.array([factorial(k) for k in i], dtype=float)
    return ders * scale[:, :, None], spans, np.stack([a, b], axis=1)


def _power_patches(surface: NurbsSurface) -> tuple[NDArray, NDArray, NDArray]:
    """``coef (ku, kv, p+1, q+1, d+1)``: the homogeneous power-basis coefficients of
    every patch in its local coordinates, with the patch intervals ``(ku, 2)``,
    ``(kv, 2)``. Straight from the B-spline by Taylor rows (:func:`_taylor_rows`):
    the same polynomials as the Bezier patches converted to the power basis, without
    the knot insertion."""
    pw = surface.homogeneous_points()                                 # (nu, nv, d+1)
    p, q = surface.degree_u, surface.degree_v
    mu, su, iu = _taylor_rows(surface.knots_u, p, pw.shape[0])
    mv, sv, iv = _taylor_rows(surface.knots_v, q, pw.shape[1])
    rows_u = su[:, None] - p + np.arange(p + 1)                       # (ku, p+1)
    rows_v = sv[:, None] - q + np.arange(q + 1)
    cu = np.einsum("sij,sjvc->sivc", mu, pw[rows_u])                  # (ku, p+1, nv, d+1)
    coef = np.einsum("tlj,sitjc->stilc", mv, cu[:, :, rows_v])        # (ku, kv, p+1, q+1, d+1)
    return np.ascontiguousarray(coef), iu, iv


@dataclass(frozen=True, eq=False)
class PatchEvaluator:
    """Power-basis form of a :class:`NurbsSurface`, for repeated small evaluations."""

    surface: NurbsSurface
    _data: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        coef, iu, iv = _power_patches(self.surface)
        self._data.update(coef=coef, iu=iu, iv=iv)
        self._data["compiled"] = distance_kernels.evaluator_arrays(coef, iu, iv) + (
            self.surface.weights is not None,)

    @property
    def compiled(self) -> tuple[NDArray, NDArray, NDArray, bool]:
        """``(coef, iu, iv, rational)`` for :mod:`.distance_kernels`."""
        return self._data["compiled"]

    @property
    def domain(self) -> tuple[float, float, float, float]:
        return self.surface.domain

    def derivatives(self, u: ArrayLike, v: ArrayLike, order: int = 2) -> NDArray:
        """``(m, order + 1, order + 1, 3)``, as :meth:`NurbsSurface.derivatives` on 1-D input."""
        u = np.asarray(u, dtype=float).reshape(-1)
        v = np.asarray(v, dtype=float).reshape(-1)
        if distance_kernels.AVAILABLE and order <= 2:
            return distance_kernels.patch_derivatives(*self.compiled, u, v)[:, :order + 1, :order + 1]
        coef, iu, iv = self._data["coef"], self._data["iu"], self._data["iv"]
        # interior breakpoints only: a parameter beyond either end stays in the end patch
        su = np.searchsorted(iu[1:, 0], u, side="right")
        sv = np.searchsorted(iv[1:, 0], v, side="right")
        a_u, a_v = iu[su, 0], iv[sv, 0]
        scale_u = 1.0 / (iu[su, 1] - a_u)
        scale_v = 1.0 / (iv[sv, 1] - a_v)
        pu = _monomials((u - a_u) * scale_u, self.surface.degree_u, order, scale_u)
        pv = _monomials((v - a_v) * scale_v, self.surface.degree_v, order, scale_v)
        c = coef[su, sv]                                            # (m, p+1, q+1, 4)
        m, p1, q1, d1 = c.shape
        tmp = np.matmul(pu, c.reshape(m, p1, q1 * d1)).reshape(m, order + 1, q1, d1)
        hom = np.matmul(pv[:, None], tmp)                           # (m, k, l, 4)
        if self.surface.weights is None:
            return hom[..., :-1]
        if order <= 2:
            return _rational_to_second_order(hom, order)
        return surface_derivatives_from_homogeneous(hom[..., :-1], hom[..., -1])

    def evaluate(self, u: ArrayLike, v: ArrayLike) -> NDArray:
        """Points ``(m, 3)``."""
        return self.derivatives(u, v, 0)[:, 0, 0]
