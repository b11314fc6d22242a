"""Which trimmed faces a structured grid can cover: four-sided on their surface's rectangle,
bounded by one loop of four edges, or (:func:`face_regions`) split into four-sided
sub-patches around a centre (a butterfly for a disc) when bounded by one loop of
another number of sides, or blocks round a single hole (one per outer corner).

A face is gridded as one block when its boundary is the whole parameter
rectangle of its surface: one loop, every edge's pcurve on a side of the
rectangle (within the edge's tolerance, measured in space), and all four sides reached (a collapsed side, a pole, is a
degenerated edge or no edge at all). Anything else -- a face with holes, a face
trimmed inside its surface, an n-sided face -- is refused with the reason, so a
user knows to heal or split it first.
"""

from __future__ import annotations

import numpy as np

from ..surface import NurbsSurface
from ..trimmed import TrimmedFace
from .region import Region

__all__ = ["POLE_CAPS", "face_region", "face_regions", "four_sided_reason", "pole_halves", "rectangle_regions"]

#: how a pole cap is gridded: ``"o"`` one block, its side at the pole collapsed (its
#: cells there triangles); ``"h"`` the butterfly of :func:`.polar.cap_regions` (no cell
#: touches the pole)
POLE_CAPS = ("o", "h")

#: a side shorter than this fraction of the surface's box diagonal is collapsed (a pole)
POLE = 1e-9
#: iso-lines sampled between two poles to find the longest (where a two-pole face is split)
POLE_SPLIT_SAMPLES = 33

#: pcurve samples per edge checked against the rectangle
SAMPLES = 9
#: how close to a side of the rectangle a pcurve must run in space, at least (fraction of
#: the surface's box diagonal; an edge's own tolerance, doubled, where that is larger)
SIDE_TOL = 1e-7


def pole_halves(surface: NurbsSurface) -> list[NurbsSurface]:
    """The surface, or its two halves when two opposite sides of its rectangle collapse.

    A sphere's rectangle runs from pole to pole: no block can have two collapsed
    sides, so the rectangle is split along its longest iso-line between the poles
    (the equator), and each half is one block round one pole, the two sharing the
    equator.

    Parameters
    ----------
    surface : NurbsSurface (3D)

    Returns
    -------
    list of NurbsSurface
        ``[surface]``, or the halves ``[low, high]`` in the direction between the poles.
    """
    u0, u1, v0, v1 = surface.domain
    diag = float(np.linalg.norm(np.ptp(surface.bounding_box(), axis=0)))
    if not diag > 0.0:
        return [surface]
    t = np.linspace(0.0, 1.0, 65)
    us, vs = u0 + t * (u1 - u0), v0 + t * (v1 - v0)
    for direction, lo, hi in (("v", v0, v1), ("u", u0, u1)):
        across = np.linspace(lo, hi, POLE_SPLIT_SAMPLES)
        # every iso-line between the poles in one evaluation: (lines, 65, 3)
        if direction == "v":
            u, v = np.meshgrid(us, across, indexing="xy")
        else:
            u, v = np.meshgrid(across, vs, indexing="ij")
        points = surface.evaluate(u, v)
        lengths = np.linalg.norm(np.diff(points, axis=1), axis=-1).sum(axis=1)
        if lengths[0] <= POLE * diag and lengths[-1] <= POLE * diag:
            cut = float(across[1 + int(np.argmax(lengths[1:-1]))])
            return list(surface.split(cut, direction))
    return [surface]


def rectangle_regions(surface: NurbsSurface, *, pole_caps: str = "o", clockwise: bool = False) -> list[Region]:
    """The regions blocks cover on a surface's whole rectangle.

    The rectangle, or its two :func:`pole_halves`; with ``pole_caps="h"`` each half
    (or the surface) that is a cap round one pole, closed round it, is five regions of
    its :class:`.polar.PoleChart` instead (003 Fig. 5: the O-type grid remapped to an
    H-type one).

    Parameters
    ----------
    surface : NurbsSurface (3D)
    pole_caps : {"o", "h"}
        See :data:`POLE_CAPS`.
    clockwise : bool
        A cap's regions taken clockwise in its chart (a face used reversed); rectangles
        are oriented by the caller.

    Returns
    -------
    list of Region

    Raises
    ------
    InvalidGeometryError
        An unknown ``pole_caps``.
    """
    from ...errors import InvalidGeometryError
    from .polar import cap_regions, pole_cap
    if pole_caps not in POLE_CAPS:
        raise InvalidGeometryError(f"pole_caps must be one of {', '.join(POLE_CAPS)}, got {pole_caps!r}")
    out = []
    for half in pole_halves(surface):
        chart = pole_cap(half) if pole_caps == "h" else None
        out.extend([Region.rectangle(half)] if chart is None else cap_regions(chart, clockwise=clockwise))
    return out


def four_sided_reason(face: TrimmedFace) -> str | None:
    """None when the face is its surface's whole parameter rectangle, else why not.

    Parameters
    ----------
    face : TrimmedFace

    Returns
    -------
    str or None
    """
    if not face.loops:
        return None                                          # the natural boundary
    if len(face.loops) > 1:
        return f"it has {len(face.loops) - 1} hole(s): not four-sided"
    surface = face.surface
    u0, u1, v0, v1 = surface.domain
    box = surface.bounding_box()
    floor = SIDE_TOL * float(np.linalg.norm(box[1] - box[0]))
    reached = set()
    for edge in face.loops[0].edges:
        uv = edge.pcurve.evaluate(np.linspace(edge.t0, edge.t1, SAMPLES))
        points = surface.evaluate(uv[:, 0], uv[:, 1])
        # on a side when the pcurve's points are within the edge's tolerance of the
        # side in space (a reparametrized face keeps its edges with refitted pcurves)
        allowed = max(2.0 * edge.tolerance, floor)
        sides = []
        for name, column, value in (("u0", 0, u0), ("u1", 0, u1), ("v0", 1, v0), ("v1", 1, v1)):
            moved = uv.copy()
            moved[:, column] = value
            gap = np.linalg.norm(points - surface.evaluate(moved[:, 0], moved[:, 1]), axis=1)
            if np.all(gap <= allowed):
                sides.append(name)
        if not sides:
            if edge.degenerated:
                continue
            return ("it is trimmed inside its surface (an edge runs off the parameter "
                    "rectangle's sides): heal or split it into four-sided faces first")
        reached.update(sides)
    missing = {"u0", "u1", "v0", "v1"} - reached
    if missing:
        return (f"its boundary leaves side(s) {', '.join(sorted(missing))} of the parameter "
                "rectangle uncovered: not four-sided")
    return None


def face_region(face: TrimmedFace) -> Region | str:
    """The four-sided region a block covers on a face, or why there is none.

    The face's whole rectangle (:func:`four_sided_reason`), else the region inside
    one loop of four edges (:meth:`Region.from_loop`, trimmed inside its surface);
    a face used reversed in its shell gets its loop taken clockwise so the block's
    normal follows the face's. Faces with holes or with more or fewer sides get the
    reason.
    """
    reason = four_sided_reason(face)
    if reason is None:
        return Region.rectangle(face.surface)
    if len(face.loops) == 1 and len(face.loops[0].edges) == 4:
        return Region.from_loop(face, clockwise=bool(face.reversed))
    if len(face.loops) == 1:
        return (f"it has {len(face.loops[0].edges)} edges, not four: heal or split it into "
                "four-sided faces first")
    return reason


def face_regions(face: TrimmedFace, *, gap_tol: float, pole_caps: str = "o",
                 _depth: int = 0) -> list[Region] | str:
    """The four-sided regions blocks cover on a face, or why there are none.

    A face :func:`face_region` grids is one region (two when its rectangle runs from
    pole to pole: :func:`pole_halves`; a pole cap's butterfly with ``pole_caps="h"``:
    :func:`rectangle_regions`). A face bounded by one loop of
    three, five or more corners is split as healing splits it (:func:`..healing.decompose.decompose_face`: the loop's
    corners, quads around a centre joined by straight spokes in ``(u, v)``), one
    region per sub-patch; blocks of neighbouring sub-patches share their spoke; a
    loop of four corners made of more edges is one region over its four sides; a
    loop of at most two corners (a disc, a lens) five, the butterfly: an inner quad
    and four between it and the loop (its O-grid remapped to an H-grid). A face with
    one hole: blocks round it, one per corner of its outer loop
    (:func:`..healing.decompose.decompose_ring`, spokes from the corners, or four cut
    points when it has at most two, to the hole). A face with more holes is cut by
    straight lines in ``(u, v)`` between them into parts of one hole each
    (:func:`.parts.separate_holes`), each part gridded so. A loop the split refuses (a
    spoke leaving a very non-convex outline) is cut from its most reflex corner
    (:func:`.parts.split_at_reflex`) and its parts gridded so, up to
    :data:`MAX_REFLEX_CUTS` cuts deep; what is still refused (a cusp) gets the reason.

    Parameters
    ----------
    face : TrimmedFace
    gap_tol : float
        Model units: largest gap between consecutive edges of the loop.
    pole_caps : {"o", "h"}
        See :data:`POLE_CAPS`.

    Returns
    -------
    list of Region, or str
    """
    from ...errors import DegenerateGeometryError, InvalidGeometryError
    from ..healing.decompose import (
        NotDecomposableError,
        decompose_face,
        decompose_ring,
        ring_edges,
    )

    region = face_region(face)
    if not isinstance(region, str):
        if not region.is_rectangle:
            return [region]
        regions = rectangle_regions(face.surface, pole_caps=pole_caps, clockwise=bool(face.reversed))
        return [region] if len(regions) == 1 and regions[0].is_rectangle else regions
    if len(face.loops) > 2:
        from .parts import separate_holes
        try:
            parts = separate_holes(face)
        except (NotDecomposableError, DegenerateGeometryError, InvalidGeometryError) as exc:
            return f"it has {len(face.loops) - 1} holes: not cut into parts of one hole ({exc})"
        out = []
        for part in parts:
            found = face_regions(part, gap_tol=gap_tol, _depth=_depth)
            if isinstance(found, str):
                return f"it has {len(face.loops) - 1} holes: a part of it is not gridded ({found})"
            out.extend(found)
        return out
    if len(face.loops) == 2:
        try:
            ring = decompose_ring(face.surface, *ring_edges(face, gap_tol=gap_tol))
        except (NotDecomposableError, DegenerateGeometryError) as exc:
            return f"it has 1 hole: not split into blocks round it ({exc})"
        return [Region.from_runs(face.surface, [(pc, *pc.domain) for pc in quad],
                                 clockwise=bool(face.reversed)) for quad in ring.quads_pcurves]
    if len(face.loops) != 1:
        return region
    try:
        split = decompose_face(face, gap_tol=gap_tol, layout="butterfly")
    except (NotDecomposableError, DegenerateGeometryError) as exc:
        return _reflex_parts(face, gap_tol, f"not split into four-sided blocks: {exc}", _depth)
    if split is None:
        return region
    return [Region.from_runs(face.surface, [(pc, *pc.domain) for pc in quad],
                             clockwise=bool(face.reversed)) for quad in split.quads_pcurves]


#: how many times over a face is cut at reflex corners before it is refused
MAX_REFLEX_CUTS = 8


def _reflex_parts(face: TrimmedFace, gap_tol: float, reason: str, depth: int) -> list[Region] | str:
    """The regions of ``face`` cut at its most reflex corner (:func:`.parts.split_at_reflex`),
    or ``reason`` when it has none or a part is still refused ``MAX_REFLEX_CUTS`` deep."""
    from ...errors import SurfprepError
    from .parts import split_at_reflex
    if depth >= MAX_REFLEX_CUTS:
        return reason
    try:
        parts = split_at_reflex(face)
    except SurfprepError:
        parts = None
    if not parts:
        return reason
    out = []
    for part in parts:
        found = face_regions(part, gap_tol=gap_tol, _depth=depth + 1)
        if isinstance(found, str):
            return reason
        out.extend(found)
    if depth == 0 and not all(_unfolded(region) for region in out):
        return reason + " (cut at its reflex corners, a block's start grid folds)"
    return out


def _unfolded(region: Region) -> bool:
    """A coarse start grid (9 x 9, no smoothing) of ``region`` has no folded cell: the
    blocks a reflex cut makes are kept only when they grid."""
    from ...errors import SurfprepError
    from .structured import grid_region
    try:
        return grid_region(region, dims=(9, 9), smooth="none").quality.folded_cells == 0
    except SurfprepError:
        return False
