"""The compiled auxiliary-plane iteration (refine_kernels.py) against the numpy form of
refine_points: same iterations, same points to rounding, the same flags; a start on a
pole goes through the numpy form."""

import numpy as np
import pytest
from helpers.surfaces import sphere_band

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import refine_kernels
from surfprep.algorithms.intersection.refine import refine_points


def test_compiled_kernels_are_available():
    # numba is a declared dependency: without it the numpy fallbacks would run
    # silently and the comparisons below would compare a form with itself
    assert refine_kernels.AVAILABLE


def _plane(z: float, half: float = 2.0, normal_axis: int = 2) -> NurbsSurface:
    g = np.linspace(-half, half, 2)
    X, Y = np.meshgrid(g, g, indexing="ij")
    cols = [X, Y]
    cols.insert(normal_axis, np.full_like(X, z))
    return NurbsSurface(np.stack(cols, -1), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def _height_field(seed: int) -> NurbsSurface:
    rng = np.random.default_rng(seed)
    x = np.linspace(-1, 1, 7)
    X, Y = np.meshgrid(x, x, indexing="ij")
    k = [0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1]
    return NurbsSurface(np.stack([X, Y, 0.3 * rng.normal(size=X.shape)], -1), k, k, 3, 3)


def _both(monkeypatch, a, b, uv_a, uv_b, **kw):
    compiled = refine_points(a, b, uv_a, uv_b, **kw)
    with monkeypatch.context() as m:
        m.setattr(refine_kernels, "AVAILABLE", False)
        reference = refine_points(a, b, uv_a, uv_b, **kw)
    return compiled, reference


def _same(r1, r2, tol):
    np.testing.assert_array_equal(r1.iterations, r2.iterations)
    np.testing.assert_array_equal(r1.converged, r2.converged)
    np.testing.assert_array_equal(r1.singular, r2.singular)
    np.testing.assert_allclose(r1.points, r2.points, rtol=0, atol=1e-3 * tol)
    np.testing.assert_allclose(r1.uv_a, r2.uv_a, rtol=0, atol=1e-9)
    np.testing.assert_allclose(r1.uv_b, r2.uv_b, rtol=0, atol=1e-9)


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
@pytest.mark.parametrize("anchored", [False, True])
def test_rational_sphere_band_by_plane(monkeypatch, tol, anchored):
    rng = np.random.default_rng(3)
    a, b = sphere_band(1.0), _plane(0.3)
    n = 200
    uv_a = np.stack([rng.uniform(0, 1, n), rng.uniform(0.6, 0.9, n)], 1)
    uv_b = np.clip(0.5 + 0.25 * a.evaluate(uv_a[:, 0], uv_a[:, 1])[:, :2]
                   + rng.normal(scale=0.02, size=(n, 2)), 0, 1)
    anchors = a.evaluate(uv_a[:, 0], uv_a[:, 1]) if anchored else None
    r1, r2 = _both(monkeypatch, a, b, uv_a, uv_b, tol=tol, anchors=anchors)
    assert r1.converged.mean() > 0.9
    _same(r1, r2, tol)


def test_height_field_by_plane_with_clamped_starts(monkeypatch):
    rng = np.random.default_rng(5)
    a, b = _height_field(5), _plane(0.0, half=1.5)
    n = 300
    uv_a = rng.uniform(-0.05, 1.05, size=(n, 2)).clip(0, 1)      # some on the domain sides
    uv_b = (a.evaluate(uv_a[:, 0], uv_a[:, 1])[:, :2] + 1.5) / 3.0
    r1, r2 = _both(monkeypatch, a, b, uv_a, uv_b, tol=1e-9)
    assert r1.converged.any()
    _same(r1, r2, 1e-9)


def test_start_on_a_pole_goes_through_the_numpy_form(monkeypatch):
    # a bilinear patch whose v = 0 side collapses onto one point (a pole)
    net = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 1.0]], [[0.0, 0.0, 0.0], [0.0, 1.0, 1.0]]])
    a = NurbsSurface(net, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    b = _plane(0.25, normal_axis=0)
    uv_a = np.array([[0.3, 0.0], [0.5, 0.0], [0.5, 0.6]])
    uv_b = np.array([[0.5, 0.5], [0.5, 0.6], [0.6, 0.6]])
    r1, r2 = _both(monkeypatch, a, b, uv_a, uv_b, tol=1e-10)
    assert r1.converged.all()
    _same(r1, r2, 1e-10)
