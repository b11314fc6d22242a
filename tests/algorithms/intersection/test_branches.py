"""Singular points of intersection curves: second-order branch directions
(algorithms.intersection.branches) and curves joined exactly at double points
(algorithms.intersection.singular_join.join_at_singular_points).

Exact answers: two cylinders of equal radius with perpendicular axes,
``x^2 + y^2 = 1`` and ``y^2 + z^2 = 1``, meet along the ellipses ``x = +-z``,
crossing at the double points ``(0, +-1, 0)`` with branch directions
``(1, 0, +-1) / sqrt 2``; Viviani's figure eight (sphere r = 2, cylinder r = 1
around ``(1, 0, z)``) has its double point at ``(2, 0, 0)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.measure import check_on_surfaces
from helpers.occ_shapes import TAU, cylinder, sphere

from surfprep.algorithms.characteristic.algorithm import choose_field
from surfprep.algorithms.characteristic.trace import to_intersection_curve, trace_intersections
from surfprep.algorithms.intersection import EndKind, intersect_surfaces, pipeline, polyline_distance
from surfprep.algorithms.intersection.branches import (
    SingularKind,
    branch_directions,
    locate_singular_points,
    singular_branches,
)
from surfprep.algorithms.intersection.singular_join import join_at_singular_points


def hook(monkeypatch):
    """The pipeline with the singular join after the marching of open ends (the hook
    proposed for ``pipeline._extend``; a no-op once the pipeline calls it itself)."""
    if "join_at_singular_points" not in pipeline._extend.__code__.co_names:
        original = pipeline._extend

        def _extend(dense, kinds, a, b, tol, mesh_tol):
            dense, kinds = original(dense, kinds, a, b, tol, mesh_tol)
            return join_at_singular_points(dense, kinds, a, b, tol=tol, reach=64 * mesh_tol)

        monkeypatch.setattr(pipeline, "_extend", _extend)
    return intersect_surfaces


@pytest.fixture
def hooked(monkeypatch):
    return hook(monkeypatch)


# ---------------------------------------------------------------- the quadratic form
@pytest.mark.parametrize("seed", range(8))
def test_double_point_directions_are_roots_of_the_form(seed):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(2, 2)))
    lam = np.array([-rng.uniform(0.1, 5), rng.uniform(0.1, 5)])
    h = q @ np.diag(lam) @ q.T
    kinds, d = branch_directions(h[None])
    assert kinds == [SingularKind.DOUBLE_POINT]
    np.testing.assert_allclose(np.linalg.norm(d[0], axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.einsum("ji,ik,jk->j", d[0], h, d[0]), 0.0, atol=1e-12)
    assert abs(d[0, 0] @ d[0, 1]) < 1 - 1e-6          # two different directions


def test_isolated_cusp_and_degenerate_points():
    kinds, d = branch_directions(np.array([[[2.0, 0.3], [0.3, 1.0]], [[1.0, 2.0], [2.0, 4.0]],
                                           [[0.0, 0.0], [0.0, 0.0]]]))
    assert kinds == [SingularKind.ISOLATED, SingularKind.CUSP, SingularKind.DEGENERATE]
    assert np.isnan(d[0]).all() and np.isnan(d[2]).all() and np.isnan(d[1, 1]).all()
    np.testing.assert_allclose(np.array([[1.0, 2.0], [2.0, 4.0]]) @ d[1, 0], 0.0, atol=1e-14)


def test_saddle_level_curve_directions():
    """f = x^2 - 3 y^2: the level curve f = 0 is the two lines x = +-sqrt(3) y."""
    kinds, d = branch_directions(np.array([[[2.0, 0.0], [0.0, -6.0]]]))
    assert kinds == [SingularKind.DOUBLE_POINT]
    slopes = np.sort(np.abs(d[0, :, 0] / d[0, :, 1]))
    np.testing.assert_allclose(slopes, np.sqrt(3), rtol=1e-14)
    assert np.sign(d[0, 0, 0] * d[0, 0, 1]) != np.sign(d[0, 1, 0] * d[0, 1, 1])


# ---------------------------------------------------------------- locating on surfaces
def equal_cylinders():
    return cylinder(1.0, 1.5), cylinder(1.0, 2.0, normal=(1, 0, 0))


def uv_of(surface, points, grid: int = 201):
    """(u, v) of points on a surface: the nearest of a parameter grid."""
    d = surface.domain
    u, v = np.meshgrid(np.linspace(d[0], d[1], grid), np.linspace(d[2], d[3], grid),
                       indexing="ij")
    p = surface.evaluate(u.ravel(), v.ravel())
    k = np.argmin(np.linalg.norm(p[None] - points[:, None], axis=2), axis=1)
    return np.stack([u.ravel()[k], v.ravel()[k]], 1)


def test_equal_cylinders_double_points_and_branches():
    a, b = equal_cylinders()
    t = np.pi / 2 + np.array([0.04, -0.03, np.pi + 0.05, np.pi - 0.02])   # near (0, +-1, 0)
    start = np.stack([np.cos(t), np.sin(t), np.cos(t)], 1)                 # on x = z
    ua, ub = uv_of(a, start), uv_of(b, start)
    ra, rb, ok = locate_singular_points(a, b, ua, ub, tol=1e-10, scale=0.1)
    assert ok.all()
    points, kinds, dirs = singular_branches(a, b, ra, rb)
    expect = np.array([[0, 1, 0], [0, 1, 0], [0, -1, 0], [0, -1, 0]], float)
    np.testing.assert_allclose(points, expect, atol=1e-12)
    assert kinds == [SingularKind.DOUBLE_POINT] * 4
    for d in dirs:
        got = np.sort(np.abs(d @ np.array([1, 0, 1]) / np.sqrt(2)))
        np.testing.assert_allclose(got, [0, 1], atol=1e-9)        # (1,0,1) and (1,0,-1)
        np.testing.assert_allclose(d[:, 1], 0.0, atol=1e-9)


def test_no_singular_point_on_a_transversal_pair():
    """Cylinders of radii 1 and 0.5 cross transversally everywhere: nothing converges."""
    a, b = cylinder(1.0, 1.5), cylinder(0.5, 2.0, normal=(1, 0, 0))
    s = np.linspace(0.1, 6.0, 7)
    y, z = 0.5 * np.cos(s), 0.5 * np.sin(s)
    start = np.stack([np.sqrt(1 - y ** 2), y, z], 1)
    _, _, ok = locate_singular_points(a, b, uv_of(a, start), uv_of(b, start), tol=1e-7,
                                      scale=0.1)
    assert not ok.any()


# ---------------------------------------------------------------- joined curves
def ellipses(n: int = 20001) -> np.ndarray:
    t = np.linspace(0, TAU, n)
    return np.concatenate([np.stack([np.cos(t), np.sin(t), s * np.cos(t)], 1)
                           for s in (1.0, -1.0)])


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
def test_equal_cylinders_curves_end_at_the_double_points(hooked, tol):
    a, b = equal_cylinders()
    curves = hooked(a, b, tol=tol)
    check_on_surfaces(curves, a, b, tol=tol)
    exact = ellipses()
    assert polyline_distance(exact, curves).max() <= tol                 # coverage
    singular = np.array([[0, 1, 0], [0, -1, 0]], float)
    ends = [(c.points[0], c.start_kind) for c in curves] + [(c.points[-1], c.end_kind)
                                                             for c in curves]
    at = [p for p, k in ends if k is EndKind.BIFURCATION]
    assert len(at) == 8                                     # four half-branches per point
    for s in singular:
        assert sum(np.linalg.norm(p - s) <= 1e-9 for p in at) == 4
    # no piece twice: the total length is the two ellipses' (no overlap at the points)
    exact_length = np.linalg.norm(np.diff(exact, axis=0), axis=1).sum() - np.linalg.norm(
        exact[20001] - exact[20000])
    assert sum(c.length for c in curves) == pytest.approx(exact_length, rel=1e-6)


def test_viviani_double_point_on_a_seam(hooked):
    """The double point (2, 0, 0) lies on the sphere's seam: both lobes keep a BOUNDARY
    end there and a BIFURCATION end, all at the point; coverage within tol."""
    tol = 1e-7
    a = sphere(2.0, normal=(0, 1, 0), xdir=(-1, 0, 0))
    b = cylinder(1.0, 2.5, origin=(1, 0, 0))
    curves = hooked(a, b, tol=tol)
    check_on_surfaces(curves, a, b, tol=tol)
    t = np.linspace(0, 2 * TAU, 40001)
    viviani = np.stack([1 + np.cos(t), np.sin(t), 2 * np.sin(t / 2)], 1)
    assert polyline_distance(viviani, curves).max() <= tol
    exact_length = np.linalg.norm(np.diff(viviani, axis=0), axis=1).sum()
    assert sum(c.length for c in curves) == pytest.approx(exact_length, rel=1e-6)
    for c in curves:
        for p, k in ((c.points[0], c.start_kind), (c.points[-1], c.end_kind)):
            if k is EndKind.BIFURCATION:
                np.testing.assert_allclose(p, [2, 0, 0], atol=1e-9)


def test_join_leaves_transversal_curves_alone(monkeypatch):
    a, b = cylinder(1.0, 1.5), cylinder(0.5, 2.0, normal=(1, 0, 0))
    with monkeypatch.context() as m:           # the pipeline without the join
        m.setattr(pipeline, "join_at_singular_points", lambda c, k, *a, **kw: (c, k),
                  raising=False)
        plain = intersect_surfaces(a, b, tol=1e-7)
    joined = hook(monkeypatch)(a, b, tol=1e-7)
    assert len(plain) == len(joined)
    for p, q in zip(plain, joined):
        np.testing.assert_array_equal(p.points, q.points)


def offset_saddle(u0: float = 0.23, v0: float = -0.17, k: float = 2.0):
    """Biquadratic Bezier ``z = (x - u0)^2 - k (y - v0)^2`` over [-1, 1]^2 and the plane
    ``z = 0``: the lines ``x - u0 = +-sqrt(k) (y - v0)`` cross at ``(u0, v0, 0)``."""
    from surfprep.algorithms import NurbsSurface

    def square(c):       # Bernstein coefficients of (x - c)^2, x = 2 t - 1
        return np.array([(1 + c) ** 2, c * c - 1, (1 - c) ** 2])

    line = np.array([-1.0, 0.0, 1.0])
    cp = np.stack(np.broadcast_arrays(line[:, None], line[None, :],
                                      square(u0)[:, None] - k * square(v0)[None, :]), -1)
    knots = [0, 0, 0, 1, 1, 1]
    s = 1.3
    flat = np.array([[[-s, -s, 0], [-s, s, 0]], [[s, -s, 0], [s, s, 0]]], float)
    return (NurbsSurface(cp, knots, knots, 2, 2),
            NurbsSurface(flat, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1))


@pytest.mark.parametrize("tol", [1e-7, 1e-10])
def test_offset_saddle_double_point_joined(monkeypatch, tol):
    """Without the join the traced curves cut the corner at the double point (coverage
    gap about 1e-4 at both tolerances); with it, four curves end exactly there."""
    u0, v0, k = 0.23, -0.17, 2.0
    a, b = offset_saddle(u0, v0, k)
    y = np.linspace(-1, 1, 40001)
    exact = []
    for sign in (1.0, -1.0):
        x = u0 + sign * np.sqrt(k) * (y - v0)
        inside = np.abs(x) <= 1
        exact.append(np.stack([x[inside], y[inside], np.zeros(inside.sum())], 1))
    exact = np.concatenate(exact)
    with monkeypatch.context() as m:           # the pipeline without the join
        m.setattr(pipeline, "join_at_singular_points", lambda c, k, *a, **kw: (c, k),
                  raising=False)
        plain = intersect_surfaces(a, b, tol=tol)
    assert polyline_distance(exact, plain).max() > 10 * tol
    curves = hook(monkeypatch)(a, b, tol=tol)
    check_on_surfaces(curves, a, b, tol=tol)
    assert polyline_distance(exact, curves).max() <= tol
    at = [p for c in curves for p, kind in ((c.points[0], c.start_kind), (c.points[-1], c.end_kind))
          if kind is EndKind.BIFURCATION]
    assert len(at) == 4
    np.testing.assert_allclose(at, [[u0, v0, 0.0]] * 4, atol=1e-9)


# ---------------------------------------------------------------- the characteristic tracer
def test_characteristic_tracer_equal_cylinders_traced_whole():
    """From one start on the ellipse x = z, the tracer splits at (0, +-1, 0) and traces
    the other ellipse too: seven pieces (cut at the seams), covering both within tol."""
    tol = 1e-7
    a, b = cylinder(1.0, 1.5), cylinder(1.0, 2.0, normal=(1, 0, 0))
    field = choose_field(a, b, tol=tol, phi_on="a")
    t = 0.7
    d = a.domain
    u, v = np.meshgrid(np.linspace(d[0], d[1], 401), np.linspace(d[2], d[3], 401), indexing="ij")
    grid = a.evaluate(u.ravel(), v.ravel())
    k = np.argmin(np.linalg.norm(grid - [np.cos(t), np.sin(t), np.cos(t)], axis=1))
    uv = np.array([[u.ravel()[k], v.ravel()[k]]])
    traced = trace_intersections(field, uv, field.jet(uv).st, np.array([0.5]), tol=tol,
                                 branches=True)
    curves = [c for c in (to_intersection_curve(field, x, tol) for x in traced) if c is not None]
    s = np.linspace(0, TAU, 20001)
    exact = np.concatenate([np.stack([np.cos(s), np.sin(s), sign * np.cos(s)], 1)
                            for sign in (1.0, -1.0)])
    assert polyline_distance(exact, curves).max() <= tol
    bif = [p for c in curves for p, k in ((c.points[0], c.start_kind), (c.points[-1], c.end_kind))
           if k is EndKind.BIFURCATION]
    assert len(bif) == 8
    for p in ([0, 1, 0], [0, -1, 0]):
        assert sum(np.linalg.norm(q - p) <= 1e-9 for q in bif) == 4


# ---------------------------------------------------------------- which samples are starts
def test_dips_tell_a_vanishing_sine_from_a_steady_small_one():
    """|N_a x N_b| falling linearly to zero (a double point between samples, whatever
    its offset) is a start; a steady small angle, or one that varies only by a few
    per cent, is not (singular_join._dips)."""
    from surfprep.algorithms.intersection.singular_join import _dips
    x = np.linspace(0, 1, 41)
    for x0 in (0.5, 0.5 + 0.25 / 40, 0.5 + 0.49 / 40):
        s = 0.3 * np.abs(x - x0)
        i = int(np.argmin(s))
        assert _dips(s, np.array([i]))[0]
    steady = np.full(41, 2.6e-3) * (1 + 0.01 * np.cos(7 * x))
    minima = np.flatnonzero((steady[1:-1] <= steady[:-2]) & (steady[1:-1] <= steady[2:])) + 1
    assert minima.size and not _dips(steady, minima).any()


def test_near_tangential_circles_give_no_sample_starts():
    """A plane 1e-6 below a torus's top circle: the normals are 2.6e-3 rad apart all
    along both circles (every sample a flat minimum); no Gauss-Newton start is made
    from the samples, and the circles come out whole."""
    from helpers.surfaces import torus_and_plane

    from surfprep.algorithms.intersection import SmallAngleWarning, StrayCurves
    from surfprep.algorithms.intersection.refine import RefinedCurve
    from surfprep.algorithms.intersection.singular_join import _singular_starts
    torus, plane = torus_and_plane(1e-6)
    with pytest.warns(SmallAngleWarning):          # 2.6e-3 rad: flat for the triangles
        curves = intersect_surfaces(torus, plane, tol=1e-9, stray=StrayCurves.DROP)
    assert len(curves) == 2
    radii = sorted(float(np.linalg.norm(c.points[0, :2])) for c in curves)
    np.testing.assert_allclose(radii, 1 + np.array([-1, 1]) * np.sqrt(0.3 ** 2 - (0.3 - 1e-6) ** 2),
                               atol=1e-9)
    dense = [RefinedCurve(c.points, c.uv_a, c.uv_b, c.closed, np.ones(len(c.points), bool),
                          np.zeros(len(c.points), bool)) for c in curves]
    kinds = [(c.start_kind, c.end_kind) for c in curves]
    pts, _, _, is_end = _singular_starts(dense, kinds, torus, plane)
    assert pts.shape[0] == int(is_end.sum())
