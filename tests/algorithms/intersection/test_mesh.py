"""TriangleMesh: validation, building from plain arrays, geometry and edge counts."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.intersection.mesh import TriangleMesh, collinear_mask
from surfprep.errors import DegenerateGeometryError, InvalidGeometryError

SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
TWO = np.array([[0, 1, 2], [0, 2, 3]])


def test_square_geometry():
    mesh = TriangleMesh(SQUARE, TWO, uv=SQUARE[:, :2], patch=[7, 7])
    np.testing.assert_allclose(mesh.areas(), [0.5, 0.5])
    np.testing.assert_allclose(mesh.normals(), [[0, 0, 1], [0, 0, 1]])
    boxes = mesh.triangle_boxes()
    assert boxes.shape == (2, 2, 3)
    np.testing.assert_array_equal(boxes[0], [[0, 0, 0], [1, 1, 0]])
    edges, counts = mesh.edges()
    assert edges.shape == (5, 2) and counts.tolist().count(2) == 1
    assert mesh.boundary_edges().shape == (4, 2)
    np.testing.assert_array_equal(mesh.triangle_uv()[1], SQUARE[[0, 2, 3], :2])
    assert mesh.n_vertices == 4 and mesh.n_triangles == 2
    assert "4 vertices" in repr(mesh)


def test_arrays_are_copied_and_read_only():
    v = SQUARE.copy()
    mesh = TriangleMesh(v, TWO)
    v[0, 0] = 5.0
    assert mesh.vertices[0, 0] == 0.0
    with pytest.raises(ValueError):
        mesh.vertices[0, 0] = 1.0
    assert mesh.triangles.dtype == np.int64


@pytest.mark.parametrize("vertices, triangles, kwargs, error, match", [
    (SQUARE[:, :2], TWO, {}, InvalidGeometryError, "vertices must have shape"),
    (np.where(SQUARE == 1, np.nan, SQUARE), TWO, {}, InvalidGeometryError, "NaN"),
    (SQUARE, [[0, 1, 4]], {}, InvalidGeometryError, "outside"),
    (SQUARE, [[0, 1, -1]], {}, InvalidGeometryError, "outside"),
    (SQUARE, [[0, 1]], {}, InvalidGeometryError, "triangles must have shape"),
    (SQUARE, [[0, 1, 1.5]], {}, InvalidGeometryError, "integer"),
    (SQUARE, TWO, {"uv": np.zeros((3, 2))}, InvalidGeometryError, "uv must have shape"),
    (SQUARE, TWO, {"uv": np.full((4, 2), np.inf)}, InvalidGeometryError, "uv contains"),
    (SQUARE, TWO, {"patch": [1]}, InvalidGeometryError, "patch must have shape"),
    (SQUARE, [[0, 1, 1]], {}, DegenerateGeometryError, "repeats"),
    (np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2.0]]), [[0, 1, 2]], {}, DegenerateGeometryError,
     "zero area"),
    (np.array([[0, 0, 0], [1, 1, 1], [0, 0, 0.0]]), [[0, 1, 2]], {}, DegenerateGeometryError,
     "zero area"),
])
def test_validation(vertices, triangles, kwargs, error, match):
    with pytest.raises(error, match=match):
        TriangleMesh(vertices, triangles, **kwargs)


def test_degenerate_error_is_an_invalid_geometry_error():
    with pytest.raises(InvalidGeometryError):
        TriangleMesh(SQUARE, [[0, 0, 1]])


def test_from_soup_merges_equal_corners():
    soup = SQUARE[TWO]                                  # (2, 3, 3) corners
    mesh = TriangleMesh.from_arrays(soup)
    assert mesh.n_vertices == 4 and mesh.n_triangles == 2
    np.testing.assert_array_equal(mesh.triangle_points(), soup)
    _, counts = mesh.edges()
    assert sorted(counts.tolist()) == [1, 1, 1, 1, 2]
    assert mesh.uv is None


def test_from_arrays_drops_unused_vertices_and_keeps_uv():
    v = np.concatenate([SQUARE, [[9, 9, 9]]])
    uv = np.arange(10.0).reshape(5, 2)
    mesh = TriangleMesh.from_arrays(v, [[4 - 4, 1, 2]], uv=uv)
    assert mesh.n_vertices == 3
    np.testing.assert_array_equal(mesh.uv, uv[:3])
    np.testing.assert_array_equal(mesh.triangle_points()[0], SQUARE[:3])


def test_from_arrays_errors():
    with pytest.raises(InvalidGeometryError, match="soup"):
        TriangleMesh.from_arrays(SQUARE)
    with pytest.raises(InvalidGeometryError, match="uv needs"):
        TriangleMesh.from_arrays(SQUARE[TWO], uv=np.zeros((4, 2)))


def test_empty_mesh():
    mesh = TriangleMesh(np.zeros((0, 3)), np.zeros((0, 3), int))
    assert mesh.triangle_boxes().shape == (0, 2, 3)
    assert mesh.bounding_box().shape == (2, 3)


def test_collinear_mask_scale_invariant():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [1, 1e-17, 0], [2, 0, 0]]])
    for scale in (1e-6, 1.0, 1e6):
        np.testing.assert_array_equal(collinear_mask(tri * scale), [False, True])


def test_collinear_mask_equals_the_reduction_form():
    """collinear_mask sums and compares column by column; the same decisions as the
    reductions it replaced, on random, sliver and coincident-corner triangles."""
    rng = np.random.default_rng(5)
    pts = rng.normal(size=(400, 3, 3))
    pts[:100, 2] = 0.5 * (pts[:100, 0] + pts[:100, 1])              # collinear
    pts[100:150, 2] = pts[100:150, 0] * (1 + 1e-14)                 # coincident to rounding
    pts[150:200, 2] = pts[150:200, 1] + 1e-13 * rng.normal(size=(50, 3))   # near slivers
    edges = pts[:, [1, 2, 0]] - pts
    longest2 = np.max(np.sum(edges * edges, axis=2), axis=1)
    cross = np.linalg.norm(np.cross(edges[:, 0], -edges[:, 2]), axis=1)
    expected = cross <= 64 * np.finfo(float).eps * longest2
    assert expected[:150].all() and not expected[200:].any()
    np.testing.assert_array_equal(collinear_mask(pts), expected)


def test_from_checked_mesh_is_the_validated_one():
    """A tessellation's mesh comes through TriangleMesh.from_checked: the same arrays,
    read-only, that full validation accepts."""
    from surfprep.algorithms.intersection.tessellation import tessellate
    from surfprep.algorithms.surface import NurbsSurface
    x = np.linspace(0, 1, 5)
    u, v = np.meshgrid(x, x, indexing="ij")
    z = 0.3 * np.sin(3 * u) * np.cos(2 * v)
    knots = [0, 0, 0, 0, 0.5, 1, 1, 1, 1]
    mesh = tessellate(NurbsSurface(np.stack([u, v, z], -1), knots, knots, 3, 3), 1e-3).mesh
    checked = TriangleMesh(mesh.vertices, mesh.triangles, mesh.uv, mesh.patch)
    for name in ("vertices", "triangles", "uv", "patch"):
        mine, full = getattr(mesh, name), getattr(checked, name)
        np.testing.assert_array_equal(mine, full)
        assert mine.dtype == full.dtype and not mine.flags.writeable
    assert not mesh.degenerate_triangles().any()


def test_structured_grids_become_one_mesh():
    """A flat 3 x 4 grid (6 cells) and a fan collapsed at one side: two triangles a cell,
    the area exact, the collapsed cells' flat triangles left out, the block in ``patch``."""
    x, y = np.meshgrid([0.0, 1.0, 3.0], [0.0, 1.0, 2.0, 4.0], indexing="ij")
    flat = np.stack([x, y, np.zeros_like(x)], axis=-1)
    fan = flat.copy()
    fan[0] = 0.0                                          # the first row collapsed to a point
    mesh = TriangleMesh.from_grids([flat, fan])
    corners = mesh.triangle_points()
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                         corners[:, 2] - corners[:, 0]), axis=1)
    first = mesh.patch == 0
    assert first.sum() == 12 and area[first].sum() == pytest.approx(12.0)
    assert (~first).sum() == 12 - 3 and area[~first].sum() == pytest.approx(
        12.0 - 1.0 * 4.0 + 0.5 * 1.0 * 4.0)               # the first column of cells a triangle
    with pytest.raises(InvalidGeometryError, match="shape"):
        TriangleMesh.from_grids([np.zeros((1, 4, 3))])
