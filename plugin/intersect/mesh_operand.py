"""A triangle mesh (STL) against faces: :func:`intersect_mesh`.

Discrete geometry (a hull from a scanner, an STL from another tool) meets exact
faces: 000 §29.1.3 asks a surface intersector to take "surfaces described by
discrete data points". The algorithms take a
:class:`~surfprep.algorithms.intersection.TriangleMesh` as an operand already
(:func:`~surfprep.algorithms.intersection.intersect_surfaces`: the mesh's
triangles against the face's tessellation, each sample then projected onto the
exact side); here every face of the other operand whose box meets the mesh's is
intersected with it, and the curves are clipped to the face's trimmed domain (the
mesh has no trimming: it is all of itself). Each curve lies on the face's surface
within ``tol``, and as close to the surface the mesh stands for as the mesh itself
is (its own deviation).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...algorithms.intersection import (
    IntersectionCurve,
    StrayCurves,
    TriangleMesh,
    clip_curve,
    closed_in_space,
    intersect_surfaces,
)
from ...algorithms.tolerance import check_tolerance
from ...errors import (
    DegenerateGeometryError,
    InputFileError,
    InvalidGeometryError,
    InvalidToleranceError,
)
from ..occ.edges import make_edge
from .operands import DEFAULT_TOL_FACTOR, MIN_TOL_FACTOR, FaceOperand, face_operands

__all__ = ["MeshCurve", "MeshIntersectionResult", "intersect_mesh", "read_mesh"]

def read_mesh(path) -> TriangleMesh:
    """An STL or Wavefront OBJ file, or a multi-block Plot3D surface grid (every cell two
    triangles), as a :class:`~surfprep.algorithms.intersection.TriangleMesh`.

    Raises
    ------
    InputFileError
        Missing, empty, not of its extension's format, truncated or holding no triangle.
    """
    from ...algorithms.grid.io.plot3d import read_plot3d
    from ...algorithms.io import read_obj, read_stl
    suffix = Path(path).suffix.lower()
    if suffix == ".stl":
        return read_stl(path)
    if suffix == ".obj":
        return read_obj(path)
    try:
        blocks = read_plot3d(path)
    except FileNotFoundError:
        raise InputFileError(f"input file {path} does not exist") from None
    except ValueError as exc:
        raise InputFileError(f"{path} is not a Plot3D surface grid: {exc}") from None
    try:
        return TriangleMesh.from_grids(blocks)
    except (InvalidGeometryError, DegenerateGeometryError) as exc:
        raise InputFileError(f"the grid of {path} makes no mesh: {exc}") from None


@dataclass(frozen=True, eq=False)
class MeshCurve:
    """One curve where the mesh meets a face, clipped to the face.

    Attributes
    ----------
    curve : IntersectionCurve
        Samples on the face's surface (``uv_b``, ``pcurve_b``); ``uv_a`` is None
        (the mesh side has no parameters).
    face : FaceOperand
    tol : float
    """

    curve: IntersectionCurve
    face: FaceOperand
    tol: float

    @property
    def points(self) -> NDArray:
        return self.curve.points

    @property
    def closed(self) -> bool:
        return closed_in_space(self.curve, self.tol)

    @property
    def length(self) -> float:
        return self.curve.length

    def distance_to_face(self) -> float:
        """Largest distance of the curve's interpolant from the face's surface, between
        the samples too (three points a span)."""
        return self.curve.max_deviation(None, self.face.surface).to_b

    def to_edges(self) -> list:
        """``[TopoDS_Edge]``: the 3D curve with its pcurve on the face."""
        c = self.curve
        if c.curve3d is None or c.pcurve_b is None:
            raise InvalidGeometryError("the curve has no interpolants to build an edge from")
        tol = max(self.tol, 1.01 * self.distance_to_face())
        return [make_edge(c.curve3d, [(c.pcurve_b, self.face.face_for_edges())], tol)]


class MeshIntersectionResult(list):
    """What :func:`intersect_mesh` found: a ``list`` of :class:`MeshCurve`, with ``tol``,
    ``time_s`` and the mesh's size."""

    def __init__(self, curves=(), *, tol: float = 0.0, mesh: TriangleMesh | None = None,
                 pairs: int = 0) -> None:
        super().__init__(curves)
        self.tol, self.mesh, self.pairs, self.time_s = tol, mesh, pairs, 0.0

    def edges(self) -> list:
        """Every curve as ``TopoDS_Edge`` s (:meth:`MeshCurve.to_edges`)."""
        return [e for c in self for e in c.to_edges()]

    def report(self) -> dict:
        """Plain-JSON report: the mesh, the faces met, each curve's face, length,
        closedness and distance from the face's surface."""
        mesh = self.mesh
        return {
            "tol": self.tol, "time_s": self.time_s, "method": "mesh",
            "mesh": None if mesh is None else {"vertices": mesh.n_vertices,
                                               "triangles": mesh.n_triangles},
            "faces_met": self.pairs, "n_curves": len(self),
            "curves": [{"face": c.face.index, "points": int(c.points.shape[0]),
                        "length": c.length, "closed": c.closed,
                        "distance_to_face": c.distance_to_face()} for c in self],
        }


def intersect_mesh(mesh: TriangleMesh, other, *, tol: float | None = None,
                   mesh_tol: float | None = None,
                   progress: Callable[[int, int], None] | None = None) -> MeshIntersectionResult:
    """The curves where a triangle mesh meets the faces of ``other``.

    Parameters
    ----------
    mesh : TriangleMesh
        E.g. from :func:`surfprep.algorithms.io.read_stl`.
    other
        Anything :func:`surfprep.intersect` takes (faces, shapes, models, paths).
    tol : float, optional
        Model units: how close to each face's surface the curves lie; default 1e-6
        of the box of the mesh and the faces.
    mesh_tol : float, optional
        Tessellation tolerance of the faces (default 1e-3 of a pair's size).
    progress : callable(done, total), optional
        Called with 0 once the faces whose boxes meet the mesh's are known, then
        after each.

    Returns
    -------
    MeshIntersectionResult

    Raises
    ------
    InvalidToleranceError
        ``tol`` not finite and positive, or above the size.
    """
    start = time.perf_counter()
    faces = face_operands(other)
    mesh_box = np.stack([mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)])
    boxes = np.stack([np.asarray(f.surface.bounding_box(), dtype=float) for f in faces])
    lo = np.minimum(mesh_box[0], boxes[:, 0].min(axis=0))
    hi = np.maximum(mesh_box[1], boxes[:, 1].max(axis=0))
    size = float(np.linalg.norm(hi - lo))
    if not size > 0:
        raise InvalidGeometryError("the mesh and the faces have no extent")
    tol = DEFAULT_TOL_FACTOR * size if tol is None else tol
    tol = check_tolerance(tol, "tol", low=MIN_TOL_FACTOR * size, high=size)
    meets = np.all((boxes[:, 0] <= mesh_box[1] + tol) & (mesh_box[0] <= boxes[:, 1] + tol),
                   axis=1)
    chosen = [f for f, m in zip(faces, meets, strict=True) if m]
    out = MeshIntersectionResult(tol=tol, mesh=mesh, pairs=len(chosen))
    if progress is not None:
        progress(0, len(chosen))
    for done, face in enumerate(chosen, start=1):
        try:
            curves = intersect_surfaces(mesh, face.surface, tol=tol, mesh_tol=mesh_tol,
                                        stray=StrayCurves.DROP)
        except (InvalidGeometryError, InvalidToleranceError, ValueError, FloatingPointError) as exc:
            warnings.warn(f"the mesh and face {face.index}: intersection skipped: {exc}",
                          stacklevel=2)
            curves = []
        for curve in curves:
            out.extend(MeshCurve(piece, face, tol) for piece in _clip_to_face(curve, face, tol))
        if progress is not None:
            progress(done, len(chosen))
    out.time_s = time.perf_counter() - start
    return out


def _clip_to_face(curve: IntersectionCurve, face: FaceOperand, tol: float
                  ) -> list[IntersectionCurve]:
    """The pieces of a mesh x face curve inside the face: the face side stands for both
    sides of :func:`clip_curve` (the mesh has no trimming), then the mesh side is None
    again."""
    if curve.uv_b is None or curve.pcurve_b is None:
        return []
    both = replace(curve, uv_a=curve.uv_b, pcurve_a=curve.pcurve_b)
    return [replace(p, uv_a=None, pcurve_a=None)
            for p in clip_curve(both, face.region, face.region, tol)]
