"""Faces re-trimmed to their neighbours' edges (algorithms/healing/retrim.py)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.healing.adjacency import face_edges, pair_edges, pair_gaps
from surfprep.algorithms.healing.loop_sides import signed_area
from surfprep.algorithms.healing.retrim import retrim_faces, retrim_partners
from surfprep.algorithms.projection import distance_to_surface
from tests.helpers.heal_cases import LID_SHORT, graph_surface, short_lid_box

GAP_TOL = 0.01


def _free(faces):
    edges = face_edges(faces)
    pairs = pair_edges(edges, GAP_TOL)
    paired = {k for p in pairs for k in p}
    return edges, pairs, [k for k in range(len(edges)) if k not in paired]


def _uv_outline(face):
    pts = []
    for e in face.loops[0].edges:
        uv = e.pcurve.evaluate(np.linspace(e.t0, e.t1, 65))
        pts.append((uv[::-1] if e.reversed else uv)[:-1])
    return np.concatenate(pts)


def test_the_short_lid_is_retrimmed_to_its_walls_and_nothing_else_moves():
    faces = short_lid_box()
    edges, pairs, free = _free(faces)
    # the lid's south, east and north edges are free (its west edge pairs with its wall)
    assert sorted(edges[k].k for k in free if edges[k].face == 0) == [0, 1, 2]
    new, retrims, notes = retrim_faces(faces, edges, free, pairs=pairs)
    assert notes == []
    assert [r.face for r in retrims] == [0]
    r = retrims[0]
    assert sorted(face for face, _ in r.partners) == [2, 3, 4]      # east, south, north walls
    assert r.width == pytest.approx(LID_SHORT, rel=0.05)            # the loop moved 0.05
    assert r.deviation < 1e-4                                       # the walls' tops on the lid
    for i in range(1, 5):
        assert new[i] is faces[i]                                   # walls untouched
    assert new[0].surface is faces[0].surface                       # the lid's surface too
    # exact answer: the lid's loop is now the square [0.1, 0.9]^2 in (u, v)
    outline = _uv_outline(new[0])
    assert outline.min(axis=0) == pytest.approx([0.1, 0.1], abs=1e-5)
    assert outline.max(axis=0) == pytest.approx([0.9, 0.9], abs=1e-5)
    assert signed_area(outline) == pytest.approx(0.64, abs=1e-4)
    # every new edge lies on the lid's surface, densely
    for e in new[0].loops[0].edges:
        pts = e.curve3d.evaluate(np.linspace(e.t0, e.t1, 101))
        assert distance_to_surface(new[0].surface, pts).max() < 1e-4
    # the lid now pairs with every wall: only the walls' bottoms stay free
    _, _, still_free = _free(new)
    assert len(still_free) == 4


def test_a_partner_beyond_the_surface_is_not_taken():
    """The lid's surface ends where its loop does: the east wall's top lies off it."""
    lid = graph_surface(lambda x, y: 0.2 * np.sin(2 * x) * np.cos(1.5 * y), samples=9)
    clipped = lid.restrict(None, 0.9 - LID_SHORT, None, None)
    faces = short_lid_box(lid_surface=lid)
    faces[0] = type(faces[0])(clipped, faces[0].loops)
    edges, pairs, free = _free(faces)
    partners = retrim_partners(faces, edges, free)
    assert all(edges[a].face != 0 for a, _, _, _ in partners)
    new, retrims, _ = retrim_faces(faces, edges, free, pairs=pairs)
    assert retrims == [] and new[0] is faces[0]


def test_tol_bounds_the_distance_of_the_partner_from_the_surface():
    faces = short_lid_box()
    edges, pairs, free = _free(faces)
    deviation = retrim_faces(faces, edges, free, pairs=pairs)[1][0].deviation
    new, retrims, _notes = retrim_faces(faces, edges, free, pairs=pairs, tol=0.5 * deviation)
    assert retrims == [] and new[0] is faces[0]


def test_a_gap_wider_than_the_retrim_width_is_left():
    faces = short_lid_box(short=0.3)         # 0.3 of an edge of 0.8: no partners
    edges, _pairs, free = _free(faces)
    assert retrim_partners(faces, edges, free) == []


def test_loose_pairs_of_a_face_nothing_else_closes_are_retrimmed_too():
    """The lid 0.005 short: its edges pair with the walls' within gap_tol (0.01), 0.005
    apart in the geometry. Given as loose pairs (the lid the face to re-trim), the lid
    takes the walls' edges; without them nothing happens."""
    faces = short_lid_box(short=0.005)
    edges, pairs, free = _free(faces)
    gaps = pair_gaps(edges, pairs)
    loose = [(own, other, float(gap)) for (a, b), gap in zip(pairs, gaps) if gap > 1e-3
             for own, other in ((a, b), (b, a)) if edges[own].face == 0]
    assert len(loose) == 3                              # south, east, north
    assert retrim_faces(faces, edges, free, pairs=pairs)[1] == []
    new, retrims, refused = retrim_faces(faces, edges, free, pairs=pairs, loose=loose)
    assert refused == [] and [r.face for r in retrims] == [0]
    outline = _uv_outline(new[0])
    assert outline.max(axis=0) == pytest.approx([0.9, 0.9], abs=1e-5)
    assert retrims[0].width == pytest.approx(0.005, rel=0.05)
    # the walls' edges now are the lid's: closed in the geometry to the deviation
    edges_after = face_edges(new)
    gaps_after = pair_gaps(edges_after, pair_edges(edges_after, GAP_TOL))
    assert gaps_after.max() < 1e-4


def test_an_edge_along_two_shorter_edges_is_replaced_by_both():
    """A T-junction: the east wall is two faces (y below and above 0.5) and the lid
    stops 0.005 short of them, within gap_tol: the lid's east edge lies along both
    walls' tops, neither pairs with it; the lid's east edge becomes the two tops."""
    faces = short_lid_box(short=0.005, split_east=True)
    edges, pairs, free = _free(faces)
    east = next(k for k in free if edges[k].face == 0 and edges[k].k == 1)
    tops = sorted(k for k in free if edges[k].face in (4, 5) and edges[k].k == 0)
    assert len(tops) == 2
    options = [o for o in retrim_partners(faces, edges, free) if o[0] == east]
    assert len(options) == 1 and sorted(options[0][1]) == tops
    new, retrims, refused = retrim_faces(faces, edges, free, pairs=pairs)
    assert refused == []
    lid = next(r for r in retrims if r.face == 0)
    # the two east tops, and the south and north walls' tops: paired with the lid's
    # (within gap_tol), their corner moves 0.005 with the east side, more than tol
    assert sorted(f for f, _ in lid.partners) == [2, 3, 4, 5]
    assert len(new[0].loops[0].edges) == 5                 # the east side in two
    outline = _uv_outline(new[0])
    assert outline.max(axis=0)[0] == pytest.approx(0.9, abs=1e-5)
    # the corner between the two new edges lies where the walls meet, y = 0.5
    middle = new[0].loops[0].edges[1].pcurve
    ends = middle.evaluate(np.array(middle.domain))
    assert np.any(np.isclose(ends[:, 1], 0.5, atol=1e-5))
    # nothing of the lid or the walls' tops is free any more
    edges_after, _, still_free = _free(new)
    assert not [k for k in still_free if edges_after[k].face == 0]
