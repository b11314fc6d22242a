"""Intersection points corrected onto both exact surfaces by triple-plane intersection
(004 §6).

A point ``p`` of a mesh intersection segment lies off the true curve by about the
chord error of the two triangulations. 004 §6 improves it by intersecting three
planes: the tangent plane of surface B at the foot ``B = B(u, v)`` of ``p`` on B, the
tangent plane of surface G at its foot ``G = G(s, t)`` on G, and the plane through the
three points ``p``, ``B``, ``G``. ``B - p`` and ``G - p`` lie along the two surfaces'
normals, so the third plane is (to first order) the normal plane of the curve
through ``p``: the new point is where the curve -- linearized as the line common to
the two tangent planes -- crosses it. The step repeats (feet again, planes again)
until the feet are within ``tol`` of each other. Where ``p``, ``B`` and ``G`` are
collinear (``p`` already on one surface, or both feet equal), the third plane's
normal is taken as ``n_B x n_G``, the same plane in the limit (also wherever the plane
through the three points is more than 60 degrees from it: its normal is then rounding
noise).

With unit normals ``n_B``, ``n_G``, ``n_3`` and offsets ``d_B = n_B . B``,
``d_G = n_G . G``, ``d_3 = n_3 . p`` the three planes meet at

.. math:: x = \\frac{d_B\\, n_G \\times n_3 + d_G\\, n_3 \\times n_B + d_3\\, n_B \\times n_G}
                    {[n_B, n_G, n_3]} .

The feet are found by Newton's method from the previous ones
(:func:`surfprep.algorithms.intersection.refine.project_points`), which is 004's
"projection" step; a start value from the mesh's barycentric ``(u, v)`` makes it
converge in a few iterations.

References
----------
004 §6 (see ``surfprep.algorithms`` References).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..intersection.refine import project_points
from ..intersection.seams import closed_directions, seam_restarts
from ..measure import normals
from ..surface import NurbsSurface
from ..tolerance import check_tolerance

__all__ = ["CorrectedPoints", "correct_points", "three_planes"]

#: a point whose feet's gap shrinks by less than this factor in a step has stalled
STALL = 0.5
#: |n_B x n_G| below this: the surfaces are tangent there and the point is left as is
TANGENT_SIN = 1e-8


@dataclass(frozen=True)
class CorrectedPoints:
    """Points corrected onto two surfaces.

    Attributes
    ----------
    points : (n, 3) float
        The midpoints of the two feet.
    uv_a, uv_b : (n, 2) float
        The feet's parameters on each surface.
    gap : (n,) float
        Distance between the two feet: the point is within ``gap / 2`` of both
        surfaces.
    converged : (n,) bool
        ``gap <= tol``. A point whose true position lies off either face (beyond its
        boundary: a foot is held there) stalls and is not converged.
    iterations : int
    """

    points: NDArray
    uv_a: NDArray
    uv_b: NDArray
    gap: NDArray
    converged: NDArray
    iterations: int


def _dot(a: NDArray, b: NDArray) -> NDArray:
    return np.einsum("ij,ij->i", a, b)


def _unit(a: NDArray) -> tuple[NDArray, NDArray]:
    size = np.linalg.norm(a, axis=1)
    return a / np.where(size > 0, size, 1.0)[:, None], size


def three_planes(normals: NDArray, offsets: NDArray) -> tuple[NDArray, NDArray]:
    """The points common to three planes ``n_k . x = d_k`` each.

    Parameters
    ----------
    normals : (n, 3, 3) float
        ``normals[:, k]`` the (unit) normal of plane ``k``.
    offsets : (n, 3) float

    Returns
    -------
    points : (n, 3) float
    determinant : (n,) float
        ``[n_0, n_1, n_2]``; where it is 0 the planes do not meet in a point (the
        point returned there is NaN).
    """
    n0, n1, n2 = normals[:, 0], normals[:, 1], normals[:, 2]
    c12, c20, c01 = np.cross(n1, n2), np.cross(n2, n0), np.cross(n0, n1)
    det = _dot(n0, c12)
    num = offsets[:, :1] * c12 + offsets[:, 1:2] * c20 + offsets[:, 2:] * c01
    with np.errstate(divide="ignore", invalid="ignore"):
        return num / det[:, None], det


def _feet(surface: NurbsSurface, x: NDArray, uv: NDArray, closed: tuple[bool, bool], tol: float
          ) -> tuple[NDArray, NDArray]:
    """Feet of ``x`` from ``uv``; a foot stopped on the seam of a closed direction is sought
    again from the seam's other side, and the nearer foot kept."""
    uv, foot, _ = project_points(surface, x, uv, tol=tol)
    for rows, start in seam_restarts(surface, uv, closed):
        uv2, foot2, _ = project_points(surface, x[rows], start, tol=tol)
        better = (np.linalg.norm(foot2 - x[rows], axis=1)
                  < np.linalg.norm(foot[rows] - x[rows], axis=1))
        uv[rows[better]], foot[rows[better]] = uv2[better], foot2[better]
    return uv, foot


def correct_points(surface_a: NurbsSurface, surface_b: NurbsSurface, points: ArrayLike,
                   uv_a: ArrayLike, uv_b: ArrayLike, *, tol: float, max_iter: int = 20
                   ) -> CorrectedPoints:
    """Move points onto the intersection of two surfaces (004 §6, the module doc).

    Parameters
    ----------
    surface_a, surface_b : NurbsSurface (3D)
    points : (n, 3) float
        Points near the intersection curve (a mesh intersection's segment ends).
    uv_a, uv_b : (n, 2) float
        Start parameters of their feet on each surface.
    tol : float > 0
        Model units: stop when the two feet are within ``tol``.
    max_iter : int

    Returns
    -------
    CorrectedPoints
    """
    tol = check_tolerance(tol)
    p = np.array(points, dtype=float).reshape(-1, 3)
    ua = np.array(uv_a, dtype=float).reshape(-1, 2)
    ub = np.array(uv_b, dtype=float).reshape(-1, 2)
    if not (ua.shape[0] == ub.shape[0] == p.shape[0]):
        raise InvalidGeometryError("points, uv_a and uv_b need one row per point")
    n = p.shape[0]
    gap = np.full(n, np.inf)
    active = np.arange(n)
    foot_a, foot_b = np.empty((n, 3)), np.empty((n, 3))
    closed_a, closed_b = closed_directions(surface_a, tol), closed_directions(surface_b, tol)
    foot_tol = 1e-3 * tol
    iterations = 0
    for iterations in range(1, max_iter + 1):
        ua[active], foot_a[active] = _feet(surface_a, p[active], ua[active], closed_a, foot_tol)
        ub[active], foot_b[active] = _feet(surface_b, p[active], ub[active], closed_b, foot_tol)
        previous = gap[active]
        gap[active] = np.linalg.norm(foot_a[active] - foot_b[active], axis=1)
        # converged, or stalled (the gap no longer halves: a foot held on a face's
        # boundary, the curve leaving the face there) from the third step on
        going = gap[active] > tol
        if iterations >= 3:
            going &= gap[active] <= STALL * previous
        active = active[going]
        if active.size == 0:
            break
        na = normals(surface_a, ua[active, 0], ua[active, 1])
        nb = normals(surface_b, ub[active, 0], ub[active, 1])
        along, sin = _unit(np.cross(na, nb))
        third = _unit(np.cross(foot_a[active] - p[active], foot_b[active] - p[active]))[0]
        # p, B, G nearly collinear (p on one surface already, or both feet equal): the
        # cross product is rounding noise; its limit is the normal plane of the curve
        collinear = ~(np.abs(_dot(third, along)) >= 0.5)
        third[collinear] = along[collinear]
        planes = np.stack([na, nb, third], axis=1)
        offsets = np.stack([_dot(na, foot_a[active]), _dot(nb, foot_b[active]),
                            _dot(third, p[active])], axis=1)
        x, det = three_planes(planes, offsets)
        ok = (sin > TANGENT_SIN) & (np.abs(det) > TANGENT_SIN) & np.all(np.isfinite(x), axis=1)
        p[active[ok]] = x[ok]
        active = active[ok]          # tangent there: no plane point; the feet stay as found
        if active.size == 0:
            break
    middle = 0.5 * (foot_a + foot_b)
    return CorrectedPoints(middle, ua, ub, gap, gap <= tol, iterations)
