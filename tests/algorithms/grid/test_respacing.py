"""Knots re-spaced at C0 joins: the same geometry, even speeds, and an elliptic solve that settles."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.paths import SAMPLES

from surfprep.algorithms.grid import grid_surface
from surfprep.algorithms.grid.elliptic import refine
from surfprep.algorithms.grid.respacing import respaced
from surfprep.algorithms.surface import NurbsSurface


def _two_patches(multiplicity: int = 2) -> NurbsSurface:
    """Two quadratic patches of a wavy sheet, joined at u = 1: the first 0.02 long in x over
    the parameter interval [0, 1], the second 10 long over [1, 2] (speeds 1 : 500). With
    ``multiplicity`` 2 (the degree) the join is C0 only; with 1 the net is the same but the
    knot is C1 and the spans may not be moved."""
    xs = [0.0, 0.01, 0.02, 5.0, 10.0] if multiplicity == 2 else [0.0, 0.01, 5.0, 10.0]
    ys = [0.0, 1.0, 2.0]
    net = np.array([[[x, y, 0.3 * np.sin(x + y)] for y in ys] for x in xs])
    ku = [0, 0, 0, 1, 1, 2, 2, 2] if multiplicity == 2 else [0, 0, 0, 1, 2, 2, 2]
    return NurbsSurface(net, ku, [0, 0, 0, 1, 1, 1], 2, 2)


def test_the_respaced_surface_is_the_same_surface_with_even_speeds():
    surface = _two_patches()
    chart = respaced(surface)
    assert chart is not None
    assert chart.surface.domain == surface.domain
    u, v = np.meshgrid(np.linspace(0, 2, 401), np.linspace(0, 1, 51), indexing="ij")
    p = np.stack([u, v], axis=-1)
    q = chart.to_chart(p)
    np.testing.assert_allclose(chart.surface.evaluate(q[..., 0], q[..., 1]), surface.evaluate(u, v),
                               atol=1e-12)
    np.testing.assert_allclose(chart.from_chart(q), p, atol=1e-14)
    # the join now lies where the lengths put it: 0.02 of 10.02 of the domain
    assert chart.spaced[0][1] == pytest.approx(2 * 0.02 / 10.02, rel=0.05)
    speed = np.linalg.norm(chart.surface.derivatives(q[..., 0], q[..., 1], 1)[..., 1, 0, :], axis=-1)
    before = np.linalg.norm(surface.derivatives(u, v, 1)[..., 1, 0, :], axis=-1)
    assert before.max() / before.min() > 300 and speed.max() / speed.min() < 3


def test_a_c1_join_or_even_speeds_are_left_alone():
    assert respaced(_two_patches(multiplicity=1)) is None
    even = NurbsSurface(np.array([[[x, y, 0.0] for y in (0, 1)] for x in (0, 1, 2)], float),
                        [0, 0, 1, 2, 2], [0, 0, 1, 1], 1, 1)
    assert respaced(even) is None


def test_a_grid_across_a_fast_and_a_slow_patch_is_refined_in_the_respaced_parameters():
    surface = _two_patches()
    start = grid_surface(surface, dims=(41, 21), smooth="none")
    result = refine(surface, start.parameters)
    assert result.converged
    for side in (np.s_[:, 0], np.s_[:, -1], np.s_[0, :], np.s_[-1, :]):
        np.testing.assert_array_equal(result.parameters[side], start.parameters[side])
    u0, u1, v0, v1 = surface.domain
    assert np.all((result.parameters[..., 0] >= u0) & (result.parameters[..., 0] <= u1))
    assert np.all((result.parameters[..., 1] >= v0) & (result.parameters[..., 1] <= v1))
    grid = grid_surface(surface, dims=(41, 21))
    assert grid.quality.folded_cells == 0 and grid.elliptic.converged


def test_the_catia_v4_face_settles_at_201_by_201():
    """occt_catia4_face_L1.igs: degree-5 Bezier patches whose v-speeds differ ~2700-fold
    across C0 joins; its 201 x 201 grid stalled at a residual of 0.017 cells."""
    import surfprep
    face = surfprep.to_nurbs(surfprep.read(SAMPLES / "occt_catia4_face_L1.igs").faces[0])
    grid = grid_surface(face.surface, dims=(201, 201), orthogonal=False)
    assert grid.elliptic.converged
    assert grid.quality.folded_cells == 0 and grid.quality.max_skewness < 0.2
    # the algebraic start, blended in the re-spaced parameters (in the original ones: 0.998)
    assert grid.start_quality.max_skewness < 0.2 and grid.start_quality.folded_cells == 0


def test_a_region_across_the_join_whose_start_folds_starts_from_tfi_in_the_respaced_parameters():
    """A four-sided region whose slanted side runs from the slow patch far into the fast one:
    TFI blended in the original parameters folds 16 cells (max skewness 0.999); blended in the
    re-spaced ones it folds none (0.914: the side bends where it leaves the slow patch), and the
    elliptic grid from there none either. A fair raw start is kept as it is."""
    from surfprep.algorithms.curve import NurbsCurve
    from surfprep.algorithms.grid.region import Region
    from surfprep.algorithms.grid.structured import grid_region

    def region(top_left):
        corners = np.array([(0, 0), (2, 0), (2, 1), top_left], float)
        runs = [(NurbsCurve(np.array([corners[k], corners[(k + 1) % 4]]), [0, 0, 1, 1], 1), 0.0, 1.0)
                for k in range(4)]
        return Region.from_runs(_two_patches(), runs)

    start = grid_region(region((1.5, 1)), dims=(41, 21), smooth="none")
    assert start.start_quality.folded_cells == 0 and start.start_quality.max_skewness < 0.95
    refined = grid_region(region((1.5, 1)), dims=(41, 21))
    assert refined.quality.folded_cells == 0
    fair = grid_region(region((0.6, 1)), dims=(41, 21), smooth="none")
    assert 0.03 < fair.start_quality.max_skewness < 0.05          # the raw TFI's own figure
