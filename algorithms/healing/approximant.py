"""One local approximant of the original geometry over four boundary curves
(Hamann & Jean 1996, paper 001 §§3-7; handbook 000 §29.3; Soni & Hamann 1993, paper 003).

:func:`local_approximant` runs, at a resolution ``(M, N)``:

1. the discrete Coons patch of the boundary (eq. 4, :mod:`.coons`);
2. normals by central differences and the upper/lower offsets (eqs. 6-8,
   :mod:`.offsets`);
3. clipping of the sources against the offsets' box (:mod:`.clipping`);
4. projection of every segment ``a b`` onto the clipped triangles, the hit
   closest to the Coons point, mapped onto the exact surface (eqs. 9-11) and
   polished by Newton (:mod:`.piercing`);
5. artificial projections where a segment hits nothing (Hardy's reciprocal
   multiquadric, localized or global, eqs. 12-15, or the thin-plate spline: :mod:`.fill`; by
   default a thin-plate spline of the same positions plus those of a ring of
   projections beyond the boundary, :mod:`.ring`, which carries the
   surroundings' slope and bending into a hole);
6. the bicubic interpolant (C1 of eqs. 16-18 or C2 of 003, :mod:`.interpolant`);
7. the error at the points of eq. (19), cells over holes skipped (:mod:`.error`).

If the error exceeds ``tol`` the resolution grows and everything is redone from
the boundary, up to ``max_resolution``; the result then says
``converged=False`` (or, with ``strict=True``, an error is raised).

Beyond the paper: by default the approximant's sides are the boundary curves
(their samples are interpolated, not projected: ``keep_boundary``), so that
approximants sharing a curve meet before any G0 averaging and a hole bounded
by the curves is filled from its rim; and the projected points are put on
the exact surfaces by Newton piercing of the segments (:mod:`.piercing`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import (
    DegenerateGeometryError,
    InvalidGeometryError,
    InvalidToleranceError,
)
from ..curve import NurbsCurve
from ..projection import project_to_curve
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from .boundary import Boundary, BoundaryCurve, as_boundary
from .clipping import Source, as_sources, clip_sources
from .coons import discrete_coons
from .error import ErrorSample, measure_error
from .fill import FillMethod, fill_positions
from .interpolant import Interpolant, interpolate_grid
from .offsets import offsets
from .piercing import project_grid
from .ring import ring_segments

__all__ = ["DEFAULT_RELATIVE_TOL", "LocalApproximant", "ResolutionStep", "local_approximant"]

#: default ``tol``: this fraction of the boundary's bounding-box diagonal
DEFAULT_RELATIVE_TOL = 1e-3
#: default chord tolerance of the triangulation of surfaces: this fraction of ``d``
MESH_FRACTION = 0.02
#: rows of projections beyond the boundary feeding the fill (:mod:`.ring`)
RING_ROWS = 4
#: a grid with artificial projections is refined at least to this resolution (the
#: fill over a hole is not measured by the error of §7; finer rims carry its shape)
FILL_RESOLUTION = (16, 16)
_BOX_PAD = 0.05             # clipping box margin reused by later passes, fraction of its size
_NEWTON_FRACTION = 1e-9      # residual of the Newton polish, fraction of the size
_INVERSION_FRACTION = 1e-10  # convergence of point inversion, fraction of the size


@dataclass(frozen=True)
class ResolutionStep:
    """One pass of the resolution loop: ``resolution (M, N)``, ``max_error``,
    ``rms_error``, ``artificial_share``."""

    resolution: tuple[int, int]
    max_error: float
    rms_error: float
    artificial_share: float


@dataclass(frozen=True, eq=False)
class LocalApproximant:
    """A bicubic B-spline approximant and how well it follows the originals.

    Attributes
    ----------
    surface : NurbsSurface
        Bicubic, non-rational, domain ``[0, 1]^2``; ``u`` runs along the bottom
        boundary curve, ``v`` along the left one (:mod:`.boundary`).
    resolution : (int, int)
        ``(M, N)``: the grid of ``(M + 1) x (N + 1)`` interpolated points.
    max_error, rms_error : float
        Error of §7 at the points of eq. (19) not over holes (model units;
        NaN when nothing could be measured).
    artificial_share : float
        Fraction of the grid points filled (:mod:`.fill`: over holes or gaps;
        boundary samples kept by ``keep_boundary`` are not artificial).
    converged : bool
        ``max_error <= tol``.
    tol : float
    interpolant : Interpolant
    offset : float
        ``d`` used (eq. 8 or given).
    grid : (M + 1, N + 1, 3) float
        The interpolated points ``y`` and ``z``.
    artificial : (M + 1, N + 1) bool
        True at the artificial projections ``z``.
    source : (M + 1, N + 1) int
        Index of the source each segment hit (the projection lies on it, or,
        on kept boundary sides, the curve's point is over it), -1 where none.
    error : ErrorSample
        The measured points and their distances (a deviation map).
    history : tuple of ResolutionStep
        Every resolution tried, in order.
    boundary : Boundary
    """

    surface: NurbsSurface
    resolution: tuple[int, int]
    max_error: float
    rms_error: float
    artificial_share: float
    converged: bool
    tol: float
    interpolant: Interpolant
    offset: float
    grid: NDArray
    artificial: NDArray
    source: NDArray
    error: ErrorSample
    history: tuple
    boundary: Boundary


def _check_resolution(value, name: str, minimum: int) -> tuple[int, int]:
    try:
        m, n = (int(x) for x in value)
    except (TypeError, ValueError):
        raise InvalidGeometryError(f"{name} must be two integers (M, N), got {value!r}") from None
    if m < minimum or n < minimum or (m, n) != tuple(value):
        raise InvalidGeometryError(f"{name} must be integers >= {minimum}, got {value!r}")
    return m, n


def _next_resolution(current: tuple[int, int], limit: tuple[int, int], growth: float
                     ) -> tuple[int, int]:
    return tuple(min(lim, max(c + 2, math.ceil(c * growth)))
                 for c, lim in zip(current, limit, strict=True))


@dataclass(frozen=True, eq=False)
class _Pass:
    surface: NurbsSurface
    grid: NDArray
    found: NDArray
    artificial: NDArray
    source: NDArray
    error: ErrorSample
    offset: float


def _sides(found: NDArray, t: NDArray, y: NDArray, x: NDArray, keep_boundary: bool,
           tol: float) -> tuple[NDArray, NDArray, NDArray]:
    """Grid points fixed to the boundary curves, and ``found``/``t`` updated for them.

    Kept sides are the Coons points ``x`` themselves (``t = 1/2`` on their
    segments, data for the fill); a side point counts as on the originals
    only where the curve is (within ``tol`` of its projection), not where it
    runs above or below them.
    """
    rim = np.zeros(found.shape, bool)
    if not keep_boundary:
        return rim, found, t
    rim[[0, -1], :] = rim[:, [0, -1]] = True
    off_surface = rim & found & (np.linalg.norm(y - x, axis=-1) > tol)
    return rim, found & ~off_surface, np.where(rim, 0.5, t)


def _side_error(surface: NurbsSurface, bnd: Boundary, m: int, n: int) -> ErrorSample:
    """Distance of the approximant's sides, halfway between the kept boundary samples,
    to the boundary curves: ``(2 m + 2 n,)`` points (between the samples a C1 side
    may cut across a tight bend of its curve)."""
    u, v = (np.arange(m) + 0.5) / m, (np.arange(n) + 0.5) / n
    uv = [np.column_stack([u, np.zeros(m)]), np.column_stack([np.ones(n), v]),
          np.column_stack([u, np.ones(m)]), np.column_stack([np.zeros(n), v])]
    pts = [surface.evaluate(q[:, 0], q[:, 1]) for q in uv]
    dist = [_distance_to_boundary_curve(c, p) for c, p in zip(bnd.curves, pts, strict=True)]
    d = np.concatenate(dist)
    return ErrorSample(np.concatenate(uv), np.concatenate(pts), d, float(d.max()),
                       float(np.sqrt(np.mean(d ** 2))))


def _distance_to_boundary_curve(curve, points: NDArray) -> NDArray:
    if isinstance(curve, NurbsCurve):
        return project_to_curve(curve, points).distance
    line = np.asarray(curve, float)
    a, ab = line[:-1], np.diff(line, axis=0)
    denom = np.maximum(np.einsum("kc,kc->k", ab, ab), np.finfo(float).tiny)
    t = np.clip(np.einsum("mkc,kc->mk", points[:, None] - a[None], ab) / denom, 0.0, 1.0)
    return np.min(np.linalg.norm(points[:, None] - (a[None] + t[..., None] * ab[None]),
                                 axis=2), axis=1)


def _merged(a: ErrorSample, b: ErrorSample) -> ErrorSample:
    d = np.concatenate([a.distance, b.distance])
    finite = d[np.isfinite(d)]
    if finite.size == 0:
        return a
    return ErrorSample(np.concatenate([a.uv, b.uv]), np.concatenate([a.points, b.points]), d,
                       float(finite.max()), float(np.sqrt(np.mean(finite ** 2))))


def _project(off, coons, ring_rows: int, sources, mesh_tol, size, cache, preferred):
    """Segments of the grid (and of the ring around it, :mod:`.ring`) projected."""
    ring = ring_segments(coons, off.distance, ring_rows) if ring_rows > 0 else None
    a, b = off.upper.reshape(-1, 3), off.lower.reshape(-1, 3)
    box = off.box
    if ring is not None:
        a, b = np.concatenate([a, ring.upper]), np.concatenate([b, ring.lower])
        both = np.concatenate([ring.upper, ring.lower])
        box = np.stack([np.minimum(box[0], both.min(axis=0)),
                        np.maximum(box[1], both.max(axis=0))])
    if cache.get("clipped") is None or not cache["clipped"].covers(box):
        # triangulate a box a little larger than needed: later passes (finer grids,
        # slightly different normals) reuse the triangles
        pad = _BOX_PAD * np.ptp(box, axis=0).max()
        cache["clipped"] = clip_sources(
            sources, box + np.array([[-pad], [pad]]),
            mesh_tol=mesh_tol if mesh_tol else MESH_FRACTION * off.distance)
    y, t, found, src = project_grid(a, b, cache["clipped"].restrict(box),
                                    tol=_NEWTON_FRACTION * size, preferred=preferred)
    return ring, y, t, found, src


def _fill_hits(off, missing: NDArray, fill_source, mesh_tol, size, cache
               ) -> tuple[NDArray, NDArray]:
    """Positions ``t`` and hit flags of the grid segments ``missing`` (flat indices) on
    the fill source (the surface a hole's surroundings continue into)."""
    a, b = off.upper.reshape(-1, 3)[missing], off.lower.reshape(-1, 3)[missing]
    box = off.box
    if cache.get("fill") is None or not cache["fill"].covers(box):
        pad = _BOX_PAD * np.ptp(box, axis=0).max()
        cache["fill"] = clip_sources(
            as_sources(fill_source), box + np.array([[-pad], [pad]]),
            mesh_tol=mesh_tol if mesh_tol else MESH_FRACTION * off.distance)
    _, t, hit, _ = project_grid(a, b, cache["fill"].restrict(box), tol=_NEWTON_FRACTION * size)
    return t, hit


def _fill(coons, ring, t, known, t_ring, found_ring, fill, neighbours) -> NDArray:
    """Positions everywhere on the grid (:mod:`.fill`, with the ring's data if any)."""
    if ring is None or np.all(known):
        return fill_positions(coons.u, coons.v, t, known, method=fill, neighbours=neighbours)
    t_ext = np.zeros(ring.outer.shape)
    known_ext = np.zeros(ring.outer.shape, bool)
    t_ext[ring.outer], known_ext[ring.outer] = t_ring, found_ring
    r = ring.rows
    t_ext[r:-r, r:-r], known_ext[r:-r, r:-r] = t, known
    return ring.inner(fill_positions(ring.u, ring.v, t_ext, known_ext, method=fill,
                                     neighbours=neighbours))


def _one_pass(boundary: Boundary, sources: tuple, m: int, n: int, *, offset: float | None,
              interpolant: Interpolant, fill: FillMethod, neighbours: int,
              mesh_tol: float | None, keep_boundary: bool, tol: float, size: float,
              ring_rows: int, preferred: int | None, cache: dict,
              side_error: bool = False, fill_source=None) -> _Pass:
    coons = discrete_coons(boundary, m, n)
    off = offsets(coons, offset)
    ring, y, t, found, src = _project(off, coons, ring_rows, sources, mesh_tol, size, cache,
                                      preferred)
    inner = (m + 1) * (n + 1)
    t_ring, found_ring = t[inner:], found[inner:]
    y, t, found, src = y[:inner], t[:inner], found[:inner], src[:inner]
    clipped = cache["clipped"].restrict(off.box)
    shape = (m + 1, n + 1)
    found, t = found.reshape(shape), t.reshape(shape)
    if not np.any(found):
        raise DegenerateGeometryError(
            "no segment of the Coons patch meets the original surfaces: the boundary does not "
            f"lie over them (or the offset distance {off.distance:.3g} is too small)")
    y = y.reshape(shape + (3,))
    rim, found, t = _sides(found, t, y, coons.points, keep_boundary, tol)
    known = found | rim
    if fill_source is not None and not np.all(known):
        # artificial positions where the segments cross the fill source
        missing = np.flatnonzero(~known)
        t_fill, hit = _fill_hits(off, missing, fill_source, mesh_tol, size, cache)
        t, known = t.copy(), known.copy()
        t.flat[missing[hit]], known.flat[missing[hit]] = t_fill[hit], True
    t_all = _fill(coons, ring, t, known, t_ring, found_ring, fill, neighbours)
    z = (1 - t_all[..., None]) * off.upper + t_all[..., None] * off.lower
    grid = np.where(found[..., None], y, z)
    grid[rim] = coons.points[rim]
    surface = interpolate_grid(grid, interpolant)
    error = measure_error(surface, found, clipped, tol=_INVERSION_FRACTION * size)
    if side_error and keep_boundary:
        error = _merged(error, _side_error(surface, boundary, m, n))
    return _Pass(surface, grid, found, ~(found | rim), src.reshape(shape), error, off.distance)


def local_approximant(boundary: Boundary | Sequence[BoundaryCurve],
                      sources: Sequence[Source] | Source, *, tol: float | None = None,
                      resolution: tuple[int, int] = (8, 8),
                      max_resolution: tuple[int, int] = (64, 64),
                      interpolant: Interpolant = Interpolant.C1_BICUBIC,
                      offset: float | None = None, neighbours: int = 8,
                      fill: FillMethod = FillMethod.THIN_PLATE, growth: float = 1.5,
                      gap_tol: float | None = None, mesh_tol: float | None = None,
                      keep_boundary: bool = True, ring_rows: int | None = None,
                      fill_resolution: tuple[int, int] = FILL_RESOLUTION,
                      preferred_source: int | None = None, side_error: bool = False,
                      fill_source: Source | None = None,
                      strict: bool = False) -> LocalApproximant:
    """A bicubic B-spline surface over four boundary curves that follows the sources.

    Parameters
    ----------
    boundary : Boundary or four NurbsCurve / (n, 3) float
        Bottom, right, top, left, meeting end to end (:mod:`.boundary`;
        :func:`.corners_boundary` for four picked points).
    sources : NurbsSurface, TriangleMesh, SurfaceSource or a sequence of them
        The original geometry.
    tol : float, optional
        Largest accepted error (§7), model units. Default
        :data:`DEFAULT_RELATIVE_TOL` times the boundary's bounding-box diagonal.
    resolution : (int, int)
        First ``(M, N)`` tried (at least 2, 3 for the C2 interpolant).
    max_resolution : (int, int)
        Largest ``(M, N)``; equal to ``resolution`` for one fixed resolution
        (compatible approximants of a network).
    interpolant : Interpolant
        C1 with triple knots (001, default) or C2 (003).
    offset : float, optional
        ``d`` of eq. (7), model units; default eq. (8).
    neighbours : int
        ``K`` of Hardy's localized method (5-10).
    fill : FillMethod
        How missing positions are filled (:mod:`.fill`): the thin-plate spline
        (default), Hardy's localized or global multiquadric (the global one is one
        dense system over all found points: ``O(n^3)``, for small grids).
    ring_rows : int >= 0
        Rows of projections beyond the boundary that feed the fill (:mod:`.ring`;
        0: only the grid's own, as in 001). Default :data:`RING_ROWS` for the
        thin-plate fill, 0 for Hardy's (his kernel with ``γ = 0.001`` bends the
        ring's data into the hole: worse than the grid alone).
    fill_resolution : (int, int)
        A grid with artificial projections is refined at least to this (capped
        by ``max_resolution``), even when ``tol`` is met earlier.
    preferred_source : int, optional
        Index into ``sources`` of the surface the approximant replaces: a
        segment that hits it takes that hit, other sources only serve where
        it is missed (gaps at its rim). Without it the hit nearest the Coons
        point wins (001), which with the long segments of eq. (8) can be a
        far-away face crossing the segment.
    growth : float > 1
        Resolution factor between passes (at least +2 each).
    gap_tol : float, optional
        Largest gap between consecutive boundary curves (:func:`.as_boundary`).
    mesh_tol : float, optional
        Chord tolerance of the triangulation of the surfaces; default ``d / 50``.
    keep_boundary : bool
        The approximant's sides are the boundary curves (their arc-length
        samples are interpolated, not projected), so approximants sharing a
        curve meet; the samples also enter the fill (at ``t = 1/2``),
        so a hole bounded by the curves is filled from its rim; side points
        farther than ``tol`` from their projection (curves above or below the
        originals) do not count as on the originals in the error of §7.
        False: the boundary samples are projected like the interior (001 as
        written; 003's four picked points on the originals).
    side_error : bool
        With ``keep_boundary``: also measure the sides against the boundary
        curves halfway between their samples, in the error (and the
        resolution loop): a side that cuts across a tight bend of its curve
        (e.g. a side made of several edges of a face) then raises the
        resolution like an interior miss. Off by default (001's error is the
        interior's only).
    fill_source : NurbsSurface, TriangleMesh or SurfaceSource, optional
        Where a segment meets no source, its artificial projection is its crossing
        with this surface (a hole's cap,
        :func:`.hole_cap.cap_hole`) instead of the fill's interpolated position;
        those points stay artificial (not in the error, counted in
        ``artificial_share``). The sources always win where they are hit.
    strict : bool
        Raise :class:`InvalidToleranceError` instead of returning an
        unconverged approximant.

    Returns
    -------
    LocalApproximant
        The first pass within ``tol``, else the pass of smallest error.

    Raises
    ------
    InvalidGeometryError
        Bad boundary (not meeting end to end, NaN...), no sources, bad resolution.
    DegenerateGeometryError
        The boundary lies over no source, or has zero area.
    InvalidToleranceError
        ``tol`` not positive, below double precision for the model or larger
        than it; with ``strict``, ``tol`` not reached at ``max_resolution``.
    """
    bnd = as_boundary(boundary, gap_tol=gap_tol)
    srcs = as_sources(sources)
    size = bnd.size
    tol = DEFAULT_RELATIVE_TOL * size if tol is None else check_tolerance(
        tol, "tol", low=1e-12 * size, high=size)
    minimum = 3 if interpolant is Interpolant.C2_BICUBIC else 2
    current = _check_resolution(resolution, "resolution", minimum)
    limit = _check_resolution(max_resolution, "max_resolution", minimum)
    if limit[0] < current[0] or limit[1] < current[1]:
        raise InvalidGeometryError(
            f"max_resolution {limit} must be at least resolution {current}")
    if not (np.isfinite(growth) and growth > 1):
        raise InvalidGeometryError(f"growth must be > 1, got {growth!r}")
    if preferred_source is not None and not (
            isinstance(preferred_source, (int, np.integer)) and 0 <= preferred_source < len(srcs)):
        raise InvalidGeometryError(
            f"preferred_source must index the {len(srcs)} sources, got {preferred_source!r}")
    if not (isinstance(neighbours, (int, np.integer)) and neighbours >= 1):
        raise InvalidGeometryError(f"neighbours must be an integer >= 1, got {neighbours!r}")
    if offset is not None:
        offset = check_tolerance(offset, "offset", low=1e-12 * size)
    fill_min = tuple(min(f, lim) for f, lim in zip(
        _check_resolution(fill_resolution, "fill_resolution", minimum), limit, strict=True))
    if ring_rows is None:
        ring_rows = RING_ROWS if fill is FillMethod.THIN_PLATE else 0
    history, passes, cache = [], [], {}
    while True:
        p = _one_pass(bnd, srcs, *current, offset=offset, interpolant=interpolant,
                      fill=fill, neighbours=neighbours, mesh_tol=mesh_tol,
                      keep_boundary=keep_boundary, tol=tol, size=size,
                      ring_rows=ring_rows, preferred=preferred_source, cache=cache,
                      side_error=side_error, fill_source=fill_source)
        share = float(p.artificial.mean())
        history.append(ResolutionStep(current, p.error.max_error, p.error.rms_error, share))
        passes.append(p)
        filled = (not p.artificial.any()
                  or all(c >= f for c, f in zip(current, fill_min, strict=True)))
        if (p.error.max_error <= tol and filled) or current == limit:
            break
        current = _next_resolution(current, limit, growth)
    errors = np.array([s.max_error for s in history])
    converged = bool(errors[-1] <= tol)   # a filled hole refined beyond tol: the last pass
    best = len(passes) - 1 if converged or np.all(np.isnan(errors)) else int(np.nanargmin(errors))
    p, step = passes[best], history[best]
    if strict and not converged:
        raise InvalidToleranceError(
            f"tol={tol:.3g} not reached up to resolution {limit}: smallest error "
            f"{np.nanmin(errors) if not np.all(np.isnan(errors)) else float('nan'):.3g} "
            f"at {step.resolution}")
    return LocalApproximant(
        surface=p.surface, resolution=step.resolution, max_error=step.max_error,
        rms_error=step.rms_error, artificial_share=step.artificial_share, converged=converged,
        tol=float(tol), interpolant=interpolant, offset=p.offset, grid=p.grid,
        artificial=p.artificial, source=p.source, error=p.error, history=tuple(history),
        boundary=bnd)
