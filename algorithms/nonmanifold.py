"""A use-based non-manifold boundary representation of trimmed faces (002 §1).

Faces cut along their intersection curves meet in edges that two, three, four or more
faces use: where two surfaces cross, the intersection edge bounds two pieces of each.
:class:`NonManifoldModel` records that structure as plain data, NOODLES-style (every
occurrence of an edge in a face's loop is a *use* of the edge, with its own pcurve and
its direction along the edge):

* **vertices** -- points where edges end, ends within ``tol`` of each other merged;
* **edges** -- one 3D curve over a parameter range and two vertices; an edge is the
  class of the loops' edge occurrences that run over the same points (start, end and
  three interior points within ``tol``, either way round: a closed edge is told from
  its reverse by its quarter points);
* **uses** -- per edge, the occurrences ``(face, loop, position)`` with their pcurve
  and whether they run against the edge, in **radial order**: the faces around the
  edge sorted by the angle of the direction pointing into each face, in the plane
  normal to the edge at its middle. A face's loops are stored for the face seen
  FORWARD (outer loop counter-clockwise in ``(u, v)``), so with ``N = S_u x S_v`` and
  ``t`` the loop's direction along the edge the face lies on the side ``N x t``;
* **faces** -- the :class:`~.trimmed.TrimmedFace` s with their origin (operand and
  index in it).

Queries: the faces around an edge (:meth:`NonManifoldModel.faces_around`), the
edges of a face, free edges (one use), the number of edges by their number of uses,
connected components, which operand a face came from.

Degenerated edges (a pole: no extent in space) are left out: they join no face to
another.

References
----------
002 §1 (see ``surfprep.algorithms`` References).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .trimmed import TrimEdge, TrimmedFace, curve3d_points, natural_loop

__all__ = ["EdgeGeometry", "EdgeUse", "NonManifoldModel"]

#: parameters (fractions of an occurrence's range) compared to tell two occurrences
#: apart: the ends, the quarter points and the middle
_FRACTIONS = np.array([0.0, 0.25, 0.5, 0.75, 1.0])


@dataclass(frozen=True)
class EdgeUse:
    """One occurrence of an edge in a face's loop.

    Attributes
    ----------
    face, loop, position : int
        Where: ``faces[face].loops[loop].edges[position]``; ``loop`` -1 for an internal
        edge (``faces[face].internal[position]``: the face lies on both sides of it,
        counted as one use).
    against : bool
        The loop runs along the edge against the edge's direction.
    angle : float
        Radians, in ``[0, 2 pi)``: the direction into the face around the edge at its
        middle (the radial order), from the edge's first use.
    """

    face: int
    loop: int
    position: int
    against: bool
    angle: float

    def occurrence(self, faces) -> TrimEdge:
        face = faces[self.face]
        return face.internal[self.position] if self.loop < 0 else face.loops[self.loop].edges[self.position]


@dataclass(frozen=True)
class EdgeGeometry:
    """One edge of a :class:`NonManifoldModel` in one parameter for all its uses, as a
    B-rep kernel stores it (one 3D curve, a pcurve per face on the same parameter).

    Attributes
    ----------
    curve3d : NurbsCurve (d=3) or None
        The 3D curve of the reference use (the first one taken); None when that use has
        only a pcurve (its points are then its pcurve through its surface).
    t0, t1 : float
        The range, in the reference use's parameter.
    start, end : int
        The model's vertices at ``t0`` and at ``t1``.
    uses : tuple of EdgeUse
        The uses taken, the reference first.
    pcurves : tuple of NurbsCurve (d=2)
        Per use, its pcurve mapped onto ``[t0, t1]`` (affinely, turned round where the
        use's own parameter runs the other way).
    reversed : tuple of bool
        Per use, its loop runs from ``t1`` to ``t0`` (the edge appears REVERSED in it).
    ends : (2, 3) float
        The edge's points at ``t0`` and ``t1``.
    end_gap : (float, float)
        The largest distance from ``ends[0]`` (``ends[1]``) to the uses' pcurves at
        ``t0`` (``t1``) through their surfaces: what the vertices there must hold.
    deviation : tuple of float
        Per use, the largest distance, on four points a knot span of the use's pcurve
        and of the 3D curve (at least 33, at most 4097), between the edge's points and the
        pcurve through the use's surface: small when the uses share a parametrization
        (the same curve, or curves read from one edge), large when they do not.
    """

    curve3d: NurbsCurve | None
    t0: float
    t1: float
    start: int
    end: int
    uses: tuple
    pcurves: tuple
    reversed: tuple
    ends: NDArray
    end_gap: tuple
    deviation: tuple


def _mapped(curve: NurbsCurve, a: float, b: float, t0: float, t1: float, flip: bool) -> NurbsCurve:
    """``curve`` reparametrized affinely so that ``[a, b]`` becomes ``[t0, t1]`` (``flip``:
    ``b`` goes to ``t0``, the control points turned round)."""
    scale = (t1 - t0) / (b - a)
    if not flip:
        if (a, b) == (t0, t1):
            return curve
        return NurbsCurve.construct_fast(curve.control_points, t0 + (curve.knots - a) * scale,
                                         curve.degree, curve.weights)
    weights = None if curve.weights is None else curve.weights[::-1].copy()
    return NurbsCurve.construct_fast(curve.control_points[::-1].copy(), t0 + (b - curve.knots[::-1]) * scale,
                                     curve.degree, weights)


def _samples(uses, faces) -> int:
    """How many points to compare an edge's curves on: four a knot span of the busiest
    of them (the 3D curve, the pcurves), at least 33 and at most 4097."""
    spans = 8
    for use in uses:
        occurrence = use.occurrence(faces)
        for curve in (occurrence.curve3d, occurrence.pcurve):
            if curve is not None:
                spans = max(spans, np.unique(curve.knots).size - 1)
    return int(min(4 * spans + 1, 4097))


def _groups(n: int, pairs: NDArray) -> NDArray:
    """``(n,)`` labels of the classes that ``pairs (k, 2)`` join (connected components)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def _loop_points(edge: TrimEdge, surface) -> NDArray:
    """``(5, 3)`` points of an occurrence at :data:`_FRACTIONS` of its range, in the
    edge's own direction (``t0`` to ``t1``)."""
    t = edge.t0 + (edge.t1 - edge.t0) * _FRACTIONS
    return curve3d_points(edge, surface, t)


def _normal_and_tangent(edge: TrimEdge, surface, pcurve: NurbsCurve) -> tuple[NDArray, NDArray, NDArray]:
    """At the occurrence's middle: the point, ``S_u x S_v`` and the tangent in space
    along ``t0 -> t1`` (through the pcurve and the surface)."""
    t = np.array([0.5 * (edge.t0 + edge.t1)])
    d = pcurve.derivatives(t, 1)[0]                                   # (2, 2)
    s = surface.derivatives(d[0, 0:1], d[0, 1:2], 1)[0]               # (2, 2, 3)
    tangent = s[1, 0] * d[1, 0] + s[0, 1] * d[1, 1]
    return s[0, 0], np.cross(s[1, 0], s[0, 1]), tangent


def _unit(v: NDArray) -> NDArray:
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


@dataclass(frozen=True, eq=False)
class NonManifoldModel:
    """Faces and the edges they share, by use (the module doc).

    Attributes
    ----------
    faces : tuple of TrimmedFace
        The faces given, an untrimmed one with its rectangle as its loop
        (:func:`~.trimmed.natural_loop`).
    origins : tuple of (str, int)
        Per face, the operand it came from and its index there.
    vertices : (nv, 3) float
    edge_vertices : (ne, 2) int
        Start and end vertex of each edge (equal for a closed edge).
    uses : tuple of tuple of EdgeUse
        Per edge, its uses in radial order.
    tol : float
    """

    faces: tuple
    origins: tuple
    vertices: NDArray
    edge_vertices: NDArray
    uses: tuple
    tol: float

    @classmethod
    def build(cls, faces: list[TrimmedFace], origins: list[tuple[str, int]] | None = None, *,
              tol: float) -> NonManifoldModel:
        """The structure of ``faces``: their edge occurrences matched in space within
        ``tol`` (model units).

        Raises
        ------
        InvalidGeometryError
            ``tol`` not positive, or ``origins`` of another length than ``faces``.
        """
        from scipy.spatial import cKDTree
        if not (np.isfinite(tol) and tol > 0):
            raise InvalidGeometryError(f"tol must be a positive length, got {tol!r}")
        faces = tuple(f if f.loops else TrimmedFace(f.surface, (natural_loop(f.surface),), 0,
                                                    f.reversed, f.name, f.internal) for f in faces)
        origins = tuple(origins) if origins is not None else tuple(("a", k) for k in range(len(faces)))
        if len(origins) != len(faces):
            raise InvalidGeometryError("origins needs one (operand, index) per face")
        where, samples = [], []
        for f, face in enumerate(faces):
            for li, loop in enumerate(face.loops):
                for k, edge in enumerate(loop.edges):
                    if edge.degenerated:
                        continue
                    where.append((f, li, k))
                    samples.append(_loop_points(edge, face.surface))
            for k, edge in enumerate(face.internal):          # loop -1: the internal edges
                where.append((f, -1, k))
                samples.append(_loop_points(edge, face.surface))
        if not where:
            return cls(faces, origins, np.zeros((0, 3)), np.zeros((0, 2), np.int64), (), float(tol))
        pts = np.array(samples)                                           # (m, 5, 3)
        i, j = cKDTree(pts[:, 2]).query_pairs(tol, output_type="ndarray").T.reshape(2, -1)
        same = np.max(np.linalg.norm(pts[i] - pts[j], axis=2), axis=1)
        other = np.max(np.linalg.norm(pts[i] - pts[j, ::-1], axis=2), axis=1)
        match = np.minimum(same, other) <= tol
        label = _groups(len(where), np.stack([i[match], j[match]], axis=1))
        first = np.unique(label, return_index=True)[1]                   # each class's first member
        ref = pts[first[label]]
        flip = (np.max(np.linalg.norm(pts[:, ::-1] - ref, axis=2), axis=1)
                < np.max(np.linalg.norm(pts - ref, axis=2), axis=1))
        # vertices: the edges' ends merged within tol
        ends = np.stack([pts[first, 0], pts[first, -1]], axis=1).reshape(-1, 3)
        vlabel = _groups(ends.shape[0], cKDTree(ends).query_pairs(tol, output_type="ndarray"))
        vertices = np.array([ends[vlabel == v].mean(axis=0) for v in range(vlabel.max() + 1)])
        edge_vertices = vlabel.reshape(-1, 2)
        uses = []
        for e in range(first.size):
            members = np.flatnonzero(label == e)
            uses.append(cls._radial(faces, [where[m] for m in members], flip[members]))
        return cls(faces, origins, vertices, edge_vertices, tuple(uses), float(tol))

    @staticmethod
    def _radial(faces, where: list[tuple[int, int, int]], flip: NDArray) -> tuple[EdgeUse, ...]:
        """The uses of one edge in radial order (the module doc)."""
        directions, axis = [], None
        for (f, li, k), flipped in zip(where, flip):
            face = faces[f]
            edge = face.internal[k] if li < 0 else face.loops[li].edges[k]
            _, normal, tangent = _normal_and_tangent(edge, face.surface, edge.pcurve)
            along = tangent * (-1.0 if edge.reversed else 1.0)          # the loop's direction
            directions.append(np.cross(normal, along))
            if axis is None:
                axis = _unit(tangent * (-1.0 if flipped else 1.0))      # the edge's direction
        e1 = directions[0] - np.dot(directions[0], axis) * axis
        e1 = _unit(e1)
        e2 = np.cross(axis, e1)
        out = []
        for (f, li, k), flipped, d in zip(where, flip, directions):
            edge = faces[f].internal[k] if li < 0 else faces[f].loops[li].edges[k]
            angle = float(np.arctan2(np.dot(d, e2), np.dot(d, e1))) % (2 * np.pi)
            out.append(EdgeUse(f, li, k, bool(edge.reversed != flipped), angle))
        return tuple(sorted(out, key=lambda u: u.angle))

    # ------------------------------------------------------------------ queries
    @property
    def n_edges(self) -> int:
        return len(self.uses)

    def faces_around(self, edge: int) -> tuple[int, ...]:
        """The faces using ``edge``, in radial order (a face twice on a seam)."""
        return tuple(u.face for u in self.uses[edge])

    def edges_of(self, face: int) -> tuple[int, ...]:
        """The edges ``face`` uses (sorted; a seam once)."""
        return tuple(sorted({e for e, uses in enumerate(self.uses) for u in uses if u.face == face}))

    def edge_geometry(self, edge: int, faces=None) -> EdgeGeometry:
        """``edge`` in one parameter for its uses by ``faces`` (a set of face indices;
        None: all): :class:`EdgeGeometry`.

        The reference is the first use taken; every other use's pcurve is mapped onto
        its range affinely (turned round where its parameter runs against it), which is
        exact for the uses of one curve (an intersection curve's pcurves on both faces,
        an edge read from a file on both its faces) and measured per use otherwise.

        Raises
        ------
        InvalidGeometryError
            No use of ``edge`` by ``faces``.
        """
        uses = [u for u in self.uses[edge] if faces is None or u.face in faces]
        if not uses:
            raise InvalidGeometryError(f"edge {edge} has no use by the faces given")
        ref = uses[0].occurrence(self.faces)
        ref_flipped = uses[0].against != ref.reversed     # runs against the model's edge
        s = ref.t0 + (ref.t1 - ref.t0) * np.linspace(0.0, 1.0, _samples(uses, self.faces))
        if ref.curve3d is not None:
            points = ref.curve3d.evaluate(s)
        else:
            uv = ref.pcurve.evaluate(s)
            points = self.faces[uses[0].face].surface.evaluate(uv[:, 0], uv[:, 1])
        pcurves, runs_back, deviation, gap = [], [], [], np.zeros(2)
        for use in uses:
            occurrence = use.occurrence(self.faces)
            flip = (use.against != occurrence.reversed) != ref_flipped
            pcurve = _mapped(occurrence.pcurve, occurrence.t0, occurrence.t1, ref.t0, ref.t1, flip)
            uv = pcurve.evaluate(s)
            on = self.faces[use.face].surface.evaluate(uv[:, 0], uv[:, 1])
            pcurves.append(pcurve)
            runs_back.append(bool(use.against != ref_flipped))
            distance = np.linalg.norm(on - points, axis=1)
            deviation.append(float(np.max(distance)))
            gap = np.maximum(gap, distance[[0, -1]])
        start, end = (int(v) for v in self.edge_vertices[edge])
        if ref_flipped:
            start, end = end, start
        return EdgeGeometry(ref.curve3d, ref.t0, ref.t1, start, end, tuple(uses), tuple(pcurves),
                            tuple(runs_back), points[[0, -1]], (float(gap[0]), float(gap[1])),
                            tuple(deviation))

    def coincident_faces(self) -> list[tuple[int, int, bool]]:
        """Faces of different operands lying on each other: bounded by the same edges
        (the same set, at least one) and a point well inside the second within ``tol``
        of the first's surface. Returns ``(f, g, along)`` with ``f < g``; ``along``
        when their normals (orientation applied) agree there, as coplanar faces of two
        overlapping boxes do, not when they are opposed, as where two solids touch."""
        from .containment import interior_point
        from .measure import normals
        from .projection.onto_surface import project_to_surface
        edges: dict[int, set[int]] = {}
        for e, uses in enumerate(self.uses):
            for u in uses:
                edges.setdefault(u.face, set()).add(e)
        by_edges: dict[frozenset, list[int]] = {}
        for f, used in edges.items():
            by_edges.setdefault(frozenset(used), []).append(f)
        out = []
        for group in by_edges.values():
            for i, f in enumerate(sorted(group)):
                for g in sorted(group)[i + 1:]:
                    if self.origins[f][0] == self.origins[g][0]:
                        continue
                    first, second = self.faces[f], self.faces[g]
                    uv, xyz = interior_point(second)
                    foot = project_to_surface(first.surface, xyz[None], tol=0.01 * self.tol)
                    if float(foot.distance[0]) > self.tol:
                        continue
                    n_first = normals(first.surface, foot.uv[:, 0], foot.uv[:, 1])[0]
                    n_second = normals(second.surface, uv[None, 0], uv[None, 1])[0]
                    sign = (-1.0 if first.reversed else 1.0) * (-1.0 if second.reversed else 1.0)
                    out.append((f, g, bool(sign * float(np.dot(n_first, n_second)) > 0)))
        return out

    def use_counts(self) -> NDArray:
        """``(ne,)`` how many uses each edge has."""
        return np.array([len(u) for u in self.uses], dtype=np.int64)

    def edges_by_uses(self) -> dict[int, int]:
        """Number of edges by their number of uses (``{1: free, 2: manifold, 4: ...}``)."""
        counts = self.use_counts()
        return {int(k): int(np.sum(counts == k)) for k in np.unique(counts)}

    def free_edges(self) -> NDArray:
        """The edges one face uses."""
        return np.flatnonzero(self.use_counts() == 1)

    def operand(self, face: int) -> str:
        return self.origins[face][0]

    def regions(self) -> list[list[int]]:
        """Faces of one operand joined through the edges only they use, two by two (each
        component sorted, largest first): the pieces of a split that lie on one side of
        the other operand, whose intersection edges (used by both operands, or by more
        than two faces) bound them -- 002 §1's connected regions, classified as one."""
        inner = [e for e, uses in enumerate(self.uses)
                 if len(uses) == 2 and self.origins[uses[0].face][0] == self.origins[uses[1].face][0]]
        return self.components(through=inner)

    def components(self, faces=None, *, through=None) -> list[list[int]]:
        """Faces connected through shared edges, each component sorted, largest first;
        among ``faces`` only (a collection of indices; None: all), joined by the edges
        they share with one another (those of ``through`` only, when given: a
        collection of edge indices)."""
        chosen = np.arange(len(self.faces)) if faces is None else np.unique(np.asarray(list(faces), np.int64))
        if not chosen.size:
            return []
        index = np.full(len(self.faces), -1, dtype=np.int64)
        index[chosen] = np.arange(chosen.size)
        pairs = []
        for e in (range(self.n_edges) if through is None else through):
            uses = self.uses[e]
            inside = [int(index[u.face]) for u in uses if index[u.face] >= 0]
            pairs.extend((inside[0], k) for k in inside[1:])
        label = _groups(chosen.size, np.array(pairs, dtype=np.int64).reshape(-1, 2))
        groups = [chosen[label == c] for c in range(label.max() + 1)]
        return sorted(([int(f) for f in g] for g in groups), key=lambda g: (-len(g), g[0]))
