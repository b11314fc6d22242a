"""Rings of free edges and their strips (healing.ring_strip), on exact circles: which
loops make a ring, and strips whose sides lie on the loops and whose ruled surfaces
span the ring (a flat annulus, a cone's band)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.curve import NurbsCurve
from surfprep.algorithms.healing.decompose import reverse_curve
from surfprep.algorithms.healing.ring_strip import NotARingError, ring_pairs, ring_strips

S2 = np.sqrt(0.5)
SQUARE = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                   [1, 0]], float)


def circle(radius, z=0.0, pieces=1, turn=0.0):
    """The circle of ``radius`` round the z axis at height ``z`` as ``pieces`` (1, 2 or
    4) exact rational arcs, the first starting at angle ``turn``."""
    c, s = np.cos(turn), np.sin(turn)
    xy = radius * SQUARE @ np.array([[c, s], [-s, c]])
    points = np.column_stack([xy, np.full(9, z)])
    weights = np.array([1, S2] * 4 + [1])
    per = 8 // pieces
    return [NurbsCurve(points[k * per:(k + 1) * per + 1],
                       np.concatenate([[0, 0, 0], np.repeat(np.arange(1, per // 2), 2),
                                       [per // 2] * 3]) / (per // 2), 2,
                       weights[k * per:(k + 1) * per + 1])
            for k in range(pieces)]


def _radius(points):
    return np.hypot(points[..., 0], points[..., 1])


def test_the_circle_helper_is_exact():
    for arc in circle(2.0, 0.5, 4, 0.3):
        p = arc.evaluate(np.linspace(*arc.domain, 101))
        np.testing.assert_allclose(_radius(p), 2.0, atol=1e-14)
        np.testing.assert_allclose(p[:, 2], 0.5)


def test_two_concentric_loops_make_a_ring_and_others_do_not():
    inner, outer = circle(10.0, pieces=1), circle(10.5, pieces=2, turn=0.4)
    far, touching = circle(15.0), circle(10.3, pieces=4)
    (pair,) = ring_pairs([inner, far, outer], gap_tol=0.01)
    assert (pair.first, pair.second) == (0, 2)
    # measured to the loops' polylines (chords 0.25 long: sagitta 7e-4)
    assert pair.width == pytest.approx(0.5, abs=1e-3)
    assert pair.narrowest == pytest.approx(0.5, abs=1e-3)
    # within gap_tol somewhere, sewing joins them: no ring
    assert ring_pairs([inner, outer], gap_tol=0.6) == []
    # of several, the nearest pair; each loop in one ring at most
    (nearest,) = ring_pairs([inner, touching, outer], gap_tol=0.01)
    assert {nearest.first, nearest.second} == {1, 2}
    assert nearest.width == pytest.approx(0.2, abs=1e-3)


def test_loops_farther_apart_than_a_sliver_are_no_ring():
    # 0.02 x the shorter loop's length (62.8 here): 1.26
    assert ring_pairs([circle(10.0), circle(11.0)], gap_tol=0.01) != []
    assert ring_pairs([circle(10.0), circle(11.5)], gap_tol=0.01) == []


@pytest.mark.parametrize("reverse", [False, True])
def test_strips_of_a_flat_annulus_lie_on_it(reverse):
    inner = circle(10.0, pieces=1, turn=0.2)
    outer = circle(10.5, pieces=2, turn=1.0)
    if reverse:                     # the other loop given the other way round
        outer = [reverse_curve(c) for c in reversed(outer)]
    strips = ring_strips(inner, outer, min_side=0.1)
    # the outer loop's two vertices, the inner one's one, none within 4 widths of another
    assert len(strips) == 3
    t = np.linspace(0.0, 1.0, 61)
    around = 0.0
    for sides, ruled in strips:
        low, _, high, _ = sides
        lp = low.evaluate(np.linspace(*low.domain, 61))
        hp = high.evaluate(np.linspace(*high.domain, 61))
        np.testing.assert_allclose(_radius(lp), 10.0, atol=1e-12)
        np.testing.assert_allclose(_radius(hp), 10.5, atol=1e-12)
        # the connectors cross the gap radially (between matched points)
        for connector in sides[1::2]:
            ends = connector.evaluate(np.array(connector.domain))
            assert np.linalg.norm(ends[0] - ends[1]) == pytest.approx(0.5, abs=1e-3)
        # the ruled surface is the annulus between the pieces, densely
        u, v = np.meshgrid(t, t, indexing="ij")
        pts = ruled.surface.evaluate(u.ravel(), v.ravel())
        assert np.abs(pts[:, 2]).max() < 1e-12
        assert _radius(pts).min() > 10.0 - 1e-6 and _radius(pts).max() < 10.5 + 1e-6
        # each strip turns the same way round, and together once
        a = np.unwrap(np.arctan2(lp[:, 1], lp[:, 0]))
        assert a[-1] > a[0]
        around += a[-1] - a[0]
    assert around == pytest.approx(2 * np.pi, abs=1e-9)


def test_a_conical_band_is_ruled_along_its_generators():
    # circles at z = 0 (r 10) and z = 0.2 (r 10.5): the band is the cone r = 10 + 2.5 z
    strips = ring_strips(circle(10.0, 0.0, 1), circle(10.5, 0.2, 1))
    assert len(strips) == 2
    t = np.linspace(0.0, 1.0, 41)
    u, v = np.meshgrid(t, t, indexing="ij")
    for _, ruled in strips:
        pts = ruled.surface.evaluate(u.ravel(), v.ravel())
        off = _radius(pts) - (10.0 + 2.5 * pts[:, 2])
        # a cubic spline through points pi/64 apart on the arcs: 5/384 h^4 / r^3, 7e-7
        assert np.abs(off).max() < 2e-6
        assert pts[:, 2].min() > -1e-9 and pts[:, 2].max() < 0.2 + 1e-9


def test_a_side_shorter_than_min_side_is_refused():
    with pytest.raises(NotARingError, match="no longer than"):
        ring_strips(circle(10.0), circle(10.5, pieces=2), min_side=0.6)


def test_loops_of_one_face_are_no_ring():
    # a band's two rims: the band's own faces have edges on both, and lie between them
    inner, outer = circle(10.0, pieces=2), circle(10.5, pieces=2)
    assert len(ring_pairs([inner, outer], gap_tol=0.01, owners=[{1, 2}, {3, 4}])) == 1
    assert ring_pairs([inner, outer], gap_tol=0.01, owners=[{1, 2}, {2, 4}]) == []
