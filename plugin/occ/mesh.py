"""Faces as triangles: OpenCascade's triangulation (``BRepMesh_IncrementalMesh``) read into
numpy arrays in model coordinates.

:func:`face_triangles` meshes all the faces in one ``BRepMesh_IncrementalMesh`` call on a
compound of them and reads each face's ``Poly_Triangulation`` with the face's location
applied and its triangles wound by the face's orientation, so that the right-hand normal
of every triangle points where the face's normal points (out of a solid).

OCP has no bulk accessor for a triangulation's nodes (``Poly_ArrayOfNodes`` exposes
``Value(i)`` only, and cadquery's ``Shape.tessellate`` and ocp-tessellate's Python path
both loop over ``Node(i)``): the nodes and triangles are read with one loop each straight
into ``np.fromiter``, and the location is applied to all nodes at once (about 0.1 s for
100 000 triangles).
"""

from __future__ import annotations

from collections.abc import Iterable
from itertools import chain

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS_Face

from ...errors import OpenCascadeError
from .failures import occ_failures
from .shapes import compound

__all__ = ["face_triangles"]


def face_triangles(faces: Iterable[TopoDS_Face], *, deflection: float,
                   angle: float = 0.5) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each face's triangulation, in model coordinates and wound by its orientation.

    Parameters
    ----------
    faces : iterable of TopoDS_Face
        The faces, each with its own location and orientation.
    deflection : float
        Largest distance between a triangle and its face (absolute, model units), > 0.
    angle : float, optional
        Largest angle in radians between the normals of neighbouring triangles (OpenCascade's
        angular deflection), > 0.

    Returns
    -------
    list of (vertices, triangles)
        One pair per face, in the order given: ``vertices`` (n, 3) float, the nodes with the
        face's location applied; ``triangles`` (m, 3) int, indices into ``vertices``, wound
        so that ``cross(v1 - v0, v2 - v0)`` points along the face's normal as the face is
        oriented (a ``TopAbs_REVERSED`` face has its triangles flipped). A face OpenCascade
        could not triangulate (an infinite plane, a broken face) gives ``(0, 3)`` arrays.

    Raises
    ------
    TypeError
        An item is not a ``TopoDS_Face``.
    ValueError
        ``deflection`` or ``angle`` is not a positive finite number.
    OpenCascadeError
        ``BRepMesh_IncrementalMesh`` raised, or did not finish (``IsDone`` false).

    Notes
    -----
    As any OpenCascade meshing, this stores the triangulation in the faces (shared with the
    caller's shape); a face that already holds a triangulation at least as fine keeps it.
    """
    faces = list(faces)
    for k, face in enumerate(faces):
        if not isinstance(face, TopoDS_Face):
            raise TypeError(f"face_triangles: item {k} is a {type(face).__name__}, not a TopoDS_Face")
    for name, value in (("deflection", deflection), ("angle", angle)):
        if not (isinstance(value, (int, float, np.floating, np.integer)) and np.isfinite(value)
                and value > 0):
            raise ValueError(f"face_triangles: {name} must be a positive finite number, got {value!r}")
    real = [f for f in faces if not f.IsNull()]
    if real:
        with occ_failures(OpenCascadeError, "BRepMesh_IncrementalMesh failed"):
            mesher = BRepMesh_IncrementalMesh(compound(real), float(deflection), False, float(angle), False)
        if not mesher.IsDone():
            raise OpenCascadeError("BRepMesh_IncrementalMesh: IsDone() is false")
    return [_read_triangulation(face) for face in faces]


def _empty() -> tuple[np.ndarray, np.ndarray]:
    return np.empty((0, 3), dtype=float), np.empty((0, 3), dtype=np.int64)


def _read_triangulation(face: TopoDS_Face) -> tuple[np.ndarray, np.ndarray]:
    """The triangulation stored in ``face`` as arrays (see :func:`face_triangles`)."""
    if face.IsNull():
        return _empty()
    location = TopLoc_Location()
    poly = BRep_Tool.Triangulation_s(face, location)
    if poly is None or poly.NbNodes() == 0 or poly.NbTriangles() == 0:
        return _empty()
    n, m = poly.NbNodes(), poly.NbTriangles()
    node, triangle = poly.Node, poly.Triangle
    nodes = np.fromiter(chain.from_iterable(node(i).Coord() for i in range(1, n + 1)),
                        dtype=float, count=3 * n).reshape(n, 3)
    triangles = np.fromiter(chain.from_iterable(triangle(i).Get() for i in range(1, m + 1)),
                            dtype=np.int64, count=3 * m).reshape(m, 3) - 1
    if not location.IsIdentity():
        trsf = location.Transformation()
        matrix = np.array([[trsf.Value(r, c) for c in range(1, 5)] for r in range(1, 4)])
        nodes = nodes @ matrix[:, :3].T + matrix[:, 3]
    if face.Orientation() == TopAbs_REVERSED:
        triangles = triangles[:, [0, 2, 1]]
    if triangles.min() < 0 or triangles.max() >= n:      # a corrupt triangulation: no triangles
        return _empty()
    return nodes, np.ascontiguousarray(triangles)
