"""Faces re-trimmed to their neighbours' edges inside surfprep.heal (plugin/heal/retrim.py):
the lid of an open box trimmed short, and the two faces of occt_k1_catia_theorem.stp
whose loops run 0.1 mm beside their neighbours'."""

from __future__ import annotations

import numpy as np
import pytest

import surfprep
from surfprep.algorithms.healing.adjacency import face_edges, pair_edges
from surfprep.algorithms.projection import distance_to_surface
from surfprep.plugin.heal import _default_gap_tol
from surfprep.plugin.heal.retrim import retrim_to_neighbours
from surfprep.plugin.io import read
from surfprep.plugin.occ.faces import face_to_nurbs, trimmed_face_to_occ
from surfprep.plugin.occ.shapes import face_area, is_valid
from tests.helpers.heal_cases import short_lid_box


def test_heal_closes_the_short_lid_by_retrimming_it():
    faces = short_lid_box()
    occ = [trimmed_face_to_occ(f) for f in faces]
    r = surfprep.heal(occ, gap_tol=0.01)
    retrimmed = r.report()["retrimmed"]
    assert [x["face"] for x in retrimmed] == [0]
    assert retrimmed[0]["moved"] == pytest.approx(0.05, rel=0.05)
    assert retrimmed[0]["deviation"] < 1e-4
    # sewn at gap_tol: 8 free edges before; after, also in the geometry (sewn at
    # 1e-7 x size), only the four bottoms of the walls (the box has no floor); without
    # the re-trimming (measured): 8 -> 8 at gap_tol, 12 -> 8 in the geometry
    assert r.free_edges_before == 8
    assert r.free_edges_after == 4
    assert r.tight_free_edges_after == 4
    assert r.valid_after
    # the lid keeps its surface and now covers [0.1, 0.9]^2 of it: the area of that face
    full = short_lid_box(short=0.0)[0]
    expected = face_area(trimmed_face_to_occ(full), 1e-9)
    lid = max(r.model.faces, key=lambda f: face_area(f))
    assert face_area(lid, 1e-9) == pytest.approx(expected, rel=1e-4)


def test_k1_theorem_faces_retrimmed_to_their_neighbours(data_dir):
    """Faces 54 and 55: every edge but one 0.09-0.1 mm beside a neighbour's edge (seven
    times gap_tol) that lies within 1e-4 mm of their surfaces; re-trimmed, no edge of
    the model is left free at gap_tol (32 before)."""
    model = read(data_dir / "occt_k1_catia_theorem.stp")
    faces = [face_to_nurbs(f, n) for f, n in zip(model.faces, model.face_names)]
    edges = face_edges(faces)
    gap_tol = _default_gap_tol(model, edges)
    pairs = pair_edges(edges, gap_tol)
    free_before = len(edges) - len({k for p in pairs for k in p})
    notes: list[str] = []
    work, new, retrims = retrim_to_neighbours(model, faces, edges, pairs, tol=None,
                                              tight=1e-7 * model.size, kept=set(), skipped=notes)
    assert free_before == 32
    assert sorted(r.face for r in retrims) == [54, 55]
    assert all(0.09 < r.width < 0.11 and r.deviation < 2e-4 for r in retrims)
    edges_after = face_edges(new)
    pairs_after = pair_edges(edges_after, gap_tol)
    assert len(edges_after) == len({k for p in pairs_after for k in p})      # none free
    for r in retrims:
        assert is_valid(work.faces[r.face])
        for loop in new[r.face].loops:
            for e in loop.edges:
                pts = e.curve3d.evaluate(np.linspace(*e.curve3d.domain, 65))
                assert distance_to_surface(new[r.face].surface, pts).max() < 2e-4
    untouched = [i for i in range(len(faces)) if i not in (54, 55)]
    assert all(work.faces[i].IsSame(model.faces[i]) for i in untouched)


def test_k1_autocad_long_edges_retrimmed_to_chains_of_short_ones(data_dir):
    """occt_k1geo_autocad.stp: T-junctions within gap_tol (a closed edge of 2.8 mm on
    faces 0 and 6 against three shorter edges of faces 1 and 2, 6e-4 mm off and on
    the long edge's surface); pairing edge to edge leaves 58 free at gap_tol, after
    the re-trimming 18 (measured)."""
    model = read(data_dir / "occt_k1geo_autocad.stp")
    faces = [face_to_nurbs(f, n) for f, n in zip(model.faces, model.face_names)]
    edges = face_edges(faces)
    gap_tol = _default_gap_tol(model, edges)
    pairs = pair_edges(edges, gap_tol)
    assert len(edges) - len({k for p in pairs for k in p}) == 58
    work, new, retrims = retrim_to_neighbours(model, faces, edges, pairs, tol=None,
                                              tight=1e-7 * model.size, kept=set(),
                                              skipped=[])
    by_face = {r.face: r for r in retrims}
    assert {0, 6} <= set(by_face)
    for f in (0, 6):
        assert {1, 2} <= {p for p, _ in by_face[f].partners}
        assert by_face[f].deviation < 2e-4 and is_valid(work.faces[f])
    edges_after = face_edges(new)
    pairs_after = pair_edges(edges_after, gap_tol)
    assert len(edges_after) - len({k for p in pairs_after for k in p}) <= 18
