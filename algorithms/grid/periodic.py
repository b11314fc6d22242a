"""A closed face's seam inside an elliptic solve: the O-type grid solved across it.

A surface closed in one direction (a cylinder, a duct, a torus, a body of
revolution) has its rectangle's two sides in that direction on one curve, the
seam. Gridding the rectangle and holding the seam's nodes fixed, as a side of
the grid, kinks the grid lines there (35 degrees on a torus: the interior lines
move toward the inside of the tube while the seam's nodes stay put). Here the
seam is no side: its nodes are solved as interior nodes, their neighbours
across the seam being the lines beside the other copy of the seam.

The solve works on the grid padded with a ghost line before the first copy of
the seam (:meth:`Seam.pad`): the line before the last copy, a period back in the
parameters, so the sweep's stencil sees a continuous grid; the sweep moves the
first copy as an interior line and holds the ghost and the last copy, which are
set again from the lines they copy after every sweep (:meth:`Seam.sync`; each
node is solved once: periodic SOR with its wrap-around neighbours one sweep
late). The parameters are kept unwrapped (a seam node may step below ``u0``) and
wrapped into the domain only to evaluate the surface (:meth:`Seam.wrapped`).

Across the seam no side holds the distribution of the lines that run round the
face any more, and Thomas--Middlecoff's controls, taken from the sides, let the
harmonic lines drift (on a torus toward the inside of the tube: skewness 0.05 ->
0.39). The control of that family is therefore the one under which the start
grid solves the system (:func:`grid_controls`), averaged round the closed lines:
on a surface of revolution the start grid (uniform in arc length round it) is
then the solution, elsewhere the lines keep its distribution on average and are
smoothed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Seam", "grid_controls"]

#: the two copies of a seam are one curve when their nodes lie this close (fraction of
#: the surface's box diagonal)
SEAM_TOL = 1e-9


@dataclass(frozen=True)
class Seam:
    """The seam of a grid closed along ``axis`` (0: the i-lines close, sides i0 and i1 are
    one curve; 1: j0 and j1).

    Attributes
    ----------
    axis : int
    shift : (2,) float
        Parameter offset from the first copy of the seam to the last (the period).
    domain : (4,) float
        The surface's ``(u0, u1, v0, v1)``.
    """

    axis: int
    shift: tuple[float, float]
    domain: tuple[float, float, float, float]

    @classmethod
    def find(cls, parameters: NDArray, points: NDArray, domain, diag: float) -> Seam | None:
        """The seam of a start grid, or None.

        Parameters
        ----------
        parameters : (ni, nj, 2) float
        points : (ni, nj, 3) float
            The grid's nodes.
        domain : (4,) float
        diag : float
            The surface's size (box diagonal).

        The first direction whose two sides coincide node for node in space, with
        a constant parameter offset of a whole period of the domain, is the seam's.
        """
        u0, u1, v0, v1 = (float(x) for x in domain)
        for axis in (0, 1):
            first = np.take(points, 0, axis=axis)
            last = np.take(points, -1, axis=axis)
            if first.shape[0] < 3 or np.max(np.linalg.norm(first - last, axis=-1)) > SEAM_TOL * diag:
                continue
            offset = np.take(parameters, -1, axis=axis) - np.take(parameters, 0, axis=axis)
            shift = offset.mean(axis=0)
            spans = (u1 - u0, v1 - v0)
            whole = [abs(abs(shift[k]) - spans[k]) <= 1e-9 * spans[k] or abs(shift[k]) <= 1e-12 * spans[k]
                     for k in (0, 1)]
            if np.ptp(offset, axis=0).max() > 1e-9 * max(spans) or not all(whole) \
                    or not np.any(np.abs(shift) > 0.0):
                continue
            return cls(axis, (float(shift[0]), float(shift[1])), (u0, u1, v0, v1))
        return None

    def pad(self, s: NDArray, t: NDArray) -> tuple[NDArray, NDArray]:
        """Parameters (ni, nj) with a ghost line before the first copy of the seam: (ni + 1, nj)
        or (ni, nj + 1), unwrapped. The sweep then moves the first copy as an interior line
        and holds the ghost and the last copy, which :meth:`sync` sets from the lines they
        copy."""
        out = []
        for a, d in ((s, self.shift[0]), (t, self.shift[1])):
            a = np.moveaxis(a, self.axis, 0)
            padded = np.concatenate([a[-2:-1] - d, a], axis=0)
            out.append(np.ascontiguousarray(np.moveaxis(padded, 0, self.axis)))
        return out[0], out[1]

    def unpad(self, a: NDArray) -> NDArray:
        """A padded array without its ghost line: the grid's own (ni, nj, ...)."""
        b = np.moveaxis(a, self.axis, 0)[1:]
        return np.ascontiguousarray(np.moveaxis(b, 0, self.axis))

    def sync(self, s: NDArray, t: NDArray, x: NDArray | None = None) -> None:
        """Refresh, in place on padded arrays, the ghost (the line before the last copy of the
        seam, a period back) and the last copy (the first, a period on); ``x``: the nodes in
        space, when given."""
        for a, d in ((s, self.shift[0]), (t, self.shift[1])):
            b = np.moveaxis(a, self.axis, 0)
            b[0] = b[-2] - d
            b[-1] = b[1] + d
        if x is not None:
            b = np.moveaxis(x, self.axis, 0)
            b[0] = b[-2]
            b[-1] = b[1]

    def box(self) -> tuple[float, float, float, float]:
        """The sweep's clipping box: a period wider on the seam's parameter (unwrapped nodes)."""
        u0, u1, v0, v1 = self.domain
        du, dv = abs(self.shift[0]), abs(self.shift[1])
        return (u0 - du, u1 + du, v0 - dv, v1 + dv)

    def wrapped(self, s: NDArray, t: NDArray) -> tuple[NDArray, NDArray]:
        """Unwrapped parameters brought into the domain (to evaluate the surface)."""
        u0, u1, v0, v1 = self.domain
        out = []
        for a, lo, hi, d in ((s, u0, u1, self.shift[0]), (t, v0, v1, self.shift[1])):
            if d == 0.0:
                out.append(np.clip(a, lo, hi))
                continue
            span = hi - lo
            w = lo + np.mod(a - lo, span)
            # a node on the seam itself stays on the side it came from
            w = np.where(np.isclose(a, hi, rtol=0.0, atol=1e-12 * span), hi, w)
            out.append(w)
        return out[0], out[1]


def grid_controls(points: NDArray) -> tuple[NDArray, NDArray]:
    """The ``P``, ``Q`` under which the grid ``points`` (ni, nj, 3) solves the elliptic system.

    At every interior node the tangential part of
    ``g22 (r_xixi + P r_xi) - 2 g12 r_xieta + g11 (r_etaeta + Q r_eta) = 0`` with the
    differences of :mod:`.elliptic_kernels`: a 2 x 2 system for ``g22 P`` and ``g11 Q``
    in the basis ``r_xi``, ``r_eta`` (0 where the two are parallel).

    Returns
    -------
    P, Q : (ni - 2, nj - 2) float
    """
    xi = 0.5 * (points[2:, 1:-1] - points[:-2, 1:-1])
    eta = 0.5 * (points[1:-1, 2:] - points[1:-1, :-2])
    xixi = points[2:, 1:-1] - 2.0 * points[1:-1, 1:-1] + points[:-2, 1:-1]
    etaeta = points[1:-1, 2:] - 2.0 * points[1:-1, 1:-1] + points[1:-1, :-2]
    xieta = 0.25 * (points[2:, 2:] - points[2:, :-2] - points[:-2, 2:] + points[:-2, :-2])
    g11 = np.einsum("...k,...k->...", xi, xi)
    g22 = np.einsum("...k,...k->...", eta, eta)
    g12 = np.einsum("...k,...k->...", xi, eta)
    R = g22[..., None] * xixi - 2.0 * g12[..., None] * xieta + g11[..., None] * etaeta
    b1 = -np.einsum("...k,...k->...", R, xi)
    b2 = -np.einsum("...k,...k->...", R, eta)
    det = g11 * g22 - g12 * g12
    ok = (det > 1e-12 * np.maximum(g11 * g22, 1e-300)) & (g11 > 0.0) & (g22 > 0.0)
    det = np.where(ok, det, 1.0)
    a = (g22 * b1 - g12 * b2) / det                   # g22 P
    b = (g11 * b2 - g12 * b1) / det                   # g11 Q
    return (np.where(ok, a / np.where(ok, g22, 1.0), 0.0),
            np.where(ok, b / np.where(ok, g11, 1.0), 0.0))
