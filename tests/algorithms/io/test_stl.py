"""STL in and out: binary and ASCII, vertices merged, zero-area triangles left out with a
word, and every kind of bad file refused with a clear error."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from surfprep.algorithms.intersection import TriangleMesh
from surfprep.algorithms.io import read_stl, write_stl
from surfprep.errors import InputFileError

#: a tetrahedron: 4 vertices, 4 triangles
CORNERS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
FACES = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])

ASCII = """solid tetra
""" + "".join(
    "  facet normal 0 0 0\n    outer loop\n"
    + "".join(f"      vertex {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in CORNERS[f])
    + "    endloop\n  endfacet\n" for f in FACES) + "endsolid tetra\n"


def test_binary_round_trip(tmp_path):
    mesh = TriangleMesh.from_arrays(CORNERS, FACES)
    path = write_stl(mesh, tmp_path / "t.stl")
    assert path.stat().st_size == 84 + 50 * 4              # the binary size rule
    back = read_stl(path)
    assert back.n_vertices == 4 and back.n_triangles == 4   # shared corners merged
    assert np.array_equal(np.sort(back.triangle_points().reshape(-1, 3), axis=0),
                          np.sort(mesh.triangle_points().reshape(-1, 3), axis=0))


def test_ascii_file(tmp_path):
    path = tmp_path / "t.stl"
    path.write_text(ASCII)
    mesh = read_stl(path)
    assert mesh.n_vertices == 4 and mesh.n_triangles == 4
    assert {tuple(p) for p in mesh.vertices} == {tuple(p) for p in CORNERS}


def test_zero_area_triangles_are_left_out_with_a_word(tmp_path):
    path = tmp_path / "t.stl"
    flat = "  facet normal 0 0 0\n    outer loop\n" + "      vertex 0 0 0\n" * 3 + \
           "    endloop\n  endfacet\n"
    path.write_text(ASCII.replace("endsolid", flat + "endsolid"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = read_stl(path)
    assert mesh.n_triangles == 4
    assert any("1 of 5 triangles have zero area" in str(w.message) for w in caught)


@pytest.mark.parametrize("content, words", [
    (b"", "empty"),
    (b"hello world, not a mesh", "not an STL file"),
    (ASCII.rsplit("vertex", 1)[0].encode(), "truncated"),
    (ASCII.replace("vertex 1 0 0", "vertex nan 0 0", 1).encode(), "not a finite number"),
    (b"solid empty\nendsolid empty\n", "no triangle"),
])
def test_bad_files_are_refused(tmp_path, content, words):
    path = tmp_path / "bad.stl"
    path.write_bytes(content)
    with pytest.raises(InputFileError, match=words):
        read_stl(path)


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(InputFileError, match="cannot read"):
        read_stl(tmp_path / "missing.stl")

