"""intersect_surfaces on two plain triangle meshes (no exact surface): end to end.

Issue 3, step 7: either operand may be a mesh with no exact form; for mesh x
mesh the traced polylines are the answer (no refinement, no interpolants).
The exact answer is then the intersection of the two piecewise-linear
surfaces themselves, computed here independently: every triangle of one mesh
against the other operand's exact plane, or by sampling the other mesh.

Checks: branch count, closedness, every output point on both meshes (distance
to the nearest triangle, brute force over all triangles), and coverage of the
independently computed intersection polygon.
"""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.intersection import (
    closed_in_space,
    connected_branches,
    intersect_surfaces,
    polyline_distance,
)
from surfprep.algorithms.intersection.mesh import TriangleMesh

TOL = 1e-9


def sphere_mesh(r: float = 1.0, centre=(0.0, 0.0, 0.0), n_lat: int = 24, n_lon: int = 48,
                tilt: float = 0.37) -> TriangleMesh:
    """Latitude-longitude triangulation of a sphere (poles as single vertices), rotated
    by ``tilt`` about x so that no mesh vertex lies in the test planes."""
    lat = np.linspace(-np.pi / 2, np.pi / 2, n_lat + 1)[1:-1]
    lon = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    la, lo = np.meshgrid(lat, lon, indexing="ij")
    ring = np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], -1)
    v = np.vstack([[0, 0, -1.0], ring.reshape(-1, 3), [0, 0, 1.0]])
    c, s = np.cos(tilt), np.sin(tilt)
    v = v @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]]).T
    idx = 1 + np.arange(lat.size * lon.size).reshape(lat.size, lon.size)
    nxt = np.roll(idx, -1, axis=1)
    tri = [np.stack([np.zeros(n_lon, int), nxt[0], idx[0]], 1)]
    for i in range(lat.size - 1):
        tri.append(np.stack([idx[i], nxt[i], nxt[i + 1]], 1).reshape(-1, 3))
        tri.append(np.stack([idx[i], nxt[i + 1], idx[i + 1]], 1).reshape(-1, 3))
    top = v.shape[0] - 1
    tri.append(np.stack([idx[-1], nxt[-1], np.full(n_lon, top)], 1))
    return TriangleMesh(r * v + np.asarray(centre, float), np.concatenate(tri))


def plane_mesh(z: float, half: float = 2.0, n: int = 7) -> TriangleMesh:
    """A square grid of triangles in the plane z = const (given as a soup)."""
    x = np.linspace(-half, half, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    v = np.stack([X, Y, np.full_like(X, z)], -1)
    soup = []
    for i in range(n - 1):
        for j in range(n - 1):
            soup.append([v[i, j], v[i + 1, j], v[i + 1, j + 1]])
            soup.append([v[i, j], v[i + 1, j + 1], v[i, j + 1]])
    return TriangleMesh.from_arrays(np.array(soup))


def distance_to_mesh(points: np.ndarray, mesh: TriangleMesh) -> np.ndarray:
    """Exact distance ``(n,)`` of points to a triangle mesh (brute force: every point
    against every triangle, closest point on each triangle by region tests)."""
    t = mesh.vertices[mesh.triangles]                              # (m, 3, 3)
    a, b, c = t[:, 0], t[:, 1], t[:, 2]
    p = points[:, None, :]                                         # (n, 1, 3)
    ab, ac = b - a, c - a
    normal = np.cross(ab, ac)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    # projection onto the plane; inside the triangle -> plane distance
    d = np.einsum("nmc,mc->nm", p - a, normal)
    q = p - d[..., None] * normal
    def inside(x):
        s0 = np.einsum("nmc,mc->nm", np.cross(b - a, x - a), normal)
        s1 = np.einsum("nmc,mc->nm", np.cross(c - b, x - b), normal)
        s2 = np.einsum("nmc,mc->nm", np.cross(a - c, x - c), normal)
        return (s0 >= 0) & (s1 >= 0) & (s2 >= 0)
    best = np.where(inside(q), np.abs(d), np.inf)
    for u, w in ((a, b), (b, c), (c, a)):                          # else: nearest edge
        e = w - u
        s = np.clip(np.einsum("nmc,mc->nm", p - u, e) / np.einsum("mc,mc->m", e, e), 0, 1)
        best = np.minimum(best, np.linalg.norm(u + s[..., None] * e - p, axis=-1))
    return best.min(axis=1)


def plane_section_of_mesh(mesh: TriangleMesh, z: float) -> list[np.ndarray]:
    """The exact section of a mesh by the plane z = const: one 2-point segment per
    triangle that crosses it (edges crossing the plane, linear interpolation)."""
    t = mesh.vertices[mesh.triangles]
    h = t[..., 2] - z
    out = []
    for tri, s in zip(t, h):
        pts = [tri[i] + s[i] / (s[i] - s[j]) * (tri[j] - tri[i])
               for i, j in ((0, 1), (1, 2), (2, 0)) if s[i] * s[j] < 0]
        if len(pts) == 2:
            out.append(np.array(pts))
    return out


def test_sphere_mesh_by_plane_mesh_one_closed_polygon():
    sphere, plane = sphere_mesh(), plane_mesh(0.3)
    curves = intersect_surfaces(sphere, plane, tol=TOL)
    assert connected_branches(curves, 1e-9) == 1
    assert len(curves) == 1 and closed_in_space(curves[0], 1e-9)
    c = curves[0]
    assert c.uv_a is None and c.uv_b is None and c.curve3d is None      # mesh x mesh: polylines
    np.testing.assert_allclose(c.points[:, 2], 0.3, atol=1e-12)         # on the plane mesh
    assert distance_to_mesh(c.points, sphere).max() <= 1e-12            # on the sphere mesh
    exact = plane_section_of_mesh(sphere, 0.3)
    assert len(exact) > 40
    exact_points = np.concatenate(exact)
    # the polygon is the exact one: every exact vertex on it and it on the exact segments
    assert polyline_distance(exact_points, curves).max() <= 1e-12
    assert polyline_distance(c.points, exact).max() <= 1e-12
    length = sum(np.linalg.norm(s[1] - s[0]) for s in exact)
    assert abs(c.length - length) <= 1e-9 * length


def test_two_sphere_meshes_meet_in_one_loop():
    """Unit sphere meshes centred at the origin and at (1, 0, 0): one closed loop near the
    circle x = 1/2, radius sqrt(3)/2 (within the meshes' chord error)."""
    a, b = sphere_mesh(), sphere_mesh(centre=(1.0, 0.0, 0.0), tilt=-0.21)
    curves = intersect_surfaces(a, b, tol=TOL)
    assert connected_branches(curves, 1e-9) == 1
    assert all(closed_in_space(c, 1e-9) for c in curves)
    p = np.concatenate([c.points for c in curves])
    assert distance_to_mesh(p, a).max() <= 1e-12
    assert distance_to_mesh(p, b).max() <= 1e-12
    sag = 1 - np.cos(np.pi / 24)                 # chord error of the meshes (lat step)
    assert np.abs(p[:, 0] - 0.5).max() <= 2 * sag
    assert np.abs(np.hypot(p[:, 1], p[:, 2]) - np.sqrt(0.75)).max() <= 4 * sag
    # covers the whole circle: every direction around the x axis has a point nearby
    angle = np.sort(np.arctan2(p[:, 2], p[:, 1]))
    assert np.diff(np.append(angle, angle[0] + 2 * np.pi)).max() < 0.2


def test_disjoint_meshes_give_nothing():
    assert intersect_surfaces(sphere_mesh(), plane_mesh(1.5), tol=TOL) == []
