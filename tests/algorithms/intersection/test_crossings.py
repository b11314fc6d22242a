"""Graded samples at the crossings of C1 knot lines, a sample on those of C2 knot lines
(algorithms/intersection/crossings.py)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import plane_z, sphere_band

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import intersect_surfaces
from surfprep.algorithms.intersection import sampling as sampling_module
from surfprep.algorithms.intersection.crossings import (
    _C2_NEAR,
    _GROWTH,
    _KINK_CONSTANT,
    _MARGIN,
    _OPEN_MARGIN,
    c1_knots,
    c2_knots,
    crossing_positions,
    on_c2_crossings,
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
    centre = _OPEN_MARGIN * _MARGIN * np.sqrt(target / (_KINK_CONSTANT * jump))   # open
    i = np.searchsorted(out, crossing)
    assert out[i - 1] < crossing < out[i]
    assert out[i] - out[i - 1] == pytest.approx(centre, rel=0.2)
    steps = np.diff(out)
    ratios = steps[1:] / steps[:-1]
    # inside the zone by _GROWTH per span, at its edges into the regular spacing by at
    # most 2 (the rounds split a span 4 times its neighbour)
    assert np.all(np.maximum(ratios, 1 / ratios) <= 2.0)
    left = steps[:i - 1][::-1]                      # from the centre span leftwards
    graded = int(np.sum(centre * _GROWTH ** np.arange(1, 41) < 0.025))
    zone = left[:graded]
    assert zone.size >= 3
    np.testing.assert_allclose(zone / centre, _GROWTH ** np.arange(1, graded + 1), rtol=1e-6)
    # past the zone no span is longer than the regular spacing (the gap the dropped
    # regular positions leave is split)
    assert np.all(steps <= 0.025 * (1 + 1e-9))
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


def counted_rounds(monkeypatch) -> list:
    """A list that gets one entry per verification round of the cubic sampling."""
    rounds = []
    original = sampling_module.verification_round

    def counted(*args, **kwargs):
        rounds.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(sampling_module, "verification_round", counted)
    return rounds


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
def test_sphere_cut_needs_few_rounds_and_stays_within_half_tol_densely(tol, monkeypatch):
    """A circle of latitude on the rational sphere crosses four C1 knot lines (a seam
    among them): with the zones in place the first subset passes after at most two
    verification rounds (a round that splits, one that checks), and the interpolants
    lie within tol / 2 of both surfaces at 40 points per span."""
    rounds = counted_rounds(monkeypatch)
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


# ------------------------------------------------------------------ C2 knot lines
def _straight(n=201):
    """Chord-length parameters of a line of length 1 and its pcurve u = s, v = 0.5."""
    s = np.linspace(0.0, 1.0, n)
    return s, np.stack([s, np.full_like(s, 0.5)], axis=1)


def test_c2_knots_only_where_the_surface_is_c2_but_not_c3():
    u, v = c2_knots(_bicubic())
    np.testing.assert_allclose(u, [0.25, 0.5, 0.75])
    np.testing.assert_allclose(v, [0.25, 0.5, 0.75])
    u, v = c2_knots(sphere_band())              # rational quadratic: degree below 3
    assert u.size == 0 and v.size == 0


def test_a_sample_on_every_c2_crossing_and_no_short_span():
    """Each crossing becomes a position; a regular position too near it moves off, so no
    span is shorter than _C2_NEAR of the regular spacing or longer than it; two
    crossings closer than that (both surfaces at one point) give one sample."""
    t, uv = _straight()
    positions = np.linspace(0.0, 1.0, 41)[1:-1]                 # spacing 0.025
    knots_a = (np.array([0.3, 0.503, 0.7]), np.zeros(0))
    knots_b = (np.array([0.5]), np.zeros(0))
    uv_b = np.stack([np.linspace(0.0, 1.0, t.size), np.full(t.size, 0.5)], axis=1)
    out = on_c2_crossings(positions, t, uv, uv_b, knots_a, knots_b, (0, 1, 0, 1),
                          (0, 1, 0, 1), False)
    for x in (0.3, 0.7):
        assert np.min(np.abs(out - x)) < 1e-12
    merged = 0.5 * (0.5 + 0.503)
    assert np.min(np.abs(out - merged)) < 1e-12 and np.sum(np.abs(out - merged) < 0.006) == 1
    steps = np.diff(np.concatenate([[0.0], out, [1.0]]))
    assert steps.min() >= _C2_NEAR * 0.025 - 1e-12 and steps.max() <= 0.025 + 1e-12
    assert out.size == positions.size + 3


def test_a_c2_crossing_next_to_a_closed_curves_start_takes_no_sample():
    """The start sample of a closed curve stays; a crossing within _C2_NEAR of the
    spacing from it is near enough (a sample beside it would leave a span far shorter
    than its neighbours)."""
    s = np.linspace(0.0, 1.0, 201)[:-1]
    uv = np.stack([np.mod(s + 0.003, 1.0), np.full_like(s, 0.5)], axis=1)   # u crosses 0.999..
    t = np.linspace(0.0, 1.0, 201)
    positions = np.linspace(0.0, 1.0, 41)[1:-1]
    out = on_c2_crossings(positions, t, uv, uv, (np.array([0.5]), np.zeros(0)),
                          (np.zeros(0), np.zeros(0)), (0, 1, 0, 1), (0, 1, 0, 1), True)
    assert np.min(np.abs(out - 0.497)) < 1e-12            # the crossing inside is taken
    out_near = on_c2_crossings(positions, t, uv, uv, (np.array([0.0035]), np.zeros(0)),
                               (np.zeros(0), np.zeros(0)), (0, 1, 0, 1), (0, 1, 0, 1), True)
    np.testing.assert_array_equal(out_near, positions)


@pytest.mark.parametrize("tol, most", [(1e-7, 1), (1e-9, 1), (1e-10, 2)])
def test_bicubic_cut_has_samples_on_its_knot_lines_and_passes_in_few_rounds(tol, most,
                                                                             monkeypatch):
    """The bumpy bicubic (20 x 20 poles) x a plane: four loops crossing about 60 simple
    knot lines. With a sample on each crossing the first subset passes the first
    verification round at 1e-7 and 1e-9 and after two at 1e-10 (it took four when the
    rounds had to find the crossings, and a second round at 1e-7 / 1e-9 while a
    position moved off a crossing could leave a span 4.3 times its neighbour, over the
    rounds' grading ratio), every crossing of pcurve_a has a kept sample within 1e-3
    of a knot span from it, and the curves stay within tol densely."""
    from helpers.measure import check_on_surfaces
    from helpers.surfaces import bumpy, flat
    rounds = counted_rounds(monkeypatch)
    a, b = bumpy(20), flat(0.2)
    curves = intersect_surfaces(a, b, tol=tol)
    assert len(curves) == 4 and len(rounds) <= most
    check_on_surfaces(curves, a, b, tol=tol)
    knots_u, knots_v = c2_knots(a)
    width = float(np.diff(knots_u[:2])[0])
    for curve in curves:
        uv = curve.pcurve_a.evaluate(np.linspace(curve.parameters[0], curve.parameters[-1],
                                                 20001))
        for q, lines in ((0, knots_u), (1, knots_v)):
            crossed = [c for c in lines if np.any(np.diff(np.sign(uv[:, q] - c)) != 0)]
            for line in crossed:
                assert np.min(np.abs(curve.uv_a[:, q] - line)) <= 1e-3 * width


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
def test_open_arc_across_knot_lines_passes_the_first_round(tol, monkeypatch):
    """An open arc of latitude across the sphere's three interior C1 knot lines (the
    band restricted to u in [0.05, 0.95]): the narrower centre span of an open curve's
    zones (its interpolant's averaged knots spread a kink's error over the zone) lets
    the first subset pass the first verification round (with a closed curve's centre
    span it took two, with 5-6 % more samples), within tol / 2 densely."""
    rounds = counted_rounds(monkeypatch)
    plane, band = plane_z(0.3), sphere_band(1.0).restrict(0.05, 0.95, 0.0, 1.0)
    (curve,) = intersect_surfaces(plane, band, tol=tol)
    assert not curve.closed
    assert len(rounds) == 1
    t = curve.parameters
    s = np.linspace(0.0, 1.0, 41)[:-1]
    at = (t[:-1, None] + s[None, :] * np.diff(t)[:, None]).ravel()
    c3 = curve.curve3d.evaluate(at)
    ub = curve.pcurve_b.evaluate(at)
    on_b = band.evaluate(ub[:, 0], ub[:, 1])
    worst = max(np.abs(np.linalg.norm(on_b, axis=1) - 1.0).max(),       # exact sphere
                np.abs(c3[:, 2] - 0.3).max(), np.linalg.norm(on_b - c3, axis=1).max())
    assert worst <= 0.5 * tol
