"""Where the open edges' ends go (plugin/heal/common_curves.py): the vertices, and at a
vertex where the fixed faces' corners lie apart across a gap that stays open, each
group of faces joined by edges that can close."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.algorithms.healing.edge_targets import END_FADE
from surfprep.plugin.heal.common_curves import FaceCorners, vertex_positions
from surfprep.plugin.heal.shared_edges import SharedEdge

TIGHT = 1e-3


def _edge(faces: list[int], first: int, last: int) -> SharedEdge:
    return SharedEdge(edge=None, faces=faces, ranges=[(0.0, 1.0)] * len(faces),
                      first=first, last=last)


def _fan(gap: float):
    """Vertex 0 where fixed faces 1 and 2 meet across a gap ``gap`` wide (edge a), moving
    face 3 meets face 1 (edge b) and moving face 4 meets face 2 (edge c). Each image runs
    from its face's corner at vertex 0 to the edge's far vertex."""
    corner = {1: np.zeros(3), 2: np.array([0.0, gap, 0.0]), 3: np.zeros(3),
              4: np.array([0.0, gap, 0.0])}
    a, b, c = _edge([1, 2], 0, 1), _edge([1, 3], 0, 2), _edge([2, 4], 0, 3)
    images = {}
    for e in (a, b, c):
        for i, f in enumerate(e.faces):
            far = np.array([1.0, 0.0, 0.0]) * (1 + e.last)
            images[id(e), i] = np.stack([corner[f], far])
    return (a, b, c), images


def test_edges_at_a_vertex_whose_fixed_corners_lie_apart_end_at_their_own_groups_corner():
    edges, images = _fan(0.2)
    a, b, c = edges
    position = vertex_positions(edges, list(edges), {3, 4}, images, None, TIGHT)
    # the vertex itself at the fixed corners' mean, its tolerance covering both groups
    assert np.allclose(position.at[0], [0.0, 0.1, 0.0])
    # the closed edge between fixed face 1 and moving face 3 ends at face 1's corner
    # (at the mean it would lie 0.1 off face 1 there), and face 2's group at face 2's
    assert np.allclose(position.ends(b)[0], [0.0, 0.0, 0.0])
    assert np.allclose(position.ends(c)[0], [0.0, 0.2, 0.0])
    # the open edge between the two fixed faces keeps the vertex's point
    assert np.allclose(position.ends(a)[0], [0.0, 0.1, 0.0])
    # far ends: one face each side, nothing to split
    assert np.allclose(position.ends(b)[1], [3.0, 0.0, 0.0])


def test_fixed_corners_within_tight_share_the_vertex():
    edges, images = _fan(0.5 * TIGHT)
    position = vertex_positions(edges, list(edges), {3, 4}, images, None, TIGHT)
    for e in edges:
        assert np.allclose(position.ends(e)[0], [0.0, 0.25 * TIGHT, 0.0])


def test_a_moving_face_between_two_fixed_faces_apart_follows_the_one_it_meets_closer():
    # face 3 meets fixed face 1 within 1e-6 (edge b) and fixed face 2 across 0.1
    # (edge c), faces 1 and 2 lying 0.2 apart: its corner stays at face 1's, and edge c
    # ends there too (face 2's side cannot follow, face 3's corner is one point); at
    # the fixed corners' mean edge b would open to 0.1
    corner = {1: np.zeros(3), 2: np.array([0.0, 0.2, 0.0]), 3: np.zeros(3)}
    a, b, c = _edge([1, 2], 0, 1), _edge([1, 3], 0, 2), _edge([2, 3], 0, 3)
    a.gap, b.gap, c.gap = 0.2, 1e-6, 0.1
    images = {(id(e), i): np.stack([corner[f], np.ones(3) * (1 + e.last)])
              for e in (a, b, c) for i, f in enumerate(e.faces)}
    position = vertex_positions((a, b, c), [a, b, c], {3}, images, None, TIGHT)
    assert np.allclose(position.ends(b)[0], [0.0, 0.0, 0.0])
    assert np.allclose(position.ends(c)[0], [0.0, 0.0, 0.0])
    # the other way round when face 3 meets face 2 the closer
    b.gap, c.gap = 0.1, 1e-6
    position = vertex_positions((a, b, c), [a, b, c], {3}, images, None, TIGHT)
    assert np.allclose(position.ends(b)[0], [0.0, 0.2, 0.0])
    assert np.allclose(position.ends(c)[0], [0.0, 0.2, 0.0])


# ------------------------------------------------------------------ face corners
def _on_face(f: int, first: int, last: int, start, end, seam_side=None) -> SharedEdge:
    """An edge of face ``f`` from vertex ``first`` to ``last`` whose pcurve is the line
    ``start`` -> ``end`` (and, on a seam, ``seam_side`` its other side's line)."""
    def line(a, b):
        return NurbsCurve(np.array([a, b], dtype=float), [0, 0, 1, 1], 1)

    e = SharedEdge(edge=None, faces=[f], ranges=[(0.0, 1.0)], first=first, last=last,
                   seam=seam_side is not None)
    e.curves[0, False] = line(start, end)
    if seam_side is not None:
        e.curves[0, True] = line(*seam_side)
    return e


def _unit_face() -> NurbsSurface:
    x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
    return NurbsSurface(np.stack([x, y, 0 * x], -1), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def test_pcurve_ends_a_little_apart_at_a_vertex_become_one_corner():
    """Face 5's edges b and c meet at vertex 1, but c's pcurve starts 1.6e-5 above
    where b's ends (as on the K1 CATIA/debis export): both end at their mean, the shift
    fading out along each edge; ends lying alone stay where they are."""
    a = _on_face(5, 0, 1, (0, 0), (1, 0))
    c = _on_face(5, 1, 2, (1, 1.6e-5), (1, 1))
    d = _on_face(5, 2, 0, (1, 1), (0, 0))
    corners = FaceCorners.of([5], {5: [a, c, d]}, None, {5: _unit_face()})
    assert np.allclose(corners.at[5, 1], [[1.0, 8e-6]], rtol=0, atol=1e-15)
    s = np.linspace(0.0, 1.0, 41)
    on_a = corners.snapped(a.curves[0, False].evaluate(s), s, 5, a)
    on_c = corners.snapped(c.curves[0, False].evaluate(s), s, 5, c)
    assert np.array_equal(on_a[-1], on_c[0]) and np.allclose(on_a[-1], [1.0, 8e-6])
    # faded: the far ends and everything beyond END_FADE from the corner as it was
    assert np.array_equal(on_a[s <= 1 - END_FADE], a.curves[0, False].evaluate(s[s <= 1 - END_FADE]))
    assert np.array_equal(on_c[s >= END_FADE], c.curves[0, False].evaluate(s[s >= END_FADE]))
    assert np.all(np.diff(on_c[:, 1]) > 0)      # still in order along the edge


def test_the_two_sides_of_a_seam_keep_their_own_corners():
    """A face closed in u: its seam (u = 0 and u = 1) meets the bottom edge at vertex 0
    on both sides; those two ends lie a period apart and stay two corners."""
    seam = _on_face(3, 0, 1, (0, 0), (0, 1), seam_side=((1, 0), (1, 1)))
    bottom = _on_face(3, 0, 0, (0, 0), (1, 0))
    corners = FaceCorners.of([3], {3: [seam, bottom]}, None, {3: _unit_face()})
    got = corners.at[3, 0]
    assert got.shape == (2, 2)
    assert {tuple(p) for p in got} == {(0.0, 0.0), (1.0, 0.0)}
    s = np.linspace(0.0, 1.0, 11)
    other_side = seam.curves[0, True].evaluate(s)
    assert np.array_equal(corners.snapped(other_side, s, 3, seam), other_side)
