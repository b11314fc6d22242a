"""The network of 001 §8: connectivity, topology rules, compatibility, G0/G1 joins.

Patches are interpolants of samples of one smooth graph z = f(x, y), cut at
different resolutions (mismatched knots along shared sides), some shifted,
flipped or transposed; joins are checked by dense independent measurements
(closest points on the other surface), not by the construction.
"""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.healing.compatibility import make_compatible
from surfprep.algorithms.healing.connectivity import (
    NetworkTopologyError,
    Side,
    find_connectivity,
    side_points,
)
from surfprep.algorithms.healing.network import Continuity, connect
from surfprep.algorithms.projection import project_to_surface
from surfprep.errors import InvalidGeometryError


def graph(x, y):
    return 0.3 * np.sin(1.3 * x) * np.cos(0.9 * y) + 0.1 * x * y


def patch(x0, x1, y0, y1, nu, nv, dz=0.0, flip_u=False, swap=False, noise=0.0, seed=0):
    x, y = np.linspace(x0, x1, nu), np.linspace(y0, y1, nv)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    z = graph(gx, gy) + dz + noise * np.random.default_rng(seed).standard_normal(gx.shape)
    net = np.stack([gx, gy, z], axis=-1)
    if flip_u:
        net = net[::-1]
    if swap:
        net = np.swapaxes(net, 0, 1)
    return interpolate_surface(net)


def grid_with_noisy_middle():
    """3 x 3 patches over [0, 1]^2, resolutions 5..7, the middle one perturbed by 2e-3."""
    out = []
    for i in range(3):
        for j in range(3):
            middle = (i, j) == (1, 1)
            out.append(patch(i / 3, (i + 1) / 3, j / 3, (j + 1) / 3, 5 + i, 5 + j,
                             noise=2e-3 if middle else 0.0, seed=1))
    return out


def dense_gap_and_angle(sa, side_a, sb, n=400):
    """Independent check: samples of a side projected onto the whole other surface."""
    points = side_points(sa, side_a, n)
    foot = project_to_surface(sb, points)
    lo, hi = side_a.running_domain(sa)
    uv = side_a.uv(sa, np.linspace(lo, hi, n))
    na = sa.normals(uv[:, 0], uv[:, 1])
    nb = sb.normals(foot.uv[:, 0], foot.uv[:, 1])
    sin = np.linalg.norm(np.cross(na, nb), axis=1)
    angle = np.degrees(np.arctan2(sin, np.abs(np.sum(na * nb, axis=1))))
    return foot.distance.max(), angle.max()


# ------------------------------------------------------------- connectivity
def test_connectivity_finds_flipped_transposed_neighbour():
    a = patch(0, 1, 0, 1, 6, 6)
    b = patch(1, 2, 0, 1, 9, 7, dz=1e-3, flip_u=True, swap=True)
    table = find_connectivity([a, b], gap_tol=5e-3)
    assert len(table.edges) == 1
    e = table.edges[0]
    assert (e.a, e.side_a, e.b, e.side_b) == (0, Side.U1, 1, Side.V1)
    assert 9e-4 < e.gap_estimate < 1.1e-3
    assert len(table.corners) == 2
    # a gap larger than gap_tol is no contact
    assert find_connectivity([a, b], gap_tol=5e-4).edges == ()


def test_bifurcation_is_refused():
    a = patch(0, 1, 0, 1, 5, 5)
    b = patch(1, 2, 0, 1, 5, 5)
    # a fin standing on the shared side x = 1
    x, y = np.meshgrid([1.0, 1.0, 1.0, 1.0], np.linspace(0, 1, 5), indexing="ij")
    z = graph(x, y) + np.linspace(0, 0.5, 4)[:, None]
    fin = interpolate_surface(np.stack([x, y, z], -1))
    with pytest.raises(NetworkTopologyError, match="at most two"):
        find_connectivity([a, b, fin], gap_tol=1e-3)
    table = find_connectivity([a, b, fin], gap_tol=1e-3, strict=False)
    assert table.edges == () and len(table.violations) == 1


@pytest.mark.parametrize("gap_tol", [1e-3, 0.1])
def test_partial_contact_is_refused(gap_tol):
    a = patch(0, 1, 0, 1, 5, 5)
    b = patch(1, 2, 0, 0.5, 5, 5)        # meets half of a's side: a T-junction
    with pytest.raises(NetworkTopologyError, match="full-face"):
        find_connectivity([a, b], gap_tol=gap_tol)


@pytest.mark.parametrize("gap_tol", [1e-3, 0.1, 0.3])
def test_sides_meeting_at_a_corner_do_not_touch_however_wide_gap_tol(gap_tol):
    # a 2 x 2 grid: sides leaving a common vertex lie within gap_tol of each other up to
    # gap_tol from it (48 false "touch over part of their length" at a tenth of a side)
    grid = [patch(i, i + 1, j, j + 1, 5, 5) for i in range(2) for j in range(2)]
    table = find_connectivity(grid, gap_tol=gap_tol)
    assert len(table.edges) == 4 and table.violations == ()
    assert len(find_connectivity(grid, gap_tol=gap_tol, strict=False).violations) == 0


# ------------------------------------------------------------ compatibility
def test_compatible_patches_keep_geometry_and_share_knots():
    a = patch(0, 1, 0, 1, 6, 6)
    b = patch(1, 2, 0, 1, 9, 7, flip_u=True, swap=True)
    table = find_connectivity([a, b], gap_tol=1e-4)   # interpolants differ by 5e-6
    ca, cb = make_compatible([a, b], table)
    t = np.linspace(0, 1, 53)
    for old, new in ((a, ca), (b, cb)):
        u0, u1, v0, v1 = old.domain
        ref = old.evaluate_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0))
        assert np.abs(new.evaluate_grid(t, t) - ref).max() < 1e-12
    # shared: side u1 of a (runs in v) and side v1 of b (runs in u), same direction
    assert ca.n_control[1] == cb.n_control[0]
    np.testing.assert_allclose(ca.knots_v, cb.knots_u, atol=1e-12)
    assert ca.knots_v.size > max(a.knots_v.size, b.knots_u.size)     # knots were inserted
    assert ca.degree_u >= 3 and cb.degree_v >= 3


def test_rational_patches_are_refused():
    a = patch(0, 1, 0, 1, 5, 5)
    w = np.ones(a.n_control)
    w[2, 2] = 2.0
    ra = type(a)(a.control_points, a.knots_u, a.knots_v, 3, 3, w)
    b = patch(1, 2, 0, 1, 5, 5)
    with pytest.raises(InvalidGeometryError, match="rational"):
        connect([ra, b])


# --------------------------------------------------------------- G0 and G1
@pytest.mark.parametrize("continuity", ["G0", "G1"])
def test_gap_of_1e3_and_mismatched_edge_are_closed(continuity):
    a = patch(0, 1, 0, 1, 6, 6)
    b = patch(1, 2, 0, 1, 9, 7, dz=1e-3, flip_u=True, swap=True)
    net = connect([a, b], continuity=continuity, gap_tol=5e-3)
    (before,), (after,) = net.joins_before, net.joins
    assert before.max_gap > 9e-4
    assert after.max_gap < 1e-12
    gap, angle = dense_gap_and_angle(net.patches[0], Side.U1, net.patches[1])
    assert gap < 1e-9
    assert abs(angle - after.max_angle) < 0.05 * after.max_angle + 1e-4
    if continuity == "G1":
        assert after.max_angle < 1e-3
    # the patches still follow the graph (they moved by about half the gap)
    for p in net.patches:
        pts = p.evaluate_grid(np.linspace(0, 1, 40), np.linspace(0, 1, 40))
        assert np.abs(pts[..., 2] - graph(pts[..., 0], pts[..., 1])).max() < 1.2e-3


def test_grid_with_noisy_middle_g1():
    patches = grid_with_noisy_middle()
    g0 = connect(patches, continuity=Continuity.G0)
    g1 = connect(patches, continuity=Continuity.G1)
    assert len(g1.edges) == 12 and len(g1.connectivity.corners) == 12
    assert max(j.max_gap for j in g1.joins_before) > 2e-3
    assert max(j.max_angle for j in g1.joins_before) > 5.0
    assert g0.max_gap < 1e-12 and g1.max_gap < 1e-12
    assert g0.max_angle > 1.0                     # averaging alone leaves kinks
    assert g1.max_angle < 0.1                     # degrees, measured (0.054: twist
    # conditions around the hole's valence-4 corners conflict, least squares there)
    # independent dense check of the worst G1 edge
    worst = max(g1.joins, key=lambda j: j.max_angle)
    gap, angle = dense_gap_and_angle(g1.patches[worst.a], worst.side_a, g1.patches[worst.b])
    assert gap < 1e-9 and angle < 0.1
    # interior corners: one point
    for cluster in g1.connectivity.corners:
        pts = [side_points(g1.patches[p], s, 2)[e] for p, s, e in cluster.members]
        assert np.ptp(np.array(pts), axis=0).max() < 1e-12


def test_single_patch_and_bad_continuity():
    a = patch(0, 1, 0, 1, 5, 5)
    net = connect([a], continuity="g1")
    assert net.edges == () and len(net.free_sides()) == 4
    with pytest.raises(InvalidGeometryError, match="G0"):
        connect([a], continuity="C2")


def test_fit_side_to_curve_closes_gap_to_a_kept_face():
    from surfprep.algorithms.healing.continuity import fit_side_to_curve
    from surfprep.algorithms.projection import project_to_curve
    a = patch(0, 1, 0, 1, 5, 5)
    kept = patch(1, 2, 0, 1, 12, 9, dz=1e-3)           # an untouched neighbour, finer
    edge = kept.isocurve(kept.domain[0], "u")           # its side at x = 1
    before = project_to_curve(edge, side_points(a, Side.U1, 300)).distance.max()
    snapped = fit_side_to_curve(a, Side.U1, edge, min_spans=16, free_corners=(True, True))
    after = project_to_curve(edge, side_points(snapped, Side.U1, 300)).distance.max()
    assert before > 9e-4 and after < 1e-6
    # the opposite side and the interior away from the edge are untouched
    t = np.linspace(0, 1, 50)
    np.testing.assert_allclose(snapped.evaluate(np.zeros(50), t),
                               a.evaluate(np.zeros(50), t), atol=1e-12)
