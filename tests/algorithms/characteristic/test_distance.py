"""Projection (eqs. 3-4, §6.2 cases), the oriented distance and its derivatives (A.1),
checked against finite differences, exact distances and the reference evaluation."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import DIAGONAL, degree_six_pair, height_field, plane_patch, sphere_band

from surfprep.algorithms.characteristic import (
    DistanceField,
    PatchEvaluator,
    ProjectionStatus,
    Projector,
    distance_jet,
)


def random_pair(seed: int = 1):
    rng = np.random.default_rng(seed)
    a = height_field(0.2 * rng.random((6, 6)))
    z = 0.1 + 0.2 * rng.random((6, 6))
    b = height_field(z)
    # stretch b beyond a so every point of a has a foot on b
    cp = b.control_points.copy()
    cp[..., :2] = 1.2 * cp[..., :2] - 0.1
    return a, type(b)(cp, b.knots_u, b.knots_v, 3, 3)


@pytest.mark.parametrize("surface", [random_pair()[0], sphere_band()], ids=["bicubic", "sphere"])
def test_patch_evaluator_matches_the_reference_evaluation(surface):
    rng = np.random.default_rng(3)
    u, v = rng.uniform(-0.05, 1.05, 200), rng.uniform(-0.05, 1.05, 200)
    ours = PatchEvaluator(surface).derivatives(u, v, 2)
    ref = surface.derivatives(u, v, 2)
    scale = np.abs(ref).max(axis=0)
    assert np.all(np.abs(ours - ref) <= 1e-10 * np.maximum(scale, 1.0))


@pytest.mark.parametrize("surface", [random_pair()[0], sphere_band(), degree_six_pair()[0]],
                         ids=["bicubic", "sphere", "degree six"])
def test_power_patches_are_the_bezier_patches_in_the_power_basis(surface):
    """The evaluator's Taylor rows (evaluator._power_patches) give the polynomials of
    the Bezier patches (knot insertion, bezier.bezier_patches) in the power basis."""
    from math import comb

    from surfprep.algorithms.bezier import bezier_patches
    from surfprep.algorithms.characteristic.evaluator import _power_patches

    def to_monomial(p):
        m = np.zeros((p + 1, p + 1))
        for i in range(p + 1):
            for k in range(i, p + 1):
                m[i, k] = comb(p, k) * comb(k, i) * (-1) ** (k - i)
        return m

    patches, iu, iv = bezier_patches(surface)
    ref = np.einsum("ik,jl,abijc->abklc", to_monomial(surface.degree_u),
                    to_monomial(surface.degree_v), patches)
    coef, ju, jv = _power_patches(surface)
    np.testing.assert_array_equal(iu, ju)
    np.testing.assert_array_equal(iv, jv)
    assert coef.shape == ref.shape
    assert np.abs(coef - ref).max() <= 1e-11 * np.abs(ref).max()


def finite_difference_check(field: DistanceField, uv: np.ndarray, h: float = 1e-5):
    jet = field.jet(uv)
    assert np.all(jet.status == ProjectionStatus.UNIQUE)
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        plus, minus = field.jet(uv + e, jet.st), field.jet(uv - e, jet.st)
        fd_phi = (plus.phi - minus.phi) / (2 * h)
        fd_grad = (plus.grad - minus.grad) / (2 * h)
        fd_st = (plus.st - minus.st) / (2 * h)
        scale = 1.0 + np.abs(jet.hess).max()
        np.testing.assert_allclose(jet.grad[:, k], fd_phi, atol=1e-7 * scale)          # (24)-(25)
        np.testing.assert_allclose(jet.hess[:, :, k], fd_grad, atol=1e-6 * scale)      # (26)-(31)
        np.testing.assert_allclose(jet.st_jacobian[:, :, k], fd_st, atol=1e-6 * scale)  # (21)
    return jet


def test_derivatives_of_phi_against_finite_differences_bicubic():
    a, b = random_pair()
    field = DistanceField(a, Projector(b, tol=1e-14))
    uv = np.random.default_rng(5).uniform(0.1, 0.9, (40, 2))
    jet = finite_difference_check(field, uv)
    # the Hessian is symmetric by construction and the mixed terms (27), (28) agree
    assert np.abs(jet.hess[:, 0, 1] - jet.hess[:, 1, 0]).max() == 0.0


def test_derivatives_of_phi_against_finite_differences_rational_sphere():
    """phi on a plane against the rational sphere: phi = |p| - 1 up to the sign, exactly."""
    a = plane_patch(0.9 * DIAGONAL, DIAGONAL)
    field = DistanceField(a, Projector(sphere_band(), tol=1e-14))
    uv = np.random.default_rng(6).uniform(0.05, 0.95, (30, 2))
    jet = finite_difference_check(field, uv)
    exact = np.linalg.norm(jet.point, axis=1) - 1.0
    np.testing.assert_allclose(np.abs(jet.phi), np.abs(exact), atol=1e-13)
    # oriented: n_q (outward normal of the band) . (r - q) is negative inside the sphere
    assert np.all(np.sign(jet.phi) == np.sign(exact) * np.sign(jet.phi[0] / exact[0]))


def test_phi_against_a_plane_is_the_signed_height():
    a, _ = random_pair()
    flat = plane_patch([0.5, 0.5, 0.05], [0, 0, 1], half=0.8)
    jet = DistanceField(a, Projector(flat, tol=1e-14)).jet(np.random.default_rng(7).random((50, 2)))
    normal = np.cross(flat.control_points[1, 0] - flat.control_points[0, 0],
                      flat.control_points[0, 1] - flat.control_points[0, 0])
    sign = np.sign(normal[2])
    np.testing.assert_allclose(jet.phi, sign * (jet.point[:, 2] - 0.05), atol=1e-14)
    np.testing.assert_allclose(jet.projection.foot[:, :2], jet.point[:, :2], atol=1e-12)


def test_projection_cases_of_section_6_2():
    """UNIQUE outside the sphere; MULTIPLE beyond the centre (the foot on the near side is
    a maximum of the distance) and at the centre (K = 0); NONE past the band's rim."""
    projector = Projector(sphere_band(), tol=1e-13)
    pts = np.array([[1.05, 1.05, 0.1], [0.2, 0.2, 0.0], [-0.3, -0.3, 0.0], [0.0, 0.0, 3.0],
                    [0.0, 0.0, 0.0]])
    res = projector.project(pts, np.tile([0.125, 0.5], (5, 1)))
    assert res.status.tolist() == [ProjectionStatus.UNIQUE, ProjectionStatus.UNIQUE,
                                   ProjectionStatus.MULTIPLE, ProjectionStatus.NONE,
                                   ProjectionStatus.MULTIPLE]
    # the regular feet are the radial projections
    for i in (0, 1):
        np.testing.assert_allclose(res.foot[i], pts[i] / np.linalg.norm(pts[i]), atol=1e-12)
    # from the seed grid (no start given) the same feet
    np.testing.assert_allclose(projector.project(pts[:2]).foot, res.foot[:2], atol=1e-12)


def test_distance_jet_function_and_field_agree():
    a, b = random_pair(2)
    projector = Projector(b, tol=1e-14)
    uv = np.random.default_rng(8).uniform(0.2, 0.8, (10, 2))
    one = distance_jet(a, projector, uv)
    two = DistanceField(a, projector).jet(uv)
    np.testing.assert_allclose(one.phi, two.phi, atol=1e-14)
    np.testing.assert_allclose(one.hess, two.hess, atol=1e-9)


@pytest.mark.parametrize("pair", ["bicubic", "sphere", "plane", "plane by Newton"])
def test_compiled_jet_matches_the_numpy_jet(pair, monkeypatch):
    """The numba pass (distance_kernels.distance_points, project_points, patch_derivatives)
    computes what the numpy forms compute: same feet, cases, phi and derivatives.
    A plane q is projected in closed form in both (distance_kernels._project_affine); "plane
    by Newton" checks the compiled closed form against the compiled Newton."""
    from surfprep.algorithms.characteristic import distance_kernels
    if pair == "bicubic":
        a, b = random_pair(4)
    elif pair.startswith("plane"):
        a, b = random_pair(4)[0], plane_patch([0.5, 0.5, 0.1], [0.1, 0.2, 1.0], 0.45)
        assert Projector(b, tol=1e-13).is_affine
    else:
        a, b = plane_patch(0.99 * DIAGONAL, DIAGONAL, 0.4), sphere_band()
    uv = np.random.default_rng(5).uniform(-0.02, 1.02, (300, 2))
    uv = np.clip(uv, 0.0, 1.0)
    compiled = DistanceField(a, Projector(b, tol=1e-13)).jet(uv)
    if pair == "plane by Newton":
        newton = Projector(b, tol=1e-13)
        newton._grid["affine"] = None
        ref = DistanceField(a, newton).jet(uv)
    else:
        monkeypatch.setattr(distance_kernels, "AVAILABLE", False)
        ref = DistanceField(a, Projector(b, tol=1e-13)).jet(uv)
        assert distance_kernels.AVAILABLE is False
    np.testing.assert_array_equal(compiled.status, ref.status)
    ok = ref.status != ProjectionStatus.NONE
    assert ok.sum() > 100
    np.testing.assert_allclose(compiled.st[ok], ref.st[ok], atol=1e-10)
    np.testing.assert_allclose(compiled.phi[ok], ref.phi[ok], atol=1e-12)
    np.testing.assert_allclose(compiled.grad[ok], ref.grad[ok], atol=1e-10)
    scale = np.abs(ref.hess[ok]).max()
    np.testing.assert_allclose(compiled.hess[ok], ref.hess[ok], atol=1e-9 * scale)
    np.testing.assert_allclose(compiled.st_jacobian[ok], ref.st_jacobian[ok], atol=1e-9 * scale)


def test_parallelogram_projection_in_closed_form_matches_newton():
    """A plane q is projected by one linear solve; Newton (compiled) finds the same feet."""
    plane = plane_patch([0.1, 0.2, 0.3], [1.0, 2.0, 2.0], 0.5)
    projector = Projector(plane, tol=1e-13)
    assert projector.is_affine
    pts = np.random.default_rng(9).uniform(-0.8, 0.8, (200, 3))
    closed = projector.project(pts)
    projector._grid["affine"] = None                  # the same projector, Newton's way
    newton = projector.project(pts)
    assert not projector.is_affine
    np.testing.assert_array_equal(closed.status, newton.status)
    np.testing.assert_allclose(closed.st, newton.st, atol=1e-12)
    np.testing.assert_allclose(closed.foot, newton.foot, atol=1e-12)
    assert (closed.status == ProjectionStatus.NONE).any() and closed.regular.any()
    # a regular foot is the orthogonal one: r - foot along the plane's normal
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    off = (pts - closed.foot)[closed.regular]
    np.testing.assert_allclose(np.linalg.norm(np.cross(off, n), axis=1), 0.0, atol=1e-12)


@pytest.mark.parametrize("compiled", [True, False])
def test_a_foot_held_at_the_clip_box_is_the_closest_point_along_it(compiled, monkeypatch):
    """Points far beyond q's side: Newton holds s at the side of the clip box (domain
    and extension) and moves t alone, so the foot is the closest point of that line,
    ``(r - q) . q_t = 0`` (the coupled step, clipped, crept to another point and ran
    its 30 steps: 897 of 1089 grid points of the sheets crossing at 5e-3 rad); ten
    steps from the domain's middle reach it, compiled and numpy alike."""
    from helpers.surfaces import flat_crossing

    from surfprep.algorithms.characteristic import distance_kernels
    from surfprep.algorithms.characteristic.projector import EXTENSION
    if not compiled:
        monkeypatch.setattr(distance_kernels, "AVAILABLE", False)
    a, b = flat_crossing(5e-3)
    pts = b.evaluate(np.full(40, 0.5), np.linspace(0.05, 0.95, 40)) + [2.0, 0.0, 0.0]
    for steps in (10, 30):
        res = Projector(a, tol=1e-12, max_iter=steps).project(pts, np.tile([0.5, 0.5], (40, 1)))
        held = np.isclose(res.st[:, 0], 1.0 + EXTENSION) | np.isclose(res.st[:, 0], -EXTENSION)
        assert held.all() and (res.status == ProjectionStatus.NONE).all()
        d = a.derivatives(res.st[:, 0], res.st[:, 1], 1)
        along = np.einsum("ij,ij->i", pts - d[:, 0, 0], d[:, 0, 1])
        assert np.abs(along).max() <= 1e-9 * np.linalg.norm(d[:, 0, 1], axis=1).max()
