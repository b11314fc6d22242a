"""Graded samples at the crossings of C1 knot lines (algorithms/intersection/crossings.py)."""

from __future__ import annotations

import numpy as np
import pytest
from ssi_surfaces import sphere_band
from test_ssi_refine import plane_z

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import intersect_surfaces
from surfprep.algorithms.intersection import sampling as sampling_module
from surfprep.algorithms.intersection.crossings import (
    _GROWTH,
    _KINK_CONSTANT,
    _MARGIN,
    c1_knots,
    crossing_positions,
)


def _bicubic() -> NurbsSurface:
    x = np.linspace(0, 1, 7)
    cp = np.stack([*np.meshgrid(x, x, indexing="ij"), np.zeros((7, 7))], axis=-1)
    k = np.concatenate([[0.0] * 3, np.linspace(0, 1, 5), [1.0] * 3])
    return NurbsSurface(cp, k, k, 3, 3)


def test_c1_knots_only_where_the_parametrization_is_c1():
    u, v = c1_knots(sphere_band())
    np.testing.assert_allclose(u, [0.25, 0.5, 0.75])
    assert v.size == 0
    u, v = c1_knots(_bicubic())                # simple knots of a cubic: C2
    assert u.size == 0 and v.size == 0


def test_zone_is_graded_around_the_crossing():
    """A straight 3D line whose pcurve u(s) has a jump J in its second derivative at
    u = 0.5: a centre span of the predicted width holds the crossing, the spans grow
    by at most _GROWTH outwards, and the regular positions inside are gone."""
    s = np.linspace(0.0, 1.0, 101)
    jump, target = 2.0, 1e-9
    u = s + 0.5 * jump * np.maximum(s - 0.5, 0.0) ** 2 / 1.0
    points = np.stack([s, np.zeros_like(s), np.zeros_like(s)], axis=1)
    uv_a = np.stack([u, np.zeros_like(s)], axis=1)
    uv_b = np.stack([s, np.zeros_like(s)], axis=1)
    stacked = np.hstack([points, uv_a, uv_b])
    regular_positions = np.linspace(0, 1, 41)[1:-1]
    regular = np.full(s.size - 1, 0.025)
    out = crossing_positions(regular_positions, s, regular, stacked, uv_a, uv_b,
                             (np.array([0.5]), np.zeros(0)), (np.zeros(0), np.zeros(0)),
                             (0, 1.5, 0, 1), (0, 1, 0, 1), False, target)
    assert np.all(np.diff(out) > 0) and out[0] > 0 and out[-1] < 1
    crossing = 0.5
    centre = _MARGIN * np.sqrt(target / (_KINK_CONSTANT * jump))
    i = np.searchsorted(out, crossing)
    assert out[i - 1] < crossing < out[i]
    assert out[i] - out[i - 1] == pytest.approx(centre, rel=0.2)
    steps = np.diff(out)
    ratios = steps[1:] / steps[:-1]
    # inside the zone by _GROWTH per span, at its edges into the regular spacing by at
    # most 2 (the rounds split a span 4 times its neighbour)
    assert np.all(np.maximum(ratios, 1 / ratios) <= 2.0)
    left = steps[:i - 1][::-1]                      # from the centre span leftwards
    zone = left[: np.argmax(left >= 0.025 * (1 - 1e-9)) - 1]
    assert zone.size >= 3
    np.testing.assert_allclose(zone[1:] / zone[:-1], _GROWTH, rtol=1e-6)
    assert out.size > regular_positions.size            # the zone added samples


def test_no_zone_on_a_c2_surface():
    s = np.linspace(0.0, 1.0, 51)
    pts = np.stack([s, s ** 2, np.zeros_like(s)], axis=1)
    uv = np.stack([s, np.zeros_like(s)], axis=1)
    positions = np.linspace(0, 1, 11)[1:-1]
    knots = c1_knots(_bicubic())
    out = crossing_positions(positions, s, np.full(50, 0.1), np.hstack([pts, uv, uv]), uv, uv,
                             knots, knots, (0, 1, 0, 1), (0, 1, 0, 1), False, 1e-9)
    np.testing.assert_array_equal(out, positions)


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
def test_sphere_cut_needs_few_rounds_and_stays_within_half_tol_densely(tol, monkeypatch):
    """A circle of latitude on the rational sphere crosses four C1 knot lines (a seam
    among them): with the zones in place the first subset passes after at most two
    verification rounds (a round that splits, one that checks), and the interpolants
    lie within tol / 2 of both surfaces at 40 points per span."""
    rounds = []
    original = sampling_module.verification_round

    def counted(*args, **kwargs):
        rounds.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(sampling_module, "verification_round", counted)
    plane, sphere = plane_z(0.3), sphere_band(1.0)
    (curve,) = intersect_surfaces(plane, sphere, tol=tol)
    assert len(rounds) <= 2
    t = curve.parameters
    s = np.linspace(0.0, 1.0, 41)[:-1]
    at = (t[:-1, None] + s[None, :] * np.diff(t)[:, None]).ravel()
    c3 = curve.curve3d.evaluate(at)
    ua, ub = curve.pcurve_a.evaluate(at), curve.pcurve_b.evaluate(at)
    on_a = plane.evaluate(ua[:, 0], ua[:, 1])
    on_b = sphere.evaluate(ub[:, 0], ub[:, 1])
    worst = max(np.abs(np.linalg.norm(on_b, axis=1) - 1.0).max(),       # exact sphere
                np.abs(c3[:, 2] - 0.3).max(),
                np.linalg.norm(on_a - c3, axis=1).max(), np.linalg.norm(on_b - c3, axis=1).max())
    assert worst <= 0.5 * tol
