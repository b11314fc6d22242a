"""Orthogonal projection of points of one surface onto another (002 eqs. 3-4, §6.2).

The foot ``Q = q(s, t)`` of a point ``r`` on the surface ``q`` solves

.. math:: (r - q(s, t)) \\cdot q_s = 0, \\qquad (r - q(s, t)) \\cdot q_t = 0
          \\qquad (3), (4)

by Newton's method: the Jacobian of the left-hand sides with respect to
``(s, t)`` is ``-K`` with ``K_ij = q_i . q_j - (r - q) . q_ij`` (eq. 22), so the
step is ``K^{-1} F``. Where ``K`` is not positive definite (the foot is not a
local minimum of the distance) the Gauss-Newton step ``(J^T J)^{-1} F`` is
taken instead.

§6.2 distinguishes three cases, reported per point by :class:`ProjectionStatus`:

* ``UNIQUE``: the projection exists, converged, and ``K`` is positive definite
  (a strict local minimum of the distance: the regular case);
* ``MULTIPLE``: ``K`` is not positive definite at the foot (``det K <= 0``, or
  both eigenvalues negative: the point lies on or beyond a focal
  point of ``q``: several projections meet there and ``K^{-1}`` does not exist;
  [15] checks for a sign change of ``det K`` along a traced curve, which
  :mod:`.curves` does);
* ``NONE``: the foot leaves ``q``'s parameter domain (or Newton does not
  converge): the point has no orthogonal projection on the finite patch. The
  foot found on the polynomial extension of the end spans is kept, so a caller
  can record where the boundary was crossed.

Start values come from the caller (continuation along a traced curve) or from
the nearest sample of a grid over ``q`` (:class:`Projector` caches it). A
parallelogram ``q`` (degree 1 x 1, four non-rational control points with
``p00 + p11 = p01 + p10``: every plane OpenCascade hands over) is affine in
``(s, t)``: its foot is the solution of one 2 x 2 linear system (eqs. 3-4 are
linear there), no Newton and no seed grid.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from . import distance_kernels
from .evaluator import PatchEvaluator

__all__ = [
    "EXTENSION",
    "GRID_SAMPLES",
    "Projection",
    "ProjectionStatus",
    "Projector",
    "projection_matrix",
]

#: samples per direction of the seed grid (at least; more for many knot spans)
GRID_SAMPLES = 33
#: Newton may run this share of the domain beyond its sides (polynomial extension)
EXTENSION = 0.05


class ProjectionStatus(enum.IntEnum):
    """The three cases of §6.2 for one point."""

    UNIQUE = 0
    MULTIPLE = 1
    NONE = 2


@dataclass(frozen=True)
class Projection:
    """Feet of ``n`` points on ``q``.

    Attributes
    ----------
    st : (n, 2) float
        Foot parameters (on the extension of ``q`` where ``status`` is NONE).
    foot : (n, 3) float
    status : (n,) int
        :class:`ProjectionStatus` values.
    det_k : (n,) float
        ``det K`` at the foot (eq. 22).
    """

    st: NDArray
    foot: NDArray
    status: NDArray
    det_k: NDArray

    @property
    def regular(self) -> NDArray:
        """``(n,) bool``: the UNIQUE case."""
        return self.status == ProjectionStatus.UNIQUE


def _dot(a: NDArray, b: NDArray) -> NDArray:
    return np.einsum("...i,...i->...", a, b)


def projection_matrix(offset: NDArray, qd: NDArray) -> NDArray:
    """``K (n, 2, 2)`` of eq. (22): ``K_ij = q_i . q_j - (r - q) . q_ij``.

    Parameters
    ----------
    offset : (n, 3) float
        ``r - q``.
    qd : (n, 3, 3, 3) float
        ``q.derivatives(s, t, 2)``.
    """
    qs, qt = qd[:, 1, 0], qd[:, 0, 1]
    k00 = _dot(qs, qs) - _dot(offset, qd[:, 2, 0])
    k01 = _dot(qs, qt) - _dot(offset, qd[:, 1, 1])
    k11 = _dot(qt, qt) - _dot(offset, qd[:, 0, 2])
    return np.stack([np.stack([k00, k01], -1), np.stack([k01, k11], -1)], -2)


def _affine_frame(surface: NurbsSurface) -> tuple[NDArray, NDArray, NDArray, NDArray] | None:
    """``(p0, q_s, q_t, Gram matrix)`` of a parallelogram ``surface``, or None."""
    if (surface.degree_u, surface.degree_v) != (1, 1) or tuple(surface.n_control) != (2, 2):
        return None
    if surface.weights is not None and np.ptp(surface.weights) > 1e-14 * np.abs(
            surface.weights).max():
        return None
    p = surface.control_points
    size = max(float(np.ptp(p.reshape(-1, 3), axis=0).max()), 1e-300)
    if np.abs(p[0, 0] + p[1, 1] - p[0, 1] - p[1, 0]).max() > 1e-14 * size:
        return None
    d = surface.domain
    qs = (p[1, 0] - p[0, 0]) / (d[1] - d[0])
    qt = (p[0, 1] - p[0, 0]) / (d[3] - d[2])
    gram = np.array([[qs @ qs, qs @ qt], [qs @ qt, qt @ qt]])
    if np.linalg.det(gram) <= 1e-12 * np.trace(gram) ** 2:
        return None
    return p[0, 0].astype(float), qs, qt, gram


@dataclass(frozen=True, eq=False)
class Projector:
    """Orthogonal projection onto one surface, with a cached seed grid.

    Parameters
    ----------
    surface : NurbsSurface
        ``q``, in 3D.
    tol : float
        Model units: Newton stops when the step moves the foot by less than this.
    max_iter : int
        Newton iterations at most (a cap: never a hang).
    """

    surface: NurbsSurface
    tol: float
    max_iter: int = 30
    _grid: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.surface, NurbsSurface) or self.surface.dimension != 3:
            raise InvalidGeometryError("projection needs a NurbsSurface in 3D")
        object.__setattr__(self, "tol", check_tolerance(self.tol))
        self._grid["evaluator"] = PatchEvaluator(self.surface)
        self._grid["affine"] = _affine_frame(self.surface)
        d = self.surface.domain
        self._grid["lower"] = np.array([d[0], d[2]])
        self._grid["upper"] = np.array([d[1], d[3]])

    @property
    def is_affine(self) -> bool:
        """True when ``q`` is a parallelogram (projection in closed form)."""
        return self._grid["affine"] is not None

    @property
    def evaluator(self) -> PatchEvaluator:
        return self._grid["evaluator"]

    # ------------------------------------------------------------ domain
    @property
    def lower(self) -> NDArray:
        return self._grid["lower"]

    @property
    def upper(self) -> NDArray:
        return self._grid["upper"]

    def inside(self, st: NDArray, rel: float = 1e-9) -> NDArray:
        """``(n,) bool``: ``st (n, 2)`` within the domain (``rel`` of its size)."""
        eps = rel * (self.upper - self.lower)
        return np.all((st >= self.lower - eps) & (st <= self.upper + eps), axis=-1)

    # ------------------------------------------------------------ seeds
    def _seed_grid(self) -> tuple[NDArray, NDArray, cKDTree]:
        if "tree" not in self._grid:
            s = self.surface
            counts = []
            for knots, degree in ((s.knots_u, s.degree_u), (s.knots_v, s.degree_v)):
                spans = np.unique(knots[degree:knots.size - degree]).size - 1
                counts.append(max(GRID_SAMPLES, 4 * spans + 1))
            su = np.linspace(self.lower[0], self.upper[0], counts[0])
            sv = np.linspace(self.lower[1], self.upper[1], counts[1])
            pts = s.evaluate_grid(su, sv).reshape(-1, 3)
            params = np.stack(np.meshgrid(su, sv, indexing="ij"), -1).reshape(-1, 2)
            self._grid.update(params=params, points=pts, tree=cKDTree(pts))
        return self._grid["params"], self._grid["points"], self._grid["tree"]

    def seeds(self, points: NDArray) -> NDArray:
        """``(n, 2)`` parameters of the nearest grid sample to each of ``points (n, 3)``."""
        params, _, tree = self._seed_grid()
        _, idx = tree.query(points)
        return params[idx]

    def _project_affine(self, x: NDArray) -> tuple[Projection, NDArray]:
        """Feet on a parallelogram ``q``: ``G (s, t) = [q_s . (x - p0), q_t . (x - p0)]``
        (eqs. 3-4 with ``q_st = 0``; ``K = G`` is the constant Gram matrix)."""
        origin, qs, qt, gram = self._grid["affine"]
        off = x - origin
        rhs = np.stack([off @ qs, off @ qt], -1)
        st = np.linalg.solve(gram, rhs.T).T + self.lower
        span = self.upper - self.lower
        st = np.clip(st, self.lower - EXTENSION * span, self.upper + EXTENSION * span)
        d = st - self.lower
        qd = np.zeros((x.shape[0], 3, 3, 3))
        qd[:, 0, 0] = origin + d[:, :1] * qs + d[:, 1:] * qt
        qd[:, 1, 0], qd[:, 0, 1] = qs, qt
        status = np.where(self.inside(st), int(ProjectionStatus.UNIQUE),
                          int(ProjectionStatus.NONE)).astype(np.int8)
        det = np.full(x.shape[0], float(np.linalg.det(gram)))
        return Projection(st, qd[:, 0, 0], status, det), qd

    # ------------------------------------------------------------ Newton
    def project(self, points: ArrayLike, st0: ArrayLike | None = None) -> Projection:
        """Feet of ``points (n, 3)`` by Newton on eqs. (3)-(4), from ``st0 (n, 2)``
        (default: :meth:`seeds`)."""
        return self.project_with_derivatives(points, st0)[0]

    def project_with_derivatives(self, points: ArrayLike, st0: ArrayLike | None = None
                                 ) -> tuple[Projection, NDArray]:
        """:meth:`project` and ``q``'s derivatives at the feet ``(n, 3, 3, 3)``."""
        ev = self.evaluator
        x = np.asarray(points, dtype=float).reshape(-1, 3)
        if self.is_affine:
            return self._project_affine(x)
        st = self.seeds(x) if st0 is None else np.array(st0, dtype=float).reshape(-1, 2)
        span = self.upper - self.lower
        lo, hi = self.lower - EXTENSION * span, self.upper + EXTENSION * span
        if distance_kernels.AVAILABLE:
            st, qd, moved, before = distance_kernels.project_points(
                *ev.compiled, x, np.ascontiguousarray(st), lo, hi, 0.25 * span,
                float(self.tol), int(self.max_iter))
            return self._finish(x, st, qd, moved, before)
        st = np.clip(st, lo, hi)
        moved = np.full(x.shape[0], np.inf)
        before = np.full(x.shape[0], np.inf)
        active = np.arange(x.shape[0])
        quarter = 0.25 * span
        for _ in range(self.max_iter):
            if active.size == 0:
                break
            # one Newton step per active point, written on components (few small
            # array operations: this loop runs for every jet of the tracers)
            sa = st[active]
            qd = ev.derivatives(sa[:, 0], sa[:, 1], 2)
            off = x[active] - qd[:, 0, 0]
            qs, qt = qd[:, 1, 0], qd[:, 0, 1]
            f0, f1 = _dot(off, qs), _dot(off, qt)
            ss, st_, tt = _dot(qs, qs), _dot(qs, qt), _dot(qt, qt)
            k00 = ss - _dot(off, qd[:, 2, 0])                               # eq. (22)
            k01 = st_ - _dot(off, qd[:, 1, 1])
            k11 = tt - _dot(off, qd[:, 0, 2])
            good = (k00 * k11 - k01 ** 2 > 0) & (k00 > 0)
            m00, m01, m11 = np.where(good, k00, ss), np.where(good, k01, st_), \
                np.where(good, k11, tt)
            mdet = m00 * m11 - m01 ** 2
            mdet = np.where(np.abs(mdet) > 1e-300, mdet, 1e-300)
            step = np.stack([m11 * f0 - m01 * f1, m00 * f1 - m01 * f0], -1) / mdet[:, None]
            # a coordinate held at a side of the clip box while the step pushes it out:
            # Newton in the other one alone (as the compiled kernel)
            held = ((sa >= hi) & (step > 0)) | ((sa <= lo) & (step < 0))
            alone = np.stack([f0 / np.maximum(m00, 1e-300), f1 / np.maximum(m11, 1e-300)], -1)
            step = np.where(held[:, ::-1] & ~held, alone, step)
            step[held] = 0.0
            # limit a step to a quarter of the domain (far seeds must not jump around)
            scale = np.max(np.abs(step) / quarter, axis=1)
            step /= np.maximum(scale, 1.0)[:, None]
            new = np.clip(sa + step, lo, hi)
            d = new - sa
            before[active] = moved[active]
            m = np.linalg.norm(qs * d[:, :1] + qt * d[:, 1:], axis=1)
            moved[active] = m
            st[active] = new
            # quadratic convergence: the next step would move about moved^3 / before^2
            b = before[active]
            nxt = np.where((m < b) & np.isfinite(b), m ** 3 / np.maximum(b, 1e-300) ** 2, np.inf)
            active = active[(m > self.tol) & (nxt > self.tol)]
        return self._finish(x, st, ev.derivatives(st[:, 0], st[:, 1], 2), moved, before)

    def _finish(self, x: NDArray, st: NDArray, qd: NDArray, moved: NDArray, before: NDArray
                ) -> tuple[Projection, NDArray]:
        """The §6.2 case of every foot from the last Newton moves."""
        k = projection_matrix(x - qd[:, 0, 0], qd)
        status, det = self.status(st, k, moved, before)
        return Projection(st, qd[:, 0, 0], status, det), qd

    def status(self, st: NDArray, k: NDArray, moved: NDArray, before: NDArray
               ) -> tuple[NDArray, NDArray]:
        """``(status (n,) int8, det K (n,))`` of feet ``st (n, 2)`` with ``K (n, 2, 2)``
        (eq. 22) and the last two Newton moves of each (§6.2 cases)."""
        det = k[:, 0, 0] * k[:, 1, 1] - k[:, 0, 1] ** 2
        status = np.full(st.shape[0], int(ProjectionStatus.UNIQUE), dtype=np.int8)
        scale = (k[:, 0, 0] + k[:, 1, 1]) ** 2
        status[(det <= 1e-12 * scale) | (k[:, 0, 0] <= 0)] = ProjectionStatus.MULTIPLE
        lost = (moved > 10 * self.tol) & ~((moved < before) & np.isfinite(before)
                                            & (moved ** 3 / np.maximum(before, 1e-300) ** 2 <= self.tol))
        status[~self.inside(st) | lost] = ProjectionStatus.NONE
        return status, det

    def kernel_frame(self) -> NDArray:
        """``(5, 3)`` float for :mod:`.distance_kernels`: a parallelogram's ``p0, q_s, q_t``, the
        inverse Gram matrix ``(g00, g01, g11)`` and ``(1, 0, 0)``; zeros otherwise."""
        if "frame" not in self._grid:
            frame = np.zeros((5, 3))
            if self.is_affine:
                origin, qs, qt, gram = self._grid["affine"]
                inv = np.linalg.inv(gram)
                frame[:3] = origin, qs, qt
                frame[3] = inv[0, 0], inv[0, 1], inv[1, 1]
                frame[4, 0] = 1.0
            self._grid["frame"] = frame
        return self._grid["frame"]

    def newton_bounds(self) -> tuple[NDArray, NDArray, NDArray]:
        """``(lo, hi, quarter)``: Newton's clip box (domain and extension) and step limit."""
        if "bounds" not in self._grid:
            span = self.upper - self.lower
            self._grid["bounds"] = (self.lower - EXTENSION * span, self.upper + EXTENSION * span,
                                    0.25 * span)
        return self._grid["bounds"]
