"""Random NURBS curves and surfaces for the algorithm tests (hypothesis strategies).

The shapes (degree, knot multiplicities, domain, rational or not) are drawn by
hypothesis; the coordinates come from a numpy generator seeded by hypothesis,
which keeps generation fast. Domains are deliberately not [0, 1] so that code
which renormalizes parameters fails.
"""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from surfprep.algorithms import NurbsCurve, NurbsSurface

MAX_DEGREE = 9


def random_knots(rng: np.random.Generator, degree: int, n_breaks: int, max_mult: int,
                 clamped: bool = True) -> np.ndarray:
    """Full knot vector with ``n_breaks`` interior breakpoints of multiplicity 1..max_mult.

    Domain ``[a, a + length]`` with random ``a`` and length; interior breakpoints
    at least 2 % of the length apart. Unclamped vectors get distinct end knots.
    """
    a = float(rng.uniform(-5, 5))
    length = float(rng.uniform(0.5, 8))
    while True:
        breaks = np.sort(rng.uniform(a, a + length, n_breaks))
        gaps = np.diff(np.concatenate([[a], breaks, [a + length]]))
        if gaps.min() > 0.02 * length:
            break
    mult = rng.integers(1, max_mult + 1, n_breaks)
    inner = np.repeat(breaks, mult)
    if clamped:
        return np.concatenate([np.full(degree + 1, a), inner, np.full(degree + 1, a + length)])
    step = length / (n_breaks + 1)
    left = a - step * np.arange(degree, 0, -1) * rng.uniform(0.5, 1.5, degree)
    right = a + length + step * np.arange(1, degree + 1) * rng.uniform(0.5, 1.5, degree)
    return np.concatenate([np.sort(left), [a], inner, [a + length], np.sort(right)])


def make_curve(seed: int, degree: int, n_breaks: int, max_mult: int, rational: bool,
               dimension: int = 3, clamped: bool = True) -> NurbsCurve:
    rng = np.random.default_rng(seed)
    knots = random_knots(rng, degree, n_breaks, max_mult, clamped)
    n = knots.size - degree - 1
    points = rng.uniform(-10, 10, (n, dimension))
    weights = rng.uniform(0.3, 3.0, n) if rational else None
    return NurbsCurve(points, knots, degree, weights)


def make_surface(seed: int, degree_u: int, degree_v: int, breaks_u: int, breaks_v: int,
                 max_mult: int, rational: bool, clamped: bool = True) -> NurbsSurface:
    rng = np.random.default_rng(seed)
    ku = random_knots(rng, degree_u, breaks_u, min(max_mult, degree_u), clamped)
    kv = random_knots(rng, degree_v, breaks_v, min(max_mult, degree_v), clamped)
    nu, nv = ku.size - degree_u - 1, kv.size - degree_v - 1
    points = rng.uniform(-10, 10, (nu, nv, 3))
    weights = rng.uniform(0.3, 3.0, (nu, nv)) if rational else None
    return NurbsSurface(points, ku, kv, degree_u, degree_v, weights)


@st.composite
def curves(draw, min_degree: int = 1, max_degree: int = MAX_DEGREE, rational=None,
           clamped: bool = True, dimension=None, max_breaks: int = 4) -> NurbsCurve:
    """Curves of degree min..max, 0..max_breaks interior breakpoints of multiplicity 1..p."""
    degree = draw(st.integers(min_degree, max_degree))
    n_breaks = draw(st.integers(0, max_breaks))
    max_mult = draw(st.integers(1, degree))
    is_rational = draw(st.booleans()) if rational is None else rational
    dim = draw(st.sampled_from([2, 3])) if dimension is None else dimension
    seed = draw(st.integers(0, 2**32 - 1))
    return make_curve(seed, degree, n_breaks, max_mult, is_rational, dim, clamped)


@st.composite
def surfaces(draw, max_degree: int = 5, rational=None, clamped: bool = True,
             max_breaks: int = 3) -> NurbsSurface:
    """Surfaces of degrees 1..max_degree per direction, multiple interior knots."""
    degree_u = draw(st.integers(1, max_degree))
    degree_v = draw(st.integers(1, max_degree))
    breaks_u = draw(st.integers(0, max_breaks))
    breaks_v = draw(st.integers(0, max_breaks))
    max_mult = draw(st.integers(1, max(degree_u, degree_v)))
    is_rational = draw(st.booleans()) if rational is None else rational
    seed = draw(st.integers(0, 2**32 - 1))
    return make_surface(seed, degree_u, degree_v, breaks_u, breaks_v, max_mult, is_rational,
                        clamped)


def curve_samples(curve: NurbsCurve, count: int = 200, lo=None, hi=None) -> np.ndarray:
    """``count`` parameters evenly over [lo, hi] (default the domain) plus the knots in it."""
    a, b = curve.domain
    lo = a if lo is None else lo
    hi = b if hi is None else hi
    knots = curve.knots[(curve.knots >= lo) & (curve.knots <= hi)]
    return np.unique(np.concatenate([np.linspace(lo, hi, count), knots]))


def surface_samples(surface: NurbsSurface, count: int = 40, box=None):
    """Tensor grid parameters ``(u, v)`` of ``count`` values per direction plus knots."""
    u0, u1, v0, v1 = surface.domain if box is None else box
    ku = surface.knots_u[(surface.knots_u >= u0) & (surface.knots_u <= u1)]
    kv = surface.knots_v[(surface.knots_v >= v0) & (surface.knots_v <= v1)]
    return (np.unique(np.concatenate([np.linspace(u0, u1, count), ku])),
            np.unique(np.concatenate([np.linspace(v0, v1, count), kv])))


def scale_of(geometry) -> float:
    """Size of the control points, for relative tolerances."""
    return float(np.abs(geometry.control_points).max()) + 1.0


def assert_same_curve(result: NurbsCurve, original: NurbsCurve, t: np.ndarray,
                      rtol: float = 1e-12) -> None:
    """Both curves agree at every parameter of ``t`` to ``rtol`` times the size."""
    err = np.abs(result.evaluate(t) - original.evaluate(t)).max()
    assert err <= rtol * scale_of(original), f"max deviation {err:.3e}"


def assert_same_surface(result: NurbsSurface, original: NurbsSurface, u: np.ndarray,
                        v: np.ndarray, rtol: float = 1e-12) -> None:
    err = np.abs(result.evaluate_grid(u, v) - original.evaluate_grid(u, v)).max()
    assert err <= rtol * scale_of(original), f"max deviation {err:.3e}"
