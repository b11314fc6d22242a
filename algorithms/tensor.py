"""A tensor-product surface seen along one of its parametric directions.

A surface operation in one direction (knot insertion, refinement, restriction,
degree elevation, isocurves) is the curve operation applied to every row of the
control net at once: the homogeneous net with that direction's poles on axis 0
(:func:`net_along`), the direction's knots and degree (:func:`knots_along`), and
the surface rebuilt from the new net and knots (:func:`surface_from_net`).
:class:`Direction` names the direction; :func:`check_parameter` and
:func:`check_in_domain` validate a parameter value against a knot vector with
the package's messages.
"""

from __future__ import annotations

import enum

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .surface import NurbsSurface

__all__ = [
    "Direction",
    "as_direction",
    "check_in_domain",
    "check_parameter",
    "domain_of",
    "knots_along",
    "net_along",
    "surface_from_net",
]


class Direction(enum.Enum):
    """Parametric direction of a surface."""

    U = 0
    V = 1


def as_direction(direction: Direction | str | int) -> Direction:
    """Accept a :class:`Direction`, ``"u"``/``"v"`` or ``0``/``1``."""
    if isinstance(direction, Direction):
        return direction
    if isinstance(direction, str) and direction.lower() in ("u", "v"):
        return Direction.U if direction.lower() == "u" else Direction.V
    if isinstance(direction, (int, np.integer)) and not isinstance(direction, bool) \
            and int(direction) in (0, 1):
        return Direction(int(direction))
    raise InvalidGeometryError(
        f"direction must be Direction.U or Direction.V, got {direction!r}")


def check_parameter(value: float, name: str) -> float:
    """``value`` as a finite float; :class:`InvalidGeometryError` naming ``name`` otherwise."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidGeometryError(f"{name} must be a real number, got {value!r}") from None
    if not np.isfinite(x):
        raise InvalidGeometryError(f"{name} must be finite, got {x}")
    return x


def domain_of(knots: NDArray, degree: int) -> tuple[float, float]:
    """``(knots[degree], knots[n])``: the domain of a clamped or unclamped knot vector."""
    n = knots.size - degree - 1
    return float(knots[degree]), float(knots[n])


def check_in_domain(x: float, knots: NDArray, degree: int, name: str,
                    open_ends: bool = False) -> None:
    """Refuse ``x`` outside the domain (its interior with ``open_ends``), naming ``name``."""
    lo, hi = domain_of(knots, degree)
    inside = lo < x < hi if open_ends else lo <= x <= hi
    if not inside:
        kind = "interior of the domain" if open_ends else "domain"
        raise InvalidGeometryError(
            f"{name} = {x!r} is outside the {kind} [{lo!r}, {hi!r}]")


def net_along(surface: NurbsSurface, direction: Direction) -> NDArray:
    """The homogeneous control net ``(n_dir, n_other, d + 1)``: ``direction``'s poles on axis 0."""
    pw = surface.homogeneous_points()
    return pw if direction is Direction.U else np.swapaxes(pw, 0, 1)


def knots_along(surface: NurbsSurface, direction: Direction) -> tuple[NDArray, int]:
    """The knots and the degree of ``direction``."""
    if direction is Direction.U:
        return surface.knots_u, surface.degree_u
    return surface.knots_v, surface.degree_v


def surface_from_net(surface: NurbsSurface, direction: Direction, points_w: NDArray,
                     knots: NDArray, degree: int | None = None) -> NurbsSurface:
    """Rebuild a surface after an operation on ``direction`` (net along axis 0), trusted
    (:meth:`NurbsSurface.construct_fast`: the operations keep the net valid)."""
    pw = points_w if direction is Direction.U else np.swapaxes(points_w, 0, 1)
    w = pw[..., -1]
    weights = w if surface.weights is not None else None
    if direction is Direction.U:
        return NurbsSurface.construct_fast(
            pw[..., :-1] / w[..., None], knots, surface.knots_v,
            surface.degree_u if degree is None else degree, surface.degree_v, weights)
    return NurbsSurface.construct_fast(
        pw[..., :-1] / w[..., None], surface.knots_u, knots, surface.degree_u,
        surface.degree_v if degree is None else degree, weights)
