"""The shared edges of a sewn shape as :func:`~.close_gaps.close_gaps` reads them: each
edge's faces, its pcurves on them and their images, sampled on ``s`` in [0, 1] of each
pcurve's range (B-spline pcurves and surfaces evaluated as NURBS, others point by point
through OpenCascade), and a face's B-spline surface as a :class:`NurbsSurface` when it
converts in the same parameters."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools
from OCP.Geom import Geom_BSplineSurface
from OCP.Geom2d import Geom2d_TrimmedCurve
from OCP.gp import gp_Pnt, gp_Pnt2d
from OCP.ShapeAnalysis import ShapeAnalysis_Surface
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_REVERSED
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS

from ...algorithms.curve import NurbsCurve
from ...algorithms.fitting import interpolate_surface
from ...algorithms.projection import project_to_surface
from ...algorithms.surface import NurbsSurface
from ...errors import SurfprepError
from ..occ.edges import EXACT_2D, converts_exactly
from ..occ.geom import curve_from_occ, surface_from_occ

__all__ = ["SharedEdge", "analytic_as_nurbs", "edges_by_face", "face_surface", "feet_on_face",
           "images_on_face", "pcurve", "pcurve_points", "read_edge", "same_surface"]

#: samples a side at most of :func:`analytic_as_nurbs`'s interpolant
ANALYTIC_MAX_SAMPLES = 513


@dataclass
class SharedEdge:
    """One edge of the shape with its faces' images on ``s`` in [0, 1]."""

    edge: object
    faces: list[int]                    # indices in the face map (a seam's face once)
    ranges: list[tuple[float, float]]   # per face, the pcurve's range
    first: int                          # vertex indices at s = 0 and s = 1
    last: int
    seam: bool = False
    degenerated: bool = False
    gap: float = 0.0
    curves: dict = field(default_factory=dict)      # (i, reverse) -> NurbsCurve or None
    surfaces: dict = field(default_factory=dict)    # face -> NurbsSurface or None (shared)
    feet: dict = field(default_factory=dict)        # (i, reverse, digest) -> (uv, feet)


def read_edge(edge_faces, k: int, faces, vertices, shared: dict) -> SharedEdge:
    edge = TopoDS.Edge_s(edge_faces.FindKey(k))
    indices, ranges = [], []
    for f in edge_faces.FindFromIndex(k):
        i = faces.FindIndex(f)
        if i not in indices:
            indices.append(i)
            ranges.append(BRep_Tool.Range_s(edge, TopoDS.Face_s(f)))
    first = vertices.FindIndex(TopExp.FirstVertex_s(edge))
    last = vertices.FindIndex(TopExp.LastVertex_s(edge))
    seam = len(indices) == 1 and BRep_Tool.IsClosed_s(edge, TopoDS.Face_s(faces.FindKey(indices[0])))
    return SharedEdge(edge, indices, ranges, first, last, seam, BRep_Tool.Degenerated_s(edge),
                 surfaces=shared)


def edges_by_face(edges: list[SharedEdge]) -> dict[int, list[SharedEdge]]:
    out: dict[int, list[SharedEdge]] = {}
    for e in edges:
        for f in e.faces:
            out.setdefault(f, []).append(e)
    return out


def pcurve(e: SharedEdge, i: int, faces, reverse: bool = False):
    face = TopoDS.Face_s(faces.FindKey(e.faces[i]))
    edge = e.edge.Oriented(TopAbs_REVERSED if reverse else TopAbs_FORWARD)
    return BRep_Tool.CurveOnSurface_s(TopoDS.Edge_s(edge), face, 0.0, 0.0)


def pcurve_points(e: SharedEdge, i: int, faces, s: NDArray, reverse: bool = False) -> NDArray:
    """The pcurve of ``e`` on its ``i``-th face at ``s`` in [0, 1] of its range
    (evaluated as a NURBS curve when it converts with its parameter, B-splines and lines,
    else point by point)."""
    a, b = e.ranges[i]
    t = a + s * (b - a)
    key = (i, reverse)
    if key not in e.curves:
        curve = pcurve(e, i, faces, reverse)
        e.curves[key] = curve
        if converts_exactly(curve, EXACT_2D, Geom2d_TrimmedCurve):
            try:
                e.curves[key] = curve_from_occ(curve, (min(a, b), max(a, b)))
            except SurfprepError:
                pass
    curve = e.curves[key]
    if isinstance(curve, NurbsCurve):
        lo, hi = curve.domain
        return curve.evaluate(np.clip(t, lo, hi))
    return np.array([curve.Value(x).Coord() for x in t])


def images_on_face(e: SharedEdge, i: int, faces, s: NDArray, reverse: bool = False) -> NDArray:
    """``S_F(pc_F(t))`` for any surface, (len(s), 3): a B-spline surface evaluated as a
    NURBS surface, others by OpenCascade.

    Beyond its domain OpenCascade continues a B-spline surface by the polynomials of its
    end spans, as :meth:`NurbsSurface.evaluate` does (``tests/plugin/occ/test_geom.py``);
    a periodic one wraps around instead, so there only parameters inside the domain are
    evaluated as a NURBS surface. (Pcurves that run a little beyond the domain sent
    every image of such an edge point by point through OpenCascade: 4.4 s of closing
    ``overture_asmo_icem.igs``'s gaps.)"""
    surface, nurbs = face_surface(e, e.faces[i], faces)
    uv = pcurve_points(e, i, faces, s, reverse)
    if nurbs is not None:
        u0, u1, v0, v1 = nurbs.domain
        if (not (surface.IsUPeriodic() or surface.IsVPeriodic())
                or np.all((uv[:, 0] >= u0) & (uv[:, 0] <= u1) & (uv[:, 1] >= v0)
                          & (uv[:, 1] <= v1))):
            return nurbs.evaluate(uv[:, 0], uv[:, 1])
    return np.array([surface.Value(u, v).Coord() for u, v in uv])


def feet_on_face(e: SharedEdge, i: int, faces, points: NDArray, s: NDArray,
                 reverse: bool = False) -> tuple[NDArray, NDArray]:
    """Closest points of the surface of ``e``'s ``i``-th face to ``points`` (m, 3), each
    started from the face's pcurve at the same ``s`` (m,): ``(uv (m, 2), feet (m, 3))``.
    A B-spline surface converting in the same parameters is projected as a NURBS
    surface (clamped to its domain), any other surface point by point by OpenCascade's
    ``ShapeAnalysis_Surface`` (an unbounded or periodic surface: the foot nearest the
    start).

    Kept on ``e`` by the points and ``s`` asked (like its pcurves, ``e.curves``: the face
    as read): the rounds of closing gaps ask some feet of a fixed face again (on the
    impeller 588 of 2 965 asks, whose revolved faces are projected point by point: the
    2 377 others cost 47 s)."""
    key = (i, reverse, hashlib.blake2b(np.ascontiguousarray(points, float).tobytes()
                                       + np.ascontiguousarray(s, float).tobytes()).digest())
    if key not in e.feet:
        e.feet[key] = _feet_on_face(e, i, faces, points, s, reverse)
    uv, feet = e.feet[key]
    return uv.copy(), feet.copy()


def _feet_on_face(e: SharedEdge, i: int, faces, points: NDArray, s: NDArray, reverse: bool
                  ) -> tuple[NDArray, NDArray]:
    f = e.faces[i]
    guess = pcurve_points(e, i, faces, s, reverse)
    surface, nurbs = face_surface(e, f, faces)
    if nurbs is not None and same_surface(faces, f, [e]) is nurbs:
        found = project_to_surface(nurbs, points, guess=guess)
        return found.uv, found.points
    analysis = ShapeAnalysis_Surface(surface)
    precision = 1e-12 * float(np.abs(points).max(initial=1.0))
    uv = np.empty((len(points), 2))
    for k, (p, (u, v)) in enumerate(zip(points, guess)):
        uv[k] = analysis.NextValueOfUV(gp_Pnt2d(u, v), gp_Pnt(*p), precision, -1.0).Coord()
    # on a periodic surface each foot in the period of its start (a torus's feet came
    # back a period away from the pcurve, and the pcurve through them crossed the face)
    for k, (periodic, period) in enumerate(((surface.IsUPeriodic(), surface.UPeriod),
                                           (surface.IsVPeriodic(), surface.VPeriod))):
        if periodic:
            step = period()
            uv[:, k] += step * np.round((guess[:, k] - uv[:, k]) / step)
    feet = np.array([surface.Value(u, v).Coord() for u, v in uv])
    return uv, feet


def face_surface(e: SharedEdge, f: int, faces):
    """Face ``f``'s surface and, for a B-spline, its :class:`NurbsSurface` (else None),
    converted once (the cache is shared by all edges of the shape)."""
    if f not in e.surfaces:
        surface = BRep_Tool.Surface_s(TopoDS.Face_s(faces.FindKey(f)))
        e.surfaces[f] = (surface, None)
        if isinstance(surface, Geom_BSplineSurface):
            try:
                e.surfaces[f] = (surface, surface_from_occ(surface))
            except SurfprepError:
                pass
    return e.surfaces[f]


def same_surface(faces, f: int, edges: list[SharedEdge]) -> NurbsSurface | None:
    """Face ``f``'s B-spline surface as a :class:`NurbsSurface` in the same parameters
    (checked at its pcurves' ends and middles), or None for a surface that is not a
    B-spline or does not convert exactly."""
    surface, nurbs = face_surface(next(e for e in edges if f in e.faces), f, faces)
    if nurbs is None:
        return None
    uv = np.concatenate([pcurve_points(e, e.faces.index(f), faces, np.array([0.0, 0.5, 1.0]))
                         for e in edges if f in e.faces])
    u0, u1, v0, v1 = nurbs.domain
    inside = ((uv[:, 0] >= u0 - 1e-9 * (u1 - u0)) & (uv[:, 0] <= u1 + 1e-9 * (u1 - u0))
              & (uv[:, 1] >= v0 - 1e-9 * (v1 - v0)) & (uv[:, 1] <= v1 + 1e-9 * (v1 - v0)))
    if not inside.all():
        return None
    ours = nurbs.evaluate(uv[:, 0], uv[:, 1])
    theirs = np.array([surface.Value(u, v).Coord() for u, v in uv])
    scale = float(np.ptp(nurbs.control_points.reshape(-1, 3), axis=0).max()) or 1.0
    return nurbs if np.max(np.abs(ours - theirs)) <= 1e-9 * scale else None


def analytic_as_nurbs(faces, f: int, tol: float, *, max_samples: int = ANALYTIC_MAX_SAMPLES
                      ) -> NurbsSurface | None:
    """Face ``f``'s surface (not a B-spline: a torus, a cylinder, ...) as a bicubic
    B-spline in the same parameters over the face's parameter box: the interpolant of
    its points on a grid refined (per direction, doubling) until it lies within ``tol``
    of the surface midway between the grid lines, or None when ``max_samples`` a side
    do not get there. Its pcurves stay valid on it, so the face can be moved like a
    B-spline face (:mod:`.close_gaps`)."""
    face = TopoDS.Face_s(faces.FindKey(f))
    surface = BRep_Tool.Surface_s(face)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    if not (u1 > u0 and v1 > v0):
        return None

    def values(u, v):
        return np.array([[surface.Value(a, b).Coord() for b in v] for a in u])

    nu = nv = 9
    while nu <= max_samples and nv <= max_samples:
        u, v = np.linspace(u0, u1, nu), np.linspace(v0, v1, nv)
        fit = interpolate_surface(values(u, v), params_u=u, params_v=v)
        mu, mv = 0.5 * (u[:-1] + u[1:]), 0.5 * (v[:-1] + v[1:])
        off_u = np.linalg.norm(fit.evaluate_grid(mu, v) - values(mu, v), axis=-1).max()
        off_v = np.linalg.norm(fit.evaluate_grid(u, mv) - values(u, mv), axis=-1).max()
        if max(off_u, off_v) <= tol:
            return fit
        nu, nv = (2 * nu - 1 if off_u > tol else nu), (2 * nv - 1 if off_v > tol else nv)
    return None
