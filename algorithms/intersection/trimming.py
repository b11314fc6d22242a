"""Intersection curves clipped to trimmed faces (the last step of ``surfprep.intersect``): the
edges of 002 §1 with their images in both parameter domains.

:func:`clip_curve` cuts a curve of two surfaces into the runs inside both trimmed
faces (:class:`~surfprep.algorithms.face_region.FaceRegion`, the one
point-in-trimmed-face test):

* **Classification**: the interpolants are classified at ``CLASSIFY_PER_SPAN``
  points per span (a curve with few samples can still leave a face between
  them) against both faces' regions.
* **Splitting**: the curve is cut into the runs of points inside both faces.
  Where a run leaves a face, the crossing is located on the interpolants
  (``curve3d``, ``pcurve_a``, ``pcurve_b`` share one parameter) to 2^-30 of a
  classification step against the loop polygons, 31 points per bracket and round
  batched over all crossings (six rounds), then moved onto the exact trimming
  pcurve by Newton on ``pcurve(t) = edge.pcurve(s)`` (kept on the polygon where
  that fails or the crossing is near-tangential), and becomes the run's end
  (:attr:`EndKind.BOUNDARY`). The pieces are new :class:`IntersectionCurve`
  objects (refined samples inside, interpolated crossing points at the ends).

**Shared edges** of faces of one shape: adjacent faces meet along their common
edge, which is an intersection of their surfaces but not one of the faces.
:func:`along_a_boundary` tells such a piece: all its samples lie within
``max(10 tol, 2 x edge tolerance)`` of the trimming loops of either face, or the
faces lie on each other all the way from the piece to their loops (a tangent
join, :func:`on_a_tangent_join`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..face_region import FaceRegion
from ..projection import project_to_surface
from .result import IntersectionCurve
from .topology import EndKind

__all__ = ["CLASSIFY_PER_SPAN", "along_a_boundary", "clip_curve", "on_a_tangent_join"]

#: a crossing's bracket is narrowed to 2^-_BISECTIONS of a classification step
_BISECTIONS = 30
#: points classified per bracket and round (:func:`_bracket_crossings`)
_BRACKET_POINTS = 31
#: the clipping classifies the interpolants at this many points per span
CLASSIFY_PER_SPAN = 8


def _inside_both(fa: FaceRegion, fb: FaceRegion, curve: IntersectionCurve, t: NDArray,
                 tol: float) -> NDArray:
    uva, uvb = curve.pcurve_a.evaluate(t), curve.pcurve_b.evaluate(t)
    return fa.contains(uva, tol) & fb.contains(uvb, tol)


def _bracket_crossings(fa: FaceRegion, fb: FaceRegion, curve: IntersectionCurve, lo: NDArray,
                       hi: NDArray, lo_in: NDArray, tol: float) -> tuple[NDArray, NDArray]:
    """Brackets ``(lo, hi)`` of every crossing narrowed ``2^-_BISECTIONS`` times at once.

    Each round classifies ``_BRACKET_POINTS`` evenly spaced points inside every
    bracket in one call and keeps the sub-interval where the classification first
    differs from ``lo``'s (``lo_in``): ``log2(_BRACKET_POINTS + 1)`` bisections'
    worth per round, so the per-call cost of the classification is paid about five
    times instead of thirty.
    """
    period = curve.parameters[-1]
    share = np.arange(1, _BRACKET_POINTS + 1) / (_BRACKET_POINTS + 1)
    rounds = int(np.ceil(_BISECTIONS / np.log2(_BRACKET_POINTS + 1)))
    for _ in range(rounds):
        mid = lo[:, None] + share[None, :] * (hi - lo)[:, None]            # (c, k)
        at = np.mod(mid, period) if curve.closed else mid
        ok = _inside_both(fa, fb, curve, at.ravel(), tol).reshape(mid.shape)
        differ = ok != lo_in[:, None]
        first = np.where(differ.any(axis=1), differ.argmax(axis=1), _BRACKET_POINTS)
        rows = np.arange(lo.size)
        new_lo = np.where(first > 0, mid[rows, np.maximum(first - 1, 0)], lo)
        hi = np.where(first < _BRACKET_POINTS, mid[rows, np.minimum(first, _BRACKET_POINTS - 1)],
                      hi)
        lo = new_lo
    return lo, hi


def _refine_crossing(curve_pcurve, face: FaceRegion, t0: float, bracket: float
                     ) -> float | None:
    """Parameter where ``curve_pcurve`` crosses the face's exact trimming pcurve near ``t0``.

    Newton on ``pcurve(t) = edge.pcurve(s)`` (2 equations, 2 unknowns) from the
    polygon crossing: the nearest boundary segment gives the edge and the start
    ``s``. Returns None (keep the polygon crossing) when it does not converge,
    the crossing is near-tangential, or ``t`` leaves ``t0 +- bracket``.
    """
    seg = face.boundary_segments()
    owners, params = face.segment_edges()
    if seg.shape[0] == 0:
        return None
    uv = curve_pcurve.evaluate(np.array([t0]))[0]
    a, d = seg[:, 0], seg[:, 1] - seg[:, 0]
    dd = np.einsum("mc,mc->m", d, d)
    w = np.clip(np.einsum("mc,mc->m", uv - a, d) / np.where(dd > 0, dd, 1.0), 0, 1)
    nearest = int(np.argmin(np.linalg.norm(a + w[:, None] * d - uv, axis=1)))
    edge = face.face.edges[int(owners[nearest])]
    s = params[nearest, 0] + w[nearest] * (params[nearest, 1] - params[nearest, 0])
    t = t0
    u0, u1, v0, v1 = face.surface.domain
    scale = np.hypot(u1 - u0, v1 - v0)
    for _ in range(12):
        c = curve_pcurve.derivatives(np.array([t]), 1)[0]
        e = edge.pcurve.derivatives(np.array([s]), 1)[0]
        residual = c[0] - e[0]
        if np.linalg.norm(residual) <= 1e-13 * scale:
            break
        jac = np.stack([c[1], -e[1]], axis=1)
        sine = abs(np.linalg.det(jac)) / max(np.linalg.norm(c[1]) * np.linalg.norm(e[1]), 1e-300)
        if sine < 0.05:                                   # near-tangential: leave it
            return None
        step = np.linalg.solve(jac, -residual)
        t, s = t + step[0], float(np.clip(s + step[1], edge.t0, edge.t1))
        if abs(t - t0) > bracket:
            return None
    else:
        return None
    return float(t)


def clip_curve(curve: IntersectionCurve, fa: FaceRegion, fb: FaceRegion, tol: float = 0.0
               ) -> list[IntersectionCurve]:
    """The pieces of ``curve`` inside both faces (module docstring: splitting).

    The interpolants are classified at ``CLASSIFY_PER_SPAN`` points per span (a
    curve with few samples can still leave a face between them); pieces keep
    the refined samples inside and get interpolated crossing points as ends.
    """
    n = curve.points.shape[0]
    period = curve.parameters[-1]
    t = curve.parameters[:n]
    spans = np.diff(curve.parameters)                                  # (n or n-1,)
    k = np.arange(CLASSIFY_PER_SPAN) / CLASSIFY_PER_SPAN
    dense = (curve.parameters[:-1, None] + k[None, :] * spans[:, None]).ravel()
    is_sample = np.tile(k == 0, spans.size)
    if not curve.closed:
        dense, is_sample = np.append(dense, t[-1]), np.append(is_sample, True)
    flags = _inside_both(fa, fb, curve, dense, tol)
    sample_index = np.cumsum(is_sample) - 1
    if flags.all():
        return [curve]
    if not flags.any():
        return []
    if curve.closed:                     # start at an outside point, go once around
        first_out = int(np.flatnonzero(~flags)[0])
        order = np.append(np.roll(np.arange(dense.size), -first_out), first_out)
        tt = dense[order].copy()
        tt[1:][tt[1:] <= tt[0]] += period
        tt[-1] = tt[0] + period
        flags, is_sample, sample_index = flags[order], is_sample[order], sample_index[order]
    else:
        tt = dense
    change = np.flatnonzero(flags[1:] != flags[:-1])       # crossing between k and k + 1
    lo, hi = tt[change].copy(), tt[change + 1].copy()
    lo_in = flags[change]
    lo, hi = _bracket_crossings(fa, fb, curve, lo, hi, lo_in, tol)
    cross_t = np.where(lo_in, lo, hi)                      # the inside end of each bracket
    # onto the exact trimming pcurve of the face the curve leaves (per crossing, few)
    # Newton may move a crossing by the polygon's error along the curve: allow a few
    # classification steps and a hundredth of the curve
    step = float(np.max(np.diff(tt))) + 0.01 * period if tt.size > 1 else period
    for k_cross, (t_lo, t_hi) in enumerate(zip(tt[change], tt[change + 1])):
        ends = np.array([t_lo, t_hi])
        ends = np.mod(ends, period) if curve.closed else ends
        flips = [bool(np.ptp(face.contains(pcurve.evaluate(ends), tol).astype(int)))
                 for face, pcurve in ((fa, curve.pcurve_a), (fb, curve.pcurve_b))]
        if flips[0] == flips[1]:
            continue                                        # both or neither: keep it
        face, pcurve = (fa, curve.pcurve_a) if flips[0] else (fb, curve.pcurve_b)
        t0 = float(np.mod(cross_t[k_cross], period)) if curve.closed else float(cross_t[k_cross])
        exact = _refine_crossing(pcurve, face, t0, step)
        if exact is not None:
            cross_t[k_cross] += exact - t0
    crossing = {int(c): i for i, c in enumerate(change)}
    pieces = []
    for run in np.split(np.arange(flags.size), change + 1):
        if not flags[run[0]]:
            continue
        params, samples = [], []
        if (run[0] - 1) in crossing:
            params.append(cross_t[crossing[run[0] - 1]])
            samples.append(-1)
        inner = run[is_sample[run]]
        params.extend(tt[inner])
        samples.extend(sample_index[inner])
        if int(run[-1]) in crossing:
            params.append(cross_t[crossing[int(run[-1])]])
            samples.append(-1)
        params, samples = np.array(params), np.array(samples)
        if params.size < 2:
            continue
        targ = np.mod(params, period) if curve.closed else params
        pts = curve.curve3d.evaluate(targ)
        uva, uvb = curve.pcurve_a.evaluate(targ), curve.pcurve_b.evaluate(targ)
        exact = samples >= 0
        pts[exact] = curve.points[samples[exact]]          # samples keep their refined values
        uva[exact], uvb[exact] = curve.uv_a[samples[exact]], curve.uv_b[samples[exact]]
        keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1)
                               > 1e-12 * max(period, 1e-300)])
        pts, uva, uvb, exact, samples = pts[keep], uva[keep], uvb[keep], exact[keep], samples[keep]
        if pts.shape[0] < 2:
            continue
        start = curve.start_kind if exact[0] and not curve.closed else EndKind.BOUNDARY
        end = curve.end_kind if exact[-1] and not curve.closed else EndKind.BOUNDARY
        sing = np.zeros(pts.shape[0], dtype=bool)
        sing[exact] = curve.singular[samples[exact]]
        pieces.append(IntersectionCurve.from_samples(pts, uva, uvb, False, start, end,
                                                     singular=sing))
    return pieces


# ------------------------------------------------------------------ shared edges
def along_a_boundary(curve: IntersectionCurve, fa: FaceRegion, fb: FaceRegion, tol: float
                     ) -> bool:
    """True when all samples lie near the trimming edges of either face.

    Faces of one valid shape meet only along their edges, so such a piece is a
    common edge, or a remnant of one (where the surfaces' intersection leaves a
    shared edge near a vertex, or runs within the edge tolerance of a loop that
    the classification counts as inside).
    """
    near = max(10 * tol, 2 * max(fa.edge_tolerance(), fb.edge_tolerance()))
    for face in (fa, fb):
        lines = face.boundary_polylines()
        if not lines:
            continue
        if face.edge_distance(curve.points).max() <= near + face.boundary_sag:
            return True
    return on_a_tangent_join(curve, fa, fb, near)


#: points on the way from a piece's sample to the nearest trimming loop (shares of the way)
_JOIN_STEPS = np.array([0.25, 0.5, 0.75, 1.0])


def on_a_tangent_join(curve: IntersectionCurve, fa: FaceRegion, fb: FaceRegion,
                      near: float) -> bool:
    """True when one face lies within ``near`` of the other's surface all the way from
    every sample of the piece to its trimming loops.

    Where two faces of one shape meet tangentially (a G1 seam, as along every join
    of the fuselage's faces), their surfaces are within the tolerance of each
    other over a strip beside the common edge and cross there along curves that
    wander tens of millimetres from it: not a self-intersection, the two faces
    coincide between that curve and their edge. Each sample's (u, v) on a face is
    joined to the nearest point of the face's loop polygon; points along that
    way are measured against the other surface (closest points).
    """
    for face, uv, other in ((fa, curve.uv_a, fb), (fb, curve.uv_b, fa)):
        if uv is None:
            continue
        tree = face.loop_tree()
        if tree is None:
            continue
        _, foot = tree.nearest(uv)
        way = uv[:, None] + _JOIN_STEPS[None, :, None] * (foot - uv)[:, None]     # (n, s, 2)
        way = way.reshape(-1, 2)
        points = face.surface.evaluate(way[:, 0], way[:, 1])
        if project_to_surface(other.surface, points).distance.max() <= near:
            return True
    return False
