"""Wavefront OBJ triangulations in: :func:`read_obj`.

OBJ is text: ``v x y z [w]`` lines give the vertices (1-based, in order; a
negative index counts back from the last vertex read), ``f a b c ...`` lines give
the faces, each index possibly followed by ``/texture/normal`` indices (ignored
here). Polygons with more than three corners are cut into a fan from their first
corner; every other record (normals, texture coordinates, groups, materials) is
left aside.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ...errors import InputFileError
from ..intersection.mesh import TriangleMesh
from .stl import triangles_with_area

__all__ = ["read_obj"]


def read_obj(path: str | os.PathLike) -> TriangleMesh:
    """The faces of a Wavefront OBJ file as an indexed triangle mesh.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    TriangleMesh
        The file's vertices (unused ones dropped), polygons cut into fans; faces of
        zero area are left out with a warning that counts them.

    Raises
    ------
    InputFileError
        Missing or unreadable, no vertex or no face, a vertex that is not three finite
        numbers, or a face index out of range.
    """
    file = Path(path)
    try:
        text = file.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise InputFileError(f"cannot read OBJ file {file}: {exc.strerror or exc}") from None
    vertices: list[list[float]] = []
    triangles: list[tuple[int, int, int]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split()
        if not words:
            continue
        if words[0] == "v":
            try:
                vertices.append([float(w) for w in words[1:4]])
            except ValueError:
                raise InputFileError(f"OBJ file {file}, line {number}: a vertex that is not "
                                     "numbers") from None
            if len(vertices[-1]) != 3:
                raise InputFileError(f"OBJ file {file}, line {number}: a vertex needs x y z")
        elif words[0] == "f":
            try:
                ids = [int(w.split("/")[0]) for w in words[1:]]
            except ValueError:
                raise InputFileError(f"OBJ file {file}, line {number}: a face index that is "
                                     "not an integer") from None
            if len(ids) < 3:
                raise InputFileError(f"OBJ file {file}, line {number}: a face needs three "
                                     "corners")
            ids = [i - 1 if i > 0 else len(vertices) + i for i in ids]
            triangles += [(ids[0], ids[k], ids[k + 1]) for k in range(1, len(ids) - 1)]
    if not vertices or not triangles:
        raise InputFileError(f"OBJ file {file} holds no {'vertex' if not vertices else 'face'}")
    points = np.asarray(vertices, dtype=float)
    tri = np.asarray(triangles, dtype=np.int64)
    if not np.all(np.isfinite(points)):
        raise InputFileError(f"OBJ file {file} holds a coordinate that is not a finite number")
    if tri.min() < 0 or tri.max() >= len(points):
        raise InputFileError(f"OBJ file {file} has a face index out of range 1..{len(points)}")
    return TriangleMesh.from_arrays(points, tri[triangles_with_area(points[tri], file, "OBJ")])
