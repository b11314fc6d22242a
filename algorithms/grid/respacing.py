"""Exact re-spacing of a surface's knots at its C0 joins, for the elliptic solve.

A surface made of patches joined only with continuity of position (a knot of
multiplicity at least the degree: CATIA V4 and many IGES exports are strings of
Bezier patches) may run through each patch at its own speed: on
``occt_catia4_face_L1.igs`` a parameter interval of width 1 spans 0.02 mm next to one
spanning 54 mm. The elliptic system is solved for the parameters of the nodes
(:mod:`.elliptic`), moving each node with the tangents where it stands; a node next
to such a join steps with the speed of its own patch and lands in the next one
thousands of cell sizes away, and back: the iteration does not settle (the 201 x 201
grid of that face stalled at a residual of 0.017 cells).

Between two such joins the surface depends only on the knots of its own group of
spans, so each group may be mapped affinely onto an interval of any width without
changing a point of the geometry: a piecewise-linear reparametrization with breaks
at the joins. Here each group's width is made its mean length in space (the average
over iso-lines across it), so the speed ``|r_u|`` is about the same on both sides of
every join; the grid is solved in those parameters and mapped back. (The same
re-spacing of whole knot spans is the first step of chord-length
reparametrization, 000 section 29.1; here it is exact because the joins are only
C0.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface

__all__ = ["RATIO", "Respacing", "respaced"]

#: the knots of a direction are re-spaced when the speeds of its groups of spans
#: (mean length in space over width in the parameter) differ by more than this factor
RATIO = 1.5
#: samples along each group, and across the surface, to measure a group's length
_ALONG, _ACROSS = 16, 9


@dataclass(frozen=True)
class Respacing:
    """A surface with its knots re-spaced at the C0 joins, and the maps to and from its parameters.

    Attributes
    ----------
    surface : NurbsSurface
        The same geometry (control net and weights), its knots moved.
    breaks : ((m,) float, (k,) float)
        The joins of the original surface in u and v, with the ends of its domain.
    spaced : ((m,) float, (k,) float)
        Where they lie in the re-spaced surface's parameters (the domain is the same:
        the ends stay where they were, and a seam's period with them).
    """

    surface: NurbsSurface
    breaks: tuple[NDArray, NDArray]
    spaced: tuple[NDArray, NDArray]

    def to_chart(self, parameters: NDArray) -> NDArray:
        """``(..., 2)`` parameters of the original surface to those of :attr:`surface`."""
        p = np.asarray(parameters, dtype=float)
        return np.stack([self.along(p[..., k], k) for k in (0, 1)], axis=-1)

    def from_chart(self, parameters: NDArray) -> NDArray:
        """``(..., 2)`` parameters of :attr:`surface` back to the original surface's."""
        p = np.asarray(parameters, dtype=float)
        return np.stack([self.along(p[..., k], k, back=True) for k in (0, 1)], axis=-1)

    def along(self, values: NDArray, axis: int, *, back: bool = False) -> NDArray:
        """Values of one parameter (``axis`` 0: u, 1: v) of the original surface mapped to
        the re-spaced one's (``back``: the other way)."""
        source, target = (self.spaced, self.breaks) if back else (self.breaks, self.spaced)
        return np.interp(values, source[axis], target[axis])


def _groups(knots: NDArray, degree: int) -> NDArray:
    """The knot values where the surface is only C0 (multiplicity >= degree), with the ends
    of the domain."""
    values, counts = np.unique(np.asarray(knots, dtype=float), return_counts=True)
    first, last = float(knots[degree]), float(knots[len(knots) - degree - 1])
    keep = (values > first) & (values < last) & (counts >= degree)
    return np.concatenate([[first], values[keep], [last]])


def _stretched(x: NDArray, source: NDArray, target: NDArray) -> NDArray:
    """The piecewise-linear map ``source -> target`` at ``x``, continued beyond the ends with
    the slopes of the first and last pieces (the knots of an unclamped surface lie there)."""
    y = np.interp(x, source, target)
    lo, hi = x < source[0], x > source[-1]
    y[lo] = target[0] + (x[lo] - source[0]) * (target[1] - target[0]) / (source[1] - source[0])
    y[hi] = target[-1] + (x[hi] - source[-1]) * (target[-1] - target[-2]) / (source[-1] - source[-2])
    return y


def _lengths(surface: NurbsSurface, breaks: NDArray, axis: int) -> NDArray:
    """Mean length in space of each group ``[breaks[g], breaks[g + 1]]`` along ``axis``."""
    u0, u1, v0, v1 = surface.domain
    across = np.linspace(*((v0, v1) if axis == 0 else (u0, u1)), _ACROSS)
    f = np.linspace(0.0, 1.0, _ALONG)
    along = breaks[:-1, None] + f[None, :] * np.diff(breaks)[:, None]       # (groups, ALONG)
    if axis == 0:
        points = surface.evaluate(along[:, :, None], across[None, None, :])
    else:
        points = surface.evaluate(across[None, None, :], along[:, :, None])
    return np.linalg.norm(np.diff(points, axis=1), axis=-1).sum(axis=1).mean(axis=1)


def respaced(surface: NurbsSurface, *, ratio: float | None = None) -> Respacing | None:
    """The surface with each group of knot spans between C0 joins as wide as it is long.

    Parameters
    ----------
    surface : NurbsSurface
    ratio : float, optional
        A direction is re-spaced only when the speeds of its groups (mean length over
        width) differ by more than this factor (default :data:`RATIO`).

    Returns
    -------
    Respacing, or None when neither direction needs it (one group, or speeds within
    ``ratio``; a collapsed surface; a :class:`.polar.PoleChart`, which has no knots).
    """
    if not isinstance(surface, NurbsSurface):
        return None
    ratio = RATIO if ratio is None else ratio
    breaks, spaced, knots = [], [], []
    changed = False
    for axis, (k, p) in enumerate(((surface.knots_u, surface.degree_u), (surface.knots_v, surface.degree_v))):
        b = _groups(k, p)
        breaks.append(b)
        spaced.append(b)
        knots.append(np.asarray(k, dtype=float))
        if b.size < 3:
            continue
        lengths = _lengths(surface, b, axis)
        total = float(lengths.sum())
        if not np.isfinite(total) or total <= 0.0:
            continue
        speeds = np.maximum(lengths, 1e-12 * total) / np.diff(b)
        if speeds.max() <= ratio * speeds.min():
            continue
        # each group as wide as it is long (at least a thousandth of the mean: a collapsed
        # group keeps some width), scaled to the original span
        widths = np.maximum(lengths, 1e-3 * total / lengths.size)
        new = b[0] + np.concatenate([[0.0], np.cumsum(widths)]) * (b[-1] - b[0]) / widths.sum()
        new[-1] = b[-1]
        spaced[axis] = new
        knots[axis] = _stretched(knots[axis], b, new)
        changed = True
    if not changed:
        return None
    chart = NurbsSurface.construct_fast(surface.control_points, knots[0], knots[1], surface.degree_u,
                                        surface.degree_v, surface.weights)
    return Respacing(chart, (breaks[0], breaks[1]), (spaced[0], spaced[1]))
