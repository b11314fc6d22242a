"""Four-sided sub-patches of a face that is not four-sided (001 §3 asks for four
boundary curves; 003 and handbook 000 §29.3 cover other regions by several
four-sided patches).

The face's outer loop is given as :class:`LoopEdge` objects (3D curve and
pcurve on the face's surface, both oriented along the loop). Its vertices are
classed by the *turning angle* on the surface (the angle between the incoming
and the outgoing tangent): a vertex turning by more than ``smooth_angle`` is a
corner, the others join their edges into one side. With ``c`` corners:

* ``c = 4``: one four-sided patch whose sides are the edge chains between the
  corners (a face of more than four edges with smooth vertices);
* ``c = 3`` or ``c >= 5``: the classic split into ``c`` quads around a centre
  point: the midpoint (half the arc length) of every side is joined to a centre
  on the surface by a *spoke*, quad ``k`` is ``V_k, M_k, C, M_{k-1}``;
* ``c <= 2`` (a disc, a lens, a half disc): the vertices (all of them when the
  loop has at most four edges) and split points at the middle (in arc length)
  of the longest stretches between them, four in all, one patch; or, with
  ``layout="butterfly"`` (what a structured grid needs: no corner of 180 degrees
  on a smooth side), five: an inner quad halfway to those four points and four
  quads between it and the loop.

Spokes are straight lines in the face's parameter plane from the centre (the
mean ``(u, v)`` of the side midpoints) mapped onto the surface and interpolated
(:func:`..fitting.interpolate_curve`), so they lie on the face; two quads
sharing a spoke get the same curve. A layout is refused
(:class:`NotDecomposableError`) when a spoke leaves the face's outline or a
sub-patch's Coons map in ``(u, v)`` folds (a very non-convex outline).

On a :class:`~..trimmed.TrimmedFace` (:func:`quad_boundaries`, the reason for a
refusal in :func:`why_not_decomposable`):

* a face of one loop of four real edges: its four edges (as
  :func:`.adjacency.four_sided_boundary`);
* a face bounded by the whole surface (no trimming loop): the surface's four
  boundary isocurves;
* other faces of one loop: :func:`decompose_loop` on its outer loop
  (:func:`loop_edges`);
* a face with one hole: the blocks round it of :func:`decompose_ring` (one per outer
  corner, four when it has at most two);
* faces with two or more holes, seam edges, loop ends further apart than
  ``gap_tol``, very non-convex outlines: not decomposable.

:func:`surfprep.heal` approximates every sub-patch with
:func:`.approximant.local_approximant` (the face's own source preferred) and
joins them with the rest; if one sub-patch misses ``tol``, the whole face is kept
as it was.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..curve import NurbsCurve
from ..face_region import inside_loops
from ..fitting import interpolate_curve
from ..tolerance import check_tolerance
from ..trimmed import TrimEdge, TrimmedFace
from .adjacency import four_sided_boundary
from .loop_sides import (
    CHECK_SAMPLES,
    DENSE,
    SPOKE_SAMPLES,
    LoopEdge,
    LoopSide,
    NotDecomposableError,
    check_quad,
    extra_cuts,
    join_curves,
    loop_pieces,
    loop_side,
    polyline_lengths,
    reverse_curve,
    signed_area,
    spoke_curve,
    turning_angles,
    uniform_uv,
    uv_segment,
)

__all__ = [
    "DEFAULT_SMOOTH_ANGLE",
    "Decomposition",
    "LoopEdge",
    "NotDecomposableError",
    "decompose_face",
    "decompose_loop",
    "decompose_ring",
    "join_curves",
    "loop_edges",
    "quad_boundaries",
    "reverse_curve",
    "ring_edges",
    "turning_angles",
    "why_not_decomposable",
]

#: a vertex turning by less than this (radians) joins its two edges into one side
DEFAULT_SMOOTH_ANGLE = np.radians(20.0)
#: most blocks round a hole :func:`quad_boundaries` (healing) accepts; grids take any
#: number (occt_k1_catia_theorem.stp faces 1 and 58, eight corners each, as eight
#: approximants: free edges at 1e-7 x size 12 -> 40)
MAX_RING_BLOCKS = 4
#: a cut on a hole this close to one of its corners (fraction of its perimeter in
#: ``(u, v)``) is moved to the corner
HOLE_CORNER_SNAP = 0.05
#: most sides handled by the split around a centre
MAX_SIDES = 16
#: a vertex turning by more than this (radians) is a cusp: no sub-patch fits in it
CUSP_ANGLE = np.radians(179.0)




@dataclass(frozen=True, eq=False)
class Decomposition:
    """Four-sided sub-patches of one face.

    Attributes
    ----------
    quads : tuple of tuple of four NurbsCurve
        Boundaries in loop order (bottom, right, top, left of :mod:`.boundary`).
    quads_uv : tuple of (4 * CHECK_SAMPLES, 2) float
        Each sub-patch's outline in the face's ``(u, v)``.
    corners : (c,) int
        Indices (into the real edges) of the edges starting at a corner.
    centre_uv : (2,) float or None
        The centre of a split (None for one patch).
    turning : (m,) float
        Turning angle (radians) at the start of every real edge.
    quads_pcurves : tuple of tuple of four NurbsCurve (2D)
        Each sub-patch's sides in the face's ``(u, v)``, as ``quads`` (the loop's
        pcurves over the same pieces, the spokes' straight segments), each run
        over its whole domain along the loop: what a structured grid of the
        sub-patch needs (:func:`surfprep.algorithms.grid.faces.face_regions`).
    """

    quads: tuple
    quads_uv: tuple
    corners: NDArray
    centre_uv: NDArray | None
    turning: NDArray
    quads_pcurves: tuple = ()


# -------------------------------------------------------------- the layouts
def _single(sides: Sequence[LoopSide], orientation: float) -> list:
    check_quad([uniform_uv(s.uv, s.length, CHECK_SAMPLES) for s in sides], orientation,
               "the four-sided patch")
    return [([s.curve for s in sides], np.concatenate([s.uv for s in sides]),
             [s.pcurve for s in sides])]


def _star(surface, real, cuts, sides, outline, orientation) -> tuple[list, NDArray]:
    """The split into ``len(sides)`` quads around a centre (module docstring)."""
    n = len(sides)
    mids = [s.locate(0.5 * s.length[-1]) for s in sides]
    mid_uv = np.array([real[k].pcurve.evaluate(t) for k, t in mids]).reshape(n, 2)
    mid_xyz = np.array([real[k].curve.evaluate(t) for k, t in mids]).reshape(n, 3)
    centre = mid_uv.mean(axis=0)
    if not inside_loops(centre[None], [outline])[0]:
        raise NotDecomposableError("the centre of the split lies outside the face (non-convex "
                                   "outline)")
    spokes = [spoke_curve(surface, centre, mid_uv[i], mid_xyz[i]) for i in range(n)]
    for curve, uv in spokes:
        if not np.all(inside_loops(uv[1:-SPOKE_SAMPLES // 8], [outline])):
            raise NotDecomposableError("a split curve leaves the face (non-convex outline)")
    first = [loop_side(real, loop_pieces(real, cuts[i], mids[i])) for i in range(n)]
    second = [loop_side(real, loop_pieces(real, mids[i], cuts[(i + 1) % n])) for i in range(n)]
    quads = []
    for i in range(n):
        j = i - 1
        spoke_out, spoke_in = spokes[i], spokes[j]
        curves = [first[i].curve, reverse_curve(spoke_out[0]), spoke_in[0], second[j].curve]
        pcurves = [first[i].pcurve, uv_segment(mid_uv[i], centre),
                   uv_segment(centre, mid_uv[j]), second[j].pcurve]
        spoke_length = [np.r_[0, np.cumsum(np.linalg.norm(np.diff(uv, axis=0), axis=1))]
                        for uv in (spoke_out[1][::-1], spoke_in[1])]
        uv_sides = [uniform_uv(first[i].uv, first[i].length, CHECK_SAMPLES),
                    uniform_uv(spoke_out[1][::-1], spoke_length[0], CHECK_SAMPLES),
                    uniform_uv(spoke_in[1], spoke_length[1], CHECK_SAMPLES),
                    uniform_uv(second[j].uv, second[j].length, CHECK_SAMPLES)]
        check_quad(uv_sides, orientation, f"sub-patch {i} of {n}")
        quads.append((curves, np.concatenate(uv_sides), pcurves))
    return quads, centre




#: inner corners of the butterfly layout: this fraction of the way from the centre to
#: the loop's split points
BUTTERFLY_INNER = 0.5


def _butterfly(surface, real, cuts, sides, outline, orientation) -> tuple[list, NDArray]:
    """Five quads for a loop of at most two corners (a disc, a lens): an inner quad
    around the centre and four quads between it and the loop, joined by straight
    spokes in ``(u, v)`` from the four split points to the inner corners (the O-grid
    of a disc remapped to an H-grid; no corner lies on a smooth side at 180 degrees)."""
    split_uv = np.array([real[k].pcurve.evaluate(t) for k, t in cuts]).reshape(4, 2)
    split_xyz = np.array([real[k].curve.evaluate(t) for k, t in cuts]).reshape(4, 3)
    centre = split_uv.mean(axis=0)
    inner = centre + BUTTERFLY_INNER * (split_uv - centre)
    if not np.all(inside_loops(inner, [outline])):
        raise NotDecomposableError("an inner corner of the butterfly lies outside the face "
                                   "(non-convex outline)")
    spokes = [spoke_curve(surface, inner[i], split_uv[i], split_xyz[i]) for i in range(4)]
    for _, uv in spokes:
        if not np.all(inside_loops(uv[:-SPOKE_SAMPLES // 8], [outline])):
            raise NotDecomposableError("a split curve leaves the face (non-convex outline)")
    ring = []
    for i in range(4):
        a, b = inner[i], inner[(i + 1) % 4]
        uv = a + np.linspace(0.0, 1.0, SPOKE_SAMPLES)[:, None] * (b - a)
        try:
            ring.append((interpolate_curve(surface.evaluate(uv[:, 0], uv[:, 1])), uv))
        except DegenerateGeometryError:
            raise NotDecomposableError("the butterfly's inner quad runs where the surface "
                                       "collapses") from None

    quads = []
    for i in range(4):
        j = (i + 1) % 4
        spoke_in, spoke_out = spokes[j], spokes[i]          # P_j -> Q_j is spoke_in reversed
        curves = [sides[i].curve, reverse_curve(spoke_in[0]), reverse_curve(ring[i][0]),
                  spoke_out[0]]
        pcurves = [sides[i].pcurve, uv_segment(split_uv[j], inner[j]),
                   uv_segment(inner[j], inner[i]), uv_segment(inner[i], split_uv[i])]
        uv_sides = [uniform_uv(sides[i].uv, sides[i].length, CHECK_SAMPLES),
                    uniform_uv(spoke_in[1][::-1], polyline_lengths(spoke_in[1][::-1]), CHECK_SAMPLES),
                    uniform_uv(ring[i][1][::-1], polyline_lengths(ring[i][1][::-1]), CHECK_SAMPLES),
                    uniform_uv(spoke_out[1], polyline_lengths(spoke_out[1]), CHECK_SAMPLES)]
        check_quad(uv_sides, orientation, f"outer sub-patch {i} of the butterfly")
        quads.append((curves, np.concatenate(uv_sides), pcurves))
    uv_sides = [uniform_uv(r[1], polyline_lengths(r[1]), CHECK_SAMPLES) for r in ring]
    check_quad(uv_sides, orientation, "the butterfly's inner sub-patch")
    quads.append(([r[0] for r in ring], np.concatenate(uv_sides),
                  [uv_segment(inner[i], inner[(i + 1) % 4]) for i in range(4)]))
    return quads, centre


def decompose_loop(surface, edges: Sequence[LoopEdge], *,
                   smooth_angle: float = DEFAULT_SMOOTH_ANGLE,
                   layout: str = "auto") -> Decomposition:
    """Four-sided sub-patches covering a face bounded by one loop (module docstring).

    Parameters
    ----------
    surface : NurbsSurface
        The face's surface (spokes are mapped through it).
    edges : sequence of LoopEdge
        The outer loop, in loop order, each edge oriented along it.
    smooth_angle : float
        Radians; vertices turning less join their edges into one side.
    layout : "auto" or "butterfly"
        For a loop of at most two corners: one patch on four split points
        ("auto", the module docstring; corners of 180 degrees where a split point
        lies on a smooth side) or five, an inner quad and four around it
        ("butterfly": :func:`_butterfly`, what a structured grid needs).

    Returns
    -------
    Decomposition

    Raises
    ------
    NotDecomposableError
        With the reason: no real edge, too many corners, a spoke leaving the
        face, a folding sub-patch.
    """
    if layout not in ("auto", "butterfly"):
        raise InvalidGeometryError(f"layout must be 'auto' or 'butterfly', got {layout!r}")
    real = [e for e in edges if e.curve is not None]
    if not real:
        raise NotDecomposableError("the loop has no edge with a 3D curve")
    turning = turning_angles(edges)
    corners = np.flatnonzero(turning > smooth_angle)
    if np.any(turning > CUSP_ANGLE):
        raise NotDecomposableError(
            f"a cusp: the loop turns back by {np.degrees(turning.max()):.0f} degrees")
    if corners.size > MAX_SIDES:
        raise NotDecomposableError(f"{corners.size} corners: more than {MAX_SIDES} sides")
    cuts = [(int(k), real[k].curve.domain[0]) for k in corners]
    if len(cuts) <= 2:
        # every vertex of a loop of at most four edges stays a corner (the neighbours'
        # edges end there), split points fill the longest stretches up to four
        seeds = [(k, real[k].curve.domain[0]) for k in range(len(real))] if len(real) <= 4 \
            else cuts
        cuts = extra_cuts(real, seeds, 4)
    n = len(cuts)
    sides = [loop_side(real, loop_pieces(real, cuts[i], cuts[(i + 1) % n])) for i in range(n)]
    outline = np.concatenate([e.pcurve.evaluate(np.linspace(*e.pcurve.domain, DENSE))[:-1]
                              for e in edges])
    orientation = np.sign(signed_area(outline)) or 1.0
    if n == 4 and layout == "butterfly" and corners.size <= 2:
        quads, centre = _butterfly(surface, real, cuts, sides, outline, orientation)
    elif n == 4:
        quads, centre = _single(sides, orientation), None
    else:
        quads, centre = _star(surface, real, cuts, sides, outline, orientation)
    return Decomposition(tuple(tuple(q) for q, _, _ in quads), tuple(uv for _, uv, _ in quads),
                         corners, centre, turning, tuple(tuple(p) for _, _, p in quads))


def _inner_cut(real_inner, centre: NDArray, towards: NDArray) -> tuple[int, float]:
    """Loop position on the inner loop seen from ``centre`` in the direction of
    ``towards`` (both in ``(u, v)``): the dense sample whose polar angle is nearest."""
    want = np.arctan2(*(towards - centre)[::-1])
    best, where = np.inf, None
    for k, e in enumerate(real_inner):
        t = np.linspace(*e.pcurve.domain, DENSE)
        d = e.pcurve.evaluate(t) - centre
        gap = np.abs(np.angle(np.exp(1j * (np.arctan2(d[:, 1], d[:, 0]) - want))))
        j = int(np.argmin(gap))
        if gap[j] < best:
            best, where = gap[j], (k, float(t[j]))
    return where


def _snap_to_corners(hole: Sequence[LoopEdge], cuts: list[tuple[int, float]],
                     outline: NDArray, smooth_angle: float) -> list[tuple[int, float]]:
    """``cuts`` on the hole moved to the hole's corners within :data:`HOLE_CORNER_SNAP`
    of its ``(u, v)`` perimeter: a block's hole side would otherwise turn a corner a
    sliver before its end."""
    turning = turning_angles(hole)
    corners = [(int(k), float(hole[k].pcurve.domain[0])) for k in
               np.flatnonzero(turning > smooth_angle)]
    if not corners:
        return cuts
    at = np.array([hole[k].pcurve.evaluate(t) for k, t in corners]).reshape(-1, 2)
    reach = HOLE_CORNER_SNAP * polyline_lengths(np.vstack([outline, outline[:1]]))[-1]
    out = []
    for k, t in cuts:
        d = np.linalg.norm(at - hole[k].pcurve.evaluate(t), axis=1)
        out.append(corners[int(np.argmin(d))] if d.min() <= reach else (k, t))
    return out


def decompose_ring(surface, outer: Sequence[LoopEdge], inner: Sequence[LoopEdge], *,
                   smooth_angle: float = DEFAULT_SMOOTH_ANGLE) -> Decomposition:
    """Quads covering a face with one hole (an annulus: the O-grid round a hole cut into
    blocks), one per outer corner.

    The outer loop is cut at its corners, three or more (with at most two, at four
    points spread in arc length as :func:`decompose_loop` spreads them); the hole's
    loop at the points seen from its centre in the directions of those cuts; quad
    ``i`` runs along the outer loop from cut ``i`` to ``i + 1``, in along a straight
    spoke in ``(u, v)``, back along the hole and out along the next spoke. Every
    block's outer side is then free of corners, so each is a proper quad.

    Parameters
    ----------
    surface : NurbsSurface
    outer, inner : sequence of LoopEdge
        The outer loop counter-clockwise, the hole's loop counter-clockwise too (run
        the other way from the face's orientation of it), each edge along its loop.

    Raises
    ------
    NotDecomposableError
        Cut points on the hole that coincide, a spoke crossing the hole or leaving the
        face, a folding quad.
    """
    real = [e for e in outer if e.curve is not None]
    hole = [e for e in inner if e.curve is not None]
    if not real or not hole:
        raise NotDecomposableError("a loop without an edge with a 3D curve")
    turning = turning_angles(outer)
    corners = np.flatnonzero(turning > smooth_angle)
    cuts = [(int(k), real[k].curve.domain[0]) for k in corners]
    if len(cuts) <= 2:
        seeds = [(k, real[k].curve.domain[0]) for k in range(len(real))] if len(real) <= 4 \
            else cuts
        cuts = extra_cuts(real, seeds, 4)
    outline = np.concatenate([e.pcurve.evaluate(np.linspace(*e.pcurve.domain, DENSE))[:-1]
                              for e in outer])
    hole_outline = np.concatenate([e.pcurve.evaluate(np.linspace(*e.pcurve.domain, DENSE))[:-1]
                                   for e in inner])
    orientation = np.sign(signed_area(outline)) or 1.0
    centre = hole_outline.mean(axis=0)
    n = len(cuts)
    outer_uv = np.array([real[k].pcurve.evaluate(t) for k, t in cuts]).reshape(n, 2)
    outer_xyz = np.array([real[k].curve.evaluate(t) for k, t in cuts]).reshape(n, 3)
    hole_cuts = _snap_to_corners(hole, [_inner_cut(hole, centre, p) for p in outer_uv],
                                 hole_outline, smooth_angle)
    if len({c for c in hole_cuts}) != n:
        raise NotDecomposableError("the hole's cut points coincide (a hole far off centre)")
    hole_uv = np.array([hole[k].pcurve.evaluate(t) for k, t in hole_cuts]).reshape(n, 2)
    spokes = [spoke_curve(surface, hole_uv[i], outer_uv[i], outer_xyz[i]) for i in range(n)]
    for _, uv in spokes:
        inside = inside_loops(uv[1:-1], [outline, hole_outline])
        if not np.all(inside):
            raise NotDecomposableError("a spoke from the hole to the outer loop leaves the face")
    outer_sides = [loop_side(real, loop_pieces(real, cuts[i], cuts[(i + 1) % n])) for i in range(n)]
    hole_sides = [loop_side(hole, loop_pieces(hole, hole_cuts[i], hole_cuts[(i + 1) % n]))
                  for i in range(n)]

    quads = []
    for i in range(n):
        j = (i + 1) % n
        o, h, s_in, s_out = outer_sides[i], hole_sides[i], spokes[j], spokes[i]
        curves = [o.curve, reverse_curve(s_in[0]), reverse_curve(h.curve), s_out[0]]
        pcurves = [o.pcurve, uv_segment(outer_uv[j], hole_uv[j]), reverse_curve(h.pcurve),
                   uv_segment(hole_uv[i], outer_uv[i])]
        uv_sides = [uniform_uv(o.uv, o.length, CHECK_SAMPLES),
                    uniform_uv(s_in[1][::-1], polyline_lengths(s_in[1][::-1]), CHECK_SAMPLES),
                    uniform_uv(h.uv[::-1], h.length[-1] - h.length[::-1], CHECK_SAMPLES),
                    uniform_uv(s_out[1], polyline_lengths(s_out[1]), CHECK_SAMPLES)]
        check_quad(uv_sides, orientation, f"block {i} round the hole")
        quads.append((curves, np.concatenate(uv_sides), pcurves))
    return Decomposition(tuple(tuple(q) for q, _, _ in quads), tuple(uv for _, uv, _ in quads),
                         corners, centre, turning, tuple(tuple(p) for _, _, p in quads))


def ring_edges(face: TrimmedFace, *, gap_tol: float) -> tuple[list[LoopEdge], list[LoopEdge]]:
    """The outer loop and the one hole of a face, both counter-clockwise in ``(u, v)``
    (:func:`decompose_ring`'s input).

    Raises
    ------
    NotDecomposableError
        Not exactly one hole, seam edges, edges without a 3D curve, loops that do not
        close within ``gap_tol``.
    """
    if len(face.loops) != 2:
        raise NotDecomposableError(f"{len(face.loops) - 1} holes: a ring needs one")
    out = []
    for n in (face.outer_loop_index, 1 - face.outer_loop_index):
        alone = TrimmedFace(face.surface, (face.loops[n],))
        edges = loop_edges(alone, gap_tol=gap_tol)
        out.append(edges)
    outer, inner = out
    if signed_area(np.concatenate([e.pcurve.evaluate(np.linspace(*e.pcurve.domain, 9))[:-1]
                                    for e in inner])) < 0:
        inner = [LoopEdge(None if e.curve is None else reverse_curve(e.curve),
                          reverse_curve(e.pcurve)) for e in reversed(inner)]
    return outer, inner


# ------------------------------------------------------------------ trimmed faces
def _loop_edge(edge: TrimEdge) -> LoopEdge:
    curve = None if edge.degenerated else edge.curve3d
    if not edge.reversed:
        return LoopEdge(curve, edge.pcurve)
    return LoopEdge(None if curve is None else reverse_curve(curve), reverse_curve(edge.pcurve))


def loop_edges(face: TrimmedFace, *, gap_tol: float) -> list[LoopEdge]:
    """The face's single outer loop as :class:`LoopEdge` (oriented along the loop).

    Raises
    ------
    NotDecomposableError
        Inner loops, a seam edge, a real edge without 3D curve, or consecutive
        3D edge ends further apart than ``gap_tol``.
    """
    if len(face.loops) != 1:
        raise NotDecomposableError(f"{len(face.loops) - 1} inner loop(s) (holes in the face)")
    edges = face.loops[0].edges
    if any(e.is_seam for e in edges):
        raise NotDecomposableError("a seam edge (face closed on its surface)")
    if any(e.curve3d is None and not e.degenerated for e in edges):
        raise NotDecomposableError("an edge without a 3D curve")
    out = [_loop_edge(e) for e in edges]
    real = [e.curve for e in out if e.curve is not None]
    ends = np.array([c.evaluate(np.array(c.domain)) for c in real])      # (m, 2, 3)
    gaps = np.linalg.norm(ends[:, 1] - np.roll(ends[:, 0], -1, axis=0), axis=1)
    degenerate_between = any(e.curve is None for e in out)
    if not degenerate_between and gaps.size and gaps.max() > gap_tol:
        raise NotDecomposableError(
            f"loop edges do not meet: gap {gaps.max():.3g} > gap_tol {gap_tol:.3g}")
    return out


def decompose_face(face: TrimmedFace, *, gap_tol: float,
                   smooth_angle: float = DEFAULT_SMOOTH_ANGLE,
                   layout: str = "auto") -> Decomposition | None:
    """The decomposition of a face that is neither four-sided nor untrimmed (None for
    those: :func:`quad_boundaries` handles them); raises with the reason. ``layout``
    as :func:`decompose_loop`."""
    gap_tol = check_tolerance(gap_tol, "gap_tol")
    if four_sided_boundary(face) is not None or not face.loops:
        return None
    return decompose_loop(face.surface, loop_edges(face, gap_tol=gap_tol),
                          smooth_angle=smooth_angle, layout=layout)


def _surface_sides(face: TrimmedFace) -> list[NurbsCurve]:
    """The four boundary isocurves of an untrimmed surface, in loop order."""
    s = face.surface
    u0, u1, v0, v1 = s.domain
    return [s.isocurve(v0, "v"), s.isocurve(u1, "u"), reverse_curve(s.isocurve(v1, "v")),
            reverse_curve(s.isocurve(u0, "u"))]


def quad_boundaries(face: TrimmedFace, *, gap_tol: float,
                    smooth_angle: float = DEFAULT_SMOOTH_ANGLE) -> list[list[NurbsCurve]] | None:
    """Boundaries of four-sided sub-patches covering ``face`` (module docstring).

    Parameters
    ----------
    face : TrimmedFace
    gap_tol : float
        Model units: largest gap between consecutive edges of the loop.
    smooth_angle : float
        Radians: vertices turning less join their edges into one side.

    Returns
    -------
    list of list of four NurbsCurve, or None
        Each boundary in loop order (bottom, right, top, left); None when the
        face is not decomposable (:func:`why_not_decomposable` says why).
    """
    try:
        return _boundaries(face, gap_tol, smooth_angle)
    except NotDecomposableError:
        return None


def why_not_decomposable(face: TrimmedFace, *, gap_tol: float,
                         smooth_angle: float = DEFAULT_SMOOTH_ANGLE) -> str | None:
    """The reason :func:`quad_boundaries` returns None for ``face``, else None."""
    try:
        _boundaries(face, gap_tol, smooth_angle)
    except NotDecomposableError as exc:
        return str(exc)
    return None


def _boundaries(face: TrimmedFace, gap_tol: float, smooth_angle: float
                ) -> list[list[NurbsCurve]]:
    four = four_sided_boundary(face)
    if four is not None:
        return [four]
    if not face.loops:
        return [_surface_sides(face)]
    if len(face.loops) == 2:
        outer, inner = ring_edges(face, gap_tol=gap_tol)
        decomposition = decompose_ring(face.surface, outer, inner, smooth_angle=smooth_angle)
        if len(decomposition.quads) > MAX_RING_BLOCKS:
            raise NotDecomposableError(
                f"a face with a hole and {len(decomposition.quads)} outer corners: healing "
                f"replaces a ring by at most {MAX_RING_BLOCKS} blocks (the blocks would meet "
                "its kept neighbours within tol where its edges now meet them exactly)")
    else:
        decomposition = decompose_face(face, gap_tol=gap_tol, smooth_angle=smooth_angle)
    return [list(q) for q in decomposition.quads]
