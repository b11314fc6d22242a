"""RCA reparametrization (section 29.2) on surfaces with known bad parametrizations.

Every result is checked independently of the method's own error loop: the new
surface is sampled densely (>= 10 x 10 per interpolation cell) and projected
onto the original with seeds, and the original is sampled densely and
projected onto the new surface. The chord-length mismatch (eqs. 29.1/29.2) is
compared as its excess over the perfect value 1.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.reparam import reparametrize_surface
from surfprep.algorithms.reparam.deviation import subdivide
from surfprep.algorithms.surface import NurbsSurface
from surfprep.errors import (
    DegenerateGeometryError,
    InvalidGeometryError,
    InvalidToleranceError,
)


def _geometry(a, b):
    """A smooth, doubly curved sheet over [0, 2] x [0, 1.5] (a, b in [0, 1])."""
    return np.stack([2 * a, 1.5 * b, 0.4 * np.sin(np.pi * a) * np.cos(0.8 * np.pi * (b - 0.5))], -1)


def warped(warp, n: int = 12) -> NurbsSurface:
    """C2 interpolant of the sheet at ``warp(u, v)`` on a uniform n x n grid."""
    t = np.linspace(0.0, 1.0, n)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    a, b = warp(uu, vv)
    return interpolate_surface(_geometry(a, b), params_u=t, params_v=t)


def u_cubed(u, v):
    return u ** 3, v


def clustered_ends(u, v):
    return 0.5 - 0.5 * np.cos(np.pi * u), 0.5 - 0.5 * np.cos(np.pi * v)


def sheared(u, v):
    """u is distorted as u^(1 + 1.5 sin(pi v)): straight along v = 0 and v = 1, u^2.5
    in the middle; the distortion mixes u and v."""
    return u ** (1.0 + 1.5 * np.sin(np.pi * v)), v


def dense_deviation(original: NurbsSurface, result) -> float:
    """Both ways, projections seeded from sample grids (not the method's map):
    10 x 10 per interpolation cell of the result, 150 x 150 on the original."""
    new = result.surface
    gu, gv = subdivide(result.params_u, 10), subdivide(result.params_v, 10)
    forward = project_to_surface(original, new.evaluate_grid(gu, gv), n_seeds=1).distance.max()
    ou = np.linspace(*original.domain[:2], 150)
    ov = np.linspace(*original.domain[2:], 150)
    backward = project_to_surface(new, original.evaluate_grid(ou, ov), n_seeds=1).distance.max()
    return float(max(forward, backward))


def excess(mismatch: float) -> float:
    return mismatch - 1.0


@functools.cache
def reparametrized(warp, **options):
    """(original, result), computed once per warp and options for all tests."""
    original = warped(warp)
    return original, reparametrize_surface(original, **options)


@pytest.mark.parametrize("warp", [u_cubed, clustered_ends, sheared])
def test_within_tol_and_chord_length(warp):
    original, result = reparametrized(warp)
    assert result.within_tolerance
    assert result.max_deviation <= result.tol
    assert dense_deviation(original, result) <= result.tol
    assert excess(result.mismatch_before) > 0.3                      # really distorted
    assert excess(result.mismatch_after) * 10 <= excess(result.mismatch_before)
    assert result.relocation_converged
    # the parameters follow arc length: the domain is about the boundary lengths
    u0, u1, v0, v1 = result.surface.domain
    assert u1 - u0 == pytest.approx(2.0 * 1.2, rel=0.2)
    assert v1 - v0 == pytest.approx(1.5, rel=0.05)


def test_a_far_off_surface_gets_the_same_answer():
    """The surface 1e6 away from the origin (169 across in the issue's file, 2.4 here):
    worked on about its own box centre, so the answer is the near one moved, not a
    different fit of coordinates that lost their low bits."""
    offset = np.array([1e6, -1e6, 1e6])
    original, near = reparametrized(u_cubed)
    far_original = original.translated(offset)
    far = reparametrize_surface(far_original, tol=near.tol)
    assert far.within_tolerance
    assert far.surface.n_control == near.surface.n_control
    assert far.iterations == near.iterations
    assert far.mismatch_after == pytest.approx(near.mismatch_after, rel=1e-6)
    assert far.max_deviation == pytest.approx(near.max_deviation, rel=1e-4)
    # the same surface, moved (coordinates at 1e6 are rounded to ~1e-10; the relocation,
    # converged to its own threshold, carries that to ~1e-8)
    np.testing.assert_allclose(far.surface.control_points - offset, near.surface.control_points,
                               rtol=0, atol=1e-3 * near.tol)
    assert dense_deviation(far_original, far) <= far.tol


def test_shear_needs_the_interior_relocation():
    """Per-direction arc length (straight lines in the original domain) leaves the
    shear in; the penalty relocation removes it."""
    _, without = reparametrized(sheared, relocation=False)
    _, with_it = reparametrized(sheared)
    assert excess(without.mismatch_after) > 0.5 * excess(original_mismatch := without.mismatch_before)
    assert excess(with_it.mismatch_after) * 10 <= excess(original_mismatch)


@pytest.mark.slow
def test_tighter_tolerance_inserts_knots():
    original = warped(u_cubed)
    loose = reparametrize_surface(original, tol=1e-3)
    tight = reparametrize_surface(original, tol=5e-5)
    assert tight.within_tolerance and loose.within_tolerance
    assert dense_deviation(original, tight) <= 5e-5
    assert tight.surface.n_control[0] > loose.surface.n_control[0]


def test_limit_reached_is_reported_not_hidden():
    original, full = reparametrized(u_cubed)
    assert full.iterations > 1 and full.within_tolerance
    cut = reparametrize_surface(original, max_iterations=1)
    assert not cut.within_tolerance
    assert cut.max_deviation > cut.tol


def _cone_with_pole(n: int = 10) -> NurbsSurface:
    """Quarter cone, apex along v = 0 (a collapsed edge), u distorted as u^2."""
    t = np.linspace(0.0, 1.0, n)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    angle = 0.5 * np.pi * uu ** 2
    points = np.stack([vv * np.cos(angle), vv * np.sin(angle), 1.0 - vv], -1)
    return interpolate_surface(points, params_u=t, params_v=t)


def test_collapsed_edge_stays_collapsed():
    original = _cone_with_pole()
    result = reparametrize_surface(original)
    assert result.within_tolerance
    assert dense_deviation(original, result) <= result.tol
    new = result.surface
    u0, u1, v0, _ = new.domain
    apex = new.evaluate(np.linspace(u0, u1, 50), np.full(50, v0))
    assert np.ptp(apex, axis=0).max() <= result.tol
    assert excess(result.mismatch_after) * 10 <= excess(result.mismatch_before)


def test_point_and_collapsed_direction_are_degenerate():
    point = NurbsSurface(np.ones((4, 4, 3)), [0] * 4 + [1] * 4, [0] * 4 + [1] * 4, 3, 3)
    with pytest.raises(DegenerateGeometryError):
        reparametrize_surface(point)
    t = np.linspace(0.0, 1.0, 5)
    line = np.zeros((5, 5, 3))
    line[:, :, 0] = t[None, :]                       # independent of u
    ribbon = interpolate_surface(line, params_u=t, params_v=t)
    with pytest.raises(DegenerateGeometryError, match="collapsed"):
        reparametrize_surface(ribbon)


@pytest.mark.parametrize("tol", [math.nan, -1.0, 0.0, 1e3, 1e-14, "abc"])
def test_bad_tolerance(tol):
    with pytest.raises(InvalidToleranceError):
        reparametrize_surface(warped(u_cubed, 6), tol=tol)


def test_bad_input():
    with pytest.raises(InvalidGeometryError):
        reparametrize_surface(np.zeros((4, 4, 3)))
    cp = np.zeros((4, 4, 3))
    cp[1, 1, 2] = np.nan
    with pytest.raises(InvalidGeometryError, match="NaN"):
        NurbsSurface(cp, [0] * 4 + [1] * 4, [0] * 4 + [1] * 4, 3, 3)


def _roof() -> NurbsSurface:
    """Degree 1 x 3 roof: two planar slopes meeting in a crease at the knot u = 0.2
    (equal slope lengths: the u parameter runs 4x faster on the second slope),
    v distorted as v^3."""
    t = np.linspace(0.0, 1.0, 8)
    x = np.array([0.0, 1.0, 2.0])
    z = np.array([0.0, 0.6, 0.0])
    cp = np.zeros((3, 8, 3))
    column = interpolate_surface(np.stack([np.zeros((4, 8)), 1.5 * (np.linspace(0, 1, 4)[:, None]
                                                                   * 0 + t[None, :] ** 3),
                                           np.zeros((4, 8))], -1), params_u=np.linspace(0, 1, 4),
                                 params_v=t)
    vy = column.control_points[0, :, 1]                       # y control values of v^3
    cp[:, :, 0], cp[:, :, 1], cp[:, :, 2] = x[:, None], vy[None, :], z[:, None]
    return NurbsSurface(cp, [0, 0, 0.2, 1, 1], column.knots_v, 1, 3)


def test_crease_becomes_a_fixed_c0_line():
    from surfprep.algorithms.reparam.rca import crease_knots
    original = _roof()
    assert list(crease_knots(original)[0]) == [0.2]
    result = reparametrize_surface(original)
    assert result.within_tolerance
    assert dense_deviation(original, result) <= result.tol
    assert excess(result.mismatch_after) * 10 <= excess(result.mismatch_before)
    # the crease is a triple knot of the new surface, halfway (equal slope lengths)
    ku = result.surface.knots_u
    values, counts = np.unique(ku[4:-4], return_counts=True)
    (crease,) = values[counts == 3]
    u0, u1 = result.surface.domain[:2]
    assert (crease - u0) / (u1 - u0) == pytest.approx(0.5, abs=1e-6)
    ridge = result.surface.evaluate(np.full(5, crease), np.linspace(*result.surface.domain[2:], 5))
    assert np.allclose(ridge[:, [0, 2]], [1.0, 0.6], atol=result.tol)


def _tapering_tail() -> NurbsSurface:
    """A tapering quarter tube in three cubic Bezier pieces along u joined C0 (the axis
    bends at u = 1 and 2: creases), its rows crowded at every piece start (u
    distorted), the cross-section poles uneven (v distorted); the radius shrinks
    from 1 to 0.16 (like the fuselage tail, occt_fuselage faces 4-7)."""
    ends, slopes = np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 0.25, 0.7])
    rows = np.concatenate([ends[k] + np.array(s) for k, s in
                           enumerate([(0, 0.04, 0.25), (0, 0.04, 0.25), (0, 0.04, 0.25, 1)])])
    piece = np.minimum(rows.astype(int), 2)
    z = np.concatenate([[0], np.cumsum(slopes)])[piece] + slopes[piece] * (rows - ends[piece])
    radius = 1.0 - 0.28 * rows
    section = np.array([[1, 0], [1, 0.15], [0.35, 1.0], [0, 1]], float)
    cp = np.stack([np.broadcast_to(3 * rows[:, None], (len(rows), 4)),
                   radius[:, None] * section[None, :, 0],
                   z[:, None] + radius[:, None] * section[None, :, 1]], -1)
    return NurbsSurface(cp, [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3], [0] * 4 + [1] * 4, 3, 3)


def _no_near_duplicates(params) -> bool:
    """Neighbouring interpolation intervals differ by less than 8x."""
    h = np.diff(params)
    return bool(np.all(np.maximum(h[1:] / h[:-1], h[:-1] / h[1:]) < 8.0))


def test_creased_tapering_tail():
    from surfprep.algorithms.reparam.rca import crease_knots
    original = _tapering_tail()
    assert list(crease_knots(original)[0]) == [1.0, 2.0]
    result = reparametrize_surface(original)
    assert result.within_tolerance and result.relocation_converged
    assert dense_deviation(original, result) <= result.tol
    assert excess(result.mismatch_before) > 3.0
    assert excess(result.mismatch_after) * 10 <= excess(result.mismatch_before)
    # the v points of four lines (two boundaries, two creases) reconcile to one set,
    # without clusters of nearly equal fractions
    assert _no_near_duplicates(result.params_v) and _no_near_duplicates(result.params_u)
    assert result.surface.n_control[1] <= 12


@pytest.mark.parametrize("warp", [u_cubed, sheared])
def test_coarsening_saves_poles_within_tol(warp):
    original, coarse = reparametrized(warp)
    _, dense = reparametrized(warp, coarsening=False)
    assert dense.within_tolerance and coarse.within_tolerance
    assert dense_deviation(original, coarse) <= coarse.tol
    assert np.prod(coarse.surface.n_control) < np.prod(dense.surface.n_control)
    assert excess(coarse.mismatch_after) * 10 <= excess(coarse.mismatch_before)
