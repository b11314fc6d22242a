"""Edge pairing and hole loops of algorithms/healing/adjacency.py on a closed solid whose
faces have inner loops."""

from __future__ import annotations

from helpers.heal_cases import slotted_plate

from surfprep.algorithms.healing.adjacency import face_edges, hole_loops, pair_edges
from surfprep.plugin.occ.faces import face_to_nurbs
from surfprep.plugin.occ.shapes import all_faces


def test_the_walls_of_a_slot_pair_with_the_inner_loops_and_make_no_hole():
    # a plate with a square slot through it: the top and bottom faces meet the four
    # walls along their inner loops. Read from the outer loops only, the walls' top and
    # bottom edges were free and chained into two four-sided "holes" (the slot's mouths)
    faces = [face_to_nurbs(f) for f in all_faces(slotted_plate())]
    edges = face_edges(faces)
    inner = [e for e in edges if e.k < 0]
    assert len(inner) == 8 and len({e.face for e in inner}) == 2
    assert sorted(e.k for e in inner if e.face == inner[0].face) == [-4, -3, -2, -1]
    pairs = pair_edges(edges, 1e-3)
    paired = {k for pair in pairs for k in pair}
    assert len(paired) == len(edges) == 2 * len(pairs)       # closed: each edge paired once
    assert hole_loops(edges, [], 1e-3) == []
    outer = [e for e in edges if e.k >= 0]
    outer_pairs = pair_edges(outer, 1e-3)
    free = sorted(set(range(len(outer))) - {k for pair in outer_pairs for k in pair})
    assert len(hole_loops(outer, free, 1e-3)) == 2           # what the outer loops alone say
