"""One local approximant end to end (001 §§3-7, Figs. 5-8 kinds; 003 four points).

Every deviation is checked densely: a grid of points on the approximant is projected
onto the exact original surfaces (Newton point inversion), never only at the
interpolated points."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import (
    crossing_surfaces,
    envelope_boundary,
    holed_mesh,
    iso_boundary,
    oscillating_surface,
    smooth_surface,
    stepped_gap,
    surrounding_patches,
    upper_envelope,
)

from surfprep.algorithms.face_region import inside_loops
from surfprep.algorithms.healing import (
    FillMethod,
    Interpolant,
    SurfaceSource,
    corners_boundary,
    local_approximant,
)
from surfprep.algorithms.healing.clipping import trimmed_source
from surfprep.algorithms.intersection.mesh import TriangleMesh
from surfprep.algorithms.projection import distance_to_curve, distance_to_surface
from surfprep.errors import (
    DegenerateGeometryError,
    InvalidGeometryError,
    InvalidToleranceError,
)

HOLE = (0.4, 0.6, 0.4, 0.6)          # in the smooth surface's parameters
PATCH = (0.2, 0.8, 0.2, 0.8)         # the approximant's boundary, around the hole


def _dense(result, n=61):
    s = np.linspace(0.0, 1.0, n)
    return s, result.surface.evaluate_grid(s, s)


def _fixed(boundary, sources, res, **kw):
    return local_approximant(boundary, sources, resolution=(res, res),
                             max_resolution=(res, res), **kw)


@pytest.fixture(scope="module")
def smooth():
    return smooth_surface()


def test_part_of_a_single_patch(smooth):
    r = local_approximant(iso_boundary(smooth, *PATCH), [smooth], tol=1e-4)
    assert r.converged and r.max_error <= 1e-4
    assert r.artificial_share == 0.0 and np.all(r.source == 0)
    _, pts = _dense(r)
    dense = distance_to_surface(smooth, pts.reshape(-1, 3))
    assert dense.max() < 1.5e-4                       # the e/f/g estimate is close to the truth
    assert dense.max() < 1.5 * r.max_error
    assert r.rms_error <= r.max_error
    # the grid points are on the surface, and the approximant's sides on the boundary curves
    assert distance_to_surface(smooth, r.grid.reshape(-1, 3)).max() < 1e-9
    s = np.linspace(0, 1, 41)
    curves = iso_boundary(smooth, *PATCH)
    sides = [r.surface.evaluate(s, 0.0), r.surface.evaluate(1.0, s),
             r.surface.evaluate(s, 1.0), r.surface.evaluate(0.0, s)]
    for side, curve in zip(sides, curves, strict=True):
        assert distance_to_curve(curve, side).max() < r.tol


def test_error_decreases_with_resolution(smooth):
    errors = [_fixed(iso_boundary(smooth, *PATCH), [smooth], m).max_error for m in (4, 8, 16)]
    assert errors[0] > 3 * errors[1] > 9 * errors[2]          # ~ h^2 at least


def test_hole_between_four_patches(smooth):
    sources = surrounding_patches(smooth, HOLE)
    r = _fixed(iso_boundary(smooth, *PATCH), sources, 12)
    assert r.artificial_share > 0.03
    # the artificial points are exactly the grid points over the hole
    xy = r.grid[..., :2]
    inside = ((xy[..., 0] > HOLE[0] + 1e-6) & (xy[..., 0] < HOLE[1] - 1e-6)
              & (xy[..., 1] > HOLE[2] + 1e-6) & (xy[..., 1] < HOLE[3] - 1e-6))
    np.testing.assert_array_equal(r.artificial, inside)
    assert r.max_error < 1e-4                          # measured away from the hole
    # dense check away from the hole (cells with a found corner only)
    _s, pts = _dense(r)
    near_sources = np.min([distance_to_surface(p, pts.reshape(-1, 3)) for p in sources], axis=0)
    around = ~np.asarray([(HOLE[0] - .05 < x < HOLE[1] + .05) and (HOLE[2] - .05 < y < HOLE[3] + .05)
                          for x, y in pts.reshape(-1, 3)[:, :2]])
    assert near_sources[around].max() < 2 * r.max_error
    # over the hole the Hardy fill follows the surface that was cut away
    assert distance_to_surface(smooth, pts.reshape(-1, 3)).max() < 2e-3


def test_hole_bounded_by_its_rim_is_filled_from_the_rim(smooth):
    # the four-sided hole of a network: the boundary is the hole's edges, no interior
    # segment meets anything; Hardy's fill from the rim follows the cut-away surface
    r = _fixed(iso_boundary(smooth, *HOLE), surrounding_patches(smooth, HOLE), 8)
    assert np.all(r.artificial[1:-1, 1:-1]) and not np.any(r.artificial[[0, -1]])
    assert r.artificial_share == pytest.approx(49 / 81)
    _, pts = _dense(r)
    assert distance_to_surface(smooth, pts.reshape(-1, 3)).max() < 2e-4


def test_gap_with_a_step_between_two_surfaces():
    boundary, sources = stepped_gap(step=0.01)
    r = _fixed(boundary, sources, 8)
    assert 0 < r.artificial_share < 0.2
    assert set(np.unique(r.source)) == {-1, 0, 1}
    xy = r.grid[..., 0]
    np.testing.assert_array_equal(r.artificial[1:-1, 1:-1],
                                  ((xy > 0.45) & (xy < 0.55))[1:-1, 1:-1])
    assert r.max_error < 1e-3                          # cells over the gap left out
    # dense check away from the gap, against both sources
    _, pts = _dense(r)
    pts = pts.reshape(-1, 3)
    away = (pts[:, 0] < 0.4) | (pts[:, 0] > 0.6)
    dense = np.min([distance_to_surface(src, pts[away]) for src in sources], axis=0)
    assert dense.max() < 2 * r.max_error
    # over the gap the approximant bridges the step between the two rims (no overshoot)
    line = r.surface.evaluate(np.linspace(0, 1, 401), 0.5)
    over = line[(line[:, 0] > 0.45) & (line[:, 0] < 0.55)]
    rims = np.array([sources[0].evaluate(0.45, over[0, 1])[2],
                     sources[1].evaluate(0.55, over[0, 1])[2]])
    assert np.all(over[:, 2] > rims.min() - 2e-3) and np.all(over[:, 2] < rims.max() + 2e-3)


@pytest.mark.parametrize("with_surface", [False, True])
def test_hole_in_a_triangle_mesh(smooth, with_surface):
    mesh = holed_mesh(smooth, HOLE)
    source = SurfaceSource(smooth, mesh) if with_surface else mesh
    r = _fixed(iso_boundary(smooth, *PATCH), [source], 8)
    assert r.artificial_share > 0.05
    assert np.all(r.source[~r.artificial] == 0)
    assert r.max_error < 2e-4
    _, pts = _dense(r)
    assert distance_to_surface(smooth, pts.reshape(-1, 3)).max() < 2e-3


def test_global_and_local_hardy_agree_roughly(smooth):
    b, src = iso_boundary(smooth, *PATCH), surrounding_patches(smooth, HOLE)
    local = _fixed(b, src, 10)
    glob = _fixed(b, src, 10, fill=FillMethod.HARDY_GLOBAL)
    np.testing.assert_array_equal(local.artificial, glob.artificial)
    np.testing.assert_array_equal(local.grid[~local.artificial], glob.grid[~glob.artificial])
    assert np.abs(local.grid - glob.grid).max() < 5e-3


def test_patch_across_two_intersecting_surfaces():
    surfaces = crossing_surfaces()
    errors = []
    for m in (4, 8, 16):
        r = _fixed(envelope_boundary(0.2, 0.8, 0.2, 0.8), surfaces, m)
        # every grid point lies on the upper envelope (the hit nearest the Coons patch)
        # (inside exactly; the sides are samples of the polylines on it)
        g = r.grid[1:-1, 1:-1].reshape(-1, 3)
        np.testing.assert_allclose(g[:, 2], upper_envelope(g[:, 0], g[:, 1]), atol=1e-12)
        g = r.grid.reshape(-1, 3)
        np.testing.assert_allclose(g[:, 2], upper_envelope(g[:, 0], g[:, 1]), atol=1e-5)
        assert set(np.unique(r.source)) == {0, 1}
        errors.append(r.max_error)
        _, pts = _dense(r)
        dense = np.min([distance_to_surface(s, pts.reshape(-1, 3)) for s in surfaces], axis=0)
        assert dense.max() < 2 * r.max_error
    assert errors[0] > errors[1] > errors[2]           # the crease is rounded less and less
    assert r.artificial_share == 0.0


def test_four_picked_points_straight_boundary():
    # 003: four points on the originals, straight lines between them (here across the
    # crease, so the lines float above it); the block's points are all projected
    surfaces = crossing_surfaces()
    corners = [np.array([x, y, upper_envelope(x, y)]) for x, y in
               ((0.2, 0.2), (0.8, 0.2), (0.8, 0.8), (0.2, 0.8))]
    r = _fixed(corners_boundary(*corners), surfaces, 8, keep_boundary=False)
    np.testing.assert_allclose(r.surface.evaluate([0, 1, 1, 0], [0, 0, 1, 1]), corners,
                               atol=1e-9)
    g = r.grid.reshape(-1, 3)
    np.testing.assert_allclose(g[:, 2], upper_envelope(g[:, 0], g[:, 1]), atol=1e-12)
    assert r.artificial_share == 0.0 and r.max_error < 0.01
    _, pts = _dense(r)
    dense = np.min([distance_to_surface(s, pts.reshape(-1, 3)) for s in surfaces], axis=0)
    assert dense.max() < 2 * r.max_error
    # kept straight sides: they float above the crease, so the error of §7 leaves out
    # the cells along them, and the sides are the lines
    kept = _fixed(corners_boundary(*corners), surfaces, 8)
    side = kept.surface.evaluate(np.linspace(0, 1, 21), 0.0)
    line = corners[0] + np.linspace(0, 1, 21)[:, None] * (corners[1] - corners[0])
    np.testing.assert_allclose(side, line, atol=1e-12)
    assert kept.max_error < 0.02 and kept.error.n_points < r.error.n_points


def test_oscillating_surface_needs_more_resolution():
    wavy = oscillating_surface()
    boundary = iso_boundary(wavy, 0.1, 0.9, 0.1, 0.9)
    coarse = _fixed(boundary, [wavy], 8, tol=1e-3)
    assert not coarse.converged and coarse.max_error > 1e-3
    with pytest.raises(InvalidToleranceError, match="not reached"):
        _fixed(boundary, [wavy], 8, tol=1e-3, strict=True)
    r = local_approximant(boundary, [wavy], tol=1e-3)
    assert r.converged and r.resolution[0] > 8
    assert next(h.resolution for h in r.history) == (8, 8)
    assert r.history[-1].max_error <= 1e-3 < r.history[0].max_error
    _, pts = _dense(r, 91)
    assert distance_to_surface(wavy, pts.reshape(-1, 3)).max() < 1.5e-3


def test_c2_interpolant_option(smooth):
    r = _fixed(iso_boundary(smooth, *PATCH), [smooth], 8, interpolant=Interpolant.C2_BICUBIC)
    assert r.surface.n_control == (9, 9) and r.interpolant is Interpolant.C2_BICUBIC
    _, pts = _dense(r)
    dense = distance_to_surface(smooth, pts.reshape(-1, 3))
    assert dense.max() < 1e-4 and dense.max() < 1.5 * r.max_error


def test_given_offset_and_unreachable_sources(smooth):
    b = iso_boundary(smooth, *PATCH)
    r = _fixed(b, [smooth], 6, offset=0.05)
    assert r.offset == 0.05
    far = smooth.control_points + np.array([0.0, 0.0, 5.0])
    from surfprep.algorithms.surface import NurbsSurface
    moved = NurbsSurface(far, smooth.knots_u, smooth.knots_v, 3, 3)
    with pytest.raises(DegenerateGeometryError, match="no segment"):
        _fixed(b, [moved], 6)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"tol": 1e-20}, InvalidToleranceError, "double precision"),
    ({"tol": 1e3}, InvalidToleranceError, "absurdly large"),
    ({"tol": float("nan")}, InvalidToleranceError, "finite"),
    ({"tol": -1.0}, InvalidToleranceError, "finite"),
    ({"resolution": (1, 8)}, InvalidGeometryError, ">= 2"),
    ({"resolution": (16, 16)}, InvalidGeometryError, "at least resolution"),
    ({"offset": 0.0}, InvalidToleranceError, "offset"),
    ({"neighbours": 0}, InvalidGeometryError, "neighbours"),
])
def test_bad_arguments(smooth, kwargs, error, match):
    with pytest.raises(error, match=match):
        local_approximant(iso_boundary(smooth, *PATCH), [smooth],
                          max_resolution=kwargs.pop("max_resolution", (12, 12)), **kwargs)


def test_bad_boundary_and_sources(smooth):
    b = iso_boundary(smooth, *PATCH)
    with pytest.raises(InvalidGeometryError, match="no original surfaces"):
        local_approximant(b, [])
    with pytest.raises(InvalidGeometryError, match="source 0 must be"):
        local_approximant(b, [np.zeros((3, 3))])
    shifted = [b[0], b[1], b[2].evaluate(np.linspace(*b[2].domain, 9)) + [0, 0, 0.01], b[3]]
    with pytest.raises(InvalidGeometryError, match=r"do not meet end to end.*0\.01"):
        local_approximant(shifted, [smooth])
    with pytest.raises(InvalidGeometryError, match="NaN"):
        local_approximant([np.full((3, 3), np.nan)] + list(b[1:]), [smooth])


def test_surface_source_validation(smooth):
    with pytest.raises(InvalidGeometryError, match="surface, a mesh or both"):
        SurfaceSource()
    mesh = holed_mesh(smooth, HOLE)
    plain = TriangleMesh(mesh.vertices, mesh.triangles)
    with pytest.raises(InvalidGeometryError, match=r"mesh's \(u, v\)"):
        SurfaceSource(smooth, plain)


def test_trimmed_face_with_a_round_hole(smooth):
    # a face trimmed by a square and a circular hole (loops in (u, v)): projections miss
    # the hole, the error is measured around it, the fill follows the surface under it
    angle = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    hole = np.stack([0.5 + 0.1 * np.cos(angle), 0.5 - 0.1 * np.sin(angle)], axis=1)
    outer = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    face = trimmed_source(smooth, [outer, hole], name="holed")
    corners = face.mesh.triangle_uv()                       # a triangle across the rim stays
    assert not np.any(np.all(np.linalg.norm(corners - 0.5, axis=-1) < 0.1, axis=1))
    assert np.any(np.linalg.norm(corners - 0.5, axis=-1) < 0.1)
    assert inside_loops(np.array([[0.5, 0.5], [0.2, 0.2], [1.5, 0.5]]), [outer, hole]).tolist() \
        == [False, True, False]
    r = _fixed(iso_boundary(smooth, *PATCH), [face], 12)
    xy = r.grid[..., :2]
    assert np.all(r.artificial[np.linalg.norm(xy - 0.5, axis=-1) < 0.09])
    assert r.artificial_share > 0.05 and r.max_error < 1e-3
    _, pts = _dense(r)
    assert distance_to_surface(smooth, pts.reshape(-1, 3)).max() < 1e-3
    with pytest.raises(InvalidGeometryError, match="inside the trimming loops"):
        trimmed_source(smooth, [outer + 5.0])


def test_ring_carries_the_surroundings_into_a_rim_bounded_hole(smooth):
    # 16 x 16 over the hole's own edges: the thin-plate fill with the ring of projections
    # beyond the rim follows the cut-away surface several times closer than the Coons
    # interior (Hardy's fill from the rim alone), checked densely against the true surface
    boundary, sources = iso_boundary(smooth, *HOLE), surrounding_patches(smooth, HOLE)
    ring = _fixed(boundary, sources, 16)
    rim_only = _fixed(boundary, sources, 16, fill=FillMethod.HARDY_LOCAL)
    assert ring.artificial_share == pytest.approx(15 ** 2 / 17 ** 2)
    dev_ring = distance_to_surface(smooth, _dense(ring)[1].reshape(-1, 3)).max()
    dev_rim = distance_to_surface(smooth, _dense(rim_only)[1].reshape(-1, 3)).max()
    assert dev_ring < 0.5 * dev_rim
    assert dev_ring < 2e-5


def test_hole_refined_to_the_fill_resolution(smooth):
    # the error of §7 skips the hole, so tol is met at 8 x 8; the fill still gets 16 x 16
    r = local_approximant(iso_boundary(smooth, *HOLE), surrounding_patches(smooth, HOLE))
    assert r.converged and min(r.resolution) >= 16
    full = local_approximant(iso_boundary(smooth, *PATCH), [smooth])
    assert full.resolution == (8, 8)                   # nothing missing: no refinement
