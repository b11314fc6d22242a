"""The default ``auto`` method: the triangle method, checked and completed by the
characteristic stage (002), on one pair of surfaces.

:func:`auto_intersection` chooses per pair, cheapest first:

1. **prefilter** (:func:`.prefilter.no_loop_reason`): boxes apart (nothing to do), or
   a plane against a ruled surface or a monotone height (no loop, no contact
   possible): the triangle method alone;
2. ``phi`` on the stage's grid (:func:`.grid.stage_grid`); surfaces that cross
   **at a small angle** somewhere on it (``crossing_sine`` below
   :func:`small_angle`): the characteristic method alone
   (:func:`.algorithm.characteristic_intersection`, on that grid), whose tracing
   by eq. 33 with a corrector does not depend on an angle, where the triangles'
   segments stop chaining into one curve (:mod:`.crossing`: fragments,
   zigzags, or a curve dropped as stray);
3. the **characteristic stage** (:func:`.algorithm.characteristic_analysis`, the
   light form: u-characteristic curves from the sides, no border points);
   surfaces **coinciding** over the whole grid: no triangles (they would give
   only debris), the coincident region is the answer;
4. otherwise the triangle method, told the **tangential curves** the stage
   traced (their fragments left out), then the certificate
   (:func:`.algorithm.certify`): loops it missed are traced and added.

``record.extra["route"]`` says which way a pair went.
"""

from __future__ import annotations

import enum
import warnings
from collections.abc import Callable, Sequence

from ..intersection import IntersectionCurve, SmallAngleWarning, StrayCurves, intersect_surfaces
from ..intersection.angles import small_crossing_sine
from ..intersection.pipeline import MESH_TOL_FACTOR, operand_size
from ..surface import NurbsSurface
from .algorithm import (
    CharacteristicRecord,
    certify,
    characteristic_analysis,
    characteristic_intersection,
    tangential_curves,
)
from .grid import stage_grid
from .prefilter import NoLoopReason, no_loop_reason, uncertified_record

__all__ = ["FULL_COINCIDENCE", "Route", "auto_intersection", "small_angle"]

#: a coincident region with this share of the grid: the triangle method is not run
FULL_COINCIDENCE = 0.95

Triangles = Callable[[Sequence[IntersectionCurve]], list[IntersectionCurve]]


class Route(str, enum.Enum):
    """How :func:`auto_intersection` answered a pair."""

    PREFILTER = "prefilter"
    COINCIDENT = "coincident"
    SMALL_ANGLE = "small crossing angle"
    CERTIFIED = "triangles + certificate"


def small_angle(a: NurbsSurface, b: NurbsSurface, mesh_tol: float | None = None) -> float:
    """Sine below which a crossing is too flat for the triangle method at ``mesh_tol``
    (default: the pipeline's, ``MESH_TOL_FACTOR`` times the pair's size;
    :func:`..intersection.angles.small_crossing_sine`)."""
    size = operand_size(a, b)[0]
    return small_crossing_sine(size, MESH_TOL_FACTOR * size if mesh_tol is None else mesh_tol)


def _default_triangles(a: NurbsSurface, b: NurbsSurface, tol: float, mesh_tol: float | None
                       ) -> Triangles:
    return lambda tangential: intersect_surfaces(a, b, tol=tol, mesh_tol=mesh_tol,
                                                 stray=StrayCurves.DROP, tangential=tangential)


def _quiet(run: Triangles) -> Triangles:
    """``run`` without the triangle method's SmallAngleWarning: ``auto`` weighed the
    angle for its route, and the warning points users to ``auto``."""
    def quiet(tangential: Sequence[IntersectionCurve]) -> list[IntersectionCurve]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SmallAngleWarning)
            return run(tangential)
    return quiet


def _routed(record: CharacteristicRecord, route: Route) -> CharacteristicRecord:
    record.extra["route"] = route.value
    return record


def auto_intersection(a: NurbsSurface, b: NurbsSurface, *, tol: float,
                      mesh_tol: float | None = None, triangles: Triangles | None = None
                      ) -> CharacteristicRecord:
    """Intersection of two surfaces by the ``auto`` method (module docstring).

    Parameters
    ----------
    a, b : NurbsSurface
        In 3D.
    tol : float
        Model units.
    mesh_tol : float, optional
        The triangle method's tessellation tolerance (its default when None).
    triangles : callable, optional
        ``triangles(tangential) -> curves``: the triangle method to run (e.g. one
        that turns its failures into warnings); by default
        ``intersect_surfaces(a, b, tol=tol, mesh_tol=mesh_tol, stray=DROP,
        tangential=tangential)``.

    Returns
    -------
    CharacteristicRecord
        Curves with how each was found, isolated contact points, coincident
        regions; ``extra["route"]`` the :class:`Route` taken.
    """
    run = _quiet(triangles or _default_triangles(a, b, tol, mesh_tol))
    reason = no_loop_reason(a, b, tol=tol)
    if reason is not None:
        curves = [] if reason is NoLoopReason.APART else run(())
        return _routed(uncertified_record(curves, reason), Route.PREFILTER)
    grid = stage_grid(a, b, tol=tol)
    if grid.crossing_sine < small_angle(a, b, mesh_tol):
        record = characteristic_intersection(a, b, tol=tol, grid=grid)
        whole = any(r.share >= FULL_COINCIDENCE for r in record.coincident)
        return _routed(record, Route.COINCIDENT if whole else Route.SMALL_ANGLE)
    analysis = characteristic_analysis(a, b, tol=tol, trace_critical=False, borders=False,
                                       grid=grid)
    if any(r.share >= FULL_COINCIDENCE for r in analysis.coincident):
        return _routed(certify(a, b, [], tol=tol, analysis=analysis), Route.COINCIDENT)
    tangential = tangential_curves(analysis, tol)
    curves = run(tangential)
    record = certify(a, b, curves, tol=tol, analysis=analysis, tangential=tangential)
    return _routed(record, Route.CERTIFIED)
