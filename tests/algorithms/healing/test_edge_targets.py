"""Where a face's sides go (algorithms/healing/edge_targets.py), against exact answers on
a plane and a bump."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.healing.edge_targets import (
    CORNER_OFF,
    END_FADE,
    ON_BORDER,
    along_iso,
    beyond_sides,
    monotone,
    on_surface,
    pinned_ends,
    roughness,
    spread_ends,
)


def _plane():
    x, y = np.meshgrid(np.linspace(0, 2, 4), np.linspace(0, 1, 4), indexing="ij")
    return interpolate_surface(np.stack([x, y, 0 * x], axis=-1))        # S(u, v) = (2u, v, 0)


def _bump():
    x, y = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij")
    return interpolate_surface(np.stack([x, y, 0.2 * np.exp(-8 * ((x - 0.5) ** 2 + (y - 0.5) ** 2))],
                                        axis=-1))


def test_points_beside_a_side_slide_along_it_and_past_its_end():
    plane = _plane()
    v = np.linspace(0, 1, 11)
    points = np.stack([0 * v - 0.01, 1.1 * v, 0 * v + 0.003], axis=1)   # off the side u = 0
    guess = np.stack([0 * v, v], axis=1)
    uv = along_iso(plane, points, guess, 0, 0.0)
    assert np.all(uv[:, 0] == 0.0)
    assert np.allclose(uv[:, 1], 1.1 * v, atol=1e-12)                    # past v = 1 too
    assert np.array_equal(on_surface(plane, points, guess, v), uv)       # a border pcurve


def test_a_side_whose_ends_were_pinned_to_corners_off_it_still_slides_along_it():
    """A face's corner is the mean of its two edges' ends there, which an exporter leaves
    a little apart (turbine face 12: 1e-6 of the domain across its side v = v0). The side's
    pcurve, its ends pinned to those corners, still runs along the side: its samples
    slide along the iso-curve, not onto the closest points, which past the corner pile
    up on it and ask the surface to stretch a step across the side to one along it."""
    plane = _plane()
    s = np.linspace(0, 1, 201)
    side = np.stack([s, 0 * s], axis=1)                                  # v = 0
    corner = np.array([0.0, 1e-6])
    guess = pinned_ends(side, np.array([corner, *side[1:]]), s)
    assert guess[0, 1] == 1e-6 and np.all(guess[s >= END_FADE, 1] == 0.0)
    points = np.stack([2.0 * (1.05 * s - 0.05), 0 * s - 0.01, 0 * s], axis=1)  # from before u = 0
    uv = on_surface(plane, points, guess, s)
    assert np.all(uv[:, 1] == 0.0)
    assert np.allclose(uv[:, 0], 1.05 * s - 0.05, atol=1e-12)          # past u = 0, in order
    # ends farther off the side than CORNER_OFF, or a middle off it: not a side (points
    # inside the face then go to their closest points, off the side)
    inside = np.stack([2.0 * s, 0 * s + 0.003, 0 * s], axis=1)
    assert np.all(on_surface(plane, inside, guess, s)[:, 1] == 0.0)
    far = pinned_ends(side, np.array([[0.0, 2 * CORNER_OFF], *side[1:]]), s)
    wavy = side + np.array([0.0, 10 * ON_BORDER])
    for not_a_side in (far, wavy):
        assert np.allclose(on_surface(plane, inside, not_a_side, s)[:, 1], 0.003, atol=1e-12)


def test_points_beyond_a_side_get_parameters_beyond_it_and_the_end_comes_back_smoothly():
    """A common curve whose end lies beyond the face's side (KCS hull face 5: its vertex
    2e-5 of the domain outside) projects onto the side there, its last samples piled
    along it; on the tangent plane they get the parameters beyond the side the surface
    extended would give them (exact on a plane: v = y), and pinned to its corner the
    end comes back inside in a fade that keeps the samples in order."""
    plane = _plane()                                                     # S(u, v) = (2u, v, 0)
    s = np.linspace(0, 1, 401)
    y = 0.8 - 0.8 * s - 0.02 * s ** 2                                    # ends at y = -0.02
    points = np.stack([0.6 + 0 * s, y, 0 * s + 1e-3], axis=1)
    guess = np.stack([0.3 + 0 * s, 0.8 - 0.8 * s], axis=1)              # the old pcurve, to v = 0
    uv = on_surface(plane, points, guess, s)
    assert np.allclose(uv, np.stack([0.3 + 0 * s, y], axis=1), atol=1e-12)
    assert np.count_nonzero(uv[:, 1] < 0) > 5                            # past the side
    pinned = pinned_ends(uv, guess, s)
    assert np.array_equal(pinned[-1], guess[-1])
    assert np.all(pinned[:, 1] >= 0) and np.all(np.diff(pinned[:, 1]) < 0)
    # a foot inside, and one on a side whose point lies beside it, stay where they are
    feet = np.array([[0.5, 0.5], [0.3, 0.0]])
    assert np.allclose(beyond_sides(plane, np.array([[1.0, 0.5, 0.1], [0.6, 0.0, 0.1]]), feet),
                       feet, atol=1e-15)
    # so does a foot on a pole, where the parameter along it says nothing (K1 CATIA/debis:
    # a step of 24 domains along a side collapsed to a point)
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    fan = interpolate_surface(np.stack([x * (1 - y), y, 0 * x], axis=-1))    # v = 1 a point
    pole = np.array([[0.67, 1.0]])
    off = fan.evaluate(pole[:, 0], pole[:, 1]) + np.array([-1e-14, 1e-14, 0.0])
    assert np.array_equal(beyond_sides(fan, off, pole), pole)


def test_feet_clamped_onto_a_corner_with_rounding_noise_are_spread():
    """Feet projected past a corner land on it up to a few 1e-12 of the domain apart
    (clamped Newton steps); they are one pile, spread along the edge to the first foot
    that did not pile, not kept as distinct parameters 1e-12 apart."""
    s = np.linspace(0, 1, 101)
    uv = np.stack([s, 0 * s], axis=1)
    uv[:5] = 0.0
    uv[1:5, 1] = 2.4e-12 * np.arange(1, 5)
    spread = spread_ends(uv, s)
    assert np.allclose(spread[:6, 0], np.linspace(0, 0.05, 6), atol=1e-12)
    assert np.all(np.diff(spread[:7, 0]) > 0)


def test_points_inside_go_to_their_closest_points():
    bump = _bump()
    a = np.linspace(0, 2 * np.pi, 50)
    guess = np.stack([0.5 + 0.3 * np.cos(a), 0.5 + 0.3 * np.sin(a)], axis=1)
    on = bump.evaluate(guess[:, 0], guess[:, 1])
    normal = bump.normals(guess[:, 0], guess[:, 1])
    uv = on_surface(bump, on + 1e-3 * normal, guess + 1e-3, a / (2 * np.pi))
    assert np.max(np.abs(uv - guess)) <= 1e-8


def test_a_side_projected_back_and_forth_over_a_crease_is_put_in_order():
    """A common curve passing over a crease of the face projects onto the crease from a
    whole stretch (a pile) and steps back beside it: two targets at one parameter ask
    for two points there. The stretch gets parameters linear in s between the samples
    that keep the order; samples at one s (the even and Chebyshev samples share 0.5)
    keep one parameter; an ordered side is unchanged."""
    s = np.union1d(np.linspace(0, 1, 21), 0.5 - 0.5 * np.cos(np.linspace(0, np.pi, 21)))
    uv = np.stack([0 * s, s ** 2], axis=1)
    assert np.array_equal(monotone(uv, 1, s), uv)
    bad = uv.copy()
    pile = (s > 0.3) & (s < 0.45)
    bad[pile, 1] = 0.3 ** 2                                  # piled on the crease
    back = np.flatnonzero(s >= 0.45)[0]
    bad[back, 1] = 0.29 ** 2                                 # and one stepping back
    out = monotone(bad, 1, s)
    assert np.all(np.diff(out[:, 1])[np.diff(s) > 1e-12] > 0)
    kept = ~pile & (np.arange(s.size) != back)
    assert np.array_equal(out[kept], bad[kept])
    lo, hi = np.flatnonzero(kept & (s <= 0.3))[-1], np.flatnonzero(kept & (s > 0.45))[0]
    inside = slice(lo + 1, hi)
    expected = bad[lo, 1] + (s[inside] - s[lo]) / (s[hi] - s[lo]) * (bad[hi, 1] - bad[lo, 1])
    assert np.allclose(out[inside, 1], expected, atol=1e-15)
    twins = np.flatnonzero(np.diff(s) <= 1e-12)
    assert twins.size and np.allclose(out[twins], out[twins + 1], rtol=0, atol=1e-15)


def test_piled_ends_are_spread_and_ends_pinned_smoothly():
    s = np.linspace(0, 1, 101)
    uv = np.stack([s, 0 * s], axis=1)
    uv[:5] = uv[0]                                    # four samples piled on the first
    spread = spread_ends(uv, s)
    assert np.allclose(spread[:6, 0], np.linspace(0, 0.05, 6))
    assert np.array_equal(spread[6:], uv[6:])
    old = np.stack([s, 0 * s], axis=1)
    shifted = old + np.array([0.0, 1e-3])
    pinned = pinned_ends(shifted, old, s)
    assert np.array_equal(pinned[[0, -1]], old[[0, -1]])
    middle = (s > END_FADE) & (s < 1 - END_FADE)
    assert np.allclose(pinned[middle], shifted[middle], atol=1e-15)
    # C1: second differences bounded by the cubic's curvature 6 shift / END_FADE^2
    h = s[1] - s[0]
    assert np.max(np.abs(np.diff(pinned[:, 1], 2))) <= 1.01 * 6 * 1e-3 * h ** 2 / END_FADE ** 2


def test_roughness_sees_waves_not_shape():
    s = np.linspace(0, 1, 513)
    arc = np.stack([np.cos(s), np.sin(s), 0 * s], axis=1)
    assert roughness(arc, s) <= 1e-6                 # the shape, approximated
    wavy = arc + np.stack([0 * s, 0 * s, 1e-4 * np.sin(200 * s)], axis=1)
    assert 0.5e-4 <= roughness(wavy, s) <= 2e-4
    assert roughness(arc[:5], s[:5]) == 0.0          # too few points to fit
