"""The common curve each open edge's faces go to in :func:`~.close_gaps.close_gaps`, and
the vertices its ends are pulled to.

An edge open at ``tight`` gets one curve its moving faces are fitted to and its fixed
faces may be re-trimmed to (:func:`common_curve`, the rules in :mod:`.close_gaps`);
a closed or free edge is held, each moving face keeping its own side. The curve is the
cubic through ``FIT_SAMPLES`` even samples (:func:`through`), evaluated at every sample;
each moving face's new pcurve is its closest points to it (:func:`uv_on`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.distance import cdist, pdist

from ...algorithms.curve import NurbsCurve
from ...algorithms.fitting import interpolate_curve
from ...algorithms.healing.edge_targets import on_surface, pinned_ends, roughness, spread_ends
from ...algorithms.projection import project_to_surface
from ...algorithms.surface import NurbsSurface
from .shared_edges import SharedEdge, feet_on_face, pcurve_points

__all__ = ["CORNER_GROUP", "FIT_SAMPLES", "FIT_SHARE", "CommonCurve", "FaceCorners",
           "VertexPositions", "common_curve", "cornered", "even_samples", "through",
           "to_vertices", "uv_on", "vertex_positions"]

#: evenly spaced samples per edge where a moving face is fitted (as many again clustered
#: at the ends; knot spans are split while one holds 12 of them): the common curve is
#: the cubic through the even ones
FIT_SAMPLES = 513
#: a face moves when its fit leaves at most this share of the tight tolerance (two faces
#: then meet within it)
FIT_SHARE = 0.4
#: weight of an image's waves (:func:`~surfprep.algorithms.healing.edge_targets.roughness`)
#: against its distance from the other faces in choosing the common curve
_ROUGHNESS_WEIGHT = 2.0
#: ends of a face's pcurves at one vertex within this share of the diagonal of its
#: surface's domain of each other are one corner (:class:`FaceCorners`)
CORNER_GROUP = 1e-3


@dataclass
class CommonCurve:
    """An edge's common curve: ``points`` C(t) at ``t`` (the reference face's pcurve
    parameters), and per (face, seam side) of a moving face its new pcurve's samples and,
    where it does not go to C, where its side goes."""

    t: NDArray
    points: NDArray
    even: NDArray                                 # indices of the evenly spaced samples
    curve: NurbsCurve | None = None               # C: the cubic through the even samples
    uv: dict = field(default_factory=dict)        # (face, seam side) -> (m, 2)
    goals: dict = field(default_factory=dict)     # (face, seam side) -> (m, 3), else points
    retrimmed: dict = field(default_factory=dict)  # fixed face re-trimmed -> its boundary's shift


def to_vertices(curve: NDArray, s: NDArray, start: NDArray, end: NDArray) -> NDArray:
    """``curve`` (m, 3) at ``s`` (m,) with its ends' shifts onto the vertices ``start``
    and ``end`` blended by ``3 s^2 - 2 s^3``: level at both ends, so the targets of two
    edges in line keep one slope through their vertex (a kink there the fit resolves
    only with ever shorter knot spans)."""
    w = (s * s * (3.0 - 2.0 * s))[:, None]
    return curve + (1.0 - w) * (start - curve[0]) + w * (end - curve[-1])


def uv_on(surface: NurbsSurface, points: NDArray, guess: NDArray, s: NDArray) -> NDArray:
    """Parameters of a moving face's new pcurve: ``points`` (m, 3) at ``s`` projected onto
    ``surface`` from its old pcurve ``guess`` (m, 2), its ends where they were, within the
    domain."""
    uv = pinned_ends(spread_ends(on_surface(surface, points, guess, s), s), guess, s)
    u0, u1, v0, v1 = surface.domain
    return np.stack([np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)], axis=1)


def common_curve(e: SharedEdge, s: NDArray, images, position, moving: set[int],
                 trimmable: set[int], surfaces, faces, tight: float, allowed: float
                 ) -> CommonCurve | None:
    """The common curve of ``e`` (the rules in :mod:`.close_gaps`), its ends pulled onto
    the vertices.
    An edge open at ``tight``: where a fixed face may be re-trimmed, the other face's image
    or its feet on the fixed face's surface when :func:`_retrim` finds them better (None
    when no face of ``e`` moves and none can be re-trimmed so); else a fixed face's image
    if it has one, else the image of the
    face whose boundary lies nearest the other faces' surfaces and is smoothest
    (:func:`~surfprep.algorithms.healing.edge_targets.roughness`: a wavy pcurve
    beside a smooth one loses), as it is when it lies
    on them within ``FIT_SHARE`` x ``tight``, or midway to its feet on them; projected
    onto every moving face, which goes to it. A free edge, or one already closed at
    ``tight``: the mean of its faces' images, each moving face holding its own side
    (only its ends follow the vertices)."""
    still = [i for i, f in enumerate(e.faces) if f not in moving]
    if e.degenerated:
        a, b = e.ranges[0]
        return CommonCurve(a + s * (b - a), np.repeat(position.ends(e)[0][None], s.size, axis=0),
                           even_samples(s))

    def to_ends(curve: NDArray) -> NDArray:
        return to_vertices(curve, s, *position.ends(e))

    closed = len(e.faces) == 1 or e.gap <= tight
    trimmed = None
    if closed:
        ref = still[0] if still else 0
        mean = np.mean([images[id(e), i] for i in range(len(e.faces))], axis=0)
    elif still:
        ref = still[0]
        mean = images[id(e), ref]
        option = _retrim(e, s, images, position, moving, trimmable, surfaces, faces, tight,
                         allowed)
        retrim = None if option is None else _on_retrimmed(e, s, option, position, faces, tight)
        if retrim is not None:
            ref, mean, trimmed = option
        elif not any(f in moving for f in e.faces):
            return None
    else:
        best = None
        for ref in range(len(e.faces)):
            base = images[id(e), ref]
            feet = [_feet(e, i, base, images, surfaces, faces, s)
                    for i in range(len(e.faces)) if i != ref]
            score = (max(float(np.max(np.linalg.norm(foot - base, axis=1))) for foot in feet)
                     + _ROUGHNESS_WEIGHT * roughness(base, s))
            if best is None or score < best[0]:
                best = (score, ref, base, feet)
        score, ref, base, feet = best
        mean = base if score <= FIT_SHARE * tight else np.mean([base, *feet], axis=0)
    a, b = e.ranges[ref]
    t, even = a + s * (b - a), even_samples(s)
    # the targets are the edge's curve (the cubic through the even samples) at every
    # sample: points mixing feet and images can wave between the even samples, and a
    # face fitted to them would lie off its edge there
    if trimmed is not None:
        curve, uv = retrim
        common = CommonCurve(t, curve.evaluate(t), even, curve)
        common.uv[e.faces[trimmed], False] = uv
        common.retrimmed[e.faces[trimmed]] = float(np.max(np.linalg.norm(
            common.points - images[id(e), trimmed], axis=1)))
    else:
        curve = through(t, to_ends(mean), even)
        common = CommonCurve(t, curve.evaluate(t), even, curve)
    for i, f in enumerate(e.faces):
        if f not in moving:
            continue
        for side in ((False, True) if e.seam else (False,)):
            guess = cornered(e, i, faces, s, side, position)
            if closed:          # each face keeps its own side, its ends at the vertices
                common.uv[f, side] = guess
                common.goals[f, side] = to_ends(images[id(e), i])
                continue
            common.uv[f, side] = uv_on(surfaces[f], common.points, guess, s)
    return common


def _retrim(e: SharedEdge, s: NDArray, images, position, moving: set[int], trimmable: set[int],
            surfaces, faces, tight: float, allowed: float) -> tuple[int, NDArray, int] | None:
    """A common curve for the open two-face edge ``e`` lying on the surface of a face
    that does not move but may be re-trimmed (``trimmable``), as ``(ref, points, j)``:
    the other face ``ref``'s image, or its feet on face ``j``'s surface, to which ``j``
    is re-trimmed. A fixed ``ref`` qualifies when its image lies on ``j``'s surface
    within ``FIT_SHARE`` x ``tight`` (the two surfaces meet along it); a moving one
    when its feet lie within ``allowed``, and it wins against ``j``'s own boundary
    (the common curve otherwise) when its distance plus its waves
    (:func:`~surfprep.algorithms.healing.edge_targets.roughness`) are smaller. The
    re-trimmed boundary may shift by ``allowed`` at most, and its ends stay: ``j``'s
    corners must be at the vertices (within ``FIT_SHARE`` x ``tight``; its other edges
    end there). None when nothing qualifies."""
    if len(e.faces) != 2 or e.seam or e.degenerated:
        return None
    best = None
    for j in (0, 1):
        if e.faces[j] not in trimmable:
            continue
        i = 1 - j
        own = images[id(e), j]
        start, end = position.ends(e)
        if max(float(np.linalg.norm(own[0] - start)),
               float(np.linalg.norm(own[-1] - end))) > FIT_SHARE * tight:
            continue
        base = images[id(e), i]
        _, feet = feet_on_face(e, j, faces, base, s)
        off = float(np.max(np.linalg.norm(feet - base, axis=1)))
        if float(np.max(np.linalg.norm(feet - own, axis=1))) > allowed:
            continue
        if e.faces[i] not in moving:
            if off <= FIT_SHARE * tight and (best is None or off < best[0]):
                best = (off, i, base, j)
            continue
        if off > allowed:
            continue
        points = base if off <= FIT_SHARE * tight else feet
        score = off + _ROUGHNESS_WEIGHT * roughness(points, s)
        kept = (float(np.max(np.linalg.norm(_feet(e, i, own, images, surfaces, faces, s) - own,
                                            axis=1)))
                + _ROUGHNESS_WEIGHT * roughness(own, s))
        if score < kept and (best is None or score < best[0]):
            best = (score, i, points, j)
    return None if best is None else best[1:]


def _on_retrimmed(e: SharedEdge, s: NDArray, option: tuple[int, NDArray, int], position,
                  faces, tight: float):
    """The common curve of ``e`` for a :func:`_retrim` option ``(ref, points, j)`` and face
    ``j``'s new pcurve samples: ``points`` with their ends' shifts onto the vertices
    (:func:`to_vertices`), put back onto ``j``'s surface (off a plane the shifts,
    faded over the whole edge, take the curve off it: kcs by up to 5e-3), the cubic
    through them, its feet on ``j`` with ``j``'s ends where they were. None when that
    curve lies off ``j``'s surface by more than ``FIT_SHARE`` x ``tight`` (beyond the
    border of its domain, where the feet stop)."""
    ref, points, j = option
    a, b = e.ranges[ref]
    t = a + s * (b - a)
    goal = feet_on_face(e, j, faces, to_vertices(points, s, *position.ends(e)), s)[1]
    curve = through(t, goal, even_samples(s))
    on = curve.evaluate(t)
    uv, feet = feet_on_face(e, j, faces, on, s)
    if float(np.max(np.linalg.norm(feet - on, axis=1))) > FIT_SHARE * tight:
        return None
    return curve, pinned_ends(uv, pcurve_points(e, j, faces, s), s)


def even_samples(s: NDArray) -> NDArray:
    """Indices of the evenly spaced samples among ``s`` (:data:`FIT_SAMPLES` of them)."""
    return np.searchsorted(s, np.linspace(0.0, 1.0, FIT_SAMPLES))


def through(t: NDArray, points: NDArray, even: NDArray):
    """The cubic interpolating ``points`` at the evenly spaced ``t`` (the samples
    clustered at the ends would make the interpolation ill-conditioned)."""
    return interpolate_curve(points[even], parameters=t[even])


def _feet(e: SharedEdge, i: int, points: NDArray, images, surfaces, faces, s: NDArray) -> NDArray:
    """Closest points of moving face ``e.faces[i]``'s surface to ``points`` (started from
    its pcurve at the same parameters); where one lands farther than twice the edge's
    gap (a wrong local minimum), the face's own point there."""
    foot = project_to_surface(surfaces[e.faces[i]], points, guess=pcurve_points(e, i, faces, s)).points
    far = np.linalg.norm(foot - points, axis=1) > 2.0 * e.gap + 1e-12
    foot[far] = images[id(e), i][far]
    return foot


@dataclass(frozen=True)
class VertexPositions:
    """Where :func:`vertex_positions` puts the vertices (``at``) and, at a vertex whose
    fixed faces' corners lie apart (a gap between them that stays open), where each
    group of faces there goes (``groups``: per (vertex, face) its group's point) and
    which faces move (``moving``); where the moving faces' edges end in their
    parameters (``corners``)."""

    at: dict
    groups: dict = field(default_factory=dict)
    moving: frozenset = frozenset()
    corners: FaceCorners | None = None

    def ends(self, e: SharedEdge) -> tuple[NDArray, NDArray]:
        """Where ``e``'s ends go: its faces' group's point where they are in one group,
        else its moving faces' group's (a fixed face's side cannot follow, a moving
        face's corner is one point), else the vertex's."""
        return self._end(e, e.first), self._end(e, e.last)

    def _end(self, e: SharedEdge, v: int) -> NDArray:
        points = [self.groups.get((v, f)) for f in e.faces]
        if points[0] is None:
            return self.at[v]
        if all(p is points[0] for p in points):
            return points[0]
        ours = [p for p, f in zip(points, e.faces) if f in self.moving]
        if ours and all(p is ours[0] for p in ours):
            return ours[0]
        return self.at[v]


@dataclass(frozen=True)
class FaceCorners:
    """Where the edges of faces end in their parameters, one point per corner.

    An exporter's pcurves of two edges meeting at a vertex often end a little apart on
    the face (within the vertex's tolerance: 1.6e-5 of the parameter range, 3.6e-5 mm,
    on the K1 CATIA/debis export's faces 3 and 47). Both ends must go to the vertex when
    the face moves onto its neighbours' edges, so the moved surface would have to
    collapse the stretch between them to a point: fits folded the face over there (its
    tangent planes turned by 180 degrees). Ends at one vertex lying within
    ``CORNER_GROUP`` times the diagonal of the face's surface's domain of each other
    are one corner, at their mean (the two sides of a seam or a pole lie a period apart
    and stay apart).

    Attributes
    ----------
    at : dict
        ``(face, vertex) -> (k, 2)`` the face's corners at the vertex.
    """

    at: dict

    @classmethod
    def of(cls, which, of_face, faces, surfaces) -> FaceCorners:
        """The corners of the faces ``which`` (face ``f``'s edges ``of_face[f]``, its
        surface ``surfaces[f]``; ``faces`` the shape's face map)."""
        at = {}
        ends = np.array([0.0, 1.0])
        for f in which:
            u0, u1, v0, v1 = surfaces[f].domain
            near = CORNER_GROUP * float(np.hypot(u1 - u0, v1 - v0))
            by_vertex: dict[int, list[list[NDArray]]] = {}
            for e in of_face[f]:
                i = e.faces.index(f)
                for side in ((False, True) if e.seam else (False,)):
                    uv = pcurve_points(e, i, faces, ends, side)
                    for v, point in ((e.first, uv[0]), (e.last, uv[1])):
                        groups = by_vertex.setdefault(v, [])
                        group = next((g for g in groups if np.linalg.norm(g[0] - point) <= near),
                                     None)
                        if group is None:
                            groups.append([point])
                        else:
                            group.append(point)
            for v, groups in by_vertex.items():
                at[f, v] = np.array([np.mean(g, axis=0) for g in groups])
        return cls(at)

    def snapped(self, uv: NDArray, s: NDArray, f: int, e: SharedEdge) -> NDArray:
        """``uv`` (m, 2), ``e``'s pcurve on face ``f`` at ``s`` (m,), its ends moved onto
        the face's nearest corners at ``e``'s vertices, the shift faded out along the
        edge (:func:`~surfprep.algorithms.healing.edge_targets.pinned_ends`); as it is
        on a face without corners."""
        corners = [self.at.get((f, v)) for v in (e.first, e.last)]
        if corners[0] is None or corners[1] is None:
            return uv
        ends = np.array([c[np.argmin(np.linalg.norm(c - end, axis=1))]
                         for c, end in zip(corners, (uv[0], uv[-1]))])
        if np.array_equal(ends, uv[[0, -1]]):
            return uv
        return pinned_ends(uv, ends, s)


def cornered(e: SharedEdge, i: int, faces, s: NDArray, side: bool,
             position: VertexPositions) -> NDArray:
    """:func:`~.shared_edges.pcurve_points` of ``e`` on its ``i``-th face, its ends on
    the face's corners (``position.corners``) where it moves."""
    uv = pcurve_points(e, i, faces, s, side)
    if position.corners is None:
        return uv
    return position.corners.snapped(uv, s, e.faces[i], e)


def vertex_positions(around, edges: list[SharedEdge], moving: set[int], images, image,
                     tight: float) -> VertexPositions:
    """Per vertex of an edge of ``around``: the mean of its faces' corners there, one per
    face and edge (of the fixed faces' if any). Where the fixed faces' corners lie
    farther than ``tight`` apart, the faces there are grouped (:func:`_groups`) and each
    group's edges end at the mean of its own fixed corners (asmo: a closed edge between
    a moving face and a fixed one, pulled to the mean of that face's corner and of
    another fixed face's 0.02 away across an open gap, came out 0.02 wide)."""
    wanted = {v for e in around for v in (e.first, e.last)}
    corners: dict[int, dict[int, list[NDArray]]] = {v: {} for v in wanted}  # per face, per edge
    at_vertex: dict[int, list[SharedEdge]] = {v: [] for v in wanted}
    ends = np.array([0.0, 1.0])
    for e in edges:
        if e.first not in wanted and e.last not in wanted:
            continue
        for i, f in enumerate(e.faces):
            got = images.get((id(e), i))
            pts = got[[0, -1]] if got is not None else image(e, i, ends)
            for v, p in ((e.first, pts[0]), (e.last, pts[1])):
                if v in corners:
                    corners[v].setdefault(f, []).append(p)
        for v in {e.first, e.last} & wanted:
            at_vertex[v].append(e)
    at, groups = {}, {}
    for v, by_face in corners.items():
        fixed = _corners(by_face, by_face, moving)
        at[v] = np.mean(fixed if len(fixed) else _corners(by_face, by_face), axis=0)
        if len(fixed) > 1 and float(pdist(fixed).max()) > tight:
            groups.update(_groups(v, by_face, at_vertex[v], moving, tight))
    return VertexPositions(at, groups, frozenset(moving))


def _corners(faces, by_face: dict[int, list[NDArray]], moving: set[int] = frozenset()) -> NDArray:
    """The corners (k, 3) of ``faces`` that do not move, one per face and edge."""
    return np.array([p for f in faces if f not in moving for p in by_face[f]]).reshape(-1, 3)


def _groups(v: int, by_face: dict[int, list[NDArray]], edges: list[SharedEdge], moving: set[int],
            tight: float) -> dict[tuple[int, int], NDArray]:
    """Per (``v``, face) the point of the face's group at vertex ``v``: the faces there
    joined along the edges at ``v`` narrowest first, two groups not joined where their
    fixed corners would then lie more than ``tight`` apart (a moving face between two
    fixed faces that do not meet follows the one it meets more closely; the other
    edge's gap stays, or narrows)."""
    from scipy.cluster.hierarchy import DisjointSet  # (only where corners lie apart)
    grouped = DisjointSet(by_face)
    for e in sorted(edges, key=lambda e: e.gap):
        for f, g in zip(e.faces, e.faces[1:]):
            if grouped.connected(f, g):
                continue
            a = _corners(grouped.subset(f), by_face, moving)
            b = _corners(grouped.subset(g), by_face, moving)
            if len(a) and len(b) and float(cdist(a, b).max()) > tight:
                continue
            grouped.merge(f, g)
    out = {}
    for faces in grouped.subsets():
        fixed = _corners(faces, by_face, moving)
        point = np.mean(fixed if len(fixed) else _corners(faces, by_face), axis=0)
        out.update(((v, f), point) for f in faces)
    return out
