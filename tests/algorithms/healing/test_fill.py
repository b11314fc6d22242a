"""Hardy's reciprocal multiquadric over holes (001 §5 eqs. 12-15): Manhattan neighbours,
global and localized interpolation."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.healing.fill import (
    FillMethod,
    _kernel,
    fill_positions,
    hardy_parameters,
)
from surfprep.errors import DegenerateGeometryError


def _params(m, n):
    return np.meshgrid(np.linspace(0, 1, m + 1), np.linspace(0, 1, n + 1), indexing="ij")


def test_radius_is_the_mean_spacing():
    u, v = _params(10, 4)
    assert hardy_parameters(u, v) == pytest.approx(0.5 * (0.1 + 0.25))


@pytest.mark.parametrize("mode", list(FillMethod))
def test_found_positions_kept_and_smooth_field_filled(mode):
    u, v = _params(16, 16)
    t = 0.5 + 0.1 * np.sin(2 * u) * np.cos(1.5 * v)
    found = np.ones_like(t, bool)
    found[6:10, 5:9] = False
    got = fill_positions(u, v, np.where(found, t, -7.0), found, method=mode)
    np.testing.assert_array_equal(got[found], t[found])
    assert np.abs(got - t)[~found].max() < 5e-3     # the field varies by 0.1 there


def test_local_uses_at_least_k_manhattan_neighbours():
    # one missing point in the middle: its 4 neighbours at distance 1 are not enough for
    # K = 5, so all 8 points within distance 2 enter; changing a point at distance 3 does
    # not change the result, changing one at distance 2 does
    u, v = _params(8, 8)
    t = 0.3 + 0.05 * u + 0.02 * v * v
    found = np.ones_like(t, bool)
    found[4, 4] = False
    base = fill_positions(u, v, t, found, neighbours=5)[4, 4]
    far, near = t.copy(), t.copy()
    far[4, 7] += 0.1
    near[4, 6] += 0.1
    assert fill_positions(u, v, far, found, neighbours=5)[4, 4] == base
    assert fill_positions(u, v, near, found, neighbours=5)[4, 4] != base
    # by hand: the 12 points at distance <= 2, eq. (14)
    ii, jj = np.indices(t.shape)
    sel = found & (np.abs(ii - 4) + np.abs(jj - 4) <= 2)
    r = hardy_parameters(u, v)
    pu, pv = u[sel], v[sel]
    a = _kernel(pu[:, None] - pu, pv[:, None] - pv, r, 0.001)
    c = np.linalg.solve(a, t[sel])
    expected = _kernel(u[4, 4] - pu, v[4, 4] - pv, r, 0.001) @ c
    assert base == pytest.approx(expected, abs=1e-12)


def test_nothing_found_is_degenerate():
    u, v = _params(4, 4)
    with pytest.raises(DegenerateGeometryError, match="no segment"):
        fill_positions(u, v, np.zeros_like(u), np.zeros_like(u, bool))
