"""Exact isoparametric curves of NURBS surfaces.

Fixing ``u = u*`` in the homogeneous surface gives

.. math:: S^w(u^*, v) = \\sum_j N_{j,q}(v) \\Big(\\sum_i N_{i,p}(u^*) P^w_{ij}\\Big),

a B-spline curve in ``v`` with the surface's ``v`` knots and degree and the
homogeneous poles ``Q^w_j = \\sum_i N_{i,p}(u^*) P^w_{ij}``: one contraction of the
basis with the net, exact for rational surfaces (section 4.5 of [PT]).

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997.
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidGeometryError
from .basis import basis_functions
from .curve import NurbsCurve
from .surface import NurbsSurface
from .tensor import Direction, as_direction, check_in_domain, check_parameter, knots_along, net_along

__all__ = ["isocurve"]


def isocurve(surface: NurbsSurface, value: float, direction: Direction | str) -> NurbsCurve:
    """The isoparametric curve ``direction = value`` of a surface.

    Parameters
    ----------
    surface : NurbsSurface
    value : float
        Parameter held fixed, inside its domain.
    direction : Direction
        ``Direction.U``: the curve ``u = value``, parametrized by v (OpenCascade's
        ``UIso``); ``Direction.V``: the curve ``v = value``, parametrized by u.

    Returns
    -------
    NurbsCurve
        Knots and degree of the other direction; rational when the surface is.
    """
    direction = as_direction(direction)
    knots, degree = knots_along(surface, direction)
    value = check_parameter(value, "isocurve parameter")
    try:
        check_in_domain(value, knots, degree, "isocurve parameter")
    except InvalidGeometryError as exc:
        raise InvalidGeometryError(f"{exc} (direction {direction.name})") from None
    net = net_along(surface, direction)                     # (n_fixed, n_run, d+1)
    span, values = basis_functions(knots, degree, np.array([value]))
    rows = net[span[0] - degree:span[0] + 1]                 # (degree+1, n_run, d+1)
    poles_w = np.einsum("i,ijc->jc", values[0], rows)
    other = Direction.V if direction is Direction.U else Direction.U
    run_knots, run_degree = knots_along(surface, other)
    return NurbsCurve.from_homogeneous(poles_w, run_knots, run_degree,
                                       rational=surface.weights is not None)
