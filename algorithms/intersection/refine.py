"""Refinement of traced intersection points onto the exact surfaces (000 §29.4.6, 004 §6).

Point refinement — the auxiliary-plane method of Hosaka (eqs. 29.18–29.26),
vectorized over all points still active: per iteration one
``derivatives(u, v, 1)`` call per surface, then

* the unit normals ``n_p``, ``n_q`` and the tangent planes ``F_p``, ``F_q``
  (29.18: ``d_p = n_p . p``, ``d_q = n_q . q``);
* the plane ``F_n`` orthogonal to both (29.19–29.20, ``n_n = n_p x n_q / |.|``),
  through the midpoint of ``p`` and ``q`` or through a fixed *anchor* (then the
  point converges to where the curve crosses the normal plane at the anchor);
* the intersection ``x`` of the three planes (29.21, written with the standard
  three-plane formula ``x = (d_p n_q x n_n + d_q n_n x n_p + d_n n_p x n_q) /
  [n_p, n_q, n_n]``; the printed first term ``n_q x n_p`` is a misprint);
* the parameter increments (29.22–29.25): ``dw = (r_t x n) . dp / (r_t x n) . r_w``
  and likewise, each surface with its *own* normal (the printed labels swap the
  two surfaces). ``(r_t x n, r_w x n)`` scaled this way is the dual basis of
  ``(r_w, r_t)`` in the tangent plane, so these increments are exactly the
  least-squares solution of ``J d = dp`` (``J = [r_w r_t]``): the orthogonal
  projection of ``dp`` onto the tangent plane, in coordinates. We use the
  paper's form; where ``|r_w x r_t|`` vanishes (a pole) the 2x2 system is
  singular and the pseudo-inverse ``J^+ dp`` is used instead.

004 §6 builds the third plane through the mesh point and its two projections
instead; Hosaka's ``F_n`` is used here because with an anchor it fixes where along
the curve a point lands, which the chord-midpoint insertion relies on.

Iteration stops per point when ``|p - q| <= tol`` (converged points leave the
active set); parameters are clamped to the domains, and while a step is clamped
on one surface ``F_n`` passes through that surface's image instead of the
anchor (otherwise a point whose anchor plane meets the curve outside a domain
could never converge). Where ``|n_p x n_q|`` is
below ``tangent_sin`` (near-tangential surfaces) eq. 29.21 is ill-conditioned:
the point instead moves both images toward their midpoint (one Gauss–Newton
projection step of the midpoint onto each surface) and is flagged ``singular``.

Curve refinement inserts the refined chord midpoint wherever it lies farther
than ``tol`` from the chord, pass after pass (all chords of all curves in one
batch per pass), then removes points whose removal keeps every point of the
dense refined curve (samples and refined chord midpoints) within ``tol`` of the
coarser chord.

Mesh x NURBS pairs refine onto the exact side only (:func:`project_points`);
mesh x mesh pairs are not refined (the piecewise-linear curve is the result).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..jit import compiled
from ..measure import normals
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from . import refine_kernels, vectors

__all__ = [
    "RefinedCurve",
    "RefinedPoints",
    "project_points",
    "refine_curves",
    "refine_points",
    "segment_distance",
]

_DEGENERATE = 1e-10     # |Su x Sv| / (|Su| |Sv|) below this: a pole, use the pseudo-inverse
#: curve refinement: samples and chord midpoints are refined to tol * _POINT_SHARE, and a
#: chord passes when its midpoint lies within tol * _CHORD_SHARE, so that the chord of
#: two samples, each off the true curve by up to about the point tolerance, stays within tol
_POINT_SHARE = 1.0 / 16.0
_CHORD_SHARE = 0.875


@dataclass(frozen=True)
class RefinedPoints:
    """Result of :func:`refine_points` (``n`` points).

    Attributes
    ----------
    points : (n, 3) float
        Midpoints of the two images ``(S_a + S_b) / 2``.
    uv_a, uv_b : (n, 2) float
    gap : (n,) float
        ``|S_a(uv_a) - S_b(uv_b)|``.
    iterations : (n,) int
        Iterations done (0: the start already met ``tol``).
    converged : (n,) bool
        ``gap <= tol``.
    singular : (n,) bool
        Near-tangential surfaces (``|n_a x n_b| < tangent_sin``) at the result, or
        not converged with the midpoint fallback used in the last iteration.
    """

    points: NDArray
    uv_a: NDArray
    uv_b: NDArray
    gap: NDArray
    iterations: NDArray
    converged: NDArray
    singular: NDArray


@dataclass(frozen=True)
class RefinedCurve:
    """One refined intersection curve: ``n`` samples on both surfaces.

    Attributes
    ----------
    points : (n, 3) float
    uv_a, uv_b : (n, 2) float
    closed : bool
        The last sample joins the first (not repeated).
    converged, singular : (n,) bool
        Per sample, as in :class:`RefinedPoints`.
    """

    points: NDArray
    uv_a: NDArray
    uv_b: NDArray
    closed: bool
    converged: NDArray
    singular: NDArray


# ------------------------------------------------------------------ helpers
def _check_uv(uv: ArrayLike, name: str, n: int | None = None) -> NDArray:
    out = np.array(uv, dtype=float, copy=True)
    if out.ndim != 2 or out.shape[1] != 2 or (n is not None and out.shape[0] != n):
        want = "(n, 2)" if n is None else f"({n}, 2)"
        raise InvalidGeometryError(f"{name} must have shape {want}, got {out.shape}")
    if not np.all(np.isfinite(out)):
        raise InvalidGeometryError(f"{name} contains NaN or infinite values")
    return out


def _check_surface(surface: NurbsSurface, name: str) -> None:
    if not isinstance(surface, NurbsSurface) or surface.dimension != 3:
        raise InvalidGeometryError(f"{name} must be a NurbsSurface in 3D, got {surface!r}")


def _clamp(uv: NDArray, surface: NurbsSurface) -> NDArray:
    u0, u1, v0, v1 = surface.domain
    return np.stack([np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)], axis=1)


def _dot(a: NDArray, b: NDArray) -> NDArray:
    return np.einsum("ij,ij->i", a, b)


def _unit(a: NDArray) -> tuple[NDArray, NDArray]:
    norm = vectors.norm(a)
    return a / np.where(norm > 0, norm, 1.0)[:, None], norm


def _frame(surface: NurbsSurface, uv: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Point, S_u, S_v and unit normal: four (m, 3) float (one derivatives call)."""
    d = surface.derivatives(uv[:, 0], uv[:, 1], 1)
    point, su, sv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1]
    n, size = _unit(vectors.cross(su, sv))
    bad = size <= _DEGENERATE * vectors.norm(su) * vectors.norm(sv)
    if np.any(bad):     # a pole: limit normal
        n[bad] = normals(surface, uv[bad, 0], uv[bad, 1])
    return point, su, sv, n


def _increments(su: NDArray, sv: NDArray, n: NDArray, delta: NDArray) -> NDArray:
    """Parameter step ``(m, 2)`` with ``S_u du + S_v dv ~ delta`` (eqs. 29.22–29.25)."""
    su_p, sv_p = vectors.cross(su, n), vectors.cross(sv, n)          # 29.22 / 29.23
    den_u, den_v = _dot(sv_p, su), _dot(su_p, sv)
    scale = vectors.norm(su) * vectors.norm(sv)
    bad = ~(np.abs(den_u) > _DEGENERATE * scale)
    step = np.stack([_dot(sv_p, delta) / np.where(bad, 1.0, den_u),    # 29.24 / 29.25
                     _dot(su_p, delta) / np.where(bad, 1.0, den_v)], axis=1)
    if np.any(bad):
        jac = np.stack([su[bad], sv[bad]], axis=2)                     # (b, 3, 2)
        step[bad] = np.einsum("bij,bj->bi", np.linalg.pinv(jac), delta[bad])
    return step


def _three_planes(p: NDArray, q: NDArray, n_p: NDArray, n_q: NDArray, anchor: NDArray,
                  cross: NDArray, sin: NDArray) -> NDArray:
    """Eqs. 29.18–29.21: the point common to F_p, F_q and F_n."""
    d_p, d_q = _dot(n_p, p), _dot(n_q, q)                   # 29.18
    n_n = cross / sin[:, None]                              # 29.19
    d_n = _dot(n_n, anchor)                                 # 29.20
    num = (d_p[:, None] * vectors.cross(n_q, n_n) + d_q[:, None] * vectors.cross(n_n, n_p)
           + d_n[:, None] * cross)
    return num / sin[:, None]                               # [n_p, n_q, n_n] = |n_p x n_q|


def _iterate(surface_a: NurbsSurface, surface_b: NurbsSurface, ua: NDArray, ub: NDArray,
             anchor: NDArray | None, tol: float, max_iter: int, tangent_sin: float) -> tuple:
    """The numpy form of the iteration of :func:`refine_points` over all points at once:
    ``ua, ub, img_a, img_b, nrm_a, nrm_b, iterations, singular``."""
    n = ua.shape[0]
    iterations = np.zeros(n, dtype=np.int64)
    singular = np.zeros(n, dtype=bool)
    held_a = np.zeros(n, dtype=bool)        # the last step was clamped on A's / B's boundary
    held_b = np.zeros(n, dtype=bool)
    active = np.arange(n)
    # images and normals at every point's final parameters: each point leaves the loop
    # right after an evaluation at its current (u, v), so none is evaluated again
    img_a, img_b, nrm_a, nrm_b = (np.zeros((n, 3)) for _ in range(4))
    for _ in range(max_iter + 1):
        if active.size == 0:
            break
        p, su, sv, n_p = _frame(surface_a, ua[active])
        q, rw, rt, n_q = _frame(surface_b, ub[active])
        img_a[active], img_b[active], nrm_a[active], nrm_b[active] = p, q, n_p, n_q
        done = vectors.norm(p - q) <= tol
        keep = ~done & (iterations[active] < max_iter)
        active, p, q, su, sv, rw, rt, n_p, n_q = (
            a[keep] for a in (active, p, q, su, sv, rw, rt, n_p, n_q))
        if active.size == 0:
            break
        mid = 0.5 * (p + q)
        cross = vectors.cross(n_p, n_q)
        sin = vectors.norm(cross)
        near = sin < tangent_sin
        x = mid.copy()                                      # fallback: the midpoint
        ok = ~near
        if np.any(ok):
            anc = mid if anchor is None else anchor[active]
            # held on a domain side: F_n through that image, so the point can slide
            # along the boundary to where the curve leaves the domain
            ha, hb = held_a[active, None], held_b[active, None]
            anc = np.where(ha & hb, mid, np.where(ha, p, np.where(hb, q, anc)))
            x[ok] = _three_planes(p[ok], q[ok], n_p[ok], n_q[ok], anc[ok], cross[ok], sin[ok])
        step_a = ua[active] + _increments(su, sv, n_p, x - p)                          # 29.26
        step_b = ub[active] + _increments(rw, rt, n_q, x - q)
        ua[active], ub[active] = _clamp(step_a, surface_a), _clamp(step_b, surface_b)
        held_a[active] = np.any(ua[active] != step_a, axis=1)
        held_b[active] = np.any(ub[active] != step_b, axis=1)
        singular[active] = near
        iterations[active] += 1
    if active.size:                         # the loop ran out with points still moving
        img_a[active], _, _, nrm_a[active] = _frame(surface_a, ua[active])
        img_b[active], _, _, nrm_b[active] = _frame(surface_b, ub[active])
    return ua, ub, img_a, img_b, nrm_a, nrm_b, iterations, singular


# ------------------------------------------------------------------ points
def refine_points(surface_a: NurbsSurface, surface_b: NurbsSurface, uv_a: ArrayLike,
                  uv_b: ArrayLike, *, tol: float = 1e-7, anchors: ArrayLike | None = None,
                  max_iter: int = 40, tangent_sin: float = 1e-6) -> RefinedPoints:
    """Auxiliary-plane refinement (Hosaka; eqs. 29.18–29.26) of ``n`` points at once.

    Parameters
    ----------
    surface_a, surface_b : NurbsSurface
    uv_a, uv_b : (n, 2) float
        Start parameters (e.g. from the barycentric map of the triangles).
    tol : float
        Convergence when ``|S_a(uv_a) - S_b(uv_b)| <= tol``.
    anchors : (n, 3) float, optional
        Fixed points for the plane ``F_n``; default the current midpoint of the images.
    max_iter : int
    tangent_sin : float
        ``|n_p x n_q|`` below this: near-tangential, midpoint fallback, flagged.

    Returns
    -------
    RefinedPoints
    """
    _check_surface(surface_a, "surface_a")
    _check_surface(surface_b, "surface_b")
    tol = check_tolerance(tol)
    ua = _clamp(_check_uv(uv_a, "uv_a"), surface_a)
    ub = _clamp(_check_uv(uv_b, "uv_b", ua.shape[0]), surface_b)
    n = ua.shape[0]
    anchor = None if anchors is None else np.asarray(anchors, dtype=float)
    if anchor is not None and anchor.shape != (n, 3):
        raise InvalidGeometryError(f"anchors must have shape ({n}, 3), got {anchor.shape}")
    if compiled(n * 64):                        # Newton steps with two surfaces' derivatives each
        start_a, start_b = ua.copy(), ub.copy()
        img_a, img_b, nrm_a, nrm_b, iterations, singular, fallback = \
            refine_kernels.refine_compiled(surface_a, surface_b, ua, ub, anchor, tol, max_iter,
                                          tangent_sin, _DEGENERATE)
        if np.any(fallback):            # a pole on the way: the numpy form, from the start
            k = np.flatnonzero(fallback)
            ua[k], ub[k] = start_a[k], start_b[k]
            sub = _iterate(surface_a, surface_b, ua[k], ub[k],
                           None if anchor is None else anchor[k], tol, max_iter, tangent_sin)
            ua[k], ub[k] = sub[0], sub[1]
            for full, part in zip((img_a, img_b, nrm_a, nrm_b, iterations, singular), sub[2:]):
                full[k] = part
    else:
        ua, ub, img_a, img_b, nrm_a, nrm_b, iterations, singular = _iterate(
            surface_a, surface_b, ua, ub, anchor, tol, max_iter, tangent_sin)
    pa, pb, n_a, n_b = img_a, img_b, nrm_a, nrm_b
    gap = vectors.norm(pa - pb)
    converged = gap <= tol
    singular = (singular & ~converged) | (vectors.norm(vectors.cross(n_a, n_b)) < tangent_sin)
    return RefinedPoints(0.5 * (pa + pb), ua, ub, gap, iterations, converged, singular)


def project_points(surface: NurbsSurface, points: ArrayLike, uv: ArrayLike, *,
                   tol: float = 1e-10, max_iter: int = 30) -> tuple[NDArray, NDArray, NDArray]:
    """Foot points of ``points`` on ``surface`` by Newton's method from ``uv`` (mesh x NURBS).

    Minimizes ``|S(u, v) - x|^2``: gradient ``J^T (S - x)``, Hessian
    ``J^T J + (S - x) . [[S_uu, S_uv], [S_uv, S_vv]]``, falling back to the
    Gauss–Newton step where that Hessian is not positive definite.

    Parameters
    ----------
    points : (n, 3) float
    uv : (n, 2) float
        Start parameters.
    tol : float
        Stop when the parameter step moves the point by less than ``tol``.

    Returns
    -------
    uv : (n, 2) float
    foot : (n, 3) float
    converged : (n,) bool
    """
    _check_surface(surface, "surface")
    tol = check_tolerance(tol)
    x = np.asarray(points, dtype=float)
    uv = _clamp(_check_uv(uv, "uv"), surface)
    if x.shape != (uv.shape[0], 3):
        raise InvalidGeometryError(f"points must have shape ({uv.shape[0]}, 3), got {x.shape}")
    converged = np.zeros(uv.shape[0], dtype=bool)
    active = np.arange(uv.shape[0])
    for _ in range(max_iter):
        if active.size == 0:
            break
        d = surface.derivatives(uv[active, 0], uv[active, 1], 2)
        r = d[:, 0, 0] - x[active]
        su, sv = d[:, 1, 0], d[:, 0, 1]
        jtj = np.stack([np.stack([_dot(su, su), _dot(su, sv)], 1),
                        np.stack([_dot(su, sv), _dot(sv, sv)], 1)], 1)
        curv = np.stack([np.stack([_dot(r, d[:, 2, 0]), _dot(r, d[:, 1, 1])], 1),
                         np.stack([_dot(r, d[:, 1, 1]), _dot(r, d[:, 0, 2])], 1)], 1)
        hess = jtj + curv
        det = hess[:, 0, 0] * hess[:, 1, 1] - hess[:, 0, 1] ** 2
        hess = np.where(((det > 0) & (hess[:, 0, 0] > 0))[:, None, None], hess, jtj)
        grad = np.stack([_dot(su, r), _dot(sv, r)], axis=1)
        step = -np.einsum("bij,bj->bi", np.linalg.pinv(hess), grad)
        moved = np.linalg.norm(su * step[:, :1] + sv * step[:, 1:], axis=1)
        uv[active] = _clamp(uv[active] + step, surface)
        small = moved <= tol
        converged[active[small]] = True
        active = active[~small]
    return uv, surface.evaluate(uv[:, 0], uv[:, 1]), converged


# ------------------------------------------------------------------ curves
def segment_distance(x: NDArray, a: NDArray, b: NDArray) -> NDArray:
    """Distances ``(m,)`` of points ``x`` to segments ``[a, b]``, all (m, 3) float."""
    ab = b - a
    den = _dot(ab, ab)
    t = np.clip(_dot(x - a, ab) / np.where(den > 0, den, 1.0), 0.0, 1.0)
    return np.linalg.norm(x - a - t[:, None] * ab, axis=1)


def _chords(offsets: NDArray, closed: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Global (start, end) indices and curve id of every chord of every packed curve."""
    counts = np.diff(offsets)
    n_chords = counts - 1 + closed
    curve = np.repeat(np.arange(counts.size), n_chords)
    local = np.arange(curve.size) - np.repeat(np.cumsum(n_chords) - n_chords, n_chords)
    start = offsets[curve] + local
    end = np.where(local + 1 < counts[curve], start + 1, offsets[curve])
    return start, end, curve


def _chord_midpoints(surface_a, surface_b, pts, ua, ub, start, end, tol, tangent_sin):
    return refine_points(surface_a, surface_b, 0.5 * (ua[start] + ua[end]),
                         0.5 * (ub[start] + ub[end]), tol=_POINT_SHARE * tol,
                         anchors=0.5 * (pts[start] + pts[end]), tangent_sin=tangent_sin)


def _insert(surface_a, surface_b, pts, ua, ub, conv, sing, offsets, closed, tol,
            max_passes, tangent_sin):
    """Insert refined chord midpoints until every chord midpoint is within tol."""
    for _ in range(max_passes):
        start, end, curve = _chords(offsets, closed)
        if start.size == 0:
            break
        mid = _chord_midpoints(surface_a, surface_b, pts, ua, ub, start, end, tol, tangent_sin)
        dev = segment_distance(mid.points, pts[start], pts[end])
        chord = np.linalg.norm(pts[end] - pts[start], axis=1)
        add = (dev > _CHORD_SHARE * tol) & mid.converged & (chord > tol)
        if not np.any(add):
            break
        # sort key: point j of a curve -> 2j, midpoint of chord j -> 2j + 1
        pt_curve = np.repeat(np.arange(offsets.size - 1), np.diff(offsets))
        key = np.concatenate([2 * (np.arange(pts.shape[0]) - offsets[pt_curve]),
                              2 * (start[add] - offsets[curve[add]]) + 1])
        owner = np.concatenate([pt_curve, curve[add]])
        order = np.lexsort((key, owner))
        pts = np.concatenate([pts, mid.points[add]])[order]
        ua = np.concatenate([ua, mid.uv_a[add]])[order]
        ub = np.concatenate([ub, mid.uv_b[add]])[order]
        conv = np.concatenate([conv, mid.converged[add]])[order]
        sing = np.concatenate([sing, mid.singular[add]])[order]
        offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=offsets.size - 1))])
    return pts, ua, ub, conv, sing, offsets


def _run_parity_select(flag: NDArray) -> NDArray:
    """Every other entry of each run of True in ``flag`` (no two selected are adjacent)."""
    idx = np.arange(flag.size)
    run_start = flag & ~np.concatenate([[False], flag[:-1]])
    start_of = np.maximum.accumulate(np.where(run_start, idx, 0))
    return flag & ((idx - start_of) % 2 == 0)


def _simplify_one(ref: NDArray, closed: bool, tol: float) -> NDArray:
    """Kept sample mask ``(n,)`` of one curve, ``ref (2n - 1, 3)`` interleaving samples
    (even rows) and refined chord midpoints (odd rows); for a closed curve the first
    sample is repeated at the end."""
    n = (ref.shape[0] + 1) // 2
    kept = np.ones(n, dtype=bool)
    min_kept = 4 if closed else 2
    r = np.arange(ref.shape[0])
    while True:
        k = np.flatnonzero(kept)
        if k.size <= min_kept:
            break
        span = np.searchsorted(2 * k, r, side="right") - 1       # span of each ref point
        span = np.minimum(span, k.size - 2)
        # d1: removing k[s] (chord k[s-1] -> k[s+1]); d2: removing k[s+1] (k[s] -> k[s+2])
        s1 = np.clip(span, 1, k.size - 2)
        d1 = segment_distance(ref, ref[2 * k[s1 - 1]], ref[2 * k[s1 + 1]])
        s2 = np.clip(span, 0, k.size - 3)
        d2 = segment_distance(ref, ref[2 * k[s2]], ref[2 * k[s2 + 2]])
        starts = 2 * k[:-1]
        m1 = np.maximum.reduceat(d1, starts)                     # per span s
        m2 = np.maximum.reduceat(d2, starts)
        dev = np.maximum(m1[1:], m2[:-1])                        # candidate k[i], i = 1..K-2
        select = _run_parity_select(dev <= tol)
        excess = select.sum() - (k.size - min_kept)
        if excess > 0:
            select[np.flatnonzero(select)[-excess:]] = False
        if not np.any(select):
            break
        kept[k[1:-1][select]] = False
    return kept


def _simplify(surface_a, surface_b, pts, ua, ub, conv, sing, offsets, closed, tol,
              tangent_sin):
    start, end, curve = _chords(offsets, closed)
    mid = _chord_midpoints(surface_a, surface_b, pts, ua, ub, start, end, tol, tangent_sin)
    out = []
    chord_off = np.concatenate([[0], np.cumsum(np.bincount(curve, minlength=closed.size))])
    for c in range(closed.size):
        lo, hi = offsets[c], offsets[c + 1]
        sample = pts[lo:hi]
        if closed[c]:
            sample = np.vstack([sample, sample[:1]])
        ref = np.empty((2 * sample.shape[0] - 1, 3))
        ref[0::2], ref[1::2] = sample, mid.points[chord_off[c]:chord_off[c + 1]]
        keep = _simplify_one(ref, bool(closed[c]), _CHORD_SHARE * tol)[: hi - lo]
        out.append(RefinedCurve(pts[lo:hi][keep], ua[lo:hi][keep], ub[lo:hi][keep],
                                bool(closed[c]), conv[lo:hi][keep], sing[lo:hi][keep]))
    return out


def refine_curves(surface_a: NurbsSurface, surface_b: NurbsSurface,
                  uv_a: Sequence[ArrayLike], uv_b: Sequence[ArrayLike],
                  closed: Sequence[bool], *, tol: float = 1e-7, max_passes: int = 20,
                  simplify: bool = True, tangent_sin: float = 1e-6) -> list[RefinedCurve]:
    """Refine traced curves onto the exact intersection, then fix the sampling density.

    1. All samples of all curves: :func:`refine_points` to ``tol / 16``, with
       ``F_n`` anchored at the midpoint of the start images (samples keep their
       place along the curve).
    2. Insertion passes: every chord's midpoint (start: the mean of the end
       parameters; ``F_n`` anchored at the chord midpoint) is refined, and inserted
       where it lies farther than ``7/8 tol`` from the chord (the rest of ``tol`` is
       left for the sample errors). One batch per pass over
       all chords of all curves; chords shorter than ``tol`` are not split.
    3. With ``simplify``: samples are removed (ends kept; closed curves keep 3)
       while every sample and refined chord midpoint of the dense curve stays
       within ``7/8 tol`` of the coarser chord. Removal takes every other point of
       each run of removable points per pass, so the result has no redundant point
       (removing any one would break ``tol``) but may keep up to about twice the
       fewest samples that would do.

    Parameters
    ----------
    uv_a, uv_b : sequences of (n_i, 2) float
        Start parameters of each curve's samples (a closed curve does not repeat
        its first sample).
    closed : sequence of bool

    Returns
    -------
    list of RefinedCurve
    """
    _check_surface(surface_a, "surface_a")
    _check_surface(surface_b, "surface_b")
    tol = check_tolerance(tol)
    if not (len(uv_a) == len(uv_b) == len(closed)):
        raise InvalidGeometryError(
            f"uv_a, uv_b and closed need one entry per curve, got "
            f"{len(uv_a)}, {len(uv_b)}, {len(closed)}")
    if len(closed) == 0:
        return []
    ua = [_check_uv(a, f"uv_a[{i}]") for i, a in enumerate(uv_a)]
    ub = [_check_uv(b, f"uv_b[{i}]", a.shape[0]) for i, (a, b) in enumerate(zip(ua, uv_b))]
    closed = np.asarray(closed, dtype=bool)
    counts = np.array([a.shape[0] for a in ua])
    if np.any(counts < 2 + closed):
        raise InvalidGeometryError("an open curve needs >= 2 samples, a closed one >= 3")
    offsets = np.concatenate([[0], np.cumsum(counts)])
    ua, ub = np.concatenate(ua), np.concatenate(ub)
    # F_n through the start points: samples keep their place along the curve
    anchors = 0.5 * (surface_a.evaluate(ua[:, 0], ua[:, 1]) + surface_b.evaluate(ub[:, 0], ub[:, 1]))
    first = refine_points(surface_a, surface_b, ua, ub, tol=_POINT_SHARE * tol, anchors=anchors,
                          tangent_sin=tangent_sin)
    state = _insert(surface_a, surface_b, first.points, first.uv_a, first.uv_b,
                    first.converged, first.singular, offsets, closed, tol, max_passes,
                    tangent_sin)
    pts, a, b, conv, sing, offsets = state
    if simplify:
        return _simplify(surface_a, surface_b, pts, a, b, conv, sing, offsets, closed, tol,
                         tangent_sin)
    return [RefinedCurve(pts[lo:hi], a[lo:hi], b[lo:hi], bool(c), conv[lo:hi], sing[lo:hi])
            for lo, hi, c in zip(offsets[:-1], offsets[1:], closed)]
