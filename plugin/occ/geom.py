"""Lossless conversion between OpenCascade B-spline geometry and surfprep's NURBS types.

``Geom_BSplineSurface``, ``Geom_BSplineCurve`` and ``Geom2d_BSplineCurve`` map to
:class:`~surfprep.algorithms.NurbsSurface` / :class:`~surfprep.algorithms.NurbsCurve`
and back with the knot values, multiplicities, degrees, poles and weights copied
exactly (no renormalization). Periodic OpenCascade objects are converted to the
clamped (non-periodic) form on a copy first; OpenCascade's ``SetNotPeriodic``
keeps both the geometry and the parametrization. Any other ``Geom_Surface`` /
``Geom_Curve`` goes through OpenCascade's own NURBS conversion
(``GeomConvert``), after trimming infinite ones to given parameter bounds.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from OCP.Geom import (
    Geom_BSplineCurve,
    Geom_BSplineSurface,
    Geom_Curve,
    Geom_RectangularTrimmedSurface,
    Geom_Surface,
    Geom_TrimmedCurve,
)
from OCP.Geom2d import Geom2d_BSplineCurve, Geom2d_Curve, Geom2d_TrimmedCurve
from OCP.Geom2dConvert import Geom2dConvert
from OCP.GeomConvert import GeomConvert
from OCP.gp import gp_Pnt, gp_Pnt2d
from OCP.Precision import Precision
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array1OfPnt2d, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal

from ...algorithms import NurbsCurve, NurbsSurface
from ...errors import ConversionError, OpenCascadeError
from .failures import describe, is_occ_failure

__all__ = [
    "curve2d_to_occ",
    "curve_from_occ",
    "curve_to_occ",
    "surface_from_occ",
    "surface_to_occ",
]


# ------------------------------------------------------------------ helpers
def _array1(values: NDArray, cls=TColStd_Array1OfReal):
    arr = cls(1, len(values))
    for i, x in enumerate(np.asarray(values).tolist()):    # (Python floats and ints)
        arr.SetValue(i + 1, x)
    return arr


def _compress_knots(knots: NDArray) -> tuple[TColStd_Array1OfReal, TColStd_Array1OfInteger]:
    values, mults = np.unique(knots, return_counts=True)
    return _array1(values), _array1(mults.astype(int), TColStd_Array1OfInteger)


def _flat(arr) -> NDArray:
    return np.array([arr.Value(i) for i in range(arr.Lower(), arr.Upper() + 1)], dtype=float)


def _is_infinite(*bounds: float) -> bool:
    return any(abs(b) >= Precision.Infinite_s() for b in bounds)


# ------------------------------------------------------------------ surfaces
def surface_from_occ(surface: Geom_Surface,
                     bounds: tuple[float, float, float, float] | None = None) -> NurbsSurface:
    """A :class:`NurbsSurface` equal to an OpenCascade surface.

    Parameters
    ----------
    surface : Geom_Surface
        A ``Geom_BSplineSurface`` converts exactly; any other surface goes
        through ``GeomConvert.SurfaceToBSplineSurface_s``.
    bounds : (u0, u1, v0, v1), optional
        Parameter rectangle to trim to first; required for infinite surfaces
        (planes, cylinders, extrusions) and ignored for B-spline surfaces.

    Raises
    ------
    ConversionError
        For an infinite surface without bounds, or one OpenCascade cannot convert.
    """
    if not isinstance(surface, Geom_BSplineSurface):
        surface = _to_bspline_surface(surface, bounds)
    if surface.IsUPeriodic() or surface.IsVPeriodic():
        surface = surface.Copy()  # OCP returns the most-derived type
        if surface.IsUPeriodic():
            surface.SetUNotPeriodic()
        if surface.IsVPeriodic():
            surface.SetVNotPeriodic()
    nu, nv = surface.NbUPoles(), surface.NbVPoles()
    poles = surface.Poles()
    cp = np.empty((nu, nv, 3))
    for i in range(nu):
        for j in range(nv):
            cp[i, j] = poles.Value(i + 1, j + 1).Coord()
    weights = None
    if surface.IsURational() or surface.IsVRational():
        w = surface.Weights()
        weights = np.array([[w.Value(i + 1, j + 1) for j in range(nv)] for i in range(nu)])
    return NurbsSurface(cp, _flat(surface.UKnotSequence()), _flat(surface.VKnotSequence()),
                        surface.UDegree(), surface.VDegree(), weights)


def _to_bspline_surface(surface: Geom_Surface, bounds) -> Geom_BSplineSurface:
    u0, u1, v0, v1 = surface.Bounds()
    if bounds is not None:
        u0, u1, v0, v1 = bounds
    if _is_infinite(u0, u1, v0, v1):
        raise ConversionError(
            f"{surface.DynamicType().Name()} is infinite in its parameters; "
            "give bounds=(u0, u1, v0, v1) (a face's UV bounds) to convert it")
    if bounds is not None:
        surface = Geom_RectangularTrimmedSurface(surface, u0, u1, v0, v1)
    try:
        out = GeomConvert.SurfaceToBSplineSurface_s(surface)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise ConversionError(f"OpenCascade cannot convert {surface.DynamicType().Name()} "
                              f"to a B-spline: {describe(exc)}") from exc
    if out is None:
        raise OpenCascadeError("GeomConvert.SurfaceToBSplineSurface returned no surface")
    return out


def surface_to_occ(surface: NurbsSurface) -> Geom_BSplineSurface:
    """A ``Geom_BSplineSurface`` equal to ``surface`` (same knots, poles, weights)."""
    if not isinstance(surface, NurbsSurface):
        raise ConversionError(f"expected a NurbsSurface, got {type(surface).__name__}")
    if surface.dimension != 3:
        raise ConversionError(f"OpenCascade surfaces are 3D; this one has dimension {surface.dimension}")
    nu, nv = surface.n_control
    poles = TColgp_Array2OfPnt(1, nu, 1, nv)
    cp = surface.control_points
    for i in range(nu):
        for j in range(nv):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*cp[i, j].tolist()))
    uk, um = _compress_knots(surface.knots_u)
    vk, vm = _compress_knots(surface.knots_v)
    try:
        if surface.weights is None:
            return Geom_BSplineSurface(poles, uk, vk, um, vm, surface.degree_u, surface.degree_v)
        w = TColStd_Array2OfReal(1, nu, 1, nv)
        for i in range(nu):
            for j in range(nv):
                w.SetValue(i + 1, j + 1, float(surface.weights[i, j]))
        return Geom_BSplineSurface(poles, w, uk, vk, um, vm, surface.degree_u, surface.degree_v)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise ConversionError(f"OpenCascade refused the surface: {describe(exc)}") from exc


# -------------------------------------------------------------------- curves
def curve_from_occ(curve: Geom_Curve | Geom2d_Curve,
                   bounds: tuple[float, float] | None = None) -> NurbsCurve:
    """A :class:`NurbsCurve` equal to an OpenCascade 3D or 2D curve.

    Parameters
    ----------
    curve : Geom_Curve or Geom2d_Curve
        B-spline curves convert exactly; other curves go through
        ``GeomConvert`` / ``Geom2dConvert`` (``CurveToBSplineCurve``).
    bounds : (t0, t1), optional
        Trim first; required for infinite curves (lines) and for closed
        periodic curves restricted to an edge's range.
    """
    is2d = isinstance(curve, Geom2d_Curve)
    bspline_cls = Geom2d_BSplineCurve if is2d else Geom_BSplineCurve
    if not isinstance(curve, bspline_cls) or bounds is not None:
        curve = _to_bspline_curve(curve, bounds, is2d)
    if curve.IsPeriodic():
        curve = curve.Copy()
        curve.SetNotPeriodic()
    n = curve.NbPoles()
    poles = curve.Poles()
    cp = np.array([poles.Value(i + 1).Coord() for i in range(n)], dtype=float)
    weights = None
    if curve.IsRational():
        w = curve.Weights()
        weights = np.array([w.Value(i + 1) for i in range(n)])
    return NurbsCurve(cp, _flat(curve.KnotSequence()), curve.Degree(), weights)


def _to_bspline_curve(curve, bounds, is2d: bool):
    t0, t1 = (curve.FirstParameter(), curve.LastParameter()) if bounds is None else bounds
    if _is_infinite(t0, t1):
        raise ConversionError(
            f"{curve.DynamicType().Name()} is infinite; give bounds=(t0, t1) to convert it")
    trimmed_cls = Geom2d_TrimmedCurve if is2d else Geom_TrimmedCurve
    try:
        if bounds is not None:
            curve = trimmed_cls(curve, t0, t1)
        conv = Geom2dConvert if is2d else GeomConvert
        return conv.CurveToBSplineCurve_s(curve)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise ConversionError(f"OpenCascade cannot convert {curve.DynamicType().Name()} "
                              f"to a B-spline: {describe(exc)}") from exc


def curve_to_occ(curve: NurbsCurve) -> Geom_BSplineCurve:
    """A ``Geom_BSplineCurve`` equal to a 3D :class:`NurbsCurve`."""
    return _curve_to_occ(curve, 3, TColgp_Array1OfPnt, gp_Pnt, Geom_BSplineCurve)


def curve2d_to_occ(curve: NurbsCurve) -> Geom2d_BSplineCurve:
    """A ``Geom2d_BSplineCurve`` equal to a 2D :class:`NurbsCurve` (a pcurve)."""
    return _curve_to_occ(curve, 2, TColgp_Array1OfPnt2d, gp_Pnt2d, Geom2d_BSplineCurve)


def _curve_to_occ(curve, dim, array_cls, point_cls, bspline_cls):
    if not isinstance(curve, NurbsCurve):
        raise ConversionError(f"expected a NurbsCurve, got {type(curve).__name__}")
    if curve.dimension != dim:
        raise ConversionError(f"expected a {dim}D curve, got dimension {curve.dimension}")
    poles = array_cls(1, curve.n_control)
    for i, pt in enumerate(curve.control_points.tolist()):
        poles.SetValue(i + 1, point_cls(*pt))
    knots, mults = _compress_knots(curve.knots)
    try:
        if curve.weights is None:
            return bspline_cls(poles, knots, mults, curve.degree)
        return bspline_cls(poles, _array1(curve.weights), knots, mults, curve.degree)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise ConversionError(f"OpenCascade refused the curve: {describe(exc)}") from exc
