"""Cross-checks of surfprep's NURBS evaluation against OpenCascade, and the
exactness of the conversions in ``surfprep.plugin.geom``.

Random B-spline curves and surfaces (degrees 1..9, rational or not, interior
knots of multiplicity up to the degree, clamped and periodic) are built, then
evaluated by surfprep and by OpenCascade's ``D0/D1/D2``.

Tolerance: ``1e-12`` relative to the largest magnitude of the same derivative
over the sample. Both codes evaluate the same sums of products with rounding
errors ``O(p * eps)`` relative to the size of the terms summed; for the k-th
derivative the terms are of the size of the derivative's typical magnitude over
the span (differences of control points times ``p / knot span``), not of its
value at one point, which may be near zero. The maximum magnitude over a sample
of points spread over the domain measures that size; comparing each value
against its own magnitude instead would fail spuriously where a derivative
crosses zero.

Where the two disagree by more than that, exact rational arithmetic decides:
the test passes only if surfprep's value is within ``RTOL_EXACT = 1e-13`` of
the exact one (``_exact_derivatives``, Fractions). This is needed: OpenCascade's
``D1``/``D2`` are less accurate than its ``D0`` and than surfprep, e.g. on a
degree-9 curve the point returned by ``Geom2d_BSplineCurve::D2`` was off by
5e-13 (relative) and second derivatives by 1.6e-13 where surfprep's were off by
2e-16 and 3e-16; a 600-example sweep of periodic degree-9 surfaces found a
second derivative 1.1e-11 apart. Points are compared with OpenCascade's ``D0``.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface
from OCP.Geom2d import Geom2d_BSplineCurve
from OCP.gp import gp_Pnt, gp_Pnt2d
from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array1OfPnt2d, TColgp_Array2OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_Array2OfReal

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.errors import ConversionError
from surfprep.plugin.occ.geom import (
    curve2d_to_occ,
    curve_from_occ,
    curve_to_occ,
    surface_from_occ,
    surface_to_occ,
)
from surfprep.plugin.occ_reference import SURFACE_ENTRIES, evaluate_curve, evaluate_surface

RTOL = 1e-12
RTOL_EXACT = 1e-13
SETTINGS = settings(max_examples=40, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


# ------------------------------------------------------------------ strategies
@st.composite
def knot_data(draw, degree: int, periodic: bool = False):
    """(distinct knot values, multiplicities) of a clamped or periodic knot vector.

    Clamped: end multiplicities degree + 1, interior ones in 1..degree.
    Periodic (OpenCascade's convention): first and last multiplicity equal, in
    1..degree; the number of poles is the sum of the multiplicities but the last.
    """
    n_interior = draw(st.integers(0 if not periodic else 1, 5))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    # Knot ranges of several sizes and offsets. The offset stays within a few
    # lengths of the range: surfprep and OpenCascade both form t - t_i, which
    # loses log10(|t| / span) digits; with |t| >> span those lost digits (not
    # the evaluation algorithms) would dominate the comparison.
    length = draw(st.sampled_from([1.0, 0.01, 7.5, 250.0]))
    start = length * draw(st.sampled_from([0.0, -1.0, 0.4, 3.25]))
    # distinct spans of varied length (ratio up to ~20), never tiny
    spans = rng.uniform(0.05, 1.0, n_interior + 1)
    values = start + length * np.concatenate([[0.0], np.cumsum(spans) / spans.sum()])
    interior = [draw(st.integers(1, degree)) for _ in range(n_interior)]
    if periodic:
        end = draw(st.integers(1, degree))
        mults = [end, *interior, end]
        # enough poles for OpenCascade (sum of mults but the last >= degree + 1)
        while sum(mults[:-1]) < degree + 1:
            values = np.append(values, values[-1] + length * 0.3)
            mults.insert(-1, 1)
    else:
        mults = [degree + 1, *interior, degree + 1]
    return values, mults


def _weights(draw, rational: bool, shape):
    if not rational:
        return None
    seed = draw(st.integers(0, 2**32 - 1))
    return np.random.default_rng(seed).uniform(0.3, 3.0, shape)


@st.composite
def bspline_curves(draw, dimension: int = 3, periodic: bool = False):
    """An OpenCascade Geom_BSplineCurve / Geom2d_BSplineCurve (built directly
    with OpenCascade's constructor, so periodic ones use its periodic form)."""
    degree = draw(st.integers(1, 9))
    values, mults = draw(knot_data(degree, periodic))
    n = sum(mults[:-1]) if periodic else sum(mults) - degree - 1
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    poles = rng.uniform(-10, 10, (n, dimension))
    weights = _weights(draw, draw(st.booleans()), (n,))
    array_cls, point_cls, curve_cls = ((TColgp_Array1OfPnt2d, gp_Pnt2d, Geom2d_BSplineCurve)
                                       if dimension == 2 else
                                       (TColgp_Array1OfPnt, gp_Pnt, Geom_BSplineCurve))
    occ_poles = array_cls(1, n)
    for i, p in enumerate(poles.tolist()):
        occ_poles.SetValue(i + 1, point_cls(*p))
    knots = _real_array(values)
    occ_mults = _int_array(mults)
    if weights is None:
        return curve_cls(occ_poles, knots, occ_mults, degree, periodic)
    return curve_cls(occ_poles, _real_array(weights), knots, occ_mults, degree, periodic)


@st.composite
def bspline_surfaces(draw, periodic_u: bool = False, periodic_v: bool = False):
    """An OpenCascade Geom_BSplineSurface from its own constructor."""
    du, dv = draw(st.integers(1, 9)), draw(st.integers(1, 9))
    uvals, umults = draw(knot_data(du, periodic_u))
    vvals, vmults = draw(knot_data(dv, periodic_v))
    nu = sum(umults[:-1]) if periodic_u else sum(umults) - du - 1
    nv = sum(vmults[:-1]) if periodic_v else sum(vmults) - dv - 1
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    poles = rng.uniform(-10, 10, (nu, nv, 3))
    weights = _weights(draw, draw(st.booleans()), (nu, nv))
    occ_poles = TColgp_Array2OfPnt(1, nu, 1, nv)
    for i in range(nu):
        for j in range(nv):
            occ_poles.SetValue(i + 1, j + 1, gp_Pnt(*poles[i, j].tolist()))
    args = (_real_array(uvals), _real_array(vvals), _int_array(umults), _int_array(vmults),
            du, dv, periodic_u, periodic_v)
    if weights is None:
        return Geom_BSplineSurface(occ_poles, *args)
    w = TColStd_Array2OfReal(1, nu, 1, nv)
    for i in range(nu):
        for j in range(nv):
            w.SetValue(i + 1, j + 1, float(weights[i, j]))
    return Geom_BSplineSurface(occ_poles, w, *args)


def _real_array(values) -> TColStd_Array1OfReal:
    arr = TColStd_Array1OfReal(1, len(values))
    for i, x in enumerate(values):
        arr.SetValue(i + 1, float(x))
    return arr


def _int_array(values) -> TColStd_Array1OfInteger:
    arr = TColStd_Array1OfInteger(1, len(values))
    for i, x in enumerate(values):
        arr.SetValue(i + 1, int(x))
    return arr


# ------------------------------------------------------------------ helpers
def _off_knot_parameters(knots: np.ndarray, degree: int, count: int, seed: int) -> np.ndarray:
    """Random parameters in the domain, at least 1e-6 (relative) away from every
    interior knot of multiplicity > degree - 2, where the second derivative may
    jump (order-1 derivatives jump at multiplicity degree) and the two codes may
    legitimately pick different sides."""
    n = knots.size - degree - 1
    a, b = knots[degree], knots[n]
    rng = np.random.default_rng(seed)
    t = rng.uniform(a, b, 4 * count)
    values, mults = np.unique(knots[degree + 1:n], return_counts=True)
    risky = values[mults > degree - 2]
    if risky.size:
        dist = np.min(np.abs(t[:, None] - risky[None, :]), axis=1)
        t = t[dist > 1e-6 * (b - a)]
    return t[:count]


def _describe(x) -> str:
    if isinstance(x, NurbsSurface):
        return (f"degrees {x.degree_u}, {x.degree_v}; knots_u {x.knots_u.tolist()}; "
                f"knots_v {x.knots_v.tolist()}; rational {x.weights is not None}")
    return f"degree {x.degree}; knots {x.knots.tolist()}; rational {x.weights is not None}"


def _exact_basis(knots: np.ndarray, degree: int, t: float, order: int) -> list[Fraction]:
    """All ``N_{i,degree}^{(order)}(t)`` in exact arithmetic (Cox-de Boor and the
    derivative recurrence ``N' = p (N_{i,p-1}/(t_{i+p}-t_i) - N_{i+1,p-1}/(...)``)."""
    knots = [Fraction(x) for x in knots.tolist()]
    t = Fraction(t)
    memo: dict[tuple[int, int, int], Fraction] = {}

    def ratio(num, den):
        return num / den if den != 0 else Fraction(0)

    def basis(i: int, p: int, k: int) -> Fraction:
        key = (i, p, k)
        if key not in memo:
            if k > p:
                value = Fraction(0)
            elif p == 0:
                value = Fraction(int(knots[i] <= t < knots[i + 1]))
            elif k == 0:
                value = (ratio(t - knots[i], knots[i + p] - knots[i]) * basis(i, p - 1, 0)
                         + ratio(knots[i + p + 1] - t, knots[i + p + 1] - knots[i + 1])
                         * basis(i + 1, p - 1, 0))
            else:
                value = p * (ratio(basis(i, p - 1, k - 1), knots[i + p] - knots[i])
                             - ratio(basis(i + 1, p - 1, k - 1), knots[i + p + 1] - knots[i + 1]))
            memo[key] = value
        return memo[key]

    return [basis(i, degree, order) for i in range(len(knots) - degree - 1)]


def _rational_derivatives(hom, order: int):
    """Cartesian derivatives ``S[k][l]`` from homogeneous ``hom[k][l]`` = (A..., w)
    (The NURBS Book, eq. 4.20), exact."""
    from math import comb
    out = [[None] * (order + 1) for _ in range(order + 1)]
    for k in range(order + 1):
        for m in range(order + 1 - k):
            v = list(hom[k][m][:-1])
            for i in range(k + 1):
                for j in range(m + 1):
                    if i == 0 and j == 0:
                        continue
                    c = comb(k, i) * comb(m, j) * hom[i][j][-1]
                    v = [a - c * b for a, b in zip(v, out[k - i][m - j])]
            out[k][m] = [a / hom[0][0][-1] for a in v]
    return out


def _exact_derivatives(x: NurbsCurve | NurbsSurface, params, order: int) -> np.ndarray:
    """Exact derivatives at one parameter (t,) or (u, v), in surfprep's layout."""
    hom_points = [[Fraction(c) for c in row] for row in
                  x.homogeneous_points().reshape(-1, x.dimension + 1).tolist()]
    if isinstance(x, NurbsCurve):
        # a curve as a surface constant in a second parameter: its derivatives are 0
        zero = [Fraction(0)] * (x.dimension + 1)
        hom = []
        for k in range(order + 1):
            b = _exact_basis(x.knots, x.degree, params[0], k)
            point = [sum(b[i] * hom_points[i][c] for i in range(len(b)) if b[i])
                     for c in range(x.dimension + 1)]
            hom.append([point] + [zero] * order)
        exact = _rational_derivatives(hom, order)
        return np.array([[float(c) for c in exact[k][0]] for k in range(order + 1)])
    n_v = x.n_control[1]
    bu = [_exact_basis(x.knots_u, x.degree_u, params[0], k) for k in range(order + 1)]
    bv = [_exact_basis(x.knots_v, x.degree_v, params[1], k) for k in range(order + 1)]
    hom = [[[sum(bu[k][i] * bv[m][j] * hom_points[i * n_v + j][c]
                 for i in range(len(bu[k])) if bu[k][i] for j in range(n_v) if bv[m][j])
             for c in range(x.dimension + 1)] for m in range(order + 1)] for k in range(order + 1)]
    exact = _rational_derivatives(hom, order)
    out = np.full((order + 1, order + 1, x.dimension), np.nan)
    for k in range(order + 1):
        for m in range(order + 1 - k):
            out[k, m] = [float(c) for c in exact[k][m]]
    return out


def _assert_close_per_order(ours: np.ndarray, ref: np.ndarray, entries, exact=None) -> None:
    """``ours`` and ``ref`` (m, ..., d) agree on each derivative entry to RTOL
    relative to that derivative's max magnitude over the sample; where they do
    not, ``exact(point_index)`` (exact arithmetic) must agree with ours to
    RTOL_EXACT (see module doc)."""
    for idx in entries:
        a = ours[(slice(None), *idx)]
        b = ref[(slice(None), *idx)]
        scale = max(np.max(np.linalg.norm(b, axis=-1)), 1e-300)
        err = np.linalg.norm(a - b, axis=-1) / scale
        if exact is None or err.max() <= RTOL:
            assert err.max() <= RTOL, f"derivative {idx}: relative error {err.max():.3g} > {RTOL}"
            continue
        for m in np.nonzero(err > RTOL)[0]:
            truth = exact(m)[idx]
            ours_err = np.linalg.norm(a[m] - truth) / scale
            note(f"derivative {idx} at point {m}: surfprep-OCC {err[m]:.3g}, surfprep-exact "
                 f"{ours_err:.3g}, OCC-exact {np.linalg.norm(b[m] - truth) / scale:.3g}")
            assert ours_err <= RTOL_EXACT, \
                f"derivative {idx}: surfprep off the exact value by {ours_err:.3g}"


def _check_curve(ours: NurbsCurve, occ, t: np.ndarray, order: int = 2) -> None:
    _assert_close_per_order(ours.derivatives(t, 0), evaluate_curve(occ, t, 0), [(0,)],
                            lambda m: _exact_derivatives(ours, (t[m],), 0))
    entries = [(k,) for k in range(1, order + 1)]
    _assert_close_per_order(ours.derivatives(t, order), evaluate_curve(occ, t, order), entries,
                            lambda m: _exact_derivatives(ours, (t[m],), order))


def _check_surface(ours: NurbsSurface, occ, u, v, order: int = 2) -> None:
    _assert_close_per_order(ours.derivatives(u, v, 0), evaluate_surface(occ, u, v, 0), [(0, 0)],
                            lambda m: _exact_derivatives(ours, (u[m], v[m]), 0))
    entries = [e for e in SURFACE_ENTRIES[order] if sum(e) > 0]
    _assert_close_per_order(ours.derivatives(u, v, order), evaluate_surface(occ, u, v, order),
                            entries, lambda m: _exact_derivatives(ours, (u[m], v[m]), order))


def _occ_curve_domain(curve) -> tuple[float, float]:
    return curve.FirstParameter(), curve.LastParameter()


# ------------------------------------------------------------ curve evaluation
@SETTINGS
@given(curve=bspline_curves(dimension=3), seed=st.integers(0, 2**32 - 1))
def test_curve_derivatives_match_occ(curve, seed):
    ours = curve_from_occ(curve)
    note(_describe(ours))
    t = _off_knot_parameters(ours.knots, ours.degree, 25, seed)
    _check_curve(ours, curve, t)


@SETTINGS
@given(curve=bspline_curves(dimension=2), seed=st.integers(0, 2**32 - 1))
def test_pcurve_derivatives_match_occ(curve, seed):
    ours = curve_from_occ(curve)
    note(_describe(ours))
    assert ours.dimension == 2
    t = _off_knot_parameters(ours.knots, ours.degree, 25, seed)
    _check_curve(ours, curve, t)


@SETTINGS
@given(curve=bspline_curves(dimension=3, periodic=True), seed=st.integers(0, 2**32 - 1))
def test_periodic_curve_matches_occ(curve, seed):
    assert curve.IsPeriodic()
    ours = curve_from_occ(curve)
    note(_describe(ours))
    assert ours.domain == pytest.approx(_occ_curve_domain(curve), rel=0, abs=1e-12)
    t = _off_knot_parameters(ours.knots, ours.degree, 25, seed)
    _check_curve(ours, curve, t)
    # the periodic OpenCascade curve is unchanged (conversion works on a copy)
    assert curve.IsPeriodic()


@SETTINGS
@given(curve=bspline_curves(dimension=3))
def test_curve_points_on_knots_match_occ(curve):
    """On every knot (any multiplicity <= degree the curve is continuous) the
    points agree; derivatives there are one-sided and not compared."""
    ours = curve_from_occ(curve)
    note(_describe(ours))
    t = np.unique(ours.knots)
    _assert_close_per_order(ours.derivatives(t, 0), evaluate_curve(curve, t, 0), [(0,)])


def _exact_point(curve: NurbsCurve, t: float) -> np.ndarray:
    """de Boor's algorithm on the homogeneous points in exact rational arithmetic."""
    knots = [Fraction(x) for x in curve.knots.tolist()]
    p, n, t = curve.degree, curve.n_control, Fraction(t)
    span = max(i for i in range(p, n) if knots[i] <= t)
    hom = [[Fraction(x) for x in row] for row in curve.homogeneous_points().tolist()]
    d = [hom[j + span - p][:] for j in range(p + 1)]
    for r in range(1, p + 1):
        for j in range(p, r - 1, -1):
            i = j + span - p
            a = (t - knots[i]) / (knots[i + p + 1 - r] - knots[i])
            d[j] = [(1 - a) * x + a * y for x, y in zip(d[j - 1], d[j])]
    return np.array([float(x / d[p][-1]) for x in d[p][:-1]])


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(curve=bspline_curves(dimension=2), seed=st.integers(0, 2**32 - 1))
def test_curve_derivatives_match_exact_arithmetic(curve, seed):
    """surfprep is within RTOL_EXACT of exact arithmetic (the arbiter when
    surfprep and OpenCascade disagree); the exact evaluator itself is checked
    against an independent exact de Boor evaluation of the points."""
    ours = curve_from_occ(curve)
    note(_describe(ours))
    t = _off_knot_parameters(ours.knots, ours.degree, 4, seed)
    exact = np.array([_exact_derivatives(ours, (x,), 2) for x in t.tolist()])
    assert np.array_equal(exact[:, 0], np.array([_exact_point(ours, x) for x in t.tolist()]))
    computed = ours.derivatives(t, 2)
    for k in range(3):
        scale = max(np.max(np.linalg.norm(exact[:, k], axis=1)), 1e-300)
        assert np.max(np.linalg.norm(computed[:, k] - exact[:, k], axis=1)) <= RTOL_EXACT * scale


# ---------------------------------------------------------- surface evaluation
def _surface_parameters(ours: NurbsSurface, seed: int, count: int = 25):
    u = _off_knot_parameters(ours.knots_u, ours.degree_u, count, seed)
    v = _off_knot_parameters(ours.knots_v, ours.degree_v, count, seed + 1)
    m = min(u.size, v.size)
    return u[:m], v[:m]


@SETTINGS
@given(surface=bspline_surfaces(), seed=st.integers(0, 2**31))
def test_surface_derivatives_match_occ(surface, seed):
    ours = surface_from_occ(surface)
    note(_describe(ours))
    u, v = _surface_parameters(ours, seed)
    _check_surface(ours, surface, u, v)


@SETTINGS
@given(surface=bspline_surfaces(periodic_u=True), periodic_v=st.booleans(),
       seed=st.integers(0, 2**31))
def test_periodic_surface_matches_occ(surface, periodic_v, seed):
    assert surface.IsUPeriodic()
    ours = surface_from_occ(surface)
    note(_describe(ours))
    u0, u1, v0, v1 = surface.Bounds()
    assert ours.domain == pytest.approx((u0, u1, v0, v1), rel=0, abs=1e-12)
    u, v = _surface_parameters(ours, seed)
    _check_surface(ours, surface, u, v)


@SETTINGS
@given(surface=bspline_surfaces(periodic_u=True, periodic_v=True), seed=st.integers(0, 2**31))
def test_doubly_periodic_surface_matches_occ(surface, seed):
    ours = surface_from_occ(surface)
    note(_describe(ours))
    u, v = _surface_parameters(ours, seed)
    _check_surface(ours, surface, u, v, order=1)


@SETTINGS
@given(surface=bspline_surfaces())
def test_surface_points_on_knot_lines_match_occ(surface):
    ours = surface_from_occ(surface)
    note(_describe(ours))
    u, v = np.meshgrid(np.unique(ours.knots_u), np.unique(ours.knots_v), indexing="ij")
    _assert_close_per_order(ours.derivatives(u.ravel(), v.ravel(), 0),
                            evaluate_surface(surface, u.ravel(), v.ravel(), 0), [(0, 0)])


@SETTINGS
@given(surface=bspline_surfaces(), seed=st.integers(0, 2**31))
def test_non_periodic_surface_beyond_its_domain_matches_occ(surface, seed):
    # OpenCascade continues a B-spline surface beyond its domain by its end spans'
    # polynomials, as ours does: images of pcurves running past the domain are
    # evaluated as NURBS surfaces on that ground (plugin/heal/shared_edges.py)
    ours = surface_from_occ(surface)
    note(_describe(ours))
    u0, u1, v0, v1 = ours.domain
    rng = np.random.default_rng(seed)
    u = u0 + (u1 - u0) * rng.uniform(-0.02, 1.02, 25)
    v = v0 + (v1 - v0) * rng.uniform(-0.02, 1.02, 25)
    u[:4] = u0 - 1e-3 * (u1 - u0), u1 + 1e-3 * (u1 - u0), u0 - 1e-9, u1 + 1e-9
    _assert_close_per_order(ours.derivatives(u, v, 0), evaluate_surface(surface, u, v, 0),
                            [(0, 0)])


# ------------------------------------------------------------------ round trips
@SETTINGS
@given(surface=bspline_surfaces())
def test_surface_round_trip_is_exact(surface):
    ours = surface_from_occ(surface)
    note(_describe(ours))
    back = surface_from_occ(surface_to_occ(ours))
    assert np.array_equal(back.knots_u, ours.knots_u)
    assert np.array_equal(back.knots_v, ours.knots_v)
    assert np.array_equal(back.control_points, ours.control_points)
    assert (back.weights is None) == (ours.weights is None)
    if ours.weights is not None:
        assert np.array_equal(back.weights, ours.weights)
    assert (back.degree_u, back.degree_v) == (ours.degree_u, ours.degree_v)


@SETTINGS
@given(curve=bspline_curves(dimension=3))
def test_curve_round_trip_is_exact(curve):
    ours = curve_from_occ(curve)
    note(_describe(ours))
    back = curve_from_occ(curve_to_occ(ours))
    assert np.array_equal(back.knots, ours.knots)
    assert np.array_equal(back.control_points, ours.control_points)
    assert (back.weights is None) == (ours.weights is None)
    if ours.weights is not None:
        assert np.array_equal(back.weights, ours.weights)


@SETTINGS
@given(curve=bspline_curves(dimension=2))
def test_pcurve_round_trip_is_exact(curve):
    ours = curve_from_occ(curve)
    note(_describe(ours))
    back = curve_from_occ(curve2d_to_occ(ours))
    assert np.array_equal(back.knots, ours.knots)
    assert np.array_equal(back.control_points, ours.control_points)


def test_rational_with_equal_weights_stays_rational_in_occ():
    """Equal weights: surfprep keeps the weights array; OpenCascade then reports
    a non-rational curve (it drops equal weights), and reading back gives None."""
    curve = NurbsCurve(np.eye(3), [0, 0, 0, 1, 1, 1], 2, np.full(3, 2.0))
    back = curve_from_occ(curve_to_occ(curve))
    assert np.allclose(back.evaluate(np.linspace(0, 1, 5)), curve.evaluate(np.linspace(0, 1, 5)))


def test_conversion_errors():
    curve = NurbsCurve(np.zeros((2, 2)) + [[0, 0], [1, 1]], [0, 0, 1, 1], 1)
    with pytest.raises(ConversionError):
        curve_to_occ(curve)           # 2D curve to a 3D OpenCascade curve
    with pytest.raises(ConversionError):
        surface_to_occ(curve)         # not a surface


# ------------------------------------------------------------------ slow sweep
@pytest.mark.slow
@settings(max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(surface=st.one_of(bspline_surfaces(), bspline_surfaces(periodic_u=True),
                         bspline_surfaces(periodic_u=True, periodic_v=True)),
       seed=st.integers(0, 2**31))
def test_surface_derivatives_match_occ_sweep(surface, seed):
    ours = surface_from_occ(surface)
    note(_describe(ours))
    u, v = _surface_parameters(ours, seed, 60)
    _check_surface(ours, surface, u, v)


@pytest.mark.slow
@settings(max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(curve=st.one_of(bspline_curves(dimension=3), bspline_curves(dimension=2),
                       bspline_curves(dimension=3, periodic=True)),
       seed=st.integers(0, 2**32 - 1))
def test_curve_derivatives_match_occ_sweep(curve, seed):
    ours = curve_from_occ(curve)
    note(_describe(ours))
    _check_curve(ours, curve, _off_knot_parameters(ours.knots, ours.degree, 60, seed))
