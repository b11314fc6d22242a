"""Builders of trivariate NURBS solids (004 §3, Figs. 3 and 8): blocks, extrusions,
revolutions, ruled solids between two surfaces, the solid sphere and the solid torus.

Every builder returns a right-handed solid (``det J > 0``) when its input is laid out
as documented, so the orientation notes of :meth:`.NurbsVolume.boundary` apply.

* :func:`block`: an axis-aligned box, any degrees (the control points at the Greville
  abscissae, so the parametrization is affine);
* :func:`extrude`: a surface swept along a vector (degree 1 in ``w``);
* :func:`revolve`: a surface turned about an axis; the ``w`` direction is made of the
  standard rational quadratic arcs (A7.1/A8.1 of [PT]), one per 90 degrees or less,
  so every circle of the result is exact;
* :func:`ruled`: the straight lines between two surfaces, made compatible first
  (degree elevation, knot merging);
* :func:`solid_sphere`: 004 Fig. 3, a ball as one triquadratic NURBS: a half-disk
  revolved, with collapsed faces at the centre and along the axis to the poles;
* :func:`solid_torus`: 004 Fig. 8, a disk revolved, triquadratic, whose only exterior
  face is the torus.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   A7.1 (circular arcs), A8.1 (surfaces of revolution), section 5.5 (degree elevation).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from .basis import distinct_knots
from .degree import elevate_degree_surface
from .knots import clamp_surface, refine_surface
from .surface import NurbsSurface
from .volume import NurbsVolume

__all__ = ["block", "extrude", "revolve", "ruled", "solid_sphere", "solid_torus"]

_R2 = math.sqrt(0.5)


def _vector(value: ArrayLike, name: str, size: int = 3) -> NDArray:
    out = np.asarray(value, dtype=float)
    if out.shape != (size,) or not np.all(np.isfinite(out)):
        raise InvalidGeometryError(f"{name} must be {size} finite numbers, got {np.asarray(value)!r}")
    return out


def _positive(value: float, name: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidGeometryError(f"{name} must be a real number, got {value!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise InvalidGeometryError(f"{name} must be finite and > 0, got {x!r}")
    return x


def _surface_in_space(surface: NurbsSurface, name: str) -> None:
    if not isinstance(surface, NurbsSurface):
        raise InvalidGeometryError(f"{name} must be a NurbsSurface, got {type(surface).__name__}")
    if surface.dimension != 3:
        raise InvalidGeometryError(f"{name} must lie in 3D, got dimension {surface.dimension}")


# -------------------------------------------------------------------- block
def block(size: ArrayLike | float, origin: ArrayLike = (0.0, 0.0, 0.0),
          degrees: tuple[int, int, int] = (1, 1, 1)) -> NurbsVolume:
    """The box ``origin + [0, a] x [0, b] x [0, c]`` as a single-span solid.

    Parameters
    ----------
    size : float or (3,) float
        Edge lengths ``(a, b, c)`` along x, y, z, each > 0 (one number: a cube).
    origin : (3,) float
        The corner ``x(0, 0, 0)``.
    degrees : (int, int, int)
        Degrees in u, v, w (>= 1); the control points are at the Greville abscissae
        ``i / p``, so ``x(u, v, w) = origin + (a u, b v, c w)`` exactly for any degrees.

    Returns
    -------
    NurbsVolume
        Domain ``[0, 1]^3``, clamped Bézier knots, non-rational, right-handed.

    Examples
    --------
    >>> cube = block(2.0, origin=(1, 0, 0), degrees=(2, 1, 1))
    >>> cube.n_control, cube.evaluate(0.5, 0.5, 0.5)
    ((3, 2, 2), array([2., 1., 1.]))
    """
    a = np.broadcast_to(np.asarray(size, dtype=float), (3,)) if np.ndim(size) == 0 \
        else _vector(size, "size")
    for value, axis in zip(a, "xyz"):
        _positive(value, f"size along {axis}")
    o = _vector(origin, "origin")
    if len(degrees) != 3 or any(isinstance(p, bool) or int(p) != p or p < 1 for p in degrees):
        raise InvalidGeometryError(f"degrees must be three integers >= 1, got {degrees!r}")
    degrees = tuple(int(p) for p in degrees)
    axes = [np.arange(p + 1) / p * length for p, length in zip(degrees, a)]
    cp = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1) + o
    knots = [np.repeat([0.0, 1.0], p + 1) for p in degrees]
    return NurbsVolume.construct_fast(cp, *knots, *degrees)


# ------------------------------------------------------------------ extrude
def extrude(surface: NurbsSurface, vector: ArrayLike) -> NurbsVolume:
    """The solid swept by ``surface`` moved along ``vector``: ``x(u, v, w) = S(u, v) + w d``.

    Parameters
    ----------
    surface : NurbsSurface, dimension 3
    vector : (3,) float, non-zero

    Returns
    -------
    NurbsVolume
        ``u``, ``v`` as the surface's (knots, degrees, weights), ``w`` in ``[0, 1]`` of
        degree 1; face ``w0`` is the surface, ``w1`` the surface moved by ``vector``.
        Right-handed when ``vector`` is on the side of the surface normal
        ``S_u x S_v``. Its volume is ``area x (vector . unit normal)`` for a planar surface.

    Examples
    --------
    >>> import numpy as np
    >>> square = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0.]]]),
    ...                       [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    >>> round(extrude(square, (0, 0, 2)).volume(), 12)
    2.0
    """
    _surface_in_space(surface, "surface")
    d = _vector(vector, "vector")
    if not np.any(d):
        raise InvalidGeometryError("vector must be non-zero")
    cp = np.stack([surface.control_points, surface.control_points + d], axis=2)
    weights = None if surface.weights is None else np.repeat(surface.weights[..., None], 2, axis=2)
    return NurbsVolume.construct_fast(cp, surface.knots_u, surface.knots_v, [0.0, 0.0, 1.0, 1.0],
                                      surface.degree_u, surface.degree_v, 1, weights)


# ------------------------------------------------------------------ revolve
def _snap(x: NDArray) -> NDArray:
    """cos/sin values within a few ulps of 0 or +-1 made exact (quarter turns)."""
    out = np.where(np.abs(x) < 4e-16, 0.0, x)
    return np.where(np.abs(np.abs(out) - 1.0) < 4e-16, np.sign(out), out)


def _unit(vector: ArrayLike, name: str) -> NDArray:
    d = _vector(vector, name)
    norm = float(np.linalg.norm(d))
    if norm == 0:
        raise InvalidGeometryError(f"{name} must be non-zero")
    return d / norm


def revolve(surface: NurbsSurface, axis_point: ArrayLike, axis_direction: ArrayLike,
            angle: float = 2 * math.pi) -> NurbsVolume:
    """The solid swept by ``surface`` turned about an axis (rational, exact).

    Every control point ``P`` at distance ``rho`` from the axis becomes the control
    polygon of a circular arc of radius ``rho`` about the axis, made of ``n =
    ceil(angle / 90 deg)`` rational quadratic segments of ``delta = angle / n`` each:
    end poles on the circle, middle poles at ``rho / cos(delta / 2)`` on the
    bisectors, weights ``w_P`` and ``w_P cos(delta / 2)`` (A8.1 of [PT]). Points on
    the axis stay there (their arc collapses).

    Parameters
    ----------
    surface : NurbsSurface, dimension 3
    axis_point : (3,) float
    axis_direction : (3,) float, non-zero
        The rotation is right-handed about it (counter-clockwise seen from its tip).
    angle : float
        In radians, ``0 < angle <= 2 pi``.

    Returns
    -------
    NurbsVolume
        ``u``, ``v`` as the surface's, ``w`` the rotation: degree 2, knots at the
        angles ``0, delta, ..., angle`` (each inner one twice), so ``w`` is the angle
        at the knots (only there: a rational arc is not parametrized by angle).
        Face ``w0`` is the surface, ``w1`` the surface turned by ``angle``; for a full
        turn they coincide (the seam; the last poles are copies of the first).
        Right-handed when ``S_u x S_v`` points along ``axis x (P - axis)``, the way the
        points move.

    Examples
    --------
    >>> import numpy as np
    >>> rectangle = NurbsSurface(np.array([[[1, 0, 0], [1, 0, 1]], [[2, 0, 0], [2, 0, 1.]]]),
    ...                          [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    >>> ring = revolve(rectangle, (0, 0, 0), (0, 0, 1), np.pi)
    >>> round(ring.volume() / (np.pi / 2 * (2 ** 2 - 1)), 12), ring.domain[4:]
    (1.0, (0.0, 3.141592653589793))
    """
    _surface_in_space(surface, "surface")
    a = _vector(axis_point, "axis_point")
    d = _unit(axis_direction, "axis_direction")
    angle = _positive(angle, "angle")
    if angle > 2 * math.pi * (1 + 1e-15):
        raise InvalidGeometryError(f"angle must be <= 2 pi, got {angle!r}")
    angle = min(angle, 2 * math.pi)
    n_arcs = max(1, math.ceil(angle / (0.5 * math.pi) - 1e-12))
    delta = angle / n_arcs
    theta = np.arange(2 * n_arcs + 1) * (0.5 * delta)                  # ends and bisectors
    cos, sin = _snap(np.cos(theta)), _snap(np.sin(theta))
    stretch = np.where(np.arange(theta.size) % 2 == 1, 1.0 / math.cos(0.5 * delta), 1.0)
    arc_weight = np.where(np.arange(theta.size) % 2 == 1, math.cos(0.5 * delta), 1.0)
    cp = surface.control_points
    along = (cp - a) @ d
    foot = a + along[..., None] * d                                     # (nu, nv, 3)
    x_axis = cp - foot
    y_axis = np.cross(d, x_axis)
    radial = (cos[:, None] * stretch[:, None])[None, None] * x_axis[:, :, None, :] \
        + (sin[:, None] * stretch[:, None])[None, None] * y_axis[:, :, None, :]
    net = foot[:, :, None, :] + radial                                  # (nu, nv, 2n+1, 3)
    if angle == 2 * math.pi:
        net[:, :, -1] = cp                                             # the seam, exactly
    net[:, :, 0] = cp
    w_surface = np.ones(surface.n_control) if surface.weights is None else surface.weights
    weights = w_surface[..., None] * arc_weight[None, None, :]
    breaks = np.arange(n_arcs + 1) * delta
    breaks[-1] = angle
    knots_w = np.concatenate([[0.0, 0.0, 0.0], np.repeat(breaks[1:-1], 2), [angle] * 3])
    return NurbsVolume.construct_fast(net, surface.knots_u, surface.knots_v, knots_w,
                                      surface.degree_u, surface.degree_v, 2, weights)


# -------------------------------------------------------------------- ruled
def _mapped_knots(knots: NDArray, source: tuple[float, float], target: tuple[float, float]) -> NDArray:
    """Knots mapped affinely from the domain ``source`` onto ``target`` (ends exact)."""
    (s0, s1), (t0, t1) = source, target
    out = t0 + (knots - s0) * ((t1 - t0) / (s1 - s0))
    out[knots == s0], out[knots == s1] = t0, t1
    return out


def _missing(have: NDArray, want: NDArray, degree: int) -> NDArray:
    """The knots to insert into ``have`` so that it holds every knot of ``want``."""
    values, counts = distinct_knots(want, degree)
    own = np.array([np.count_nonzero(have == x) for x in values])
    return np.repeat(values, np.maximum(counts - own, 0))


def _compatible(a: NurbsSurface, b: NurbsSurface) -> tuple[NurbsSurface, NurbsSurface]:
    """``a`` and ``b`` with the same degrees and knot vectors (``b`` reparametrized
    affinely onto ``a``'s domain, both clamped, degrees raised, knots merged)."""
    a, b = clamp_surface(a), clamp_surface(b)
    ua0, ua1, va0, va1 = a.domain
    ub0, ub1, vb0, vb1 = b.domain
    b = NurbsSurface.construct_fast(b.control_points,
                                    _mapped_knots(b.knots_u, (ub0, ub1), (ua0, ua1)),
                                    _mapped_knots(b.knots_v, (vb0, vb1), (va0, va1)),
                                    b.degree_u, b.degree_v, b.weights)
    pu, pv = max(a.degree_u, b.degree_u), max(a.degree_v, b.degree_v)
    a = elevate_degree_surface(a, pu - a.degree_u, pv - a.degree_v)
    b = elevate_degree_surface(b, pu - b.degree_u, pv - b.degree_v)
    for direction, p in (("u", pu), ("v", pv)):
        ka = a.knots_u if direction == "u" else a.knots_v
        kb = b.knots_u if direction == "u" else b.knots_v
        to_a, to_b = _missing(ka, kb, p), _missing(kb, ka, p)
        if to_a.size:
            a = refine_surface(a, to_a, direction)
        if to_b.size:
            b = refine_surface(b, to_b, direction)
    return a, b


def ruled(surface_a: NurbsSurface, surface_b: NurbsSurface) -> NurbsVolume:
    """The ruled solid between two surfaces: for every ``(u, v)`` the straight segment
    from ``A(u, v)`` to ``B(u, v)``.

    The surfaces are made compatible first: both clamped, ``surface_b``'s knots mapped
    affinely onto ``surface_a``'s domain (the same geometry), the lower degree raised
    to the higher in each direction (:func:`.degree.elevate_degree_surface`) and every
    knot of one inserted into the other (:func:`.knots.refine_surface`). The solid has
    the two nets as its ``w = 0`` and ``w = 1`` layers, degree 1 in ``w``. For rational
    surfaces the segment is still straight, traversed at a rate set by the two weights.

    Parameters
    ----------
    surface_a, surface_b : NurbsSurface, dimension 3

    Returns
    -------
    NurbsVolume
        ``u``, ``v`` over ``surface_a``'s domain, ``w`` in ``[0, 1]``; face ``w0`` is
        ``surface_a``, ``w1`` is ``surface_b``; rational when either is. Right-handed
        when ``surface_b`` lies on the side of ``surface_a``'s normal ``S_u x S_v``.

    Examples
    --------
    >>> import numpy as np
    >>> flat = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0.]]]),
    ...                     [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    >>> slab = ruled(flat, flat.translated([0, 0, 3]).elevate_degree(1, 0))
    >>> slab.degrees, round(slab.volume(), 12)
    ((2, 1, 1), 3.0)
    """
    _surface_in_space(surface_a, "surface_a")
    _surface_in_space(surface_b, "surface_b")
    a, b = _compatible(surface_a, surface_b)
    cp = np.stack([a.control_points, b.control_points], axis=2)
    if a.weights is None and b.weights is None:
        weights = None
    else:
        weights = np.stack([np.ones(a.n_control) if a.weights is None else a.weights,
                            np.ones(b.n_control) if b.weights is None else b.weights], axis=2)
    return NurbsVolume.construct_fast(cp, a.knots_u, a.knots_v, [0.0, 0.0, 1.0, 1.0],
                                      a.degree_u, a.degree_v, 1, weights)


# ----------------------------------------------------------- sphere, torus
#: the unit circle as 4 rational quadratic quarter arcs, counter-clockwise from (1, 0):
#: poles (9, 2), weights (9,), knots at the angles 0, pi/2, pi, 3 pi/2, 2 pi
_CIRCLE = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]],
                   dtype=float)
_CIRCLE_WEIGHTS = np.array([1, _R2, 1, _R2, 1, _R2, 1, _R2, 1])
_CIRCLE_KNOTS = np.repeat(np.arange(5) * (0.5 * math.pi), [3, 2, 2, 2, 3])
#: the meridian of the unit sphere in the xz plane from the north pole to the south pole
#: (colatitude 0 to pi, 2 quarter arcs): poles (5, 3), weights (5,), knots at the angles
_MERIDIAN = np.array([[0, 0, 1], [1, 0, 1], [1, 0, 0], [1, 0, -1], [0, 0, -1]], dtype=float)
_MERIDIAN_WEIGHTS = _CIRCLE_WEIGHTS[:5]
_MERIDIAN_KNOTS = np.repeat(np.arange(3) * (0.5 * math.pi), [3, 2, 3])


def _polar_disk(arc_points: NDArray, arc_weights: NDArray, arc_knots: NDArray) -> NurbsSurface:
    """``S(s, t) = s C(t)``: the region swept from the origin to the arc ``C`` (points
    in 3D), ``s`` in ``[0, 1]`` of degree 2 (poles at ``s = 0, 1/2, 1``, which keeps it
    linear), the arc's weights in ``t``; collapsed at ``s = 0``."""
    s = np.array([0.0, 0.5, 1.0])
    cp = s[:, None, None] * arc_points[None, :, :]
    weights = np.broadcast_to(arc_weights, cp.shape[:2])
    return NurbsSurface.construct_fast(cp, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0], arc_knots, 2, 2, weights)


def solid_sphere(radius: float = 1.0, centre: ArrayLike = (0.0, 0.0, 0.0)) -> NurbsVolume:
    """A ball as one triquadratic rational solid with collapsed faces (004 Fig. 3).

    The half-disk ``{(rho, 0, z): rho >= 0, rho^2 + z^2 <= R^2}`` in polar form (radius
    fraction ``s``, colatitude ``t`` from the north pole) revolved a full turn about
    the z axis: ``x(s, t, phi) = centre + s R (sin t cos phi, sin t sin phi, cos t)`` at
    the knots, with the rational quadratic arcs between them (exact sphere).

    Parameters
    ----------
    radius : float > 0
    centre : (3,) float

    Returns
    -------
    NurbsVolume
        Degrees ``(2, 2, 2)``, control net ``(3, 5, 9)``; domain ``s in [0, 1]``,
        ``t in [0, pi]`` (2 spans), ``phi in [0, 2 pi]`` (4 spans); right-handed.
        Faces: ``u1`` the sphere (the only exterior face); ``u0`` the centre (a
        point), ``v0`` and ``v1`` the axis segments to the poles (curves): collapsed;
        ``w0`` = ``w1`` the half-disk seam.

    Examples
    --------
    >>> import numpy as np
    >>> ball = solid_sphere(2.0, (1, 0, 0))
    >>> sorted(name for name, flag in ball.collapsed_faces().items() if flag)
    ['u0', 'v0', 'v1']
    >>> bool(abs(ball.volume() - 4 / 3 * np.pi * 8) < 1e-12)
    True
    """
    r = _positive(radius, "radius")
    c = _vector(centre, "centre")
    half_disk = _polar_disk(r * _MERIDIAN, _MERIDIAN_WEIGHTS, _MERIDIAN_KNOTS)
    return revolve(half_disk, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)).translated(c)


def _frame(axis: NDArray) -> NDArray:
    """Rotation ``(3, 3)`` whose third column is ``axis`` (unit); the identity for z."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = helper - (helper @ axis) * axis
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(axis, e1), axis], axis=1)


def solid_torus(major: float, minor: float, centre: ArrayLike = (0.0, 0.0, 0.0),
                axis: ArrayLike = (0.0, 0.0, 1.0)) -> NurbsVolume:
    """A solid torus as one triquadratic rational solid (004 Fig. 8): a full disk revolved.

    The disk of radius ``minor`` centred at distance ``major`` from the axis, in polar
    form (radius fraction ``s``, tube angle ``t``), turned a full revolution.

    Parameters
    ----------
    major : float
        Distance from the axis to the tube's centre circle, > ``minor``.
    minor : float > 0
        Tube radius.
    centre : (3,) float
    axis : (3,) float, non-zero

    Returns
    -------
    NurbsVolume
        Degrees ``(2, 2, 2)``, control net ``(3, 9, 9)``; domain ``s in [0, 1]``,
        ``t in [0, 2 pi]``, ``phi in [0, 2 pi]`` (4 spans each); right-handed.
        Faces: ``u1`` the torus (the only exterior face), ``u0`` the centre circle
        (collapsed), ``v0`` = ``v1`` and ``w0`` = ``w1`` seams. Implicit form of the
        boundary, with ``z`` along ``axis`` and ``rho`` the distance to it:
        ``(rho - major)^2 + z^2 = minor^2``. Volume ``2 pi^2 major minor^2``.

    Examples
    --------
    >>> import numpy as np
    >>> ring = solid_torus(3.0, 1.0, axis=(1, 1, 0))
    >>> list(ring.exterior_faces()), bool(abs(ring.volume() - 6 * np.pi ** 2) < 1e-12)
    (['u1'], True)
    """
    big, small = _positive(major, "major"), _positive(minor, "minor")
    if not big > small:
        raise InvalidGeometryError(
            f"major must be > minor (a ring torus), got major = {big!r}, minor = {small!r}")
    c = _vector(centre, "centre")
    frame = _frame(_unit(axis, "axis"))
    # tube circle in the xz plane, clockwise seen from +y (right-handed with the turn)
    tube = np.stack([small * _CIRCLE[:, 0], np.zeros(9), -small * _CIRCLE[:, 1]], axis=1)
    disk = _polar_disk(tube, _CIRCLE_WEIGHTS, _CIRCLE_KNOTS)
    disk = NurbsSurface.construct_fast(disk.control_points + np.array([big, 0.0, 0.0]),
                                       disk.knots_u, disk.knots_v, 2, 2, disk.weights)
    local = revolve(disk, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    return NurbsVolume.construct_fast(local.control_points @ frame.T + c, *local.knots,
                                      *local.degrees, local.weights)
