"""The immutable trivariate NURBS solid type and its vectorized evaluation (004 §3).

A tensor-product solid of degrees ``(p, q, r)`` with control net ``P_ijk``
(``control_points[i, j, k]``), optional positive weights and full knot vectors
``knots_u``, ``knots_v``, ``knots_w`` (004 eqs. 3.1-3.2):

.. math:: P(u, v, w) = \\frac{\\sum_{i,j,k} N_{i,p}(u) N_{j,q}(v) N_{k,r}(w)\\, w_{ijk} P_{ijk}}
                            {\\sum_{i,j,k} N_{i,p}(u) N_{j,q}(v) N_{k,r}(w)\\, w_{ijk}}.

As for :class:`~.surface.NurbsSurface`, evaluation runs in homogeneous coordinates
``(w x, w y, w z, w)`` on broadcast arrays of ``(u, v, w)`` triples
(:meth:`NurbsVolume.evaluate`, :meth:`NurbsVolume.derivatives`) or on tensor grids
(:meth:`NurbsVolume.evaluate_grid`, one basis evaluation per direction contracted
with the net), and rational derivatives follow from the homogeneous ones by the
quotient rule (eq. 4.20 of [PT] with a third index). Operations along one direction
(knot insertion, refinement, restriction, degree elevation, isosurfaces) are the
curve operations of :mod:`.knots` and :mod:`.degree` applied to the net with that
direction on axis 0. The six boundary surfaces of 004 eq. 3.3 are
:meth:`NurbsVolume.boundary`; measures (volume, collapsed faces, point inversion)
are in :mod:`.volume_measure`.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass
from math import comb

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from .basis import (
    basis_derivatives,
    basis_functions,
    check_offset,
    check_weights,
    find_span,
    frozen_array,
    owned_array,
    validate_knots,
)
from .bezier import bezier_decompose_array
from .degree import elevate_degree_array
from .knots import insert_knot_array, refine_knots_array, restrict_array
from .surface import NurbsSurface
from .tensor import Direction, check_in_domain, check_parameter, domain_of
from .volume_measure import VolumeInversion, collapsed_faces, exterior_faces, invert_points, solid_volume

__all__ = ["AXES", "FACES", "BezierVolumes", "NurbsVolume", "as_axis", "rational_derivatives"]

#: the names of the three parametric directions, in axis order
AXES = ("u", "v", "w")
#: the six boundary faces of 004 eq. 3.3, ``"u0"`` the face ``u = u_min``
FACES = ("u0", "u1", "v0", "v1", "w0", "w1")
#: points evaluated per batch (bounds the ``(m, p+1, q+1, r+1, d+1)`` gather)
_CHUNK = 1 << 15


def as_axis(direction: str | int | Direction) -> int:
    """Axis ``0, 1, 2`` of ``"u"``/``"v"``/``"w"`` (any case), ``0``/``1``/``2`` or
    ``Direction.U``/``Direction.V``; :class:`InvalidGeometryError` otherwise."""
    if isinstance(direction, Direction):
        return direction.value
    if isinstance(direction, str) and direction.lower() in AXES:
        return AXES.index(direction.lower())
    if isinstance(direction, (int, np.integer)) and not isinstance(direction, bool) \
            and int(direction) in (0, 1, 2):
        return int(direction)
    raise InvalidGeometryError(f"direction must be 'u', 'v' or 'w', got {direction!r}")


@dataclass(frozen=True, eq=False)
class BezierVolumes:
    """The Bézier decomposition of a solid (004 §4.1 applied to the trivariate net).

    Attributes
    ----------
    pieces : (ku, kv, kw, p + 1, q + 1, r + 1, d + 1) float
        Homogeneous Bernstein coefficients ``(w x, ..., w)`` of span ``(i, j, k)``.
    intervals_u, intervals_v, intervals_w : (ku, 2), (kv, 2), (kw, 2) float
        Piece ``(i, j, k)`` covers ``intervals_u[i] x intervals_v[j] x intervals_w[k]``.
    boxes : (ku, kv, kw, 2, d) float
        Control-net box of every piece (``[min corner, max corner]``): with positive
        weights the piece lies inside it (convex hull property).
    degrees : (int, int, int)
    rational : bool
        The solid had weights (the pieces are rebuilt with them by :meth:`piece`).
    """

    pieces: NDArray
    intervals_u: NDArray
    intervals_v: NDArray
    intervals_w: NDArray
    boxes: NDArray
    degrees: tuple[int, int, int]
    rational: bool

    @property
    def shape(self) -> tuple[int, int, int]:
        """Number of spans ``(ku, kv, kw)``."""
        return self.pieces.shape[:3]

    def piece(self, i: int, j: int, k: int) -> NurbsVolume:
        """Span ``(i, j, k)`` as a single-span clamped :class:`NurbsVolume`."""
        knots = [np.repeat(iv, deg + 1) for iv, deg in
                 zip((self.intervals_u[i], self.intervals_v[j], self.intervals_w[k]), self.degrees)]
        return NurbsVolume.from_homogeneous(self.pieces[i, j, k], *knots, *self.degrees,
                                            rational=self.rational)


@dataclass(frozen=True, eq=False)
class NurbsVolume:
    """A trivariate NURBS (or non-rational B-spline) solid, 004 eqs. 3.1-3.2.

    Parameters
    ----------
    control_points : (n_u, n_v, n_w, d) float
        Control net in Cartesian coordinates (not multiplied by the weights).
    knots_u : (n_u + degree_u + 1,) float
    knots_v : (n_v + degree_v + 1,) float
    knots_w : (n_w + degree_w + 1,) float
        Full, non-decreasing knot vectors, clamped or not; values kept as given.
    degree_u, degree_v, degree_w : int >= 1
    weights : (n_u, n_v, n_w) float, optional
        Positive weights; ``None`` for a non-rational solid.

    The arrays are copied and made read-only.

    Examples
    --------
    >>> import numpy as np
    >>> corners = np.stack(np.meshgrid([0, 2.0], [0, 1.0], [0, 3.0], indexing="ij"), -1)
    >>> box = NurbsVolume(corners, [0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1], 1, 1, 1)
    >>> box.evaluate(0.5, 0.5, 0.5), round(box.volume(), 12)
    (array([1. , 0.5, 1.5]), 6.0)
    """

    control_points: NDArray
    knots_u: NDArray
    knots_v: NDArray
    knots_w: NDArray
    degree_u: int
    degree_v: int
    degree_w: int
    weights: NDArray | None = None

    def __post_init__(self) -> None:
        cp = frozen_array(self.control_points)
        if cp.ndim != 4 or cp.shape[3] < 1:
            raise InvalidGeometryError(
                f"control_points must have shape (n_u, n_v, n_w, d), got {cp.shape}")
        if not np.all(np.isfinite(cp)):
            raise InvalidGeometryError("control_points contain NaN or infinite values")
        knots = [frozen_array(validate_knots(k, deg, n, name)) for k, deg, n, name in
                 zip((self.knots_u, self.knots_v, self.knots_w),
                     (self.degree_u, self.degree_v, self.degree_w), cp.shape[:3],
                     ("knots_u", "knots_v", "knots_w"))]
        w = None if self.weights is None else frozen_array(self.weights)
        w = check_weights(w, cp.shape[:3], "weights")
        object.__setattr__(self, "control_points", cp)
        for name, k in zip(("knots_u", "knots_v", "knots_w"), knots):
            object.__setattr__(self, name, k)
        for name in ("degree_u", "degree_v", "degree_w"):
            object.__setattr__(self, name, int(getattr(self, name)))
        object.__setattr__(self, "weights", w)

    @classmethod
    def construct_fast(cls, control_points: NDArray, knots_u: NDArray, knots_v: NDArray,
                       knots_w: NDArray, degree_u: int, degree_v: int, degree_w: int,
                       weights: NDArray | None = None) -> NurbsVolume:
        """A solid from arrays known to be valid, without checking them.

        The trusted constructor for results of operations on valid solids (knot
        insertion, restriction, builders), as :meth:`.NurbsSurface.construct_fast`:
        nothing is checked, the arrays are taken as C-contiguous float arrays (copied
        only when they are not) and made read-only in place.
        """
        self = object.__new__(cls)
        object.__setattr__(self, "control_points", owned_array(control_points))
        object.__setattr__(self, "knots_u", owned_array(knots_u))
        object.__setattr__(self, "knots_v", owned_array(knots_v))
        object.__setattr__(self, "knots_w", owned_array(knots_w))
        object.__setattr__(self, "degree_u", int(degree_u))
        object.__setattr__(self, "degree_v", int(degree_v))
        object.__setattr__(self, "degree_w", int(degree_w))
        object.__setattr__(self, "weights", None if weights is None else owned_array(weights))
        return self

    # ------------------------------------------------------------------ shape
    @property
    def n_control(self) -> tuple[int, int, int]:
        """Control net size ``(n_u, n_v, n_w)``."""
        return tuple(self.control_points.shape[:3])

    @property
    def dimension(self) -> int:
        """Dimension of the space the solid lies in (3 in practice)."""
        return self.control_points.shape[3]

    @property
    def degrees(self) -> tuple[int, int, int]:
        """``(degree_u, degree_v, degree_w)``."""
        return self.degree_u, self.degree_v, self.degree_w

    @property
    def knots(self) -> tuple[NDArray, NDArray, NDArray]:
        """``(knots_u, knots_v, knots_w)``."""
        return self.knots_u, self.knots_v, self.knots_w

    @property
    def is_rational(self) -> bool:
        """True when the weights are not all equal."""
        return self.weights is not None and bool(np.ptp(self.weights) > 0)

    @property
    def domain(self) -> tuple[float, float, float, float, float, float]:
        """Parameter box ``(u0, u1, v0, v1, w0, w1)``."""
        return tuple(x for k, p in zip(self.knots, self.degrees) for x in domain_of(k, p))

    def homogeneous_points(self) -> NDArray:
        """Control net as ``(w x, w y, w z, w)``: (n_u, n_v, n_w, d + 1) float."""
        w = np.ones(self.n_control) if self.weights is None else self.weights
        return np.concatenate([self.control_points * w[..., None], w[..., None]], axis=3)

    @functools.cached_property
    def homogeneous_net(self) -> NDArray:
        """:meth:`homogeneous_points` computed once per solid, read-only."""
        return frozen_array(self.homogeneous_points())

    @classmethod
    def from_homogeneous(cls, points_w: ArrayLike, knots_u: ArrayLike, knots_v: ArrayLike,
                         knots_w: ArrayLike, degree_u: int, degree_v: int, degree_w: int,
                         rational: bool = True) -> NurbsVolume:
        """Build from a homogeneous net ``(n_u, n_v, n_w, d + 1)`` (last channel the weights)."""
        pw = np.asarray(points_w, dtype=float)
        w = pw[..., -1]
        if np.any(w <= 0):
            raise InvalidGeometryError("homogeneous weights must be > 0")
        return cls(pw[..., :-1] / w[..., None], knots_u, knots_v, knots_w,
                   degree_u, degree_v, degree_w, w if rational else None)

    # ------------------------------------------------------- scattered points
    def evaluate(self, u: ArrayLike, v: ArrayLike, w: ArrayLike) -> NDArray:
        """Points ``P(u, v, w)`` (004 eq. 3.1) for broadcast arrays ``u``, ``v``, ``w``.

        Returns
        -------
        (..., d) float, ``...`` the broadcast shape of ``u``, ``v`` and ``w``.
        """
        return self.derivatives(u, v, w, 0)[..., 0, 0, 0, :]

    def derivatives(self, u: ArrayLike, v: ArrayLike, w: ArrayLike, order: int = 1) -> NDArray:
        """Partial derivatives ``d^{a+b+c} P / du^a dv^b dw^c`` for ``a, b, c = 0..order``.

        Parameters
        ----------
        u, v, w : (...) float, broadcast together
        order : int >= 0

        Returns
        -------
        (..., order + 1, order + 1, order + 1, d) float
            ``[..., a, b, c, :]`` is the a-th u-, b-th v- and c-th w-derivative.
        """
        if order < 0:
            raise ValueError(f"order must be >= 0, got {order}")
        u, v, w = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (u, v, w)))
        shape = u.shape
        u, v, w = u.reshape(-1), v.reshape(-1), w.reshape(-1)
        o1 = order + 1
        out = np.empty((u.size, o1, o1, o1, self.dimension))
        for start in range(0, u.size, _CHUNK):
            part = slice(start, start + _CHUNK)
            out[part] = self._project(self._homogeneous_derivatives(u[part], v[part], w[part], order))
        return out.reshape(shape + out.shape[1:])

    def _homogeneous_derivatives(self, u: NDArray, v: NDArray, w: NDArray, order: int) -> NDArray:
        """Derivatives of the homogeneous form at scattered points: (m, o+1, o+1, o+1, d+1)."""
        net = self.homogeneous_net
        _, nv, nw, c = net.shape
        p, q, r = self.degrees
        ders, index = [], []
        for t, knots, deg in zip((u, v, w), self.knots, self.degrees):
            span = find_span(knots, deg, t)
            ders.append(basis_derivatives(knots, deg, t, order, span)[0])   # (m, o+1, deg+1)
            index.append(span[:, None] - deg + np.arange(deg + 1))
        iu, iv, iw = index
        flat = (iu[:, :, None, None] * nv + iv[:, None, :, None]) * nw + iw[:, None, None, :]
        pw = np.take(net.reshape(-1, c), flat, axis=0)                     # (m, p+1, q+1, r+1, c)
        m, o1 = u.size, order + 1
        du, dv, dw = ders
        tmp = np.matmul(du, pw.reshape(m, p + 1, -1)).reshape(m, o1, q + 1, (r + 1) * c)
        tmp = np.matmul(dv[:, None], tmp).reshape(m, o1, o1, r + 1, c)
        return np.matmul(dw[:, None, None], tmp)                           # (m, o1, o1, o1, c)

    def jacobian(self, u: ArrayLike, v: ArrayLike, w: ArrayLike) -> NDArray:
        """Jacobian matrices ``[dP/du, dP/dv, dP/dw]`` (columns) at broadcast parameters.

        Returns
        -------
        (..., d, 3) float, ``(..., 3, 3)`` for a solid in space.
        """
        d = self.derivatives(u, v, w, 1)
        return np.stack([d[..., 1, 0, 0, :], d[..., 0, 1, 0, :], d[..., 0, 0, 1, :]], axis=-1)

    # ------------------------------------------------------------ tensor grid
    def evaluate_grid(self, u: ArrayLike, v: ArrayLike, w: ArrayLike) -> NDArray:
        """Points on the tensor grid ``u x v x w``.

        Parameters
        ----------
        u : (a,) float
        v : (b,) float
        w : (c,) float

        Returns
        -------
        (a, b, c, d) float
        """
        return self.derivatives_grid(u, v, w, 0)[:, :, :, 0, 0, 0, :]

    def derivatives_grid(self, u: ArrayLike, v: ArrayLike, w: ArrayLike, order: int = 1) -> NDArray:
        """Partial derivatives on the tensor grid ``u x v x w``.

        The basis of each direction is evaluated once and contracted with the net one
        direction after the other (u, then v, then w).

        Returns
        -------
        (a, b, c, order + 1, order + 1, order + 1, d) float
        """
        if order < 0:
            raise ValueError(f"order must be >= 0, got {order}")
        params = [np.asarray(t, dtype=float).reshape(-1) for t in (u, v, w)]
        basis = []
        for t, knots, deg in zip(params, self.knots, self.degrees):
            ders, span = basis_derivatives(knots, deg, t, order)             # (n, o+1, deg+1)
            basis.append((ders, span[:, None] - deg + np.arange(deg + 1)))
        (du, iu), (dv, iv), (dw, iw) = basis
        pw = self.homogeneous_net
        tmp = np.einsum("aki,aiJKc->akJKc", du, pw[iu], optimize=True)        # (a, o1, nv, nw, c)
        tmp = np.einsum("blj,akbjKc->abklKc", dv, tmp[:, :, iv], optimize=True)  # (a, b, o1, o1, nw, c)
        hom = np.einsum("gnz,abklgzc->abgklnc", dw, tmp[:, :, :, :, iw], optimize=True)
        a, b, g = (t.size for t in params)
        out = self._project(hom.reshape((a * b * g,) + hom.shape[3:]))
        return out.reshape((a, b, g) + out.shape[1:])

    def _project(self, hom: NDArray) -> NDArray:
        """Homogeneous derivatives (m, o+1, o+1, o+1, d+1) to Cartesian ones."""
        if self.weights is None:
            return hom[..., :-1]
        return rational_derivatives(hom[..., :-1], hom[..., -1])

    def __call__(self, u: ArrayLike, v: ArrayLike, w: ArrayLike) -> NDArray:
        return self.evaluate(u, v, w)

    # ------------------------------------------------ operations in one direction
    def _net_along(self, axis: int) -> NDArray:
        return np.moveaxis(self.homogeneous_points(), axis, 0)

    def _from_net(self, axis: int, points_w: NDArray, knots: NDArray,
                  degree: int | None = None) -> NurbsVolume:
        """Rebuild (trusted) after an operation on ``axis`` (net along axis 0)."""
        pw = np.moveaxis(points_w, 0, axis)
        w = pw[..., -1]
        all_knots = list(self.knots)
        all_knots[axis] = knots
        degrees = list(self.degrees)
        degrees[axis] = degrees[axis] if degree is None else int(degree)
        return type(self).construct_fast(pw[..., :-1] / w[..., None], *all_knots, *degrees,
                                         w if self.weights is not None else None)

    def insert_knot(self, value: float, direction: str | int | Direction, r: int = 1) -> NurbsVolume:
        """Same solid with ``value`` inserted ``r`` times in ``direction`` (A5.1 of [PT])."""
        axis = as_axis(direction)
        pw, knots = insert_knot_array(self._net_along(axis), self.knots[axis], self.degrees[axis],
                                      value, r)
        return self._from_net(axis, pw, knots)

    def refine(self, new_knots: ArrayLike, direction: str | int | Direction) -> NurbsVolume:
        """Same solid with all of ``new_knots`` (m,) inserted in ``direction``."""
        axis = as_axis(direction)
        pw, knots = refine_knots_array(self._net_along(axis), self.knots[axis], self.degrees[axis],
                                       new_knots)
        return self._from_net(axis, pw, knots)

    def _restrict_axis(self, axis: int, a: float, b: float) -> NurbsVolume:
        knots, degree = self.knots[axis], self.degrees[axis]
        if np.all(knots[:degree + 1] == a) and np.all(knots[-degree - 1:] == b):
            return self
        pw, new = restrict_array(self._net_along(axis), knots, degree, a, b)
        return self._from_net(axis, pw, new)

    def restrict(self, u0: float | None = None, u1: float | None = None,
                 v0: float | None = None, v1: float | None = None,
                 w0: float | None = None, w1: float | None = None) -> NurbsVolume:
        """The sub-volume over ``[u0, u1] x [v0, v1] x [w0, w1]``, clamped, original parameters.

        A bound left as ``None`` is the corresponding end of the domain.
        """
        out = self
        bounds = (u0, u1, v0, v1, w0, w1)
        for axis in range(3):
            lo, hi = self.domain[2 * axis:2 * axis + 2]
            a, b = bounds[2 * axis], bounds[2 * axis + 1]
            out = out._restrict_axis(axis, lo if a is None else a, hi if b is None else b)
        return out

    def clamp(self) -> NurbsVolume:
        """Clamped form in the three directions over the same domain."""
        return self.restrict()

    def split(self, value: float, direction: str | int | Direction) -> tuple[NurbsVolume, NurbsVolume]:
        """Two solids split at ``direction = value`` (strictly inside the domain)."""
        axis = as_axis(direction)
        knots, degree = self.knots[axis], self.degrees[axis]
        value = check_parameter(value, "split parameter")
        check_in_domain(value, knots, degree, "split parameter", open_ends=True)
        lo, hi = domain_of(knots, degree)
        return self._restrict_axis(axis, lo, value), self._restrict_axis(axis, value, hi)

    def elevate_degree(self, t_u: int = 0, t_v: int = 0, t_w: int = 0) -> NurbsVolume:
        """Same solid with degrees ``(p + t_u, q + t_v, r + t_w)`` (section 5.5 of [PT]);
        a direction raised comes back clamped."""
        out = self
        for axis, t in enumerate((t_u, t_v, t_w)):
            if int(t) != t or t < 0:
                raise InvalidGeometryError(
                    f"degree elevation in {AXES[axis]} must be an integer >= 0, got {t!r}")
            if t:
                degree = out.degrees[axis]
                pw, knots = elevate_degree_array(out._net_along(axis), out.knots[axis], degree, int(t))
                out = out._from_net(axis, pw, knots, degree + int(t))
        return out

    def bezier_volumes(self) -> BezierVolumes:
        """Bézier decomposition: the homogeneous net of every knot span ``(i, j, k)`` and
        its control-net box (004 §4.1; the decomposition of :mod:`.bezier` in turn along
        u, v and w)."""
        seg, int_u = bezier_decompose_array(self.homogeneous_points(), self.knots_u, self.degree_u)
        seg, int_v = bezier_decompose_array(np.moveaxis(seg, 2, 0), self.knots_v, self.degree_v)
        seg, int_w = bezier_decompose_array(np.moveaxis(seg, 4, 0), self.knots_w, self.degree_w)
        pieces = np.ascontiguousarray(np.transpose(seg, (4, 2, 0, 5, 3, 1, 6)))
        cartesian = pieces[..., :-1] / pieces[..., -1:]
        boxes = np.stack([cartesian.min(axis=(3, 4, 5)), cartesian.max(axis=(3, 4, 5))], axis=3)
        return BezierVolumes(pieces, int_u, int_v, int_w, boxes, self.degrees,
                             self.weights is not None)

    # -------------------------------------------------------------- boundary
    def isosurface(self, value: float, direction: str | int | Direction) -> NurbsSurface:
        """The exact isoparametric surface ``direction = value``.

        Holding ``u = u*`` in the homogeneous form leaves a tensor-product surface in
        ``(v, w)`` with the homogeneous poles ``Q_jk = sum_i N_i(u*) P^w_ijk`` (the
        surface analogue of :func:`.isocurve.isocurve`), exact for rational solids.

        Parameters
        ----------
        value : float
            Parameter held, inside its domain.
        direction : "u", "v" or "w"

        Returns
        -------
        NurbsSurface
            Parametrized by the two other directions in their order: ``(v, w)`` for
            ``"u"``, ``(u, w)`` for ``"v"``, ``(u, v)`` for ``"w"``; their knots and
            degrees; rational when the solid is.
        """
        axis = as_axis(direction)
        knots, degree = self.knots[axis], self.degrees[axis]
        value = check_parameter(value, "isosurface parameter")
        try:
            check_in_domain(value, knots, degree, "isosurface parameter")
        except InvalidGeometryError as exc:
            raise InvalidGeometryError(f"{exc} (direction {AXES[axis]})") from None
        span, values = basis_functions(knots, degree, np.array([value]))
        net = np.moveaxis(self.homogeneous_net, axis, 0)[span[0] - degree:span[0] + 1]
        poles_w = np.tensordot(values[0], net, axes=(0, 0))                # (n_a, n_b, d+1)
        a, b = (k for k in range(3) if k != axis)
        w = poles_w[..., -1]
        return NurbsSurface.construct_fast(poles_w[..., :-1] / w[..., None], self.knots[a],
                                           self.knots[b], self.degrees[a], self.degrees[b],
                                           w if self.weights is not None else None)

    def boundary(self) -> dict[str, NurbsSurface]:
        """The six boundary surfaces of 004 eq. 3.3, collapsed ones included.

        Returns
        -------
        dict
            ``{"u0": P(u_min, v, w), "u1": P(u_max, v, w), "v0": P(u, v_min, w),
            "v1": P(u, v_max, w), "w0": P(u, v, w_min), "w1": P(u, v, w_max)}``, each a
            :meth:`isosurface`: the ``u`` faces are parametrized by ``(v, w)``, the ``v``
            faces by ``(u, w)``, the ``w`` faces by ``(u, v)``.

        Notes
        -----
        Orientation: for a right-handed solid (``det J > 0``, as every builder of
        :mod:`.volume_builders` makes), the surface normal ``S_a x S_b`` of a face points
        *out of* the solid on ``u1``, ``v0`` and ``w1`` and *into* it on ``u0``, ``v1`` and
        ``w0`` (``P_v x P_w`` is along ``+P_u``, ``P_u x P_w`` along ``-P_v``, ``P_u x P_v``
        along ``+P_w``); a left-handed solid has them the other way round. Faces that
        collapse to a curve or a point (the centre and the poles of
        :func:`.volume_builders.solid_sphere`) are reported by :meth:`collapsed_faces`;
        the faces that bound the solid (004: "the non-degenerate exterior boundary") by
        :meth:`exterior_faces`.
        """
        out = {}
        for axis, name in enumerate(AXES):
            lo, hi = self.domain[2 * axis:2 * axis + 2]
            out[f"{name}0"] = self.isosurface(lo, axis)
            out[f"{name}1"] = self.isosurface(hi, axis)
        return out

    def collapsed_faces(self, tol: float | None = None) -> dict[str, bool]:
        """Which of the six faces degenerate to a curve or a point (area ~ 0, 004 §3).

        A face is collapsed when its area (Gauss–Legendre quadrature) is at most
        ``tol * L``, ``L`` the control-net box diagonal, ``tol`` in model units
        (default ``1e-10 L``). See :func:`.volume_measure.collapsed_faces`.
        """
        return collapsed_faces(self, tol)

    def exterior_faces(self, tol: float | None = None) -> dict[str, NurbsSurface]:
        """The non-degenerate exterior boundary (004 §3): the faces of :meth:`boundary`
        neither collapsed nor glued to the opposite face of a closed direction (the seam
        of a revolved solid). See :func:`.volume_measure.exterior_faces`."""
        return exterior_faces(self, tol)

    # -------------------------------------------------------------- measures
    def volume(self, n_points: int | None = None) -> float:
        """Volume ``integral |det J| du dv dw`` by Gauss–Legendre quadrature per knot span
        (:func:`.volume_measure.solid_volume`: exact for polynomial solids)."""
        return solid_volume(self, n_points)

    def invert(self, points: ArrayLike, *, tol: float | None = None, max_iter: int = 40,
               n_seeds: int = 8) -> VolumeInversion:
        """Parameters ``(u, v, w)`` of points ``(..., 3)``, or of the nearest point of the
        solid for points outside it: ``uvw``, ``points``, ``inside``, ``distance``
        (:func:`.volume_measure.invert_points`, which says what "outside" means)."""
        return invert_points(self, points, tol=tol, max_iter=max_iter, n_seeds=n_seeds)

    def bounding_box(self) -> NDArray:
        """Control-net bounding box ``(2, d)``: contains the solid (weights are positive)."""
        points = self.control_points.reshape(-1, self.dimension)
        return np.stack([points.min(axis=0), points.max(axis=0)])

    def translated(self, offset: ArrayLike) -> NurbsVolume:
        """The same solid moved by ``offset`` ``(d,)``: control points shifted; knots,
        degrees and weights kept (exact for rational solids too)."""
        return type(self).construct_fast(self.control_points + check_offset(offset, self.dimension),
                                         *self.knots, *self.degrees, self.weights)

    def __repr__(self) -> str:
        kind = "rational" if self.weights is not None else "polynomial"
        return (f"NurbsVolume(degree={self.degrees}, n_control={self.n_control}, "
                f"{kind}, domain={self.domain})")


def rational_derivatives(a_ders: NDArray, w_ders: NDArray) -> NDArray:
    """Rational trivariate derivatives from homogeneous ones (eq. 4.20 of [PT], three indices).

    .. math:: P_{abc} = \\Big(A_{abc} - \\sum_{(i,j,k) \\ne 0}^{i \\le a, j \\le b, k \\le c}
              \\binom{a}{i}\\binom{b}{j}\\binom{c}{k}\\, w_{ijk}\\, P_{a-i,\\,b-j,\\,c-k}\\Big) / w

    Parameters
    ----------
    a_ders : (m, o + 1, o + 1, o + 1, d) float
        Derivatives of the weighted numerator.
    w_ders : (m, o + 1, o + 1, o + 1) float
        Derivatives of the weight function.

    Returns
    -------
    (m, o + 1, o + 1, o + 1, d) float
    """
    o1 = a_ders.shape[1]
    a = np.ascontiguousarray(np.moveaxis(a_ders, 0, -1))      # (o1, o1, o1, d, m)
    w = np.ascontiguousarray(np.moveaxis(w_ders, 0, -1))      # (o1, o1, o1, m)
    inv_w = 1.0 / w[0, 0, 0]
    out = np.empty_like(a)
    for i, j, k in itertools.product(range(o1), repeat=3):
        value = a[i, j, k].copy()
        for s, t, z in itertools.product(range(i + 1), range(j + 1), range(k + 1)):
            if s or t or z:
                coef = comb(i, s) * comb(j, t) * comb(k, z)
                value -= (coef * w[s, t, z]) * out[i - s, j - t, k - z]
        out[i, j, k] = value * inv_w
    return np.moveaxis(out, -1, 0)
