"""Chord-length (RCA) reparametrization of a surface within a tolerance (section 29.2).

:func:`reparametrize_surface` builds a new C2 bicubic B-spline surface ``r``
that lies within ``tol`` of the original ``s`` (both ways, eq. 29.3) and whose
parameters follow arc length (eqs. 29.1/29.2):

1. the four boundaries get interpolation points by arc length and curvature
   (:mod:`.boundary`, section 29.2.4);
2. opposite boundaries are reconciled to one fraction sequence per direction
   (:mod:`.reconcile`, section 29.2.5); the new parameters are these
   fractions times the mean length of the two boundaries, so one unit of
   parameter is about one unit of length;
3. interior points start where straight lines joining opposite boundary points
   cross in the original domain and are relocated by the penalty iteration
   (:mod:`.interior`, section 29.2.6) - this is what fixes distortions that
   mix u and v (shear), which per-direction arc length cannot;
4. the C2 cubic (not-a-knot) interpolant of the grid is measured densely
   (:mod:`.deviation`, eq. 29.3); where it is off by more than ``tol`` the
   intervals get their midpoints as new knots (a grid line of new points) and
   steps 3-4 repeat, up to ``max_iterations`` times.

A collapsed boundary (a pole: its length is below ``tol / 10``) takes the
fractions of the opposite one and gives a collapsed boundary of ``r`` again;
if both boundaries of a direction are collapsed, the middle isoparametric
curve gives the fractions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import RegularGridInterpolator

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..fitting import interpolate_surface, knots_from_breakpoints
from ..isocurve import isocurve
from ..knots import Direction
from ..parametrization import parametrization_quality
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from .boundary import ArcLengthTable, arc_length_table, boundary_fractions
from .deviation import deviation_map, original_on_new
from .interior import PENALTY_TOL, initial_guess, relocate
from .reconcile import insert_midpoints, reconcile_fractions

__all__ = [
    "DEFAULT_RELATIVE_TOL",
    "ReparametrizationResult",
    "crease_knots",
    "default_tolerance",
    "reparametrize_surface",
]

#: Default ``tol``: this fraction of the control-net bounding-box diagonal.
DEFAULT_RELATIVE_TOL = 1e-4
#: Smallest and largest ``tol`` accepted, as fractions of the diagonal.
MIN_RELATIVE_TOL, MAX_RELATIVE_TOL = 1e-9, 0.1
#: Share of ``tol`` for the boundary fits and for the error along grid lines.
BOUNDARY_SHARE = 0.8
#: Turn of the cross derivative (radians) across a knot line that makes it a crease.
CREASE_ANGLE = 1e-4
#: Fewest interpolation points per direction (a cubic not-a-knot spline).
MIN_POINTS = 4


@dataclass(frozen=True)
class ReparametrizationResult:
    """A chord-length parametrized approximation and how good it is.

    Attributes
    ----------
    surface : NurbsSurface
        Non-rational C2 bicubic; domain ``[0, L_u] x [0, L_v]`` with ``L_u``,
        ``L_v`` the mean lengths of opposite boundaries.
    tol : float
        The tolerance asked for (model units).
    max_deviation : float
        Largest measured distance, both ways (eq. 29.3), at >= ``per_span^2``
        points per cell.
    within_tolerance : bool
        ``max_deviation <= tol``; False when ``max_iterations`` or
        ``max_points`` ran out first.
    mismatch_before, mismatch_after : float
        Worst chord-length mismatch (eqs. 29.1/29.2,
        :func:`~surfprep.algorithms.parametrization.parametrization_quality`)
        of the original and of the result; 1 is perfect.
    iterations : int
        Fit-and-measure rounds.
    knots_inserted : int
        Grid lines added by the error loop (u and v together).
    relocation_sweeps : int
        Sweeps of the interior relocation over all rounds.
    relocation_converged : bool
        The last relocation stopped because no node moved.
    params_u, params_v : (n_u,), (n_v,) float
        New parameters of the interpolation points.
    uv : (n_u, n_v, 2) float
        Their parameters on the original surface (the reparametrization map).
    """

    surface: NurbsSurface
    tol: float
    max_deviation: float
    within_tolerance: bool
    mismatch_before: float
    mismatch_after: float
    iterations: int
    knots_inserted: int
    relocation_sweeps: int
    relocation_converged: bool
    params_u: NDArray
    params_v: NDArray
    uv: NDArray

    @property
    def grid_shape(self) -> tuple[int, int]:
        return (len(self.params_u), len(self.params_v))


def default_tolerance(surface: NurbsSurface) -> float:
    """:data:`DEFAULT_RELATIVE_TOL` times the control-net bounding-box diagonal."""
    return DEFAULT_RELATIVE_TOL * _size(surface)


def _size(surface: NurbsSurface) -> float:
    box = np.asarray(surface.bounding_box(), dtype=float).reshape(2, -1)
    return float(np.linalg.norm(box[1] - box[0]))


@dataclass(frozen=True)
class _Direction:
    """The two boundaries of one direction: tables (None if collapsed) and fractions."""

    first: ArcLengthTable | None
    second: ArcLengthTable | None
    length: float

    def parameters(self, fractions: NDArray) -> tuple[NDArray, NDArray]:
        a = self.first.parameters_at(fractions) if self.first is not None else None
        b = self.second.parameters_at(fractions) if self.second is not None else None
        return (a if a is not None else b), (b if b is not None else a)


def _boundaries(surface: NurbsSurface, along: Direction, tol: float
                ) -> tuple[_Direction, NDArray]:
    """Tables and reconciled fractions of the two boundaries running along ``along``."""
    held = Direction.V if along is Direction.U else Direction.U
    u0, u1, v0, v1 = surface.domain
    lo, hi = (v0, v1) if held is Direction.V else (u0, u1)
    tables = [arc_length_table(isocurve(surface, value, held), 0.1 * tol) for value in (lo, hi)]
    alive = [t if t.length > 0.1 * tol else None for t in tables]
    if all(t is None for t in alive):
        middle = arc_length_table(isocurve(surface, 0.5 * (lo + hi), held), 0.1 * tol)
        if middle.length <= 0.1 * tol:
            raise DegenerateGeometryError(
                f"the surface is collapsed along {along.name}: its boundaries and middle "
                f"isoparametric curve are shorter than tol/10 = {0.1 * tol:.3g}")
        sets = [boundary_fractions(middle, BOUNDARY_SHARE * tol)[0]]
        # both boundaries are poles: they take the middle curve's parameters
        pole = _Direction(middle, middle, middle.length)
        return pole, _at_least(reconcile_fractions(*sets))
    sets = [None if t is None else boundary_fractions(t, BOUNDARY_SHARE * tol)[0] for t in alive]
    length = float(np.mean([t.length for t in alive if t is not None]))
    return _Direction(alive[0], alive[1], length), _at_least(reconcile_fractions(*sets))


def _at_least(fractions: NDArray, count: int = MIN_POINTS) -> NDArray:
    while len(fractions) < count:
        widest = np.zeros(len(fractions) - 1, bool)
        widest[np.argmax(np.diff(fractions))] = True
        fractions = insert_midpoints(fractions, widest)
    return fractions


def _start_grid(surface: NurbsSurface, du: _Direction, dv: _Direction, fu: NDArray,
                fv: NDArray, previous: tuple[NDArray, NDArray, NDArray] | None) -> NDArray:
    """Initial guess (straight lines), or the previous grid interpolated at the new fractions."""
    bottom, top = du.parameters(fu)
    left, right = dv.parameters(fv)
    uv = initial_guess(bottom, top, left, right, surface.domain)
    if previous is not None:
        old_fu, old_fv, old_uv = previous
        lookup = RegularGridInterpolator((old_fu, old_fv), old_uv)
        mesh = np.stack(np.meshgrid(fu, fv, indexing="ij"), axis=-1)
        uv[1:-1, 1:-1] = lookup(mesh[1:-1, 1:-1].reshape(-1, 2)).reshape(mesh[1:-1, 1:-1].shape)
    return uv


def _refinement(dev, reverse, params_u: NDArray, params_v: NDArray, tol: float
                ) -> tuple[NDArray, NDArray]:
    """Intervals of u and v that get a midpoint: grid lines off by more than a share of
    ``tol`` in their own direction, both directions of a cell off by more than ``tol``."""
    bad_u = dev.u_errors > BOUNDARY_SHARE * tol
    bad_v = dev.v_errors > BOUNDARY_SHARE * tol
    ci, cj = np.nonzero(dev.cell_errors > tol)
    distance, uv = reverse
    far = distance > tol
    ri = np.clip(np.searchsorted(params_u, uv[far, 0]) - 1, 0, len(params_u) - 2)
    rj = np.clip(np.searchsorted(params_v, uv[far, 1]) - 1, 0, len(params_v) - 2)
    ci, cj = np.concatenate([ci, ri]), np.concatenate([cj, rj])
    unexplained = ~(bad_u[ci] | bad_v[cj])
    bad_u[ci[unexplained]] = True
    bad_v[cj[unexplained]] = True
    return bad_u, bad_v


def reparametrize_surface(surface: NurbsSurface, *, tol: float | None = None,
                          per_span: int = 10, max_iterations: int = 12,
                          max_points: int = 400, relocation: bool = True,
                          max_sweeps: int = 2000) -> ReparametrizationResult:
    """Chord-length (RCA) reparametrization within ``tol`` (section 29.2, module docstring).

    Parameters
    ----------
    surface : NurbsSurface
        Any (rational) B-spline surface in 3D.
    tol : float, optional
        Model units; default :data:`DEFAULT_RELATIVE_TOL` (1e-4) times the
        control-net bounding-box diagonal. Accepted between 1e-9 and 0.1 times
        the diagonal.
    per_span : int
        Check points per interpolation interval and direction (>= 10: the
        paper's density of 10 x 10 per knot span).
    max_iterations : int
        Fit-and-measure rounds at most.
    max_points : int
        Interpolation points per direction at most.
    relocation : bool
        Run the interior relocation (False: keep the straight-line initial
        guess; for comparison only).
    max_sweeps : int
        Sweeps of each relocation at most.

    Returns
    -------
    ReparametrizationResult
        ``within_tolerance`` False (not an exception) when the limits ran out.

    Raises
    ------
    InvalidGeometryError
        Not a 3D NurbsSurface, or it has creases (:func:`crease_knots`),
        which a C2 surface cannot follow.
    DegenerateGeometryError
        The surface is a point, or collapsed along a whole direction.
    InvalidToleranceError
        ``tol`` not finite and positive, or outside the accepted range.
    """
    if not isinstance(surface, NurbsSurface) or surface.dimension != 3:
        raise InvalidGeometryError(f"need a 3D NurbsSurface, got {type(surface).__name__}")
    size = _size(surface)
    if not size > 0:
        raise DegenerateGeometryError("the surface is a single point")
    tol = default_tolerance(surface) if tol is None else tol
    tol = check_tolerance(tol, "tol", low=MIN_RELATIVE_TOL * size, high=MAX_RELATIVE_TOL * size)
    _refuse_creases(surface)
    if per_span < 10:
        raise InvalidGeometryError(f"per_span must be >= 10, got {per_span}")
    du, fu = _boundaries(surface, Direction.U, tol)
    dv, fv = _boundaries(surface, Direction.V, tol)
    previous, sweeps, inserted = None, 0, 0
    for iteration in range(1, max_iterations + 1):
        uv = _start_grid(surface, du, dv, fu, fv, previous)
        if relocation:
            moved = relocate(surface, uv, fu, fv, max_sweeps=max_sweeps, penalty_tol=PENALTY_TOL)
            uv, points, settled = moved.uv, moved.points, moved.converged
            sweeps += moved.sweeps
        else:
            points, settled = surface.evaluate(uv[..., 0], uv[..., 1]), True
        pu, pv = fu * du.length, fv * dv.length
        new = interpolate_surface(points, params_u=pu, params_v=pv,
                                  knots_u=knots_from_breakpoints(pu, 3),
                                  knots_v=knots_from_breakpoints(pv, 3))
        dev = deviation_map(surface, new, pu, pv, uv, per_span)
        reverse = original_on_new(surface, new, pu, pv, uv, per_span)
        worst = max(dev.max, float(reverse[0].max()))
        done = worst <= tol
        if done or iteration == max_iterations:
            break
        bad_u, bad_v = _refinement(dev, reverse, pu, pv, tol)
        if len(fu) + bad_u.sum() > max_points or len(fv) + bad_v.sum() > max_points:
            break
        previous = (fu, fv, uv)
        fu, fv = insert_midpoints(fu, bad_u), insert_midpoints(fv, bad_v)
        inserted += int(bad_u.sum() + bad_v.sum())
    return ReparametrizationResult(
        surface=new, tol=tol, max_deviation=worst, within_tolerance=bool(done),
        mismatch_before=_mismatch(surface), mismatch_after=_mismatch(new),
        iterations=iteration, knots_inserted=inserted, relocation_sweeps=sweeps,
        relocation_converged=bool(settled), params_u=pu, params_v=pv, uv=uv)


def crease_knots(surface: NurbsSurface, angle: float = CREASE_ANGLE) -> tuple[NDArray, NDArray]:
    """Interior knot lines in u and in v where the surface has a crease.

    A candidate is an interior knot of multiplicity >= degree (only C0 by the
    knots); it is a crease when the cross derivative turns by more than
    ``angle`` (radians) across it at one of 17 points along the line (knots
    of full multiplicity with collinear poles are smooth and pass).
    """
    out = []
    along = np.linspace(0.0, 1.0, 17)
    for axis, (knots, degree, n) in enumerate(
            ((surface.knots_u, surface.degree_u, surface.n_control[0]),
             (surface.knots_v, surface.degree_v, surface.n_control[1]))):
        values, counts = np.unique(knots[degree + 1:n], return_counts=True)
        found = []
        for value in values[counts >= degree]:
            lo, hi = (surface.domain[2:] if axis == 0 else surface.domain[:2])
            other = lo + along * (hi - lo)
            eps = 1e-9 * (knots[-1] - knots[0])
            sides = []
            for x in (value - eps, value + eps):
                uv = (np.full_like(other, x), other) if axis == 0 else (other, np.full_like(other, x))
                d = surface.derivatives(*uv, 1)
                sides.append(d[:, 1, 0] if axis == 0 else d[:, 0, 1])
            cos = np.sum(sides[0] * sides[1], -1) / np.maximum(
                np.linalg.norm(sides[0], axis=-1) * np.linalg.norm(sides[1], axis=-1), 1e-300)
            if np.arccos(np.clip(cos, -1.0, 1.0)).max() > angle:
                found.append(value)
        out.append(np.array(found))
    return out[0], out[1]


def _refuse_creases(surface: NurbsSurface) -> None:
    cu, cv = crease_knots(surface)
    if cu.size or cv.size:
        raise InvalidGeometryError(
            f"the surface has creases (tangent-discontinuous knot lines u = "
            f"{[round(float(x), 9) for x in cu]}, v = {[round(float(x), 9) for x in cv]}): a C2 "
            "reparametrization cannot follow them; split the surface there first")


def _mismatch(surface: NurbsSurface) -> float:
    worst = parametrization_quality(surface).worst
    return float(worst) if not math.isnan(worst) else 1.0
