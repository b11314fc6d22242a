"""Adaptive tessellation: tolerance met densely, watertight, unique vertices, adaptivity."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import sphere_band
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection.tessellation import Tessellation, patch_rectangles, tessellate
from surfprep.errors import InvalidGeometryError, InvalidToleranceError

R2 = np.sqrt(0.5)


# ------------------------------------------------------------ test surfaces
def plane_patch():
    cp = np.array([[[0, 0, 0], [0, 2, 0]], [[3, 0, 1], [3, 2, 1]]], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def bump():
    """Bicubic Bézier patch over [0, 1]^2 with a raised middle."""
    g = np.linspace(0, 1, 4)
    cp = np.stack([*np.meshgrid(g, g, indexing="ij"), np.zeros((4, 4))], axis=-1)
    cp[1:3, 1:3, 2] = 0.8
    return NurbsSurface(cp, [0] * 4 + [1] * 4, [0] * 4 + [1] * 4, 3, 3)


def half_flat():
    """Cubic B-spline, 5 x 1 spans: flat for u < 0.6, curved above.

    The control points sit at the Greville abscissae, so the flat part is
    parametrized linearly (no tangential chord error either).
    """
    ku = np.array([0, 0, 0, 0, .2, .4, .6, .8, 1, 1, 1, 1])
    gu = np.convolve(ku[1:-1], np.ones(3) / 3, mode="valid")          # Greville abscissae
    gv = np.linspace(0, 1, 4)
    cp = np.stack([*np.meshgrid(gu, gv, indexing="ij"), np.zeros((8, 4))], axis=-1)
    cp[6:, :, 2] = [[0.3, -0.2, 0.4, 0.1], [-0.3, 0.5, 0.0, 0.2]]
    return NurbsSurface(cp, ku, [0] * 4 + [1] * 4, 3, 3)


def random_bspline(seed: int, amplitude: float):
    rng = np.random.default_rng(seed)
    nu, nv = rng.integers(4, 7, size=2)
    gu, gv = np.linspace(0, 1, nu), np.linspace(0, 1, nv)
    cp = np.stack([*np.meshgrid(gu, gv, indexing="ij"), np.zeros((nu, nv))], axis=-1)
    cp += amplitude * rng.normal(size=cp.shape)
    ku = np.concatenate([[0] * 3, np.linspace(0, 1, nu - 2), [1] * 3])
    kv = np.concatenate([[0] * 3, np.linspace(0, 1, nv - 2), [1] * 3])
    w = rng.uniform(0.5, 2.0, size=(nu, nv)) if seed % 2 else None
    return NurbsSurface(cp, ku, kv, 3, 3, w)


# ---------------------------------------------------------------- checks
def max_deviation(surface, mesh, n=6):
    """Largest |S(bary uv) - bary xyz| over a dense barycentric grid of every triangle."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    b = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n       # (s, 3)
    uv = np.einsum("sc,tcd->tsd", b, mesh.triangle_uv())
    xyz = np.einsum("sc,tcd->tsd", b, mesh.triangle_points())
    return np.linalg.norm(surface.evaluate(uv[..., 0], uv[..., 1]) - xyz, axis=-1).max()


def assert_watertight(tess: Tessellation, regions):
    """Edges used once lie on the boundary of the union of regions, others exactly twice."""
    mesh = tess.mesh
    edges, counts = mesh.edges()
    assert set(np.unique(counts)) <= {1, 2}
    boundary = edges[counts == 1]
    mid = 0.5 * (mesh.uv[boundary[:, 0]] + mesh.uv[boundary[:, 1]])
    # a boundary edge's midpoint is inside exactly one region, on its border
    r = np.asarray(regions)
    on_border = np.zeros(mid.shape[0], bool)
    inside_count = np.zeros(mid.shape[0], int)
    for u0, u1, v0, v1 in r:
        inside = (mid[:, 0] >= u0) & (mid[:, 0] <= u1) & (mid[:, 1] >= v0) & (mid[:, 1] <= v1)
        border = inside & ((mid[:, 0] == u0) | (mid[:, 0] == u1) | (mid[:, 1] == v0)
                           | (mid[:, 1] == v1))
        inside_count += inside
        on_border |= border
    assert np.all(on_border) and np.all(inside_count == 1)


def assert_unique_vertices(mesh):
    assert np.unique(mesh.uv, axis=0).shape[0] == mesh.n_vertices


def assert_oriented_like_surface(surface, mesh):
    centre = mesh.triangle_uv().mean(axis=1)
    normal = surface.normals(centre[:, 0], centre[:, 1])
    assert np.all(np.sum(normal * mesh.normals(), axis=1) > 0)


# ----------------------------------------------------------------- tests
@pytest.mark.parametrize("make, tol", [(bump, 1e-3), (half_flat, 1e-3), (sphere_band, 2e-3),
                                       (plane_patch, 1e-6)])
def test_tolerance_watertight_unique(make, tol):
    surface = make()
    tess = tessellate(surface, tol)
    mesh = tess.mesh
    assert max_deviation(surface, mesh) <= tol
    assert np.all(tess.leaf_error <= tol)
    regions = patch_rectangles(surface)
    assert_watertight(tess, regions)
    assert_unique_vertices(mesh)
    assert_oriented_like_surface(surface, mesh)
    # triangles know their leaf, and lie in it
    leaf = tess.leaves[mesh.patch]
    uv = mesh.triangle_uv()
    assert np.all((uv[..., 0] >= leaf[:, None, 0]) & (uv[..., 0] <= leaf[:, None, 1])
                  & (uv[..., 1] >= leaf[:, None, 2]) & (uv[..., 1] <= leaf[:, None, 3]))
    np.testing.assert_allclose(mesh.vertices, surface.evaluate(mesh.uv[:, 0], mesh.uv[:, 1]))


def test_hanging_vertices_are_used():
    """Leaves at different levels: some leaf is a fan (more than two triangles)."""
    tess = tessellate(bump(), 1e-3)
    per_leaf = np.bincount(tess.mesh.patch)
    assert per_leaf.max() > 2 and np.any(per_leaf == 2)
    assert np.unique(tess.leaves[:, 1] - tess.leaves[:, 0]).size > 1


def test_plane_needs_two_triangles_per_patch():
    tess = tessellate(plane_patch(), 1e-9)
    assert tess.mesh.n_triangles == 2 and tess.depth == 0


def test_fewer_triangles_where_flat():
    surface = half_flat()
    mesh = tessellate(surface, 1e-4).mesh
    centre_u = mesh.triangle_uv()[..., 0].mean(axis=1)
    flat, curved = np.sum(centre_u < 0.6), np.sum(centre_u > 0.6)
    assert np.sum(centre_u < 0.4) == 4      # two flat spans, two triangles each
    assert curved > 20 * flat               # the third flat span fans to its fine neighbour


def test_ruled_direction_split_one_way():
    """A cylinder-like strip (straight in v) is only split in u."""
    surface = sphere_band()
    cp = np.array(surface.control_points)
    cp[:, :, :2] = cp[:, 1:2, :2]                       # radius constant along v: a cylinder
    w = np.array(surface.weights)
    w[:] = w[:, 1:2] / R2
    cyl = NurbsSurface(cp, surface.knots_u, surface.knots_v, 2, 2, w)
    tess = tessellate(cyl, 1e-3)
    assert np.all(tess.leaves[:, 2] == 0) and np.all(tess.leaves[:, 3] == 1)
    assert max_deviation(cyl, tess.mesh) <= 1e-3


def test_restricted_regions():
    surface = sphere_band()
    regions = patch_rectangles(surface)[[1, 3]]
    tess = tessellate(surface, 2e-3, regions)
    uv = tess.mesh.uv
    assert np.all(((uv[:, 0] >= .25) & (uv[:, 0] <= .5)) | ((uv[:, 0] >= .75) & (uv[:, 0] <= 1)))
    assert_watertight(tess, regions)
    assert set(np.unique(tess.leaf_region)) == {0, 1}
    # adjacent regions are stitched (no crack along their common edge u = 0.5)
    both = tessellate(surface, 2e-3, patch_rectangles(surface)[[1, 2]])
    assert_watertight(both, patch_rectangles(surface)[[1, 2]])
    empty = tessellate(surface, 1e-3, np.zeros((0, 4)))
    assert empty.mesh.n_triangles == 0


def test_finer_tolerance_more_triangles_and_max_depth():
    s = bump()
    counts = [tessellate(s, tol).mesh.n_triangles for tol in (1e-2, 1e-3, 1e-4)]
    assert counts[0] < counts[1] < counts[2]
    capped = tessellate(s, 1e-6, max_depth=2)
    assert capped.depth == 2 and capped.leaf_error.max() > 1e-6


@pytest.mark.parametrize("tol", [0.0, -1.0, np.nan, np.inf])
def test_bad_tolerance(tol):
    with pytest.raises(InvalidToleranceError):
        tessellate(bump(), tol)


@pytest.mark.parametrize("regions, match", [
    ([[0, 2, 0, 1]], "domain"), ([[0.5, 0.5, 0, 1]], "u0 < u1"), ([[0, np.nan, 0, 1]], "NaN")])
def test_bad_regions(regions, match):
    with pytest.raises(InvalidGeometryError, match=match):
        tessellate(bump(), 1e-3, regions)


def test_needs_3d():
    cp = np.zeros((2, 2, 2))
    cp[1, :, 0] = 1
    cp[:, 1, 1] = 1
    with pytest.raises(InvalidGeometryError, match="3D"):
        tessellate(NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1), 1e-3)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), amplitude=st.sampled_from([0.0, 0.05, 0.2]),
       tol=st.sampled_from([3e-3, 1e-3]))
def test_random_surfaces(seed, amplitude, tol):
    surface = random_bspline(seed, amplitude)
    tess = tessellate(surface, tol)
    assert max_deviation(surface, tess.mesh, n=4) <= tol
    assert_watertight(tess, patch_rectangles(surface))
    assert_unique_vertices(tess.mesh)


def test_keep_boxes_prune_the_refinement():
    """Only rectangles near the keep box are refined; the part kept is the full one's."""
    surface = sphere_band()
    tol = 2e-3
    box = np.array([[[0.9, -0.2, -0.1], [1.1, 0.2, 0.1]]])
    full = tessellate(surface, tol)
    pruned = tessellate(surface, tol, keep_boxes=box, keep_pad=2 * tol)
    assert 0 < pruned.mesh.n_triangles < full.mesh.n_triangles / 4
    # every full-mesh triangle that meets the box is in the pruned mesh, bitwise
    boxes = full.mesh.triangle_boxes()
    near = np.all((boxes[:, 0] <= box[0, 1]) & (boxes[:, 1] >= box[0, 0]), axis=1)
    wanted = {tuple(t.ravel()) for t in full.mesh.triangle_points()[near]}
    got = {tuple(t.ravel()) for t in pruned.mesh.triangle_points()}
    assert wanted <= got
    _, counts = pruned.mesh.edges()
    assert set(np.unique(counts)) <= {1, 2}
    assert max_deviation(surface, pruned.mesh) <= tol
    far = tessellate(surface, tol, keep_boxes=box + 10.0)
    assert far.mesh.n_triangles == 0 and far.leaves.shape == (0, 4)


def test_keep_boxes_per_region_prune_only_their_own_region():
    """keep_region: a rectangle is tested against the keep boxes of its own region only."""
    cp = np.zeros((4, 4, 3))
    g = np.linspace(0, 1, 4)
    cp[..., 0], cp[..., 1] = np.meshgrid(g, g, indexing="ij")
    plane = NurbsSurface(cp, [0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1], 3, 3)
    regions = np.array([[0, 0.5, 0, 0.5], [0.5, 1, 0, 0.5]])
    box = np.array([[[0.1, 0.1, -0.1], [0.2, 0.2, 0.1]]])         # over region 0 only
    for owner, kept in ((0, {0}), (1, set())):
        t = tessellate(plane, 1e-3, regions, keep_boxes=box, keep_pad=0.01, keep_region=[owner])
        assert set(np.unique(t.leaf_region).tolist()) == kept
        if kept:
            uv = t.mesh.uv[t.mesh.triangles].reshape(-1, 2)
            assert uv[:, 0].max() <= 0.5
    with pytest.raises(InvalidGeometryError):
        tessellate(plane, 1e-3, regions, keep_boxes=box, keep_region=[2])


@pytest.mark.parametrize("diagonal", [0, 1])
def test_one_leaf_is_triangulated_as_the_general_path_does(diagonal):
    """A single leaf (a plane's one patch) skips the crack-free bookkeeping: the same
    corners, order, triangles and leaf ids as _triangulate_leaves."""
    from surfprep.algorithms.intersection.tessellation import _one_leaf, _triangulate_leaves
    leaf = np.array([0.2, 0.7, -1.0, 3.0])
    fast = _one_leaf(leaf, diagonal)
    general = _triangulate_leaves(leaf[None], np.array([diagonal]))
    for x, y in zip(fast, general):
        np.testing.assert_array_equal(x, y)
        assert x.dtype == y.dtype
