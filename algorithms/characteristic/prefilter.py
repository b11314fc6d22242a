"""Pairs the certificate need not examine: cheap, exact reasons why two surfaces
can have no closed loop and no isolated contact point.

The certificate (:func:`.algorithm.certify`) looks for closed loops around
critical points of ``phi`` and for tangential contact points. Two cases rule
both out from the control nets alone (the net's convex hull holds the surface):

* **apart**: no Bézier-patch box of one surface comes within ``tol`` of a
  patch box of the other: the surfaces do not meet at all (no curve either);
* **plane x ruled**: one surface is planar (its control points within
  ``PLANAR_SHARE * tol`` of a plane) and the other is a plane too or has a
  straight parameter direction (degree 1 with two control points: every
  isoparametric line in that direction is a straight segment, rational or
  not). A segment meets a plane once or lies in it, so the intersection is a
  graph over the other parameter: it cannot close inside the domain; and at a
  tangential contact the segment through the point lies in the tangent plane,
  i.e. in the plane, so the contact is a segment, not an isolated point. The
  rule is not applied when the other surface lies within ``tol`` of the plane
  (coincidence is the full analysis's answer to give).
"""

from __future__ import annotations

import enum
from collections.abc import Sequence

import numpy as np

from ..intersection import IntersectionCurve
from ..surface import NurbsSurface
from .algorithm import CharacteristicRecord, FoundBy

__all__ = ["PLANAR_SHARE", "NoLoopReason", "no_loop_reason", "uncertified_record"]

#: a control net within this share of ``tol`` of a plane is planar
PLANAR_SHARE = 1e-3


class NoLoopReason(str, enum.Enum):
    """Why a pair can have no closed loop nor isolated contact point."""

    APART = "apart"
    PLANE_AND_RULED = "plane and ruled"


def _patch_boxes(s: NurbsSurface) -> np.ndarray:
    boxes, _, _ = s.patch_bounding_boxes()
    return np.asarray(boxes, dtype=float).reshape(-1, 2, s.dimension)


def _apart(a: NurbsSurface, b: NurbsSurface, tol: float) -> bool:
    ba, bb = _patch_boxes(a), _patch_boxes(b)
    touch = np.all((ba[:, None, 0] <= bb[None, :, 1] + tol)
                   & (bb[None, :, 0] <= ba[:, None, 1] + tol), axis=-1)
    return not bool(touch.any())


def _plane(s: NurbsSurface, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """``(point, unit normal)`` when the control net is planar within ``PLANAR_SHARE tol``."""
    pts = s.control_points.reshape(-1, s.dimension)
    if s.dimension != 3 or pts.shape[0] < 3:
        return None
    centre = pts.mean(axis=0)
    _, sv, vt = np.linalg.svd(pts - centre, full_matrices=False)
    if sv.size < 3 or sv[1] <= 0:
        return None
    normal = vt[2]
    if np.abs((pts - centre) @ normal).max() > PLANAR_SHARE * tol:
        return None
    return centre, normal


def _straight_direction(s: NurbsSurface) -> bool:
    """True when u or v is degree 1 with two control points (straight isolines)."""
    nu, nv = s.n_control
    return (s.degree_u == 1 and nu == 2) or (s.degree_v == 1 and nv == 2)


def no_loop_reason(a: NurbsSurface, b: NurbsSurface, *, tol: float) -> NoLoopReason | None:
    """Why ``a`` and ``b`` can have no closed loop nor isolated contact point (module
    docstring), or None when the certificate must look.

    Parameters
    ----------
    a, b : NurbsSurface
        In 3D.
    tol : float
        Model units.
    """
    if _apart(a, b, tol):
        return NoLoopReason.APART
    for flat, other in ((a, b), (b, a)):
        plane = _plane(flat, tol)
        if plane is None or not (_straight_direction(other) or _plane(other, tol) is not None):
            continue
        centre, normal = plane
        if np.abs((other.control_points.reshape(-1, 3) - centre) @ normal).max() <= tol:
            continue                                     # may coincide: full analysis
        return NoLoopReason.PLANE_AND_RULED
    return None


def uncertified_record(curves: Sequence[IntersectionCurve], reason: NoLoopReason
                       ) -> CharacteristicRecord:
    """The record of a pair the certificate skipped: ``curves`` as the triangle method
    found them, no characteristic points, ``extra["skipped"]`` the reason."""
    curves = tuple(curves)
    return CharacteristicRecord(curves, (FoundBy.MESH,) * len(curves), (), (), (), (), "a",
                                0.0, 0.0, extra={"skipped": reason.value})
