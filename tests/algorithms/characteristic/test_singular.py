"""The characteristic tracer through singular points (characteristic.trace.continue_at_singular_points).

Exact answers, numpy only:

* the saddle ``z = (x - X0)^2 - 2 (y - Y0)^2`` cut by the plane ``z = 0``: the two
  lines ``x - X0 = +-sqrt 2 (y - Y0)`` crossing at the double point ``(X0, Y0, 0)``;
* the graph ``z = (x - X0)^3 / 3 - 2 (x - X0) (y - Y0)^2`` over the plane: its
  u-characteristic curve ``phi_u = 0`` is ``(x - X0)^2 = 2 (y - Y0)^2``, the
  same two lines crossing (a saddle-shaped ``phi_u``);

(the equal-radius cylinders traced through their double points are in
tests/algorithms/intersection/test_branch_singular.py, next to the OpenCascade
surfaces).
"""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.characteristic.algorithm import choose_field
from surfprep.algorithms.characteristic.curves import CurveKind, EndReason, TracedCurve, trace_curves
from surfprep.algorithms.characteristic.singular import continue_at_singular_points
from surfprep.algorithms.characteristic.trace import (
    to_intersection_curve,
    trace_intersections,
)
from surfprep.algorithms.intersection import EndKind, polyline_distance

X0, Y0 = 0.56, 0.43
SLOPE = np.sqrt(2.0)


def graph(f, p: int, q: int) -> NurbsSurface:
    """Bezier graph ``(x, y, f(x, y))`` over [0, 1]^2 with ``x = u``, ``y = v``; exact
    for a polynomial ``f`` of degrees ``(p, q)`` (Bernstein coefficients solved
    from ``(p + 1) (q + 1)`` samples)."""
    from math import comb

    def bernstein(n, t):
        return np.stack([comb(n, i) * t ** i * (1 - t) ** (n - i) for i in range(n + 1)], 1)

    s, t = np.linspace(0, 1, p + 1), np.linspace(0, 1, q + 1)
    bu, bv = bernstein(p, s), bernstein(q, t)
    z = f(s[:, None], t[None, :])
    coef = np.linalg.solve(bu, np.linalg.solve(bv, z.T).T)
    X, Y = np.meshgrid(s, t, indexing="ij")
    # x = u needs the control abscissae i / p (linear precision)
    return NurbsSurface(np.stack([X, Y, coef], -1), [0] * (p + 1) + [1] * (p + 1),
                        [0] * (q + 1) + [1] * (q + 1), p, q)


def plane() -> NurbsSurface:
    cp = np.array([[[-0.2, -0.2, 0], [-0.2, 1.2, 0]], [[1.2, -0.2, 0], [1.2, 1.2, 0]]], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def two_lines(n: int = 4001) -> np.ndarray:
    """Dense samples of ``x - X0 = +-sqrt 2 (y - Y0)`` inside [0, 1]^2, z = 0."""
    out = []
    for sign in (1.0, -1.0):
        y = np.linspace(0, 1, n)
        x = X0 + sign * SLOPE * (y - Y0)
        m = (x >= 0) & (x <= 1)
        out.append(np.stack([x[m], y[m], np.zeros(m.sum())], 1))
    return np.concatenate(out)


def segment_gap(points: np.ndarray, polylines: list[np.ndarray]) -> np.ndarray:
    """Distance ``(n,)`` of each point to the nearest chord of the polylines (all chords)."""
    a = np.concatenate([p[:-1] for p in polylines])
    d = np.concatenate([np.diff(p, axis=0) for p in polylines])
    dd = np.maximum(np.einsum("sc,sc->s", d, d), 1e-300)
    w = np.clip(np.einsum("nsc,sc->ns", points[:, None] - a[None], d) / dd, 0, 1)
    return np.linalg.norm(a[None] + w[..., None] * d[None] - points[:, None], axis=2).min(axis=1)


def start_on(field, point: np.ndarray):
    """A start ``(uv, st)`` on r at the 3D ``point`` (r is a graph over x, y)."""
    uv = point[None, :2].copy()
    return uv, field.jet(uv).st


def test_saddle_double_point_all_four_branches():
    tol = 1e-7
    saddle = graph(lambda x, y: (x - X0) ** 2 - 2 * (y - Y0) ** 2, 2, 2)
    field = choose_field(saddle, plane(), tol=tol, phi_on="a")
    y = 0.7
    uv, st = start_on(field, np.array([X0 + SLOPE * (y - Y0), y, 0.0]))
    plain = trace_intersections(field, uv, st, np.array([0.3]), tol=tol)
    traced = trace_intersections(field, uv, st, np.array([0.3]), tol=tol, branches=True)
    ends = [t for t in traced if EndReason.SINGULAR in (t.start_reason, t.end_reason)]
    assert len(ends) == 4                                          # four half-branches
    curves = [c for c in (to_intersection_curve(field, t, tol) for t in traced) if c is not None]
    assert len(curves) == 4
    exact = two_lines()
    assert polyline_distance(exact, curves).max() <= tol                       # coverage
    plain_curves = [c for c in (to_intersection_curve(field, t, tol) for t in plain)
                    if c is not None]
    assert polyline_distance(exact, plain_curves).max() > 0.1     # one line only without
    for c in curves:
        assert c.max_deviation(saddle, plane()).max <= tol
        at = [p for p, k in ((c.points[0], c.start_kind), (c.points[-1], c.end_kind))
              if k is EndKind.BIFURCATION]
        assert len(at) == 1
        np.testing.assert_allclose(at[0], [X0, Y0, 0.0], atol=1e-9)
    # nothing twice: each line runs over a y-range of length 1 / sqrt 2 inside the
    # domain, with length sqrt 3 per unit of y
    total = sum(c.length for c in curves)
    assert total == pytest.approx(2 * np.sqrt(3) / SLOPE, rel=1e-9)


def test_u_characteristic_crossing_itself():
    """``phi_u = 0`` of a monkey-saddle-like graph: two lines crossing; traced from one
    end, the tracer comes back with all four half-branches."""
    tol = 1e-7
    surface = graph(lambda x, y: (x - X0) ** 3 / 3 - 2 * (x - X0) * (y - Y0) ** 2, 3, 2)
    field = choose_field(surface, plane(), tol=tol, phi_on="a")
    y = Y0 + (1 - X0) / SLOPE                                 # on the side x = 1
    uv, st = start_on(field, np.array([1.0, y, 0.0]))
    first = trace_curves(field, CurveKind.U_CHARACTERISTIC, uv, st, np.array([[-SLOPE, -1.0]]),
                         h0=0.01, h_max=0.02)
    pieces = continue_at_singular_points(field, first, tol=tol, h_max=0.02)
    at = [t for t in pieces if EndReason.SINGULAR in (t.start_reason, t.end_reason)]
    assert len(at) == 4
    for t in at:
        end = t.uv[0] if t.start_reason is EndReason.SINGULAR else t.uv[-1]
        np.testing.assert_allclose(end, [X0, Y0], atol=1e-9)
    samples = np.concatenate([t.uv for t in pieces])
    line = np.abs(np.abs(samples[:, 0] - X0) - SLOPE * np.abs(samples[:, 1] - Y0))
    assert line.max() <= 1e-6
    # every part of both lines inside the domain is traced (chords of straight lines)
    assert segment_gap(two_lines()[:, :2], [t.uv for t in pieces]).max() <= 1e-6


def test_isolated_point_has_no_branches():
    """``z = (x - X0)^2 + (y - Y0)^2`` touches the plane at one point: a trace started
    there finds the point and no branch."""
    tol = 1e-7
    bowl = graph(lambda x, y: (x - X0) ** 2 + (y - Y0) ** 2, 2, 2)
    field = choose_field(bowl, plane(), tol=tol, phi_on="a")
    uv, st = start_on(field, np.array([X0 + 1e-4, Y0, 0.0]))
    traced = trace_intersections(field, uv, st, np.array([0.1]), tol=tol, branches=True)
    assert all(t.uv.shape[0] <= 2 for t in traced)        # nothing leaves the point


def test_tangential_contact_is_not_split_into_branch_points():
    """The parabolic cylinder ``z = (y - Y0)^2`` touches the plane along the line
    ``y = Y0``: ``grad phi`` vanishes all along it, so Newton on ``grad phi = 0``
    converges wherever it starts, to points with a rank-one Hessian. They are points
    of the contact, not branch points: a trace along the line comes back whole, with
    no branch added (real files' tangential joins gave hundreds of such points and
    hours of splitting)."""
    tol = 1e-7
    trough = graph(lambda x, y: (y - Y0) ** 2 + 0 * x, 1, 2)
    field = choose_field(trough, plane(), tol=tol, phi_on="a")
    x = np.linspace(0.05, 0.95, 61)
    uv = np.stack([x, np.full_like(x, Y0)], axis=1)
    uv[:, 1] += 1e-9 * np.sin(37 * x)              # rounding-sized wiggle: |grad| dips
    jet = field.jet(uv)
    trace = TracedCurve(CurveKind.INTERSECTION, uv, jet.st, jet.phi, jet.grad,
                        jet.projection.det_k, EndReason.DOMAIN, EndReason.DOMAIN)
    assert np.abs(jet.phi).max() <= tol
    pieces = continue_at_singular_points(field, [trace], tol=tol, h_max=0.02)
    assert len(pieces) == 1
    np.testing.assert_array_equal(pieces[0].uv, uv)
