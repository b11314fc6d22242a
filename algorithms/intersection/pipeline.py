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
5-6. :func:`.result.intersection_curves`: auxiliary-plane refinement (eqs.
     29.18-29.26) to ``tol``, chord-midpoint insertion, redundant points dropped,
     interpolants checked between the samples.

Seams. A closed surface converted to a B-spline (a sphere, a cylinder, a
torus) has two parameter lines that are one curve in space. The soup's ends on
both sides of it are one 3D point, so the topology merges them and a chain
crosses the seam with a jump of almost the whole period in ``u`` (or ``v``);
refining across that chord would average the parameters of the two sides.
Chains are therefore cut at every step whose parameter change exceeds half
the domain on a side where the surface is closed (the point moved to the
opposite side of the domain is the same point in space); the cut point is duplicated and each copy gets the
parameter of the side it continues on (the domain end opposite to the one the
merged point kept). A loop crossing a seam once comes out as one open curve
whose two ends coincide in space (``start_kind == end_kind == BOUNDARY``);
:func:`closed_in_space` tells such curves apart.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError, InvalidToleranceError
from ..surface import NurbsSurface
from .mesh import TriangleMesh
from .result import IntersectionCurve, intersection_curves
from .segments import mesh_segments
from .topology import Chain, EndKind, SegmentTopology, topology_from_soup

__all__ = ["intersect_surfaces", "operand_size", "default_mesh_tolerance", "closed_in_space",
           "MESH_TOL_FACTOR", "MIN_TOL_FACTOR", "MAX_TOL_FACTOR", "MAX_MESH_TOL_FACTOR"]

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


def _check_tolerance(value, name: str, low: float, high: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InvalidToleranceError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise InvalidToleranceError(f"{name} must be finite and > 0, got {value!r}")
    if value < low:
        raise InvalidToleranceError(
            f"{name}={value:g} is below what double precision resolves on operands of "
            f"this size (>= {low:.3g} model units)")
    if value > high:
        raise InvalidToleranceError(
            f"{name}={value:g} is absurdly large for operands of this size (<= {high:.3g} "
            "model units)")
    return value


# ------------------------------------------------------------------ seams
def _jumps(uv: NDArray | None, surface: NurbsSurface | None, closed: bool,
           closure_tol: float) -> NDArray:
    """Steps ``(s,) bool`` of a chain that cross a seam of ``surface``.

    ``uv`` is the chain's ``(n, 2)`` parameters; step ``i`` goes from sample
    ``i`` to ``i + 1`` (the last step of a closed chain back to sample 0). A step
    crosses a seam when its (u, v) change by more than half the domain and one
    of its ends, moved to the opposite side of the domain in that coordinate,
    is the same point in space (within ``closure_tol``): the surface is closed
    there. A curve that merely spans an open surface with few samples has the
    large change but not the closure.
    """
    if uv is None or surface is None:
        n = 0 if uv is None else uv.shape[0]
        return np.zeros(max(n - (not closed), 0), dtype=bool)
    domain = surface.domain
    nxt = np.roll(uv, -1, axis=0) if closed else uv[1:]
    here = uv[: nxt.shape[0]]
    half = 0.5 * np.array([domain[1] - domain[0], domain[3] - domain[2]])
    jump = np.any(np.abs(nxt - here) > half, axis=1)
    steps = np.flatnonzero(jump)
    if steps.size:
        ends = np.concatenate([here[steps], nxt[steps]])              # (2c, 2)
        toward = np.concatenate([nxt[steps], here[steps]])
        moved = np.stack([_other_side(e, t, domain) for e, t in zip(ends, toward)])
        gap = np.linalg.norm(surface.evaluate(moved[:, 0], moved[:, 1])
                             - surface.evaluate(ends[:, 0], ends[:, 1]), axis=1)
        seam = np.minimum(gap[: steps.size], gap[steps.size:]) <= closure_tol
        jump[steps[~seam]] = False
    return jump


def _other_side(uv: NDArray, toward: NDArray, domain) -> NDArray:
    """``uv (2,)`` moved to the domain end nearer to ``toward`` in each coordinate
    whose difference exceeds half the domain (the seam's other parameter line)."""
    lo = np.array([domain[0], domain[2]])
    hi = np.array([domain[1], domain[3]])
    out = uv.copy()
    far = np.abs(toward - uv) > 0.5 * (hi - lo)
    out[far] = np.where(toward[far] > uv[far], hi[far], lo[far])
    return out


def _on_side(uv: NDArray, domain, rel: float = 1e-9) -> bool:
    """True when ``uv (2,)`` lies on a side of the domain (within ``rel`` of its size)."""
    lo = np.array([domain[0], domain[2]])
    hi = np.array([domain[1], domain[3]])
    eps = rel * (hi - lo)
    return bool(np.any((uv <= lo + eps) | (uv >= hi - eps)))


def _seam_point(j: int, uv_a: NDArray | None, uv_b: NDArray | None, domain_a, domain_b,
                jump_a: NDArray, jump_b: NDArray) -> int:
    """Which end of jump step ``j -> j + 1`` is the seam point: ``j`` or ``j + 1``
    (the one on a side of the domain of the surface that jumps)."""
    n = (uv_a if uv_a is not None else uv_b).shape[0]
    for uv, domain, jump in ((uv_a, domain_a, jump_a), (uv_b, domain_b, jump_b)):
        if uv is not None and domain is not None and jump[j]:
            return j if _on_side(uv[j], domain) else (j + 1) % n
    return j


def _cut_at_seams(topology: SegmentTopology, surface_a: NurbsSurface | None,
                  surface_b: NurbsSurface | None, closure_tol: float) -> SegmentTopology:
    """Cut every chain at its seam jumps, duplicating the seam points (module docstring).

    Per chain (not per point) in Python; the samples themselves are numpy arrays.
    """
    domain_a = None if surface_a is None else surface_a.domain
    domain_b = None if surface_b is None else surface_b.domain
    points = [topology.points]
    uv_a = None if topology.uv_a is None else [topology.uv_a]
    uv_b = None if topology.uv_b is None else [topology.uv_b]
    count = topology.points.shape[0]
    chains: list[Chain] = []
    for chain in topology.chains:
        ids = chain.point_ids
        ca = None if uv_a is None else topology.uv_a[ids]
        cb = None if uv_b is None else topology.uv_b[ids]
        jump_a = _jumps(ca, surface_a, chain.closed, closure_tol)
        jump_b = _jumps(cb, surface_b, chain.closed, closure_tol)
        jump = jump_a | jump_b
        if not jump.any():
            chains.append(chain)
            continue
        n = ids.size
        cuts = np.flatnonzero(jump)
        if chain.closed:          # start right after the first jump, end at it
            order = np.roll(np.arange(n), -(int(cuts[0]) + 1))
        else:
            order = np.arange(n)
        pieces: list[list[int]] = [[int(order[0])]]
        for k in range(1, n):
            step = int(order[k - 1])              # the step from order[k-1] to order[k]
            if jump[step]:
                seam = _seam_point(step, ca, cb, domain_a, domain_b, jump_a, jump_b)
                if seam == step:
                    pieces.append([step, int(order[k])])
                else:
                    pieces[-1].append(int(order[k]))
                    pieces.append([int(order[k])])
            else:
                pieces[-1].append(int(order[k]))
        if chain.closed:          # the closing step is the first jump
            step = int(order[-1])
            seam = _seam_point(step, ca, cb, domain_a, domain_b, jump_a, jump_b)
            if seam == step:
                pieces[0].insert(0, step)
            else:
                pieces[-1].append(int(order[0]))
        for k, local in enumerate(pieces):
            if len(local) < 2:
                continue
            local = np.asarray(local)
            piece_uv = []
            for cuv, domain in ((ca, domain_a), (cb, domain_b)):
                if cuv is None:
                    piece_uv.append(None)
                    continue
                part = cuv[local].copy()
                if domain is not None and (k > 0 or chain.closed):      # starts at a seam
                    part[0] = _other_side(part[0], part[1], domain)
                if domain is not None and (k < len(pieces) - 1 or chain.closed):   # ends at one
                    part[-1] = _other_side(part[-1], part[-2], domain)
                piece_uv.append(part)
            fresh = np.arange(count, count + local.size)
            count += local.size
            points.append(topology.points[ids[local]])
            if uv_a is not None:
                uv_a.append(piece_uv[0])
            if uv_b is not None:
                uv_b.append(piece_uv[1])
            first = k == 0 and not chain.closed
            last = k == len(pieces) - 1 and not chain.closed
            chains.append(Chain(fresh, np.zeros(local.size - 1, dtype=np.int64), False,
                                chain.start_kind if first else EndKind.BOUNDARY,
                                chain.end_kind if last else EndKind.BOUNDARY))
    return replace(topology, points=np.concatenate(points),
                   uv_a=None if uv_a is None else np.concatenate(uv_a),
                   uv_b=None if uv_b is None else np.concatenate(uv_b),
                   chains=tuple(chains))


def closed_in_space(curve: IntersectionCurve, tol: float) -> bool:
    """True for a closed curve, or an open one whose ends meet within ``tol``
    (a loop cut at a seam of a closed surface)."""
    if curve.closed:
        return True
    return bool(np.linalg.norm(curve.points[0] - curve.points[-1]) <= tol)


# ------------------------------------------------------------------ driver
def intersect_surfaces(a: Operand, b: Operand, *, tol: float = 1e-7,
                       mesh_tol: float | None = None, max_depth: int = 24
                       ) -> list[IntersectionCurve]:
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
        them (the work grows about as ``1 / mesh_tol`` along the curves).
    max_depth : int
        Tessellation refinement levels at most.

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
        An operand of another type, or a surface not in 3D.
    """
    size, magnitude = operand_size(a, b)
    scale = max(size, magnitude, np.finfo(float).tiny)
    tol = _check_tolerance(tol, "tol", MIN_TOL_FACTOR * scale, max(MAX_TOL_FACTOR * size,
                                                                    MIN_TOL_FACTOR * scale))
    if mesh_tol is None:
        mesh_tol = max(MESH_TOL_FACTOR * size, tol)
    mesh_tol = _check_tolerance(mesh_tol, "mesh_tol", tol,
                                max(MAX_MESH_TOL_FACTOR * size, tol))
    soup = mesh_segments(a, b, tol=mesh_tol, max_depth=max_depth)
    if soup.n_segments == 0:
        return []
    domain_a = a.domain if isinstance(a, NurbsSurface) else None
    domain_b = b.domain if isinstance(b, NurbsSurface) else None
    merge = max(_MERGE_SHARE * mesh_tol, MIN_TOL_FACTOR * scale)
    topology = topology_from_soup(soup, tol=merge, join_tol=_JOIN_FACTOR * mesh_tol,
                                  domain_a=domain_a, domain_b=domain_b)
    surface_a = a if isinstance(a, NurbsSurface) else None
    surface_b = b if isinstance(b, NurbsSurface) else None
    topology = _cut_at_seams(topology, surface_a, surface_b, _JOIN_FACTOR * mesh_tol)
    return intersection_curves(topology, surface_a, surface_b, tol=tol)
