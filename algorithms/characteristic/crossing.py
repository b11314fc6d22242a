"""How steeply two surfaces cross, read off the characteristic stage's grid.

On the first surface ``r`` the oriented distance ``phi = n_q . (r - Q)`` (002
eq. 2) has the surface gradient ``grad_S phi = n_q - (n_q . n_r) n_r``: its
length is the sine of the angle between the two surfaces' normals. In
parameters, ``phi_u = n_q . r_u`` and ``phi_v = n_q . r_v`` (eqs. 24-25), so

    |grad_S phi|^2 = (G phi_u^2 - 2 F phi_u phi_v + E phi_v^2) / (E G - F^2)

with ``E, F, G`` the first fundamental form of ``r``.
:func:`grid_crossing_sine` takes the smallest of it over the grid nodes beside a
sign change of ``phi``: the steepness of the flattest crossing. A triangle
method whose tessellations stray ``mesh_tol`` from the surfaces places a
crossing at an angle ``theta`` up to about ``2 mesh_tol / theta`` off along the
surface, more than a triangle's width once ``theta`` falls below about
``sqrt(mesh_tol kappa)``: its segments no longer chain into one curve
(fragments, zigzags, or nothing left within tol).
"""

from __future__ import annotations

import numpy as np

from .distance import DistanceField, DistanceJet
from .projector import ProjectionStatus

__all__ = ["grid_crossing_sine"]


def grid_crossing_sine(field: DistanceField, jet: DistanceJet, shape: tuple[int, int]) -> float:
    """Smallest sine of the angle between the normals at the grid nodes beside a sign
    change of ``phi`` (module docstring); ``inf`` when ``phi`` changes sign nowhere.

    Parameters
    ----------
    field : DistanceField
    jet : DistanceJet
        ``phi`` and its gradient at the ``nu * nv`` grid nodes, row by row.
    shape : (nu, nv)
    """
    nu, nv = shape
    positive = (jet.phi > 0).reshape(nu, nv)          # phi = 0 on a node counts as a side
    ok = (jet.status == ProjectionStatus.UNIQUE).reshape(nu, nv)
    beside = np.zeros((nu, nv), dtype=bool)
    for axis in (0, 1):
        lo = (slice(0, -1), slice(None)) if axis == 0 else (slice(None), slice(0, -1))
        hi = (slice(1, None), slice(None)) if axis == 0 else (slice(None), slice(1, None))
        change = (positive[lo] != positive[hi]) & ok[lo] & ok[hi]
        beside[lo] |= change
        beside[hi] |= change
    rows = np.flatnonzero(beside.ravel())
    if rows.size == 0:
        return float("inf")
    uv = jet.uv[rows]
    d = field.r.derivatives(uv[:, 0], uv[:, 1], 1)
    ru, rv = d[:, 1, 0], d[:, 0, 1]
    e, f, g = (np.einsum("ij,ij->i", x, y) for x, y in ((ru, ru), (ru, rv), (rv, rv)))
    det = e * g - f * f
    pu, pv = jet.grad[rows, 0], jet.grad[rows, 1]
    regular = det > 1e-12 * np.maximum(e * g, np.finfo(float).tiny)
    if not regular.any():
        return float("inf")
    sq = (g * pu * pu - 2 * f * pu * pv + e * pv * pv)[regular] / det[regular]
    return float(np.sqrt(np.clip(sq, 0.0, 1.0)).min())
