"""The immutable NURBS surface type and its vectorized evaluation.

A tensor-product surface of degrees ``(p, q)`` with control net ``P_ij``
(``control_points[i, j]``), optional positive weights and full knot vectors
``knots_u``, ``knots_v``:

.. math:: S(u, v) = \\frac{\\sum_{i,j} N_{i,p}(u) N_{j,q}(v)\\, w_{ij} P_{ij}}
                          {\\sum_{i,j} N_{i,p}(u) N_{j,q}(v)\\, w_{ij}}.

Evaluation comes in two forms: on broadcast arrays of (u, v) pairs
(:meth:`NurbsSurface.evaluate`, :meth:`NurbsSurface.derivatives`) and on tensor
grids (:meth:`NurbsSurface.evaluate_grid`, :meth:`NurbsSurface.derivatives_grid`),
which evaluates each direction's basis once and contracts with BLAS.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from . import basis_kernels
from .basis import (
    basis_derivatives,
    check_offset,
    check_weights,
    find_span,
    frozen_array,
    owned_array,
    validate_knots,
)
from .jit import compiled
from .rational import surface_derivatives_from_homogeneous

__all__ = ["NurbsSurface"]


@dataclass(frozen=True, eq=False)
class NurbsSurface:
    """A NURBS (or non-rational B-spline) tensor-product surface.

    Parameters
    ----------
    control_points : (n_u, n_v, 3) float
        Control net in Cartesian coordinates.
    knots_u : (n_u + degree_u + 1,) float
    knots_v : (n_v + degree_v + 1,) float
    degree_u, degree_v : int
    weights : (n_u, n_v) float, optional
        Positive weights; ``None`` for a non-rational surface.

    The arrays are copied and made read-only.
    """

    control_points: NDArray
    knots_u: NDArray
    knots_v: NDArray
    degree_u: int
    degree_v: int
    weights: NDArray | None = None

    def __post_init__(self) -> None:
        cp = frozen_array(self.control_points)
        if cp.ndim != 3 or cp.shape[2] < 1:
            raise InvalidGeometryError(
                f"control_points must have shape (n_u, n_v, d), got {cp.shape}")
        if not np.all(np.isfinite(cp)):
            raise InvalidGeometryError("control_points contain NaN or infinite values")
        ku = frozen_array(validate_knots(self.knots_u, self.degree_u, cp.shape[0], "knots_u"))
        kv = frozen_array(validate_knots(self.knots_v, self.degree_v, cp.shape[1], "knots_v"))
        w = None if self.weights is None else frozen_array(self.weights)
        w = check_weights(w, cp.shape[:2], "weights")
        object.__setattr__(self, "control_points", cp)
        object.__setattr__(self, "knots_u", ku)
        object.__setattr__(self, "knots_v", kv)
        object.__setattr__(self, "degree_u", int(self.degree_u))
        object.__setattr__(self, "degree_v", int(self.degree_v))
        object.__setattr__(self, "weights", w)

    @classmethod
    def construct_fast(cls, control_points: NDArray, knots_u: NDArray, knots_v: NDArray,
                       degree_u: int, degree_v: int,
                       weights: NDArray | None = None) -> NurbsSurface:
        """A surface from arrays known to be valid, without checking them.

        The trusted constructor for results of operations on valid surfaces (knot
        insertion, restriction, degree elevation, interpolants), as scipy's
        ``BSpline.construct_fast``: nothing is checked, the arrays are taken as
        C-contiguous float arrays (copied only when they are not) and made
        read-only in place. Users build surfaces with ``NurbsSurface(...)``.
        """
        self = object.__new__(cls)
        object.__setattr__(self, "control_points", owned_array(control_points))
        object.__setattr__(self, "knots_u", owned_array(knots_u))
        object.__setattr__(self, "knots_v", owned_array(knots_v))
        object.__setattr__(self, "degree_u", int(degree_u))
        object.__setattr__(self, "degree_v", int(degree_v))
        object.__setattr__(self, "weights", None if weights is None else owned_array(weights))
        return self

    # ------------------------------------------------------------------ shape
    @property
    def n_control(self) -> tuple[int, int]:
        """Control net size ``(n_u, n_v)``."""
        return self.control_points.shape[0], self.control_points.shape[1]

    @property
    def dimension(self) -> int:
        return self.control_points.shape[2]

    @property
    def is_rational(self) -> bool:
        """True when the weights are not all equal."""
        return self.weights is not None and bool(np.ptp(self.weights) > 0)

    @property
    def domain(self) -> tuple[float, float, float, float]:
        """Parameter rectangle ``(u0, u1, v0, v1)``."""
        nu, nv = self.n_control
        return (float(self.knots_u[self.degree_u]), float(self.knots_u[nu]),
                float(self.knots_v[self.degree_v]), float(self.knots_v[nv]))

    def homogeneous_points(self) -> NDArray:
        """Control net as ``(w x, w y, w z, w)``: (n_u, n_v, d + 1) float."""
        w = np.ones(self.n_control) if self.weights is None else self.weights
        return np.concatenate([self.control_points * w[..., None], w[..., None]], axis=2)

    @functools.cached_property
    def homogeneous_net(self) -> NDArray:
        """:meth:`homogeneous_points` computed once per surface, read-only ``(n_u, n_v, d + 1)``
        (the evaluation kernels take it as is)."""
        return frozen_array(self.homogeneous_points())

    @classmethod
    def from_homogeneous(cls, points_w: ArrayLike, knots_u: ArrayLike, knots_v: ArrayLike,
                         degree_u: int, degree_v: int, rational: bool = True) -> NurbsSurface:
        """Build from a homogeneous net ``(n_u, n_v, d + 1)`` (last channel the weights)."""
        pw = np.asarray(points_w, dtype=float)
        w = pw[..., -1]
        if np.any(w <= 0):
            raise InvalidGeometryError("homogeneous weights must be > 0")
        return cls(pw[..., :-1] / w[..., None], knots_u, knots_v, degree_u, degree_v,
                   w if rational else None)

    # ------------------------------------------------------- scattered points
    def evaluate(self, u: ArrayLike, v: ArrayLike) -> NDArray:
        """Points ``S(u, v)`` for broadcast arrays ``u``, ``v``.

        Returns
        -------
        (..., d) float, ``...`` the broadcast shape of ``u`` and ``v``.
        """
        return self.derivatives(u, v, 0)[..., 0, 0, :]

    def derivatives(self, u: ArrayLike, v: ArrayLike, order: int = 1) -> NDArray:
        """Partial derivatives ``d^{k+l} S / du^k dv^l`` for ``k, l = 0..order``.

        Parameters
        ----------
        u, v : (...) float, broadcast together
        order : int >= 0

        Returns
        -------
        (..., order + 1, order + 1, d) float
            ``[..., k, l, :]`` is the k-th u- and l-th v-derivative.
        """
        if order < 0:
            raise ValueError(f"order must be >= 0, got {order}")
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        shape = u.shape
        u, v = u.reshape(-1), v.reshape(-1)
        p, q = self.degree_u, self.degree_v
        su = find_span(self.knots_u, p, u)
        sv = find_span(self.knots_v, q, v)
        net = self.homogeneous_net
        if compiled(u.size * (p + 1) * (q + 1) * (order + 1)):   # the same sums, compiled
            out = basis_kernels.surface_derivatives_compiled(
                self.knots_u, self.knots_v, p, q, net, u, v, su, sv, order,
                self.weights is not None)
            return out.reshape(shape + out.shape[1:])
        du, _ = basis_derivatives(self.knots_u, p, u, order, su)    # (m, o+1, p+1)
        dv, _ = basis_derivatives(self.knots_v, q, v, order, sv)    # (m, o+1, q+1)
        iu = su[:, None] - p + np.arange(p + 1)
        iv = sv[:, None] - q + np.arange(q + 1)
        flat = iu[:, :, None] * net.shape[1] + iv[:, None, :]             # (m, p+1, q+1)
        pw = np.take(net.reshape(-1, net.shape[2]), flat, axis=0)        # (m, p+1, q+1, d+1)
        # hom[m, k, l, c] = sum_ij du[m, k, i] dv[m, l, j] pw[m, i, j, c] as two batched
        # matmuls (no einsum path search per call; same sums in the same order)
        m, c = u.size, pw.shape[3]
        tmp = np.matmul(du, pw.reshape(m, p + 1, (q + 1) * c)).reshape(m, du.shape[1], q + 1, c)
        hom = np.matmul(dv[:, None], tmp)                                 # (m, o+1, o+1, d+1)
        out = self._project(hom)
        return out.reshape(shape + out.shape[1:])

    # ------------------------------------------------------------ tensor grid
    def evaluate_grid(self, u: ArrayLike, v: ArrayLike) -> NDArray:
        """Points on the tensor grid ``u x v``.

        Parameters
        ----------
        u : (a,) float
        v : (b,) float

        Returns
        -------
        (a, b, d) float
        """
        return self.derivatives_grid(u, v, 0)[:, :, 0, 0, :]

    def derivatives_grid(self, u: ArrayLike, v: ArrayLike, order: int = 1) -> NDArray:
        """Partial derivatives on the tensor grid ``u x v``.

        The basis of each direction is evaluated once, then contracted with the
        control net span by span, so the cost is about ``(p+1)(q+1)`` multiply-adds
        per grid point and derivative.

        Returns
        -------
        (a, b, order + 1, order + 1, d) float
        """
        if order < 0:
            raise ValueError(f"order must be >= 0, got {order}")
        u = np.asarray(u, dtype=float).reshape(-1)
        v = np.asarray(v, dtype=float).reshape(-1)
        p, q = self.degree_u, self.degree_v
        # one vectorized call per direction: no kernel (nor numba) needed for a grid
        du, su = basis_derivatives(self.knots_u, p, u, order, compiled=False)  # (a, o+1, p+1)
        dv, sv = basis_derivatives(self.knots_v, q, v, order, compiled=False)  # (b, o+1, q+1)
        iu = su[:, None] - p + np.arange(p + 1)                    # (a, p+1)
        pw = self.homogeneous_net
        # contract u first: (a, o+1, n_v, d+1)
        tmp = np.einsum("aki,aijc->akjc", du, pw[iu], optimize=True)
        iv = sv[:, None] - q + np.arange(q + 1)                    # (b, q+1)
        hom = np.einsum("blj,akbjc->abklc", dv, tmp[:, :, iv], optimize=True)
        a, b = u.size, v.size
        out = self._project(hom.reshape((a * b,) + hom.shape[2:]))
        return out.reshape((a, b) + out.shape[1:])

    def _project(self, hom: NDArray) -> NDArray:
        """Homogeneous derivatives (m, o+1, o+1, d+1) to Cartesian ones."""
        if self.weights is None:
            return hom[..., :-1]
        return surface_derivatives_from_homogeneous(hom[..., :-1], hom[..., -1])

    def __call__(self, u: ArrayLike, v: ArrayLike) -> NDArray:
        return self.evaluate(u, v)

    # ------------------------------------------------- operations (facades)
    # Thin delegations to the algorithm modules, imported lazily (they import
    # this module). ``direction`` is a ``tensor.Direction`` (or "u"/"v").
    def insert_knot(self, value: float, direction, r: int = 1) -> NurbsSurface:
        """Same surface with ``value`` inserted ``r`` times in ``direction``."""
        from .knots import insert_knot_surface
        return insert_knot_surface(self, value, direction, r)

    def refine(self, new_knots: ArrayLike, direction) -> NurbsSurface:
        """Same surface with all of ``new_knots`` inserted in ``direction``."""
        from .knots import refine_surface
        return refine_surface(self, new_knots, direction)

    def split(self, value: float, direction) -> tuple[NurbsSurface, NurbsSurface]:
        """Two patches split at ``direction = value`` (:func:`.knots.split_surface`)."""
        from .knots import split_surface
        return split_surface(self, value, direction)

    def restrict(self, u0: float | None = None, u1: float | None = None,
                 v0: float | None = None, v1: float | None = None) -> NurbsSurface:
        """Patch over ``[u0, u1] x [v0, v1]``, original parameters."""
        from .knots import restrict_surface
        return restrict_surface(self, u0, u1, v0, v1)

    def clamp(self) -> NurbsSurface:
        """Clamped form in both directions over the same domain."""
        from .knots import clamp_surface
        return clamp_surface(self)

    def elevate_degree(self, t_u: int = 0, t_v: int = 0) -> NurbsSurface:
        """Same surface with degrees ``(p + t_u, q + t_v)``."""
        from .degree import elevate_degree_surface
        return elevate_degree_surface(self, t_u, t_v)

    def bezier_patches(self) -> tuple[NDArray, NDArray, NDArray]:
        """Homogeneous patches ``(ku, kv, p+1, q+1, d+1)`` and their u, v intervals."""
        from .bezier import bezier_patches
        return bezier_patches(self)

    def patch_bounding_boxes(self) -> tuple[NDArray, NDArray, NDArray]:
        """Control-net box ``(ku, kv, 2, d)`` of every Bézier patch, with intervals."""
        from .bezier import patch_bounding_boxes
        return patch_bounding_boxes(self)

    def bounding_box(self) -> NDArray:
        """Control-net bounding box ``(2, d)``."""
        from .measure import bounding_box
        return bounding_box(self)

    def translated(self, offset: ArrayLike) -> NurbsSurface:
        """The same surface moved by ``offset`` ``(d,)``: control points shifted; knots,
        degrees and weights kept (exact for rational surfaces too, as a NURBS is
        affinely invariant). Algorithms work on a far-off surface moved to its own box
        centre, where coordinates keep their low bits."""
        return type(self).construct_fast(self.control_points + check_offset(offset, self.dimension),
                                         self.knots_u, self.knots_v, self.degree_u,
                                         self.degree_v, self.weights)

    def normals(self, u: ArrayLike, v: ArrayLike) -> NDArray:
        """Unit normals ``(..., 3)``, limit direction at degenerate points."""
        from .measure import normals
        return normals(self, u, v)

    def isocurve(self, value: float, direction):
        """Exact isoparametric curve (:func:`.isocurve.isocurve`).

        ``Direction.U``: the curve ``u = value`` running in v (OpenCascade's
        ``UIso``); ``Direction.V``: the curve ``v = value`` running in u.
        """
        from .isocurve import isocurve
        return isocurve(self, value, direction)

    def __repr__(self) -> str:
        kind = "rational" if self.weights is not None else "polynomial"
        return (f"NurbsSurface(degree=({self.degree_u}, {self.degree_v}), "
                f"n_control={self.n_control}, {kind}, domain={self.domain})")

