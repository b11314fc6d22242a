"""Faces that are not four-sided as four-sided sub-patches (healing/decompose.py on a
TrimmedFace):
faces built in OpenCascade on a wavy B-spline surface and read back, their
sub-patches approximated over the face (its trimmed source) and joined."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import (
    disc,
    occ_triangle_face,
    pentagon,
    polygon_loop,
    six_edges_two_smooth,
    triangle,
    wavy_surface,
)

from surfprep.algorithms.healing import connect, local_approximant
from surfprep.algorithms.healing.adjacency import four_sided_boundary
from surfprep.algorithms.healing.clipping import face_source
from surfprep.algorithms.healing.decompose import (
    MAX_RING_BLOCKS,
    decompose_face,
    decompose_ring,
    quad_boundaries,
    reverse_curve,
    ring_edges,
    why_not_decomposable,
)
from surfprep.algorithms.healing.loop_sides import signed_area
from surfprep.algorithms.projection import distance_to_surface
from surfprep.algorithms.trimmed import TrimEdge, TrimLoop
from surfprep.plugin.occ.faces import face_to_nurbs, make_face

SURFACE = wavy_surface()
GAP = 1e-6


def occ_face(loops, reverse_edges=False):
    """TrimmedFace read back from an OpenCascade face with these loops (LoopEdges);
    with ``reverse_edges`` every edge is stored the other way and used reversed."""
    trim = []
    for loop in loops:
        edges = []
        for e in loop:
            if reverse_edges:
                edges.append(TrimEdge(reverse_curve(e.curve), reverse_curve(e.pcurve), 0.0, 1.0,
                                      reversed=True))
            else:
                edges.append(TrimEdge(e.curve, e.pcurve, 0.0, 1.0))
        trim.append(TrimLoop(edges))
    return face_to_nurbs(make_face(SURFACE, trim))


def _ends_meet(boundary):
    ends = np.array([[c.evaluate(c.domain[0]), c.evaluate(c.domain[1])] for c in boundary])
    forward = np.linalg.norm(ends[:, 1] - np.roll(ends[:, 0], -1, axis=0), axis=1).max()
    return forward < 1e-7


@pytest.mark.parametrize(("case", "n_quads", "reverse"),
                         [(triangle, 3, False), (triangle, 3, True), (pentagon, 5, False),
                          (six_edges_two_smooth, 1, False), (disc, 1, True)])
def test_quad_boundaries_of_occ_faces(case, n_quads, reverse):
    face = occ_face([case(SURFACE)], reverse_edges=reverse)
    quads = quad_boundaries(face, gap_tol=GAP)
    assert quads is not None and len(quads) == n_quads
    assert all(len(q) == 4 and _ends_meet(q) for q in quads)


def test_four_sided_face_is_its_own_boundary():
    face = occ_face([polygon_loop(SURFACE, [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)])])
    quads = quad_boundaries(face, gap_tol=GAP)
    assert len(quads) == 1 and quads[0] == four_sided_boundary(face)
    assert decompose_face(face, gap_tol=GAP) is None


def _octagon(radius=0.4):
    angles = np.radians(22.5 + 45.0 * np.arange(8))
    return [(0.5 + radius * np.cos(a), 0.5 + radius * np.sin(a)) for a in angles]


@pytest.mark.parametrize(("outline", "hole", "ring_area"), [
    ([(0.05, 0.05), (0.95, 0.05), (0.5, 0.95)],
     [(0.4, 0.3), (0.5, 0.5), (0.6, 0.3)], 0.405 - 0.02),
    (_octagon(), [(0.4, 0.4), (0.4, 0.6), (0.6, 0.6), (0.6, 0.4)], 2 * np.sqrt(2) * 0.16 - 0.04),
])
def test_face_with_a_hole_is_one_block_per_outer_corner(outline, hole, ring_area):
    """A triangle and an octagon (occt_k1_catia_theorem.stp faces 1 and 58 have eight
    corners), each with a hole: one block per corner, whose (u, v) outlines tile the
    ring exactly, approximated on the face and joined along the spokes. Healing takes
    at most four (more would meet the kept neighbours within tol, not exactly)."""
    face = occ_face([polygon_loop(SURFACE, outline), polygon_loop(SURFACE, hole)])
    d = decompose_ring(face.surface, *ring_edges(face, gap_tol=GAP))
    quads = [list(q) for q in d.quads]
    assert len(quads) == len(outline)
    assert all(len(q) == 4 and _ends_meet(q) for q in quads)
    healing = quad_boundaries(face, gap_tol=GAP)
    if len(outline) <= MAX_RING_BLOCKS:
        assert healing is not None and len(healing) == len(outline)
    else:
        assert healing is None
        assert "8 outer corners" in why_not_decomposable(face, gap_tol=GAP)
    areas = [signed_area(np.concatenate([pc.evaluate(np.linspace(*pc.domain, 4001))[:-1]
                                         for pc in quad])) for quad in d.quads_pcurves]
    assert min(areas) > 0 and sum(areas) == pytest.approx(ring_area, abs=1e-6)
    source = face_source(face)
    las = [local_approximant(q, [source], preferred_source=0) for q in quads]
    assert all(la.converged for la in las)
    net = connect(las, continuity="G0")
    assert len(net.joins) == len(outline) and max(j.max_gap for j in net.joins) <= 1e-9


def test_face_with_a_hole_off_its_centre_says_why_it_is_not_split():
    """A hole near one side of a triangle: a spoke from the far corner would cross it."""
    outer = polygon_loop(SURFACE, [(0.05, 0.05), (0.95, 0.05), (0.5, 0.95)])
    hole = polygon_loop(SURFACE, [(0.2, 0.1), (0.2, 0.2), (0.8, 0.2), (0.8, 0.1)])
    face = occ_face([outer, hole])
    assert quad_boundaries(face, gap_tol=GAP) is None
    assert why_not_decomposable(face, gap_tol=GAP)


def test_face_with_one_hole_is_four_blocks_round_it_covering_the_ring():
    """A square with a square hole (clockwise, as a face stores it): four quads whose
    (u, v) outlines tile the ring exactly (areas add up to 0.64 - 0.04), each a closed
    boundary, approximated on the face and joined along the four spokes."""
    outer = polygon_loop(SURFACE, [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)])
    hole = polygon_loop(SURFACE, [(0.4, 0.4), (0.4, 0.6), (0.6, 0.6), (0.6, 0.4)])
    face = occ_face([outer, hole])
    quads = quad_boundaries(face, gap_tol=GAP)
    assert quads is not None and len(quads) == 4
    assert all(len(q) == 4 and _ends_meet(q) for q in quads)
    d = decompose_ring(face.surface, *ring_edges(face, gap_tol=GAP))
    assert sum(signed_area(uv) for uv in d.quads_uv) == pytest.approx(0.64 - 0.04, abs=1e-6)
    source = face_source(face)
    las = [local_approximant(q, [source], preferred_source=0) for q in quads]
    assert all(la.converged for la in las)
    net = connect(las, continuity="G0")
    assert len(net.joins) == 4 and max(j.max_gap for j in net.joins) <= 1e-9


def test_triangle_sub_patches_follow_the_trimmed_face_and_join_g1():
    face = occ_face([triangle(SURFACE)])
    source = face_source(face)
    quads = quad_boundaries(face, gap_tol=GAP)
    las = [local_approximant(q, [source], preferred_source=0) for q in quads]
    assert all(la.converged for la in las)
    net = connect(las, continuity="G1")
    size = float(np.linalg.norm(np.ptp(SURFACE.bounding_box(), axis=0)))
    assert len(net.joins) == 3
    assert max(j.max_gap for j in net.joins) <= 1e-9 * size
    assert max(j.max_angle for j in net.joins) < 0.2
    t = np.linspace(0, 1, 41)
    for la, p in zip(las, net.patches):
        assert distance_to_surface(face.surface, p.evaluate_grid(t, t).reshape(-1, 3)).max() \
            <= la.tol



def test_heal_split_faces_replaces_a_triangle_by_three_patches():
    # surfprep.heal(split_faces=True): the three-sided face becomes three sub-patches
    # that follow it (dense check against the surface), keep its area and outline, and
    # are joined G0 into one valid face set (the default); with split_faces=False the
    # face is kept, and so it is with the default replace="defects" (it has no defect)
    from surfprep.algorithms.healing.adjacency import face_edges, polyline_distance
    from surfprep.plugin.heal import heal
    shape = occ_triangle_face()
    kept = heal(shape, split_faces=False, replace="all")
    assert kept.patches == () and kept.model.n_faces == 1
    assert heal(shape).patches == ()
    r = heal(shape, replace="all")
    assert [p.origin.kind for p in r.patches] == ["face"] * 3
    assert {p.origin.faces for p in r.patches} == {(0,)}
    assert r.valid_after and r.model.n_faces == 3
    # its three free edges are now six sides: kept with replace="all", and said so
    assert any("free edges 3 -> 6, kept" in s and "sub-patches" in s for s in r.skipped)
    for la in r.approximants:
        u0, u1, v0, v1 = la.surface.domain
        uu, vv = np.meshgrid(np.linspace(u0, u1, 25), np.linspace(v0, v1, 25), indexing="ij")
        pts = la.surface.evaluate(uu.ravel(), vv.ravel())
        assert distance_to_surface(SURFACE, pts).max() <= la.tol
    assert all(j.max_gap < 1e-9 for j in r.joins) and len(r.joins) == 3
    before = face_edges([face_to_nurbs(shape)])
    after = face_edges([face_to_nurbs(f) for f in r.model.faces])
    outline = np.concatenate([e.samples for e in before])
    on_outline = np.concatenate([e.samples for e in after])
    near = [polyline_distance(e.samples, outline).max() for e in after]
    tol = max(la.tol for la in r.approximants)
    assert sum(d <= tol for d in near) == 6               # two outer sides per sub-patch
    assert polyline_distance(outline, on_outline).max() <= tol   # the whole outline kept
