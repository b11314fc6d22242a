"""The compiled basis / surface kernels (algorithms/basis_kernels.py) against the numpy forms."""

import numpy as np
import pytest

from surfprep.algorithms import basis, basis_kernels
from surfprep.algorithms.surface import NurbsSurface


def test_compiled_kernels_are_available():
    # numba is a declared dependency: without it the numpy fallbacks would run
    # silently and the comparisons below would compare a form with itself
    assert basis_kernels.AVAILABLE


def _knots(rng, degree: int, n: int) -> np.ndarray:
    inner = np.sort(rng.random(n - degree - 1))
    inner[len(inner) // 2] = inner[len(inner) // 2 - 1]            # a double knot
    return np.concatenate([[0.0] * (degree + 1), inner, [1.0] * (degree + 1)])


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
@pytest.mark.parametrize("order", [0, 1, 2, 6])
def test_basis_derivatives_match_numpy_form(degree, order):
    rng = np.random.default_rng(degree * 10 + order)
    knots = _knots(rng, degree, 9)
    t = np.concatenate([rng.random(300), [0.0, 1.0], knots[degree + 1:-degree - 1]])
    ders, span = basis.basis_derivatives(knots, degree, t, order)
    reference = basis._basis_derivatives_numpy(knots, degree, t, order, span)
    assert ders.shape == reference.shape == (t.size, order + 1, degree + 1)
    np.testing.assert_allclose(ders, reference, rtol=1e-13, atol=1e-13 * np.abs(reference).max())
    np.testing.assert_allclose(ders[:, 0].sum(axis=1), 1.0, rtol=1e-13)    # partition of unity


@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("order", [0, 1, 2])
def test_surface_derivatives_match_numpy_form(monkeypatch, rational, order):
    rng = np.random.default_rng(7 + order)
    p, q, nu, nv = 3, 2, 7, 6
    net = rng.normal(size=(nu, nv, 3))
    weights = rng.uniform(0.5, 2.0, size=(nu, nv)) if rational else None
    s = NurbsSurface(net, _knots(rng, p, nu), _knots(rng, q, nv), p, q, weights)
    u, v = rng.random((2, 4, 50))                     # a 2D batch keeps its shape
    compiled = s.derivatives(u, v, order)
    monkeypatch.setattr(basis_kernels, "AVAILABLE", False)
    reference = s.derivatives(u, v, order)
    assert compiled.shape == reference.shape == (4, 50, order + 1, order + 1, 3)
    np.testing.assert_allclose(compiled, reference, rtol=1e-12,
                               atol=1e-12 * np.abs(reference).max())
