"""Where a face's sides go (algorithms/healing/edge_targets.py), against exact answers on
a plane and a bump."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.healing.edge_targets import (
    END_FADE,
    along_iso,
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
    assert np.array_equal(on_surface(plane, points, guess), uv)          # a border pcurve


def test_points_inside_go_to_their_closest_points():
    bump = _bump()
    a = np.linspace(0, 2 * np.pi, 50)
    guess = np.stack([0.5 + 0.3 * np.cos(a), 0.5 + 0.3 * np.sin(a)], axis=1)
    on = bump.evaluate(guess[:, 0], guess[:, 1])
    normal = bump.normals(guess[:, 0], guess[:, 1])
    uv = on_surface(bump, on + 1e-3 * normal, guess + 1e-3)
    assert np.max(np.abs(uv - guess)) <= 1e-8


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
