"""Which points lie inside a closed shell of trimmed faces: ray parity on the exact
surfaces (002 §1's classification of the pieces of a split, in the math layer).

A ray from the point crosses the boundary of a solid an odd number of times when the
point is inside. The crossings are found on the faces' exact surfaces: the Bézier
patches whose control-net boxes the ray's segment meets are halved (blossoming,
:func:`.intersection.culling.subpatch_boxes`) while their boxes still meet it, down
to leaves of ``LEAF_SHARE`` of the shell's size -- the boxes contain the surface, so
no crossing is lost on the way, as one would be by a triangulation that lies inside a
convex surface and outside a saddle --, and from each leaf Newton on
``S(u, v) = p + t d`` (:func:`.healing.piercing.pierce_surface`) finds the crossing;
a crossing is kept when its ``(u, v)`` lies inside the face's trimming loops
(:class:`.face_region.FaceRegion`), and counted once (several leaves of one crossing
merged).

A ray is *ambiguous* for a point when one of its crossings lies near a face's
trimming edge (it may pass between two faces or through both) or grazes a surface
(``|n . d|`` small); the point is then tried again with the next of a fixed set of
directions; so is a ray whose crossings do not alternate in and out (the faces being
oriented one way, outward or inward: a crossing was missed, two tangent ones counted
as one). A point within ``tol`` of a face (a crossing at ``|t d| <= tol``) is *on* the
shell.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from .face_region import FaceRegion
from .healing.piercing import pierce_surface
from .intersection.culling import patch_rectangles, subpatch_boxes
from .intersection.seams import closed_directions, seam_restarts
from .measure import normals
from .trimmed import TrimmedFace, natural_loop

__all__ = ["INSIDE", "ON", "OUTSIDE", "classify_points", "interior_point", "piece_states",
           "sheet_side"]

INSIDE, OUTSIDE, ON = 1, 0, -1
#: ray directions tried in turn (fixed: the answer does not depend on a seed)
_DIRECTIONS = np.array([[0.5377, 0.1834, 0.8229], [-0.3412, 0.8733, 0.3478],
                        [0.2311, -0.6066, 0.7607], [-0.8147, -0.1270, 0.5657],
                        [0.4387, 0.7815, -0.4436], [-0.2290, -0.9131, -0.3375]])
#: a crossing this many tol from a trimming edge makes the ray ambiguous
EDGE_MARGIN = 20.0
#: a crossing with |n . d| below this (unit vectors) grazes the surface
GRAZING = 0.05
#: a foot on a sheet counts where p - q makes at most acos(this) with the normal
SHEET_NORMAL = 0.99
#: leaf sub-patches' box diagonal, times the shell's diagonal
LEAF_SHARE = 0.02
#: halvings of a Bézier patch at most
MAX_DEPTH = 12


def _segment_meets(origin: NDArray, ray: NDArray, boxes: NDArray, pad: float
                   ) -> tuple[NDArray, NDArray]:
    """Slab test of segments ``origin + t ray``, ``t`` in ``[0, 1]``, against boxes
    ``(m, 2, 3)`` (widened by ``pad``): which meet, and ``t`` where each enters."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / ray
        a = (boxes[:, 0] - pad - origin) * inv
        b = (boxes[:, 1] + pad - origin) * inv
    lo = np.where(np.isnan(a), -np.inf, np.minimum(a, b))
    hi = np.where(np.isnan(b), np.inf, np.maximum(a, b))
    flat = ray == 0                                     # parallel to a slab: inside it or not
    inside = (origin >= boxes[:, 0] - pad) & (origin <= boxes[:, 1] + pad)
    lo = np.where(flat, np.where(inside, -np.inf, np.inf), lo)
    hi = np.where(flat, np.where(inside, np.inf, -np.inf), hi)
    enter, leave = np.max(lo, axis=1), np.min(hi, axis=1)
    return (enter <= leave) & (leave >= 0.0) & (enter <= 1.0), np.clip(enter, 0.0, 1.0)


def _leaves(surface, origins: NDArray, ray: NDArray, leaf: float, pad: float
            ) -> tuple[NDArray, NDArray, NDArray]:
    """The leaf sub-patches (their ``(u, v)`` centres) whose boxes the rays' segments
    meet, per ray: ``(ray index, uv (k, 2), t where the segment enters the box)``."""
    rects = patch_rectangles(surface)
    who = np.repeat(np.arange(origins.shape[0]), rects.shape[0])
    rect = np.tile(rects, (origins.shape[0], 1))
    out_who, out_uv, out_t = [], [], []
    for _ in range(MAX_DEPTH):
        if who.size == 0:
            break
        key, inverse = np.unique(rect, axis=0, return_inverse=True)
        boxes = subpatch_boxes(surface, key)[inverse.ravel()]
        meet, enter = _segment_meets(origins[who], ray, boxes, pad)
        who, rect, boxes, enter = who[meet], rect[meet], boxes[meet], enter[meet]
        small = np.linalg.norm(boxes[:, 1] - boxes[:, 0], axis=1) <= leaf
        out_who.append(who[small])
        out_uv.append(np.stack([0.5 * (rect[small, 0] + rect[small, 1]),
                                0.5 * (rect[small, 2] + rect[small, 3])], axis=1))
        out_t.append(enter[small])
        who, rect = who[~small], rect[~small]
        um, vm = 0.5 * (rect[:, 0] + rect[:, 1]), 0.5 * (rect[:, 2] + rect[:, 3])
        rect = np.concatenate([np.stack([rect[:, 0], um, rect[:, 2], vm], 1),
                               np.stack([um, rect[:, 1], rect[:, 2], vm], 1),
                               np.stack([rect[:, 0], um, vm, rect[:, 3]], 1),
                               np.stack([um, rect[:, 1], vm, rect[:, 3]], 1)])
        who = np.tile(who, 4)
    if who.size:                                        # depth exhausted: these are leaves too
        out_who.append(who)
        out_uv.append(np.stack([0.5 * (rect[:, 0] + rect[:, 1]), 0.5 * (rect[:, 2] + rect[:, 3])], 1))
        out_t.append(np.zeros(who.size))
    return np.concatenate(out_who), np.concatenate(out_uv), np.concatenate(out_t)


def _across_seams(surface, closed: tuple[bool, bool], origin: NDArray, direction: NDArray,
                  uv: NDArray, t: NDArray, t_mesh: NDArray, ok: NDArray, tol: float
                  ) -> tuple[NDArray, NDArray, NDArray]:
    """Crossings Newton could not reach because they lie across a seam of a closed
    direction (the step was held at the domain's side): tried again from the other
    side."""
    for rows, start in seam_restarts(surface, uv, closed, ~ok):
        uv2, t2, ok2 = pierce_surface(surface, origin[rows], direction[rows], start,
                                      t_mesh[rows].copy(), tol)
        uv[rows[ok2]], t[rows[ok2]], ok[rows[ok2]] = uv2[ok2], t2[ok2], True
    return uv, t, ok


def _crossings(faces, regions, closed, points: NDArray, ray: NDArray, tol: float, leaf: float
               ) -> tuple[NDArray, NDArray, NDArray]:
    """Per point: the number of crossings of its ray, whether the ray is ambiguous, and
    whether the point is on a face.

    The segment starts a little (``10 tol``) behind the point so that a crossing at the
    point itself is found (the point is then on the shell)."""
    back = 10.0 * tol
    unit = ray / np.linalg.norm(ray)
    origins = points - back * unit
    ray = ray + back * unit
    n = origins.shape[0]
    count = np.zeros(n, dtype=np.int64)
    ambiguous = np.zeros(n, dtype=bool)
    on = np.zeros(n, dtype=bool)
    found = []                                             # (point, t, sense, sine) of every crossing
    length = float(np.linalg.norm(ray))
    for f, face in enumerate(faces):
        point, uv0, t0 = _leaves(face.surface, origins, ray, leaf, tol)
        if point.size == 0:
            continue
        origin = origins[point]
        direction = np.ascontiguousarray(np.broadcast_to(ray, origin.shape))
        uv, t, ok = pierce_surface(face.surface, origin, direction, uv0, t0.copy(), tol)
        uv, t, ok = _across_seams(face.surface, closed[f], origin, direction, uv, t, t0, ok, tol)
        t = t * length - back                             # distance from the point along the ray
        ok &= t >= -tol
        keep = ok & regions[f].contains(uv, tol=0.0)
        if not np.any(ok):
            continue
        # one crossing per point and face, however many leaves found it
        order = np.lexsort((t, point))
        point, t, uv, keep, ok = point[order], t[order], uv[order], keep[order], ok[order]
        point, t, uv, keep = point[ok], t[ok], uv[ok], keep[ok]
        new = np.ones(point.size, dtype=bool)
        new[1:] = (point[1:] != point[:-1]) | (t[1:] - t[:-1] > 10 * tol)
        first = new
        pts = face.surface.evaluate(uv[first, 0], uv[first, 1])
        near_edge = regions[f].edge_distance(pts) <= EDGE_MARGIN * tol
        d = face.surface.derivatives(uv[first, 0], uv[first, 1], 1)
        normal = np.cross(d[:, 1, 0], d[:, 0, 1])
        cosine = np.abs(normal @ ray) / np.maximum(np.linalg.norm(normal, axis=1) * length, 1e-300)
        who = point[first]
        np.add.at(count, who[keep[first]], 1)
        ambiguous[who[near_edge | (cosine < GRAZING)]] = True
        on[who[np.abs(t[first]) <= tol]] = True
        side = np.sign(normal @ ray) * (-1.0 if face.reversed else 1.0)
        counted = keep[first]
        found.append(np.stack([who[counted], t[first][counted], side[counted], cosine[counted]],
                              axis=1))
    if found:
        rec = np.concatenate(found)
        rec = rec[np.lexsort((rec[:, 1], rec[:, 0]))]
        point, side = rec[:, 0].astype(np.int64), rec[:, 2]
        # a closed shell oriented one way (outward or inward) is crossed in and out in
        # turn: two crossings of the same sense in a row mean one between them was missed
        same = (point[1:] == point[:-1]) & (side[1:] == side[:-1])
        ambiguous[point[1:][same]] = True
    return count, ambiguous, on


def classify_points(faces: Sequence[TrimmedFace], points: ArrayLike, *, tol: float,
                    leaf: float | None = None) -> NDArray:
    """``(n,)`` :data:`INSIDE` (1), :data:`OUTSIDE` (0) or :data:`ON` (-1) for ``points
    (n, 3)`` against the closed shell ``faces`` (the module doc).

    Parameters
    ----------
    faces : sequence of TrimmedFace
        A closed shell (every edge shared): the answer is a parity and means nothing for
        an open one.
    points : (n, 3) float
    tol : float > 0
        Model units: a point this close to a face is on it; crossings this close to a
        trimming edge (times ``EDGE_MARGIN``) make a ray ambiguous.
    leaf : float, optional
        Size (box diagonal) of the sub-patches Newton starts from; default
        ``LEAF_SHARE`` of the shell's diagonal.

    Raises
    ------
    InvalidGeometryError
        No face, a bad tolerance, non-finite points, or a point for which every
        direction is ambiguous.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    faces = [f if f.loops else TrimmedFace(f.surface, (natural_loop(f.surface),), 0, f.reversed, f.name)
             for f in faces]                 # a whole surface: its rectangle's edges are edges
    if not faces:
        raise InvalidGeometryError("classify_points needs the faces of a closed shell")
    if not (np.isfinite(tol) and tol > 0):
        raise InvalidGeometryError(f"tol must be a positive length, got {tol!r}")
    if not np.all(np.isfinite(p)):
        raise InvalidGeometryError("points contain NaN or infinite values")
    box = np.vstack([f.surface.bounding_box() for f in faces] + [p.min(axis=0, keepdims=True),
                                                                  p.max(axis=0, keepdims=True)])
    size = float(np.linalg.norm(box.max(axis=0) - box.min(axis=0)))
    leaf = max(LEAF_SHARE * size, tol) if leaf is None else float(leaf)
    regions = [FaceRegion(f) for f in faces]
    closed = [closed_directions(f.surface, tol) for f in faces]
    label = np.full(p.shape[0], -2, dtype=np.int64)
    todo = np.arange(p.shape[0])
    for direction in _DIRECTIONS:
        if todo.size == 0:
            break
        ray = 2.0 * size * direction / np.linalg.norm(direction)
        count, ambiguous, on = _crossings(faces, regions, closed, p[todo], ray, tol, leaf)
        label[todo[on]] = ON
        decided = ~on & ~ambiguous
        label[todo[decided]] = np.where(count[decided] % 2 == 1, INSIDE, OUTSIDE)
        todo = todo[~on & ambiguous]
    if todo.size:
        raise InvalidGeometryError(f"{todo.size} point(s) lie where every ray passes a face's "
                                   "trimming edge or grazes a surface: no parity")
    return label


def sheet_side(faces: Sequence[TrimmedFace], points: ArrayLike, *, tol: float) -> NDArray:
    """``(n,)`` +1 / -1 / 0: the side of an open sheet of trimmed faces each point lies on,
    that the faces' normals point to (+1) or the other (-1), or on the sheet (0).

    The side is that of the nearest foot point on the sheet: every face's surface is
    projected on (:func:`~surfprep.algorithms.projection.project_to_surface`), feet
    outside a face's trimming loops are left out, and so are feet where ``p - q`` is
    not along the normal (held on the surface's edge: the point lies beyond it); the
    sign of ``(p - q) . n`` at the nearest foot ``q`` decides (``n`` the face's normal, ``S_u x S_v`` turned over
    for a reversed face). A point within ``tol`` of the sheet is on it.

    Raises
    ------
    InvalidGeometryError
        A point none of whose feet lies inside a face (the sheet does not reach over it:
        its side is not defined), no face, a bad tolerance.
    """
    from .projection import project_to_surface
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    if not faces:
        raise InvalidGeometryError("sheet_side needs the faces of a sheet")
    if not (np.isfinite(tol) and tol > 0):
        raise InvalidGeometryError(f"tol must be a positive length, got {tol!r}")
    best = np.full(p.shape[0], np.inf)
    side = np.zeros(p.shape[0], dtype=np.int64)
    for face in faces:
        foot = project_to_surface(face.surface, p)
        d = face.surface.derivatives(foot.uv[:, 0], foot.uv[:, 1], 1)
        normal = np.cross(d[:, 1, 0], d[:, 0, 1]) * (-1.0 if face.reversed else 1.0)
        offset = np.einsum("ij,ij->i", p - foot.points, normal)
        # a foot held on the surface's boundary (the point lies beyond the sheet's edge)
        # is no foot: the point is over the face only where p - q runs along the normal
        along = np.abs(offset) >= SHEET_NORMAL * foot.distance * np.linalg.norm(normal, axis=1)
        usable = FaceRegion(face).contains(foot.uv, tol=tol) & (along | (foot.distance <= tol))
        nearer = usable & (foot.distance < best)
        best[nearer] = foot.distance[nearer]
        side[nearer] = np.where(foot.distance[nearer] <= tol, 0, np.sign(offset[nearer]).astype(np.int64))
    if np.any(np.isinf(best)):
        raise InvalidGeometryError(f"{int(np.sum(np.isinf(best)))} point(s) lie where the sheet "
                                   "does not reach: no side")
    return side


def interior_point(face: TrimmedFace, samples: int = 33) -> tuple[NDArray, NDArray]:
    """A point well inside a trimmed face: of a ``samples x samples`` grid of its
    parameter box the point inside its loops farthest (in space) from its trimming
    edges. Returns ``(uv (2,), xyz (3,))``.

    Raises
    ------
    InvalidGeometryError
        No grid point lies inside the face.
    """
    region = FaceRegion(face)
    u0, u1, v0, v1 = face.surface.domain
    if face.loops:
        uv_all = np.concatenate([e.pcurve.evaluate(np.linspace(e.t0, e.t1, 9))
                                 for loop in face.loops for e in loop.edges])
        u0, v0 = np.maximum([u0, v0], uv_all.min(axis=0))
        u1, v1 = np.minimum([u1, v1], uv_all.max(axis=0))
    s = (np.arange(samples) + 0.5) / samples
    uu, vv = np.meshgrid(u0 + (u1 - u0) * s, v0 + (v1 - v0) * s, indexing="ij")
    uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
    uv = uv[region.contains(uv)]
    if uv.shape[0] == 0:
        raise InvalidGeometryError("no point found inside the face")
    xyz = face.surface.evaluate(uv[:, 0], uv[:, 1])
    if not face.loops:
        best = int(np.argmin(np.linalg.norm(uv - [0.5 * (u0 + u1), 0.5 * (v0 + v1)], axis=1)))
    else:
        best = int(np.argmax(region.edge_distance(xyz)))
    return uv[best], xyz[best]


def _normal(face: TrimmedFace, uv: NDArray) -> NDArray:
    """Unit normals ``(n, 3)`` of a face at ``uv (n, 2)``, turned over for a reversed face."""
    return normals(face.surface, uv[:, 0], uv[:, 1]) * (-1.0 if face.reversed else 1.0)


def piece_states(pieces: Sequence[TrimmedFace], others: Sequence[Sequence[TrimmedFace]], *,
                 tol: float) -> list[str]:
    """Where each piece of a split lies against the other operand's closed shell:
    ``"in"``, ``"out"``, or on it -- ``"shared"`` (its normal along the shell's there:
    the operands' boundaries overlap, as coplanar faces of two boxes) or
    ``"opposite"`` (normals opposed: two solids touching along the face).

    A point well inside each piece (:func:`interior_point`) is classified by ray parity
    (:func:`classify_points`); one on the shell is compared with the nearest face of the
    shell containing its foot. Faces are oriented (``reversed``) out of their solids.

    Parameters
    ----------
    pieces : sequence of TrimmedFace
    others : sequence of sequences of TrimmedFace
        Per piece, the faces of the other operand's closed shell (the same list object
        for the pieces of one operand: the classification is done once per list).
    tol : float > 0
    """
    from .projection import project_to_surface
    uvs, points = zip(*(interior_point(piece) for piece in pieces)) if pieces else ((), ())
    points = np.array(points).reshape(-1, 3)
    out = [""] * len(pieces)
    groups: dict[int, list[int]] = {}
    for k, shell in enumerate(others):
        groups.setdefault(id(shell), []).append(k)
    for rows in groups.values():
        shell = others[rows[0]]
        label = classify_points(shell, points[rows], tol=tol)
        for k, lab in zip(rows, label):
            out[k] = "in" if lab == INSIDE else "out" if lab == OUTSIDE else ""
        on = [k for k, lab in zip(rows, label) if lab == ON]
        if not on:
            continue
        best = np.full(len(on), np.inf)
        normal = np.zeros((len(on), 3))
        for face in shell:
            foot = project_to_surface(face.surface, points[on])
            usable = FaceRegion(face).contains(foot.uv, tol=tol) & (foot.distance < best)
            if np.any(usable):
                best[usable] = foot.distance[usable]
                normal[usable] = _normal(face, foot.uv[usable])
        for j, k in enumerate(on):
            own = _normal(pieces[k], np.asarray(uvs[k]).reshape(1, 2))[0]
            out[k] = "shared" if float(own @ normal[j]) > 0 else "opposite"
    return out
