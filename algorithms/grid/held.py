"""Interior curves held as grid lines (003, "remapping ... when interior objects are to be
kept fixed as part of the interior surface grid").

A held curve runs across a face from one side to the opposite one (a crease, an
intersection curve, a line the user wants in the grid). It is inverted to the
face's parameters (closest points, Newton with the surface's first and second
derivatives, :func:`~surfprep.algorithms.projection.project_to_surface`), given a
grid index -- curves from side ``j0`` to side ``j1`` become i-lines, curves from
``i0`` to ``i1`` j-lines -- and its nodes are placed along it in arc length. The
distribution space is then split along the held lines: each piece between two of
them is a four-sided region of its own, gridded by weighted TFI and refined with
the held lines as fixed boundaries, and the pieces are stitched into one block.
The side nodes move so that a held curve's ends are nodes: the side's
distribution is mapped piecewise linearly through those anchors.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..curve import NurbsCurve
from ..projection import project_to_curve, project_to_surface
from ..surface import NurbsSurface
from .tfi import distribution_mesh, normalized_arc_length, transfinite

__all__ = ["HeldLine", "held_line", "split_along"]

#: samples taken along a held NurbsCurve; polylines are densified to at least this many points
SAMPLES = 401
#: how close (fraction of the surface's box diagonal) a held curve's ends must be to the sides
END_TOL = 1e-4


@dataclass(frozen=True)
class HeldLine:
    """A curve across a face, in the face's normalized parameters.

    Attributes
    ----------
    family : {"i", "j"}
        ``"i"``: it runs from side ``j0`` to side ``j1`` and becomes an i-line;
        ``"j"``: from ``i0`` to ``i1``, a j-line.
    path : (m, 2) float
        The curve in normalized ``(x, y)`` (``x`` the face's u, ``y`` its v, both
        in [0, 1]), ordered from its start side to the opposite one.
    distance : float
        Largest distance from the curve's samples to the surface (the inversion's).
    curve : NurbsCurve or None
        The curve itself when one was given: the held nodes are projected onto it
        (a polyline is held as given).
    """

    family: str
    path: NDArray
    distance: float
    curve: NurbsCurve | None = None


def _samples(curve: NurbsCurve | ArrayLike) -> NDArray:
    if isinstance(curve, NurbsCurve):
        if curve.dimension != 3:
            raise InvalidGeometryError("a held curve must be a 3D curve")
        t0, t1 = curve.domain
        return curve.evaluate(np.linspace(t0, t1, SAMPLES))
    points = np.asarray(curve, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < 2 or not np.all(np.isfinite(points)):
        raise InvalidGeometryError("a held curve must be a NurbsCurve or (m >= 2, 3) finite points")
    if points.shape[0] < SAMPLES:                     # densify along the polyline
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
        if not chord[-1] > 0:
            raise InvalidGeometryError("a held curve of zero length")
        at = np.linspace(0.0, chord[-1], SAMPLES)
        points = np.stack([np.interp(at, chord, points[:, k]) for k in range(3)], axis=1)
    return points


def held_line(surface: NurbsSurface, curve: NurbsCurve | ArrayLike, *, tol: float) -> HeldLine:
    """Invert a curve onto a surface and say which grid family it belongs to.

    Parameters
    ----------
    surface : NurbsSurface
    curve : NurbsCurve (3D) or (m, 3) points
    tol : float
        Largest distance from the surface allowed (model units).

    Raises
    ------
    InvalidGeometryError
        The curve leaves the surface by more than ``tol``, or does not run from a
        side of the face to the opposite side.
    """
    points = _samples(curve)
    projected = project_to_surface(surface, points)
    distance = float(np.max(projected.distance))
    if distance > tol:
        raise InvalidGeometryError(
            f"a held curve lies {distance:.3g} from the face (more than {tol:.3g})")
    u0, u1, v0, v1 = surface.domain
    xy = (projected.uv - [u0, v0]) / [u1 - u0, v1 - v0]
    box = surface.bounding_box()
    near = END_TOL * float(np.linalg.norm(box[1] - box[0]))

    def on(end: NDArray, column: int, value: float) -> bool:
        moved = end.copy()
        moved[column] = value
        a = surface.evaluate(u0 + end[0] * (u1 - u0), v0 + end[1] * (v1 - v0))
        b = surface.evaluate(u0 + moved[0] * (u1 - u0), v0 + moved[1] * (v1 - v0))
        return float(np.linalg.norm(a - b)) <= near

    start, end = xy[0], xy[-1]
    for family, column in (("i", 1), ("j", 0)):
        if on(start, column, 0.0) and on(end, column, 1.0):
            path = xy
        elif on(start, column, 1.0) and on(end, column, 0.0):
            path = xy[::-1]
        else:
            continue
        path = path.copy()
        path[0, column], path[-1, column] = 0.0, 1.0
        return HeldLine(family, np.clip(path, 0.0, 1.0), distance,
                        curve if isinstance(curve, NurbsCurve) else None)
    raise InvalidGeometryError("a held curve must run from one side of the face to the opposite "
                               "side (its ends are not on two opposite sides)")


def _remap(fractions: NDArray, anchors: list[tuple[int, float]]) -> NDArray:
    """Map a side's fractions piecewise linearly so node ``i`` lands on ``x`` for each anchor."""
    out = fractions.copy()
    for (p, xp), (q, xq) in itertools.pairwise(anchors):
        a, b = fractions[p], fractions[q]
        out[p:q + 1] = xp + (fractions[p:q + 1] - a) * (xq - xp) / (b - a)
    return out


def _nodes_along(surface, to_uv, from_uv, line: HeldLine, fractions: NDArray) -> NDArray:
    """Nodes on a held line at the given fractions of its length in space, ``(n, 2)``
    normalized; on the curve itself (closest points, then back onto the surface)
    when the line came from a curve, on its polyline otherwise."""
    path = line.path
    uv = to_uv(path)
    points = surface.evaluate(uv[:, 0], uv[:, 1])
    s = normalized_arc_length(points)
    keep = np.concatenate([[True], np.diff(s) > 0])
    s, path = s[keep], path[keep]
    nodes = np.stack([np.interp(fractions, s, path[:, 0]), np.interp(fractions, s, path[:, 1])], axis=1)
    if line.curve is not None and nodes.shape[0] > 2:
        inner = to_uv(nodes[1:-1])
        on_curve = project_to_curve(line.curve, surface.evaluate(inner[:, 0], inner[:, 1])).points
        nodes[1:-1] = from_uv(project_to_surface(surface, on_curve, guess=inner).uv)
    return nodes


def split_along(surface: NurbsSurface, lines: list[HeldLine], bottom: NDArray, top: NDArray,
                left: NDArray, right: NDArray) -> tuple[NDArray, list[tuple[int, int]]]:
    """The start grid of a face with held i-lines, in normalized ``(x, y)``, and its pieces.

    Parameters
    ----------
    surface : NurbsSurface
    lines : list of HeldLine, all of family ``"i"``
    bottom, top : (ni,) float
        Normalized u of the nodes of sides ``j0`` and ``j1``.
    left, right : (nj,) float
        Normalized v of the nodes of sides ``i0`` and ``i1``.

    Returns
    -------
    xy : (ni, nj, 2) float
        The start grid, held lines as i-lines (their nodes in arc length along them).
    pieces : list of (int, int)
        The i-ranges ``[p, q]`` of the regions between held lines (shared columns).
    """
    u0, u1, v0, v1 = surface.domain
    ni, nj = bottom.size, left.size

    def to_uv(xy: NDArray) -> NDArray:
        return np.stack([u0 + xy[..., 0] * (u1 - u0), v0 + xy[..., 1] * (v1 - v0)], axis=-1)

    def from_uv(uv: NDArray) -> NDArray:
        return np.stack([(uv[..., 0] - u0) / (u1 - u0), (uv[..., 1] - v0) / (v1 - v0)], axis=-1)

    ordered = sorted(lines, key=lambda h: h.path[:, 0].mean())
    index = [round(0.5 * (h.path[0, 0] + h.path[-1, 0]) * (ni - 1)) for h in ordered]
    index = [min(max(i, 1), ni - 2) for i in index]
    if any(b <= a for a, b in itertools.pairwise(index)):
        raise InvalidGeometryError(f"held curves too close together for {ni} nodes along i: "
                                   "give more nodes or fewer curves")
    bottom = _remap(bottom, [(0, 0.0)] + [(i, h.path[0, 0]) for i, h in zip(index, ordered)] + [(ni - 1, 1.0)])
    top = _remap(top, [(0, 0.0)] + [(i, h.path[-1, 0]) for i, h in zip(index, ordered)] + [(ni - 1, 1.0)])
    if np.any(np.diff(bottom) <= 0) or np.any(np.diff(top) <= 0):
        raise InvalidGeometryError("held curves cross each other or leave no room between them")
    # each held line's nodes: the sides' arc-length fractions blended across
    side_fractions = []
    for column, values in ((0.0, left), (1.0, right)):
        xy = np.stack([np.full(nj, column), values], axis=1)
        uv = to_uv(xy)
        side_fractions.append(normalized_arc_length(surface.evaluate(uv[:, 0], uv[:, 1])))
    columns = {0: np.stack([np.zeros(nj), left], axis=1), ni - 1: np.stack([np.ones(nj), right], axis=1)}
    for i, h in zip(index, ordered, strict=True):
        w = i / (ni - 1)
        columns[i] = _nodes_along(surface, to_uv, from_uv, h,
                                  (1 - w) * side_fractions[0] + w * side_fractions[1])
    xy = np.empty((ni, nj, 2))
    bounds = [0] + index + [ni - 1]
    pieces = list(itertools.pairwise(bounds))
    for p, q in pieces:
        b = np.stack([bottom[p:q + 1], np.zeros(q - p + 1)], axis=1)
        t = np.stack([top[p:q + 1], np.ones(q - p + 1)], axis=1)
        lo, hi = columns[p], columns[q]
        weights = distribution_mesh(*(normalized_arc_length(surface.evaluate(*to_uv(side).T))
                                      for side in (b, t, lo, hi)))
        xy[p:q + 1] = transfinite(b, t, lo, hi, weights=weights)
    return np.clip(xy, 0.0, 1.0), pieces
