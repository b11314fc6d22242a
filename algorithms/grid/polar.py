"""A pole cap gridded as an H-type block layout: its O-type parameters remapped (003 Fig. 5).

A surface of revolution's cap (a hemisphere, a fuselage nose) is, in its own
parameters, a rectangle one side of which collapses to the pole and whose two
other sides meet at a seam: an O-type grid, whose lines run round the pole and
into it, the cells next to the pole triangles. 003 remaps such a grid to an
H-type one by making a new distribution space and evaluating the surface there
(Fig. 5b-d). Here that space is a disc, :class:`PoleChart`: the angle round the
pole is the parameter along the seam's direction, the distance from the centre the
mean arc length from the pole along the meridians (a disc of radius one at the
rim), so the pole is an ordinary point of the chart and the seam no line at all.
In the disc the cap is split as a disc is (a butterfly, :func:`cap_regions`): a
square round the pole and four blocks between it and the rim, joined by straight
spokes. No cell touches a pole; the price is four points where three blocks meet.

The chart goes to the surface's parameters as

.. math::

    u = u_0 + \\frac{\\theta}{2\\pi} (u_1 - u_0), \\qquad
    v = v_p + (v_r - v_p)\\, g(\\rho), \\qquad
    \\rho = \\sqrt{x^2 + y^2}, \\quad \\theta = \\operatorname{atan2}(y, x) \\bmod 2\\pi,

``v_p`` the pole's parameter, ``v_r`` the rim's, and ``g`` the monotone cubic
(PCHIP) through the mean meridian lengths; its derivatives by the chain rule,
``S_x = S_u u_\\theta \\theta_x + S_v v_\\rho \\rho_x`` with ``theta_x = -y / rho^2``,
``rho_x = x / rho``, and likewise for ``y``. ``S_u`` vanishes at the pole as
``rho`` does, so the product stays finite; within ``1e-9`` of the centre the
derivatives are those at that radius.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PchipInterpolator

from ..curve import NurbsCurve
from ..healing.loop_sides import uv_segment
from ..measure import normals as _surface_normals
from ..surface import NurbsSurface
from .region import Region

__all__ = ["CORNER_RADIUS", "PoleChart", "cap_regions", "pole_cap", "surface_normals"]

#: the butterfly's inner square has its corners this far from the pole (fraction of
#: the rim's radius in the chart)
CORNER_RADIUS = 0.55
#: the inner square's sides bulge so that its corners are 120 degrees, as are the outer
#: regions' there (three blocks meet at each: 120 degrees each is the most even split)
BULGE = math.radians(15.0)
#: a side is collapsed, and a seam closed, within this fraction of the box diagonal
CLOSED = 1e-9
#: meridians and samples along each, to measure the radius of the chart
_MERIDIANS, _ALONG = 16, 65
#: nearer the centre than this (chart units), derivatives are taken at this radius
_CENTRE = 1e-9


@dataclass(frozen=True, eq=False)
class PoleChart:
    """A pole cap of a surface in a unit disc whose centre is the pole (see the module doc).

    It stands for a surface in a grid: :meth:`evaluate`, :meth:`derivatives` (first
    order) and :attr:`domain` in chart coordinates ``(x, y)``, the disc inside the
    square ``[-1, 1]^2``.

    Attributes
    ----------
    surface : NurbsSurface
        The cap.
    angle_axis : int
        0: ``u`` runs round the pole (the pole is a side ``v = const``); 1: ``v`` does.
    pole, rim : float
        The other parameter at the pole and at the rim.
    radius : (k,) float
        Mean arc length from the pole, as a fraction of the rim's, at ``levels``.
    levels : (k,) float
        Values of the radial parameter from the pole (0) to the rim (1), normalized.
    turn : (m,) float
        Angle round the pole (radians, 0 to 2 pi): arc length along the iso-line half
        way to the rim, as a fraction of its length times 2 pi, at ``angles``.
    angles : (m,) float
        Values of the angle parameter, from one end of its span to the other.
    """

    surface: NurbsSurface
    angle_axis: int
    pole: float
    rim: float
    radius: NDArray
    levels: NDArray
    turn: NDArray
    angles: NDArray
    _g: PchipInterpolator = field(init=False, repr=False)
    _dg: PchipInterpolator = field(init=False, repr=False)
    _a: PchipInterpolator = field(init=False, repr=False)
    _da: PchipInterpolator = field(init=False, repr=False)

    def __post_init__(self) -> None:
        g = PchipInterpolator(self.radius, self.levels)
        a = PchipInterpolator(self.turn, self.angles)
        object.__setattr__(self, "_g", g)
        object.__setattr__(self, "_dg", g.derivative())
        object.__setattr__(self, "_a", a)
        object.__setattr__(self, "_da", a.derivative())

    dimension = 3

    @property
    def domain(self) -> tuple[float, float, float, float]:
        return (-1.0, 1.0, -1.0, 1.0)

    def bounding_box(self) -> NDArray:
        """The cap's control-net box ``(2, 3)``."""
        return self.surface.bounding_box()

    def to_surface(self, parameters: ArrayLike) -> NDArray:
        """``(..., 2)`` chart points to the cap's ``(u, v)`` (the centre: the pole, at the
        angle ``theta = 0``; outside the disc: on the rim)."""
        p = np.asarray(parameters, dtype=float)
        x, y = p[..., 0], p[..., 1]
        rho = np.minimum(np.hypot(x, y), 1.0)
        angle = self._a(np.mod(np.arctan2(y, x), 2.0 * math.pi))
        radial = self.pole + (self.rim - self.pole) * self._g(rho)
        return np.stack([angle, radial] if self.angle_axis == 0 else [radial, angle], axis=-1)

    def evaluate(self, x: ArrayLike, y: ArrayLike) -> NDArray:
        """Points of the cap at chart points ``(x, y)``, broadcast: ``(..., 3)``."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        uv = self.to_surface(np.stack([x, y], axis=-1))
        return self.surface.evaluate(uv[..., 0], uv[..., 1])

    def derivatives(self, x: ArrayLike, y: ArrayLike, order: int = 1) -> NDArray:
        """Point and first derivatives in the chart, ``(..., 2, 2, 3)``: ``[..., 0, 0]`` the
        point, ``[..., 1, 0]`` ``S_x``, ``[..., 0, 1]`` ``S_y`` (``[..., 1, 1]`` is not
        computed: NaN).

        Raises
        ------
        ValueError
            ``order`` other than 1.
        """
        if order != 1:
            raise ValueError(f"a pole chart has first derivatives only, got order {order}")
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        rho = np.hypot(x, y)
        near = rho < _CENTRE
        # at the centre: the derivatives just off it (along +x where exactly at it)
        scale = np.where(near, _CENTRE / np.where(rho > 0.0, rho, 1.0), 1.0)
        xs = np.where(near & (rho == 0.0), _CENTRE, x * scale)
        ys = y * scale
        r = np.hypot(xs, ys)
        uv = self.to_surface(np.stack([xs, ys], axis=-1))
        d = self.surface.derivatives(uv[..., 0], uv[..., 1], 1)
        s_angle, s_radial = (d[..., 1, 0, :], d[..., 0, 1, :]) if self.angle_axis == 0 \
            else (d[..., 0, 1, :], d[..., 1, 0, :])
        # per radian and per chart unit of radius
        along = s_angle * self._da(np.mod(np.arctan2(ys, xs), 2.0 * math.pi))[..., None]
        across = s_radial * ((self.rim - self.pole) * self._dg(np.minimum(r, 1.0)))[..., None]
        out = np.full(x.shape + (2, 2, 3), np.nan)
        out[..., 0, 0, :] = d[..., 0, 0, :]
        out[..., 1, 0, :] = along * (-ys / r**2)[..., None] + across * (xs / r)[..., None]   # theta_x, rho_x
        out[..., 0, 1, :] = along * (xs / r**2)[..., None] + across * (ys / r)[..., None]    # theta_y, rho_y
        return out

    def normals(self, x: ArrayLike, y: ArrayLike) -> NDArray:
        """Unit normals ``S_x x S_y / |S_x x S_y|`` of the cap at chart points, the pole's
        included (the surface's own normals there, :func:`..measure.normals`, turned by
        the sign of the chart's Jacobian)."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        uv = self.to_surface(np.stack([x, y], axis=-1))
        n = _surface_normals(self.surface, uv[..., 0], uv[..., 1])
        # d(u, v)/d(x, y) has the sign of -(angle span)(rim - pole) when u is the angle
        sign = -np.sign((self.angles[-1] - self.angles[0]) * (self.rim - self.pole))
        return n * (sign if self.angle_axis == 0 else -sign)


def surface_normals(surface: NurbsSurface | PoleChart, u: ArrayLike, v: ArrayLike) -> NDArray:
    """Unit normals of a surface or a pole chart at its parameters ``(u, v)``: ``(..., 3)``."""
    if isinstance(surface, PoleChart):
        return surface.normals(u, v)
    return _surface_normals(surface, u, v)


def pole_cap(surface: NurbsSurface) -> PoleChart | None:
    """The surface's chart round its pole, or None when it is not a pole cap.

    A pole cap has exactly one collapsed side (its length under :data:`CLOSED` times the
    box diagonal) and is closed across the direction along that side (its two other
    sides coincide, within the same fraction).

    Parameters
    ----------
    surface : NurbsSurface (3D)

    Returns
    -------
    PoleChart or None
    """
    u0, u1, v0, v1 = surface.domain
    diag = float(np.linalg.norm(np.ptp(surface.bounding_box(), axis=0)))
    if not diag > 0.0:
        return None
    f = np.linspace(0.0, 1.0, _ALONG)
    us, vs = u0 + f * (u1 - u0), v0 + f * (v1 - v0)
    for angle_axis in (0, 1):
        if angle_axis == 0:
            sides = surface.evaluate(us[None, :], np.array([v0, v1])[:, None])       # (2, ALONG, 3)
            seam = surface.evaluate(np.array([u0, u1])[:, None], vs[None, :])
        else:
            sides = surface.evaluate(np.array([u0, u1])[:, None], vs[None, :])
            seam = surface.evaluate(us[None, :], np.array([v0, v1])[:, None])
        lengths = np.linalg.norm(np.diff(sides, axis=1), axis=-1).sum(axis=1)
        collapsed = lengths <= CLOSED * diag
        if collapsed.sum() != 1 or np.abs(seam[0] - seam[1]).max() > CLOSED * diag:
            continue
        lo, hi = (v0, v1) if angle_axis == 0 else (u0, u1)
        pole, rim = (lo, hi) if collapsed[0] else (hi, lo)
        return PoleChart(surface, angle_axis, pole, rim, *_meridian_radius(surface, angle_axis, pole, rim),
                         *_turning(surface, angle_axis, pole, rim))
    return None


def _length_table(steps: NDArray, values: NDArray) -> tuple[NDArray, NDArray] | None:
    """Cumulative ``steps`` as a fraction of their sum, and the ``values`` at them, both
    increasing (steps of no length dropped); None when there is no length."""
    length = np.concatenate([[0.0], np.cumsum(steps)])
    keep = np.concatenate([[True], np.diff(length) > 1e-12 * max(length[-1], 1e-300)])
    if length[-1] <= 0.0 or keep.sum() < 2:
        return None
    return length[keep] / length[-1], values[keep]


def _meridian_radius(surface: NurbsSurface, angle_axis: int, pole: float, rim: float) -> tuple[NDArray, NDArray]:
    """Mean arc length from the pole along the meridians, normalized to 1 at the rim, at
    levels 0..1 of the radial parameter: ``(radius, levels)``, both increasing."""
    a0, a1 = surface.domain[:2] if angle_axis == 0 else surface.domain[2:]
    angles = a0 + (np.arange(_MERIDIANS) + 0.5) / _MERIDIANS * (a1 - a0)
    levels = np.linspace(0.0, 1.0, _ALONG)
    radial = pole + (rim - pole) * levels
    if angle_axis == 0:
        points = surface.evaluate(angles[:, None], radial[None, :])
    else:
        points = surface.evaluate(radial[None, :], angles[:, None])
    table = _length_table(np.linalg.norm(np.diff(points, axis=1), axis=-1).mean(axis=0), levels)
    return (levels, levels) if table is None else table          # no length: linear in the parameter


def _turning(surface: NurbsSurface, angle_axis: int, pole: float, rim: float) -> tuple[NDArray, NDArray]:
    """Arc length along the iso-line half way from the pole to the rim, scaled to
    ``2 pi``, at values of the angle parameter: ``(turn, angles)``, both increasing (a
    surface of revolution: the true angle round its axis)."""
    a0, a1 = surface.domain[:2] if angle_axis == 0 else surface.domain[2:]
    angles = np.linspace(a0, a1, 4 * _ALONG + 1)
    middle = np.full_like(angles, 0.5 * (pole + rim))
    points = surface.evaluate(angles, middle) if angle_axis == 0 else surface.evaluate(middle, angles)
    table = _length_table(np.linalg.norm(np.diff(points, axis=0), axis=-1), angles)
    if table is None:
        return np.array([0.0, 2.0 * math.pi]), np.array([a0, a1])
    return 2.0 * math.pi * table[0], table[1]


def _arc(a: float, b: float) -> NurbsCurve:
    """The arc of the unit circle from angle ``a`` to ``b`` (``|b - a| <= pi / 2``), exact
    (rational quadratic) in the chart."""
    h = 0.5 * (b - a)
    m = 0.5 * (a + b)
    cp = np.array([[math.cos(a), math.sin(a)], [math.cos(m) / math.cos(h), math.sin(m) / math.cos(h)],
                   [math.cos(b), math.sin(b)]])
    return NurbsCurve(cp, np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]), 2, weights=np.array([1.0, math.cos(h), 1.0]))


def _bulged(a: NDArray, b: NDArray, turn: float) -> NurbsCurve:
    """The circular arc from ``a`` to ``b`` bulging away from the origin, its tangents
    turned by ``turn`` (radians) from the chord at both ends (rational quadratic)."""
    middle, half = 0.5 * (a + b), 0.5 * (b - a)
    out = np.array([half[1], -half[0]])
    if np.dot(out, middle) < 0.0:
        out = -out
    apex = middle + out * math.tan(turn)
    return NurbsCurve(np.array([a, apex, b]), np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]), 2,
                      weights=np.array([1.0, math.cos(turn), 1.0]))


def cap_regions(chart: PoleChart, *, corner_radius: float = CORNER_RADIUS,
                clockwise: bool = False) -> list[Region]:
    """A pole cap as five four-sided regions of its chart: the butterfly (H-type).

    A square round the pole, its corners at ``corner_radius`` on the diagonals
    (angles 45, 135, 225 and 315 degrees round the pole, the rim split at the same
    angles, the first an eighth of a turn past the seam), its sides circular arcs
    bulging by :data:`BULGE` so that each of the three regions meeting at a corner
    has 120 degrees there, and four regions between its sides and the rim, joined by
    radial spokes.

    Parameters
    ----------
    chart : PoleChart
    corner_radius : float
        In (0, 1).
    clockwise : bool
        The regions' loops taken clockwise (a face used reversed).

    Returns
    -------
    list of Region
        The square first, then the four outer regions counter-clockwise from the one
        that holds the seam.
    """
    if not 0.0 < corner_radius < 1.0:
        raise ValueError(f"corner_radius must lie in (0, 1), got {corner_radius!r}")
    angles = [math.pi / 4 + k * math.pi / 2 for k in range(-1, 4)]          # -45 .. 315 degrees
    inner = [corner_radius * np.array([math.cos(a), math.sin(a)]) for a in angles]
    rim = [np.array([math.cos(a), math.sin(a)]) for a in angles]
    sides = [_bulged(inner[k], inner[k + 1], BULGE) for k in range(4)]
    out = [Region.from_runs(chart, [(side, 0.0, 1.0) for side in sides], clockwise=clockwise)]
    for k in range(4):
        runs = [(sides[k], 0.0, 1.0),
                (uv_segment(inner[k + 1], rim[k + 1]), 0.0, 1.0),
                (_arc(angles[k + 1], angles[k]), 0.0, 1.0),
                (uv_segment(rim[k], inner[k]), 0.0, 1.0)]
        out.append(Region.from_runs(chart, runs, clockwise=clockwise))
    return out

