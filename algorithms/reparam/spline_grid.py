"""The interpolating spline of a relocated grid and its dense error (000 §29.2.3, §29.2.7).

Shared by the error loop of :mod:`.rca` and the coarsening of :mod:`.coarsen`:
crease lines of the grid become triple knots (C0) joining not-a-knot cubic
pieces; every fit is measured densely both ways (eq. 29.3).
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import NDArray

from ..fitting import interpolate_surface, knots_from_breakpoints
from ..surface import NurbsSurface
from .coarsen import Fit
from .deviation import deviation_map, original_on_new

__all__ = ["cell_errors", "fit_and_measure", "joined_knots", "line_indices", "subgrid_fit"]


def line_indices(fractions: NDArray, f_breaks: NDArray) -> NDArray:
    """Grid indices of the nodes on crease lines (interior f_breaks)."""
    return np.array([int(np.argmin(np.abs(fractions - f))) for f in f_breaks[1:-1]], dtype=int)


def joined_knots(params: NDArray, joints: NDArray) -> NDArray:
    """Not-a-knot cubic knots per piece, joined with multiplicity 3 (C0) at ``joints``."""
    cuts = np.concatenate([[0], joints, [len(params) - 1]])
    parts = [knots_from_breakpoints(params[a:b + 1], 3) for a, b in itertools.pairwise(cuts)]
    out = [parts[0][:-4]]
    for k, part in enumerate(parts[1:]):
        out.append(np.full(3, params[joints[k]]))
        out.append(part[4:-4] if k < len(parts) - 2 else part[4:])
    if len(parts) == 1:
        return parts[0]
    return np.concatenate(out)


def cell_errors(dev, reverse, params_u: NDArray, params_v: NDArray) -> NDArray:
    """Largest distance per interpolation cell, both ways ``(n_u - 1, n_v - 1)``."""
    cells = dev.cell_errors.copy()
    distance, uv = reverse
    ri = np.clip(np.searchsorted(params_u, uv[:, 0]) - 1, 0, len(params_u) - 2)
    rj = np.clip(np.searchsorted(params_v, uv[:, 1]) - 1, 0, len(params_v) - 2)
    np.maximum.at(cells, (ri, rj), distance)
    return cells


def subgrid_fit(surface: NurbsSurface, uv: NDArray, params_u: NDArray, params_v: NDArray,
                creases: tuple[NDArray, NDArray], per_span: int):
    """``(keep_u, keep_v) -> Fit``: interpolate the kept lines of the relocated grid
    (crease lines stay triple knots) and measure densely (eq. 29.3, both ways)."""
    def fit(keep_u: NDArray, keep_v: NDArray) -> Fit:
        sub = uv[np.ix_(keep_u, keep_v)]
        pu, pv = params_u[keep_u], params_v[keep_v]
        ju = np.cumsum(keep_u)[creases[0]] - 1
        jv = np.cumsum(keep_v)[creases[1]] - 1
        new, dev, reverse, worst = fit_and_measure(surface, sub, pu, pv, (ju, jv), per_span)
        return Fit(keep_u, keep_v, worst, cell_errors(dev, reverse, pu, pv), (new, pu, pv, sub))
    return fit


def fit_and_measure(surface: NurbsSurface, uv: NDArray, params_u: NDArray, params_v: NDArray,
                    joints: tuple[NDArray, NDArray], per_span: int):
    """Interpolate ``surface(uv)`` at ``params_u x params_v`` (C0 at the ``joints`` grid
    indices) and measure it densely: ``(new, deviation map, reverse, worst)``."""
    new = interpolate_surface(surface.evaluate(uv[..., 0], uv[..., 1]), params_u=params_u,
                              params_v=params_v, knots_u=joined_knots(params_u, joints[0]),
                              knots_v=joined_knots(params_v, joints[1]))
    dev = deviation_map(surface, new, params_u, params_v, uv, per_span)
    reverse = original_on_new(surface, new, params_u, params_v, uv, per_span)
    return new, dev, reverse, max(dev.max, float(reverse[0].max()))
