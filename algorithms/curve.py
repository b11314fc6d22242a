"""The immutable NURBS curve type and its vectorized evaluation.

A curve of degree ``p`` with ``n`` control points ``P_i`` (rows of
``control_points``, any dimension: 3 for space curves, 2 for curves in a
surface's parameter domain), optional positive weights ``w_i`` and a full knot
vector ``t_0 <= ... <= t_{n+p}``:

.. math:: C(t) = \\frac{\\sum_i N_{i,p}(t)\\, w_i P_i}{\\sum_i N_{i,p}(t)\\, w_i},
          \\qquad t \\in [t_p, t_n].

Knot values are kept as given (never renormalized), so a round trip through
OpenCascade is exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from .basis import basis_derivatives, check_offset, check_weights, find_span, frozen_array, owned_array, validate_knots
from .rational import curve_derivatives_from_homogeneous

__all__ = ["NurbsCurve"]


@dataclass(frozen=True, eq=False)
class NurbsCurve:
    """A NURBS (or non-rational B-spline) curve.

    Parameters
    ----------
    control_points : (n, d) float
        Control points in Cartesian coordinates (not multiplied by the weights).
    knots : (n + degree + 1,) float
        Full, non-decreasing knot vector.
    degree : int
    weights : (n,) float, optional
        Positive weights; ``None`` for a non-rational curve.

    The arrays are copied and made read-only.
    """

    control_points: NDArray
    knots: NDArray
    degree: int
    weights: NDArray | None = None

    def __post_init__(self) -> None:
        cp = frozen_array(self.control_points)
        if cp.ndim != 2 or cp.shape[1] < 1:
            raise InvalidGeometryError(
                f"control_points must have shape (n, d), got {cp.shape}")
        if not np.all(np.isfinite(cp)):
            raise InvalidGeometryError("control_points contain NaN or infinite values")
        knots = frozen_array(validate_knots(self.knots, self.degree, cp.shape[0]))
        w = None if self.weights is None else frozen_array(self.weights)
        w = check_weights(w, (cp.shape[0],), "weights")
        object.__setattr__(self, "control_points", cp)
        object.__setattr__(self, "knots", knots)
        object.__setattr__(self, "degree", int(self.degree))
        object.__setattr__(self, "weights", w)

    @classmethod
    def construct_fast(cls, control_points: NDArray, knots: NDArray, degree: int,
                       weights: NDArray | None = None) -> NurbsCurve:
        """A curve from arrays known to be valid, without checking them.

        The trusted constructor for results of operations on valid curves (knot
        insertion, splitting, interpolants), as scipy's ``BSpline.construct_fast``:
        the shapes, the knot order, finiteness and the weights' signs are not
        checked. The arrays are taken as C-contiguous float arrays (copied only
        when they are not) and made read-only in place, so the caller must not
        keep writing to them. Users build curves with ``NurbsCurve(...)``.
        """
        self = object.__new__(cls)
        object.__setattr__(self, "control_points", owned_array(control_points))
        object.__setattr__(self, "knots", owned_array(knots))
        object.__setattr__(self, "degree", int(degree))
        object.__setattr__(self, "weights", None if weights is None else owned_array(weights))
        return self

    # ------------------------------------------------------------------ shape
    @property
    def n_control(self) -> int:
        """Number of control points."""
        return self.control_points.shape[0]

    @property
    def dimension(self) -> int:
        """Dimension of the space the curve lies in (2 or 3 in practice)."""
        return self.control_points.shape[1]

    @property
    def is_rational(self) -> bool:
        """True when the weights are not all equal (an equal-weight curve is polynomial)."""
        return self.weights is not None and bool(np.ptp(self.weights) > 0)

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter interval ``(t_p, t_n)``."""
        return float(self.knots[self.degree]), float(self.knots[self.n_control])

    def homogeneous_points(self) -> NDArray:
        """Control points as ``(w x, w y, ..., w)``: (n, d + 1) float."""
        w = np.ones(self.n_control) if self.weights is None else self.weights
        return np.concatenate([self.control_points * w[:, None], w[:, None]], axis=1)

    @classmethod
    def from_homogeneous(cls, points_w: ArrayLike, knots: ArrayLike, degree: int,
                         rational: bool = True) -> NurbsCurve:
        """Build from homogeneous control points ``(n, d + 1)`` (last column the weights)."""
        pw = np.asarray(points_w, dtype=float)
        w = pw[:, -1]
        if np.any(w <= 0):
            raise InvalidGeometryError("homogeneous weights must be > 0")
        return cls(pw[:, :-1] / w[:, None], knots, degree, w if rational else None)

    # ------------------------------------------------------------- evaluation
    def evaluate(self, t: ArrayLike) -> NDArray:
        """Points ``C(t)``.

        Parameters
        ----------
        t : (...) float

        Returns
        -------
        (..., d) float
        """
        return self.derivatives(t, 0)[..., 0, :]

    def derivatives(self, t: ArrayLike, order: int = 1) -> NDArray:
        """Derivatives ``C^{(k)}(t)``, ``k = 0..order``.

        Parameters
        ----------
        t : (...) float
        order : int >= 0

        Returns
        -------
        (..., order + 1, d) float
            ``[..., k, :]`` is the k-th derivative.
        """
        if order < 0:
            raise ValueError(f"order must be >= 0, got {order}")
        t = np.asarray(t, dtype=float)
        shape = t.shape
        p = self.degree
        span = find_span(self.knots, p, t.reshape(-1))
        ders, _ = basis_derivatives(self.knots, p, t.reshape(-1), order, span)
        idx = span[:, None] - p + np.arange(p + 1)                # (m, p+1)
        pw = self.homogeneous_points()[idx]                        # (m, p+1, d+1)
        hom = np.einsum("mkj,mjc->mkc", ders, pw)                  # (m, order+1, d+1)
        if self.weights is None:
            out = hom[..., :-1]
        else:
            out = curve_derivatives_from_homogeneous(hom[..., :-1], hom[..., -1])
        return out.reshape(shape + (order + 1, self.dimension))

    def __call__(self, t: ArrayLike) -> NDArray:
        return self.evaluate(t)

    # ------------------------------------------------- operations (facades)
    # Thin delegations to the algorithm modules, imported lazily (they import
    # this module).
    def insert_knot(self, t: float, r: int = 1) -> NurbsCurve:
        """Same curve with knot ``t`` inserted ``r`` times (:func:`.knots.insert_knot`)."""
        from .knots import insert_knot
        return insert_knot(self, t, r)

    def refine(self, new_knots: ArrayLike) -> NurbsCurve:
        """Same curve with all of ``new_knots`` inserted (:func:`.knots.refine`)."""
        from .knots import refine
        return refine(self, new_knots)

    def split(self, t: float) -> tuple[NurbsCurve, NurbsCurve]:
        """Pieces over ``[t0, t]`` and ``[t, t1]`` (:func:`.knots.split`)."""
        from .knots import split
        return split(self, t)

    def restrict(self, a: float, b: float) -> NurbsCurve:
        """Piece over ``[a, b]``, original parameters (:func:`.knots.restrict`)."""
        from .knots import restrict
        return restrict(self, a, b)

    def clamp(self) -> NurbsCurve:
        """Clamped form over the same domain (:func:`.knots.clamp`)."""
        from .knots import clamp
        return clamp(self)

    def elevate_degree(self, t: int = 1) -> NurbsCurve:
        """Same curve with degree ``p + t`` (:func:`.degree.elevate_degree`)."""
        from .degree import elevate_degree
        return elevate_degree(self, t)

    def bezier_segments(self) -> tuple[NDArray, NDArray]:
        """Homogeneous Bézier segments ``(k, p+1, d+1)`` and intervals ``(k, 2)``."""
        from .bezier import bezier_segments
        return bezier_segments(self)

    def bounding_box(self) -> NDArray:
        """Control-point bounding box ``(2, d)`` (:func:`.measure.bounding_box`)."""
        from .measure import bounding_box
        return bounding_box(self)

    def translated(self, offset: ArrayLike) -> NurbsCurve:
        """The same curve moved by ``offset`` ``(d,)``: control points shifted; knots,
        degree and weights kept (exact for rational curves too)."""
        return type(self).construct_fast(self.control_points + check_offset(offset, self.dimension),
                                         self.knots, self.degree, self.weights)

    def arc_length(self, t0: float | None = None, t1: float | None = None,
                   tol: float = 1e-12) -> float:
        """Length between ``t0`` and ``t1`` (:func:`.measure.arc_length`)."""
        from .measure import arc_length
        return arc_length(self, t0, t1, tol)

    def cumulative_arc_length(self, t: ArrayLike, tol: float = 1e-12) -> NDArray:
        """Length from the domain start to each of ``t`` (same shape as ``t``)."""
        from .measure import cumulative_arc_length
        return cumulative_arc_length(self, t, tol)

    def __repr__(self) -> str:
        kind = "rational" if self.weights is not None else "polynomial"
        return (f"NurbsCurve(degree={self.degree}, n_control={self.n_control}, "
                f"dimension={self.dimension}, {kind}, domain={self.domain})")
