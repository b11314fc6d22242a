"""mesh_segments: overlap boxes -> selective tessellation -> trees -> triangle intersection."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import sphere_band

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection.mesh import TriangleMesh
from surfprep.algorithms.intersection.segments import SegmentSoup, mesh_segments
from surfprep.errors import InvalidGeometryError, InvalidToleranceError


def plane(x, y, z=0.0, tilt=(0.0, 0.0)):
    """Bilinear patch over [x0, x1] x [y0, y1] at height z + tilt . (x, y)."""
    cp = np.array([[[xi, yj, z + tilt[0] * xi + tilt[1] * yj] for yj in y] for xi in x], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def vertical_plane(x, y, z):
    """The plane x = const spanned over y and z (x: (x0, x1) may lean)."""
    cp = np.array([[[x[0], y[0], z[0]], [x[1], y[0], z[1]]],
                   [[x[0], y[1], z[0]], [x[1], y[1], z[1]]]], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def chain_length(soup: SegmentSoup) -> float:
    return float(np.linalg.norm(soup.points[:, 1] - soup.points[:, 0], axis=1).sum())


def assert_contract(soup: SegmentSoup):
    k = soup.n_segments
    assert soup.points.shape == (k, 2, 3)
    assert soup.tri_a.shape == (k,) and soup.tri_b.shape == (k,)
    assert soup.bary_a.shape == (k, 2, 3) and soup.end_source.shape == (k, 2)
    for uv, mesh, tri, bary in ((soup.uv_a, soup.mesh_a, soup.tri_a, soup.bary_a),
                                (soup.uv_b, soup.mesh_b, soup.tri_b, soup.bary_b)):
        np.testing.assert_allclose(np.einsum("kec,kcd->ked", bary, mesh.triangle_points()[tri]),
                                   soup.points, atol=1e-12)
        if mesh.uv is not None:
            assert uv.shape == (k, 2, 2)
    # ends with equal combinatorial keys are bitwise equal points
    keys = soup.end_keys().reshape(-1, 4)
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    ends = soup.points.reshape(-1, 3)
    first = np.full(inverse.max() + 1 if k else 0, -1)
    first[inverse[::-1]] = np.arange(ends.shape[0])[::-1]
    np.testing.assert_array_equal(ends, ends[first[inverse]])


def test_plane_plane_on_the_exact_line():
    a = plane((0, 1), (0, 1))
    b = vertical_plane((0.3, 0.5), (-0.5, 1.5), (-1, 1))          # x = 0.4 + 0.1 z
    soup = mesh_segments(a, b, tol=1e-6)
    assert_contract(soup)
    assert soup.mesh_a.n_triangles == 2 and soup.mesh_b.n_triangles == 2
    np.testing.assert_allclose(soup.points[..., 2], 0, atol=1e-15)
    np.testing.assert_allclose(soup.points[..., 0], 0.4, atol=1e-15)
    assert chain_length(soup) == pytest.approx(1.0, abs=1e-14)
    # uv is exact on bilinear patches
    pa = a.evaluate(soup.uv_a[..., 0], soup.uv_a[..., 1])
    pb = b.evaluate(soup.uv_b[..., 0], soup.uv_b[..., 1])
    np.testing.assert_allclose(pa, soup.points, atol=1e-15)
    np.testing.assert_allclose(pb, soup.points, atol=1e-15)


def test_plane_cuts_sphere_in_a_circle():
    h, tol = 0.1, 1e-3
    sphere = sphere_band()
    soup = mesh_segments(plane((-2, 2), (-2, 2), h), sphere, tol=tol)
    assert_contract(soup)
    radius = np.sqrt(1 - h * h)
    np.testing.assert_allclose(soup.points[..., 2], h, atol=1e-15)
    assert np.abs(np.linalg.norm(soup.points[..., :2], axis=-1) - radius).max() <= tol
    assert chain_length(soup) == pytest.approx(2 * np.pi * radius, rel=tol)
    # the (u, v) on the sphere maps back within the tessellation tolerance
    on_sphere = sphere.evaluate(soup.uv_b[..., 0], soup.uv_b[..., 1])
    assert np.abs(on_sphere - soup.points).max() <= tol
    # a closed loop: every end is shared by exactly two segments (the seam u = 0 = 1 of
    # the band has distinct parameters but the same points)
    _, counts = np.unique(soup.points.reshape(-1, 3), axis=0, return_counts=True)
    assert np.all(counts == 2)
    assert soup.touching_points.shape[0] == 0 and soup.coplanar_pairs.shape[0] == 0


def test_work_follows_the_intersection():
    sphere = sphere_band()
    soup = mesh_segments(plane((0.6, 1.5), (-0.3, 0.3), 0.0, tilt=(0.1, 0.0)), sphere, tol=1e-3)
    assert soup.stats.patches_b == 4 and soup.stats.tessellated_b < 4
    assert soup.n_segments > 0
    full = mesh_segments(plane((-2, 2), (-2, 2), 0.0), sphere, tol=1e-3)
    assert soup.mesh_b.n_triangles < full.mesh_b.n_triangles


def test_far_apart_surfaces_do_no_work():
    soup = mesh_segments(sphere_band(), sphere_band(centre=(5, 0, 0)), tol=1e-3)
    assert soup.n_segments == 0
    assert soup.mesh_a.n_triangles == 0 and soup.mesh_b.n_triangles == 0
    assert soup.stats.overlap_pairs == 0 and soup.stats.candidate_pairs == 0
    assert soup.stats.tessellated_a == 0 and soup.stats.tessellated_b == 0
    assert soup.uv_a.shape == (0, 2, 2)


def test_mesh_operands():
    """A plain triangle mesh as an operand (no uv), against a surface and a mesh."""
    h = 0.2
    square = np.array([[-2, -2, h], [2, -2, h], [2, 2, h], [-2, 2, h]], float)
    mesh = TriangleMesh.from_arrays(square, [[0, 1, 2], [0, 2, 3]])
    sphere = sphere_band()
    soup = mesh_segments(sphere, mesh, tol=1e-3)
    assert soup.uv_b is None and soup.uv_a.shape == (soup.n_segments, 2, 2)
    assert soup.mesh_b is mesh
    radius = np.sqrt(1 - h * h)
    assert np.abs(np.linalg.norm(soup.points[..., :2], axis=-1) - radius).max() <= 1e-3
    assert_contract(soup)
    both = mesh_segments(soup.mesh_a, mesh, tol=1e-3)
    np.testing.assert_array_equal(both.points, soup.points)


def test_coplanar_and_touching_are_reported():
    a = plane((0, 1), (0, 1))
    coplanar = mesh_segments(a, plane((0.5, 2), (0.5, 2)), tol=1e-3)
    assert coplanar.n_segments == 0 and coplanar.coplanar_pairs.shape[0] > 0
    # a tilted plane resting on the corner (1, 1, 0) of a
    corner = TriangleMesh.from_arrays(np.array([[[1, 1, 0], [2, 1, 1], [1, 2, 1]]], float))
    touch = mesh_segments(a, corner, tol=1e-3)
    assert touch.n_segments == 0
    np.testing.assert_array_equal(np.unique(touch.touching_points, axis=0), [[1, 1, 0]])
    np.testing.assert_array_equal(touch.touching_uv_a[0], [1, 1])
    assert touch.touching_uv_b is None


@pytest.mark.parametrize("tol", [0, -1e-3, np.nan])
def test_bad_tolerance(tol):
    with pytest.raises(InvalidToleranceError):
        mesh_segments(plane((0, 1), (0, 1)), plane((0, 1), (0, 1)), tol=tol)


def test_bad_operand():
    with pytest.raises(InvalidGeometryError, match="NurbsSurface or a TriangleMesh"):
        mesh_segments(plane((0, 1), (0, 1)), np.zeros((3, 3)), tol=1e-3)


def full_intersection(a, b, tol):
    """Reference: whole tessellations of both surfaces, all overlapping triangle pairs."""
    from surfprep.algorithms.intersection.culling import candidate_pairs
    from surfprep.algorithms.intersection.tessellation import tessellate
    from surfprep.algorithms.intersection.triangles import intersect_triangles
    ma, mb = tessellate(a, tol).mesh, tessellate(b, tol).mesh
    pairs = candidate_pairs(ma.triangle_boxes(), mb.triangle_boxes())
    hits = intersect_triangles(ma.triangle_points()[pairs[:, 0]], mb.triangle_points()[pairs[:, 1]])
    return hits.segments, ma, mb


def sorted_rows(x):
    x = x.reshape(x.shape[0], -1)
    return x[np.lexsort(x.T[::-1])]


def test_pruned_refinement_finds_the_same_segments():
    """Pruning the refinement by overlap boxes and by the other mesh loses nothing:
    the segments equal those of the full tessellations."""
    a, b = sphere_band(), sphere_band(centre=(1.2, 0.3, 0.1))
    soup = mesh_segments(a, b, tol=2e-3)
    reference, ma, mb = full_intersection(a, b, 2e-3)
    np.testing.assert_array_equal(sorted_rows(soup.points), sorted_rows(reference))
    assert soup.mesh_a.n_triangles < ma.n_triangles / 2
    assert soup.mesh_b.n_triangles < mb.n_triangles / 4
    assert_contract(soup)
    # both spheres: the ends lie on both within the tolerance
    for surface, uv in ((a, soup.uv_a), (b, soup.uv_b)):
        assert np.abs(surface.evaluate(uv[..., 0], uv[..., 1]) - soup.points).max() <= 2e-3


def test_candidate_pairs_of_the_soup_are_the_brute_force_ones():
    from surfprep.algorithms.intersection.culling import candidate_pairs
    soup = mesh_segments(sphere_band(), sphere_band(centre=(1.2, 0.3, 0.1)), tol=2e-3)
    ba, bb = soup.mesh_a.triangle_boxes(), soup.mesh_b.triangle_boxes()
    hit = np.all((ba[:, None, 0] <= bb[None, :, 1]) & (bb[None, :, 0] <= ba[:, None, 1]), axis=-1)
    np.testing.assert_array_equal(candidate_pairs(ba, bb), np.argwhere(hit))
    assert soup.stats.candidate_pairs == int(hit.sum())
    # every segment's pair is a candidate
    assert np.all(hit[soup.tri_a, soup.tri_b])


def test_touching_points_that_are_segment_ends_are_told_apart():
    """_not_segment_ends: a touching point bitwise equal to a segment end (a signed
    zero counts as zero) is one; one off by an ulp is not; empty inputs keep all."""
    from surfprep.algorithms.intersection.segments import _not_segment_ends
    ends = np.array([[0.0, 1.0, 2.0], [0.5, -0.25, 3.0], [1.0, 1.0, 1.0]])
    touch = np.array([[0.5, -0.25, 3.0], [-0.0, 1.0, 2.0], [np.nextafter(1.0, 2.0), 1.0, 1.0],
                      [7.0, 8.0, 9.0]])
    np.testing.assert_array_equal(_not_segment_ends(touch, ends), [False, False, True, True])
    np.testing.assert_array_equal(_not_segment_ends(touch, np.zeros((0, 3))), [True] * 4)
    assert _not_segment_ends(np.zeros((0, 3)), ends).shape == (0,)
