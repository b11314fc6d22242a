"""Intersection curves of faces: :func:`intersect` on anything that holds faces.

For every pair of faces (across ``a`` and ``b``, or within ``a`` when ``b`` is
None) whose boxes overlap, the two *surfaces* are intersected by
:func:`surfprep.algorithms.intersection.intersect_surfaces`, then every curve
is clipped to both faces' trimmed domains:

* **Classification**: each face's trimming loops are sampled densely in
  ``(u, v)`` (every edge's pcurve at ``EDGE_SAMPLES`` points, more for edges
  that are long in the parameter plane) into one set of polygon segments; a
  (u, v) point is inside when a ray in +u crosses them an odd number of times
  (even-odd rule: outer loop and holes at once), counted by a compiled kernel
  over the segments of the point's v-bucket. A face without loops is its whole
  parameter rectangle. Everything the test needs is built once per face and
  cached (:class:`surfprep.plugin.trim_loops.LoopIndex`: the segments bucketed
  by v, a k-d tree of them in (u, v); a k-d tree of the trimming edges in space
  for the tolerance band).
* **Splitting**: a curve is cut into the runs of samples inside both faces.
  Where a run leaves a face, the crossing is located on the interpolants
  (``curve3d``, ``pcurve_a``, ``pcurve_b`` share one parameter) to 2^-30 of
  a classification step against the loop polygons, 31 points per bracket and
  round batched over all crossings (six rounds), then
  moved onto the exact trimming pcurve by Newton on ``pcurve(t) =
  edge.pcurve(s)`` (kept on the polygon where that fails or the crossing is
  near-tangential), and becomes the run's end (:attr:`EndKind.BOUNDARY`). The pieces are new :class:`IntersectionCurve`
  objects (refined samples inside, interpolated crossing points at the ends).
* **Shared edges** (faces of one shape): adjacent faces meet along their common
  edge, which is an intersection of their surfaces but not one of the faces.
  With ``b`` None a piece is dropped when all its samples lie within
  ``max(10 tol, 2 x edge tolerance)`` of the trimming loops of *either* face:
  faces of one valid shape meet only along edges, so it is a common edge or
  a remnant of one. Across ``a`` and ``b`` nothing is dropped (a face of ``b``
  touching an edge of ``a`` is an answer there).

Each result is a :class:`FaceIntersection` (the piece, the two faces' indices
and names, and how it was found); :meth:`FaceIntersection.to_edges` builds a
``TopoDS_Edge`` with the 3D curve and a pcurve on each face
(:func:`surfprep.plugin.edges.make_edge`, checked by BRepCheck).

**Methods** (``method=``, :class:`Method`):

* ``"mesh"``: the triangle method alone
  (:func:`surfprep.algorithms.intersection.intersect_surfaces`);
* ``"characteristic"``: the characteristic-curve method of paper 002 alone
  (:func:`surfprep.algorithms.characteristic.characteristic_intersection`);
* ``"auto"`` (default): the triangle method, then the characteristic points as
  a certificate (:func:`surfprep.algorithms.characteristic.certify`): every
  closed loop they imply must be among the curves; a loop the triangles missed
  is traced, refined to ``tol`` and added (``found_by`` ``"characteristic"``).
  When the characteristic stage finds the surfaces coincident over their whole
  grid, the triangle method is not run at all (it would only produce debris).

**The result** is an :class:`IntersectionResult`: a ``list`` of
FaceIntersection (so every existing use of the returned list works as
before) with three more attributes: ``isolated_points`` (tangential contact
points, :class:`ContactPoint`: a contact is a point, not a curve, and is not
dropped), ``coincident`` (:class:`CoincidentFaces`: face pairs whose surfaces
coincide within ``tol`` over a region, with that region) and ``records`` (the
characteristic record of every face pair, :class:`PairRecord`, for reports and
plots).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..algorithms.characteristic import CharacteristicRecord
from ..algorithms.intersection import (
    EndKind,
    IntersectionCurve,
    closed_in_space,
)
from ..algorithms.projection import project_to_surface
from ..errors import InvalidGeometryError, InvalidToleranceError
from .edges import make_edge
from .intersect_methods import (
    CoincidentFaces,
    ContactPoint,
    FoundBy,
    IntersectionResult,
    Method,
    PairRecord,
    pair_curves,
)
from .intersect_operands import (
    FaceOperand,
    face_operands,
    inside_face,
)

__all__ = [
    "DEFAULT_TOL_FACTOR",
    "MIN_TOL_FACTOR",
    "CoincidentFaces",
    "ContactPoint",
    "FaceIntersection",
    "FaceOperand",
    "FoundBy",
    "IntersectionResult",
    "Method",
    "PairRecord",
    "clip_curve",
    "face_operands",
    "inside_face",
    "intersect",
]

#: default ``tol``: this times the diagonal of the box of all faces
DEFAULT_TOL_FACTOR = 1e-6
#: smallest accepted ``tol``: this times that diagonal
MIN_TOL_FACTOR = 1e-9
#: a crossing's bracket is narrowed to 2^-_BISECTIONS of a classification step
_BISECTIONS = 30
#: points classified per bracket and round (:func:`_bracket_crossings`)
_BRACKET_POINTS = 31
#: the clipping classifies the interpolants at this many points per span
CLASSIFY_PER_SPAN = 8


def _inside_both(fa: FaceOperand, fb: FaceOperand, curve: IntersectionCurve, t: NDArray,
                 tol: float) -> NDArray:
    uva, uvb = curve.pcurve_a.evaluate(t), curve.pcurve_b.evaluate(t)
    return inside_face(fa, uva, tol) & inside_face(fb, uvb, tol)


def _bracket_crossings(fa: FaceOperand, fb: FaceOperand, curve: IntersectionCurve, lo: NDArray,
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


def _refine_crossing(curve_pcurve, face: FaceOperand, t0: float, bracket: float
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
    edge = face.trimmed.edges[int(owners[nearest])]
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


def clip_curve(curve: IntersectionCurve, fa: FaceOperand, fb: FaceOperand, tol: float = 0.0
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
        flips = [bool(np.ptp(inside_face(face, pcurve.evaluate(ends), tol).astype(int)))
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


# ------------------------------------------------------------------ result
@dataclass(frozen=True, eq=False)
class FaceIntersection:
    """One intersection curve of two faces, clipped to both.

    Attributes
    ----------
    curve : IntersectionCurve
        Samples, (u, v) on each face's surface, interpolants.
    face_a, face_b : FaceOperand
        The faces (``face_b`` from ``b``, or from ``a`` when ``b`` was None).
    tol : float
        The tolerance the curve was computed to (model units).
    found_by : FoundBy
        ``MESH`` (the triangle method) or ``CHARACTERISTIC`` (traced from a
        characteristic point: with ``method="auto"``, a loop the triangles missed).
    """

    curve: IntersectionCurve
    face_a: FaceOperand
    face_b: FaceOperand
    tol: float
    found_by: FoundBy = FoundBy.MESH

    @property
    def points(self) -> NDArray:
        return self.curve.points

    @property
    def closed(self) -> bool:
        """Closed in space (a loop cut at a seam included)."""
        return closed_in_space(self.curve, self.tol)

    @property
    def length(self) -> float:
        return self.curve.length

    @property
    def faces(self) -> tuple[int, int]:
        """Indices of the two faces in their operands."""
        return self.face_a.index, self.face_b.index

    def max_deviation(self):
        """:meth:`IntersectionCurve.max_deviation` from both faces' surfaces."""
        return self.curve.max_deviation(self.face_a.surface, self.face_b.surface)

    def to_edges(self, tol: float | None = None) -> list:
        """``[TopoDS_Edge]``: the 3D curve with a pcurve on each face, checked by BRepCheck.

        ``tol`` (edge tolerance) defaults to the larger of the curve's tolerance
        and its measured deviation from the surfaces.
        """
        c = self.curve
        if c.curve3d is None or c.pcurve_a is None or c.pcurve_b is None:
            raise InvalidGeometryError("the curve has no interpolants to build an edge from")
        if tol is None:
            tol = max(self.tol, 1.01 * self.max_deviation().max)
        fa, fb = self.face_a.face_for_edges(), self.face_b.face_for_edges()
        pcurves = [(c.pcurve_a, fa)]
        if not fb.IsSame(fa):
            pcurves.append((c.pcurve_b, fb))
        return [make_edge(c.curve3d, pcurves, tol)]


# ------------------------------------------------------------------ driver
def _boxes(faces: Sequence[FaceOperand]) -> NDArray:
    return np.stack([np.asarray(f.surface.bounding_box(), dtype=float) for f in faces]) \
        if faces else np.zeros((0, 2, 3))


def _size(boxes: NDArray) -> float:
    return float(np.linalg.norm(boxes[:, 1].max(axis=0) - boxes[:, 0].min(axis=0)))


def _along_a_boundary(curve: IntersectionCurve, fa: FaceOperand, fb: FaceOperand, tol: float
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
        if "sag" not in face._cache:
            face._cache["sag"] = 0.01 * max(
                float(np.linalg.norm(np.diff(p, axis=0), axis=1).max(initial=0.0))
                for p in lines)
        if face.edge_distance(curve.points).max() <= near + face._cache["sag"]:
            return True
    return _on_a_tangent_join(curve, fa, fb, near)


#: points on the way from a piece's sample to the nearest trimming loop (shares of the way)
_JOIN_STEPS = np.array([0.25, 0.5, 0.75, 1.0])


def _on_a_tangent_join(curve: IntersectionCurve, fa: FaceOperand, fb: FaceOperand,
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


def _contacts(record: CharacteristicRecord | None, fa: FaceOperand, fb: FaceOperand,
              tol: float, within: bool) -> list[ContactPoint]:
    """The record's isolated points inside both faces (not on a shared edge within a shape)."""
    if record is None:
        return []
    out = []
    for p in record.isolated_points:
        if not (inside_face(fa, p.uv_a[None], tol)[0] and inside_face(fb, p.uv_b[None], tol)[0]):
            continue
        if within:
            near = max(10 * tol, 2 * max(fa.edge_tolerance(), fb.edge_tolerance()))
            if min(fa.edge_distance(p.point[None])[0], fb.edge_distance(p.point[None])[0]) \
                    <= near:
                continue
        out.append(ContactPoint(p.point, p.uv_a, p.uv_b, fa, fb))
    return out


def intersect(a: Any, b: Any = None, *, tol: float | None = None,
              mesh_tol: float | None = None, method: Method | str = Method.AUTO,
              progress: Callable[[int, int], None] | None = None) -> IntersectionResult:
    """Intersection curves of the faces of ``a`` with those of ``b`` (or among ``a``'s).

    Parameters
    ----------
    a, b
        Faces, shapes, :class:`CadModel`, ``Geom_Surface`` (finite),
        :class:`NurbsSurface`, :class:`TrimmedFace`, cadquery / build123d
        objects, or lists of these. With ``b`` None, every pair of distinct
        faces of ``a`` is intersected and common edges of adjacent faces are
        not reported (module docstring).
    tol : float, optional
        Model units; default ``DEFAULT_TOL_FACTOR`` (1e-6) times the diagonal
        of the box of all faces. Must not be below ``MIN_TOL_FACTOR`` (1e-9)
        times that diagonal.
    mesh_tol : float, optional
        Tessellation tolerance per pair (default: 1e-3 times the pair's size).
    method : Method or str
        ``"auto"`` (default), ``"mesh"`` or ``"characteristic"`` (module docstring).
    progress : callable(done, total), optional
        Called after each face pair whose boxes overlap.

    Returns
    -------
    IntersectionResult
        A list of FaceIntersection: pieces clipped to both faces, in face-pair
        order, each with ``found_by``. Curves that break ``tol`` (near-tangential
        or overlapping surfaces, where the refinement does not converge) are left
        out (``StrayCurves.DROP``); a pair whose intersection fails raises no
        error: it is skipped with a warning. Also ``isolated_points``
        (tangential contacts), ``coincident`` (face pairs coinciding over a
        region) and ``records`` (the characteristic record per pair).

    Raises
    ------
    InvalidToleranceError
        ``tol`` not finite and positive, or below ``MIN_TOL_FACTOR`` times the size.
    ConversionError
        An operand without faces or of an unsupported type.
    ValueError
        An unknown ``method``.
    """
    method = Method(method)
    faces_a = face_operands(a)
    faces_b = faces_a if b is None else face_operands(b)
    boxes_a, boxes_b = _boxes(faces_a), _boxes(faces_b)
    size = _size(np.concatenate([boxes_a, boxes_b]))
    if tol is None:
        tol = DEFAULT_TOL_FACTOR * size
    try:
        tol = float(tol)
    except (TypeError, ValueError):
        raise InvalidToleranceError(f"tol must be a number, got {tol!r}") from None
    if not np.isfinite(tol) or tol <= 0:
        raise InvalidToleranceError(f"tol must be finite and > 0, got {tol!r}")
    if tol < MIN_TOL_FACTOR * size:
        raise InvalidToleranceError(
            f"tol={tol:g} is below {MIN_TOL_FACTOR:g} x the model size {size:g}; "
            "the refinement cannot reach it reliably")
    pad = tol
    overlap = np.all((boxes_a[:, None, 0] <= boxes_b[None, :, 1] + pad)
                     & (boxes_b[None, :, 0] <= boxes_a[:, None, 1] + pad), axis=-1)
    if b is None:
        overlap &= np.triu(np.ones_like(overlap), k=1).astype(bool)
    pairs = np.argwhere(overlap)
    out = IntersectionResult(method=method)
    for done, (i, j) in enumerate(pairs, start=1):
        fa, fb = faces_a[i], faces_b[j]
        start = time.perf_counter()
        curves, found_by, record = pair_curves(fa, fb, tol, mesh_tol, method)
        for curve, how in zip(curves, found_by):
            for piece in clip_curve(curve, fa, fb, tol):
                if b is None and _along_a_boundary(piece, fa, fb, tol):
                    continue
                out.append(FaceIntersection(piece, fa, fb, tol, how))
        out.isolated_points += _contacts(record, fa, fb, tol, b is None)
        if record is not None:
            out.coincident += [CoincidentFaces(fa, fb, r) for r in record.coincident]
        out.records.append(PairRecord(fa, fb, record, tuple(curves), time.perf_counter() - start))
        if progress is not None:
            progress(done, len(pairs))
    return out
