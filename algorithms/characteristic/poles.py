"""Tangential contacts at collapsed sides (poles) of a parametrization.

The characteristic points of 002 are found where ``grad phi = 0`` inside the
domain of ``r``, and the projection onto ``q`` assumes a regular ``q``. A
sphere resting on a plate touches it at a *pole* of the usual NURBS sphere: a
side of the parameter domain that collapses to one point. There ``phi`` has
its extremum on the boundary of the domain (``phi_u = 0`` along the whole
side, ``det H = 0``), and projecting onto the pole is degenerate, so neither
role of the pair sees the contact as a critical point.

This module checks those points directly. For every collapsed side ``P`` of
either surface:

1. ``P`` lies within ``tol`` of the other surface (closest-point projection);
2. the normals there are parallel (the limit normal at the pole,
   :func:`surfprep.algorithms.measure.normals`) -- otherwise the other surface
   crosses the pole transversally and the curve through it is the triangle
   method's business;
3. two rings of points around ``P`` on its surface (at 1e-3 and 1e-2 of the
   pair's size) lie strictly on one side of the other surface, farther than
   ``tol``: locally the surfaces meet only at ``P``, an isolated point
   (002 §4.2, ``det H > 0``) rather than a small loop or a tangential curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..measure import normals
from ..projection import project_to_surface
from ..surface import NurbsSurface

__all__ = ["PoleContact", "collapsed_sides", "pole_contacts"]

#: sin of the largest angle between the normals at a tangential contact
PARALLEL_SINE = 1e-3
#: ring radii around a pole, as shares of the pair's size
RING_SHARES = (1e-3, 1e-2)
#: points per ring
RING_POINTS = 16


@dataclass(frozen=True)
class PoleContact:
    """An isolated tangential contact at a collapsed side.

    Attributes
    ----------
    point : (3,) float
    uv_a, uv_b : (2,) float
        Parameters on the pair's ``a`` and ``b`` (on the collapsed side: its mid
        parameter).
    distance : float
        Distance between the two surfaces there.
    """

    point: NDArray
    uv_a: NDArray
    uv_b: NDArray
    distance: float


def collapsed_sides(surface: NurbsSurface, *, rel: float = 1e-12) -> list[NDArray]:
    """Mid parameters ``(2,)`` of the sides of the domain whose control row is one point.

    A side collapses when every control point of its boundary row lies within
    ``rel`` times the control-net diagonal of the first one (then the side maps
    to that point whatever the weights).
    """
    net = surface.control_points
    scale = max(float(np.ptp(net.reshape(-1, net.shape[-1]), axis=0).max()), 1e-300)
    u0, u1, v0, v1 = surface.domain
    rows = ((net[0], (u0, 0.5 * (v0 + v1))), (net[-1], (u1, 0.5 * (v0 + v1))),
            (net[:, 0], (0.5 * (u0 + u1), v0)), (net[:, -1], (0.5 * (u0 + u1), v1)))
    return [np.array(uv, dtype=float) for row, uv in rows
            if np.abs(row - row[0]).max() <= rel * scale]


def _ring(surface: NurbsSurface, uv: NDArray, radius: float) -> NDArray:
    """``(RING_POINTS, 3)`` points of ``surface`` about ``radius`` from its pole at ``uv``."""
    u0, u1, v0, v1 = surface.domain
    pole = surface.evaluate(*uv)
    on_u_side = uv[0] in (u0, u1)
    along = np.linspace(v0, v1, RING_POINTS) if on_u_side else np.linspace(u0, u1, RING_POINTS)
    lo, hi = (u0, u1) if on_u_side else (v0, v1)
    inward = 1.0 if uv[0 if on_u_side else 1] == lo else -1.0
    # the step off the pole that puts the ring at ``radius`` (bisection on the mean distance)
    a, b = 0.0, hi - lo
    for _ in range(50):
        h = 0.5 * (a + b)
        cross = uv[0 if on_u_side else 1] + inward * h
        pts = (surface.evaluate(np.full(RING_POINTS, cross), along) if on_u_side
               else surface.evaluate(along, np.full(RING_POINTS, cross)))
        a, b = (h, b) if np.linalg.norm(pts - pole, axis=-1).mean() < radius else (a, h)
    return pts


def _contact_at(s: NurbsSurface, o: NurbsSurface, uv: NDArray, *, tol: float, size: float
                ) -> tuple[NDArray, NDArray, float] | None:
    """Point, parameters on ``o`` and distance of a contact at ``s``'s pole ``uv``, or None."""
    pole = s.evaluate(*uv)
    foot = project_to_surface(o, pole[None], tol=1e-3 * tol)
    distance = float(foot.distance[0])
    if distance > tol:
        return None
    n_s = normals(s, uv[0], uv[1])
    n_o = normals(o, foot.uv[0, 0], foot.uv[0, 1])
    if np.linalg.norm(np.cross(n_s, n_o)) > PARALLEL_SINE:
        return None
    for share in RING_SHARES:
        ring = _ring(s, uv, share * size)
        feet = project_to_surface(o, ring, tol=1e-3 * tol)
        side = np.einsum("ij,ij->i", ring - feet.points, normals(o, feet.uv[:, 0], feet.uv[:, 1]))
        if not (np.all(side > tol) or np.all(side < -tol)):
            return None
    return pole, foot.uv[0], distance


def pole_contacts(a: NurbsSurface, b: NurbsSurface, *, tol: float) -> list[PoleContact]:
    """Isolated tangential contacts of ``a`` and ``b`` at collapsed sides of either.

    Parameters
    ----------
    a, b : NurbsSurface
    tol : float
        Model units: the largest distance between the surfaces at a contact.

    Returns
    -------
    list of PoleContact
        In the pair's order (``uv_a`` on ``a``, ``uv_b`` on ``b``).
    """
    size = float(np.linalg.norm(np.ptp(np.concatenate([a.bounding_box(), b.bounding_box()]),
                                       axis=0)))
    found = []
    for s, o, swapped in ((a, b, False), (b, a, True)):
        for uv in collapsed_sides(s):
            hit = _contact_at(s, o, uv, tol=tol, size=size)
            if hit is None:
                continue
            point, uv_other, distance = hit
            uv_a, uv_b = (uv_other, uv) if swapped else (uv, uv_other)
            found.append(PoleContact(point, uv_a, uv_b, distance))
    return found
