"""A triangle mesh (STL) against exact faces: surfprep.intersect and ``surfprep intersect
mesh.stl part.step``. The mesh is OpenCascade's triangulation of a sphere of radius 10
(a mesh exported from a known surface); the faces are the 1 mm slab at z = 4.5..5.5.
The answer: two circles in the planes z = 4.5 and z = 5.5 (the exact side: within tol)
whose radii are those of the sphere's circles less at most the mesh's own deviation
(its chords run inside the sphere)."""

from __future__ import annotations

import json

import cadquery as cq
import numpy as np
import pytest
from helpers.cli import run

import surfprep
from surfprep.algorithms.intersection import TriangleMesh
from surfprep.algorithms.io import write_stl
from surfprep.plugin.intersect.mesh_operand import MeshIntersectionResult
from surfprep.plugin.occ.mesh import face_triangles
from surfprep.plugin.occ.shapes import all_faces

RADIUS, DEFLECTION = 10.0, 0.01


@pytest.fixture(scope="module")
def sphere_stl(tmp_path_factory):
    sphere = cq.Workplane().sphere(RADIUS).val().wrapped
    parts = face_triangles(all_faces(sphere), deflection=DEFLECTION)
    corners = np.concatenate([v[t] for v, t in parts])
    area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                          axis=1)
    path = tmp_path_factory.mktemp("mesh") / "sphere.stl"
    write_stl(TriangleMesh.from_arrays(corners[area > 0]), path)
    return path


@pytest.fixture(scope="module")
def slab():
    return cq.Workplane().box(30, 30, 1).translate((0, 0, 5))


def test_the_mesh_meets_the_slab_in_two_circles(sphere_stl, slab):
    result = surfprep.intersect(sphere_stl, slab)
    assert isinstance(result, MeshIntersectionResult) and len(result) == 2
    for curve in sorted(result, key=lambda c: c.points[0, 2]):
        z = curve.points[0, 2]
        assert z in (pytest.approx(4.5, abs=1e-9), pytest.approx(5.5, abs=1e-9))
        assert np.max(np.abs(curve.points[:, 2] - z)) <= result.tol       # on the exact face
        assert curve.distance_to_face() <= result.tol                     # between samples too
        radius = np.linalg.norm(curve.points[:, :2], axis=1)
        exact = np.sqrt(RADIUS ** 2 - z ** 2)
        assert np.all(radius <= exact + 1e-6)                 # chords run inside the sphere
        assert np.all(radius >= exact - 2 * DEFLECTION)       # by the mesh's own deviation
        assert curve.closed
    assert len(result.edges()) == 2


def test_the_order_of_the_operands_does_not_matter(sphere_stl, slab):
    a, b = surfprep.intersect(sphere_stl, slab), surfprep.intersect(slab, str(sphere_stl))
    assert sorted(round(c.length, 9) for c in a) == sorted(round(c.length, 9) for c in b)


def test_a_mesh_needs_exact_faces_beside_it(sphere_stl):
    with pytest.raises(surfprep.InvalidGeometryError, match="one mesh and one model"):
        surfprep.intersect(sphere_stl)
    with pytest.raises(surfprep.InvalidGeometryError, match="one mesh and one model"):
        surfprep.intersect(sphere_stl, sphere_stl)


def test_the_command_line_takes_an_stl_file(sphere_stl, slab, tmp_path, capsys):
    step, out, report = tmp_path / "slab.step", tmp_path / "curves.step", tmp_path / "r.json"
    surfprep.write(slab, step)
    code, stdout, err = run(capsys, "intersect", sphere_stl, step, "-o", out, "--json", report)
    assert code == 0, err
    assert "2 intersection curve(s) of the mesh" in stdout
    data = json.loads(report.read_text())
    assert data["n_curves"] == 2 and data["mesh"]["triangles"] > 1000
    assert all(c["closed"] and c["distance_to_face"] <= data["tol"] for c in data["curves"])
    assert surfprep.read(out, require_faces=False).shape is not None
    code, _, err = run(capsys, "intersect", sphere_stl, "-o", tmp_path / "x.step")
    assert code == 2 and "give one of each" in err


def test_a_plot3d_surface_grid_is_a_mesh_operand(slab, tmp_path, capsys):
    """A structured grid of the sphere (two blocks: the upper and lower halves, 61 x 121
    nodes, collapsed at the poles) written as Plot3D, against the slab: the same two circles,
    within the grid's own chordal deviation."""
    from surfprep.algorithms.grid.io import write_plot3d
    theta = np.linspace(0.0, 2.0 * np.pi, 121)
    blocks = []
    for lat in (np.linspace(0.0, np.pi / 2, 61), np.linspace(-np.pi / 2, 0.0, 61)):
        la, th = np.meshgrid(lat, theta, indexing="ij")
        blocks.append(RADIUS * np.stack([np.cos(la) * np.cos(th), np.cos(la) * np.sin(th),
                                         np.sin(la)], axis=-1))
    path = write_plot3d(tmp_path / "sphere.xyz", blocks)
    result = surfprep.intersect(path, slab)
    assert len(result) == 2 and set(result.mesh.patch.tolist()) == {0, 1}
    sag = RADIUS * (1 - np.cos(np.pi / 120))               # a cell's chord below the arc
    for curve in result:
        z = curve.points[0, 2]
        assert np.max(np.abs(curve.points[:, 2] - z)) <= result.tol
        radius = np.linalg.norm(curve.points[:, :2], axis=1)
        exact = np.sqrt(RADIUS ** 2 - z ** 2)
        assert np.all(radius <= exact + 1e-6) and np.all(radius >= exact - 2 * sag)
    step = tmp_path / "slab.step"
    surfprep.write(slab, step)
    code, stdout, err = run(capsys, "intersect", path, step, "-o", tmp_path / "c.step")
    assert code == 0 and "2 intersection curve(s) of the mesh" in stdout, err


def test_an_obj_file_is_the_same_mesh(sphere_stl, slab, tmp_path):
    """The sphere's mesh written as Wavefront OBJ (full precision) gives the STL's curves."""
    from surfprep.algorithms.io import read_stl
    mesh = read_stl(sphere_stl)
    path = tmp_path / "sphere.obj"
    path.write_text("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in mesh.vertices)
                    + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in mesh.triangles))
    from_obj, from_stl = surfprep.intersect(path, slab), surfprep.intersect(sphere_stl, slab)
    assert len(from_obj) == len(from_stl) == 2
    assert sorted(round(c.length, 9) for c in from_obj) == \
        sorted(round(c.length, 9) for c in from_stl)
