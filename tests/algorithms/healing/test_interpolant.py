"""The C1 bicubic interpolant with triple knots (001 eqs. 16-18) and the C2 one (003):
interpolation, knots, and continuity measured with one-sided derivatives at the knots."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.healing.interpolant import (
    Interpolant,
    c1_bicubic,
    c2_bicubic,
    interpolate_grid,
    triple_knots,
)

RNG = np.random.default_rng(5)


def _grid(m, n, f):
    u, v = np.meshgrid(np.linspace(0, 1, m + 1), np.linspace(0, 1, n + 1), indexing="ij")
    return np.stack([u, v, f(u, v)], axis=-1)


def _one_sided(surface, direction, knot, others, order):
    """Derivatives of order ``order`` across the knot line ``direction = knot``, from the
    left piece and the right piece (restricted surfaces: exact one-sided values)."""
    if direction == "u":
        left = surface.restrict(None, knot, None, None).derivatives(knot, others, order)
        right = surface.restrict(knot, None, None, None).derivatives(knot, others, order)
        return left[:, order, 0], right[:, order, 0]
    left = surface.restrict(None, None, None, knot).derivatives(others, knot, order)
    right = surface.restrict(None, None, knot, None).derivatives(others, knot, order)
    return left[:, 0, order], right[:, 0, order]


def test_triple_knots_and_net_size():
    np.testing.assert_array_equal(triple_knots(3), [0, 0, 0, 0, 1 / 3, 1 / 3, 1 / 3, 2 / 3,
                                                    2 / 3, 2 / 3, 1, 1, 1, 1])
    s = c1_bicubic(RNG.random((5, 4, 3)))
    assert s.n_control == (13, 10)
    assert (s.degree_u, s.degree_v) == (3, 3)
    np.testing.assert_array_equal(s.knots_v, triple_knots(3))


@pytest.mark.parametrize("kind", list(Interpolant))
def test_interpolates_the_grid(kind):
    q = RNG.random((6, 5, 3))
    s = interpolate_grid(q, kind)
    got = s.evaluate_grid(np.linspace(0, 1, 6), np.linspace(0, 1, 5))
    np.testing.assert_allclose(got, q, atol=1e-13)


def test_c1_reproduces_sums_of_quadratics_exactly():
    # central-difference legs and parabolic end legs are exact for quadratics, and the
    # zero-twist rule of eq. (18) is exact for f(u) + g(v)
    def f(u, v):
        return 0.3 * u * u - 0.7 * v * v + 0.2 * u - 0.1 * v
    s = c1_bicubic(_grid(5, 7, f))
    t = RNG.random((500, 2))
    p = s.evaluate(t[:, 0], t[:, 1])
    np.testing.assert_allclose(p[:, :2], t, atol=1e-13)
    np.testing.assert_allclose(p[:, 2], f(t[:, 0], t[:, 1]), atol=1e-13)


@pytest.mark.parametrize("direction", ["u", "v"])
def test_c1_first_derivatives_continuous_across_every_knot(direction):
    q = RNG.random((5, 6, 3))
    s = c1_bicubic(q)
    m = (q.shape[0] if direction == "u" else q.shape[1]) - 1
    others = np.linspace(0, 1, 37)
    jumps1, jumps2 = [], []
    for k in range(1, m):
        a, b = _one_sided(s, direction, k / m, others, 1)
        jumps1.append(np.abs(a - b).max())
        a, b = _one_sided(s, direction, k / m, others, 2)
        jumps2.append(np.abs(a - b).max())
    assert max(jumps1) < 1e-12
    assert max(jumps2) > 1e-2          # C1 only: the second derivative jumps (random data)


@pytest.mark.parametrize("direction", ["u", "v"])
def test_c2_second_derivatives_continuous(direction):
    q = RNG.random((6, 7, 3))
    s = c2_bicubic(q)
    knots = np.unique(s.knots_u if direction == "u" else s.knots_v)[1:-1]
    others = np.linspace(0, 1, 37)
    for k in knots:
        for order in (1, 2):
            a, b = _one_sided(s, direction, k, others, order)
            assert np.abs(a - b).max() < 1e-10 * (1 + np.abs(a).max())
    assert s.n_control == (6, 7)
