"""STL triangulations in and out: :func:`read_stl`, :func:`write_stl`.

STL (stereolithography) is the discrete geometry most tools export: a list of
triangles, each three corner points and a normal, no shared vertices, no units.
Binary files hold an 80-byte header, a little-endian ``uint32`` triangle count
and 50 bytes a triangle (normal and three corners as 12 ``float32``, a ``uint16``
attribute); ASCII files hold ``facet normal ... outer loop vertex x y z ...``.
:func:`read_stl` tells them apart by the binary size rule (84 + 50 m bytes),
reads either in bulk and merges bitwise-equal corners into one vertex
(:meth:`~surfprep.algorithms.intersection.TriangleMesh.from_arrays`), so the
mesh is indexed, as the intersection and healing algorithms take it.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...atomic_files import atomic_output
from ...errors import InputFileError
from ..intersection.mesh import TriangleMesh, collinear_mask

__all__ = ["read_stl", "triangles_with_area", "write_stl"]

_RECORD = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


def read_stl(path: str | os.PathLike) -> TriangleMesh:
    """The triangles of an STL file (binary or ASCII) as an indexed mesh.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    TriangleMesh
        Corners that are bitwise equal in the file are one vertex; no ``uv``.
        Triangles of zero area (at a pole of a sphere, say) are left out with a
        warning that counts them.

    Raises
    ------
    InputFileError
        The file is missing, empty, not STL, truncated, holds no triangle, or
        holds a coordinate that is not a finite number.
    """
    file = Path(path)
    try:
        data = file.read_bytes()
    except OSError as exc:
        raise InputFileError(f"cannot read STL file {file}: {exc.strerror or exc}") from None
    if not data:
        raise InputFileError(f"STL file {file} is empty (0 bytes)")
    count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    if count >= 0 and len(data) == 84 + 50 * count:
        corners = np.frombuffer(data, dtype=_RECORD, count=count, offset=84)["corners"]
    elif data.lstrip()[:5].lower() == b"solid":
        values = _VERTEX.findall(data)
        if len(values) % 3:
            raise InputFileError(f"STL file {file} is truncated: {len(values)} vertices, not "
                                 "three a facet")
        try:
            corners = np.array(values, dtype=float).reshape(-1, 3, 3)
        except ValueError:
            raise InputFileError(f"STL file {file} holds a vertex that is not three numbers") \
                from None
    else:
        raise InputFileError(f"{file} is not an STL file (neither the binary size 84 + 50 m "
                             "bytes nor an ASCII 'solid')")
    if corners.shape[0] == 0:
        raise InputFileError(f"STL file {file} holds no triangle")
    corners = np.asarray(corners, dtype=float)
    if not np.all(np.isfinite(corners)):
        raise InputFileError(f"STL file {file} holds a coordinate that is not a finite number")
    return TriangleMesh.from_arrays(corners[triangles_with_area(corners, file, "STL")])


def triangles_with_area(corners: NDArray, file: Path, kind: str) -> NDArray:
    """Mask ``(m,)`` of the triangles ``corners (m, 3, 3)`` of a ``kind`` file that have an
    area; the others are counted in a warning (they are left out), and a file without any
    is refused (:class:`InputFileError`)."""
    flat = collinear_mask(corners)
    if flat.all():
        raise InputFileError(f"{kind} file {file} holds only triangles of zero area")
    if flat.any():
        warnings.warn(f"{file.name}: {int(flat.sum())} of {flat.size} triangles have zero area "
                      "(coincident or collinear corners) and are left out", stacklevel=3)
    return ~flat


def write_stl(mesh: TriangleMesh, path: str | os.PathLike) -> Path:
    """Write ``mesh`` as a binary STL file, atomically; its path.

    Normals are the triangles' right-hand normals (zero for a degenerate one);
    coordinates become ``float32``, as the format holds them.
    """
    corners = mesh.triangle_points()
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    records = np.zeros(corners.shape[0], dtype=_RECORD)
    records["normal"] = np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)
    records["corners"] = corners
    header = b"surfprep binary STL".ljust(80, b" ")
    with atomic_output(path) as tmp:
        tmp.write_bytes(header + np.uint32(corners.shape[0]).tobytes() + records.tobytes())
    return Path(path)
