"""Four-sided faces overlapping over a strip (001 §1 "overlaps", for :func:`surfprep.heal`):
one is trimmed back
to the other, or both replaced over their union.

Two four-sided faces A and B *overlap* when a side of A lies on B's surface
inside B (within ``gap_tol`` of the surface, farther than ``gap_tol`` from B's
edges) and a side of B lies on A likewise: the strip between the two sides is
covered twice. B (the later face) is trimmed back: its approximant is built
over A's side, the parts of B's two adjacent sides beyond it (each curve cut
at the closest point to the end of A's side) and B's far side. A and the
trimmed B then share A's side as a full boundary curve, and the network joins
them G0/G1 like any neighbours. With ``overlap="union"`` both are replaced
instead by one approximant over the union's outline (:func:`union_boundary`).
Exact duplicates are handled before this (:func:`.adjacency.duplicate_faces`).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..curve import NurbsCurve
from ..projection import distance_to_surface, project_to_curve, project_to_surface
from ..trimmed import TrimmedFace
from .adjacency import box_pairs, four_sided_boundary

__all__ = [
    "Overlap",
    "OverlapRepair",
    "find_overlaps",
    "overlap_boundaries",
    "trimmed_back_boundary",
    "union_boundary",
]

_SAMPLES = 9
#: samples per side of a union outline
_UNION_SAMPLES = 65
#: grid samples per direction of a face for the cheap nearness test
_GRID_SAMPLES = 16
#: a point on a surface is within this many grid spacings of a grid point
_NEAR_CELLS = 1.5


@dataclass(frozen=True)
class Overlap:
    """Side ``side_kept`` (loop position) of face ``kept`` lies inside face ``trimmed``,
    and side ``side_trimmed`` of ``trimmed`` inside ``kept``."""

    kept: int
    side_kept: int
    trimmed: int
    side_trimmed: int


def _interior_samples(curve: NurbsCurve) -> NDArray:
    t0, t1 = curve.domain
    return curve.evaluate(np.linspace(t0, t1, _SAMPLES + 2)[1:-1])


def _near_curves(points: NDArray, curves: list[NurbsCurve], tol: float) -> bool:
    """Whether a point lies within ``tol`` of a curve (curves whose control-point box,
    grown by ``tol``, holds no point are not projected onto)."""
    for c in curves:
        box = c.control_points
        inside = np.all((points >= box.min(axis=0) - tol) & (points <= box.max(axis=0) + tol),
                        axis=1)
        if inside.any() and project_to_curve(c, points[inside]).distance.min() <= tol:
            return True
    return False


@dataclass(frozen=True, eq=False)
class SurfaceGrid:
    """A face's surface sampled on ``(samples + 1) ** 2`` points, border rows included,
    in a k-d tree; ``spacing`` is the largest distance between grid neighbours, ``uv``
    ``(n, 2)`` the samples' parameters (starts for projections)."""

    tree: cKDTree
    interior: NDArray
    spacing: float
    box: NDArray
    uv: NDArray | None = None


def surface_grid(face: TrimmedFace, samples: int) -> SurfaceGrid:
    u0, u1, v0, v1 = face.surface.domain
    t = np.linspace(0.0, 1.0, samples + 1)
    g = face.surface.evaluate_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0))
    spacing = max(np.linalg.norm(np.diff(g, axis=0), axis=-1).max(),
                  np.linalg.norm(np.diff(g, axis=1), axis=-1).max())
    interior = np.zeros(g.shape[:2], bool)
    interior[1:-1, 1:-1] = True
    pts = g.reshape(-1, 3)
    uu, vv = np.meshgrid(u0 + t * (u1 - u0), v0 + t * (v1 - v0), indexing="ij")
    return SurfaceGrid(cKDTree(pts), interior.ravel(), float(spacing),
                       np.array([pts.min(axis=0), pts.max(axis=0)]),
                       np.stack([uu.ravel(), vv.ravel()], axis=1))


def _inside_sides(a: TrimmedFace, b: TrimmedFace, gap_tol: float,
                  grid: SurfaceGrid) -> list[int]:
    """Sides of ``a`` lying on ``b``'s surface and away from ``b``'s edges.

    Cheap tests first: samples off ``b``'s control-net box or far from its grid, then
    near ``b``'s edges (a side shared with ``b`` lies on its surface too); the surface
    distance is projected from the nearest grid samples' parameters, and globally
    only where that start finds a sample off the surface (a proof of "on" is cheap,
    of "off" is not)."""
    sides_a, sides_b = four_sided_boundary(a), four_sided_boundary(b)
    out = []
    box = b.surface.bounding_box()           # control net: holds the surface
    for k, curve in enumerate(sides_a):
        pts = _interior_samples(curve)
        if np.any((pts < box[0] - gap_tol) | (pts > box[1] + gap_tol)):
            continue                          # a sample off b's box is off b's surface
        near, nearest = grid.tree.query(pts, distance_upper_bound=_NEAR_CELLS * grid.spacing
                                        + gap_tol)
        if not np.all(np.isfinite(near)):
            continue                          # a sample far from every grid point of b
        if _near_curves(pts, sides_b, gap_tol):
            continue
        if _on_surface(b, pts, grid.uv[nearest] if grid.uv is not None else None, gap_tol):
            out.append(k)
    return out


def _on_surface(face: TrimmedFace, pts: NDArray, guess: NDArray | None, gap_tol: float) -> bool:
    if guess is not None and project_to_surface(face.surface, pts, guess=guess
                                                ).distance.max() <= gap_tol:
        return True
    return bool(distance_to_surface(face.surface, pts).max() <= gap_tol)


def find_overlaps(faces: list[TrimmedFace | None], candidates: list[int], gap_tol: float
                  ) -> list[Overlap]:
    """Overlapping pairs among the four-sided ``candidates`` (each face trimmed once)."""
    out, used, grids = [], set(), {}
    if not candidates:
        return out
    # the surfaces' boxes (their low corners lowered by gap_tol) paired at once, in the
    # order of the pairwise loop that asked each surface for its box again for each
    # pair (1.3 s on asmo's 255 faces)
    boxes = np.stack([np.asarray(faces[i].surface.bounding_box(), float) for i in candidates])
    for n, m in zip(*box_pairs(boxes[:, 0] - gap_tol, boxes[:, 1])):
        i, j = candidates[n], candidates[m]
        if i in used or j in used:
            continue
        for f in (i, j):
            if f not in grids:
                grids[f] = surface_grid(faces[f], _GRID_SAMPLES)
        ka = _inside_sides(faces[i], faces[j], gap_tol, grids[j])
        if len(ka) != 1:
            continue
        kb = _inside_sides(faces[j], faces[i], gap_tol, grids[i])
        if len(kb) == 1:
            out.append(Overlap(i, ka[0], j, kb[0]))
            used.add(j)
    return out


def _cut_away_from(curve: NurbsCurve, at: NDArray, away_from: NDArray) -> NurbsCurve:
    """The piece of ``curve`` from its closest point to ``at`` to the end farther from
    ``away_from``."""
    t = float(project_to_curve(curve, at[None]).t[0])
    t0, t1 = curve.domain
    start_near = np.linalg.norm(curve.evaluate(t0) - away_from) < \
        np.linalg.norm(curve.evaluate(t1) - away_from)
    if start_near:
        return curve.restrict(t, t1) if t < t1 else curve
    return curve.restrict(t0, t) if t > t0 else curve


def trimmed_back_boundary(faces: list[TrimmedFace | None], overlap: Overlap) -> list[NurbsCurve]:
    """Four boundary curves (loop order) of the trimmed face without the doubled strip."""
    sides = four_sided_boundary(faces[overlap.trimmed])
    cut = four_sided_boundary(faces[overlap.kept])[overlap.side_kept]
    k = overlap.side_trimmed
    gone = sides[k]
    ends = cut.evaluate(np.array(cut.domain))                 # (2, 3)
    out = [cut]
    for step in (1, 2, 3):
        curve = sides[(k + step) % 4]
        if step == 2:
            out.append(curve)
            continue
        # the end of ``cut`` nearest to this adjacent side
        end = ends[int(np.argmin(project_to_curve(curve, ends).distance))]
        out.append(_cut_away_from(curve, end, _nearest_end(gone, curve)))
    return out


def _nearest_end(gone: NurbsCurve, curve: NurbsCurve) -> NDArray:
    """The end of the removed side where ``curve`` starts or ends."""
    g = gone.evaluate(np.array(gone.domain))
    c = curve.evaluate(np.array(curve.domain))
    d = np.linalg.norm(g[:, None] - c[None], axis=2)
    return g[np.unravel_index(np.argmin(d), d.shape)[0]]


class OverlapRepair(str, Enum):
    """What :func:`surfprep.heal` does with a strip overlap of two four-sided faces:
    ``TRIM`` the later face back to the other's side, or one approximant over the
    ``UNION``'s outline (four-sided: the two faces' adjacent sides continue each other)
    replacing both."""

    TRIM = "trim"
    UNION = "union"

    @classmethod
    def parse(cls, value) -> OverlapRepair:
        try:
            return cls(value.value if isinstance(value, cls) else str(value).lower())
        except ValueError:
            raise InvalidGeometryError(f"overlap repair must be 'trim' or 'union', got "
                                       f"{value!r}") from None


def _dense(curve: NurbsCurve, n: int = _UNION_SAMPLES) -> NDArray:
    t0, t1 = curve.domain
    return curve.evaluate(np.linspace(t0, t1, n))


def union_boundary(faces: list[TrimmedFace | None], overlap: Overlap, gap_tol: float
                   ) -> list[NDArray] | None:
    """Four polylines ``(n, 3) float`` (loop order) around the union of the two faces of a
    strip overlap: the kept face's three other sides and the trimmed face's three sides
    beyond the strip (:func:`trimmed_back_boundary`), chained end to end, the two pairs
    meeting at the ends of the kept face's inside side merged. None when they do not
    chain within ``gap_tol`` into such a loop."""
    sides_a = four_sided_boundary(faces[overlap.kept])
    k = overlap.side_kept
    cut = sides_a[k]
    ends = cut.evaluate(np.array(cut.domain))
    pieces = [_dense(sides_a[(k + s) % 4]) for s in (1, 2, 3)]
    pieces += [_dense(c) for c in trimmed_back_boundary(faces, overlap)[1:]]
    chain = [pieces.pop(0)]
    while pieces:
        end = chain[-1][-1]
        gaps = [min(np.linalg.norm(p[0] - end), np.linalg.norm(p[-1] - end)) for p in pieces]
        n = int(np.argmin(gaps))
        if gaps[n] > gap_tol:
            return None
        p = pieces.pop(n)
        chain.append(p if np.linalg.norm(p[0] - end) <= np.linalg.norm(p[-1] - end)
                     else p[::-1])
    if np.linalg.norm(chain[-1][-1] - chain[0][0]) > gap_tol:
        return None
    out = []
    for p in chain:
        if out and np.min(np.linalg.norm(ends - out[-1][-1], axis=1)) <= gap_tol:
            out[-1] = np.concatenate([out[-1], p[1:]])
        else:
            out.append(p)
    if len(out) == 5 and np.min(np.linalg.norm(ends - out[-1][-1], axis=1)) <= gap_tol:
        out = [np.concatenate([out[-1], out[0][1:]])] + out[1:-1]
    return out if len(out) == 4 else None


def overlap_boundaries(faces: list[TrimmedFace | None], overlaps: list[Overlap],
                       repair: OverlapRepair, gap_tol: float) -> tuple[dict, dict]:
    """``(trimmed, unions)``: trimmed face -> its boundary without the strip, and with
    ``UNION`` kept face -> (trimmed face, the union's outline) where that is four-sided."""
    unions = {}
    if repair is OverlapRepair.UNION:
        for o in overlaps:
            outline = union_boundary(faces, o, gap_tol)
            if outline is not None:
                unions[o.kept] = (o.trimmed, outline)
    return ({o.trimmed: trimmed_back_boundary(faces, o) for o in overlaps
             if o.kept not in unions}, unions)
