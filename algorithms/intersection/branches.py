"""Branches of an implicit curve at a singular point, to second order.

Where a curve ``f(x) = 0`` in the plane has ``f = 0`` and ``grad f = 0`` the
first-order tangent is undefined and tracers stop. Expanding to second order
(002 §4, the classification of singular points of ``phi = 0`` by the Hessian of
the oriented distance; 000 §29.5.1, tangent directions at a singular point of
a surface-surface intersection)::

    f(x0 + d) = 1/2 d^T H d + O(|d|^3)

so the branches leave ``x0`` along the real roots of the quadratic form
``d^T H d = 0``:

* ``det H < 0``: a double point (two branches crossing, four half-branches
  along ``+-d1``, ``+-d2``);
* ``det H > 0``: an isolated point (no branch: tangential contact);
* ``det H = 0``, ``H != 0``: a cusp (one direction, the null vector of ``H``;
  which sense is decided by third-order terms);
* ``H = 0``: degenerate (higher-order contact; nothing is said).

For two surfaces ``a(u, v)`` and ``b(s, t)`` meeting at a point with parallel
normals (a singular point of their intersection), both are graphs over the
common tangent plane, ``h_a(x) = 1/2 x^T II_a x``, ``h_b(x) = 1/2 x^T II_b x``
(second fundamental forms in an orthonormal frame of the tangent plane, with
one normal ``N``), and the intersection is ``h_a - h_b = 0``: the form above
with ``H = II_a - II_b`` (:func:`surface_pair_form`). The singular point itself
is the zero of ``[a - b, N_a x N_b]`` (:func:`locate_singular_points`,
Gauss-Newton: five independent equations, four unknowns, consistent there).

Pure numpy; used by :mod:`.extend` (triangle method) and by
:mod:`surfprep.algorithms.characteristic.trace` (the ODE tracer).
"""

from __future__ import annotations

import enum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..surface import NurbsSurface

__all__ = [
    "SingularKind",
    "branch_directions",
    "locate_singular_points",
    "singular_branches",
    "surface_pair_form",
]


class SingularKind(enum.Enum):
    """Type of a singular point of ``f = 0`` by its Hessian (002 §4)."""

    #: det H < 0: two branches cross
    DOUBLE_POINT = "double_point"
    #: det H > 0: the point is alone (tangential contact)
    ISOLATED = "isolated"
    #: det H ~ 0, H != 0: one tangent direction
    CUSP = "cusp"
    #: H ~ 0: contact of higher order, no second-order answer
    DEGENERATE = "degenerate"


def branch_directions(hessian: ArrayLike, *, rel_tol: float = 1e-8
                      ) -> tuple[list[SingularKind], NDArray]:
    """Tangent directions of ``f = 0`` at singular points (roots of ``d^T H d = 0``).

    Parameters
    ----------
    hessian : (n, 2, 2) float
        Second derivatives of ``f`` (symmetrized here) at points where ``f`` and
        ``grad f`` vanish (002 eqs. 26-29 for ``f = phi``).
    rel_tol : float
        ``|det H|`` below ``rel_tol`` times the squared largest eigenvalue is a
        cusp; a largest eigenvalue below ``rel_tol`` times the largest entry of
        all ``hessian`` (or exactly 0) is degenerate.

    Returns
    -------
    kinds : list of SingularKind, n
    directions : (n, 2, 2) float
        Unit directions ``directions[i, j]``: two for a double point, the null
        direction (in ``[i, 0]``) for a cusp, NaN where there is none.
    """
    h = np.asarray(hessian, dtype=float).reshape(-1, 2, 2)
    h = 0.5 * (h + np.swapaxes(h, 1, 2))
    lam, vec = np.linalg.eigh(h)                       # ascending: lam[:, 0] <= lam[:, 1]
    big = np.abs(lam).max(axis=1)
    floor = rel_tol * max(float(big.max(initial=0.0)), np.finfo(float).tiny)
    out = np.full((h.shape[0], 2, 2), np.nan)
    kinds = []
    for i in range(h.shape[0]):
        lo, hi = lam[i]
        if big[i] <= floor:
            kinds.append(SingularKind.DEGENERATE)
        elif abs(lo * hi) <= rel_tol * big[i] ** 2:
            kinds.append(SingularKind.CUSP)
            null = 0 if abs(lo) <= abs(hi) else 1
            out[i, 0] = vec[i, :, null]
        elif lo * hi > 0:
            kinds.append(SingularKind.ISOLATED)
        else:
            # lo < 0 < hi: d = a e_lo + b e_hi with lo a^2 + hi b^2 = 0
            a, b = np.sqrt(hi), np.sqrt(-lo)
            norm = np.hypot(a, b)
            for j, sign in enumerate((1.0, -1.0)):
                out[i, j] = (a * vec[i, :, 0] + sign * b * vec[i, :, 1]) / norm
            kinds.append(SingularKind.DOUBLE_POINT)
    return kinds, out


def _cross(a: NDArray, b: NDArray) -> NDArray:
    """Row-wise cross product of ``(n, 3)`` arrays (np.cross without its axis moves)."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
                     a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _unit_normal(d: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Unit normal ``(n, 3)`` and its u- and v-derivatives from derivatives
    ``d (n, 3, 3, 3)`` (order 2)."""
    su, sv = d[:, 1, 0], d[:, 0, 1]
    n = _cross(su, sv)
    length = np.maximum(np.linalg.norm(n, axis=1), np.finfo(float).tiny)[:, None]
    unit = n / length
    out = [unit]
    for dn in (_cross(d[:, 2, 0], sv) + _cross(su, d[:, 1, 1]),
               _cross(d[:, 1, 1], sv) + _cross(su, d[:, 0, 2])):
        out.append((dn - unit * np.einsum("ij,ij->i", unit, dn)[:, None]) / length)
    return out[0], out[1], out[2]


def _second_form(d: NDArray, normal: NDArray, frame: NDArray) -> NDArray:
    """Second fundamental form ``(n, 2, 2)`` of a surface in the orthonormal tangent
    frame ``frame (n, 3, 2)`` with normal ``normal (n, 3)`` (000 §29.5.1:
    ``L = N . S_uu`` etc., then ``M^-T L M^-1`` with ``M = frame^T [S_u S_v]``)."""
    jac = np.stack([d[:, 1, 0], d[:, 0, 1]], axis=2)                       # (n, 3, 2)
    form = np.empty((d.shape[0], 2, 2))
    form[:, 0, 0] = np.einsum("ij,ij->i", normal, d[:, 2, 0])
    form[:, 1, 1] = np.einsum("ij,ij->i", normal, d[:, 0, 2])
    form[:, 0, 1] = form[:, 1, 0] = np.einsum("ij,ij->i", normal, d[:, 1, 1])
    m_inv = np.linalg.inv(np.einsum("nci,ncj->nij", frame, jac))
    return np.einsum("nki,nkl,nlj->nij", m_inv, form, m_inv)


def surface_pair_form(da: NDArray, db: NDArray) -> tuple[NDArray, NDArray]:
    """Frame of the common tangent plane and the form ``II_a - II_b`` in it.

    Parameters
    ----------
    da, db : (n, 3, 3, 3) float
        ``NurbsSurface.derivatives(..., 2)`` of both surfaces at a singular point
        of their intersection (parallel normals).

    Returns
    -------
    frame : (n, 3, 2) float
        Orthonormal tangent vectors (the first along ``a``'s ``S_u``).
    form : (n, 2, 2) float
        ``II_a - II_b`` with the normal of ``a`` for both (000 §29.5.1): the
        intersection is ``x^T form x = 0`` to second order in the frame's
        coordinates ``x``; :func:`branch_directions` takes it as ``H``.
    """
    na = _unit_normal(da)[0]
    e1 = da[:, 1, 0] / np.linalg.norm(da[:, 1, 0], axis=1)[:, None]
    e2 = _cross(na, e1)
    frame = np.stack([e1, e2], axis=2)
    return frame, _second_form(da, na, frame) - _second_form(db, na, frame)


#: a start of :func:`locate_singular_points` whose residual has not fallen below this share
#: of what it was ``_STALL_STEPS`` steps before is given up (no singular point near it)
_STALL_GAIN = 0.9
_STALL_STEPS = 10


def locate_singular_points(surface_a: NurbsSurface, surface_b: NurbsSurface, uv_a: ArrayLike,
                           uv_b: ArrayLike, *, tol: float, scale: float, iterations: int = 40
                           ) -> tuple[NDArray, NDArray, NDArray]:
    """Singular points of the intersection of two surfaces near ``k`` starts.

    Gauss-Newton (Levenberg-damped) on the six residuals
    ``[a(u, v) - b(s, t), scale (N_a x N_b)]`` in the four unknowns
    ``(u, v, s, t)``: a common point with parallel normals (000 §29.5.1; 002
    §4: ``phi = 0`` and ``grad phi = 0``). At a double point the residual
    vanishes and the Jacobian has full rank, so the iteration converges
    quadratically; once a start meets ``tol`` two more steps bring its point to
    rounding level. A start whose residual has not fallen by 10 % in 10 steps
    (a minimum of ``|N_a x N_b|`` off zero: near-tangential surfaces, no
    singular point) is given up, not iterated to the end.

    Parameters
    ----------
    uv_a, uv_b : (k, 2) float
        Starts (e.g. ends of traced curves near the point).
    tol : float
        Model units: converged when ``|a - b| <= tol / 16`` and
        ``scale |N_a x N_b| <= tol / 16``.
    scale : float
        Model units weighting the normal residual (e.g. the search radius).

    Returns
    -------
    uv_a, uv_b : (k, 2) float
    converged : (k,) bool
    """
    ua = np.array(uv_a, dtype=float).reshape(-1, 2)
    ub = np.array(uv_b, dtype=float).reshape(-1, 2)
    lo = np.concatenate([surface_a.domain[0::2], surface_b.domain[0::2]])
    hi = np.concatenate([surface_a.domain[1::2], surface_b.domain[1::2]])
    z = np.concatenate([ua, ub], axis=1)
    converged = np.zeros(z.shape[0], dtype=bool)
    mu = np.full(z.shape[0], 1e-12)
    polish = np.zeros(z.shape[0], dtype=np.int64)
    history = np.full((iterations, z.shape[0]), np.inf)     # residual norm per iteration
    active = np.arange(z.shape[0])
    for it in range(iterations):
        res, jac = _residual(surface_a, surface_b, z[active], scale)
        norm = np.linalg.norm(res, axis=1)
        history[it, active] = norm
        converged[active] = (np.linalg.norm(res[:, :3], axis=1) <= tol / 16) & \
            (np.linalg.norm(res[:, 3:], axis=1) <= tol / 16)
        polish[active] += converged[active]   # two more steps once within tol: rounding
        # a start that is done, or has not gained _STALL_GAIN in _STALL_STEPS steps (no
        # singular point near it: a minimum of |N_a x N_b| off zero), leaves the batch
        stalled = (it >= _STALL_STEPS) & ~converged[active] & \
            (norm > _STALL_GAIN * history[it - _STALL_STEPS, active])
        stay = (polish[active] <= 2) & ~stalled
        active, res, jac, norm = active[stay], res[stay], jac[stay], norm[stay]
        if active.size == 0:
            break
        jtj = np.einsum("nki,nkj->nij", jac, jac)
        jtr = np.einsum("nki,nk->ni", jac, res)
        diag = np.einsum("nii->ni", jtj)
        step = -np.linalg.solve(jtj + (mu[active, None] * np.maximum(diag, 1e-300))[:, :, None]
                                * np.eye(4), jtr[..., None])[..., 0]
        trial = np.clip(z[active] + step, lo, hi)
        new_norm = np.linalg.norm(_residual(surface_a, surface_b, trial, scale, False)[0], axis=1)
        better = new_norm < norm
        z[active] = np.where(better[:, None], trial, z[active])
        mu[active] = np.where(better, np.maximum(mu[active] / 10, 1e-12),
                              np.minimum(mu[active] * 10, 1e6))
    return z[:, :2], z[:, 2:], converged & np.isfinite(z).all(axis=1)


def _residual(surface_a: NurbsSurface, surface_b: NurbsSurface, z: NDArray, scale: float,
              with_jacobian: bool = True) -> tuple[NDArray, NDArray | None]:
    """``(k, 6)`` residual of :func:`locate_singular_points` and its ``(k, 6, 4)`` Jacobian."""
    if not with_jacobian:          # the residual alone needs first derivatives only
        da = surface_a.derivatives(z[:, 0], z[:, 1], 1)
        db = surface_b.derivatives(z[:, 2], z[:, 3], 1)
        na, nb = _cross(da[:, 1, 0], da[:, 0, 1]), _cross(db[:, 1, 0], db[:, 0, 1])
        tiny = np.finfo(float).tiny
        na /= np.maximum(np.linalg.norm(na, axis=1), tiny)[:, None]
        nb /= np.maximum(np.linalg.norm(nb, axis=1), tiny)[:, None]
        return np.concatenate([da[:, 0, 0] - db[:, 0, 0], scale * _cross(na, nb)], axis=1), None
    da = surface_a.derivatives(z[:, 0], z[:, 1], 2)
    db = surface_b.derivatives(z[:, 2], z[:, 3], 2)
    na, na_u, na_v = _unit_normal(da)
    nb, nb_s, nb_t = _unit_normal(db)
    res = np.concatenate([da[:, 0, 0] - db[:, 0, 0], scale * _cross(na, nb)], axis=1)
    top = np.stack([da[:, 1, 0], da[:, 0, 1], -db[:, 1, 0], -db[:, 0, 1]], axis=2)
    bottom = scale * np.stack([_cross(na_u, nb), _cross(na_v, nb),
                               _cross(na, nb_s), _cross(na, nb_t)], axis=2)
    return res, np.concatenate([top, bottom], axis=1)


def singular_branches(surface_a: NurbsSurface, surface_b: NurbsSurface, uv_a: ArrayLike,
                      uv_b: ArrayLike, *, rel_tol: float = 1e-8
                      ) -> tuple[NDArray, list[SingularKind], NDArray]:
    """Point, kind and 3D branch directions at singular points of an intersection.

    Parameters
    ----------
    uv_a, uv_b : (k, 2) float
        Located singular points (:func:`locate_singular_points`).

    Returns
    -------
    points : (k, 3) float
    kinds : list of SingularKind
    directions : (k, 2, 3) float
        Unit tangent directions of the branches in space (each taken both ways
        gives the half-branches); NaN where there is none (see
        :func:`branch_directions`).
    """
    ua = np.asarray(uv_a, dtype=float).reshape(-1, 2)
    ub = np.asarray(uv_b, dtype=float).reshape(-1, 2)
    da = surface_a.derivatives(ua[:, 0], ua[:, 1], 2)
    db = surface_b.derivatives(ub[:, 0], ub[:, 1], 2)
    frame, form = surface_pair_form(da, db)
    kinds, plane = branch_directions(form, rel_tol=rel_tol)
    points = 0.5 * (da[:, 0, 0] + db[:, 0, 0])
    return points, kinds, np.einsum("kci,kji->kjc", frame, plane)
