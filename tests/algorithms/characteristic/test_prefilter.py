"""The certificate's prefilter: pairs with no possible loop nor contact point."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import (
    horizontal_plane,
    plane_patch,
    several_bumps,
    sphere_and_plane,
    sphere_band,
)

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.characteristic import (
    FoundBy,
    NoLoopReason,
    characteristic_intersection,
    no_loop_reason,
    uncertified_record,
)

TOL = 1e-7


def wavy_ruled(amplitude: float = 0.3) -> NurbsSurface:
    """Cubic in u, straight in v (two control rows): a wavy wall, rational weights."""
    u = np.linspace(0, 1, 7)
    bottom = np.c_[u, 0.2 * np.sin(6 * u), np.full(7, -0.5)]
    top = np.c_[u, 0.2 * np.cos(5 * u) + 0.1, np.full(7, 0.5 + amplitude * u)]
    knots_u = [0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1]
    w = np.c_[np.linspace(1, 2, 7), np.linspace(2, 1, 7)]
    return NurbsSurface(np.stack([bottom, top], 1), knots_u, [0, 0, 1, 1], 3, 1, w)


def test_plane_and_ruled_and_two_planes():
    wall = wavy_ruled()
    for z in (0.0, 0.3):
        plane = horizontal_plane(z)
        assert no_loop_reason(plane, wall, tol=TOL) is NoLoopReason.PLANE_AND_RULED
        assert no_loop_reason(wall, plane, tol=TOL) is NoLoopReason.PLANE_AND_RULED
    tilted = plane_patch([0.5, 0.5, 0.0], [0.3, 0.1, 1.0], half=2.0)
    assert no_loop_reason(horizontal_plane(0.0), tilted, tol=TOL) is NoLoopReason.PLANE_AND_RULED


def test_cases_the_certificate_must_see():
    a, b, _, _ = sphere_and_plane(2e-2)                     # a loop
    assert no_loop_reason(a, b, tol=TOL) is None
    bumps = several_bumps()                                 # bicubic x plane: loops
    assert no_loop_reason(bumps, horizontal_plane(0.3), tol=TOL) is None
    plane = horizontal_plane(0.0)                           # coplanar planes: coincidence
    assert no_loop_reason(plane, horizontal_plane(0.5 * TOL), tol=TOL) is None
    near_plane = NurbsSurface(plane.control_points + [0, 0, 1e-3 * TOL], plane.knots_u,
                              plane.knots_v, 1, 1)
    assert no_loop_reason(near_plane, plane, tol=TOL) is None
    # a plane bent by more than the planarity share is not a plane
    net = several_bumps().control_points.copy()
    net[..., 2] = 1e-6 * np.sin(net[..., 0] * 7)
    bent = NurbsSurface(net, several_bumps().knots_u, several_bumps().knots_v, 3, 3)
    assert no_loop_reason(bent, wavy_ruled(), tol=TOL) is None


def test_apart():
    a, b, _, _ = sphere_and_plane(2e-2)
    far = NurbsSurface(b.control_points + [0, 0, 50.0], b.knots_u, b.knots_v, b.degree_u,
                       b.degree_v, b.weights)
    assert no_loop_reason(a, far, tol=TOL) is NoLoopReason.APART


@pytest.mark.parametrize("z", [-0.45, 0.4])
def test_skipped_pairs_have_no_loop_and_no_contact(z):
    """The full characteristic method on plane x ruled pairs finds no closed loop
    inside the domain and no isolated point: the skip loses nothing."""
    wall, plane = wavy_ruled(), horizontal_plane(z)
    assert no_loop_reason(plane, wall, tol=TOL) is NoLoopReason.PLANE_AND_RULED
    record = characteristic_intersection(plane, wall, tol=TOL)
    assert not record.isolated_points and record.curves
    lo, hi = np.array([0.0, 0.0]), np.array([1.0, 1.0])
    for c in record.curves:
        uv = c.uv_b
        # every curve reaches the wall's domain boundary (no interior loop)
        edge = np.minimum(np.abs(uv - lo), np.abs(uv - hi)).min(axis=1)
        assert edge.min() <= 1e-6


def test_uncertified_record():
    rec = uncertified_record([], NoLoopReason.APART)
    assert rec.curves == () and rec.extra["skipped"] == "apart" and rec.counts() == {}
    assert rec.found_by == () and FoundBy.MESH.value == "mesh"


def sloped_sheet() -> NurbsSurface:
    """Bicubic height field rising in u (z = 0.6 u + small waves), 9 x 8 poles."""
    u, v = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 8), indexing="ij")
    z = 0.6 * u + 0.02 * np.sin(9 * v) + 0.01 * np.cos(5 * u)
    knots_u = [0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 0.9, 1, 1, 1, 1]
    knots_v = [0, 0, 0, 0, 0.25, 0.5, 0.75, 0.9, 1, 1, 1, 1]
    return NurbsSurface(np.stack([u, v, z], -1), knots_u, knots_v, 3, 3)


@pytest.mark.parametrize("z", [0.05, 0.55])
def test_monotone_height_over_a_plane(z):
    """Sloped sheet x horizontal plane: the height rises in u across the rows near the
    plane, so no loop and no contact; the full method agrees (one open curve)."""
    sheet, plane = sloped_sheet(), horizontal_plane(z)
    assert no_loop_reason(sheet, plane, tol=TOL) is NoLoopReason.MONOTONE_HEIGHT
    record = characteristic_intersection(sheet, plane, tol=TOL)
    assert not record.isolated_points and len(record.curves) == 1
    uv = record.curves[0].uv_a
    assert min(uv[:, 1].min(), 1 - uv[:, 1].max()) <= 1e-6      # crosses the v-range


def test_a_bump_near_the_plane_is_not_monotone():
    net = sloped_sheet().control_points.copy()
    net[4, 4, 2] += 0.4                                  # a bump in the middle
    s = sloped_sheet()
    bumped = NurbsSurface(net, s.knots_u, s.knots_v, 3, 3)
    assert no_loop_reason(bumped, horizontal_plane(0.4), tol=TOL) is None


def test_monotone_height_after_halving_the_spans():
    """Control heights 0, 0.5, 0.4, 1 along u: the net turns, the cubic does not
    (its derivative's Bernstein coefficients 1.5, -0.3, 1.8 stay positive in
    between): the rule holds once the spans are halved."""
    heights = np.array([0.0, 0.5, 0.4, 1.0])
    u, v = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
    z = heights[:, None] + 0.05 * np.sin(2 * np.pi * v)      # v turns: only u can pass
    sheet = NurbsSurface(np.stack([u, v, z], -1), [0] * 4 + [1] * 4, [0] * 4 + [1] * 4, 3, 3)
    plane = horizontal_plane(0.45)
    assert no_loop_reason(sheet, plane, tol=TOL) is NoLoopReason.MONOTONE_HEIGHT
    record = characteristic_intersection(sheet, plane, tol=TOL)
    assert not record.isolated_points and len(record.curves) == 1


@pytest.mark.parametrize("z", [-0.5, 0.3])
def test_monotone_height_on_a_rational_sphere_band(z):
    """Rational sphere zone (weights w_ij = a_i b_j) x horizontal plane: the height
    rises along every meridian, so no loop, no contact; the full method agrees (a
    circle of latitude, open in the band's domain at the seam)."""
    band, plane = sphere_band(), plane_patch([0.0, 0.0, z], [0.0, 0.0, 1.0], half=2.0)
    assert no_loop_reason(band, plane, tol=TOL) is NoLoopReason.MONOTONE_HEIGHT
    record = characteristic_intersection(band, plane, tol=TOL)
    assert not record.isolated_points and record.curves
    uv = np.concatenate([c.uv_a for c in record.curves])
    assert np.abs(band.evaluate(uv[:, 0], uv[:, 1])[:, 2] - z).max() <= 10 * TOL
    length = sum(c.length for c in record.curves)
    assert length == pytest.approx(2 * np.pi * np.sqrt(1 - z * z), rel=1e-6)


def test_rational_weights_that_do_not_separate_are_not_used():
    band = sphere_band()
    w = band.weights.copy()
    w[4, 1] *= 1.5
    bent = NurbsSurface(band.control_points, band.knots_u, band.knots_v, 2, 2, w)
    plane = plane_patch([0.0, 0.0, 0.3], [0.0, 0.0, 1.0], half=2.0)
    assert no_loop_reason(bent, plane, tol=TOL) is None


# ------------------------------------------------------------ the cheap forms agree
def _many_span_sheet(n: int = 30, seed: int = 3) -> NurbsSurface:
    """A bicubic height field with n x n poles: a slope in u plus noise, so that some
    rows near a plane are monotone and some turn."""
    rng = np.random.default_rng(seed)
    x = np.linspace(0, 1, n)
    u, v = np.meshgrid(x, x, indexing="ij")
    z = u + 0.02 * rng.standard_normal((n, n)) * (v > 0.5)
    knots = np.concatenate([[0] * 4, np.linspace(0, 1, n - 2)[1:-1], [1] * 4])
    return NurbsSurface(np.stack([u, v, z], -1), knots, knots, 3, 3)


@pytest.mark.parametrize("z", [-0.5, 0.02, 0.3, 0.5, 0.77, 1.5])
def test_monotone_rule_on_the_near_part_equals_the_whole_surface(z):
    """The rule runs on the spans near the plane only (prefilter._near_spans,
    prefilter._restricted); its answer must be the rule's answer on the whole
    surface's Bézier patches."""
    from surfprep.algorithms.characteristic import prefilter
    sheet, (centre, normal) = _many_span_sheet(), (np.array([0.0, 0.0, z]), np.array([0, 0, 1.0]))
    near = prefilter._near_spans(sheet, centre, normal, TOL)
    part = None if near is None else prefilter._restricted(sheet, near)
    whole = prefilter._monotone_patches(sheet, centre, normal, TOL)
    assert (part is None) == (z < -0.2 or z > 1.2)
    assert (True if part is None else prefilter._monotone_patches(part, centre, normal, TOL)) \
        == whole
    if part is not None and 0.2 < z < 0.8:
        assert part.n_control[0] < sheet.n_control[0]          # only a band of rows


@pytest.mark.parametrize("z", [0.02, 0.2, 0.4, 0.5])
def test_crossed_twice_on_the_near_part_equals_the_whole_surface(z):
    """_monotone_height asks _crossed_twice of the whole surface before restricting it
    when the near spans are most of it: every sign change of the sampled heights lies
    in the near spans, so both must answer alike (here on bumps that make rows cross
    the plane twice and a slope that crosses once)."""
    from surfprep.algorithms.characteristic import prefilter
    x = np.linspace(0, 1, 14)
    u, v = np.meshgrid(x, x, indexing="ij")
    height = 0.5 * u + 0.3 * np.exp(-((u - 0.5) ** 2 + (v - 0.6) ** 2) / 0.02)
    knots = np.concatenate([[0] * 4, np.linspace(0, 1, 12)[1:-1], [1] * 4])
    sheet = NurbsSurface(np.stack([u, v, height], -1), knots, knots, 3, 3)
    centre, normal = np.array([0.0, 0.0, z]), np.array([0, 0, 1.0])
    near = prefilter._near_spans(sheet, centre, normal, TOL)
    part = prefilter._restricted(sheet, near)
    assert part.n_control[0] < sheet.n_control[0]              # a true restriction
    assert prefilter._crossed_twice(sheet, centre, normal) == \
        prefilter._crossed_twice(part, centre, normal)


@pytest.mark.parametrize("poles", [6, 12])
@pytest.mark.parametrize("shift", [0.0, 0.3, 1.0 + 2e-7, 1.0 + 5e-7, 3.0])
def test_apart_equals_all_pairs_of_bezier_boxes(shift, poles):
    """The test (all pairs for 3 x 3 patches; for 9 x 9 span hulls in trees, then
    Bézier boxes of candidates only) against every pair of Bézier boxes."""
    from surfprep.algorithms.characteristic import prefilter
    a = _many_span_sheet(poles)
    b = NurbsSurface(a.control_points + [0, 0, shift], a.knots_u, a.knots_v, 3, 3)
    ba = a.patch_bounding_boxes()[0].reshape(-1, 2, 3)
    bb = b.patch_bounding_boxes()[0].reshape(-1, 2, 3)
    touch = np.all((ba[:, None, 0] <= bb[None, :, 1] + TOL)
                   & (bb[None, :, 0] <= ba[:, None, 1] + TOL), axis=-1).any()
    assert prefilter._apart(a, b, TOL) == (not touch)


def test_loops_refuse_the_monotone_rule_without_halving():
    """A plane through bumps cuts closed loops, each crossed twice by lines of both
    directions: prefilter._crossed_twice says so, both ways, from one sample grid (no span
    halvings); a sloped sheet, crossed once per line, is not refused that way."""
    from surfprep.algorithms.characteristic import prefilter
    up = np.array([0.0, 0.0, 1.0])
    bumps = several_bumps()
    top = bumps.evaluate(0.5, 0.72)[2]
    assert all(prefilter._crossed_twice(bumps, np.array([0, 0, top - 0.01]), up))
    assert no_loop_reason(bumps, horizontal_plane(top - 0.01), tol=TOL) is None
    assert not all(prefilter._crossed_twice(sloped_sheet(), np.array([0, 0, 0.3]), up))


def test_a_torus_cut_normal_to_its_axis_is_refused_without_halving(monkeypatch):
    """A torus cut just below its top by a plane normal to its axis: its heights do
    not change along the circles (a near patch flat along u within tol: halvings only
    halve those differences) and lines across the tube cross the plane twice, so the
    monotone rule is refused from the net as it is (it used to be tried on three
    halvings first); the answer is None (the certificate looks) as before."""
    from helpers.surfaces import torus_and_plane

    from surfprep.algorithms.characteristic import prefilter
    torus, plane = torus_and_plane(1e-6)
    centre, normal = plane.evaluate(0.5, 0.5), np.array([0.0, 0.0, 1.0])
    flat = prefilter._flat_directions(torus, centre, normal, TOL)
    twice = prefilter._crossed_twice(torus, centre, normal)
    assert all(f or t for f, t in zip(flat, twice)) and any(flat)
    halvings = []
    monkeypatch.setattr(prefilter, "_halved", lambda s: halvings.append(s) or s)
    assert no_loop_reason(torus, plane, tol=TOL) is None
    assert halvings == []
    # a sloped sheet is flat in no direction (its heights rise by more than tol)
    assert prefilter._flat_directions(sloped_sheet(), np.array([0, 0, 0.3]), normal, TOL) \
        == (False, False)
