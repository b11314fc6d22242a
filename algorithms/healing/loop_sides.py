"""The outer loop of a face cut into sides: the pieces of its edges between loop
positions, joined, measured and checked (what :mod:`.decompose` lays its four-sided
sub-patches out with).

A loop is a sequence of :class:`LoopEdge` (3D curve and pcurve, oriented along the
loop); a loop position is ``(edge, t)``. :func:`loop_pieces` lists the edge pieces
between two positions, :func:`loop_side` joins them into one 3D curve and one pcurve
with dense samples of their arc length; :func:`extra_cuts` spreads positions along the
loop; :func:`spoke_curve` maps a straight line of the face's parameters onto its
surface; :func:`check_quad` refuses a sub-patch whose Coons map folds in ``(u, v)``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..curve import NurbsCurve
from ..fitting import interpolate_curve

__all__ = [
    "CHECK_SAMPLES",
    "DENSE",
    "SPOKE_SAMPLES",
    "TANGENT_REACH",
    "LoopEdge",
    "LoopSide",
    "NotDecomposableError",
    "check_quad",
    "coons_cells",
    "end_tangent",
    "extra_cuts",
    "join_curves",
    "loop_pieces",
    "loop_side",
    "polyline_lengths",
    "restricted_curve",
    "reverse_curve",
    "signed_area",
    "spoke_curve",
    "turning_angles",
    "uniform_uv",
    "uv_segment",
]

#: tangents at a vertex: chord to the point this fraction of the edge's end-to-end distance away
TANGENT_REACH = 0.01
#: samples of a spoke in (u, v) interpolated in 3D
SPOKE_SAMPLES = 33
#: samples per side of the (u, v) Coons check of a sub-patch
CHECK_SAMPLES = 16
#: parameter samples per edge for arc lengths and outlines
DENSE = 65


class NotDecomposableError(InvalidGeometryError):
    """The face cannot be split into four-sided sub-patches; ``str()`` is the reason."""


@dataclass(frozen=True, eq=False)
class LoopEdge:
    """One edge of a face's outer loop, oriented along the loop.

    Attributes
    ----------
    curve : NurbsCurve (3D) or None
        None for a degenerated edge (a surface pole).
    pcurve : NurbsCurve (2D)
        Same parameter and direction as ``curve``.
    """

    curve: NurbsCurve | None
    pcurve: NurbsCurve



# ------------------------------------------------------------------ curves
def reverse_curve(curve: NurbsCurve) -> NurbsCurve:
    """The same curve run the other way, on the same domain."""
    a, b = curve.domain
    knots = a + b - curve.knots[::-1]
    weights = None if curve.weights is None else curve.weights[::-1]
    return NurbsCurve(curve.control_points[::-1], knots, curve.degree, weights)


def join_curves(curves: Sequence[NurbsCurve]) -> NurbsCurve:
    """Exact C0 join of curves meeting end to end: degrees raised to the largest,
    domains laid end to end, each piece's weights scaled to match at the joint
    (a homogeneous scaling leaves a rational curve unchanged), tiny gaps closed
    at their midpoint."""
    if len(curves) == 1:
        return curves[0]
    degree = max(c.degree for c in curves)
    rational = any(c.is_rational for c in curves)
    pws, knots, scale = [], [], 1.0
    for n, c in enumerate(curves):
        c = c.clamp()
        c = c.elevate_degree(degree - c.degree) if c.degree < degree else c
        pw = (c.homogeneous_points() if rational
              else np.column_stack([c.control_points, np.ones(c.n_control)]))
        k = np.asarray(c.knots, float)
        if n:
            pw *= scale / pw[0, -1]
            pws[-1][-1] = 0.5 * (pws[-1][-1] + pw[0])
            pw, k = pw[1:], k[degree + 1:] + (knots[-1][-1] - k[0])
            knots[-1] = knots[-1][:-1]          # the joint stays ``degree`` times
        scale = pw[-1, -1]
        pws.append(pw)
        knots.append(k)
    pw, kv = np.concatenate(pws), np.concatenate(knots)
    if rational:
        return NurbsCurve.from_homogeneous(pw, kv, degree)
    return NurbsCurve(pw[:, :-1], kv, degree)


def turning_angles(edges: Sequence[LoopEdge]) -> NDArray:
    """(m,) float: the angle (radians) between the end tangent of real edge ``k - 1``
    and the start tangent of real edge ``k`` (cyclic; a degenerated edge between them,
    a surface pole, is skipped: the 3D tangents meet there as at any vertex)."""
    real = [e.curve for e in edges if e.curve is not None]
    t_in = np.roll(np.array([end_tangent(c, 1) for c in real]), 1, axis=0)
    t_out = np.array([end_tangent(c, 0) for c in real])
    denom = np.linalg.norm(t_in, axis=1) * np.linalg.norm(t_out, axis=1)
    cos = np.einsum("kc,kc->k", t_in, t_out) / np.where(denom > 0, denom, 1.0)
    return np.where(denom > 0, np.arccos(np.clip(cos, -1.0, 1.0)), np.pi)


def end_tangent(curve: NurbsCurve, end: int) -> NDArray:
    """(3,) float: the curve's direction at its start (``end = 0``) or end (1), along
    the curve, as the chord to the first point :data:`TANGENT_REACH` of the edge's
    length away: a vanishing or wild end derivative (repeated or nearly repeated
    control points of high-degree edges, tiny hooks) does not fake a cusp."""
    t0, t1 = curve.domain
    steps = np.geomspace(1e-7, 1.0, 60) * (t1 - t0)
    t = t1 - steps if end else t0 + steps
    pts = curve.evaluate(np.r_[t1 if end else t0, t])
    reach = np.linalg.norm(pts[1:] - pts[0], axis=1)
    k = int(np.argmax(reach >= TANGENT_REACH * reach[-1])) if reach[-1] > 0 else 0
    chord = pts[k + 1] - pts[0]
    return -chord if end else chord


# ------------------------------------------------------------ loop positions
@dataclass(frozen=True, eq=False)
class LoopSide:
    """A chain of edge pieces ``(edge, t_start, t_end)`` between two loop positions,
    its joined 3D curve and dense samples (3D arc length ``(k,)``, uv ``(k, 2)``,
    piece index and parameter ``(k,)``)."""

    pieces: tuple
    curve: NurbsCurve
    length: NDArray
    uv: NDArray
    piece: NDArray
    t: NDArray
    pcurve: NurbsCurve | None = None

    def locate(self, s: float) -> tuple[int, float]:
        """Loop position ``(edge, t)`` at arc length ``s`` along the side."""
        j = int(np.clip(np.searchsorted(self.length, s) - 1, 0, self.length.size - 2))
        if self.piece[j] != self.piece[j + 1]:
            j += 1 if j + 2 < self.length.size else -1
        span = self.length[j + 1] - self.length[j]
        w = 0.0 if span <= 0 else float(np.clip((s - self.length[j]) / span, 0, 1))
        k = self.pieces[int(self.piece[j])][0]
        return k, float((1 - w) * self.t[j] + w * self.t[j + 1])


def restricted_curve(curve: NurbsCurve, a: float, b: float) -> NurbsCurve:
    """The curve between ``a`` and ``b`` (itself when that is its whole domain)."""
    t0, t1 = curve.domain
    eps = 1e-12 * (t1 - t0)
    if a <= t0 + eps and b >= t1 - eps:
        return curve
    return curve.restrict(max(a, t0), min(b, t1))


def loop_pieces(real: Sequence[LoopEdge], a: tuple[int, float], b: tuple[int, float]) -> list:
    """Edge pieces ``(edge, t0, t1)`` along the loop from position ``a`` to ``b``."""
    (ka, ta), (kb, tb) = a, b
    if ka == kb and tb > ta:
        return [(ka, ta, tb)]
    out = [(ka, ta, real[ka].curve.domain[1])]
    k = (ka + 1) % len(real)
    while k != kb:
        out.append((k, *real[k].curve.domain))
        k = (k + 1) % len(real)
    out.append((kb, real[kb].curve.domain[0], tb))
    return [p for p in out if p[2] - p[1] > 1e-12 * np.ptp(real[p[0]].curve.domain)]


def loop_side(real: Sequence[LoopEdge], pieces: list) -> LoopSide:
    curve = join_curves([restricted_curve(real[k].curve, a, b) for k, a, b in pieces])
    xyz, uv, piece, ts = [], [], [], []
    for n, (k, a, b) in enumerate(pieces):
        t = np.linspace(a, b, DENSE)
        xyz.append(real[k].curve.evaluate(t))
        uv.append(real[k].pcurve.evaluate(t))
        piece.append(np.full(t.size, n))
        ts.append(t)
    xyz = np.concatenate(xyz)
    length = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))]
    pcurve = join_curves([restricted_curve(real[k].pcurve, a, b) for k, a, b in pieces])
    return LoopSide(tuple(pieces), curve, length, np.concatenate(uv), np.concatenate(piece),
                 np.concatenate(ts), pcurve)


def polyline_lengths(points: NDArray) -> NDArray:
    """``(m,)`` float: the length along a polyline ``(m, k)`` from its first point."""
    return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]


def uniform_uv(side_uv: NDArray, length: NDArray, n: int) -> NDArray:
    """(n + 1, 2) float: uv points at uniform arc length (eq. 4's sampling)."""
    s = np.linspace(0.0, length[-1], n + 1)
    return np.column_stack([np.interp(s, length, side_uv[:, 0]), np.interp(s, length, side_uv[:, 1])])


def extra_cuts(real: Sequence[LoopEdge], cuts: list, count: int) -> list:
    """``cuts`` completed to ``count`` loop positions, each new one at the middle (in
    arc length) of the longest stretch between positions."""
    lengths = np.array([np.sum(np.linalg.norm(np.diff(real[k].curve.evaluate(
        np.linspace(*real[k].curve.domain, DENSE)), axis=0), axis=1)) for k in range(len(real))])
    start = np.r_[0.0, np.cumsum(lengths)]
    total = start[-1]
    at = sorted(start[k] for k, _ in cuts) or [0.0]
    while len(at) < count:
        gaps = np.diff(np.r_[at, at[0] + total])
        g = int(np.argmax(gaps))
        at = sorted(at + [(at[g] + 0.5 * gaps[g]) % total])
    whole = loop_side(real, [(k, *real[k].curve.domain) for k in range(len(real))])
    return [whole.locate(s) for s in at]


# ------------------------------------------------------------------ checks
def coons_cells(sides_uv: Sequence[NDArray]) -> NDArray:
    """Signed areas ``(m, m)`` of the cells of the bilinearly blended Coons map (001
    eq. 4) of four uv sides (bottom, right, top, left, in loop order, ``(m + 1, 2)``)."""
    bottom, right, top, left = (np.asarray(s, float) for s in sides_uv)
    top, left = top[::-1], left[::-1]
    m = bottom.shape[0] - 1
    u = np.linspace(0, 1, m + 1)[:, None, None]
    v = np.linspace(0, 1, m + 1)[None, :, None]
    p00, p10, p11, p01 = bottom[0], bottom[-1], top[-1], top[0]
    x = ((1 - v) * bottom[:, None] + v * top[:, None] + (1 - u) * left[None] + u * right[None]
         - ((1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + u * v * p11 + (1 - u) * v * p01))
    d1 = x[1:, 1:] - x[:-1, :-1]
    d2 = x[:-1, 1:] - x[1:, :-1]
    return 0.5 * (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0])


def signed_area(poly: NDArray) -> float:
    """Signed area of a closed polygon ``(m, 2)`` (positive counter-clockwise)."""
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def check_quad(sides_uv: Sequence[NDArray], orientation: float, what: str) -> None:
    cells = coons_cells(sides_uv) * orientation
    if cells.min() < -1e-9 * np.abs(cells).sum():
        raise NotDecomposableError(
            f"{what}: its Coons map folds in (u, v) (a very non-convex outline)")


# ------------------------------------------------------------------ spokes
def spoke_curve(surface, centre: NDArray, mid_uv: NDArray, mid_xyz: NDArray
                ) -> tuple[NurbsCurve, NDArray]:
    """3D curve from the centre to a side midpoint along the uv line, and its uv
    samples ``(SPOKE_SAMPLES, 2)``."""
    s = np.linspace(0.0, 1.0, SPOKE_SAMPLES)[:, None]
    uv = (1 - s) * centre + s * mid_uv
    pts = surface.evaluate(uv[:, 0], uv[:, 1])
    pts[-1] = mid_xyz                      # the edge's point (on the surface within its tolerance)
    try:
        return interpolate_curve(pts), uv
    except DegenerateGeometryError:
        raise NotDecomposableError("a spoke runs where the surface collapses (its points "
                                   "coincide in space)") from None


def uv_segment(a: NDArray, b: NDArray) -> NurbsCurve:
    """The straight segment from ``a`` to ``b`` in ``(u, v)`` (a spoke's pcurve)."""
    return NurbsCurve(np.array([a, b], dtype=float), np.array([0.0, 0.0, 1.0, 1.0]), 1)
