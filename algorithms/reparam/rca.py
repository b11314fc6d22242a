"""Chord-length (RCA) reparametrization of a surface within a tolerance (000 §29.2).

:func:`reparametrize_surface` builds a new C2 bicubic B-spline surface ``r``
that lies within ``tol`` of the original ``s`` (both ways, eq. 29.3) and whose
parameters follow arc length (eqs. 29.1/29.2):

1. the four boundaries get interpolation points by arc length and curvature
   (:mod:`.boundary_points`, section 29.2.4);
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
   steps 3-4 repeat, up to ``max_iterations`` times (or until the deviation
   grows to twice the best so far: then the relocation does not settle and
   more points do not help);
5. once within ``tol``, fewer points where the error leaves room
   (:mod:`.coarsen`): each direction is respaced by the h^4 law from the error
   its own spacing causes, relocated, fitted and measured again (kept only
   within ``tol``), then single grid lines far below ``tol`` are dropped.

Creases (knot lines of multiplicity >= degree across which the surface turns,
:func:`crease_knots`) become fixed grid lines: the lines along the other
direction are split there into pieces parametrized each by its own arc
length, the crease curves join the boundaries in the reconciliation, their
nodes do not move in the relocation, and the interpolant has a triple knot
(C0) there.

A collapsed boundary (a pole: its length is below ``tol / 10``) takes the
fractions of the opposite one and gives a collapsed boundary of ``r`` again;
if both boundaries of a direction are collapsed, the middle isoparametric
curve gives the fractions.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import RegularGridInterpolator

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..isocurve import isocurve
from ..measure import box_centre
from ..parametrization import parametrization_quality
from ..surface import NurbsSurface
from ..tensor import Direction
from ..tolerance import check_tolerance
from .boundary_points import arc_length_table, boundary_fractions
from .coarsen import RESPACE_TARGET, Fit, coarsen, respaced_fractions
from .interior import PENALTY_TOL, initial_guess, relocate
from .reconcile import insert_midpoints, reconcile_fractions
from .spline_grid import cell_errors, fit_and_measure, line_indices, subgrid_fit

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
#: Stop refining when the deviation grows beyond this factor of the best so far.
DIVERGING = 2.0
#: A coarser fit is kept only within this share of ``tol`` (a margin for what lies
#: between the 10 x 10 check points per cell).
COARSE_SHARE = 0.9
#: Respacings tried after the fit is within tol (each one relocation + fit + dense
#: check); each starts from the errors of the previous one, kept or not.
RESPACE_TRIES = 4
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
    lines_removed : int
        Grid lines dropped again by the coarsening (u and v together).
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
    lines_removed: int = 0

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
    """The lines running along one direction and the creases that split them.

    ``held`` are the values of the other parameter on which the lines lie: the
    two boundaries, then the creases of the other direction. ``tables[k]`` is
    line k's arc-length table (None when collapsed: it takes a live line's
    parameters). ``breaks`` are this direction's own crease parameters; the
    common coordinate ``F`` in [0, 1] runs through the pieces between them in
    proportion to their mean length, and each line maps ``F`` piecewise
    linearly to its own arc-length fraction (identity without creases).
    """

    held: NDArray
    tables: tuple
    breaks: NDArray
    f_breaks: NDArray
    arc_breaks: tuple
    length: float

    def parameters(self, fractions: NDArray) -> list[NDArray]:
        """Original parameters along every line at the common fractions ``(n,)``."""
        out = []
        for table, arcs in zip(self.tables, self.arc_breaks):
            out.append(None if table is None else
                       table.parameters_at(np.interp(fractions, self.f_breaks, arcs)))
        live = next(p for p in out if p is not None)
        out = [live if p is None else p for p in out]
        for k, c in enumerate(self.breaks, start=1):      # crease nodes exactly on the crease
            at = np.isclose(fractions, self.f_breaks[k], rtol=0.0, atol=1e-14)
            for p in out:
                p[at] = c
        return out

    def to_common(self, line: int, arc_fractions: NDArray) -> NDArray:
        return np.interp(arc_fractions, self.arc_breaks[line], self.f_breaks)


def _direction(surface: NurbsSurface, along: Direction, breaks: NDArray, other_breaks: NDArray,
               tol: float) -> tuple[_Direction, NDArray]:
    """Lines along ``along`` (boundaries + the other direction's creases), their pieces
    between ``breaks`` and the reconciled common fractions."""
    held_dir = Direction.V if along is Direction.U else Direction.U
    u0, u1, v0, v1 = surface.domain
    lo, hi = (v0, v1) if held_dir is Direction.V else (u0, u1)
    held = np.concatenate([[lo, hi], other_breaks])
    tables = [arc_length_table(isocurve(surface, value, held_dir), 0.1 * tol) for value in held]
    alive = [t if t.length > 0.1 * tol else None for t in tables]
    if all(t is None for t in alive):
        middle = arc_length_table(isocurve(surface, 0.5 * (lo + hi), held_dir), 0.1 * tol)
        if middle.length <= 0.1 * tol:
            raise DegenerateGeometryError(
                f"the surface is collapsed along {along.name}: its boundaries and middle "
                f"isoparametric curve are shorter than tol/10 = {0.1 * tol:.3g}")
        alive = [middle] * len(held)             # all lines are poles: the middle one leads
    breaks = np.asarray(breaks, float)
    while True:                          # creases closer than tol to another crease or an end go
        arcs = [None if t is None else np.concatenate([[0.0], t.fractions_at(breaks), [1.0]])
                for t in alive]
        pieces = np.mean([np.diff(a) * t.length for a, t in zip(arcs, alive) if t is not None],
                         axis=0)
        short = np.nonzero(pieces <= tol)[0]
        if not breaks.size or not short.size:
            break
        breaks = np.delete(breaks, min(short[0], breaks.size - 1))
    f_breaks = np.concatenate([[0.0], np.cumsum(pieces) / np.sum(pieces)])
    f_breaks[-1] = 1.0
    lengths = [t.length for t in alive if t is not None]
    line = _Direction(held, tuple(alive), breaks, f_breaks,
                      tuple(a if a is not None else f_breaks for a in arcs),
                      float(np.mean(lengths)))
    sets = [None if t is None else line.to_common(k, _piecewise_fractions(t, breaks, arcs[k], tol))
            for k, t in enumerate(alive)]
    if len({id(t) for t in alive if t is not None}) == 1:
        sets = [next(s for s in sets if s is not None)]
    fractions = _pin(reconcile_fractions(*sets), f_breaks)
    return line, _at_least(fractions, f_breaks)


def _piecewise_fractions(table, breaks: NDArray, arcs: NDArray, tol: float) -> NDArray:
    """Boundary fractions (section 29.2.4) of a line, piece by piece between creases,
    as arc-length fractions of the whole line (a C2 fit across a crease never converges)."""
    if not len(breaks):
        return boundary_fractions(table, BOUNDARY_SHARE * tol)[0]
    ends = np.concatenate([[table.t[0]], breaks, [table.t[-1]]])
    out = []
    for k, (a, b) in enumerate(itertools.pairwise(ends)):
        piece = arc_length_table(table.curve.restrict(a, b), 0.1 * tol)
        local = (boundary_fractions(piece, BOUNDARY_SHARE * tol)[0] if piece.length > 0.1 * tol
                 else np.array([0.0, 1.0]))
        out.append(arcs[k] + local * (arcs[k + 1] - arcs[k]))
    return np.unique(np.concatenate(out))


def _pin(fractions: NDArray, f_breaks: NDArray) -> NDArray:
    """``fractions`` with every crease fraction present exactly (a nearby value moves there)."""
    out = fractions.copy()
    for f in f_breaks[1:-1]:
        k = int(np.argmin(np.abs(out - f)))
        step = np.min(np.diff(out)) if len(out) > 1 else 1.0
        if abs(out[k] - f) <= 0.25 * step and 0 < k < len(out) - 1:
            out[k] = f
        else:
            out = np.sort(np.append(out, f))
    return out


def _at_least(fractions: NDArray, f_breaks: NDArray, count: int = MIN_POINTS) -> NDArray:
    """At least ``count`` points in every piece between crease fractions."""
    for a, b in itertools.pairwise(f_breaks):
        while True:
            inside = (fractions >= a - 1e-15) & (fractions <= b + 1e-15)
            if inside.sum() >= count:
                break
            idx = np.nonzero(inside)[0]
            if idx.size < 2:
                break
            widths = np.diff(fractions[idx])
            k = idx[int(np.argmax(widths))]
            fractions = np.sort(np.append(fractions, 0.5 * (fractions[k] + fractions[k + 1])))
    return fractions


def _coons_blocks(uv: NDArray, fu: NDArray, fv: NDArray, iu: NDArray, jv: NDArray) -> NDArray:
    """Interior nodes of each block between fixed lines by bilinear Coons blending."""
    rows = np.concatenate([[0], iu, [len(fu) - 1]])
    cols = np.concatenate([[0], jv, [len(fv) - 1]])
    for i0, i1 in itertools.pairwise(rows):
        for j0, j1 in itertools.pairwise(cols):
            if i1 - i0 < 2 or j1 - j0 < 2:
                continue
            s = ((fu[i0 + 1:i1] - fu[i0]) / (fu[i1] - fu[i0]))[:, None, None]
            t = ((fv[j0 + 1:j1] - fv[j0]) / (fv[j1] - fv[j0]))[None, :, None]
            a, b = uv[i0, j0 + 1:j1][None], uv[i1, j0 + 1:j1][None]
            c, d = uv[i0 + 1:i1, j0][:, None], uv[i0 + 1:i1, j1][:, None]
            corners = ((1 - s) * (1 - t) * uv[i0, j0] + s * (1 - t) * uv[i1, j0]
                       + (1 - s) * t * uv[i0, j1] + s * t * uv[i1, j1])
            uv[i0 + 1:i1, j0 + 1:j1] = (1 - s) * a + s * b + (1 - t) * c + t * d - corners
    return uv


def _start_grid(surface: NurbsSurface, du: _Direction, dv: _Direction, fu: NDArray,
                fv: NDArray, previous: tuple[NDArray, NDArray, NDArray] | None
                ) -> tuple[NDArray, NDArray]:
    """Initial guess and the mask of fixed nodes (boundaries and crease lines).

    Without creases the interior comes from straight lines joining opposite
    boundary nodes (:func:`initial_guess`); with creases from Coons blending
    inside each block between crease lines; on refinement from the previous
    grid interpolated at the new fractions.
    """
    u_lines, v_lines = du.parameters(fu), dv.parameters(fv)
    uv = initial_guess(u_lines[0], u_lines[1], v_lines[0], v_lines[1], surface.domain)
    iu, jv = line_indices(fu, du.f_breaks), line_indices(fv, dv.f_breaks)
    for k, j in enumerate(jv):                   # v = crease lines (run along u)
        uv[:, j] = np.stack([u_lines[2 + k], np.full(len(fu), dv.breaks[k])], -1)
    for k, i in enumerate(iu):                   # u = crease lines (run along v)
        uv[i, :] = np.stack([np.full(len(fv), du.breaks[k]), v_lines[2 + k]], -1)
    for k, i in enumerate(iu):
        uv[i, jv] = np.stack([np.full(len(jv), du.breaks[k]), dv.breaks], -1)
    fixed = np.zeros(uv.shape[:2], bool)
    fixed[[0, -1], :] = fixed[:, [0, -1]] = True
    fixed[iu, :] = fixed[:, jv] = True
    if previous is not None:
        old_fu, old_fv, old_uv = previous
        lookup = RegularGridInterpolator((old_fu, old_fv), old_uv)
        mesh = np.stack(np.meshgrid(fu, fv, indexing="ij"), axis=-1)
        free = ~fixed
        uv[free] = lookup(mesh[free])
    elif iu.size or jv.size:
        uv = _coons_blocks(uv, fu, fv, iu, jv)
    return uv, fixed


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
                          max_sweeps: int = 2000, coarsening: bool = True
                          ) -> ReparametrizationResult:
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
    coarsening : bool
        Once within ``tol``, respace the points where the dense error leaves
        headroom and drop grid lines (:mod:`.coarsen`; fewer poles, every
        step measured densely and kept only within ``tol``).

    Returns
    -------
    ReparametrizationResult
        ``within_tolerance`` False (not an exception) when the limits ran out.

    Raises
    ------
    InvalidGeometryError
        Not a 3D NurbsSurface.
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
    if per_span < 10:
        raise InvalidGeometryError(f"per_span must be >= 10, got {per_span}")
    # worked on about its own box centre: 1e6 away from the origin, a surface 169 across
    # kept only ~1e-10 of its coordinates' bits, the arc lengths (converged to 1e-12 of
    # the length) bisected to their cap and the fit took 3x as long
    centre = box_centre(surface)
    surface = surface.translated(-centre)
    creases_u, creases_v = crease_knots(surface)
    du, fu = _direction(surface, Direction.U, creases_u, creases_v, tol)
    dv, fv = _direction(surface, Direction.V, creases_v, du.breaks, tol)
    if dv.breaks.size != creases_v.size:         # a v crease was dropped as too short
        du, fu = _direction(surface, Direction.U, du.breaks, dv.breaks, tol)
    previous, sweeps, inserted, best = None, 0, 0, np.inf
    for iteration in range(1, max_iterations + 1):
        uv, fixed = _start_grid(surface, du, dv, fu, fv, previous)
        if relocation:
            moved = relocate(surface, uv, fu, fv, max_sweeps=max_sweeps, penalty_tol=PENALTY_TOL,
                             fixed=fixed)
            uv, settled = moved.uv, moved.converged
            sweeps += moved.sweeps
        else:
            settled = True
        pu, pv = fu * du.length, fv * dv.length
        new, dev, reverse, worst = fit_and_measure(
            surface, uv, pu, pv, (line_indices(fu, du.f_breaks), line_indices(fv, dv.f_breaks)),
            per_span)
        done = worst <= tol
        if done or iteration == max_iterations or worst > DIVERGING * best:
            break
        best = min(best, worst)
        bad_u, bad_v = _refinement(dev, reverse, pu, pv, tol)
        if len(fu) + bad_u.sum() > max_points or len(fv) + bad_v.sum() > max_points:
            break
        previous = (fu, fv, uv)
        fu, fv = insert_midpoints(fu, bad_u), insert_midpoints(fv, bad_v)
        inserted += int(bad_u.sum() + bad_v.sum())
    removed = 0
    if done and coarsening:
        best_state = current = (fu, fv, uv, pu, pv, new, dev, reverse, worst)
        for _ in range(RESPACE_TRIES):          # a coarser point set where errors leave room
            cfu, cfv, cuv, cpu, cpv, _, cdev, creverse, _ = current
            eu, ev = _direction_errors(cdev, creverse, cpu, cpv)
            grow = current is best_state          # after a miss: refine only
            su = respaced_fractions(cfu, eu, tol, du.f_breaks, RESPACE_TARGET, MIN_POINTS, grow)
            sv = respaced_fractions(cfv, ev, tol, dv.f_breaks, RESPACE_TARGET, MIN_POINTS, grow)
            if len(su) * len(sv) >= len(best_state[0]) * len(best_state[1]):
                break
            trial_uv, fixed = _start_grid(surface, du, dv, su, sv, (cfu, cfv, cuv))
            if relocation:
                trial_uv = relocate(surface, trial_uv, su, sv, max_sweeps=max_sweeps,
                                    penalty_tol=PENALTY_TOL, fixed=fixed).uv
            tu, tv = su * du.length, sv * dv.length
            trial = fit_and_measure(surface, trial_uv, tu, tv, (line_indices(su, du.f_breaks),
                                                                line_indices(sv, dv.f_breaks)),
                                    per_span)
            current = (su, sv, trial_uv, tu, tv, *trial)   # a miss still tells where to refine
            if trial[3] <= COARSE_SHARE * tol:
                best_state = current
        fu, fv, uv, pu, pv, new, dev, reverse, worst = best_state
        fit = subgrid_fit(surface, uv, pu, pv,
                          (line_indices(fu, du.f_breaks), line_indices(fv, dv.f_breaks)), per_span)
        full_u, full_v = np.ones(len(fu), bool), np.ones(len(fv), bool)
        start = Fit(full_u, full_v, worst, cell_errors(dev, reverse, pu, pv), (new, pu, pv, uv))
        fixed_u, fixed_v = ~full_u, ~full_v
        fixed_u[[0, -1]] = fixed_v[[0, -1]] = True
        fixed_u[line_indices(fu, du.f_breaks)] = True
        fixed_v[line_indices(fv, dv.f_breaks)] = True
        best = coarsen(fit, start, fixed_u, fixed_v, COARSE_SHARE * tol, MIN_POINTS)
        new, pu, pv, uv = best.payload
        worst = best.worst
        removed = int((~best.keep_u).sum() + (~best.keep_v).sum())
    return ReparametrizationResult(
        surface=new.translated(centre), tol=tol, max_deviation=worst,
        within_tolerance=bool(done),
        mismatch_before=_mismatch(surface), mismatch_after=_mismatch(new),
        iterations=iteration, knots_inserted=inserted, relocation_sweeps=sweeps,
        relocation_converged=bool(settled), params_u=pu, params_v=pv, uv=uv,
        lines_removed=removed)


def _direction_errors(dev, reverse, params_u: NDArray, params_v: NDArray
                      ) -> tuple[NDArray, NDArray]:
    """Error per u and per v interval that its own spacing causes ``(n_u-1,), (n_v-1,)``.

    Along the grid lines the interpolant is a pure u (or v) interpolation, so
    the line errors belong to one direction; what a cell adds beyond the sum of
    its two line errors is shared by both in proportion to them.
    """
    cells = cell_errors(dev, reverse, params_u, params_v)
    lu, lv = dev.u_errors[:, None], dev.v_errors[None, :]
    total = np.maximum(lu + lv, 1e-300)
    extra = np.maximum(cells - (lu + lv), 0.0)
    return ((lu + extra * lu / total).max(axis=1), (lv + extra * lv / total).max(axis=0))


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


def _mismatch(surface: NurbsSurface) -> float:
    worst = parametrization_quality(surface).worst
    return float(worst) if not math.isnan(worst) else 1.0
