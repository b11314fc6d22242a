"""The oriented distance function and its derivatives (002 §3.2, appendix A.1).

For a point ``r(u, v)`` of the first surface and its orthogonal projection
``Q = q(s, t)`` on the second (:mod:`.projection`), with ``n_q`` the unit normal
of ``q`` at ``Q``:

.. math:: \\phi(u, v) = n_q \\cdot (r(u, v) - q(s, t))        \\qquad (2)

    \\phi_u = n_q \\cdot r_u, \\quad \\phi_v = n_q \\cdot r_v        \\qquad (24), (25)

    \\phi_{uu} = n_{q,u} \\cdot r_u + n_q \\cdot r_{uu}, \\quad
    \\phi_{uv} = n_{q,v} \\cdot r_u + n_q \\cdot r_{uv}, \\quad
    \\phi_{vv} = n_{q,v} \\cdot r_v + n_q \\cdot r_{vv}         \\qquad (26)-(29)

with ``n_{q,u} = [n_{q,s}\\; n_{q,t}] K^{-1} [r_u . q_s,\\; r_u . q_t]^T`` and
likewise for ``v`` (eqs. 30-31); ``K`` is the matrix of eq. (22) and
``[s_u, s_v; t_u, t_v] = K^{-1} G`` with ``G_ij = r_j . q_i`` (eqs. 21, 23) is
the map of the parameter velocities onto ``q``'s domain. ``n_{q,s}`` and
``n_{q,t}`` are the derivatives of the unit normal (Weingarten map) from
``q``'s second derivatives. Everything is vectorized over points.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..surface import NurbsSurface
from . import distance_kernels
from .evaluator import PatchEvaluator
from .projector import Projection, Projector, projection_matrix

__all__ = ["DistanceField", "DistanceJet", "distance_jet"]


@dataclass(frozen=True)
class DistanceJet:
    """``phi`` and its derivatives at ``n`` points of the first surface.

    Attributes
    ----------
    uv : (n, 2) float
    point : (n, 3) float
        ``r(u, v)``.
    projection : Projection
        Feet on ``q`` (``st``, ``foot``, ``status``, ``det_k``).
    normal : (n, 3) float
        Unit normal ``n_q`` at the feet.
    phi : (n,) float
        Oriented distance (eq. 2).
    grad : (n, 2) float
        ``(phi_u, phi_v)`` (eqs. 24-25).
    hess : (n, 2, 2) float
        ``[[phi_uu, phi_uv], [phi_vu, phi_vv]]`` (eqs. 26-29), symmetrized.
    st_jacobian : (n, 2, 2) float
        ``[[s_u, s_v], [t_u, t_v]] = K^{-1} G`` (eq. 21).
    """

    uv: NDArray
    point: NDArray
    projection: Projection
    normal: NDArray
    phi: NDArray
    grad: NDArray
    hess: NDArray
    st_jacobian: NDArray

    @property
    def st(self) -> NDArray:
        return self.projection.st

    @property
    def status(self) -> NDArray:
        return self.projection.status

    @property
    def det_hess(self) -> NDArray:
        h = self.hess
        return h[:, 0, 0] * h[:, 1, 1] - h[:, 0, 1] * h[:, 1, 0]


def _dot(a: NDArray, b: NDArray) -> NDArray:
    return np.einsum("...i,...i->...", a, b)


def _cross(a: NDArray, b: NDArray) -> NDArray:
    """Row-wise cross product of ``(m, 3)`` arrays (cheaper than np.cross on small batches)."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], -1)


def _unit_normal_derivatives(qd: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Unit normal ``n (m, 3)`` and its derivatives ``n_s, n_t (m, 3)`` from ``q``'s
    second-order derivatives ``qd (m, 3, 3, 3)``."""
    qs, qt = qd[:, 1, 0], qd[:, 0, 1]
    big = _cross(qs, qt)
    length = np.linalg.norm(big, axis=1)
    length = np.where(length > 1e-300, length, 1e-300)
    n = big / length[:, None]
    out = []
    for d in (_cross(qd[:, 2, 0], qt) + _cross(qs, qd[:, 1, 1]),
              _cross(qd[:, 1, 1], qt) + _cross(qs, qd[:, 0, 2])):
        out.append((d - n * _dot(n, d)[:, None]) / length[:, None])
    return n, out[0], out[1]


def _solve2(mat: NDArray, rhs: NDArray) -> NDArray:
    """``mat^{-1} rhs`` for ``mat (m, 2, 2)``, ``rhs (m, 2, k)`` (singular: zeros)."""
    det = mat[:, 0, 0] * mat[:, 1, 1] - mat[:, 0, 1] * mat[:, 1, 0]
    ok = np.abs(det) > 1e-300
    det = np.where(ok, det, 1.0)
    inv = np.stack([np.stack([mat[:, 1, 1], -mat[:, 0, 1]], -1),
                    np.stack([-mat[:, 1, 0], mat[:, 0, 0]], -1)], -2) / det[:, None, None]
    return np.where(ok[:, None, None], inv @ rhs, 0.0)


def distance_jet(r: NurbsSurface | PatchEvaluator, projector: Projector, uv: ArrayLike,
                 st0: ArrayLike | None = None) -> DistanceJet:
    """``phi``, gradient and Hessian at ``uv (n, 2)`` of ``r`` against ``projector.surface``.

    Parameters
    ----------
    r : NurbsSurface or PatchEvaluator
        The first surface (its domain is where ``phi`` lives).
    projector : Projector
        Projection onto the second surface ``q``.
    uv : (n, 2) float
    st0 : (n, 2) float, optional
        Start feet (continuation); default the projector's seed grid.
    """
    uv = np.asarray(uv, dtype=float).reshape(-1, 2)
    if distance_kernels.AVAILABLE and isinstance(r, PatchEvaluator):
        return _compiled_jet(r, projector, uv, st0)
    rd = r.derivatives(uv[:, 0], uv[:, 1], 2)
    point = rd[:, 0, 0]
    proj, qd = projector.project_with_derivatives(point, st0)
    n, n_s, n_t = _unit_normal_derivatives(qd)
    off = point - qd[:, 0, 0]
    phi = _dot(n, off)
    ru, rv = rd[:, 1, 0], rd[:, 0, 1]
    grad = np.stack([_dot(n, ru), _dot(n, rv)], -1)                       # (24)-(25)
    qs, qt = qd[:, 1, 0], qd[:, 0, 1]
    g = np.stack([np.stack([_dot(ru, qs), _dot(rv, qs)], -1),
                  np.stack([_dot(ru, qt), _dot(rv, qt)], -1)], -2)         # (23)
    jac = _solve2(projection_matrix(off, qd), g)                           # (21)
    n_u = n_s * jac[:, 0, 0, None] + n_t * jac[:, 1, 0, None]              # (30)
    n_v = n_s * jac[:, 0, 1, None] + n_t * jac[:, 1, 1, None]              # (31)
    huu = _dot(n_u, ru) + _dot(n, rd[:, 2, 0])                             # (26)
    huv = _dot(n_v, ru) + _dot(n, rd[:, 1, 1])                             # (27)
    hvu = _dot(n_u, rv) + _dot(n, rd[:, 1, 1])                             # (28)
    hvv = _dot(n_v, rv) + _dot(n, rd[:, 0, 2])                             # (29)
    mixed = 0.5 * (huv + hvu)
    hess = np.stack([np.stack([huu, mixed], -1), np.stack([mixed, hvv], -1)], -2)
    return DistanceJet(uv, point, proj, n, phi, grad, hess, jac)


def _compiled_jet(r: PatchEvaluator, projector: Projector, uv: NDArray,
                  st0: ArrayLike | None) -> DistanceJet:
    """:func:`distance_jet` by :func:`.distance_kernels.distance_points` (one compiled pass)."""
    if st0 is None:                   # a parallelogram q is projected in closed form
        st0 = (np.zeros_like(uv) if projector.is_affine
               else projector.seeds(r.evaluate(uv[:, 0], uv[:, 1])))
    st0 = np.ascontiguousarray(np.asarray(st0, dtype=float).reshape(-1, 2))
    lo, hi, quarter = projector.newton_bounds()
    point, foot, normal, st, phi, grad, hess, jac, status, det = distance_kernels.distance_points(
        *r.compiled, *projector.evaluator.compiled, np.ascontiguousarray(uv), st0, lo, hi,
        quarter, float(projector.tol), int(projector.max_iter), projector.lower,
        projector.upper, projector.kernel_frame())
    return DistanceJet(uv, point, Projection(st, foot, status, det), normal, phi, grad, hess, jac)


@dataclass(frozen=True, eq=False)
class DistanceField:
    """``phi`` on the domain of ``r`` against ``q``, for a pair ``(a, b)`` in either role.

    Attributes
    ----------
    r : NurbsSurface
        The surface whose parameter domain ``phi`` lives on.
    projector : Projector
        Projection onto ``q``.
    swapped : bool
        False: ``r`` is the pair's ``a`` and ``q`` its ``b``; True: the other way.
    """

    r: NurbsSurface
    projector: Projector
    swapped: bool = False
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def evaluator(self) -> PatchEvaluator:
        if "evaluator" not in self._cache:
            self._cache["evaluator"] = PatchEvaluator(self.r)
        return self._cache["evaluator"]

    @property
    def q(self) -> NurbsSurface:
        return self.projector.surface

    @property
    def lower(self) -> NDArray:
        if "lower" not in self._cache:
            d = self.r.domain
            self._cache["lower"] = np.array([d[0], d[2]])
        return self._cache["lower"]

    @property
    def upper(self) -> NDArray:
        if "upper" not in self._cache:
            d = self.r.domain
            self._cache["upper"] = np.array([d[1], d[3]])
        return self._cache["upper"]

    @property
    def diagonal(self) -> float:
        """Diagonal of ``r``'s parameter rectangle."""
        if "diagonal" not in self._cache:
            self._cache["diagonal"] = float(np.linalg.norm(self.upper - self.lower))
        return self._cache["diagonal"]

    @property
    def speed(self) -> float:
        """Largest ``|r_u|``, ``|r_v|`` on a 9 x 9 grid (model units per parameter unit)."""
        if "speed" not in self._cache:
            u = np.linspace(self.lower[0], self.upper[0], 9)
            v = np.linspace(self.lower[1], self.upper[1], 9)
            d = self.r.derivatives_grid(u, v, 1)
            self._cache["speed"] = float(max(np.linalg.norm(d[:, :, 1, 0], axis=-1).max(),
                                             np.linalg.norm(d[:, :, 0, 1], axis=-1).max(), 1e-300))
        return self._cache["speed"]

    def inside(self, uv: NDArray, rel: float = 1e-12) -> NDArray:
        """``(n,) bool``: ``uv (n, 2)`` within ``r``'s domain."""
        eps = rel * (self.upper - self.lower)
        return np.all((uv >= self.lower - eps) & (uv <= self.upper + eps), axis=-1)

    def jet(self, uv: ArrayLike, st0: ArrayLike | None = None) -> DistanceJet:
        """:func:`distance_jet` at ``uv (n, 2)``."""
        return distance_jet(self.evaluator, self.projector, uv, st0)

    def pair(self) -> tuple[NurbsSurface, NurbsSurface]:
        """``(a, b)``: the two surfaces in the pair's order."""
        return (self.q, self.r) if self.swapped else (self.r, self.q)

    def ab(self, uv: NDArray, st: NDArray) -> tuple[NDArray, NDArray]:
        """``(uv_a, uv_b)``: parameters on ``r`` and ``q`` in the pair's order."""
        return (st, uv) if self.swapped else (uv, st)
