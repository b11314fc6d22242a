"""Surface-surface intersection end to end (000 §29.4.1, all six steps).

:func:`intersect_surfaces` chains the stages written in the sibling modules:

1-4. :func:`.segments.mesh_segments`: overlap boxes, adaptive tessellation only
     where the boxes overlap, box trees, triangle-triangle intersection, at the
     chord tolerance ``mesh_tol``;
4.   :func:`.topology.topology_from_soup`: unique points (merged within
     ``1e-6 mesh_tol``), PointUses, traced chains; hanging ends of neighbouring
     overlap boxes closer than ``4 mesh_tol`` are joined (004 §5);
     then chains are **cut where their (u, v) jumps across a seam** of a closed
     surface (see below);
5.   :func:`.result.refine_chains`: every traced sample refined onto both
     surfaces by the auxiliary-plane method (eqs. 29.18-29.26) to ``tol / 16``;
     then every end the topology found on a domain side is solved again on
     that side (Newton with the side parameter held), because the anchored
     refinement lets it slide inward by up to about ``mesh_tol``
     (:func:`.boundary_ends.close_boundary_gaps`);
6.   :func:`.result.sampled_curves`: only the samples the C2 cubic
     interpolants need (:mod:`.sampling`: curvature-spaced subset, then
     midpoints checked on both exact surfaces and inserted where a span
     fails), so the sample count grows as ``L kappa^(3/4) / tol^(1/4)``, not as
     ``L / sqrt(tol)`` for straight chords.

Seams: a loop crossing a seam of a closed surface is cut there
(:mod:`.seams`) and comes out as one open curve whose two ends coincide in
space (``start_kind == end_kind == BOUNDARY``); :func:`closed_in_space` tells
such curves apart.
"""

from __future__ import annotations

import enum
import warnings
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from .angles import FLAT_SHARE, flat_share, normal_sines, small_crossing_sine
from .boundary_ends import close_boundary_gaps
from .compare import polyline_distance
from .extend import extend_open_ends
from .mesh import TriangleMesh
from .refine import RefinedCurve
from .result import (
    IntersectionCurve,
    checked_curves,
    intersection_curves,
    refine_chains,
)
from .seams import cut_at_seams
from .segments import mesh_segments
from .sides import (
    DomainSide,
    box_sides,
    covered_samples,
    may_run_along_many,
    side_curves,
    uncovered_pieces,
)
from .singular_join import join_at_singular_points
from .topology import Chain, EndKind, SegmentTopology, topology_from_soup

__all__ = [
    "MAX_MESH_TOL_FACTOR",
    "MAX_TOL_FACTOR",
    "MESH_TOL_FACTOR",
    "MIN_TOL_FACTOR",
    "SmallAngleWarning",
    "StrayCurves",
    "closed_in_space",
    "default_mesh_tolerance",
    "intersect_surfaces",
    "operand_size",
]

Operand = NurbsSurface | TriangleMesh

#: default tessellation chord tolerance, relative to the operands' size
MESH_TOL_FACTOR = 1e-3
#: ``tol`` below this times the size cannot be reached in double precision
MIN_TOL_FACTOR = 1e-14
#: ``tol`` above this times the size is not an intersection tolerance any more
MAX_TOL_FACTOR = 1e-2
#: ``mesh_tol`` above this times the size would miss every small loop
MAX_MESH_TOL_FACTOR = 0.1
#: points of the soup closer than this times ``mesh_tol`` are one Point
_MERGE_SHARE = 1e-6
#: hanging ends closer than this times ``mesh_tol`` are joined (004 §5)
_JOIN_FACTOR = 4.0
#: a folded or straying result is computed again this many times at most, each time
#: with ``mesh_tol`` divided by ``_RETRY_FACTOR``, never below ``_RETRY_FLOOR tol``
_RETRIES = 2
_RETRY_FACTOR = 8.0
_RETRY_FLOOR = 16.0
#: a surface is closed across a seam when its opposite sides meet within this
#: times ``tol`` (not ``mesh_tol``: a face narrower than a few ``mesh_tol``, like
#: the KCS hull's 20 mm transom at mesh_tol 9 mm, is not closed)
_SEAM_CLOSURE = 64.0
#: segment ends (every k-th) whose normals decide the SmallAngleWarning, at least
_FLAT_SAMPLES = 256
#: first marching step from a hanging end, times ``mesh_tol``
_MARCH_STEP = 0.25
#: singular points are looked for within this times the mesh tolerance of curve ends
_SINGULAR_REACH = 64.0
#: a refined chain within this times tol (or ``_TANGENTIAL_SHARE`` times the size) of a
#: known tangential curve all along is a fragment of it (as the certificate's test)
_TANGENTIAL_REACH, _TANGENTIAL_SHARE = 1e3, 1e-4
#: traced points this share of the domain from a side count as on it (candidates only:
#: the side is then probed, :func:`.sides.may_run_along_many`)
_SIDE_SLACK = 1e-4
#: consecutive chords of refined samples turning by more than this: a fold
_FOLD_ANGLE = np.radians(120.0)


def _operand_box(operand: Operand) -> NDArray:
    """``(2, 3)`` box: the control-net box of a surface, the vertex box of a mesh."""
    if isinstance(operand, NurbsSurface):
        if operand.dimension != 3:
            raise InvalidGeometryError(
                f"intersection needs surfaces in 3D, got dimension {operand.dimension}")
        return np.asarray(operand.bounding_box(), dtype=float)
    if isinstance(operand, TriangleMesh):
        return np.asarray(operand.bounding_box(), dtype=float)
    raise InvalidGeometryError(
        f"an operand must be a NurbsSurface or a TriangleMesh, got {type(operand).__name__}")


def operand_size(a: Operand, b: Operand) -> tuple[float, float]:
    """Length scale of a pair: ``(diagonal, magnitude)``.

    ``diagonal`` is the diagonal of the box holding both operands (control nets
    for surfaces); ``magnitude`` the largest absolute coordinate (what rounding
    errors scale with).
    """
    boxes = np.stack([_operand_box(a), _operand_box(b)])
    lo, hi = boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)
    return float(np.linalg.norm(hi - lo)), float(np.abs(boxes).max())


def default_mesh_tolerance(a: Operand, b: Operand) -> float:
    """``MESH_TOL_FACTOR`` times the operands' diagonal (model units)."""
    return MESH_TOL_FACTOR * operand_size(a, b)[0]


def closed_in_space(curve: IntersectionCurve, tol: float) -> bool:
    """True for a closed curve, or an open one whose ends meet within ``tol``
    (a loop cut at a seam of a closed surface)."""
    if curve.closed:
        return True
    return bool(np.linalg.norm(curve.points[0] - curve.points[-1]) <= tol)


def _extend(dense: list[RefinedCurve], kinds: list, surface_a: NurbsSurface,
            surface_b: NurbsSurface, tol: float, mesh_tol: float):
    """OPEN (hanging) ends continued on the exact surfaces (:mod:`.extend`); an end
    that reaches a domain side becomes BOUNDARY; then curves meeting at singular
    points (double points) are made to end exactly there (BIFURCATION,
    :func:`.singular_join.join_at_singular_points`)."""
    open_ends = [(s is EndKind.OPEN, e is EndKind.OPEN) for s, e in kinds]
    if any(a or b for a, b in open_ends):
        dense, reached = extend_open_ends(dense, open_ends, surface_a, surface_b, tol=tol,
                                          step=_MARCH_STEP * mesh_tol)
        kinds = [tuple(EndKind.BOUNDARY if r else k for k, r in zip(kind, hit))
                 for kind, hit in zip(kinds, reached)]
    return join_at_singular_points(dense, kinds, surface_a, surface_b, tol=tol,
                                   reach=_SINGULAR_REACH * mesh_tol)


def _domain_sides(domain) -> list[tuple[int, float, float]]:
    """``(coord, value, slack)`` of the four sides of a domain: a traced point this close
    to a side (``_SIDE_SLACK`` of the extent) may be on a stretch along it (a chain of
    one segment ending 2e-5 of the extent inside the side it runs along, b1_euclid
    faces 28 x 37, had the side left unexamined at 1e-9)."""
    extent = (domain[1] - domain[0], domain[3] - domain[2])
    return [(0, domain[0], _SIDE_SLACK * extent[0]), (0, domain[1], _SIDE_SLACK * extent[0]),
            (1, domain[2], _SIDE_SLACK * extent[1]), (1, domain[3], _SIDE_SLACK * extent[1])]


def _traced_sides(topology: SegmentTopology, chains: list[Chain], surface_a: NurbsSurface,
                  surface_b: NurbsSurface, tol: float) -> list[DomainSide]:
    """Domain sides the traced chains may run along: a chain has two consecutive
    points on the side, or two chain ends lie on it (scattered pieces along it),
    and the side lies on the other surface next to one of those points
    (:func:`.sides.may_run_along`). A curve merely crossing a side costs a few
    projections at most."""
    sides = []
    surfaces = (surface_a, surface_b)
    uvs = (topology.uv_a, topology.uv_b)
    for owner, surface in enumerate(surfaces):
        uv_all = uvs[owner]
        candidates, ts, guesses = [], [], []
        for coord, value, slack in _domain_sides(surface.domain):
            ends, ids = 0, []
            for chain in chains:
                on = np.abs(uv_all[chain.point_ids, coord] - value) <= slack
                ids.append(chain.point_ids[on])
                if np.any(on[:-1] & on[1:]):
                    ends = 2
                ends += 0 if chain.closed else int(on[0]) + int(on[-1])
            if ends < 2:
                continue
            ids = np.concatenate(ids)
            candidates.append(DomainSide(owner, coord, float(value)))
            ts.append(uv_all[ids, 1 - coord])
            guesses.append(uvs[1 - owner][ids])
        if candidates:          # all sides of this surface tested in one projection
            keep = may_run_along_many(surface, surfaces[1 - owner], candidates, ts, guesses,
                                      tol=tol)
            sides.extend(side for side, k in zip(candidates, keep) if k)
    return sides


def _along_sides(dense: list[RefinedCurve], kinds: list, topology: SegmentTopology,
                 chains: list[Chain], surface_a: NurbsSurface, surface_b: NurbsSurface,
                 tol: float):
    """Curves running along a domain side (:mod:`.sides`) replace the traced pieces
    lying on them (the tessellations only touch there, so those come in pieces)."""
    sides = _traced_sides(topology, chains, surface_a, surface_b, tol)
    if not sides:
        return dense, kinds
    extra, runs = side_curves(surface_a, surface_b, sides, tol=tol)
    if not extra:
        return dense, kinds
    kept, kept_kinds = [], []
    for c, kind in zip(dense, kinds):
        covered = covered_samples(c, runs, surface_a, surface_b, tol)
        if covered.all():
            continue                       # wholly along a side: the side curve replaces it
        if c.closed or not covered.any():
            kept.append(c)
            kept_kinds.append(kind)
            continue
        # partly along a side (a plane through the edges where faces meet: the traced
        # curve runs along a side, then into the face): the stretches off the runs are
        # kept, ending where they leave the side, on the domain's boundary
        for piece, from_side, to_side in uncovered_pieces(c, covered):
            kept.append(piece)
            kept_kinds.append((EndKind.BOUNDARY if from_side else kind[0],
                               EndKind.BOUNDARY if to_side else kind[1]))
    return kept + extra, kept_kinds + [(EndKind.BOUNDARY, EndKind.BOUNDARY)] * len(extra)


def _only_along_sides(a: NurbsSurface, b: NurbsSurface, tol: float, stray) -> list:
    """No crossing at all in the tessellations: the surfaces may still meet along a
    domain side (touching chords); the sides whose hulls reach the other box are
    examined."""
    sides = box_sides(a, b, tol)
    extra = side_curves(a, b, sides, tol=tol)[0] if sides else []
    if not extra:
        return []
    curves, worst = checked_curves(extra, [(EndKind.BOUNDARY, EndKind.BOUNDARY)] * len(extra),
                                   a, b, tol=tol)
    return _stray_policy(curves, worst, tol, stray)


# ------------------------------------------------------------------ driver
class StrayCurveWarning(UserWarning):
    """Curves were left out because they stray from the surfaces by more than tol."""


class SmallAngleWarning(UserWarning):
    """The surfaces cross at an angle too small for the triangle method at its mesh
    tolerance (:mod:`.angles`): curves there may come out in fragments or be missed."""


def _warn_if_flat(soup, a: NurbsSurface, b: NurbsSurface, mesh_tol: float) -> None:
    """:class:`SmallAngleWarning` when the exact normals at ``FLAT_SHARE`` or more of the
    soup's segment ends are closer to parallel than :func:`.angles.small_crossing_sine`
    allows (the median of those angles is named). Every k-th end is looked at, at
    least ``_FLAT_SAMPLES`` of them: a share and a median need no more, and a cut of
    four loops has a thousand ends."""
    limit = small_crossing_sine(operand_size(a, b)[0], mesh_tol)
    uv_a, uv_b = soup.uv_a.reshape(-1, 2), soup.uv_b.reshape(-1, 2)
    step = max(1, uv_a.shape[0] // _FLAT_SAMPLES)         # a share and a median: a sample
    sines = normal_sines(a, b, uv_a[::step], uv_b[::step])
    if flat_share(sines, limit) >= FLAT_SHARE:
        sine = float(np.median(sines[sines < limit]))
        warnings.warn(
            f"the surfaces cross at angles about {np.arcsin(min(sine, 1.0)):.2g} rad, below "
            f"{np.arcsin(limit):.2g} for mesh_tol={mesh_tol:g}: the triangle method may give "
            "fragments or miss the curve there (surfprep.intersect's default method 'auto' "
            "traces such pairs by the characteristic method; or pass a smaller mesh_tol)",
            SmallAngleWarning, stacklevel=4)


class StrayCurves(enum.Enum):
    """What :func:`intersect_surfaces` does with curves that break ``tol``."""

    #: raise InvalidGeometryError (the default: no silent loss)
    RAISE = "raise"
    #: leave them out and return the others
    DROP = "drop"


def _stray_policy(curves: list, worst: NDArray, tol: float, stray: StrayCurves,
                  folded: NDArray | None = None) -> list:
    """Curves straying beyond ``tol`` or ``folded (c,) bool`` (turning back on
    themselves) dropped with a warning or raised (``stray``)."""
    folded = np.zeros(worst.shape, dtype=bool) if folded is None else folded
    bad = (worst > tol) | folded
    if not np.any(bad):
        return curves
    how = (f"stray from the surfaces by up to {worst.max():.3g} > tol={tol:g}"
           if np.any(worst > tol) else "")
    if folded.any():
        how += (" or " if how else "") + f"fold back on themselves ({folded.sum()})"
    if stray is StrayCurves.DROP:
        warnings.warn(f"{bad.sum()} of {len(curves)} intersection curves left out: they "
                      f"{how} (near-tangential or overlapping surfaces)", StrayCurveWarning,
                      stacklevel=3)
        return [c for c, b in zip(curves, bad) if not b]
    raise InvalidGeometryError(
        f"{bad.sum()} of {len(curves)} intersection curves {how}: the surfaces are "
        "near-tangential or overlap there")


def intersect_surfaces(a: Operand, b: Operand, *, tol: float = 1e-7,
                       mesh_tol: float | None = None, max_depth: int = 24,
                       stray: StrayCurves = StrayCurves.RAISE,
                       tangential: Sequence[IntersectionCurve] = (),
                       touching_sides: bool = True) -> list[IntersectionCurve]:
    """Intersection curves of two surfaces and/or triangle meshes (000 §29.4, steps 1-6).

    Parameters
    ----------
    a, b : NurbsSurface (dimension 3) or TriangleMesh
    tol : float
        Model units. Every sample of a NURBS x NURBS result lies within ``tol``
        of both surfaces, and so do the interpolants between the samples
        (checked at three points per span, eqs. 29.18-29.26 refinement with
        midpoint insertion). For a mesh x NURBS pair the samples are projected
        onto the exact side; mesh x mesh returns the traced polylines.
    mesh_tol : float, optional
        Chord tolerance of the tessellations (model units); default
        ``MESH_TOL_FACTOR`` (1e-3) times the diagonal of the operands' box.
        Loops smaller than a few ``mesh_tol`` may be missed: lower it to find
        them (the work grows about as ``1 / mesh_tol`` along the curves). A
        NURBS x NURBS result with a folded or straying curve (near-tangential
        surfaces, too coarse a tessellation) is computed again with ``mesh_tol``
        divided by 8, twice at most and not below ``16 tol``.
    max_depth : int
        Tessellation refinement levels at most.
    stray : StrayCurves
        A NURBS x NURBS curve whose interpolants stray from the surfaces by more
        than ``tol`` (near-tangential or overlapping surfaces, where the
        refinement does not converge) raises (``RAISE``) or is left out (``DROP``).
    tangential : sequence of IntersectionCurve
        Known curves of tangential contact (e.g. the characteristic method's
        ridges, :mod:`..characteristic.ridges`). Along such a curve the
        tessellations only graze each other and give fragments, whose marching
        and refinement are ill-conditioned (seconds, then retries); traced chains
        whose refined samples all lie within ``_TANGENTIAL_REACH`` of one are
        left out right after the refinement. The tangential curves themselves
        are not returned.
    touching_sides : bool
        When the tessellations do not cross at all, the surfaces may still meet
        along a side of a domain, touching (two faces of one shape on either side
        of a shared edge): those side curves are looked for (default). False
        leaves them out, for a caller that drops every curve along a face's
        edges anyway (a shape's self-intersection): 28 % of the time of
        occt_b1_euclid.stp's.

    Returns
    -------
    list of IntersectionCurve
        Each with samples ``points (n, 3)``, ``uv_a``/``uv_b (n, 2)`` (None for
        a mesh side), open or closed, end kinds, interpolants. A loop through a
        seam of a closed surface comes as one open curve whose ends coincide
        (:func:`closed_in_space`). Empty when the operands do not meet.

    Raises
    ------
    InvalidToleranceError
        ``tol`` or ``mesh_tol`` not finite and positive, ``tol`` below
        ``MIN_TOL_FACTOR`` times the operands' magnitude or above
        ``MAX_TOL_FACTOR`` times their diagonal, ``mesh_tol`` above
        ``MAX_MESH_TOL_FACTOR`` times the diagonal or below ``tol``.
    InvalidGeometryError
        An operand of another type, a surface not in 3D, or a NURBS x NURBS
        result that breaks the tolerance contract (some curve's interpolants
        stray from the surfaces by more than ``tol``: near-tangential or
        overlapping surfaces, where the refinement does not converge).
    """
    size, magnitude = operand_size(a, b)
    scale = max(size, magnitude, np.finfo(float).tiny)
    tol = check_tolerance(tol, "tol", low=MIN_TOL_FACTOR * scale,
                          high=max(MAX_TOL_FACTOR * size, MIN_TOL_FACTOR * scale))
    if mesh_tol is None:
        mesh_tol = max(MESH_TOL_FACTOR * size, tol)
    mesh_tol = check_tolerance(mesh_tol, "mesh_tol", low=tol,
                               high=max(MAX_MESH_TOL_FACTOR * size, tol))
    if tangential:
        reach = max(_TANGENTIAL_REACH * tol, _TANGENTIAL_SHARE * size)
        return _intersect(a, b, tol, mesh_tol, max_depth, stray, scale, _RETRIES,
                          (tuple(tangential), reach), touching_sides=touching_sides)
    return _intersect(a, b, tol, mesh_tol, max_depth, stray, scale, _RETRIES,
                      touching_sides=touching_sides)


def _folded(curve: RefinedCurve) -> bool:
    """True when the refined samples turn back on themselves (consecutive chords
    more than ``_FOLD_ANGLE`` apart at a regular sample): a traced loop whose
    refined points landed on one part of the true curve twice, as where the
    tessellations are too coarse for surfaces meeting at a small angle."""
    p = curve.points
    if p.shape[0] < 3:
        return False
    if curve.closed:
        p = np.concatenate([p, p[:2]])
    d = np.diff(p, axis=0)
    norm = np.linalg.norm(d, axis=1)
    cos = np.einsum("ij,ij->i", d[:-1], d[1:]) / np.maximum(norm[:-1] * norm[1:],
                                                             np.finfo(float).tiny)
    middle = np.roll(curve.singular, -1)[: cos.size] if curve.closed else curve.singular[1:-1]
    return bool(np.any((cos < np.cos(_FOLD_ANGLE)) & ~middle))


def _trim_overshoot(curve: RefinedCurve) -> RefinedCurve:
    """An open curve without the samples its end point lies behind: where the last
    (first) chord turns back by more than ``_FOLD_ANGLE`` from the one before it, the
    sample before the end ran past the end point -- a chain cut at a seam whose
    refined samples near the cut crossed the seam -- and is dropped, repeatedly. What
    is dropped lies on the curve's continuation beyond the seam (another curve's
    stretch)."""
    if curve.closed or curve.points.shape[0] < 4:
        return curve
    keep = np.ones(curve.points.shape[0], dtype=bool)
    limit = np.cos(_FOLD_ANGLE)
    for end in (-1, 0):
        while keep.sum() >= 4:
            idx = np.flatnonzero(keep)
            k = idx[::-1][:3] if end == -1 else idx[:3]            # end, next, next-but-one
            p = curve.points[k]
            d1, d0 = p[0] - p[1], p[1] - p[2]
            cos = float(np.dot(d0, d1)) / max(float(np.linalg.norm(d0) * np.linalg.norm(d1)),
                                              np.finfo(float).tiny)
            if cos >= limit:
                break
            keep[k[1]] = False
    if keep.all():
        return curve
    return RefinedCurve(curve.points[keep], curve.uv_a[keep], curve.uv_b[keep], False,
                        curve.converged[keep], curve.singular[keep])


def _off_tangential(chains: list[Chain], dense: list[RefinedCurve],
                    tangential: tuple[IntersectionCurve, ...], reach: float
                    ) -> tuple[list[Chain], list[RefinedCurve]]:
    """The chains and refined curves that do not lie wholly within ``reach`` of a known
    tangential curve (``intersect_surfaces(tangential=...)``)."""
    if not dense:
        return chains, dense
    points = np.concatenate([c.points for c in dense])
    owner = np.repeat(np.arange(len(dense)), [c.points.shape[0] for c in dense])
    far = polyline_distance(points, list(tangential)) > reach
    keep = np.bincount(owner[far], minlength=len(dense)) > 0
    return ([c for c, k in zip(chains, keep) if k], [c for c, k in zip(dense, keep) if k])


def _intersect(a: Operand, b: Operand, tol: float, mesh_tol: float, max_depth: int,
               stray: StrayCurves, scale: float, retries: int,
               tangential: tuple | None = None, *, touching_sides: bool = True
               ) -> list[IntersectionCurve]:
    """:func:`intersect_surfaces` at one ``mesh_tol``; a NURBS x NURBS result with a
    folded or straying curve is computed again at ``mesh_tol / _RETRY_FACTOR``
    (``retries`` more times at most, not below ``_RETRY_FLOOR tol``): the
    tessellations were too coarse for a near-tangential stretch."""
    finer = mesh_tol / _RETRY_FACTOR
    can_retry = retries > 0 and finer >= _RETRY_FLOOR * tol
    soup = mesh_segments(a, b, tol=mesh_tol, max_depth=max_depth)
    if soup.n_segments == 0:
        if isinstance(a, NurbsSurface) and isinstance(b, NurbsSurface) and touching_sides:
            return _only_along_sides(a, b, tol, stray)
        return []
    domain_a = a.domain if isinstance(a, NurbsSurface) else None
    domain_b = b.domain if isinstance(b, NurbsSurface) else None
    merge = max(_MERGE_SHARE * mesh_tol, MIN_TOL_FACTOR * scale)
    topology = topology_from_soup(soup, tol=merge, join_tol=_JOIN_FACTOR * mesh_tol,
                                  domain_a=domain_a, domain_b=domain_b)
    surface_a = a if isinstance(a, NurbsSurface) else None
    surface_b = b if isinstance(b, NurbsSurface) else None
    if retries == _RETRIES and surface_a is not None and surface_b is not None:
        _warn_if_flat(soup, surface_a, surface_b, mesh_tol)
    closure = min(_JOIN_FACTOR * mesh_tol, max(_SEAM_CLOSURE * tol, merge))
    topology = cut_at_seams(topology, surface_a, surface_b, closure)
    if surface_a is None or surface_b is None:
        return intersection_curves(topology, surface_a, surface_b, tol=tol)
    chains, dense = refine_chains(topology, surface_a, surface_b, tol=tol)
    if tangential is not None:
        chains, dense = _off_tangential(chains, dense, *tangential)
        if not dense:
            return []
    if can_retry and any(_folded(c) for c in dense):
        return _intersect(a, b, tol, finer, max_depth, stray, scale, retries - 1, tangential,
                          touching_sides=touching_sides)
    ends = [((topology.uv_a[c.point_ids[0]], topology.uv_b[c.point_ids[0]]),
             (topology.uv_a[c.point_ids[-1]], topology.uv_b[c.point_ids[-1]])) for c in chains]
    dense, left = close_boundary_gaps(dense, chains, ends, surface_a, surface_b, tol,
                                       reach=_JOIN_FACTOR * mesh_tol)
    kinds = [(EndKind.OPEN if (i, 0) in left else c.start_kind,
              EndKind.OPEN if (i, -1) in left else c.end_kind) for i, c in enumerate(chains)]
    dense, kinds = _extend(dense, kinds, surface_a, surface_b, tol, mesh_tol)
    dense, kinds = _along_sides(dense, kinds, topology, chains, surface_a, surface_b, tol)
    dense = [_trim_overshoot(c) for c in dense]
    curves, worst = checked_curves(dense, kinds, surface_a, surface_b, tol=tol)
    # a curve whose kept samples still turn back on themselves runs over one stretch
    # twice: within tol of both surfaces, but not the intersection curve
    folded = np.array([_folded(c) for c in curves], dtype=bool)
    if can_retry and (np.any(worst > tol) or folded.any()):
        return _intersect(a, b, tol, finer, max_depth, stray, scale, retries - 1, tangential,
                          touching_sides=touching_sides)
    return _stray_policy(curves, worst, tol, stray, folded)
