"""Which pieces of faces cut through each other are overshoots (001 §1, "intersecting
surfaces"; for :func:`surfprep.heal` without a directed patch).

Two faces *cross* when each runs on past the curve where they meet: an exporter that
wrote the untrimmed surfaces, or trimmed them short of their intersection on one side
and long on the other. Cut along the crossing curve, each face falls into pieces; the
model the user meant keeps one piece of each face at every crossing curve, the two
meeting along it, and drops the others (the overshoots).

Which side is the overshoot is told by the model around it, not by the cut alone. The
pieces (and the faces no curve cuts) are joined into *components* through their edges
other than the crossing curves (edges of different pieces lying on each other within
``gap_tol``, as :func:`~.adjacency.pair_edges` pairs them); a component is *dangling*
when one of those edges is free (a flap that sticks out of the model ends in free
edges, and so does a collar of walls overshooting a lid together). At each crossing
curve and for each of its two faces, the two pieces along the curve are compared by
their components:

* a dangling component against one that is not: the dangling one is the overshoot
  (the walls of a closed box overshooting its lid: the walls' collar, and the lid's rim);
* both dangling (two sheets, nothing else): the one whose area is at most
  ``OVERSHOOT_SHARE`` of the other's is the overshoot; of two of about the same area
  neither is, and the crossing is left (reported);
* neither dangling (a crossing inside a closed model, each side part of it), or both
  pieces in one component (the face's pieces join round the curve's ends): left.

A component is dropped when it is the overshoot at one curve and the kept side at
none; a component holding a face no curve cuts is never dropped (a crossing removes
pieces of the faces it cuts, not whole faces). A crossing curve is *trimmed* when, of
each of its faces, exactly one piece along it is kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..face_region import FaceRegion
from ..projection import project_to_surface
from ..trimmed import TrimmedFace
from .adjacency import face_edges, pair_edges, polyline_distance

__all__ = ["OVERSHOOT_SHARE", "SIDE_GRID", "CrossingDecision", "SurfaceSides", "edges_pass_through",
           "overshoot_pieces"]

#: samples per direction of a surface for the first signed distances (SurfaceSides)
SIDE_GRID = 33

#: of two dangling pieces along a crossing curve, the smaller is the overshoot when its
#: component's area is at most this share of the other's
OVERSHOOT_SHARE = 0.5


@dataclass(frozen=True)
class CrossingDecision:
    """What :func:`overshoot_pieces` decided at one crossing curve.

    Attributes
    ----------
    curve : int
        The curve's index.
    dropped : tuple of int
        Pieces (indices into ``pieces``) dropped along it.
    reason : str or None
        Why the crossing is left as it is; None when it is trimmed.
    """

    curve: int
    dropped: tuple[int, ...]
    reason: str | None = None


class SurfaceSides:
    """A face's surface sampled once (``SIDE_GRID`` squared points with their normals, in a
    k-d tree), to tell on which side of it many points lie: the nearest sample's tangent
    plane gives each point a first signed distance, exact for a plane and off by about
    the surface's curvature times the samples' spacing squared elsewhere."""

    def __init__(self, region: FaceRegion) -> None:
        self.region = region
        surface = region.surface
        u0, u1, v0, v1 = surface.domain
        u, v = np.linspace(u0, u1, SIDE_GRID), np.linspace(v0, v1, SIDE_GRID)
        uu, vv = np.meshgrid(u, v, indexing="ij")
        self.uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
        self.points = surface.evaluate_grid(u, v).reshape(-1, 3)
        self.normals = surface.normals(self.uv[:, 0], self.uv[:, 1])
        self.tree = cKDTree(self.points)
        cp = surface.control_points[..., :3].reshape(-1, 3)
        self.lo, self.hi = cp.min(axis=0), cp.max(axis=0)

    def first_guess(self, points: NDArray) -> tuple[NDArray, NDArray]:
        """Signed distances ``(n,)`` of ``points (n, 3)`` to the nearest sample's tangent
        plane, and that sample's ``(n, 2)`` parameters."""
        nearest = self.tree.query(points)[1]
        d = np.einsum("nc,nc->n", points - self.points[nearest], self.normals[nearest])
        return d, self.uv[nearest]


def edges_pass_through(sides: SurfaceSides, edges: NDArray, gap_tol: float) -> bool:
    """Whether one of the polylines ``edges (m, k, 3)`` (another face's edges, sampled)
    passes through the face of ``sides``: from farther than ``gap_tol`` on one side of
    its surface to farther than ``gap_tol`` on the other, crossing the surface inside
    the face (or on its boundary: two sheets crossing flush at their sides). Where two
    faces cut through each other, an edge of one does (a flap's side through the other
    sheet, a wall's corner through the lid it overshoots); faces that only meet, or
    overlap their neighbours by less than ``gap_tol`` at a gap, do not -- the cheap test
    before intersecting them. Only the polylines whose box meets the surface's control
    box (grown by ``gap_tol``) and whose first signed distances
    (:meth:`SurfaceSides.first_guess`) change sign are projected onto the surface
    (Newton from the nearest sample).
    """
    edges = np.asarray(edges, float)
    near = np.all((edges.max(axis=1) >= sides.lo - gap_tol)
                  & (edges.min(axis=1) <= sides.hi + gap_tol), axis=1)
    edges = edges[near]
    if not edges.size:
        return False
    m, k, _ = edges.shape
    rough, guess = sides.first_guess(edges.reshape(-1, 3))
    rough = rough.reshape(m, k)
    maybe = (rough.min(axis=1) < -0.5 * gap_tol) & (rough.max(axis=1) > 0.5 * gap_tol)
    if not np.any(maybe):
        return False
    edges, guess = edges[maybe], guess.reshape(m, k, 2)[maybe]
    m = edges.shape[0]
    surface = sides.region.surface
    foot = project_to_surface(surface, edges.reshape(-1, 3), guess=guess.reshape(-1, 2))
    uv = foot.uv.reshape(m, k, 2)
    normal = surface.normals(foot.uv[:, 0], foot.uv[:, 1]).reshape(m, k, 3)
    d = np.einsum("mkc,mkc->mk", edges - foot.points.reshape(m, k, 3), normal)
    beyond = ((d.min(axis=1) < -gap_tol) & (d.max(axis=1) > gap_tol))[:, None]
    e, s = np.nonzero(beyond & (np.sign(d[:, :-1]) * np.sign(d[:, 1:]) < 0))
    if not e.size:
        return False
    w = (d[e, s] / (d[e, s] - d[e, s + 1]))[:, None]
    return bool(np.any(sides.region.contains((1 - w) * uv[e, s] + w * uv[e, s + 1])))


def overshoot_pieces(pieces: list[TrimmedFace], origin: list[int], areas: NDArray,
                     curves: list[NDArray], curve_faces: list[tuple[int, int]],
                     gap_tol: float) -> tuple[set[int], list[CrossingDecision]]:
    """The overshooting pieces of faces cut along their crossing curves (module doc).

    Parameters
    ----------
    pieces : list of TrimmedFace
        The pieces of the cut faces and the faces no curve cuts, the whole model.
    origin : list of int
        Per piece the face it comes from (pieces of one face share it).
    areas : (len(pieces),) float
        Per piece its area.
    curves : list of (m, 3) float
        The crossing curves, as polylines in space.
    curve_faces : list of (int, int)
        Per curve the two faces (``origin`` values) it was found on.
    gap_tol : float
        Edges within this distance of each other are one (model units).

    Returns
    -------
    dropped : set of int
        The pieces to drop.
    decisions : list of CrossingDecision
        One per curve.
    """
    areas = np.asarray(areas, float)
    origin_arr = np.asarray(origin)
    counts = np.bincount(origin_arr, minlength=origin_arr.max() + 1 if len(origin) else 0)
    edges = face_edges(pieces)
    on_curve = _edges_on_curves(edges, origin, curves, curve_faces, gap_tol)
    others = [k for k in range(len(edges)) if on_curve[k] is None]
    pairs = pair_edges([edges[k] for k in others], gap_tol)
    paired = {others[k] for pair in pairs for k in pair}
    n = len(pieces)
    rows = [edges[others[a]].face for a, _ in pairs]
    cols = [edges[others[b]].face for _, b in pairs]
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, component = connected_components(graph, directed=False)
    dangling = np.zeros(component.max() + 1 if n else 0, bool)
    for k in others:
        if k not in paired:
            dangling[component[edges[k].face]] = True
    comp_area = np.bincount(component, weights=areas)
    whole = np.zeros_like(dangling)                    # holds a face no curve cuts
    for p in range(n):
        if counts[origin[p]] == 1:
            whole[component[p]] = True
    worse: dict[int, list[int]] = {}                  # component -> curves where it loses
    better: set[int] = set()
    reasons: dict[int, str] = {}
    along = _pieces_along(edges, on_curve)
    for c, faces in enumerate(curve_faces):
        for f in faces:
            sides = sorted({p for p in along.get(c, ()) if origin[p] == f})
            if len(sides) != 2:
                reasons[c] = f"face {f}: the curve does not divide it in two"
                break
            lost = _overshoot(*(component[p] for p in sides), dangling, comp_area)
            if isinstance(lost, str):
                reasons[c] = f"face {f}: {lost}"
                break
            if whole[lost]:
                reasons[c] = f"face {f}: its overshoot joins a face no curve cuts"
                break
            kept = component[sides[0]] if lost == component[sides[1]] else component[sides[1]]
            worse.setdefault(lost, []).append(c)
            better.add(kept)
    while True:                 # a curve found inconsistent keeps its pieces: decide again
        drop = {comp for comp, where in worse.items()
                if comp not in better and not any(c in reasons for c in where)}
        dropped = {p for p in range(n) if component[p] in drop}
        late = {}
        for c, faces in enumerate(curve_faces):
            kept = [p for p in along.get(c, ()) if p not in dropped]
            if c not in reasons and sorted(origin[p] for p in kept) != sorted(faces):
                late[c] = ("the pieces kept along it are not one of each face (another "
                           "crossing decides them otherwise)")
        if not late:
            break
        reasons.update(late)
    decisions = [CrossingDecision(c, (), reasons[c]) if c in reasons else
                 CrossingDecision(c, tuple(sorted(p for p in along.get(c, ()) if p in dropped)))
                 for c in range(len(curve_faces))]
    return dropped, decisions


def _edges_on_curves(edges, origin, curves, curve_faces, gap_tol) -> list[int | None]:
    """Per edge the crossing curve it lies on (its face being one of the curve's), else
    None."""
    out: list[int | None] = [None] * len(edges)
    boxes = [(c.min(axis=0) - gap_tol, c.max(axis=0) + gap_tol) for c in curves]
    for k, e in enumerate(edges):
        lo, hi = e.samples.min(axis=0), e.samples.max(axis=0)
        for c, (clo, chi) in enumerate(boxes):
            if origin[e.face] not in curve_faces[c]:
                continue
            if np.any(lo > chi) or np.any(hi < clo):
                continue
            if polyline_distance(e.samples, curves[c]).max() <= gap_tol:
                out[k] = c
                break
    return out


def _pieces_along(edges, on_curve) -> dict[int, set[int]]:
    out: dict[int, set[int]] = {}
    for e, c in zip(edges, on_curve):
        if c is not None:
            out.setdefault(c, set()).add(e.face)
    return out


def _overshoot(a: int, b: int, dangling: NDArray, area: NDArray) -> int | str:
    """The component of the two on either side of a curve that overshoots, or why
    neither does."""
    if a == b:
        return "its pieces on either side of the curve join round its ends"
    if dangling[a] != dangling[b]:
        return a if dangling[a] else b
    if not dangling[a]:
        return "both sides are part of the model (edges shared all round)"
    small, large = (a, b) if area[a] <= area[b] else (b, a)
    if area[small] <= OVERSHOOT_SHARE * area[large]:
        return small
    return (f"both sides end in free edges and are of about the same area "
            f"({area[small]:.4g} and {area[large]:.4g})")
