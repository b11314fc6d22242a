"""The volumes and boundaries of the regions of two composed solids (004, issue 24), in
the math layer: from the curves of a :class:`~.compose.Composition`, without a B-rep.

**Volumes** by the divergence theorem. For a solid ``X`` with outward normal ``n`` and
any origin ``c``, ``V(X) = (1/3) integral_{dX} (x - c) . n dA``; the boundary of
``A n B`` is the part of ``dA`` inside ``B`` and the part of ``dB`` inside ``A``, so

.. math:: V(A \\cap B) = \\tfrac13 \\Big[\\int_{\\partial A \\cap B} (x - c)\\cdot n_A\\,dA
          + \\int_{\\partial B \\cap A} (x - c)\\cdot n_B\\,dA\\Big].

On one exterior face ``S(s, t)`` over ``[s_0, s_1] x [t_0, t_1]`` whose normal
``S_s x S_t`` points out of its solid times ``sigma = +-1`` (``u1``, ``v0``, ``w1`` of a
right-handed solid point out, 004 eq. 3.3 and :meth:`.NurbsVolume.boundary`), the part
inside the other solid is the image of a region ``R`` of the rectangle and

.. math:: \\int_{S(R)} (x - c)\\cdot n\\,dA = \\iint_R f\\,ds\\,dt, \\qquad
          f = \\sigma\\,(S - c)\\cdot(S_s \\times S_t) / 3 .

Green's theorem in the parameter plane turns it into a line integral: with
``F(s, t) = integral_{s_0}^{s} f(r, t) dr``, ``iint_R f = oint_{dR} F dt``, ``dR``
run with ``R`` on its left. ``F`` is a Gauss--Legendre rule on every knot span of
``s`` (``ceil(3 p / 2)`` points, exact for a polynomial face, plus
:data:`.volume_measure.RATIONAL_EXTRA` for a rational one), the line integral a
Gauss rule on every piece of the curve between its own knots and its crossings of
the face's knot lines (where ``F`` is only piecewise smooth). ``dR`` is made of

* the composition's curves on the face (their pcurves; a linear interpolant of the
  ``uv`` samples when a curve has none), each run forwards or backwards: the side of
  ``R`` is found by stepping a little to the left and to the right of the curve at a
  few parameters and inverting those points into the other solid (majority vote;
  a curve with the same answer on both sides, a tangency, bounds nothing);
* the pieces of the edge ``s = s_1`` between the curves' ends there that are inside
  (tested at a point just off the edge). The edge ``s = s_0`` has ``F = 0`` and the
  edges ``t = const`` have ``dt = 0``, so nothing else contributes -- which is why a
  curve ending on a seam or on another edge needs no more than that. A face no curve
  touches is the whole rectangle or nothing (the same test on its edge).

Then ``both = V(A n B)``, ``a_only = V(A) - both``, ``b_only = V(B) - both`` and
``union = V(A) + V(B) - both`` (:func:`region_volumes`). The pcurves are only within
the composition's ``tol`` of the intersection (a relative error ~1e-7 on the volume);
at every node of a curve's line integral the offset ``eta`` to the true intersection
along the curve's normal is found by Newton and the strip ``integral f eta |c'|^2``
taken off (:meth:`_FaceIntegral.line`), which leaves ``O(tol^2)``: 1e-13 on the tests.

**Boundaries** (:func:`boundary_pieces`): every exterior face is cut along its curves
(:func:`.face_split.split_face`) and each region is classified by a point just inside
it; a result's boundary is made of the pieces ``"union"``: ``dA`` outside ``B`` and
``dB`` outside ``A``; ``"common"``: ``dA`` inside ``B`` and ``dB`` inside ``A``;
``"A-B"``: ``dA`` outside ``B`` and ``dB`` inside ``A`` reversed. A closed face cut
across its seam gives a region on either side of the seam (two pieces for one cap).
The pieces are bounded by the pcurves as they are (no correction): their areas and
fluxes (:meth:`BoundaryPiece.area`, :meth:`BoundaryPiece.flux`) are within ~1e-7.

Not handled: faces of ``A`` and ``B`` that overlap (coincident surfaces have no
intersection curve and their points are on both boundaries), curves running along a
face's edges, and splits :func:`.face_split.split_face` refuses (raised as
:class:`~surfprep.errors.InvalidGeometryError`).
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..basis import distinct_knots
from ..curve import NurbsCurve
from ..face_split import Cut, split_face
from ..surface import NurbsSurface
from ..trimmed import TrimmedFace
from ..volume import NurbsVolume
from ..volume_measure import OUTWARD, RATIONAL_EXTRA, handedness

if TYPE_CHECKING:                                        # pragma: no cover
    from .compose import Composition

__all__ = ["BOUNDARIES", "BoundaryPiece", "RegionVolumes", "boundary_pieces",
           "face_integral", "region_volumes"]

#: the boundaries :func:`boundary_pieces` builds
BOUNDARIES = ("A", "B", "union", "common", "A-B")
#: Gauss points per piece of a curve in the line integral, at least
CURVE_GAUSS = 8
#: probes step this many times the composition's tolerance off a curve or an edge
PROBE_STEP = 64.0
#: where along a curve (fractions of its parameter range) its sides are probed
PROBE_FRACTIONS = (0.1, 0.3, 0.5, 0.7, 0.9)
#: safeguarded Newton steps for a pcurve's crossing of a knot line
CROSSING_STEPS = 12
#: the end of one curve and the start of the next nearer than this times tol: one point
JUNCTION = 64.0


@functools.cache
def _legendre(n: int) -> tuple[NDArray, NDArray]:
    return np.polynomial.legendre.leggauss(n)


def _outward_sign(volume: NurbsVolume, name: str, right: float | None = None) -> float:
    """``sigma``: +1 when the face's ``S_a x S_b`` points out of the solid, else -1."""
    right = handedness(volume) if right is None else right
    return 1.0 if (name in OUTWARD) == (right > 0) else -1.0


class _FaceIntegral:
    """``iint_R g ds dt`` over regions ``R`` of one face by Green's theorem (module doc):
    ``g = |S_s x S_t|`` (``"area"``) or ``sign (S - c) . (S_s x S_t) / 3`` (``"flux"``)."""

    def __init__(self, surface: NurbsSurface, kind: str, sign: float = 1.0,
                 origin: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        self.surface, self.kind, self.sign = surface, kind, float(sign)
        self.origin = np.asarray(origin, dtype=float)
        extra = RATIONAL_EXTRA if surface.weights is not None else 0
        p, q = surface.degree_u, surface.degree_v
        self.breaks_s = distinct_knots(surface.knots_u, p)[0]
        self.breaks_t = distinct_knots(surface.knots_v, q)[0]
        self.n_s = -(-3 * p // 2) + extra
        self.n_line = max(CURVE_GAUSS, -(-3 * (p + q) // 2)) + extra

    def integrand(self, s: NDArray, t: NDArray) -> NDArray:
        d = self.surface.derivatives(s, t, 1)
        normal = np.cross(d[..., 1, 0, :], d[..., 0, 1, :])
        if self.kind == "area":
            return np.linalg.norm(normal, axis=-1)
        return self.sign / 3.0 * np.einsum("...i,...i->...", d[..., 0, 0, :] - self.origin, normal)

    def antiderivative(self, s: NDArray, t: NDArray) -> NDArray:
        """``F(s, t) = integral_{s_0}^{s} g(r, t) dr`` for ``(m,)`` points, Gauss per span."""
        a, b = self.breaks_s[:-1], self.breaks_s[1:]
        half = 0.5 * (np.clip(s[:, None], a, b) - a)                       # (m, spans)
        row, col = np.nonzero(half > 0)
        out = np.zeros(s.size)
        if row.size:
            x, w = _legendre(self.n_s)
            h = half[row, col][:, None]
            nodes = a[col][:, None] + h * (x + 1.0)
            values = self.integrand(nodes, np.broadcast_to(t[row][:, None], nodes.shape))
            np.add.at(out, row, np.sum(values * w * h, axis=1))
        return out

    def _breaks(self, pcurve: NurbsCurve, lo: float, hi: float) -> NDArray:
        """``lo``, ``hi``, the pcurve's knots between and its crossings of the knot lines."""
        own = distinct_knots(pcurve.knots, pcurve.degree)[0]
        tau = np.unique(np.concatenate([np.linspace(lo, hi, 16 * own.size + 17),
                                        own[(own > lo) & (own < hi)]]))
        uv = pcurve.evaluate(tau)
        found = [tau[[0, -1]], own[(own > lo) & (own < hi)]]
        brackets = []                                  # (a, b, level, axis) of every crossing
        for axis, lines in ((0, self.breaks_s[1:-1]), (1, self.breaks_t[1:-1])):
            gap = uv[:, axis, None] - lines[None, :]                       # (n, lines)
            k, j = np.nonzero((gap[:-1] < 0) != (gap[1:] < 0))
            brackets.append((tau[k], tau[k + 1], lines[j], np.full(k.size, axis)))
        a, b, level, axis = (np.concatenate(x) for x in zip(*brackets))
        if a.size:
            found.append(_crossings(pcurve, a, b, level, axis))
        out = np.unique(np.concatenate(found))
        return out[np.concatenate([[True], np.diff(out) > 1e-13 * max(hi - lo, 1e-300)])]

    def line(self, pcurve: NurbsCurve, lo: float | None = None, hi: float | None = None,
             partner: tuple[NurbsSurface, NurbsCurve] | None = None, tol: float = 0.0) -> float:
        """``integral F(c(tau)) t'(tau) dtau`` along the pcurve ``c = (s, t)`` from ``lo`` to
        ``hi`` (its domain by default).

        With ``partner = (surface, pcurve)``, the other surface of an intersection curve
        and the curve's pcurve on it (same parameter), the strip between ``c`` and the
        true intersection is taken off: at every node ``S(c + eta m) = S'(p, q)`` is
        solved by Newton for ``(eta, p, q)``, ``m = (-t', s')`` the left normal, and
        ``integral g(c) eta |c'|^2 dtau`` (the region on the left loses that strip) is
        subtracted, which leaves an error of the order of the curve's deviation squared.
        ``eta`` is 0 where Newton does not converge or moves more than ``16 tol``.
        """
        d0, d1 = pcurve.domain
        lo, hi = d0 if lo is None else lo, d1 if hi is None else hi
        brk = self._breaks(pcurve, lo, hi)
        x, w = _legendre(self.n_line)
        half = 0.5 * np.diff(brk)[:, None]
        tau = ((0.5 * (brk[:-1] + brk[1:]))[:, None] + half * x).reshape(-1)
        d = pcurve.derivatives(tau, 1)
        values = self.antiderivative(d[:, 0, 0], d[:, 0, 1]) * d[:, 1, 1]
        if partner is not None:
            eta = self._offsets(d, tau, *partner, tol)
            values -= self.integrand(d[:, 0, 0], d[:, 0, 1]) * eta * np.sum(d[:, 1] ** 2, axis=1)
        return float(np.sum(values * (half * w).reshape(-1)))

    def _offsets(self, d: NDArray, tau: NDArray, other: NurbsSurface, other_pcurve: NurbsCurve,
                 tol: float) -> NDArray:
        """``eta (m,)`` with ``S(c + eta m) = S'(p, q)`` (:meth:`line`), 0 where not found."""
        m = np.column_stack([-d[:, 1, 1], d[:, 1, 0]])
        pq = other_pcurve.evaluate(tau)
        q0, q1, r0, r1 = other.domain
        eta = np.zeros(tau.size)
        residual = np.full(tau.size, np.inf)
        for _ in range(5):
            uv = d[:, 0] + eta[:, None] * m
            ds = self.surface.derivatives(uv[:, 0], uv[:, 1], 1)
            do = other.derivatives(pq[:, 0], pq[:, 1], 1)
            g = ds[:, 0, 0] - do[:, 0, 0]
            residual = np.linalg.norm(g, axis=1)
            jac = np.stack([m[:, :1] * ds[:, 1, 0] + m[:, 1:] * ds[:, 0, 1], -do[:, 1, 0],
                            -do[:, 0, 1]], axis=2)
            det = np.linalg.det(jac)
            ok = np.abs(det) > 1e-12 * np.prod(np.linalg.norm(jac, axis=1), axis=1)
            step = np.zeros((tau.size, 3))
            step[ok] = np.linalg.solve(jac[ok], -g[ok][:, :, None])[:, :, 0]
            eta += step[:, 0]
            pq = np.column_stack([np.clip(pq[:, 0] + step[:, 1], q0, q1),
                                  np.clip(pq[:, 1] + step[:, 2], r0, r1)])
        uv = d[:, 0] + eta[:, None] * m
        moved = np.linalg.norm(self.surface.evaluate(uv[:, 0], uv[:, 1])
                               - self.surface.evaluate(d[:, 0, 0], d[:, 0, 1]), axis=1)
        good = (residual <= max(1e-3 * tol, 1e-13)) & (moved <= 16.0 * tol)
        return np.where(good, eta, 0.0)


def _crossings(pcurve: NurbsCurve, a: NDArray, b: NDArray, level: NDArray, axis: NDArray
               ) -> NDArray:
    """Parameters where coordinate ``axis`` of the pcurve equals ``level``, one in each
    bracket ``[a, b]`` (a sign change): safeguarded Newton from the secant's root, all
    brackets at once, bisection where a step would leave its bracket."""
    rows = np.arange(a.size)
    fa = pcurve.evaluate(a)[rows, axis] - level
    fb = pcurve.evaluate(b)[rows, axis] - level
    x = np.where(fb != fa, a - fa * (b - a) / np.where(fb != fa, fb - fa, 1.0), 0.5 * (a + b))
    for _ in range(CROSSING_STEPS):
        d = pcurve.derivatives(x, 1)
        f, df = d[rows, 0, axis] - level, d[rows, 1, axis]
        below = (f < 0) == (fa < 0)                  # x on a's side: the root lies above it
        a, b = np.where(below, x, a), np.where(below, b, x)
        fa = np.where(below, f, fa)
        step = x - f / np.where(df != 0, df, np.inf)
        inside = (step >= a) & (step <= b) & np.isfinite(step)
        x = np.where(f == 0, x, np.where(inside, step, 0.5 * (a + b)))
    return x


def _segment(a: ArrayLike, b: ArrayLike) -> NurbsCurve:
    """The straight pcurve from ``a`` to ``b`` on ``[0, 1]``."""
    return NurbsCurve.construct_fast(np.array([a, b], dtype=float), np.array([0.0, 0, 1, 1]), 1)


def _pcurve(curve, side: int) -> NurbsCurve:
    """The curve's pcurve on A (``side`` 0) or B: its interpolant, else the polyline of its
    samples on its parameters (closed by the first sample when the curve is closed)."""
    pcurve = curve.pcurve_a if side == 0 else curve.pcurve_b
    if pcurve is not None:
        return pcurve
    uv = curve.uv_a if side == 0 else curve.uv_b
    if uv is None:
        raise InvalidGeometryError("an intersection curve has no parameters on a face")
    uv = np.vstack([uv, uv[:1]]) if curve.closed else np.asarray(uv, dtype=float)
    t = np.asarray(curve.parameters, dtype=float)[:uv.shape[0]]
    return NurbsCurve(uv, np.concatenate([t[:1], t, t[-1:]]), 1)


def _on_face(composition: Composition, side: int, name: str) -> list[tuple[str, object]]:
    """The composition's curves on face ``name`` of A (``side`` 0) or B, each with the name
    of the face of the other solid it lies on."""
    return [((fa, fb)[1 - side], curve) for fa, fb, curve in composition.curves
            if (fa, fb)[side] == name]


def _uv_step(surface: NurbsSurface, uv: NDArray, direction: NDArray, length: float) -> NDArray:
    """Parameter steps ``(m,)`` along unit ``direction (m, 2)`` that move ``length`` in space
    (at most 1 % of the domain's smaller side)."""
    s0, s1, t0, t1 = surface.domain
    d = surface.derivatives(uv[:, 0], uv[:, 1], 1)
    speed = np.linalg.norm(direction[:, :1] * d[:, 1, 0] + direction[:, 1:] * d[:, 0, 1], axis=1)
    cap = 0.01 * min(s1 - s0, t1 - t0)
    with np.errstate(divide="ignore"):
        return np.minimum(np.where(speed > 0, length / speed, cap), cap)


def _side_probes(surface: NurbsSurface, pcurve: NurbsCurve, length: float
                 ) -> tuple[NDArray, NDArray, NDArray]:
    """Points in ``(u, v)`` just left and just right of a curve at :data:`PROBE_FRACTIONS`,
    and whether both are in the domain."""
    lo, hi = pcurve.domain
    d = pcurve.derivatives(lo + (hi - lo) * np.asarray(PROBE_FRACTIONS), 1)
    tangent = d[:, 1] / np.maximum(np.linalg.norm(d[:, 1], axis=1, keepdims=True), 1e-300)
    left = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    step = _uv_step(surface, d[:, 0], left, length)[:, None]
    a, b = d[:, 0] + step * left, d[:, 0] - step * left
    lo, hi = np.array(surface.domain[0::2]), np.array(surface.domain[1::2])
    return a, b, np.all((a >= lo) & (a <= hi) & (b >= lo) & (b <= hi), axis=1)


def _share_probes(surface: NurbsSurface, pcurves: list[NurbsCurve], closed: list[bool],
                  length: float) -> tuple[NDArray, NDArray, NDArray]:
    """The points of one face to classify: left and right of every curve
    (:func:`_side_probes`), then one just inside each piece of the edge ``s = s1`` between
    the curves' ends there. Returns them ``(k, 2)``, which side probes are valid and the
    pieces' ends ``ts``."""
    s0, s1, t0, t1 = surface.domain
    probes, valid = [np.zeros((0, 2))], [np.zeros(0, bool)]
    for pc in pcurves:
        a, b, ok = _side_probes(surface, pc, length)
        probes += [a, b]
        valid.append(ok)
    ends = [pc.evaluate(np.array(pc.domain)) for pc, c in zip(pcurves, closed) if not c]
    ends = np.concatenate(ends) if ends else np.zeros((0, 2))
    at_edge = ends[np.abs(ends[:, 0] - s1) <= 1e-6 * (s1 - s0), 1]
    ts = np.unique(np.concatenate([[t0, t1], np.clip(at_edge, t0, t1)]))
    ts = ts[np.concatenate([[True], np.diff(ts) > 1e-12 * (t1 - t0)])]
    ts[-1] = t1
    mids = np.column_stack([np.full(ts.size - 1, s1), 0.5 * (ts[:-1] + ts[1:])])
    mids[:, 0] -= _uv_step(surface, mids, np.tile([-1.0, 0.0], (mids.shape[0], 1)), length)
    return np.concatenate(probes + [mids]), np.concatenate(valid), ts


def _share(integral: _FaceIntegral, pcurves: list[NurbsCurve], partners: list, valid: NDArray,
           ts: NDArray, inside: NDArray, tol: float) -> float:
    """``iint_R f`` over the part ``R`` of a face inside the other solid, from the
    classification ``inside`` of the probes of :func:`_share_probes` (module doc)."""
    n = len(PROBE_FRACTIONS)
    s1 = integral.surface.domain[1]
    total = 0.0
    runs = []
    for k, pc in enumerate(pcurves):
        left, right = inside[2 * k * n:(2 * k + 1) * n], inside[(2 * k + 1) * n:(2 * k + 2) * n]
        vote = int(np.sum((left.astype(int) - right.astype(int))[valid[k * n:(k + 1) * n]]))
        if vote:
            total += (1.0 if vote > 0 else -1.0) * integral.line(pc, partner=partners[k], tol=tol)
            ends = pc.evaluate(np.array(pc.domain))
            runs.append(ends if vote > 0 else ends[::-1])
    total += _junctions(integral, runs, tol)
    for (ta, tb), keep in zip(itertools.pairwise(ts), inside[inside.size - ts.size + 1:]):
        if keep:
            total += integral.line(_segment((s1, ta), (s1, tb)))
    return total


def _junctions(integral: _FaceIntegral, runs: list[NDArray], tol: float) -> float:
    """``oint F dt`` over the short gaps where one curve of the region's boundary ends and
    the next begins: two intersection curves meeting where the curve passes from one face
    of the other solid to the next end within ``tol`` of each other, not exactly at one
    point, and ``dR`` must close there (else an error of ``tol`` times the region's size).

    ``runs`` are the oriented curves' ``(start, end)`` in ``(u, v)``; each end is joined
    to the nearest start within :data:`JUNCTION` ``tol`` in space and a thousandth of
    the domain in ``(u, v)`` (a seam's two sides are far apart in ``(u, v)``)."""
    if not runs:
        return 0.0
    s0, s1, t0, t1 = integral.surface.domain
    ends = np.array([r[1] for r in runs])
    starts = np.array([r[0] for r in runs])
    x_end = integral.surface.evaluate(ends[:, 0], ends[:, 1])
    x_start = integral.surface.evaluate(starts[:, 0], starts[:, 1])
    space = np.linalg.norm(x_end[:, None] - x_start[None], axis=2)
    scale = np.array([s1 - s0, t1 - t0])
    plane = np.max(np.abs(ends[:, None] - starts[None]) / scale, axis=2)
    space[(space > JUNCTION * tol) | (plane > 1e-3)] = np.inf
    total = 0.0
    for i in range(len(runs)):
        j = int(np.argmin(space[i]))
        if np.isfinite(space[i, j]) and np.any(ends[i] != starts[j]):
            total += integral.line(_segment(ends[i], starts[j]))
    return total


@dataclass(frozen=True)
class RegionVolumes:
    """Volumes of the regions of two composed solids (model units cubed).

    Attributes
    ----------
    a_only, b_only, both, union : float
        ``V(A - B)``, ``V(B - A)``, ``V(A n B)``, ``V(A u B)``.
    """

    a_only: float
    b_only: float
    both: float
    union: float

    def as_dict(self) -> dict:
        return {"A only": self.a_only, "B only": self.b_only, "both": self.both,
                "union": self.union}


def region_volumes(composition: Composition) -> RegionVolumes:
    """Volumes of "A only", "B only", "both" and the union by the divergence theorem over
    the faces' parts inside the other solid (module doc).

    Parameters
    ----------
    composition : Composition

    Returns
    -------
    RegionVolumes

    Raises
    ------
    InvalidGeometryError
        A solid without orientation (``det J = 0`` at its centre), a curve without
        parameters on a face.
    """
    a, b, tol = composition.a, composition.b, composition.tol
    box = np.vstack([a.bounding_box(), b.bounding_box()])
    origin = 0.5 * (box.min(axis=0) + box.max(axis=0))
    faces = (a.exterior_faces(), b.exterior_faces())
    both = 0.0
    for side, (own, other) in enumerate(((a, b), (b, a))):
        right = handedness(own)
        jobs, probes = [], []
        for name, surface in faces[side].items():
            curves = _on_face(composition, side, name)
            pcurves = [_pcurve(c, side) for _, c in curves]
            partners = [(faces[1 - side][other_face], _pcurve(c, 1 - side))
                        for other_face, c in curves]
            uv, valid, ts = _share_probes(surface, pcurves, [c.closed for _, c in curves],
                                          PROBE_STEP * tol)
            integral = _FaceIntegral(surface, "flux", _outward_sign(own, name, right), origin)
            jobs.append((integral, pcurves, partners, valid, ts, uv.shape[0]))
            probes.append(surface.evaluate(uv[:, 0], uv[:, 1]))
        if not jobs:
            continue
        inside = other.invert(np.concatenate(probes), tol=tol).inside       # one call per solid
        start = 0
        for integral, pcurves, partners, valid, ts, count in jobs:
            both += _share(integral, pcurves, partners, valid, ts, inside[start:start + count], tol)
            start += count
    va, vb = float(a.volume()), float(b.volume())
    return RegionVolumes(va - both, vb - both, both, va + vb - both)


def face_integral(face: TrimmedFace, kind: str = "area", origin: ArrayLike = (0.0, 0.0, 0.0)
                  ) -> float:
    """``integral dA`` (``kind="area"``) or ``(1/3) integral (x - c) . n dA`` (``"flux"``,
    ``n`` the face's normal: ``S_u x S_v``, opposite when ``face.reversed``) over a trimmed
    face, by Green's theorem along its loops (module doc: ``oint F dv`` over every edge's
    pcurve, degenerated edges included). A face without loops is its whole surface."""
    if kind not in ("area", "flux"):
        raise InvalidGeometryError(f"kind must be 'area' or 'flux', got {kind!r}")
    integral = _FaceIntegral(face.surface, kind, -1.0 if face.reversed else 1.0, origin)
    if not face.loops:
        _, u1, v0, v1 = face.surface.domain
        return integral.line(_segment((u1, v0), (u1, v1)))
    total = 0.0
    for edge in face.edges:
        value = integral.line(edge.pcurve, edge.t0, edge.t1)
        total += -value if edge.reversed else value
    return total


@dataclass(frozen=True, eq=False)
class BoundaryPiece:
    """A piece of the boundary of a composed result.

    Attributes
    ----------
    operand : str
        ``"A"`` or ``"B"``: the solid whose exterior face it is part of.
    face_name : str
        That face (``"u1"``...).
    face : TrimmedFace
        The region of the face's surface, its ``reversed`` set so that its normal
        points out of the result.
    reversed : bool
        The normal is the opposite of the operand's outward normal (``B`` inside ``A``
        in ``"A-B"``).
    inside_other : bool
        The piece lies inside the other solid.
    """

    operand: str
    face_name: str
    face: TrimmedFace
    reversed: bool
    inside_other: bool

    def area(self) -> float:
        """Area of the piece (:func:`face_integral`)."""
        return face_integral(self.face, "area")

    def flux(self, origin: ArrayLike = (0.0, 0.0, 0.0)) -> float:
        """``(1/3) integral (x - c) . n dA``, ``n`` out of the result: summed over the
        pieces of a closed boundary, the volume it bounds (:func:`face_integral`)."""
        return face_integral(self.face, "flux", origin)


def _check_which(which: str) -> str:
    if which not in BOUNDARIES:
        raise InvalidGeometryError(f"which must be one of {', '.join(map(repr, BOUNDARIES))}, "
                                   f"got {which!r}")
    return which


def _wanted(which: str, operand: str, inside: bool) -> tuple[bool, bool]:
    """Whether a piece of ``operand`` inside (or outside) the other solid bounds the result
    ``which``, and whether its normal is flipped."""
    if which in ("A", "B"):
        return operand == which, False
    if which == "union":
        return not inside, False
    if which == "common":
        return inside, False
    return (not inside, False) if operand == "A" else (inside, True)      # A-B


def _interior_probe(region: TrimmedFace, length: float) -> NDArray:
    """A point ``(2,)`` just inside a region: left of the middle of the longest edge of
    its outer loop (the loops keep the region on their left)."""
    best, best_len = None, -1.0
    for edge in region.loops[region.outer_loop_index].edges:
        if edge.degenerated:
            continue
        ends = edge.pcurve.evaluate(np.array([edge.t0, edge.t1]))
        size = float(np.linalg.norm(ends[1] - ends[0]))
        if size > best_len:
            best, best_len = edge, size
    if best is None:
        raise InvalidGeometryError("a region of a split face has only degenerated edges")
    d = best.pcurve.derivatives(np.array([0.5 * (best.t0 + best.t1)]), 1)[0]
    tangent = -d[1] if best.reversed else d[1]
    left = np.array([[-tangent[1], tangent[0]]]) / max(float(np.linalg.norm(tangent)), 1e-300)
    return d[0] + _uv_step(region.surface, d[:1], left, length)[0] * left[0]


def boundary_pieces(composition: Composition, which: str) -> list[BoundaryPiece]:
    """The pieces of the exterior faces that bound ``which`` (module doc).

    Parameters
    ----------
    composition : Composition
    which : {"A", "B", "union", "common", "A-B"}
        ``"A"`` / ``"B"``: every piece of that solid's boundary (split along the curves,
        classified); the others: the boundary of that result.

    Returns
    -------
    list of BoundaryPiece
        A's pieces then B's, face by face.

    Raises
    ------
    InvalidGeometryError
        An unknown ``which``; a face :func:`.face_split.split_face` cannot split along
        its curves (the message names the face).
    """
    _check_which(which)
    pieces = []
    length = PROBE_STEP * composition.tol
    for side, (operand, own, other) in enumerate((("A", composition.a, composition.b),
                                                  ("B", composition.b, composition.a))):
        if which in ("A", "B") and operand != which:
            continue
        right = handedness(own)
        found = []
        for name, surface in own.exterior_faces().items():
            curves = [c for _, c in _on_face(composition, side, name)]
            cuts = [Cut(_pcurve(c, side),
                        c.curve3d if (c.pcurve_a, c.pcurve_b)[side] is not None else None)
                    for c in curves]
            try:
                regions = split_face(TrimmedFace(surface, name=name), cuts,
                                     tol3d=16.0 * composition.tol)
            except InvalidGeometryError as exc:
                raise InvalidGeometryError(f"face {name} of {operand} cannot be split along its "
                                           f"{len(cuts)} curve(s): {exc}") from exc
            outward = _outward_sign(own, name, right) > 0
            found += [(name, outward, r, surface.evaluate(*_interior_probe(r, length)))
                      for r in regions]
        if not found:
            continue
        inside = other.invert(np.array([f[3] for f in found]), tol=composition.tol).inside
        for (name, outward, region, _), ins in zip(found, inside):
            keep, flip = _wanted(which, operand, bool(ins))
            if keep:
                face = TrimmedFace(region.surface, region.loops, region.outer_loop_index,
                                   outward == flip, name)
                pieces.append(BoundaryPiece(operand, name, face, flip, bool(ins)))
    return pieces
