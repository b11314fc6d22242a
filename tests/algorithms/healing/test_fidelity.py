"""Distance of healed geometry from the input faces (algorithms.healing.fidelity), against
exact answers: a plane face with a disc hole, a bump over a face, several faces culled."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import HOLE_RADIUS, graph_surface, plane_with_hole, wavy_surface

from surfprep.algorithms.healing.fidelity import InputFaces, surface_deviation
from surfprep.algorithms.trimmed import TrimmedFace


def test_distance_to_a_trimmed_face_is_exact_inside_over_its_hole_and_outside_it():
    faces = InputFaces.of([plane_with_hole()])
    h = 0.1
    points = np.array([[0.2, 0.3, h],            # over the face: h
                       [0.5, 0.5, h],            # over the hole's centre: to its rim
                       [0.5, 0.75, 0.0],         # in the hole, 0.05 from its rim
                       [0.95, 0.5, 0.0],         # beyond the outer loop, on the surface
                       [1.2, 0.5, -h]])          # beyond the surface itself
    exact = [h, np.hypot(HOLE_RADIUS, h), HOLE_RADIUS - 0.25, 0.05, np.hypot(0.3, h)]
    got = faces.distance(points, tol=1e-9)
    # the rim is measured on polylines of 128 chords per edge: sag below 1e-4 here
    assert got == pytest.approx(exact, abs=1e-4)


def test_rim_only_sees_the_sides_and_the_whole_sample_sees_the_bump():
    """A bump of height 0.05 over a flat face whose sides lie on the face: 0 along its
    rim, the bump's height over all (the centre is a sample of the 25 x 25 grid)."""
    flat = InputFaces.of([TrimmedFace(graph_surface(lambda x, y: 0.0 * x, samples=9))])
    bump = graph_surface(lambda x, y: 0.05 * np.sin(np.pi * x) * np.sin(np.pi * y), samples=33)
    rim = surface_deviation(bump, flat, tol=1e-10, rim_only=True)
    whole = surface_deviation(bump, flat, tol=1e-10)
    assert rim.max_distance < 1e-12 and rim.samples == 4 * 25
    assert whole.max_distance == pytest.approx(0.05, rel=1e-6)
    assert whole.worst_point == pytest.approx([0.5, 0.5, 0.05], abs=1e-6)
    assert whole.samples == 25 * 25


def test_culling_gives_the_distance_to_the_nearest_of_all_faces():
    """Six faces (the same free-form patch moved about): the culled search returns
    what projecting every point onto every face returns."""
    base = wavy_surface()
    offsets = [(0, 0, 0), (1.05, 0, 0.02), (0, 1.1, -0.05), (2.2, 0.3, 0.4),
               (-0.5, -1.2, 0.1), (0.3, 0.2, 0.35)]
    faces = [TrimmedFace(base.translated(np.array(o, float))) for o in offsets]
    rng = np.random.default_rng(7)
    points = rng.uniform([-1, -1.5, -0.5], [3, 2, 1], size=(400, 3))
    together = InputFaces.of(faces).distance(points, tol=1e-10)
    alone = np.min([InputFaces.of([f]).distance(points, tol=1e-10) for f in faces], axis=0)
    assert together == pytest.approx(alone, abs=1e-9)


def test_no_face_is_infinitely_far():
    assert np.all(np.isinf(InputFaces.of([None]).distance(np.zeros((3, 3)), tol=1e-9)))
