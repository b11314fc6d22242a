"""Caps over loops of free edges, their kind and their four-sided sub-patches
(hole_cap.py), checked against exact surfaces."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import fan_around_hole, gentle_height

from surfprep.algorithms.face_region import inside_loops
from surfprep.algorithms.fitting import interpolate_curve
from surfprep.algorithms.healing.hole_cap import (
    HoleCap,
    LoopKind,
    NotCappableError,
    cap_hole,
    hole_quads,
    loop_width,
    orient_loop,
    surroundings,
)
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.trimmed import TrimmedFace
from surfprep.errors import InvalidGeometryError


def _inside_cap(cap: HoleCap, n: int = 60) -> np.ndarray:
    """(k, 3) points of the cap inside its rim (its own (s, t) outline)."""
    s = np.linspace(0.0, 1.0, n)
    ss, tt = np.meshgrid(s, s, indexing="ij")
    st = np.column_stack([ss.ravel(), tt.ravel()])
    st = st[inside_loops(st, [cap.outline()])]
    return cap.surface.evaluate(st[:, 0], st[:, 1])


def _sphere_loop(n: int, polar: float, *, shuffle: bool = False, bulge: float = 0.15) -> list:
    """``n`` arcs on the unit sphere joining ``n`` points at polar angle ``polar``, each
    bulging towards the pole by ``bulge`` of it in the middle (interpolated through 17
    points on the sphere)."""
    azimuth = np.linspace(0.0, 2 * np.pi, n + 1)
    curves = []
    for k in range(n):
        a = np.linspace(azimuth[k], azimuth[k + 1], 17)
        # the rim bulges towards the pole between the corners: a curved n-gon
        theta = polar * (1 - bulge * np.sin(np.pi * (a - azimuth[k]) / (azimuth[k + 1] - azimuth[k])))
        pts = np.column_stack([np.sin(theta) * np.cos(a), np.sin(theta) * np.sin(a), np.cos(theta)])
        c = interpolate_curve(pts)
        curves.append(c if not (shuffle and k % 2) else _reversed(c))
    return curves


def _reversed(c):
    from surfprep.algorithms.healing.decompose import reverse_curve
    return reverse_curve(c)


def _sphere_ring(polar: float, width: float) -> np.ndarray:
    """Points of the unit sphere in the band ``polar .. polar + width``."""
    theta, phi = np.meshgrid(np.linspace(polar, polar + width, 12),
                             np.linspace(0, 2 * np.pi, 90, endpoint=False))
    return np.column_stack([(np.sin(theta) * np.cos(phi)).ravel(),
                            (np.sin(theta) * np.sin(phi)).ravel(), np.cos(theta).ravel()])


@pytest.mark.parametrize("n", [3, 5, 6])
def test_a_hole_in_a_sphere_is_capped_by_the_sphere(n):
    curves = _sphere_loop(n, 0.35, shuffle=True)
    cap = cap_hole(curves, _sphere_ring(0.36, 0.15))
    assert cap.kind is LoopKind.HOLE and cap.continued
    assert cap.slope < 25.0                 # the sphere turns by ~0.35 rad across the rim
    assert cap.covered == 0.0
    pts = _inside_cap(cap)
    assert pts.shape[0] > 500
    # nothing is known inside the hole: the smoothest continuation of the rim and
    # the band (a quadric is reproduced exactly, below) misses the sphere's r^4 / 8
    # term, about 1.5e-3 at the middle of a hole of radius 0.34; the rim alone
    # leaves the sagitta, 0.05
    assert np.abs(np.linalg.norm(pts, axis=1) - 1.0).max() < 2e-3


@pytest.mark.parametrize("n", [4, 6, 8])
def test_a_hole_in_a_quadric_is_capped_exactly(n):
    # centrally symmetric about the z axis, so the rim's best-fit plane is z = const
    # and the quadric is a quadratic graph over it: the spline's polynomial part
    def quadric(x, y):
        return 0.4 * x * x - 0.3 * x * y + 0.2 * y * y

    surfaces = fan_around_hole(n, height=quadric, centre=(0.0, 0.0))
    rim = [s.isocurve(0.0, "v") for s in surfaces]
    samples = np.concatenate([c.evaluate(np.linspace(0, 1, 20)) for c in rim])
    cap = cap_hole(rim, surroundings([TrimmedFace(s) for s in surfaces], samples, reach=0.1))
    pts = _inside_cap(cap)
    assert np.abs(pts[:, 2] - quadric(pts[:, 0], pts[:, 1])).max() < 1e-9


def _sphere_angle(cap: HoleCap, curves) -> float:
    """Degrees: the largest angle between the cap's normal and the sphere's along the rim."""
    pts = np.concatenate([c.evaluate(np.linspace(*c.domain, 40)) for c in curves])
    foot = project_to_surface(cap.surface, pts)
    n = cap.surface.normals(foot.uv[:, 0], foot.uv[:, 1])
    cos = np.abs(np.einsum("kc,kc->k", n, pts / np.linalg.norm(pts, axis=1, keepdims=True)))
    return float(np.degrees(np.arccos(np.clip(cos, -1, 1))).max())


def test_the_surroundings_give_the_cap_their_tangent_planes_at_the_rim():
    # a circle of latitude: planar, so through the rim alone the cap is its flat disc,
    # 0.35 rad (20 degrees) off the sphere's tangent planes along the rim
    curves = _sphere_loop(5, 0.35, bulge=0.0)
    with_ring = cap_hole(curves, _sphere_ring(0.351, 0.15))
    alone = cap_hole(curves)
    assert not alone.continued and np.isnan(alone.slope)
    assert _sphere_angle(alone, curves) == pytest.approx(np.degrees(0.35), abs=0.01)
    assert _sphere_angle(with_ring, curves) < 0.1


def test_orient_loop_turns_curves_head_to_tail():
    curves = orient_loop(_sphere_loop(5, 0.3, shuffle=True))
    ends = np.array([c.evaluate(np.array(c.domain)) for c in curves])
    gaps = np.linalg.norm(ends[:, 1] - np.roll(ends[:, 0], -1, axis=0), axis=1)
    assert gaps.max() < 1e-12


@pytest.mark.parametrize("n", [3, 5, 6, 8])
def test_hole_quads_cover_the_rim_with_spokes_shared(n):
    surfaces = fan_around_hole(n)
    rim = [s.isocurve(0.0, "v") for s in surfaces]
    around = surroundings([TrimmedFace(s) for s in surfaces],
                          np.concatenate([c.evaluate(np.linspace(0, 1, 20)) for c in rim]),
                          reach=0.1)
    cap = cap_hole(rim, around)
    quads = hole_quads(cap)
    assert len(quads) == n
    assert all(sides == (0, 3) for _, sides in quads)
    for curves, _ in quads:                       # each a closed loop of four
        ends = np.array([c.evaluate(np.array(c.domain)) for c in curves])
        assert np.linalg.norm(ends[:, 1] - np.roll(ends[:, 0], -1, axis=0), axis=1).max() < 1e-9
    # rim sides: their lengths add up to the rim's; spokes: each used by two quads
    rim_length = sum(c.arc_length() for c in rim)
    sides = sum(q[0].arc_length() + q[3].arc_length() for q, _ in quads)
    assert sides == pytest.approx(rim_length, rel=1e-6)
    centre = [q[2].evaluate(q[2].domain[0]) for q, _ in quads]
    assert np.ptp(np.array(centre), axis=0).max() < 1e-9          # one centre
    for i in range(n):
        mine, theirs = quads[i][0][1], quads[(i + 1) % n][0][2]    # out-spoke / in-spoke
        t = np.linspace(0, 1, 11)
        a = mine.evaluate(mine.domain[0] + t * np.ptp(mine.domain))
        b = theirs.evaluate(theirs.domain[1] - t * np.ptp(theirs.domain))
        assert np.abs(a - b).max() < 1e-10
    # the spokes lie on the graph the fan was cut from, to the cap's accuracy
    spoke = np.concatenate([q[2].evaluate(np.linspace(*q[2].domain, 21)) for q, _ in quads])
    assert np.abs(spoke[:, 2] - gentle_height(spoke[:, 0], spoke[:, 1])).max() < 5e-6


def test_four_corners_give_one_patch_over_all_four_sides():
    surfaces = fan_around_hole(4)
    rim = [s.isocurve(0.0, "v") for s in surfaces]
    (quad, sides), = hole_quads(cap_hole(rim))
    assert sides == (0, 1, 2, 3) and len(quad) == 4


def test_the_end_of_a_pipe_is_an_open_boundary():
    phi = np.linspace(0, 2 * np.pi, 5)
    rim = [interpolate_curve(np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)]))
           for a in (np.linspace(phi[k], phi[k + 1], 9) for k in range(4))]
    a, z = np.meshgrid(np.linspace(0, 2 * np.pi, 80), np.linspace(-0.3, -0.01, 10))
    wall = np.column_stack([np.cos(a).ravel(), np.sin(a).ravel(), z.ravel()])
    cap = cap_hole(rim, wall)
    assert cap.kind is LoopKind.OPEN and cap.slope > 80.0
    assert cap.covered < 0.05 and not cap.continued
    # the cap through the rim alone is the disc
    assert np.abs(_inside_cap(cap)[:, 2]).max() < 1e-9


def test_the_outer_edge_of_a_sheet_is_open_and_covered():
    surfaces = fan_around_hole(5)
    outer = [s.isocurve(1.0, "v") for s in surfaces]
    samples = np.concatenate([c.evaluate(np.linspace(0, 1, 20)) for c in outer])
    around = surroundings([TrimmedFace(s) for s in surfaces], samples, reach=0.2)
    cap = cap_hole(outer, around)
    assert cap.kind is LoopKind.OPEN
    assert cap.covered > 0.5


def test_surroundings_stay_inside_the_trimmed_faces_and_within_reach():
    surfaces = fan_around_hole(4)
    rim = np.concatenate([s.isocurve(0.0, "v").evaluate(np.linspace(0, 1, 30))
                          for s in surfaces])
    pts = surroundings([TrimmedFace(s) for s in surfaces], rim, reach=0.05)
    assert pts.shape[0] > 100
    from scipy.spatial import cKDTree
    d, _ = cKDTree(rim).query(pts)
    assert d.max() <= 0.05
    on = np.min([project_to_surface(s, pts).distance for s in surfaces], axis=0)
    assert on.max() < 1e-9


def test_loops_without_a_cap_are_refused_with_the_reason():
    line = [interpolate_curve(np.array([[0.0, 0, 0], [1, 0, 0]]), degree=1),
            interpolate_curve(np.array([[1.0, 0, 0], [0, 0, 0]]), degree=1)]
    with pytest.raises(NotCappableError, match="no area"):
        cap_hole(line)
    # a bow tie with unequal lobes: two of its sides cross seen along its plane's normal
    corners = np.array([[0.0, 0, 0], [3, 1, 0], [3, 0, 0], [0, 2, 0]])   # cross at samples
    eight = [interpolate_curve(corners[[k, (k + 1) % 4]], degree=1) for k in range(4)]
    with pytest.raises(NotCappableError, match="folds over itself"):
        cap_hole(eight)
    # a corner touching another side (at its middle) is a fold too
    corners = np.array([[0.0, 0, 0], [2, 0, 0], [2, 2, 0], [1, 0, 0], [0, 1, 0]])
    touching = [interpolate_curve(corners[[k, (k + 1) % 5]], degree=1) for k in range(5)]
    with pytest.raises(NotCappableError, match="folds over itself"):
        cap_hole(touching)
    with pytest.raises(InvalidGeometryError, match="open_angle"):
        cap_hole(_sphere_loop(4, 0.3), open_angle=95.0)


@pytest.mark.parametrize("angle", [0.3, 1.1, 2.0, 2.9])
def test_a_short_gently_bent_edge_on_a_rim_is_no_fold(angle):
    # the bearing's hole: a 2.5e-4 long, barely bent edge on a rim 0.1 across; its 24
    # samples lie on each other's lines within rounding, beyond each other's ends, which
    # read as touching (the loop "folded over itself" and was not capped)
    rotation = np.array([[np.cos(angle), -np.sin(angle), 0.0],
                         [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    t = np.linspace(0.0, 2.5e-4, 5)
    short = np.column_stack([t, 4e-4 * t ** 2 / 2.5e-4, np.zeros_like(t)]) @ rotation.T
    far = short[-1] + rotation @ np.array([0.0, 0.1, 0.0])
    back = short[0] + rotation @ np.array([-0.05, 0.05, 0.0])
    curves = [interpolate_curve(short, degree=2),
              interpolate_curve(np.array([short[-1], far]), degree=1),
              interpolate_curve(np.array([far, back]), degree=1),
              interpolate_curve(np.array([back, short[0]]), degree=1)]
    cap = cap_hole(curves)
    # the cap of a flat rim without surroundings is its plane
    u0, u1, v0, v1 = cap.surface.domain
    grid = cap.surface.evaluate_grid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 9))
    assert np.abs(grid[..., 2]).max() < 1e-9


def test_a_sliver_is_a_few_thousandths_of_its_length_wide_and_a_hole_is_not():
    x = np.linspace(0.0, 10.0, 21)
    lower = interpolate_curve(np.column_stack([x, np.zeros_like(x), np.zeros_like(x)]))
    # a lens: the upper curve 0.02 above the lower in the middle, meeting it at both ends
    upper = interpolate_curve(np.column_stack([x[::-1], 0.02 * np.sin(np.pi * x[::-1] / 10),
                                               np.zeros_like(x)]))
    width, length = loop_width([lower, upper])
    assert width == pytest.approx(0.02, rel=1e-3) and length == pytest.approx(20.0, rel=1e-4)
    square = [interpolate_curve(np.array(pair, float), degree=1) for pair in
              ([[0, 0, 0], [1, 0, 0]], [[1, 0, 0], [1, 1, 0]], [[1, 1, 0], [0, 1, 0]],
               [[0, 1, 0], [0, 0, 0]])]
    width, length = loop_width(square)
    assert width == pytest.approx(0.5, rel=1e-6) and length == pytest.approx(4.0)
