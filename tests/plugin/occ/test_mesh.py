"""``face_triangles``: OpenCascade's triangulation as arrays, against exact answers (a box's
faces, a sphere's area and radius), with locations and orientations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeSphere
from OCP.gp import gp_Ax1, gp_Dir, gp_Pln, gp_Pnt, gp_Trsf, gp_Vec
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Face

from surfprep.plugin.occ.mesh import face_triangles
from surfprep.plugin.occ.shapes import all_faces


def _normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 3) right-hand normals, as long as twice the triangles' areas."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return np.cross(b - a, c - a)


def _area(vertices: np.ndarray, triangles: np.ndarray) -> float:
    return float(np.linalg.norm(_normals(vertices, triangles), axis=1).sum() / 2)


def test_a_box_face_is_two_triangles_of_its_exact_area_with_normals_out():
    size = np.array([10.0, 20.0, 30.0])
    box = BRepPrimAPI_MakeBox(*size).Shape()
    faces = all_faces(box)
    meshes = face_triangles(faces, deflection=0.1)
    assert len(meshes) == 6
    centre = size / 2
    areas = []
    for (vertices, triangles), face in zip(meshes, faces, strict=True):
        assert vertices.shape == (4, 3) and triangles.shape == (2, 3)
        assert vertices.dtype == float and triangles.dtype.kind == "i"
        # the four corners of the face: each coordinate 0 or the box's size
        assert np.all((vertices == 0) | (vertices == size))
        areas.append(_area(vertices, triangles))
        # wound by the face's orientation in the solid: every normal points out of the box
        normals = _normals(vertices, triangles)
        outward = vertices[triangles].mean(axis=1) - centre
        assert np.all(np.einsum("ij,ij->i", normals, outward) > 0), face.Orientation()
    assert sorted(areas) == [200.0, 200.0, 300.0, 300.0, 600.0, 600.0]
    # the box has faces of both orientations, so both windings were exercised
    assert any(f.Orientation() == TopAbs_REVERSED for f in faces)
    assert any(f.Orientation() != TopAbs_REVERSED for f in faces)


def test_a_reversed_face_has_its_triangles_flipped():
    face = all_faces(BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape())[1]
    flipped = TopoDS.Face_s(face.Reversed())
    (v1, t1), (v2, t2) = face_triangles([face, flipped], deflection=0.1)
    np.testing.assert_array_equal(v1, v2)
    n1, n2 = _normals(v1, t1), _normals(v2, t2)
    np.testing.assert_array_equal(n2, -n1)


@pytest.mark.parametrize("deflection", [0.1, 0.01])
def test_a_sphere_within_the_deflection_bound(deflection):
    r = 10.0
    (vertices, triangles), = face_triangles(all_faces(BRepPrimAPI_MakeSphere(r).Shape()),
                                            deflection=deflection)
    assert len(triangles) > 500
    # every node on the sphere (to rounding; well within the deflection)
    assert np.abs(np.linalg.norm(vertices, axis=1) - r).max() < 1e-12 * r
    # a closed polyhedron with its nodes on the sphere and within `deflection` of it lies
    # between the spheres of radius r - deflection and r: its area between their areas
    area = _area(vertices, triangles)
    assert 4 * math.pi * (r - deflection) ** 2 <= area <= 4 * math.pi * r ** 2
    # normals out of the sphere (the two degenerate triangles at the poles have none)
    normals = _normals(vertices, triangles)
    real = np.linalg.norm(normals, axis=1) > 1e-12 * r ** 2
    assert (~real).sum() <= 4
    assert np.all(np.einsum("ij,ij->i", normals[real], vertices[triangles[real]].mean(axis=1)) > 0)


def test_the_face_location_is_applied():
    face = all_faces(BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape())[5]
    trsf = gp_Trsf()
    trsf.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.pi / 2)
    move = gp_Trsf()
    move.SetTranslation(gp_Vec(1e6, -3.0, 7.0))
    trsf = move.Multiplied(trsf)
    moved = TopoDS.Face_s(face.Moved(TopLoc_Location(trsf)))
    (v0, t0), (v1, t1) = face_triangles([face, moved], deflection=0.1)
    # rotation by 90 degrees about z, then the translation: (x, y, z) -> (-y + 1e6, x - 3, z + 7)
    expected = np.column_stack([-v0[:, 1] + 1e6, v0[:, 0] - 3.0, v0[:, 2] + 7.0])
    np.testing.assert_allclose(v1, expected, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(t1, t0)
    np.testing.assert_allclose(_area(v1, t1), _area(v0, t0))


def test_a_face_without_triangulation_gives_empty_arrays_not_an_exception():
    infinite = BRepBuilderAPI_MakeFace(gp_Pln()).Face()             # no bounds: cannot be meshed
    box_face = all_faces(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape())[0]
    (v0, t0), (v1, t1), (v2, t2) = face_triangles([infinite, box_face, TopoDS_Face()],
                                                  deflection=0.01)
    assert v0.shape == (0, 3) and t0.shape == (0, 3)
    assert v2.shape == (0, 3) and t2.shape == (0, 3)               # a null face too
    assert t1.shape == (2, 3) and _area(v1, t1) == pytest.approx(1.0)


def test_no_faces_no_meshes():
    assert face_triangles([], deflection=0.1) == []


@pytest.mark.parametrize("kwargs", [{"deflection": 0.0}, {"deflection": -1.0},
                                    {"deflection": float("nan")}, {"deflection": 0.1, "angle": 0.0},
                                    {"deflection": "0.1"}])
def test_bad_tolerances_are_refused(kwargs):
    face = all_faces(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape())[0]
    with pytest.raises(ValueError, match="positive finite"):
        face_triangles([face], **kwargs)


def test_a_shape_that_is_not_a_face_is_refused():
    box = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape()
    with pytest.raises(TypeError, match="item 0 .*not a TopoDS_Face"):
        face_triangles([box], deflection=0.1)
