"""Closest points on NURBS surfaces and curves (point inversion), vectorized over points.

For a query point ``P`` the foot point minimizes ``f(u, v) = |S(u, v) - P|^2 / 2``
over the parameter rectangle. With ``r = S(u, v) - P`` (section 6.1 of [PT]):

.. math:: \\nabla f = \\begin{pmatrix} r \\cdot S_u \\\\ r \\cdot S_v \\end{pmatrix},
          \\qquad
          \\nabla^2 f = \\begin{pmatrix} |S_u|^2 + r \\cdot S_{uu} & S_u \\cdot S_v + r \\cdot S_{uv} \\\\
                                         S_u \\cdot S_v + r \\cdot S_{uv} & |S_v|^2 + r \\cdot S_{vv}
                        \\end{pmatrix}  \\qquad (6.6, 6.7)

and Newton's step solves ``H delta = -grad f``. The method, for all points at once:

1. **Seeds.** The surface is sampled on a grid a few times denser than its knot
   spans (``evaluate_grid``); a :class:`scipy.spatial.cKDTree` gives each
   query's nearest samples. The nearest one (distance ``d0``) is always a
   seed; up to ``n_seeds - 1`` more are taken among the samples within
   ``d0 + h`` (``h`` the largest grid cell size: every closer basin has a
   sample there) that are local minima of the distance on the grid and not
   grid neighbours of the nearest, so a point over a fold or a narrow neck
   also starts on the other sheet, while a point over a plain region costs
   one seed. Every
   (point, seed) pair is one Newton problem.
2. **Newton with bounds.** A parameter at a bound whose gradient pushes
   outward is fixed for that iteration (the problem continues in 1D along the
   boundary, or stops at a corner); the others take the Newton step of the
   full Hessian when it is positive definite, else of the Hessian shifted to
   be positive definite (a descent step that follows negative curvature),
   projected onto the box. A step that increases the distance is halved (up
   to 30 times); each accepted step decreases the distance, so a result is
   never farther than its seed sample.
3. **Convergence** (eq. 6.8 of [PT], in model units): the point coincides
   (``|r| <= tol``), or the zero-cosine test holds for the free parameters,
   written as tangential residuals ``|r . S_u| / |S_u| <= tol`` (the 3D
   distance from the foot along the tangent), or the 3D step
   ``|S(x_new) - S(x)|`` is ``<= tol``. The step of the iteration that passes
   the test is still applied, which squares the error (Newton).
   Only the unconverged problems are evaluated in each iteration.
4. **Creases.** Knot lines of multiplicity >= degree may carry a jump of the
   first derivatives, where Newton would stall. The domain is cut there into
   pieces and each problem runs inside one piece (its box). A seed on a
   crease starts on both sides; a problem that stops on a crease with
   descent on the other side continues in the neighbouring piece; grid
   neighbours across a crease do not count in the local-minimum test of
   the seeds; a foot within ``_CREASE_REACH`` of its piece's width from a
   crease is sought again from the crease's other side (the basin there may
   have no seed). A foot exactly on a crease is reported ``1e-13`` of the
   parameter range before it when reached from below (:mod:`.creases`).
5. The best result over the seeds of each query is returned.

Curves are the same with one parameter (``r . C'`` and ``|C'|^2 + r . C''``).

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   section 6.1 (point inversion and projection, eqs. 6.3-6.8).
"""

from .newton import DEFAULT_RELATIVE_TOL
from .onto_curve import CurveProjectionResult, distance_to_curve, project_to_curve
from .onto_surface import ProjectionResult, distance_to_surface, project_to_surface

__all__ = [
    "DEFAULT_RELATIVE_TOL",
    "CurveProjectionResult",
    "ProjectionResult",
    "distance_to_curve",
    "distance_to_surface",
    "project_to_curve",
    "project_to_surface",
]
