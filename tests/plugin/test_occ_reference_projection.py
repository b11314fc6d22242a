"""Closest points: surfprep's projection against GeomAPI_ProjectPointOnSurf.

OpenCascade's projector reports orthogonal projections (extrema of the distance
inside the domain). When the closest point of a trimmed-to-its-domain surface lies
on the boundary, it returns a farther interior extremum instead. These tests pin
that: ours is never farther than OpenCascade's, and where the two differ, a dense
brute-force search confirms ours.
"""

from __future__ import annotations

import numpy as np

from surfprep import NurbsSurface
from surfprep.algorithms.projection import project_to_surface
from surfprep.plugin import occ_reference


def wavy_surface() -> NurbsSurface:
    rng = np.random.default_rng(7)

    def knots(k, p):
        return np.r_[[0.0] * (p + 1), np.sort(rng.uniform(0, 1, k - p - 1)), [1.0] * (p + 1)]

    g = np.linspace(0, 1, 12)
    x, y = np.meshgrid(g, g, indexing="ij")
    net = np.stack([x, y, np.zeros_like(x)], axis=-1) + 0.05 * rng.normal(size=(12, 12, 3))
    return NurbsSurface(net, knots(12, 3), knots(12, 3), 3, 3)


def brute_force_distance(surface: NurbsSurface, points: np.ndarray, n: int = 600) -> np.ndarray:
    u0, u1, v0, v1 = surface.domain
    grid = surface.evaluate_grid(np.linspace(u0, u1, n), np.linspace(v0, v1, n)).reshape(-1, 3)
    return np.array([np.linalg.norm(grid - p, axis=1).min() for p in points])


def test_ours_is_never_farther_and_opencascade_misses_boundary_feet():
    surface = wavy_surface()
    rng = np.random.default_rng(11)
    points = surface.evaluate(rng.uniform(0, 1, 300), rng.uniform(0, 1, 300))
    points = points + rng.normal(size=(300, 3)) * 0.07
    ours = project_to_surface(surface, points)
    _, occ_distance = occ_reference.project_point_on_surface(surface, points)
    assert np.all(ours.converged)
    assert np.all(ours.distance <= occ_distance + 1e-12)
    occ_farther = np.where(occ_distance - ours.distance > 1e-6)[0]
    # OpenCascade returns a farther point for a sizeable share of these queries ...
    assert occ_farther.size >= 10
    # ... mostly points whose true foot lies on the domain boundary
    on_boundary = np.any((ours.uv[occ_farther] <= 1e-12) | (ours.uv[occ_farther] >= 1 - 1e-12), axis=1)
    assert on_boundary.mean() > 0.8
    # and a dense brute force agrees with ours, not with OpenCascade
    brute = brute_force_distance(surface, points[occ_farther])
    assert np.all(ours.distance[occ_farther] <= brute + 1e-12)
    assert np.all(brute < occ_distance[occ_farther] - 1e-6)
