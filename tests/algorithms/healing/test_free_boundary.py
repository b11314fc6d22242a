"""What free edges are: sides of gaps, or the open boundary (or a hole's rim)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.healing.free_boundary import BESIDE, classify_free_edges
from surfprep.errors import InvalidGeometryError


def segment(a, b, n: int = 9) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)[:, None]
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a + t * (b - a)


def square(x0: float, y0: float, side: float = 1.0, n: int = 9) -> list[np.ndarray]:
    c = [(x0, y0, 0), (x0 + side, y0, 0), (x0 + side, y0 + side, 0), (x0, y0 + side, 0)]
    return [segment(c[k], c[(k + 1) % 4], n) for k in range(4)]


def test_two_faces_side_by_side_have_a_gap_between_them_and_the_rest_is_boundary():
    lines = square(0, 0) + square(1.03, 0)
    fb = classify_free_edges(lines, [0] * 4 + [1] * 4, join=0.05)
    assert fb.kinds == ("boundary", "gap", "boundary", "boundary",
                        "boundary", "boundary", "boundary", "gap")
    # the facing sides are 0.03 apart everywhere
    assert fb.widths[1] == pytest.approx(0.03, abs=1e-12)
    assert fb.widths[7] == pytest.approx(0.03, abs=1e-12)
    assert np.isnan(fb.widths[[0, 2, 3, 4, 5, 6]]).all()
    assert fb.loop_kinds == ("gap and boundary",)
    assert fb.edges == {"gap": 2, "open boundary": 6, "hole": 0}
    assert fb.interior == 2
    assert fb.as_dict()["widest_gap"] == pytest.approx(0.03, abs=1e-12)
    # the loop's interior part: the two facing sides, of faces 0 and 1, 2 long
    (loop,) = fb.as_dict()["interior_loops"]
    assert loop["kind"] == "gap and boundary" and loop["edges"] == 2
    assert loop["faces"] == [0, 1] and loop["length"] == pytest.approx(2.0, abs=1e-12)
    assert loop["widest_gap"] == pytest.approx(0.03, abs=1e-12)


def test_faces_apart_make_separate_loops_and_a_lone_sheet_is_all_boundary():
    lines = square(0, 0) + square(5, 0)
    fb = classify_free_edges(lines, [0] * 4 + [1] * 4, join=0.05)
    assert set(fb.kinds) == {"boundary"}
    assert fb.loop_kinds == ("open boundary", "open boundary")
    assert list(fb.loop) == [0] * 4 + [1] * 4
    assert fb.interior == 0
    assert fb.as_dict() == {"edges": {"gap": 0, "open boundary": 8, "hole": 0},
                            "interior": 0, "loops": {"open boundary": 2},
                            "widest_gap": None, "interior_loops": []}


def test_a_long_edge_against_the_short_edges_of_a_t_junction_is_a_gap_on_both_sides():
    # face 0's top edge from 0 to 2; faces 1 and 2 sit above it 0.02 up, 1 wide each
    long = segment((0, 0, 0), (2, 0, 0))
    left = segment((0, 0.02, 0), (1, 0.02, 0))
    right = segment((1, 0.02, 0), (2, 0.02, 0))
    fb = classify_free_edges([long, left, right], [0, 1, 2], join=0.05)
    assert fb.kinds == ("gap", "gap", "gap")
    np.testing.assert_allclose(fb.widths, 0.02, atol=1e-12)
    assert fb.loop_kinds == ("gap",)
    # and a second gap, wider, elsewhere: listed first
    wide = classify_free_edges([long, left, right, long + (0, 0, 5), long + (0, 0.08, 5)],
                               [0, 1, 2, 3, 4], join=0.1)
    first, second = wide.interior_loops()
    assert first["faces"] == [3, 4] and first["widest_gap"] == pytest.approx(0.08)
    assert second["faces"] == [0, 1, 2] and second["length"] == pytest.approx(4.0)


@pytest.mark.parametrize(("degrees", "kind"), [(3.0, "gap"), (6.0, "boundary")])
def test_edges_of_two_faces_leaving_one_vertex_are_a_gap_only_at_a_sliver_angle(degrees, kind):
    # at angle a their three-quarter points lie 3 sin(a) / 4 of their length apart:
    # BESIDE = 0.05 is about 3.8 degrees
    a = np.radians(degrees)
    first = segment((0, 0, 0), (1, 0, 0))
    second = segment((0, 0, 0), (np.cos(a), np.sin(a), 0))
    fb = classify_free_edges([first, second], [0, 1], join=1e-6)
    assert 0.75 * np.sin(np.radians(3.0)) < BESIDE < 0.75 * np.sin(np.radians(6.0))
    assert fb.kinds == (kind, kind)


def test_a_slot_cut_into_one_face_is_its_boundary_not_a_gap():
    # a face's outline running into a slot 0.01 wide and back: only other faces make gaps
    lines = [segment((0, 0, 0), (1, 0, 0)), segment((1, 0, 0), (1, 0.495, 0)),
             segment((1, 0.495, 0), (0.2, 0.495, 0)), segment((0.2, 0.495, 0), (0.2, 0.505, 0)),
             segment((0.2, 0.505, 0), (1, 0.505, 0)), segment((1, 0.505, 0), (1, 1, 0)),
             segment((1, 1, 0), (0, 1, 0)), segment((0, 1, 0), (0, 0, 0))]
    fb = classify_free_edges(lines, [0] * len(lines), join=1e-6)
    assert set(fb.kinds) == {"boundary"}
    assert fb.loop_kinds == ("open boundary",)


def test_a_loop_along_a_rim_classified_as_a_hole_counts_as_interior():
    # four faces around a unit hole: its four edges, one per face
    rim = square(0, 0)
    owners = [0, 1, 2, 3]
    # the rim as classified, sampled apart from the free edges' points: 5 samples a
    # side against 9, so most points lie between its samples
    hole = [segment(p[0], p[-1], 5) for p in rim]
    fb = classify_free_edges(rim, owners, join=1e-3, holes=[hole])
    assert fb.loop_kinds == ("hole",)
    assert fb.edges == {"gap": 0, "open boundary": 0, "hole": 4}
    assert fb.interior == 4
    assert fb.interior_loops() == [{"kind": "hole", "edges": 4, "faces": [0, 1, 2, 3],
                                    "length": pytest.approx(4.0), "widest_gap": None}]
    # the same loop next to a rim elsewhere is an open boundary
    far = classify_free_edges(rim, owners, join=1e-3,
                              holes=[[p + (0.0, 0.0, 0.01) for p in hole]])
    assert far.loop_kinds == ("open boundary",)
    assert far.interior == 0


def test_dense_polylines_are_classified_as_the_coarse_ones():
    coarse = square(0, 0) + square(1.03, 0)
    dense = square(0, 0, n=129) + square(1.03, 0, n=129)
    owners = [0] * 4 + [1] * 4
    a = classify_free_edges(coarse, owners, join=0.05)
    b = classify_free_edges(dense, owners, join=0.05)
    assert a.kinds == b.kinds
    np.testing.assert_allclose(a.widths, b.widths, atol=1e-12)


def test_a_curved_gap_is_measured_between_the_curves():
    # concentric quarter arcs of radii 1 and 1.05 (faces 0 and 1), 33 of their 65
    # samples kept: chords of pi/64, whose sagitta is r (1 - cos(pi/128)); the inner
    # arc's points lie 0.05 from the outer arc less up to its sagitta, the outer arc's
    # 0.05 from the inner one plus up to its sagitta
    t = np.linspace(0.0, np.pi / 2, 65)
    inner = np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
    outer = 1.05 * inner
    fb = classify_free_edges([inner, outer], [0, 1], join=0.1)
    sag = 1 - np.cos(np.pi / 128)
    assert fb.kinds == ("gap", "gap")
    assert 0.05 - 1.05 * sag - 1e-12 <= fb.widths[0] <= 0.05 + 1e-12
    assert 0.05 - 1e-12 <= fb.widths[1] <= 0.05 + sag + 1e-12


def test_the_sides_of_a_short_sewn_edge_are_a_gap_however_far_apart_for_their_length():
    # an edge 0.1 long whose faces lie 0.02 apart (a fifth of it): by the rule a
    # boundary, but sewing shares it, so its two sides are a gap's, 0.02 wide
    a = segment((0, 0, 0), (0.1, 0, 0))
    b = a + (0.0, 0.0, 0.02)
    loose = classify_free_edges([a, b], [0, 1], join=0.05)
    assert loose.kinds == ("boundary", "boundary")
    sewn = classify_free_edges([a, b], [0, 1], join=0.05, sewn=[True, True])
    assert sewn.kinds == ("gap", "gap") and sewn.interior == 2
    np.testing.assert_allclose(sewn.widths, 0.02, atol=1e-12)


def test_many_tiny_edges_beside_a_long_one_do_not_cut_it_into_billions_of_pieces():
    # 200 degenerate edges 1e-9 long (most segments tiny) and one 1000 long: the long
    # one is classified as ever, the search cut into pieces of a quarter of the mean
    tiny = [segment((5.0 * k, 500.0, 0.0), (5.0 * k + 1e-9, 500.0, 0.0)) for k in range(200)]
    long = segment((0.0, 0.0, 0.0), (1000.0, 0.0, 0.0))
    fb = classify_free_edges(tiny + [long], list(range(201)), join=1e-12)
    assert fb.kinds[-1] == "boundary" and fb.edges["open boundary"] == 201


def test_no_free_edge_gives_an_empty_answer():
    fb = classify_free_edges([], [], join=0.1)
    assert fb.kinds == () and fb.loop_kinds == () and fb.interior == 0


@pytest.mark.parametrize(("lines", "owners", "join", "message"), [
    ([segment((0, 0, 0), (1, 0, 0))], [0, 1], 0.1, "one face per polyline"),
    ([np.zeros((2, 3))], [0], 0.1, r"\(m >= 3, 3\) finite"),
    ([np.full((5, 3), np.nan)], [0], 0.1, r"\(m >= 3, 3\) finite"),
    ([np.zeros((5, 2))], [0], 0.1, r"\(m >= 3, 3\) finite"),
    ([segment((0, 0, 0), (1, 0, 0))], [0], float("nan"), "join must be"),
    ([segment((0, 0, 0), (1, 0, 0))], [0], -1.0, "join must be"),
])
def test_bad_input_is_refused_with_a_clear_message(lines, owners, join, message):
    with pytest.raises(InvalidGeometryError, match=message):
        classify_free_edges(lines, owners, join=join)


def test_one_sewn_flag_per_polyline_is_asked_for():
    with pytest.raises(InvalidGeometryError, match="one flag per polyline"):
        classify_free_edges([segment((0, 0, 0), (1, 0, 0))], [0], join=0.1,
                            sewn=[True, False])
