"""The use-based non-manifold structure (002 §1): edges matched in space, their uses in
radial order, and the queries, on faces whose answers are known."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep import NurbsCurve, NurbsSurface, TrimmedFace
from surfprep.algorithms.face_split import Cut, split_face
from surfprep.algorithms.nonmanifold import NonManifoldModel
from surfprep.algorithms.volume_builders import block
from surfprep.algorithms.volume_measure import OUTWARD
from surfprep.errors import InvalidGeometryError


def bilinear(corners) -> NurbsSurface:
    """The bilinear surface with ``corners`` at (u, v) = (0, 0), (1, 0), (0, 1), (1, 1)."""
    c = np.asarray(corners, float)
    return NurbsSurface(np.array([[c[0], c[2]], [c[1], c[3]]]), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def line(a, b, dim) -> NurbsCurve:
    return NurbsCurve(np.array([a, b], float).reshape(2, dim), [0, 0, 1, 1], 1)


def crossing_sheets():
    """z = 0 and x = 0 over [-1, 1]^2, split along their common line x = z = 0."""
    a = bilinear([(-1, -1, 0), (1, -1, 0), (-1, 1, 0), (1, 1, 0)])     # (u, v) -> (2u-1, 2v-1, 0)
    b = bilinear([(0, -1, -1), (0, 1, -1), (0, -1, 1), (0, 1, 1)])     # (u, v) -> (0, 2u-1, 2v-1)
    curve = line((0, -1, 0), (0, 1, 0), 3)
    pieces_a = split_face(TrimmedFace(a), [Cut(line((0.5, 0), (0.5, 1), 2), curve)])
    pieces_b = split_face(TrimmedFace(b), [Cut(line((0, 0.5), (1, 0.5), 2), curve)])
    faces = pieces_a + pieces_b
    origins = [("a", 0)] * len(pieces_a) + [("b", 0)] * len(pieces_b)
    return NonManifoldModel.build(faces, origins, tol=1e-9)


def test_two_crossing_sheets_share_one_edge_used_by_four_faces_in_radial_order():
    model = crossing_sheets()
    assert len(model.faces) == 4
    assert model.edges_by_uses() == {1: 12, 4: 1}        # the borders cut in two where the line ends
    (edge,) = [e for e in range(model.n_edges) if len(model.uses[e]) == 4]
    around = model.faces_around(edge)
    # radial order alternates the sheets: a piece of one between the two pieces of the other
    operands = [model.operand(f) for f in around]
    assert operands in (["a", "b", "a", "b"], ["b", "a", "b", "a"])
    angles = np.array([u.angle for u in model.uses[edge]])
    np.testing.assert_allclose(np.diff(angles), np.pi / 2, atol=1e-9)   # the sheets are orthogonal
    # the edge's two vertices are the line's ends
    ends = model.vertices[model.edge_vertices[edge]]
    np.testing.assert_allclose(sorted(ends[:, 1]), [-1, 1], atol=1e-12)
    # each sheet's two pieces run the edge opposite ways
    for operand in "ab":
        against = [u.against for u in model.uses[edge] if model.operand(u.face) == operand]
        assert sorted(against) == [False, True]
    assert model.components() == [[0, 1, 2, 3]]
    assert len(model.free_edges()) == 12


def test_a_closed_block_has_twelve_edges_each_used_twice_and_eight_vertices():
    solid = block((1.0, 2.0, 3.0))
    faces = [TrimmedFace(s, reversed=name not in OUTWARD, name=name)
             for name, s in solid.exterior_faces().items()]
    model = NonManifoldModel.build(faces, tol=1e-9)
    assert model.edges_by_uses() == {2: 12}
    assert model.vertices.shape == (8, 3) and len(model.free_edges()) == 0
    assert model.components() == [[0, 1, 2, 3, 4, 5]]
    for e in range(model.n_edges):
        a, b = model.uses[e]
        # the two faces around a box edge are 90 degrees apart (seen from the edge)
        assert abs(abs(b.angle - a.angle) - np.pi / 2) < 1e-9 or abs(abs(b.angle - a.angle) - 1.5 * np.pi) < 1e-9
    assert sorted(len(model.edges_of(f)) for f in range(6)) == [4] * 6
    # oriented outward, the two faces run every edge opposite ways
    for uses in model.uses:
        a, b = (u.against != model.faces[u.face].reversed for u in uses)
        assert a != b


def test_faces_apart_are_separate_components_and_poles_are_no_edges():
    left = TrimmedFace(bilinear([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]))
    right = TrimmedFace(bilinear([(5, 0, 0), (6, 0, 0), (5, 1, 0), (6, 1, 0)]))
    # a triangle: the side u = 0 collapsed to one point (a pole)
    fan = TrimmedFace(bilinear([(0, 0, 2), (1, 0, 2), (0, 0, 2), (1, 1, 2)]))
    model = NonManifoldModel.build([left, right, fan], [("a", 0), ("a", 1), ("b", 0)], tol=1e-9)
    assert model.components() == [[0], [1], [2]]
    assert model.edges_by_uses() == {1: 11}               # 4 + 4 + 3: the pole is no edge
    assert model.operand(2) == "b" and model.origins[1] == ("a", 1)


def test_bad_arguments_are_refused():
    face = TrimmedFace(bilinear([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]))
    with pytest.raises(InvalidGeometryError, match="tol"):
        NonManifoldModel.build([face], tol=0.0)
    with pytest.raises(InvalidGeometryError, match="origins"):
        NonManifoldModel.build([face], [("a", 0), ("a", 1)], tol=1e-9)


def test_an_edge_used_the_other_way_round_and_on_another_range_is_put_on_one_parameter():
    # A: (u, v) -> (u, v, 0) on [0, 1]^2; B: (u, v) -> (1 - u / 5, 0, v) on [0, 5] x [0, 1]:
    # their common edge y = z = 0 runs x = 0..1 along A's u and x = 1..0 along B's u / 5
    a = bilinear([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)])
    b = NurbsSurface(np.array([[(1, 0, 0), (1, 0, 1)], [(0, 0, 0), (0, 0, 1)]], float),
                     [0, 0, 5, 5], [0, 0, 1, 1], 1, 1)
    model = NonManifoldModel.build([TrimmedFace(a), TrimmedFace(b)], tol=1e-9)
    (edge,) = [e for e in range(model.n_edges) if len(model.uses[e]) == 2]
    g = model.edge_geometry(edge)
    s = np.linspace(g.t0, g.t1, 11)
    reference = g.curve3d.evaluate(s) if g.curve3d is not None else None
    for use, pcurve in zip(g.uses, g.pcurves):
        uv = pcurve.evaluate(s)
        points = model.faces[use.face].surface.evaluate(uv[:, 0], uv[:, 1])
        if reference is None:
            reference = points
        np.testing.assert_allclose(points, reference, atol=1e-12)
    assert max(g.deviation) < 1e-12 and max(g.end_gap) < 1e-12
    np.testing.assert_allclose(model.vertices[[g.start, g.end]], g.ends, atol=1e-12)
    # A's loop (counter-clockwise) runs its side v = 0 along +x, B's (counter-clockwise in
    # its own (u, v)) along its u: -x; so the two faces run the edge opposite ways
    assert g.reversed[0] != g.reversed[1]
    # taken from B alone, B is the reference: its own range, not turned round
    only_b = model.edge_geometry(edge, {1})
    assert (only_b.t0, only_b.t1) == (0.0, 5.0) and only_b.uses[0].face == 1 and not only_b.reversed[0]
    with pytest.raises(InvalidGeometryError, match="no use"):
        model.edge_geometry(edge, {7})


def test_components_among_some_faces_only():
    model = crossing_sheets()
    # pieces 0 and 1 of sheet a touch only along the intersection edge: joined by it
    assert model.components([0, 1]) == [[0, 1]]
    assert model.components([0]) == [[0]] and model.components([]) == []


def test_regions_are_joined_by_edges_of_one_operand_only():
    # the four pieces of two crossing sheets meet only at the intersection edge (four uses,
    # both operands): four regions
    assert crossing_sheets().regions() == [[0], [1], [2], [3]]
    # a closed block: one region, its twelve edges used twice by its own faces
    solid = block((1.0, 2.0, 3.0))
    faces = [TrimmedFace(s, reversed=name not in OUTWARD) for name, s in solid.exterior_faces().items()]
    assert NonManifoldModel.build(faces, tol=1e-9).regions() == [[0, 1, 2, 3, 4, 5]]
    # the same block's faces split between two operands: the edges between them join nothing
    model = NonManifoldModel.build(faces, [("a", 0)] * 3 + [("b", 0)] * 3, tol=1e-9)
    assert sorted(map(len, model.regions())) == [3, 3]
