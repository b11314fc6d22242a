"""cubic_samples: as few samples as the C2 cubic interpolants need, tolerance checked densely."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import R_SPHERE, plane_z, sphere_patch, sphere_plane_start

from surfprep.algorithms.intersection.refine import RefinedCurve, refine_curves
from surfprep.algorithms.intersection.result import checked_curves
from surfprep.algorithms.intersection.sampling import (
    _NEIGHBOUR_SHARE,
    _with_neighbours,
    cubic_samples,
    interpolate_samples,
    interpolate_stacked,
    sample_parameters,
)
from surfprep.algorithms.intersection.topology import EndKind


def dense_arc(c: float, n: int, tol: float):
    """Densely refined samples of the latitude circle z = c on the sphere patch (90 deg)."""
    uv_a, uv_b = sphere_plane_start(c, n, np.random.default_rng(3), perturb=1e-3)
    (curve,) = refine_curves(plane_z(c), sphere_patch(), [uv_a], [uv_b], [False], tol=tol,
                             max_passes=0, simplify=False)
    return curve


def exact_distance(points: np.ndarray, c: float) -> np.ndarray:
    """Distance of points to the circle z = c on the sphere of radius R_SPHERE."""
    rho = np.sqrt(R_SPHERE ** 2 - c ** 2)
    return np.hypot(np.hypot(points[:, 0], points[:, 1]) - rho, points[:, 2] - c)


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
def test_interpolants_within_tol_densely_and_few_samples(tol):
    c = 0.5
    dense = dense_arc(c, 120, tol)
    (sampled,) = cubic_samples(plane_z(c), sphere_patch(), [dense], tol=tol)
    curve3d, pcurve_a, pcurve_b = sampled.interpolants
    t = np.linspace(sampled.parameters[0], sampled.parameters[-1], 20001)   # 16+ per span
    assert exact_distance(curve3d.evaluate(t), c).max() <= tol
    for surface, pcurve in ((plane_z(c), pcurve_a), (sphere_patch(), pcurve_b)):
        uv = pcurve.evaluate(t)
        assert np.linalg.norm(surface.evaluate(uv[:, 0], uv[:, 1]) - curve3d.evaluate(t),
                              axis=1).max() <= tol
    assert 0 < sampled.error <= 0.5 * tol
    # the ends are the dense ends; far fewer samples than straight chords would need
    np.testing.assert_array_equal(sampled.curve.points[[0, -1]], dense.points[[0, -1]])
    rho = np.sqrt(R_SPHERE ** 2 - c ** 2)
    chords = (np.pi / 2) / (2 * np.arccos(1 - tol / rho))
    n = sampled.curve.points.shape[0]
    assert n < chords / 5
    # and not many more than the interior error rule kappa^3 h^4 / 384 <= tol / 2 asks
    h = (384 * 0.5 * tol * rho ** 3) ** 0.25
    assert n <= 3 * (np.pi / 2 * rho / h) + 10


def test_sample_count_grows_as_the_fourth_root_of_one_over_tol():
    c = 0.2
    counts = []
    for tol in (1e-6, 1e-10):
        (sampled,) = cubic_samples(plane_z(c), sphere_patch(), [dense_arc(c, 120, tol)], tol=tol)
        counts.append(sampled.curve.points.shape[0])
    ratio = counts[1] / counts[0]
    assert 4e4 ** 0.25 / 2 < ratio < 2 * 1e4 ** 0.25        # ~10 for four decades


def test_stacked_interpolation_equals_separate():
    dense = dense_arc(0.3, 40, 1e-9)
    t = sample_parameters(dense.points, False)
    stacked = interpolate_stacked([dense.points, dense.uv_a, None, dense.uv_b], t, False)
    assert stacked[2] is None
    s = np.linspace(0, t[-1], 101)
    for values, curve in zip((dense.points, dense.uv_a, dense.uv_b),
                             (stacked[0], stacked[1], stacked[3])):
        np.testing.assert_allclose(curve.evaluate(s),
                                   interpolate_samples(values, t, False).evaluate(s), atol=1e-12)


def test_reported_error_is_the_measured_one():
    """checked_curves reports the errors of the last (local) checks: they agree with a
    full max_deviation of the result."""
    c, tol = -0.4, 1e-8
    dense = dense_arc(c, 150, tol)
    curves, worst = checked_curves([dense], [(EndKind.BOUNDARY, EndKind.BOUNDARY)],
                                   plane_z(c), sphere_patch(), tol=tol)
    measured = curves[0].max_deviation(plane_z(c), sphere_patch()).max
    assert measured <= 0.5 * tol
    assert worst[0] == pytest.approx(measured, rel=1e-2, abs=1e-3 * tol)


def test_closed_curve_and_collapsed_curve():
    c, tol = 0.5, 1e-8
    dense = dense_arc(c, 60, tol)
    point = RefinedCurve(np.repeat(dense.points[:1], 3, axis=0), np.repeat(dense.uv_a[:1], 3, 0),
                         np.repeat(dense.uv_b[:1], 3, 0), False, np.ones(3, bool),
                         np.zeros(3, bool))
    out = cubic_samples(plane_z(c), sphere_patch(), [dense, point], tol=tol)
    assert out[1] is None                                    # collapsed onto one point
    assert out[0].curve.points.shape[0] >= 2
    assert exact_distance(out[0].interpolants[0].evaluate(
        np.linspace(0, out[0].parameters[-1], 5001)), c).max() <= tol


def test_grading_is_closed_in_one_call():
    """_graded: after one call no piece is over _MAX_RATIO times the piece beside it
    across a span end, unless the span got the most pieces a round allows; spans cut
    at a kept dense sample and spans that may not be split keep their pieces."""
    from surfprep.algorithms.intersection.sampling_rounds import _MAX_GRADED, _MAX_RATIO, _graded
    rng = np.random.default_rng(5)
    for closed in (False, True):
        for _ in range(20):
            n = 30
            dt = rng.uniform(0.5, 2.0, n)
            planned = np.where(rng.uniform(size=n) < 0.2, rng.integers(2, 5, n), 1)
            cut = np.where(rng.uniform(size=n) < 0.15, rng.uniform(0.01, 0.99, n), np.nan)
            can = rng.uniform(size=n) < 0.9
            pieces = _graded(dt, planned, cut, closed, can)
            fixed = ~np.isnan(cut) | ~can
            assert np.all(pieces[fixed] == planned[fixed])
            assert np.all(pieces >= planned) and pieces.max() <= max(_MAX_GRADED, planned.max())
            has = ~np.isnan(cut)
            first = np.where(has, np.nan_to_num(cut) * dt, dt / pieces)
            last = np.where(has, (1 - np.nan_to_num(cut)) * dt, dt / pieces)
            pairs = range(n) if closed else range(n - 1)
            for i in pairs:
                j = (i + 1) % n
                for long_, short, span in ((last[i], first[j], i), (first[j], last[i], j)):
                    if long_ > _MAX_RATIO * short * (1 + 1e-12):
                        assert fixed[span] or pieces[span] == _MAX_GRADED


def test_a_dip_of_the_fourth_derivative_estimate_is_raised_to_its_neighbours():
    """One chord far below its neighbours (the fourth derivative passing through zero)
    takes _NEIGHBOUR_SHARE of the larger neighbour; smooth values and a peak stay; a
    closed curve's first and last chords are neighbours."""
    f4 = np.array([4.0, 4.2, 0.1, 8.0, 8.0, 7.9])
    out = _with_neighbours(f4, closed=False)
    assert out[2] == pytest.approx(_NEIGHBOUR_SHARE * 8.0)
    np.testing.assert_array_equal(np.delete(out, 2), np.delete(f4, 2))
    assert np.all(out >= f4)
    ring = np.array([0.01, 1.0, 1.0, 1.0, 2.0])
    assert _with_neighbours(ring, closed=True)[0] == pytest.approx(_NEIGHBOUR_SHARE * 2.0)
    assert _with_neighbours(ring, closed=False)[0] == pytest.approx(_NEIGHBOUR_SHARE * 1.0)


def test_repeated_dense_samples_do_not_inflate_the_plan():
    """Seven dense samples a rounding apart (a corner where a refined curve piled up,
    occt_spaceship_alias.stp faces 1 x 3) made fourth divided differences of
    rounding over 1e-48 and a plan of millions of samples; the repeats are left out
    and the curve comes out as without them, within tol densely."""
    c, tol = 0.5, 1e-7
    dense = dense_arc(c, 120, tol)
    k = 40
    rng = np.random.default_rng(5)
    idx = np.concatenate([np.arange(k + 1), np.full(6, k), np.arange(k + 1, dense.points.shape[0])])
    wiggle = np.zeros((idx.size, 1))
    wiggle[k + 1:k + 7] = 1.0
    piled = RefinedCurve(dense.points[idx] + 1e-13 * wiggle * rng.standard_normal((idx.size, 3)),
                         dense.uv_a[idx] + 1e-15 * wiggle * rng.standard_normal((idx.size, 2)),
                         dense.uv_b[idx] + 1e-15 * wiggle * rng.standard_normal((idx.size, 2)),
                         False, dense.converged[idx], dense.singular[idx])
    (clean,) = cubic_samples(plane_z(c), sphere_patch(), [dense], tol=tol)
    (sampled,) = cubic_samples(plane_z(c), sphere_patch(), [piled], tol=tol)
    assert sampled.curve.points.shape[0] <= clean.curve.points.shape[0] + 2
    curve3d = sampled.interpolants[0]
    t = np.linspace(sampled.parameters[0], sampled.parameters[-1], 20001)
    assert exact_distance(curve3d.evaluate(t), c).max() <= tol
