"""Triple-plane correction of intersection points onto two exact surfaces (004 §6)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.composition.correction import correct_points, three_planes
from surfprep.algorithms.intersection.seams import closed_directions
from surfprep.algorithms.volume_builders import block, solid_sphere, solid_torus


def test_three_planes_meet_where_the_equations_say():
    normals = np.array([[[1.0, 0, 0], [0, 1, 0], [0, 0, 1]],
                        [[1.0, 1, 0], [0, 1, 1], [1, 0, 1]]])
    normals[1] /= np.linalg.norm(normals[1], axis=1)[:, None]
    target = np.array([[1.0, -2.0, 3.0], [0.5, 0.25, -4.0]])
    offsets = np.einsum("kij,kj->ki", normals, target)
    x, det = three_planes(normals, offsets)
    np.testing.assert_allclose(x, target, atol=1e-13)
    assert np.all(np.abs(det) > 0.1)
    parallel = np.array([[[1.0, 0, 0], [1.0, 0, 0], [0, 0, 1]]])
    _, det = three_planes(parallel, np.zeros((1, 3)))
    assert det[0] == 0.0


def test_points_off_the_circle_of_two_spheres_land_on_it():
    r, d, tol = 5.0, 6.0, 1e-9
    sa = solid_sphere(r).exterior_faces()["u1"]
    sb = solid_sphere(r, (d, 0, 0)).exterior_faces()["u1"]
    rng = np.random.default_rng(3)
    angle = rng.uniform(0, 2 * np.pi, 200)
    exact = np.stack([np.full(200, d / 2), 4 * np.cos(angle), 4 * np.sin(angle)], axis=1)
    start = exact + rng.normal(scale=0.05, size=exact.shape)      # a coarse mesh's error
    # start parameters: the nearest of a coarse grid on each sphere
    fixed = []
    for s in (sa, sb):
        u = np.linspace(*s.domain[:2], 41)
        v = np.linspace(*s.domain[2:], 41)
        grid = s.evaluate_grid(u, v).reshape(-1, 3)
        k = np.argmin(np.linalg.norm(start[:, None] - grid[None], axis=2), axis=1)
        fixed.append(np.stack([u[k // 41], v[k % 41]], axis=1))
    out = correct_points(sa, sb, start, fixed[0], fixed[1], tol=tol)
    assert out.converged.all()
    assert out.gap.max() <= tol
    np.testing.assert_allclose(out.points[:, 0], d / 2, atol=tol)
    np.testing.assert_allclose(np.hypot(out.points[:, 1], out.points[:, 2]), 4.0, atol=tol)
    np.testing.assert_allclose(sa.evaluate(out.uv_a[:, 0], out.uv_a[:, 1]), out.points, atol=tol)
    np.testing.assert_allclose(sb.evaluate(out.uv_b[:, 0], out.uv_b[:, 1]), out.points, atol=tol)
    # the step moves a point along the curve's normal plane: it stays near its angle
    moved = np.arctan2(out.points[:, 2], out.points[:, 1])
    assert np.max(np.abs(np.angle(np.exp(1j * (moved - angle))))) < 0.1


def test_a_foot_across_the_seam_of_a_closed_surface_is_found():
    torus = solid_torus(3.0, 1.0).exterior_faces()["u1"]
    assert closed_directions(torus, 1e-9) == (True, True)
    assert closed_directions(block(1.0).exterior_faces()["u0"], 1e-9) == (False, False)
    # points on the torus near its seam, started on the wrong side of it
    u0, u1 = torus.domain[:2]
    uv = np.array([[u1 - 1e-3, 0.4], [u0 + 2e-3, 1.3]])
    x = torus.evaluate(uv[:, 0], uv[:, 1])
    wrong = np.array([[u0, 0.4], [u1, 1.3]])
    out = correct_points(torus, torus, x, wrong, wrong, tol=1e-10)
    np.testing.assert_allclose(out.points, x, atol=1e-9)
    np.testing.assert_allclose(out.uv_a, uv, atol=1e-7)


@pytest.mark.parametrize("tol", [0.0, -1.0, np.nan])
def test_bad_tolerance_is_refused(tol):
    s = solid_sphere(1.0).exterior_faces()["u1"]
    with pytest.raises(Exception, match="tol"):
        correct_points(s, s, np.zeros((1, 3)), np.zeros((1, 2)), np.zeros((1, 2)), tol=tol)
