"""SOR sweeps of the tangential elliptic grid system (:mod:`.elliptic`), compiled and in numpy.

One sweep visits every interior node, computes the Jacobi move of the 3D system

.. math::

    R = g_{22}(r_{i+1,j} + r_{i-1,j}) + g_{11}(r_{i,j+1} + r_{i,j-1})
        - 2 g_{12} r_{\\xi\\eta} + g_{22} P r_\\xi + g_{11} Q r_\\eta - 2 (g_{11} + g_{22}) r_{ij},
    \\qquad \\delta r = R / (2 (g_{11} + g_{22})),

keeps its tangential part by solving ``[E F; F G] (ds, dt) = (r_s . dr, r_t . dr)``
with the node's frozen tangents, and moves the node by ``omega (ds, dt)`` in the
parameters (at most :data:`LIMIT` of its distance to the nearest line whose crossing
would fold one of its four cells, so no move folds a cell; clipped to the domain) and by ``r_s ds + r_t dt`` in space (the
linearized surface; the caller evaluates the surface again every few sweeps).

``sweep`` is lexicographic SOR (compiled); ``sweep_numpy`` is the red-black form
of the same update, the reference and the fallback without numba. Both return
the largest unrelaxed tangential move in units of the local cell size
``sqrt((g11 + g22) / 2)``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..jit import AVAILABLE, jit

__all__ = ["LIMIT", "corner_jacobians", "folds", "numerators", "sor_relaxation", "sweep", "sweep_numpy",
           "tangential_residual"]

#: the kernel's stand-in for "no target" (an array of another shape: never read)
_NO_TARGET = np.zeros((1, 1, 3))

#: largest step of a node, as a fraction of its distance to the nearest line whose
#: crossing would fold one of its cells (:func:`_reach`)
LIMIT = 0.5


def corner_jacobians(s: NDArray, t: NDArray) -> NDArray:
    """Signed area of the four corner triangles of every cell of a 2-D grid.

    Parameters
    ----------
    s, t : (ni, nj) float

    Returns
    -------
    (4, ni - 1, nj - 1) float; all of one sign when no cell is folded.
    """
    p = np.stack([s, t], axis=-1)
    p00, p10, p01, p11 = p[:-1, :-1], p[1:, :-1], p[:-1, 1:], p[1:, 1:]

    def cross(o: NDArray, a: NDArray, b: NDArray) -> NDArray:
        u, v = a - o, b - o
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    return np.stack([cross(p00, p10, p01), cross(p10, p11, p00),
                     cross(p11, p01, p10), cross(p01, p00, p11)])



@jit
def _folds_kernel(s, t, sign):  # pragma: no cover - compiled
    ni, nj = s.shape
    for i in range(ni - 1):
        for j in range(nj - 1):
            ax = s[i + 1, j] - s[i, j]
            ay = t[i + 1, j] - t[i, j]
            bx = s[i, j + 1] - s[i, j]
            by = t[i, j + 1] - t[i, j]
            if sign * (ax * by - ay * bx) <= 0.0:
                return True
            cx = s[i + 1, j + 1] - s[i + 1, j]
            cy = t[i + 1, j + 1] - t[i + 1, j]
            if sign * (cx * (-ay) - cy * (-ax)) <= 0.0:
                return True
            dx = s[i, j + 1] - s[i + 1, j + 1]
            dy = t[i, j + 1] - t[i + 1, j + 1]
            if sign * (dx * (-cy) - dy * (-cx)) <= 0.0:
                return True
            if sign * ((-bx) * (-dy) - (-by) * (-dx)) <= 0.0:
                return True
    return False


def folds(s: NDArray, t: NDArray, sign: float) -> bool:
    """A corner of a cell of the grid ``s, t`` (ni, nj) is not of orientation ``sign`` (+1 or
    -1): :func:`corner_jacobians` ``* sign <= 0`` anywhere, stopping at the first."""
    if not AVAILABLE:                   # pragma: no cover - numba is installed in CI
        return bool(np.any(sign * corner_jacobians(s, t) <= 0.0))
    return bool(_folds_kernel(s, t, float(sign)))

@jit
def _line_distance(px, py, ax, ay, bx, by):  # pragma: no cover - compiled
    dx = bx - ax
    dy = by - ay
    n = np.sqrt(dx * dx + dy * dy)
    if n == 0.0:
        return np.sqrt((px - ax) ** 2 + (py - ay) ** 2)
    return abs((px - ax) * dy - (py - ay) * dx) / n


@jit
def _reach(s, t, i, j):  # pragma: no cover - compiled
    """Distance from node (i, j) to the nearest line that a fold would cross.

    For each cell ``(p, a, c, b)`` around the node ``p`` (``a``, ``b`` its edge
    neighbours, ``c`` the diagonal one) the corners at ``p``, ``a`` and ``b`` change
    sign when ``p`` crosses the line ``ab``, ``ac`` and ``bc`` respectively.
    """
    px = s[i, j]
    py = t[i, j]
    best = 1e300
    for di, dj in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        ax = s[i + di, j]
        ay = t[i + di, j]
        bx = s[i, j + dj]
        by = t[i, j + dj]
        cx = s[i + di, j + dj]
        cy = t[i + di, j + dj]
        best = min(best, _line_distance(px, py, ax, ay, bx, by),
                   _line_distance(px, py, ax, ay, cx, cy), _line_distance(px, py, bx, by, cx, cy))
    return best


@jit
def _metric(x, i, j):  # pragma: no cover - compiled
    """``g11, g22, g12`` of interior node (i, j) by central differences."""
    g11 = 0.0
    g22 = 0.0
    g12 = 0.0
    for k in range(3):
        a = 0.5 * (x[i + 1, j, k] - x[i - 1, j, k])
        b = 0.5 * (x[i, j + 1, k] - x[i, j - 1, k])
        g11 += a * a
        g22 += b * b
        g12 += a * b
    return g11, g22, g12


@jit
def _numerator(x, p, q, g11, g22, g12, i, j, k):  # pragma: no cover - compiled
    """Component ``k`` of the numerator ``R`` of interior node (i, j) (module doc)."""
    xi = 0.5 * (x[i + 1, j, k] - x[i - 1, j, k])
    eta = 0.5 * (x[i, j + 1, k] - x[i, j - 1, k])
    xe = 0.25 * (x[i + 1, j + 1, k] - x[i + 1, j - 1, k] - x[i - 1, j + 1, k] + x[i - 1, j - 1, k])
    return (g22 * (x[i + 1, j, k] + x[i - 1, j, k]) + g11 * (x[i, j + 1, k] + x[i, j - 1, k])
            - 2.0 * g12 * xe + g22 * p[i, j] * xi + g11 * q[i, j] * eta - 2.0 * (g11 + g22) * x[i, j, k])


@jit
def _sweep_kernel(s, t, x, rs, rt, p, q, target, omega, u0, u1, v0, v1):  # pragma: no cover - compiled
    ni, nj = s.shape
    has_target = target.shape[0] == ni
    worst = 0.0
    for i in range(1, ni - 1):
        for j in range(1, nj - 1):
            g11, g22, g12 = _metric(x, i, j)
            diag = 2.0 * (g11 + g22)
            if diag <= 0.0:
                continue
            e = 0.0
            f = 0.0
            gg = 0.0
            ar = 0.0
            at = 0.0
            for k in range(3):
                r = _numerator(x, p, q, g11, g22, g12, i, j, k)
                if has_target:
                    r -= target[i, j, k]
                r /= diag
                e += rs[i, j, k] * rs[i, j, k]
                f += rs[i, j, k] * rt[i, j, k]
                gg += rt[i, j, k] * rt[i, j, k]
                ar += rs[i, j, k] * r
                at += rt[i, j, k] * r
            det = e * gg - f * f
            if det <= 0.0:
                continue
            ds = (gg * ar - f * at) / det
            dt = (e * at - f * ar) / det
            move = np.sqrt(max(e * ds * ds + 2.0 * f * ds * dt + gg * dt * dt, 0.0))
            size = np.sqrt(0.5 * (g11 + g22))
            if size > 0.0 and move / size > worst:
                worst = move / size
            # the step stays within LIMIT of the distance to every line whose crossing
            # would fold a corner of the four cells around the node (none can fold)
            step = omega * np.sqrt(ds * ds + dt * dt)
            scale = omega
            reach = _reach(s, t, i, j)
            if step > LIMIT * reach:
                scale = omega * LIMIT * reach / step
            sn = min(max(s[i, j] + scale * ds, u0), u1)
            tn = min(max(t[i, j] + scale * dt, v0), v1)
            ds = sn - s[i, j]
            dt = tn - t[i, j]
            s[i, j] = sn
            t[i, j] = tn
            for k in range(3):
                x[i, j, k] += rs[i, j, k] * ds + rt[i, j, k] * dt
    return worst


def numerators(x: NDArray, p: NDArray, q: NDArray) -> tuple[NDArray, NDArray]:
    """The discrete operator of the system at the interior nodes of ``x`` (ni, nj, 3), before
    its division by the diagonal: ``R`` (ni - 2, nj - 2, 3) of the module doc (zero at a
    solution, up to its normal part) and the diagonal ``2 (g11 + g22)`` (ni - 2, nj - 2)."""
    c = (slice(1, -1), slice(1, -1))
    xi = 0.5 * (x[2:, 1:-1] - x[:-2, 1:-1])
    eta = 0.5 * (x[1:-1, 2:] - x[1:-1, :-2])
    xe = 0.25 * (x[2:, 2:] - x[2:, :-2] - x[:-2, 2:] + x[:-2, :-2])
    g11 = np.einsum("...k,...k->...", xi, xi)
    g22 = np.einsum("...k,...k->...", eta, eta)
    g12 = np.einsum("...k,...k->...", xi, eta)
    diag = 2.0 * (g11 + g22)
    r = (g22[..., None] * (x[2:, 1:-1] + x[:-2, 1:-1]) + g11[..., None] * (x[1:-1, 2:] + x[1:-1, :-2])
         - 2.0 * g12[..., None] * xe + (g22 * p[c])[..., None] * xi + (g11 * q[c])[..., None] * eta
         - diag[..., None] * x[c])
    return r, diag


@jit
def _tangential_kernel(x, rs, rt, p, q, target, out):  # pragma: no cover - compiled
    ni, nj = x.shape[0], x.shape[1]
    has_target = target.shape[0] == ni
    r = np.empty(3)
    for i in range(1, ni - 1):
        for j in range(1, nj - 1):
            g11, g22, g12 = _metric(x, i, j)
            for k in range(3):
                r[k] = _numerator(x, p, q, g11, g22, g12, i, j, k)
                if has_target:
                    r[k] -= target[i, j, k]
            n0 = rs[i, j, 1] * rt[i, j, 2] - rs[i, j, 2] * rt[i, j, 1]
            n1 = rs[i, j, 2] * rt[i, j, 0] - rs[i, j, 0] * rt[i, j, 2]
            n2 = rs[i, j, 0] * rt[i, j, 1] - rs[i, j, 1] * rt[i, j, 0]
            nn = n0 * n0 + n1 * n1 + n2 * n2
            c = (r[0] * n0 + r[1] * n1 + r[2] * n2) / nn if nn > 0.0 else 0.0
            out[i, j, 0] = r[0] - c * n0
            out[i, j, 1] = r[1] - c * n1
            out[i, j, 2] = r[2] - c * n2


def tangential_residual(x: NDArray, rs: NDArray, rt: NDArray, p: NDArray, q: NDArray,
                        target: NDArray | None = None) -> NDArray:
    """The tangential part (normal ``rs x rt``) of ``R - target`` at every node of ``x``
    (ni, nj, 3), :func:`numerators`' ``R``; zero on the boundary. (ni, nj, 3)."""
    out = np.zeros(x.shape)
    if AVAILABLE:
        _tangential_kernel(x, rs, rt, p, q, _NO_TARGET if target is None else target, out)
        return out
    r, _ = numerators(x, p, q)                           # pragma: no cover - numba is installed in CI
    if target is not None:
        r = r - target[1:-1, 1:-1]
    n = np.cross(rs[1:-1, 1:-1], rt[1:-1, 1:-1])
    nn = np.einsum("...k,...k->...", n, n)
    c = np.where(nn > 0, np.einsum("...k,...k->...", r, n) / np.where(nn > 0, nn, 1.0), 0.0)
    out[1:-1, 1:-1] = r - n * c[..., None]
    return out


def _moves(s, t, x, rs, rt, p, q, target=None):
    """Unrelaxed tangential moves ``(ds, dt)`` and their size in cells, on the interior."""
    c = (slice(1, -1), slice(1, -1))
    numerator, diag = numerators(x, p, q)
    if target is not None:
        numerator = numerator - target[c]
    g11_g22 = 0.5 * diag
    ok = diag > 0
    diag = np.where(ok, diag, 1.0)
    r = numerator / diag[..., None]
    a, b = rs[c], rt[c]
    e = np.einsum("...k,...k->...", a, a)
    f = np.einsum("...k,...k->...", a, b)
    gg = np.einsum("...k,...k->...", b, b)
    ar = np.einsum("...k,...k->...", a, r)
    at = np.einsum("...k,...k->...", b, r)
    det = e * gg - f * f
    ok &= det > 0
    det = np.where(ok, det, 1.0)
    ds = np.where(ok, (gg * ar - f * at) / det, 0.0)
    dt = np.where(ok, (e * at - f * ar) / det, 0.0)
    move = np.sqrt(np.maximum(e * ds * ds + 2.0 * f * ds * dt + gg * dt * dt, 0.0))
    size = np.sqrt(np.maximum(0.5 * g11_g22, 1e-300))
    return ds, dt, move / size


def _reach_numpy(s: NDArray, t: NDArray) -> NDArray:
    """:func:`_reach` of every interior node, ``(ni - 2, nj - 2)``."""
    p = np.stack([s, t], axis=-1)
    c = p[1:-1, 1:-1]
    ni, nj = s.shape

    def at(di: int, dj: int) -> NDArray:
        return p[1 + di:ni - 1 + di, 1 + dj:nj - 1 + dj]

    def distance(a: NDArray, b: NDArray) -> NDArray:
        d = b - a
        n = np.hypot(d[..., 0], d[..., 1])
        cross = np.abs((c[..., 0] - a[..., 0]) * d[..., 1] - (c[..., 1] - a[..., 1]) * d[..., 0])
        return np.where(n > 0, cross / np.where(n > 0, n, 1.0), np.hypot(*(c - a).transpose(2, 0, 1)))

    best = np.full(s.shape, np.inf)[1:-1, 1:-1]
    for di, dj in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        a, b, d = at(di, 0), at(0, dj), at(di, dj)
        best = np.minimum.reduce([best, distance(a, b), distance(a, d), distance(b, d)])
    return best


def sor_relaxation(n: int) -> float:
    """The SOR factor for a grid of ``n`` nodes along its longer side: Young's optimum for
    Laplace's equation, ``2 / (1 + sin(pi / n))``, at most 1.95 (the system is nonlinear)."""
    return min(1.95, 2.0 / (1.0 + math.sin(math.pi / n)))


def sweep_numpy(s: NDArray, t: NDArray, x: NDArray, rs: NDArray, rt: NDArray, p: NDArray, q: NDArray,
                omega: float, box: tuple[float, float, float, float], target: NDArray | None = None) -> float:
    """One red-black sweep in place (numpy); returns the largest move in cells.

    Parameters
    ----------
    s, t : (ni, nj) float
        The parameters of the nodes (updated in place; boundary untouched).
    x : (ni, nj, 3) float
        The nodes in space (updated in place by the linearized move).
    rs, rt : (ni, nj, 3) float
        Frozen tangents at the nodes.
    p, q : (ni, nj) float
        Control functions (the boundary values are not read).
    omega : float
        Relaxation.
    box : (u0, u1, v0, v1)
    target : (ni, nj, 3) float, optional
        Solve ``R = target`` instead of ``R = 0`` (a coarse level of :mod:`.multigrid`).
    """
    u0, u1, v0, v1 = box
    ni, nj = s.shape
    ii, jj = np.meshgrid(np.arange(1, ni - 1), np.arange(1, nj - 1), indexing="ij")
    worst = 0.0
    c = (slice(1, -1), slice(1, -1))
    for colour in (0, 1):
        mask = (ii + jj) % 2 == colour
        ds, dt, cells = _moves(s, t, x, rs, rt, p, q, target)
        worst = max(worst, float(cells[mask].max(initial=0.0)))
        sc, tc = s[c], t[c]
        reach = _reach_numpy(s, t)
        step = omega * np.hypot(ds, dt)
        limit = LIMIT * reach
        scale = np.where(step > limit, omega * limit / np.where(step > 0, step, 1.0), omega)
        sn = np.clip(sc + scale * ds, u0, u1)
        tn = np.clip(tc + scale * dt, v0, v1)
        ds, dt = np.where(mask, sn - sc, 0.0), np.where(mask, tn - tc, 0.0)
        sc += ds
        tc += dt
        x[c] += rs[c] * ds[..., None] + rt[c] * dt[..., None]
    return worst


def sweep(s: NDArray, t: NDArray, x: NDArray, rs: NDArray, rt: NDArray, p: NDArray, q: NDArray,
          omega: float, box: tuple[float, float, float, float], target: NDArray | None = None) -> float:
    """One SOR sweep in place (compiled lexicographic; :func:`sweep_numpy` without numba)."""
    if not AVAILABLE:                   # pragma: no cover - numba is installed in CI
        return sweep_numpy(s, t, x, rs, rt, p, q, omega, box, target)
    held = _NO_TARGET if target is None else target
    return float(_sweep_kernel(s, t, x, rs, rt, p, q, held, float(omega), *map(float, box)))
