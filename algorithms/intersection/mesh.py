"""Indexed triangle meshes: the piecewise-linear operands of surface-surface intersection.

A :class:`TriangleMesh` stores each vertex once and a connectivity table, with
the (u, v) parameters of each vertex when the mesh approximates a parametric
surface, as section 29.4.2 of [HJ] asks ("each vertex in the triangulation is
stored only once ... a separate list of associated uv parameter values"). The
same type is how a caller passes a plain triangulation (STL-like data) as an
intersection operand (:meth:`TriangleMesh.from_arrays`).

References
----------
.. [HJ] B. Hamann, B. Jean, "Surface-surface intersection", section 29.4 of the
   *Handbook of Grid Generation* (shared paper 000).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from . import vectors

__all__ = ["TriangleMesh", "collinear_mask"]

#: a triangle is degenerate when |e1 x e2| <= _COLLINEAR * (longest edge)^2
_COLLINEAR = 64 * np.finfo(float).eps


def collinear_mask(points: NDArray) -> NDArray:
    """Mask of zero-area triangles given by their corners.

    Parameters
    ----------
    points : (m, 3, 3) float

    Returns
    -------
    (m,) bool
        True where ``|e1 x e2| <= 64 eps |e_max|^2``: collinear or coincident
        corners, to rounding.
    """
    edges = points[:, [1, 2, 0]] - points
    # the squared lengths summed and compared column by column: numpy's reductions over
    # an axis of three run several times slower (same sums in the same order)
    length2 = edges[..., 0] * edges[..., 0] + edges[..., 1] * edges[..., 1] \
        + edges[..., 2] * edges[..., 2]
    longest2 = np.maximum(np.maximum(length2[:, 0], length2[:, 1]), length2[:, 2])
    cross = np.linalg.norm(vectors.cross(edges[:, 0], -edges[:, 2]), axis=1)
    return cross <= _COLLINEAR * longest2


def _frozen(a: ArrayLike, dtype) -> NDArray:
    out = np.array(a, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


def _as_index_array(a: ArrayLike, name: str) -> NDArray:
    arr = np.asarray(a)
    fractional = arr.size and not np.issubdtype(arr.dtype, np.integer) and (
        not np.all(np.isfinite(arr)) or np.any(arr != np.round(arr)))
    if fractional:
        raise InvalidGeometryError(f"{name} must hold integer indices")
    return _frozen(arr, np.int64)


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    """An indexed triangle mesh in 3D, optionally carrying surface parameters.

    Parameters
    ----------
    vertices : (n, 3) float
        Each vertex once; finite.
    triangles : (m, 3) int
        Vertex indices of each triangle, counter-clockwise seen from the side the
        normal points to; three distinct indices in ``[0, n)``.
    uv : (n, 2) float, optional
        Surface parameters ``(u, v)`` of each vertex when the mesh was made from a
        parametric surface; ``None`` for a plain triangulation.
    patch : (m,) int, optional
        Id of the parameter rectangle (tessellation leaf) each triangle lies in.

    Raises
    ------
    InvalidGeometryError
        Wrong shapes, NaN or infinite values, indices out of range.
    DegenerateGeometryError
        A triangle with a repeated vertex or zero area (collinear vertices).

    The arrays are copied and made read-only.
    """

    vertices: NDArray
    triangles: NDArray
    uv: NDArray | None = None
    patch: NDArray | None = None

    def __post_init__(self) -> None:
        v = _frozen(self.vertices, float)
        if v.ndim != 2 or v.shape[1] != 3:
            raise InvalidGeometryError(f"vertices must have shape (n, 3), got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InvalidGeometryError("vertices contain NaN or infinite values")
        t = _as_index_array(self.triangles, "triangles")
        if t.ndim != 2 or t.shape[1] != 3:
            raise InvalidGeometryError(f"triangles must have shape (m, 3), got {t.shape}")
        if t.size and (t.min() < 0 or t.max() >= v.shape[0]):
            bad = int(np.flatnonzero(np.any((t < 0) | (t >= v.shape[0]), axis=1))[0])
            raise InvalidGeometryError(
                f"triangle {bad} has a vertex index outside [0, {v.shape[0]}): {t[bad].tolist()}")
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "triangles", t)
        object.__setattr__(self, "uv", self._check_uv(self.uv, v.shape[0]))
        object.__setattr__(self, "patch", self._check_patch(self.patch, t.shape[0]))
        self._check_degenerate()

    @classmethod
    def from_checked(cls, vertices: NDArray, triangles: NDArray, uv: NDArray | None = None,
                     patch: NDArray | None = None) -> TriangleMesh:
        """A mesh whose arrays the caller has just made and checked (finite float
        vertices and uv, int64 triangles in range with no zero-area one, e.g.
        :func:`collinear_mask` applied): frozen copies, without validating again."""
        mesh = object.__new__(cls)
        arrays = (("vertices", vertices, float), ("triangles", triangles, np.int64),
                  ("uv", uv, float), ("patch", patch, np.int64))
        for name, value, dtype in arrays:
            object.__setattr__(mesh, name, None if value is None else _frozen(value, dtype))
        return mesh

    @staticmethod
    def _check_uv(uv, n: int) -> NDArray | None:
        if uv is None:
            return None
        uv = _frozen(uv, float)
        if uv.shape != (n, 2):
            raise InvalidGeometryError(f"uv must have shape ({n}, 2), got {uv.shape}")
        if not np.all(np.isfinite(uv)):
            raise InvalidGeometryError("uv contains NaN or infinite values")
        return uv

    @staticmethod
    def _check_patch(patch, m: int) -> NDArray | None:
        if patch is None:
            return None
        patch = _as_index_array(patch, "patch")
        if patch.shape != (m,):
            raise InvalidGeometryError(f"patch must have shape ({m},), got {patch.shape}")
        return patch

    def _check_degenerate(self) -> None:
        t = self.triangles
        repeated = (t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])
        if np.any(repeated):
            bad = int(np.flatnonzero(repeated)[0])
            raise DegenerateGeometryError(
                f"triangle {bad} repeats a vertex: {t[bad].tolist()}")
        flat = self.degenerate_triangles()
        if np.any(flat):
            bad = int(np.flatnonzero(flat)[0])
            raise DegenerateGeometryError(
                f"triangle {bad} has zero area (collinear or coincident vertices): "
                f"{self.vertices[t[bad]].tolist()}")

    # ---------------------------------------------------------------- building
    @classmethod
    def from_arrays(cls, vertices: ArrayLike, triangles: ArrayLike | None = None,
                    uv: ArrayLike | None = None, patch: ArrayLike | None = None
                    ) -> TriangleMesh:
        """A mesh from plain arrays, e.g. a triangulation read from STL.

        Parameters
        ----------
        vertices : (n, 3) float, or (m, 3, 3) float when ``triangles`` is None
            Indexed vertices, or a triangle soup (three corner points per triangle)
            whose bitwise-equal corners are merged into one vertex.
        triangles : (m, 3) int, optional
        uv : (n, 2) float, optional
            Only with indexed vertices.
        patch : (m,) int, optional

        Returns
        -------
        TriangleMesh
            Validated; vertices no triangle uses are dropped.
        """
        points = np.asarray(vertices, dtype=float)
        if triangles is None:
            if points.ndim != 3 or points.shape[1:] != (3, 3):
                raise InvalidGeometryError(
                    f"a triangle soup must have shape (m, 3, 3), got {points.shape}")
            if uv is not None:
                raise InvalidGeometryError("uv needs indexed vertices, not a triangle soup")
            unique, inverse = np.unique(points.reshape(-1, 3), axis=0, return_inverse=True)
            return cls(unique, inverse.reshape(-1, 3), None, patch)
        tri = _as_index_array(triangles, "triangles")
        mesh = cls(points, tri, uv, patch)          # validates indices first
        used = np.unique(mesh.triangles)
        if used.size == mesh.n_vertices:
            return mesh
        remap = np.full(mesh.n_vertices, -1, dtype=np.int64)
        remap[used] = np.arange(used.size)
        return cls(mesh.vertices[used], remap[mesh.triangles],
                   None if mesh.uv is None else mesh.uv[used], mesh.patch)

    @classmethod
    def from_grids(cls, blocks) -> TriangleMesh:
        """Structured surface grids (Plot3D blocks, ``(ni, nj, 3)`` float each) as one mesh.

        Every cell becomes two triangles (split along its shorter diagonal, the better
        chord of a curved cell); ``patch`` numbers the block each comes from; cells
        collapsed to a line or a point (a pole, a degenerate side) give no triangle.
        Blocks keep their own vertices (a shared edge is not merged).
        """
        points, triangles, patch, offset = [], [], [], 0
        for k, block in enumerate(blocks):
            x = np.asarray(block, dtype=float)
            if x.ndim != 3 or x.shape[2] != 3 or x.shape[0] < 2 or x.shape[1] < 2:
                raise InvalidGeometryError(f"grid block {k} must have shape (ni >= 2, nj >= 2, "
                                           f"3), got {x.shape}")
            ni, nj = x.shape[:2]
            idx = offset + np.arange(ni * nj).reshape(ni, nj)
            a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
            flat = x.reshape(-1, 3)
            short = (np.linalg.norm(flat[a - offset] - flat[c - offset], axis=-1)
                     <= np.linalg.norm(flat[b - offset] - flat[d - offset], axis=-1))
            first = np.where(short[..., None], np.stack([a, b, c], -1), np.stack([a, b, d], -1))
            second = np.where(short[..., None], np.stack([a, c, d], -1), np.stack([b, c, d], -1))
            tri = np.concatenate([first.reshape(-1, 3), second.reshape(-1, 3)])
            points.append(flat)
            triangles.append(tri)
            patch.append(np.full(tri.shape[0], k))
            offset += ni * nj
        if not points:
            raise InvalidGeometryError("no grid block to make a mesh of")
        vertices, tri = np.concatenate(points), np.concatenate(triangles)
        keep = ~collinear_mask(vertices[tri])
        return cls.from_arrays(vertices, tri[keep], patch=np.concatenate(patch)[keep])

    # ------------------------------------------------------------------ sizes
    @property
    def n_vertices(self) -> int:
        return self.vertices.shape[0]

    @property
    def n_triangles(self) -> int:
        return self.triangles.shape[0]

    # ------------------------------------------------------------- geometry
    def triangle_points(self) -> NDArray:
        """Corner points of every triangle: (m, 3, 3) float, ``[t, corner, xyz]``."""
        return self.vertices[self.triangles]

    def triangle_uv(self) -> NDArray:
        """Corner parameters of every triangle: (m, 3, 2) float (needs ``uv``)."""
        if self.uv is None:
            raise InvalidGeometryError("this mesh has no (u, v) parameters")
        return self.uv[self.triangles]

    def triangle_boxes(self) -> NDArray:
        """Axis-aligned box of every triangle: (m, 2, 3) float, ``[t, min/max, xyz]``."""
        p = self.triangle_points()
        return np.stack([vectors.corner_min(p), vectors.corner_max(p)], axis=1)

    def bounding_box(self) -> NDArray:
        """Box of all vertices: (2, 3) float (zeros for an empty mesh)."""
        if self.n_vertices == 0:
            return np.zeros((2, 3))
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def area_vectors(self) -> NDArray:
        """``(p1 - p0) x (p2 - p0)`` of every triangle: (m, 3) float (twice the area)."""
        p = self.triangle_points()
        return vectors.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])

    def areas(self) -> NDArray:
        """Triangle areas: (m,) float."""
        return 0.5 * np.linalg.norm(self.area_vectors(), axis=1)

    def normals(self) -> NDArray:
        """Unit normals of the triangles (right-hand rule on the corner order): (m, 3) float."""
        n = self.area_vectors()
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def degenerate_triangles(self) -> NDArray:
        """Mask of zero-area triangles: (m,) bool.

        A triangle is degenerate when ``|e1 x e2| <= 64 eps |e_max|^2``: its
        vertices are collinear or coincident to rounding.
        """
        return collinear_mask(self.triangle_points())

    # ------------------------------------------------------------ topology
    def edges(self) -> tuple[NDArray, NDArray]:
        """Undirected edges and how many triangles use each.

        Returns
        -------
        edges : (e, 2) int
            Vertex pairs ``(i, j)``, ``i < j``, sorted.
        counts : (e,) int
            Number of triangles having the edge: 2 inside a watertight
            (manifold) mesh, 1 on its boundary.
        """
        t = self.triangles
        pairs = np.stack([t, t[:, [1, 2, 0]]], axis=2).reshape(-1, 2)
        pairs = np.sort(pairs, axis=1)
        return np.unique(pairs, axis=0, return_counts=True)

    def boundary_edges(self) -> NDArray:
        """Edges used by exactly one triangle: (b, 2) int."""
        edges, counts = self.edges()
        return edges[counts == 1]

    def __repr__(self) -> str:
        extra = "" if self.uv is None else ", with uv"
        return f"TriangleMesh({self.n_vertices} vertices, {self.n_triangles} triangles{extra})"
