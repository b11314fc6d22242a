"""Four-sided regions of a surface's parameters: what one structured block covers.

A :class:`Region` is a surface and four :class:`Side` s, each a curve in the
surface's ``(u, v)`` run in grid order: ``"j0"`` and ``"j1"`` run along i (the
first and last j-line), ``"i0"`` and ``"i1"`` along j. :meth:`Region.rectangle`
is the surface's whole parameter rectangle (its iso-lines as sides, i along u);
:meth:`Region.from_loop` is a trimmed face bounded by one loop of four edges (its
pcurves as sides). A side knows its length in space, places nodes at arc-length
fractions and finds where points of space lie along it, all by Gauss--Legendre
quadrature of ``|S_u u' + S_v v'|`` on a fine partition of its parameter (so a
side of the rectangle is measured exactly as its iso-curve is).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..arc_length_inversion import lengths_between, parameters_at_lengths
from ..curve import NurbsCurve
from ..surface import NurbsSurface
from ..trimmed import TrimmedFace

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

__all__ = ["SIDE_NAMES", "Region", "Side"]

SIDE_NAMES = ("j0", "j1", "i0", "i1")
#: cells of the parameter partition a side's length is integrated on (plus the pcurve's knots)
CELLS = 256
_NEWTON_STEPS = 4


@dataclass(frozen=True, eq=False)
class Side:
    """A curve in a surface's parameters, run from ``x = 0`` to ``x = 1``.

    Attributes
    ----------
    surface : NurbsSurface
    pcurve : NurbsCurve (2D)
        The curve in ``(u, v)``.
    t0, t1 : float
        The pcurve's parameters at ``x = 0`` and ``x = 1`` (``t1 < t0`` runs it backwards).
    """

    surface: NurbsSurface
    pcurve: NurbsCurve
    t0: float
    t1: float

    def t(self, x: ArrayLike) -> NDArray:
        """The pcurve parameter at normalized ``x`` in [0, 1]."""
        return self.t0 + np.asarray(x, dtype=float) * (self.t1 - self.t0)

    def uv(self, x: ArrayLike) -> NDArray:
        """``(n, 2)`` parameters of the surface at normalized ``x``."""
        return self.pcurve.evaluate(self.t(np.atleast_1d(x)))

    def points(self, x: ArrayLike) -> NDArray:
        """``(n, 3)`` points in space at normalized ``x``."""
        uv = self.uv(x)
        return self.surface.evaluate(uv[:, 0], uv[:, 1])

    def _speed(self, x: NDArray) -> NDArray:
        """``|d S(pcurve(t(x))) / dx|``."""
        d = self.pcurve.derivatives(self.t(x), 1)
        uv, duv = d[:, 0], d[:, 1] * (self.t1 - self.t0)
        s = self.surface.derivatives(uv[:, 0], uv[:, 1], 1)
        tangent = s[:, 1, 0] * duv[:, :1] + s[:, 0, 1] * duv[:, 1:]
        return np.linalg.norm(tangent, axis=1)

    @cached_property
    def table(self) -> tuple[NDArray, NDArray]:
        """Normalized parameters of a fine partition and the arc length at each."""
        lo, hi = sorted((self.t0, self.t1))
        knots = self.pcurve.knots[(self.pcurve.knots > lo) & (self.pcurve.knots < hi)]
        x = np.unique(np.concatenate([np.linspace(0.0, 1.0, CELLS + 1),
                                      (knots - self.t0) / (self.t1 - self.t0)]))
        return x, np.concatenate([[0.0], np.cumsum(lengths_between(self._speed, x[:-1], x[1:]))])

    @property
    def length(self) -> float:
        return float(self.table[1][-1])

    def at_fractions(self, fractions: ArrayLike) -> NDArray:
        """Normalized parameters ``x`` of the points at the given fractions of the length."""
        f = np.asarray(fractions, dtype=float)
        x, s = self.table
        length = s[-1]
        if not length > 0.0:
            return f.copy()                              # a collapsed side: spread in x
        out = parameters_at_lengths(self._speed, x, s, f * length, (f > 0) & (f < 1))
        out[f <= 0] = 0.0
        out[f >= 1] = 1.0
        return out

    def fractions_of(self, x: ArrayLike) -> NDArray:
        """Arc-length fractions of the points at normalized ``x`` (the inverse of
        :meth:`at_fractions`, to the table's interpolation)."""
        grid, s = self.table
        if not s[-1] > 0.0:
            return np.asarray(x, dtype=float).copy()
        return np.interp(np.asarray(x, dtype=float), grid, s) / s[-1]

    @cached_property
    def _dense(self) -> tuple[NDArray, NDArray, cKDTree]:
        from scipy.spatial import cKDTree
        x = np.linspace(0.0, 1.0, 4 * CELLS + 1)
        q = self.points(x)
        return x, q, cKDTree(q)

    def locate(self, points: ArrayLike) -> NDArray:
        """Normalized ``x`` of the points of the side nearest to ``points (n, 3)``: the foot on
        the two segments of a dense polyline of the side beside its nearest vertex, then
        Gauss--Newton on the side itself."""
        p = np.asarray(points, dtype=float)
        x, q, tree = self._dense
        nearest = tree.query(p)[1]
        best = np.full(p.shape[0], np.inf)
        out = x[nearest].copy()
        for k in (np.maximum(nearest - 1, 0), np.minimum(nearest, len(x) - 2)):     # the segments k, k + 1
            a, ab = q[k], q[k + 1] - q[k]
            w = np.clip(np.einsum("nc,nc->n", p - a, ab) / np.maximum(np.einsum("nc,nc->n", ab, ab), 1e-300),
                        0.0, 1.0)
            d = np.linalg.norm(p - (a + w[:, None] * ab), axis=1)
            closer = d < best
            best = np.where(closer, d, best)
            out = np.where(closer, x[k] + w * (x[k + 1] - x[k]), out)
        for _ in range(_NEWTON_STEPS):                 # Gauss-Newton on |P(x) - p|^2
            d = self.pcurve.derivatives(self.t(out), 1)
            uv, duv = d[:, 0], d[:, 1] * (self.t1 - self.t0)
            sd = self.surface.derivatives(uv[:, 0], uv[:, 1], 1)
            tangent = sd[:, 1, 0] * duv[:, :1] + sd[:, 0, 1] * duv[:, 1:]
            t2 = np.einsum("ij,ij->i", tangent, tangent)
            step = np.where(t2 > 0, np.einsum("ij,ij->i", p - sd[:, 0, 0], tangent) / np.maximum(t2, 1e-300),
                            0.0)
            out = np.clip(out + step, 0.0, 1.0)
        return out


def _segment(a: ArrayLike, b: ArrayLike) -> NurbsCurve:
    return NurbsCurve(np.array([a, b], dtype=float), np.array([0.0, 0.0, 1.0, 1.0]), 1)


@dataclass(frozen=True, eq=False)
class Region:
    """A four-sided region of a surface's parameters (see the module doc).

    Attributes
    ----------
    surface : NurbsSurface
    sides : dict of str to Side
        ``"j0"``, ``"j1"`` (run along i), ``"i0"``, ``"i1"`` (run along j); the
        corners shared (``j0`` starts where ``i0`` starts...).
    is_rectangle : bool
        The sides are the surface's boundary iso-lines, i along u.
    """

    surface: NurbsSurface
    sides: dict = field(default_factory=dict)
    is_rectangle: bool = False

    def sides_uv(self, x: dict) -> dict:
        """The ``(u, v)`` of nodes on the four sides, ``x[name]`` their normalized
        parameters (:class:`Side`): name to ``(n, 2)``, each corner the mean of its two
        sides' ends (a loop's pcurves meet to its tolerance), so they can be blended."""
        uv = {name: self.sides[name].uv(x[name]) for name in SIDE_NAMES}
        for a, ia, b, ib in (("j0", 0, "i0", 0), ("j0", -1, "i1", 0), ("j1", 0, "i0", -1),
                             ("j1", -1, "i1", -1)):
            uv[a][ia] = uv[b][ib] = 0.5 * (uv[a][ia] + uv[b][ib])
        return uv

    @classmethod
    def rectangle(cls, surface: NurbsSurface) -> Region:
        """The surface's whole parameter rectangle."""
        u0, u1, v0, v1 = surface.domain
        return cls(surface, {"j0": Side(surface, _segment((u0, v0), (u1, v0)), 0.0, 1.0),
                             "j1": Side(surface, _segment((u0, v1), (u1, v1)), 0.0, 1.0),
                             "i0": Side(surface, _segment((u0, v0), (u0, v1)), 0.0, 1.0),
                             "i1": Side(surface, _segment((u1, v0), (u1, v1)), 0.0, 1.0)}, True)

    @classmethod
    def from_loop(cls, face: TrimmedFace, *, clockwise: bool = False) -> Region:
        """The region of a face bounded by one loop of exactly four edges.

        The loop is taken counter-clockwise in ``(u, v)`` (``clockwise=True``: the
        other way, which reverses the blocks' orientation); ``j0`` is the edge whose
        chord runs most nearly along +u, then ``i1``, ``j1`` and ``i0`` follow round
        the loop, ``j1`` and ``i0`` run against it.

        Raises
        ------
        InvalidGeometryError
            Not one loop of four edges.
        """
        if len(face.loops) != 1 or len(face.loops[0].edges) != 4:
            raise InvalidGeometryError("the face is not bounded by one loop of four edges")
        runs = []
        for e in face.loops[0].edges:
            t0, t1 = (e.t1, e.t0) if e.reversed else (e.t0, e.t1)
            runs.append((e.pcurve, t0, t1))
        return cls.from_runs(face.surface, runs, clockwise=clockwise)

    @classmethod
    def from_runs(cls, surface: NurbsSurface, runs, *, clockwise: bool = False) -> Region:
        """The region inside four pcurves meeting end to end, as :meth:`from_loop` takes
        a face's loop (a four-sided sub-patch of a face that is not four-sided).

        Parameters
        ----------
        surface : NurbsSurface
        runs : sequence of four (NurbsCurve (2D), float, float)
            Each pcurve and the parameters it is run between, in loop order.
        clockwise : bool
        """
        runs = list(runs)
        if len(runs) != 4:
            raise InvalidGeometryError(f"a region has four sides, got {len(runs)}")
        face_domain = surface.domain
        ends = [pc.evaluate(np.array([a, b])) for pc, a, b in runs]
        area = sum(a[0, 0] * a[1, 1] - a[1, 0] * a[0, 1] for a in ends)    # shoelace over the chords
        if (area < 0) != clockwise:                                          # turn it the asked way
            runs = [(pc, b, a) for pc, a, b in reversed(runs)]
            ends = [e[::-1] for e in reversed(ends)]
        chords = [e[1] - e[0] for e in ends]
        span = np.array([np.ptp(face_domain[:2]), np.ptp(face_domain[2:])])
        along_u = [c[0] / span[0] / max(np.linalg.norm(c / span), 1e-300) for c in chords]
        k = int(np.argmax(along_u))
        order = [runs[(k + m) % 4] for m in range(4)]
        (p0, a0, b0), (p1, a1, b1), (p2, a2, b2), (p3, a3, b3) = order
        s = surface
        return cls(s, {"j0": Side(s, p0, a0, b0), "i1": Side(s, p1, a1, b1),
                       "j1": Side(s, p2, b2, a2), "i0": Side(s, p3, b3, a3)}, False)
