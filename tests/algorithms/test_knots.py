"""Knot insertion, refinement, clamping, periodic input, split and restrict."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.strategies import (
    assert_same_curve,
    assert_same_surface,
    curve_samples,
    curves,
    make_curve,
    make_surface,
    surface_samples,
    surfaces,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms import (
    Direction,
    NurbsCurve,
    NurbsSurface,
    clamp,
    insert_knot,
    insert_knot_array,
    periodic_to_clamped,
    refine,
    refine_surface,
    restrict,
    restrict_surface,
    split,
    split_surface,
)
from surfprep.errors import InvalidGeometryError

SETTINGS = settings(max_examples=60, deadline=None)


def multiplicity(knots, x):
    return int(np.count_nonzero(knots == x))


def is_clamped(knots, degree):
    return (np.all(knots[:degree + 1] == knots[0])
            and np.all(knots[-degree - 1:] == knots[-1]))


# --------------------------------------------------------------- insertion
@SETTINGS
@given(curves(), st.floats(0, 1), st.data())
def test_insert_knot_keeps_geometry(curve, fraction, data):
    lo, hi = curve.domain
    t = lo + fraction * (hi - lo)
    s = multiplicity(curve.knots, t)
    if s >= curve.degree:                   # already full: use the first span's midpoint
        t = 0.5 * (lo + curve.knots[np.searchsorted(curve.knots, lo, "right")])
        s = multiplicity(curve.knots, t)
    r = data.draw(st.integers(1, curve.degree - s))
    result = insert_knot(curve, t, r)
    assert result.degree == curve.degree
    assert result.n_control == curve.n_control + r
    assert multiplicity(result.knots, t) == s + r
    assert (result.weights is None) == (curve.weights is None)
    # the old knots are all still there, with their exact values
    np.testing.assert_array_equal(np.sort(np.concatenate([curve.knots, np.full(r, t)])),
                                  result.knots)
    assert_same_curve(result, curve, curve_samples(curve))


def test_insert_knot_matches_hand_computed_quadratic():
    # Quadratic on [0,0,0,1,1,1] with poles P0, P1, P2: inserting 1/2 gives the
    # de Casteljau midpoints (P0+P1)/2 and (P1+P2)/2.
    poles = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 0.0]])
    curve = NurbsCurve(poles, [0, 0, 0, 1, 1, 1], 2)
    result = insert_knot(curve, 0.5)
    expected = [poles[0], (poles[0] + poles[1]) / 2, (poles[1] + poles[2]) / 2, poles[2]]
    np.testing.assert_allclose(result.control_points, expected, atol=1e-15)


def test_insert_knot_array_carries_trailing_axes():
    curve = make_curve(3, 3, 2, 2, rational=True)
    pw = curve.homogeneous_points()
    stacked = np.stack([pw, 2 * pw], axis=1)                     # (n, 2, d+1)
    new, knots = insert_knot_array(stacked, curve.knots, 3, 0.5 * sum(curve.domain), 2)
    single, knots1 = insert_knot_array(pw, curve.knots, 3, 0.5 * sum(curve.domain), 2)
    np.testing.assert_array_equal(knots, knots1)
    np.testing.assert_allclose(new[:, 0], single, rtol=0, atol=1e-14)
    np.testing.assert_allclose(new[:, 1], 2 * single, rtol=0, atol=1e-13)


@pytest.mark.parametrize("value, r, match", [
    (-100.0, 1, "outside the domain"),
    (np.nan, 1, "finite"),
    (np.inf, 1, "finite"),
    (None, 1, "real number"),
    ("mid", 0, "integer >= 1"),
    ("mid", 1.5, "integer >= 1"),
    ("mid", 4, "multiplicity"),
    ("start", 1, "multiplicity"),
])
def test_insert_knot_rejects_bad_arguments(value, r, match):
    curve = make_curve(1, 3, 0, 1, rational=False)
    lo, hi = curve.domain
    if value == "mid":
        value = 0.5 * (lo + hi)
    elif value == "start":                  # clamped end: multiplicity already p + 1
        value = lo
    with pytest.raises(InvalidGeometryError, match=match):
        insert_knot(curve, value, r)


def test_insert_knot_over_existing_multiplicity_raises():
    curve = NurbsCurve(np.zeros((7, 2)), [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2], 3)
    with pytest.raises(InvalidGeometryError, match="from 3 to 4 > degree = 3"):
        insert_knot(curve, 1.0)


# --------------------------------------------------------------- refinement
@SETTINGS
@given(curves(), st.lists(st.floats(0, 1), min_size=1, max_size=8))
def test_refine_keeps_geometry(curve, fractions):
    lo, hi = curve.domain
    new = np.round(lo + np.array(fractions) * (hi - lo), 3)
    new = np.clip(new, lo, hi)
    allowed = [x for x in new if multiplicity(curve.knots, x) + np.count_nonzero(new == x)
               <= curve.degree]
    result = refine(curve, allowed)
    np.testing.assert_array_equal(np.sort(np.concatenate([curve.knots, allowed])), result.knots)
    assert_same_curve(result, curve, curve_samples(curve))


def test_refine_rejects_bad_knots():
    curve = make_curve(2, 2, 1, 1, rational=True)
    lo, hi = curve.domain
    mid = 0.5 * (lo + hi)
    with pytest.raises(InvalidGeometryError, match="outside the domain"):
        refine(curve, [mid, hi + 1])
    with pytest.raises(InvalidGeometryError, match="NaN"):
        refine(curve, [mid, np.nan])
    with pytest.raises(InvalidGeometryError, match="multiplicity 3 > degree = 2"):
        refine(curve, [mid, mid, mid])
    assert refine(curve, []).n_control == curve.n_control


# ------------------------------------------------------------ split/restrict
@SETTINGS
@given(curves(), st.floats(0.05, 0.95))
def test_split_pieces_match_original(curve, fraction):
    lo, hi = curve.domain
    t = lo + fraction * (hi - lo)
    left, right = split(curve, t)
    assert left.domain == (lo, t) and right.domain == (t, hi)
    assert is_clamped(left.knots, curve.degree) and is_clamped(right.knots, curve.degree)
    assert_same_curve(left, curve, curve_samples(curve, 200, lo, t))
    assert_same_curve(right, curve, curve_samples(curve, 200, t, hi))
    # the pieces meet: last pole of the left is the first of the right
    np.testing.assert_allclose(left.control_points[-1], right.control_points[0], atol=1e-12)


@SETTINGS
@given(curves(clamped=False) | curves(), st.floats(0, 1), st.floats(0, 1))
def test_restrict_keeps_original_parameters(curve, f0, f1):
    lo, hi = curve.domain
    a, b = sorted([lo + f0 * (hi - lo), lo + f1 * (hi - lo)])
    if b - a < 1e-3 * (hi - lo):
        a, b = lo, hi
    piece = restrict(curve, a, b)
    assert piece.domain == (a, b)
    inside = curve.knots[(curve.knots > a) & (curve.knots < b)]
    np.testing.assert_array_equal(piece.knots[curve.degree + 1:-curve.degree - 1], inside)
    assert_same_curve(piece, curve, curve_samples(curve, 200, a, b))


@pytest.mark.parametrize("a, b, match", [
    (0.6, 0.4, "need a < b"),
    (0.5, 0.5, "need a < b"),
    (-1.0, 0.5, "outside the domain"),
    (0.5, np.nan, "finite"),
])
def test_restrict_rejects_bad_interval(a, b, match):
    curve = NurbsCurve(np.eye(4, 3), [0, 0, 0, 0, 1, 1, 1, 1], 3)
    with pytest.raises(InvalidGeometryError, match=match):
        restrict(curve, a, b)


def test_split_at_domain_end_raises():
    curve = NurbsCurve(np.eye(4, 3), [0, 0, 0, 0, 1, 1, 1, 1], 3)
    with pytest.raises(InvalidGeometryError, match="interior of the domain"):
        split(curve, 1.0)


# -------------------------------------------------------------------- clamp
@SETTINGS
@given(curves(clamped=False))
def test_clamp_unclamped_curve(curve):
    result = clamp(curve)
    assert result.domain == curve.domain
    assert is_clamped(result.knots, curve.degree)
    assert_same_curve(result, curve, curve_samples(curve))
    lo, hi = curve.domain
    np.testing.assert_allclose(result.control_points[[0, -1]], curve.evaluate([lo, hi]),
                               atol=1e-12 * np.abs(curve.control_points).max())


def test_clamp_of_clamped_curve_is_identity():
    curve = make_curve(5, 4, 3, 2, rational=True)
    result = clamp(curve)
    np.testing.assert_array_equal(result.knots, curve.knots)
    np.testing.assert_array_equal(result.control_points, curve.control_points)
    np.testing.assert_array_equal(result.weights, curve.weights)


def test_clamp_uniform_cubic_start_pole_is_b_spline_average():
    # uniform cubic: C(t_p) = (P0 + 4 P1 + P2) / 6
    poles = np.random.default_rng(0).normal(size=(6, 3))
    curve = NurbsCurve(poles, np.arange(10.0), 3)
    result = clamp(curve)
    np.testing.assert_allclose(result.control_points[0],
                               (poles[0] + 4 * poles[1] + poles[2]) / 6, atol=1e-14)


# ----------------------------------------------------------------- periodic
def uniform_cubic_periodic(poles, t):
    """Explicit uniform cubic periodic B-spline on knots 0..n (independent formula)."""
    n = len(poles)
    i = np.minimum(np.floor(t).astype(int), n - 1)
    s = (t - i)[:, None]
    b = [(1 - s) ** 3 / 6, (3 * s**3 - 6 * s**2 + 4) / 6,
         (-3 * s**3 + 3 * s**2 + 3 * s + 1) / 6, s**3 / 6]
    return sum(b[k] * poles[(i + k) % n] for k in range(4))


def test_periodic_uniform_cubic_matches_explicit_formula():
    poles = np.random.default_rng(7).normal(size=(7, 3))
    curve = periodic_to_clamped(poles, 3)
    assert curve.domain == (0.0, 7.0)
    assert is_clamped(curve.knots, 3)
    t = np.linspace(0, 7, 300)
    np.testing.assert_allclose(curve.evaluate(t), uniform_cubic_periodic(poles, t),
                               rtol=0, atol=1e-13)


@pytest.mark.parametrize("degree", [1, 2, 3, 5, 8])
@pytest.mark.parametrize("rational", [False, True])
def test_periodic_nonuniform_is_closed_and_smooth_at_seam(degree, rational):
    rng = np.random.default_rng(degree)
    n = degree + 4
    poles = rng.normal(size=(n, 3))
    gaps = rng.uniform(0.5, 1.5, n)
    knots = 0.3 + 4.7 * np.concatenate([[0.0], np.cumsum(gaps) / gaps.sum()])
    knots[-1] = 5.0
    weights = rng.uniform(0.5, 2, n) if rational else None
    curve = periodic_to_clamped(poles, degree, knots, weights)
    assert curve.domain == (0.3, 5.0)
    ders = curve.derivatives([0.3, 5.0], degree - 1)           # C^{p-1} across the seam
    for k in range(degree):
        scale = np.abs(ders[0, k]).max() + 1     # k-th derivatives lose about a digit each
        np.testing.assert_allclose(ders[0, k], ders[1, k], rtol=0, atol=1e-13 * 10**k * scale)


def test_periodic_geometry_matches_unclamped_periodic_representation():
    rng = np.random.default_rng(3)
    poles, p = rng.normal(size=(6, 2)), 2
    curve = periodic_to_clamped(poles, p, [0, 1, 1.5, 3, 4, 4.2, 6])
    # unclamped representation written by hand: poles P0..P5, P0, P1; knots extended
    flat = np.array([4 - 6, 4.2 - 6, 0, 1, 1.5, 3, 4, 4.2, 6, 7, 7.5])
    reference = NurbsCurve(poles[[0, 1, 2, 3, 4, 5, 0, 1]], flat, p)
    assert_same_curve(curve, reference, np.linspace(0, 6, 200))


def test_periodic_rejects_bad_input():
    poles = np.zeros((5, 3))
    with pytest.raises(InvalidGeometryError, match="shape"):
        periodic_to_clamped(poles, 2, np.arange(5.0))
    with pytest.raises(InvalidGeometryError, match="non-decreasing"):
        periodic_to_clamped(poles, 2, [0, 2, 1, 3, 4, 5])
    with pytest.raises(InvalidGeometryError, match="at least 4 poles"):
        periodic_to_clamped(poles[:3], 3)
    with pytest.raises(InvalidGeometryError, match="multiplicity 3 > degree = 2"):
        periodic_to_clamped(poles, 2, [0, 1, 1, 1, 4, 5])
    with pytest.raises(InvalidGeometryError, match="multiplicity 3 > degree = 2"):
        periodic_to_clamped(poles, 2, [0, 0, 1, 2, 5, 5])        # 0 and 5 are one knot
    with pytest.raises(InvalidGeometryError, match="weights"):
        periodic_to_clamped(poles, 2, None, np.ones(4))


# ----------------------------------------------------------------- surfaces
@settings(max_examples=40, deadline=None)
@given(surfaces(), st.sampled_from([Direction.U, Direction.V, "u", "v"]), st.floats(0.05, 0.95))
def test_surface_insert_refine_split_keep_geometry(surface, direction, fraction):
    u0, u1, v0, v1 = surface.domain
    along_u = direction in (Direction.U, "u")
    lo, hi = (u0, u1) if along_u else (v0, v1)
    degree = surface.degree_u if along_u else surface.degree_v
    knots = surface.knots_u if along_u else surface.knots_v
    value = lo + fraction * (hi - lo)
    u, v = surface_samples(surface)
    r = degree - multiplicity(knots, value)
    if r >= 1:
        inserted = surface.insert_knot(value, direction, r)
        assert inserted.n_control[0 if along_u else 1] == surface.n_control[0 if along_u else 1] + r
        assert_same_surface(inserted, surface, u, v)
    refined = refine_surface(surface, [value] * r, direction)
    assert_same_surface(refined, surface, u, v)
    first, second = split_surface(surface, value, direction)
    if along_u:
        box1, box2 = (u0, value, v0, v1), (value, u1, v0, v1)
    else:
        box1, box2 = (u0, u1, v0, value), (u0, u1, value, v1)
    assert first.domain == box1 and second.domain == box2
    assert_same_surface(first, surface, *surface_samples(surface, 40, box1))
    assert_same_surface(second, surface, *surface_samples(surface, 40, box2))


@settings(max_examples=40, deadline=None)
@given(surfaces(clamped=False) | surfaces(), st.floats(0, 0.45), st.floats(0.55, 1),
       st.floats(0, 0.45), st.floats(0.55, 1))
def test_restrict_surface(surface, fu0, fu1, fv0, fv1):
    u0, u1, v0, v1 = surface.domain
    box = (u0 + fu0 * (u1 - u0), u0 + fu1 * (u1 - u0), v0 + fv0 * (v1 - v0),
           v0 + fv1 * (v1 - v0))
    patch = restrict_surface(surface, *box)
    assert patch.domain == box
    assert_same_surface(patch, surface, *surface_samples(surface, 40, box))
    clamped = surface.clamp()
    assert clamped.domain == surface.domain
    assert_same_surface(clamped, surface, *surface_samples(surface))


def test_surface_direction_is_checked():
    surface = make_surface(0, 2, 2, 1, 1, 1, rational=False)
    with pytest.raises(InvalidGeometryError, match="direction"):
        surface.insert_knot(0.5 * sum(surface.domain[:2]), "w")
    with pytest.raises(InvalidGeometryError, match="direction"):
        surface.insert_knot(0.5 * sum(surface.domain[:2]), True)
    with pytest.raises(InvalidGeometryError, match="outside the domain"):
        surface.insert_knot(surface.domain[3] + 1, Direction.V)


def test_curve_facades_delegate():
    curve = make_curve(11, 3, 2, 1, rational=True)
    lo, hi = curve.domain
    mid = 0.5 * (lo + hi)
    t = curve_samples(curve)
    assert_same_curve(curve.insert_knot(mid, 2), curve, t)
    assert_same_curve(curve.refine([mid, mid]), curve, t)
    assert_same_curve(curve.restrict(lo, mid), curve, t[t <= mid])
    assert curve.split(mid)[1].domain == (mid, hi)
    assert_same_curve(curve.clamp(), curve, t)


@pytest.mark.parametrize("degrees", [(9, 1), (1, 9), (8, 7)])
def test_high_degree_surface_restrict_and_insert(degrees):
    surface = make_surface(sum(degrees), *degrees, 2, 2, 3, rational=True)
    u0, u1, v0, v1 = surface.domain
    box = (u0 + 0.1 * (u1 - u0), u1 - 0.3 * (u1 - u0), v0 + 0.25 * (v1 - v0), v1)
    assert_same_surface(surface.restrict(*box), surface, *surface_samples(surface, 40, box))
    mid_v = 0.5 * (v0 + v1)
    inserted = surface.insert_knot(mid_v, Direction.V, degrees[1] - multiplicity(
        surface.knots_v, mid_v))
    assert_same_surface(inserted, surface, *surface_samples(surface))


@pytest.mark.parametrize("degree", range(1, 10))
@pytest.mark.parametrize("rational", [False, True])
def test_every_degree_keeps_geometry(degree, rational):
    # deterministic sweep next to the hypothesis tests: multiple interior knots
    # (multiplicities up to the degree), non-unit domain, rational or not
    curve = make_curve(1000 + degree, degree, 4, degree, rational)
    unclamped = make_curve(2000 + degree, degree, 3, degree, rational, clamped=False)
    t = curve_samples(curve)
    lo, hi = curve.domain
    mid = lo + 0.37 * (hi - lo)
    r = max(degree - multiplicity(curve.knots, mid), 1)
    if multiplicity(curve.knots, mid) < degree:
        assert_same_curve(insert_knot(curve, mid, r), curve, t)
    assert_same_curve(refine(curve, np.linspace(lo, hi, 7)[1:-1]), curve, t)
    left, right = split(curve, mid)
    assert_same_curve(left, curve, t[t <= mid])
    assert_same_curve(right, curve, t[t >= mid])
    clamped = clamp(unclamped)
    assert is_clamped(clamped.knots, degree)
    assert_same_curve(clamped, unclamped, curve_samples(unclamped))


def test_a_split_a_rounding_off_a_full_knot_moves_the_knot_onto_it():
    """A half cylinder of two rational quadratic quarter arcs joined at u = pi/2 (a knot of
    multiplicity 2), split a rounding below it (as 0.5 * pi computed from a fraction is):
    the double knot is moved onto the cut; the split inserted two more knots beside it, the piece began
    with a span 6e-16 wide, and its S_u at the join was (-151, 18.7, -7) where the surface's
    is (0, -45, 0) (its normal turned 160 degrees; a grid on it counted 30 folded cells)."""
    w = np.sqrt(0.5)
    cp = np.array([[[0, 1, 0], [0, 1, 1]], [[1, 1, 0], [1, 1, 1]], [[1, 0, 0], [1, 0, 1]],
                   [[1, -1, 0], [1, -1, 1]], [[0, -1, 0], [0, -1, 1]]], dtype=float)
    weights = np.array([[1, 1], [w, w], [1, 1], [w, w], [1, 1]])
    knots_u = [0, 0, 0, np.pi / 2, np.pi / 2, np.pi, np.pi, np.pi]
    half = NurbsSurface(cp, knots_u, [0, 0, 1, 1], 2, 1, weights)
    cut = 0.5 * 3.141592653589793 * (1 - 4e-16)
    assert cut != np.pi / 2
    low, high = half.split(cut, "u")
    assert low.domain[1] == cut == high.domain[0]                  # the cut asked for
    for piece in (low, high):
        ku = np.asarray(piece.knots_u)
        assert np.count_nonzero(ku == ku[0]) == 3 and np.count_nonzero(ku == ku[-1]) == 3
    at = np.pi / 2
    one_sided = half.derivatives(at + 1e-9, 0.5, 1)[1, 0]
    assert np.allclose(high.derivatives(high.domain[0], 0.5, 1)[1, 0], one_sided, atol=1e-6)
    assert np.allclose(low.evaluate(low.domain[1], 0.3), half.evaluate(at, 0.3), atol=1e-12)


def test_a_cut_near_a_knot_but_not_a_rounding_off_it_leaves_the_knot():
    """Hypothesis's case: a bilinear surface restricted from 1e-12 of its v domain above
    the knot where that domain starts. A snap of knots within 1e-12 of the span moved that knot onto
    the cut, shifting the geometry over the short span by 1.6e-11 of its size; only knots
    a rounding off a cut (64 roundings) are moved now, and the piece is the surface."""
    cp = np.array([[[0.87249983, 8.70144848, 6.31707108], [-9.94523, 7.14808553, -9.32828849]],
                   [[4.59310893, -6.48688759, 7.26357845], [0.8292244, -4.00576219, -1.54625558]]])
    s = NurbsSurface(cp, [4.52409183e-03, 1.36961687e+00, 3.89301723e+00, 5.19642324e+00],
                     [-4.99627532, 3.13270239, 10.47836922, 19.50984133], 1, 1)
    u0, u1, v0, v1 = s.domain
    box = (u0, u1, v0 + 1e-12 * (v1 - v0), v1)
    piece = restrict_surface(s, *box)
    assert piece.domain == box
    assert_same_surface(piece, s, *surface_samples(s, 40, box))
