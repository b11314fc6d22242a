"""Wavefront OBJ in: polygons as fans, negative indices, bad files refused."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.errors import InputFileError


def test_an_obj_file_is_read_with_its_polygons_as_fans(tmp_path):
    """A unit cube as six quads with texture and normal indices, and one face by negative
    indices: 12 triangles, 8 vertices, area 6."""
    from surfprep.algorithms.io import read_obj
    text = "# cube\no cube\n" + "".join(f"v {x} {y} {z}\n" for x in (0, 1) for y in (0, 1)
                                         for z in (0, 1))
    text += "vt 0 0\nvn 0 0 1\n"
    quads = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3)]
    text += "".join("f " + " ".join(f"{i}/1/1" for i in q) + "\n" for q in quads)
    text += "f -7 -3 -1 -5\n"                              # (2, 6, 8, 4) counted from the end
    path = tmp_path / "cube.obj"
    path.write_text(text)
    mesh = read_obj(path)
    corners = mesh.triangle_points()
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                         corners[:, 2] - corners[:, 0]), axis=1)
    assert mesh.n_vertices == 8 and mesh.n_triangles == 12
    assert area.sum() == pytest.approx(6.0)


@pytest.mark.parametrize("text, words", [
    ("", "no vertex"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no face"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "out of range"),
    ("v 0 zero 0\n", "not numbers"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "three corners"),
])
def test_bad_obj_files_are_refused(tmp_path, text, words):
    from surfprep.algorithms.io import read_obj
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(InputFileError, match=words):
        read_obj(path)
