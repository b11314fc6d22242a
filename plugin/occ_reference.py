"""OpenCascade's own answers, for cross-checks and benchmarks.

Thin wrappers: every function calls the OpenCascade method named in its
docstring once per point, in a Python loop, and returns numpy arrays in the
layout of the matching surfprep function. Nothing is approximated or repaired
here; OpenCascade failures raise :class:`~surfprep.errors.OpenCascadeError`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from OCP.Geom import Geom_Curve, Geom_Surface
from OCP.Geom2d import Geom2d_Curve
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d

from ..algorithms import NurbsCurve, NurbsSurface
from ..errors import ConversionError, OpenCascadeError
from .occ.failures import describe, is_occ_failure
from .occ.geom import curve2d_to_occ, curve_to_occ, surface_to_occ

__all__ = ["evaluate_surface", "evaluate_curve", "project_point_on_surface"]

#: Which ``[k, l]`` entries of a surface derivative array OpenCascade fills, per order:
#: D0 gives S; D1 adds S_u, S_v; D2 adds S_uu, S_uv, S_vv. ``[1, 2]``, ``[2, 1]``
#: and ``[2, 2]`` (third and fourth total order) are left NaN.
SURFACE_ENTRIES = {
    0: ((0, 0),),
    1: ((0, 0), (1, 0), (0, 1)),
    2: ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)),
}


def _occ_surface(surface: NurbsSurface | Geom_Surface) -> Geom_Surface:
    if isinstance(surface, NurbsSurface):
        return surface_to_occ(surface)
    if isinstance(surface, Geom_Surface):
        return surface
    raise ConversionError(f"expected a NurbsSurface or Geom_Surface, got {type(surface).__name__}")


def _check_order(order: int) -> int:
    if order not in (0, 1, 2):
        raise ValueError(f"OpenCascade reference evaluation supports order 0, 1, 2; got {order}")
    return order


def evaluate_surface(surface: NurbsSurface | Geom_Surface, u: ArrayLike, v: ArrayLike,
                     order: int = 0) -> NDArray:
    """Surface point and partial derivatives by ``Geom_Surface.D0/D1/D2``.

    Parameters
    ----------
    surface : NurbsSurface or Geom_Surface
    u, v : (...) float, broadcast together
    order : 0, 1 or 2

    Returns
    -------
    (..., order + 1, order + 1, 3) float
        Same layout as :meth:`NurbsSurface.derivatives`: ``[..., k, l, :]`` is
        ``d^{k+l} S / du^k dv^l``. Only the entries of total order <= ``order``
        are filled (see :data:`SURFACE_ENTRIES`); the others are NaN.
    """
    order = _check_order(order)
    occ = _occ_surface(surface)
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    shape = u.shape
    out = np.full((u.size, order + 1, order + 1, 3), np.nan)
    p = gp_Pnt()
    d1u, d1v, d2u, d2v, d2uv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    for i, (a, b) in enumerate(zip(u.reshape(-1).tolist(), v.reshape(-1).tolist())):
        if order == 0:
            occ.D0(a, b, p)
        elif order == 1:
            occ.D1(a, b, p, d1u, d1v)
        else:
            occ.D2(a, b, p, d1u, d1v, d2u, d2v, d2uv)
        out[i, 0, 0] = p.Coord()
        if order >= 1:
            out[i, 1, 0] = d1u.Coord()
            out[i, 0, 1] = d1v.Coord()
        if order >= 2:
            out[i, 2, 0] = d2u.Coord()
            out[i, 1, 1] = d2uv.Coord()
            out[i, 0, 2] = d2v.Coord()
    return out.reshape(shape + out.shape[1:])


def evaluate_curve(curve: NurbsCurve | Geom_Curve | Geom2d_Curve, t: ArrayLike,
                   order: int = 0) -> NDArray:
    """Curve point and derivatives by ``Geom_Curve`` / ``Geom2d_Curve`` ``.D0/D1/D2``.

    Parameters
    ----------
    curve : NurbsCurve (d = 2 or 3), Geom_Curve or Geom2d_Curve
    t : (...) float
    order : 0, 1 or 2

    Returns
    -------
    (..., order + 1, d) float
        Same layout as :meth:`NurbsCurve.derivatives`, every entry filled.
    """
    order = _check_order(order)
    if isinstance(curve, NurbsCurve):
        if curve.dimension not in (2, 3):
            raise ConversionError(f"curves of dimension {curve.dimension} have no OpenCascade type")
        curve = curve2d_to_occ(curve) if curve.dimension == 2 else curve_to_occ(curve)
    if isinstance(curve, Geom2d_Curve):
        dim, p, d1, d2 = 2, gp_Pnt2d(), gp_Vec2d(), gp_Vec2d()
    elif isinstance(curve, Geom_Curve):
        dim, p, d1, d2 = 3, gp_Pnt(), gp_Vec(), gp_Vec()
    else:
        raise ConversionError(f"expected a NurbsCurve, Geom_Curve or Geom2d_Curve, got "
                              f"{type(curve).__name__}")
    t = np.asarray(t, dtype=float)
    out = np.empty((t.size, order + 1, dim))
    for i, a in enumerate(t.reshape(-1).tolist()):
        if order == 0:
            curve.D0(a, p)
        elif order == 1:
            curve.D1(a, p, d1)
        else:
            curve.D2(a, p, d1, d2)
        out[i, 0] = p.Coord()
        if order >= 1:
            out[i, 1] = d1.Coord()
        if order >= 2:
            out[i, 2] = d2.Coord()
    return out.reshape(t.shape + out.shape[1:])


def project_point_on_surface(surface: NurbsSurface | Geom_Surface,
                             points: ArrayLike) -> tuple[NDArray, NDArray]:
    """Closest point on the surface by ``GeomAPI_ProjectPointOnSurf``.

    The search is restricted to the surface's parameter bounds
    (``Geom_Surface.Bounds``); the nearest of the extrema found
    (``LowerDistanceParameters``) is returned.

    Parameters
    ----------
    surface : NurbsSurface or Geom_Surface (finite)
    points : (..., 3) float

    Returns
    -------
    uv : (..., 2) float
    distance : (...) float

    Raises
    ------
    OpenCascadeError
        When OpenCascade finds no projection for a point (``IsDone()`` false or
        ``NbPoints() == 0``), naming the point.
    """
    occ = _occ_surface(surface)
    points = np.asarray(points, dtype=float)
    if points.shape[-1] != 3:
        raise ValueError(f"points must have shape (..., 3), got {points.shape}")
    flat = points.reshape(-1, 3)
    uv = np.empty((flat.shape[0], 2))
    distance = np.empty(flat.shape[0])
    u0, u1, v0, v1 = occ.Bounds()
    projector = GeomAPI_ProjectPointOnSurf()
    projector.Init(occ, u0, u1, v0, v1)
    for i, xyz in enumerate(flat.tolist()):
        try:
            projector.Perform(gp_Pnt(*xyz))
        except Exception as exc:
            if not is_occ_failure(exc):
                raise
            raise OpenCascadeError(
                f"GeomAPI_ProjectPointOnSurf failed on point {xyz}: {describe(exc)}") from exc
        if not projector.IsDone() or projector.NbPoints() == 0:
            raise OpenCascadeError(f"GeomAPI_ProjectPointOnSurf found no projection of point {xyz}")
        uv[i] = projector.LowerDistanceParameters()
        distance[i] = projector.LowerDistance()
    return uv.reshape(points.shape[:-1] + (2,)), distance.reshape(points.shape[:-1])


# ====================================================== surface-surface intersection
# OpenCascade's answer to SSI (issue 3), returned as :class:`OccCurve` objects that
# carry ``points``, ``closed`` and ``length`` like surfprep's IntersectionCurve, so
# the same checks apply to both.
from dataclasses import dataclass as _dataclass  # noqa: E402

from OCP.BRep import BRep_Tool  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Curve  # noqa: E402
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section  # noqa: E402
from OCP.GeomAPI import GeomAPI_IntSS  # noqa: E402
from OCP.TopAbs import TopAbs_EDGE  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402
from OCP.TopoDS import TopoDS, TopoDS_Face  # noqa: E402

__all__ += ["OccCurve", "intersect_surfaces_occ", "section_faces_occ", "sample_occ_curve"]

#: samples per OpenCascade curve (uniform in its parameter)
OCC_CURVE_SAMPLES = 801


@_dataclass(frozen=True)
class OccCurve:
    """One intersection curve found by OpenCascade.

    Attributes
    ----------
    points : (n, 3) float
        Samples, uniform in the curve's parameter (a closed curve does not repeat
        its first sample).
    closed : bool
        The curve's ends meet (within ``1e-7`` times its length, or the curve says so).
    length : float
        Length of the polyline of the samples (closing chord included when closed).
    curves : tuple of Geom_Curve
        The OpenCascade curve(s) sampled (several edges of a section joined end to end).
    """

    points: NDArray
    closed: bool
    length: float
    curves: tuple


def sample_occ_curve(curve: Geom_Curve, first: float | None = None, last: float | None = None,
                     samples: int = OCC_CURVE_SAMPLES) -> NDArray:
    """``(samples, 3)`` points of ``curve`` uniform in its parameter over ``[first, last]``
    (default: its own bounds), by ``Geom_Curve.D0`` per point."""
    t0 = curve.FirstParameter() if first is None else first
    t1 = curve.LastParameter() if last is None else last
    if not (np.isfinite(t0) and np.isfinite(t1)) or abs(t0) > 1e90 or abs(t1) > 1e90:
        raise OpenCascadeError(f"cannot sample an infinite {curve.DynamicType().Name()}")
    return evaluate_curve(curve, np.linspace(t0, t1, samples))[:, 0]


def _occ_curve(points: NDArray, curves: tuple, closed_flag: bool = False) -> OccCurve:
    chord = np.linalg.norm(np.diff(points, axis=0), axis=1).sum()
    gap = float(np.linalg.norm(points[-1] - points[0]))
    closed = closed_flag or (points.shape[0] > 2 and gap <= 1e-7 * max(chord, 1e-300))
    if closed and gap <= 1e-7 * max(chord, 1e-300):
        points = points[:-1]
    length = chord if not closed else chord + (0.0 if gap <= 1e-7 * chord else gap)
    points = np.ascontiguousarray(points)
    points.setflags(write=False)
    return OccCurve(points, bool(closed), float(length), curves)


def intersect_surfaces_occ(surface_a: NurbsSurface | Geom_Surface,
                           surface_b: NurbsSurface | Geom_Surface, tol: float,
                           samples: int = OCC_CURVE_SAMPLES) -> list[OccCurve]:
    """Intersection curves by ``GeomAPI_IntSS(S1, S2, tol)``, one per ``Line(i)``.

    Raises
    ------
    OpenCascadeError
        ``IsDone()`` false, or OpenCascade throws.
    """
    sa, sb = _occ_surface(surface_a), _occ_surface(surface_b)
    try:
        algo = GeomAPI_IntSS(sa, sb, float(tol))
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"GeomAPI_IntSS failed: {describe(exc)}") from exc
    if not algo.IsDone():
        raise OpenCascadeError("GeomAPI_IntSS did not finish (IsDone() is false)")
    out = []
    for i in range(1, algo.NbLines() + 1):
        line = algo.Line(i)
        pts = sample_occ_curve(line, samples=samples)
        out.append(_occ_curve(pts, (line,), bool(line.IsClosed())))
    return out


def _join_polylines(polylines: list[NDArray], curves: list, tol: float) -> list[OccCurve]:
    """Join polylines end to end where their ends meet within ``tol`` (greedy)."""
    pieces = [(p, [c]) for p, c in zip(polylines, curves)]
    joined: list[tuple[NDArray, list]] = []
    while pieces:
        cur, cs = pieces.pop(0)
        grown = True
        while grown:
            grown = False
            for k, (p, c) in enumerate(pieces):
                if np.linalg.norm(cur[-1] - p[0]) <= tol:
                    cur = np.vstack([cur, p[1:]])
                elif np.linalg.norm(cur[-1] - p[-1]) <= tol:
                    cur = np.vstack([cur, p[::-1][1:]])
                elif np.linalg.norm(cur[0] - p[-1]) <= tol:
                    cur = np.vstack([p, cur[1:]])
                elif np.linalg.norm(cur[0] - p[0]) <= tol:
                    cur = np.vstack([p[::-1], cur[1:]])
                else:
                    continue
                cs = cs + c
                pieces.pop(k)
                grown = True
                break
        joined.append((cur, cs))
    out = []
    for pts, cs in joined:
        closed = pts.shape[0] > 2 and np.linalg.norm(pts[-1] - pts[0]) <= tol
        out.append(_occ_curve(pts[:-1] if closed else pts, tuple(cs), bool(closed)))
    return out


def section_faces_occ(face_a: TopoDS_Face, face_b: TopoDS_Face, tol: float = 1e-7,
                      samples: int = OCC_CURVE_SAMPLES) -> list[OccCurve]:
    """Section of two trimmed faces by ``BRepAlgoAPI_Section`` (approximated curves).

    The section's edges are sampled over their ranges and joined end to end
    where they meet within ``tol`` (or the larger vertex tolerance), so one
    :class:`OccCurve` is one branch.

    Raises
    ------
    OpenCascadeError
        ``IsDone()`` false or OpenCascade throws.
    """
    try:
        section = BRepAlgoAPI_Section(face_a, face_b, False)
        section.Approximation(True)
        section.ComputePCurveOn1(True)
        section.ComputePCurveOn2(True)
        section.Build()
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"BRepAlgoAPI_Section failed: {describe(exc)}") from exc
    if not section.IsDone():
        raise OpenCascadeError("BRepAlgoAPI_Section did not finish (IsDone() is false)")
    shape = section.Shape()
    polylines, curves = [], []
    join = float(tol)
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        explorer.Next()
        if BRep_Tool.Degenerated_s(edge):
            continue
        adaptor = BRepAdaptor_Curve(edge)          # the edge's curve, location applied
        t = np.linspace(adaptor.FirstParameter(), adaptor.LastParameter(), samples)
        pts = np.array([adaptor.Value(x).Coord() for x in t.tolist()])
        polylines.append(pts)
        curves.append(BRep_Tool.Curve_s(edge, 0.0, 0.0))
        join = max(join, BRep_Tool.Tolerance_s(edge))
    return _join_polylines(polylines, curves, join)
