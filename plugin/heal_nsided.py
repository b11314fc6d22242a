"""Faces that are not four-sided, as four-sided sub-patches for :func:`surfprep.heal`.

:func:`quad_boundaries` gives the boundaries (four 3D curves each) of
sub-patches covering a :class:`TrimmedFace`, or None with the reason in
:func:`why_not_decomposable` / :class:`NotDecomposableError`:

* a face of one loop of four real edges: its four edges (as
  :func:`.heal_topology.four_sided_boundary`);
* a face bounded by the whole surface (no trimming loop): the surface's four
  boundary isocurves;
* other faces of one loop: :func:`..algorithms.healing.decompose.decompose_loop`
  (edges joined at smooth vertices, triangles and n-gons split around a
  centre, discs cut into four arcs; split curves on the face);
* faces with inner loops (holes), seam edges, loop ends further apart than
  ``gap_tol``, very non-convex outlines: not decomposable.

Approximate every sub-patch with :func:`local_approximant` (the face's own
source preferred) and :func:`connect` them with the rest; if one sub-patch
misses ``tol``, keep the whole face as it was.
"""

from __future__ import annotations

import numpy as np

from ..algorithms import NurbsCurve
from ..algorithms.healing.decompose import (
    DEFAULT_SMOOTH_ANGLE,
    Decomposition,
    LoopEdge,
    NotDecomposableError,
    decompose_loop,
    reverse_curve,
)
from ..algorithms.tolerance import check_tolerance
from .edges import TrimEdge
from .faces import TrimmedFace
from .heal_topology import four_sided_boundary

__all__ = ["NotDecomposableError", "decompose_face", "loop_edges", "quad_boundaries",
           "why_not_decomposable"]


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
                   smooth_angle: float = DEFAULT_SMOOTH_ANGLE) -> Decomposition | None:
    """The decomposition of a face that is neither four-sided nor untrimmed (None for
    those: :func:`quad_boundaries` handles them); raises with the reason."""
    gap_tol = check_tolerance(gap_tol, "gap_tol")
    if four_sided_boundary(face) is not None or not face.loops:
        return None
    return decompose_loop(face.surface, loop_edges(face, gap_tol=gap_tol),
                          smooth_angle=smooth_angle)


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
    decomposition = decompose_face(face, gap_tol=gap_tol, smooth_angle=smooth_angle)
    return [list(q) for q in decomposition.quads]
