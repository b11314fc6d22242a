"""surfprep.heal end to end on synthetic faults: a 1e-3 gap with mismatched edges, a
3x3 grid with the middle face missing, an exact duplicate face, a directed patch.

Closure is checked in the geometry (measured joins, free edges after sewing at
1e-7 x size), validity by BRepCheck, deviation from the true graph densely.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import surfprep
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.surface import NurbsSurface
from surfprep.errors import InvalidGeometryError
from surfprep.plugin.convert import to_nurbs
from surfprep.plugin.heal import heal
from surfprep.plugin.io import CadModel
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import compound


def graph(x, y):
    return 0.3 * np.sin(1.3 * x) * np.cos(0.9 * y) + 0.1 * x * y


def graph_patch(x0, x1, y0, y1, nu=6, nv=6, dz=0.0, flip_u=False, swap=False):
    x, y = np.linspace(x0, x1, nu), np.linspace(y0, y1, nv)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    net = np.stack([gx, gy, graph(gx, gy) + dz], axis=-1)
    if flip_u:
        net = net[::-1]
    if swap:
        net = np.swapaxes(net, 0, 1)
    return interpolate_surface(net)


def deviation_from_graph(result) -> float:
    worst = 0.0
    for face in to_nurbs(result.model.shape) if result.model.n_faces > 1 else [
            to_nurbs(result.model.faces[0])]:
        s = face.surface
        u0, u1, v0, v1 = s.domain
        pts = s.evaluate_grid(np.linspace(u0, u1, 41), np.linspace(v0, v1, 41))
        worst = max(worst, float(np.abs(pts[..., 2] - graph(pts[..., 0], pts[..., 1])).max()))
    return worst


@pytest.fixture(scope="module")
def gap_pair():
    a = graph_patch(0, 1, 0, 1, 6, 6)
    b = graph_patch(1, 2, 0, 1, 9, 7, dz=1e-3, flip_u=True, swap=True)
    return compound([make_face(a), make_face(b)])


@pytest.mark.parametrize("continuity", ["G0", "G1"])
def test_gap_closed_in_geometry(gap_pair, continuity):
    r = heal(gap_pair, continuity=continuity)
    (join,) = r.joins
    (before,) = r.network.joins_before
    assert before.max_gap > 9e-4 and join.max_gap < 1e-12
    assert r.tight_free_edges_before == 8            # the gap is open at 1e-7 x size
    assert r.tight_free_edges_after == 6             # only the outer border is free
    assert r.free_edges_after == 6
    assert r.valid_after and r.model.shape.ShapeType().name == "TopAbs_SHELL"
    assert r.max_edge_tolerance < 1e-6               # closed by geometry, not tolerance
    assert all(p.converged for p in r.patches)
    assert deviation_from_graph(r) < 1.5e-3
    if continuity == "G1":
        assert join.max_angle < 1e-2
    rep = json.loads(json.dumps(r.report()))
    assert rep["free_edges"]["tight_after"] == 6 and len(rep["patches"]) == 2
    # the two facing sides were a gap's, 1e-3 wide; the six left are the outer border
    before, after = rep["free_boundary"]["before"], rep["free_boundary"]["after"]
    assert before["edges"] == {"gap": 2, "open boundary": 6, "hole": 0}
    assert before["widest_gap"] == pytest.approx(1e-3, rel=0.02)
    assert after == {"edges": {"gap": 0, "open boundary": 6, "hole": 0}, "interior": 0,
                     "loops": {"open boundary": 1}, "widest_gap": None,
                     "interior_loops": []}
    (gap,) = before["interior_loops"]
    assert gap["faces"] == [0, 1] and gap["edges"] == 2
    assert 2.0 < gap["length"] < 2.01      # two sides 1 long in plan, on the curved graph


def test_a_gap_wider_than_gap_tol_is_reported_as_interior_free_edges(gap_pair):
    # gap_tol 1e-4 below the 1e-3 gap: its sides stay free, and are said to be a gap's
    r = heal(gap_pair, gap_tol=1e-4)
    assert r.tight_free_edges_after == 8
    after = r.report()["free_boundary"]["after"]
    assert after["edges"] == {"gap": 2, "open boundary": 6, "hole": 0}
    assert after["interior"] == 2
    assert 1e-3 <= after["widest_gap"] <= 1.05e-3


@pytest.fixture(scope="module")
def grid_with_hole():
    faces = []
    for i in range(3):
        for j in range(3):
            if (i, j) != (1, 1):
                faces.append(make_face(graph_patch(i / 3, (i + 1) / 3, j / 3, (j + 1) / 3,
                                                   5 + i, 5 + j)))
    return compound(faces)


@pytest.mark.slow
def test_hole_in_grid_filled_g1(grid_with_hole):
    r = heal(grid_with_hole, continuity="G1")
    holes = [p for p in r.patches if p.origin.kind == "hole"]
    assert len(holes) == 1 and len(holes[0].origin.faces) == 4
    assert r.model.n_faces == 9
    assert r.tight_free_edges_before == 16 and r.tight_free_edges_after == 12   # border + hole
    assert r.valid_after
    assert max(j.max_gap for j in r.joins) < 1e-12
    assert max(j.max_angle for j in r.joins) < 0.1
    # the filled hole follows the graph (Hardy over the hole, paper's Fig. 6 kind)
    assert deviation_from_graph(r) < 5e-3
    # with G1 the faces at the hole's corners are rebuilt too (they share its tangent
    # planes there): all eight; with G0 only the four along its edges
    assert len([p for p in r.patches if p.origin.kind == "face"]) == 8
    g0 = heal(grid_with_hole, continuity="G0")
    assert sorted(p.origin.index for p in g0.patches if p.origin.kind == "face") == [1, 3, 4, 6]
    assert g0.tight_free_edges_after == 12 and g0.valid_after


def test_duplicate_face_dropped(gap_pair):
    a = graph_patch(0, 1, 0, 1, 6, 6)
    b = graph_patch(1, 2, 0, 1, 6, 6)
    shape = compound([make_face(a), make_face(b), make_face(a)])
    model = CadModel.from_shape(shape)
    model = CadModel(model.shape, model.faces, ("left", "right", "left copy"),
                     model.face_colors)
    r = heal(model)
    assert r.dropped == ((0, 2),)
    assert r.model.n_faces == 2
    assert sorted(n for n in r.model.face_names) == ["left", "right"]
    assert r.tight_free_edges_after == 6 and r.valid_after
    # the copy closed the left face's other three edges in the input (4 free edges):
    # more after, said so, and the drop stays (it is no gap opened)
    (note,) = [s for s in r.skipped if "free edges 4 -> 6" in s]
    assert "3 are edges of a face that only its duplicate (dropped) closed" in note


def test_directed_patch_and_names(tmp_path):
    a = graph_patch(0, 1, 0, 1, 6, 6)
    spec = {"patches": [{"name": "cap", "corners": [[0, 0, 0.0], [1, 0, 0.0],
                                                     [1, 1, 0.0], [0, 1, 0.0]]}]}
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(spec))
    r = heal(make_face(a), patches=path)
    kinds = [p.origin.kind for p in r.patches]
    assert kinds == ["face", "directed"]
    assert "cap" in r.model.face_names
    with pytest.raises(InvalidGeometryError, match="4 finite"):
        heal(make_face(a), patches={"patches": [{"corners": [[0, 0, 0]] * 3}]})


def test_public_entry_points():
    """The building blocks live in their module; nothing is set on the verb at import."""
    from surfprep.algorithms import healing
    assert callable(healing.local_approximant) and callable(healing.connect)
    assert callable(surfprep.heal)
    assert not hasattr(surfprep.heal, "local_approximant")


def _area(shape) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    return props.Mass()


def _graph_area(x0, x1) -> float:
    x, y = np.linspace(x0, x1, 801), np.linspace(0, 1, 801)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    h = 1e-6
    zx = (graph(gx + h, gy) - graph(gx - h, gy)) / (2 * h)
    zy = (graph(gx, gy + h) - graph(gx, gy - h)) / (2 * h)
    f = np.sqrt(1 + zx ** 2 + zy ** 2)
    return float(np.trapezoid(np.trapezoid(f, y, axis=1), x))


@pytest.mark.parametrize("overlap", ["trim", "union"])
def test_overlapping_faces_trimmed_back(overlap):
    continuity = "G1"
    a = graph_patch(0, 1, 0, 1, 6, 6)
    b = graph_patch(0.7, 1.7, 0, 1, 7, 6)          # overlaps a over 0.7 <= x <= 1
    shape = compound([make_face(a), make_face(b)])
    assert _area(shape) > _graph_area(0, 1.7) + 0.25      # the strip counted twice
    r = heal(shape, continuity=continuity, overlap=overlap)
    rep = r.report()
    action = "union" if overlap == "union" else "trimmed back"
    assert rep["trimmed_overlaps"] == [{"kept": 0, "trimmed": 1, "replaced": True,
                                        "action": action}]
    assert abs(_area(r.model.shape) - _graph_area(0, 1.7)) < 2e-3     # no doubled area
    assert r.valid_after
    assert deviation_from_graph(r) < 1.5e-3
    if overlap == "union":            # one approximant over the union's outline
        assert [p.origin.kind for p in r.patches] == ["union"]
        assert r.model.n_faces == 1 and r.tight_free_edges_after == 4
        return
    assert len(r.joins) == 1 and r.joins[0].max_gap < 1e-12
    assert r.tight_free_edges_after == 6
    if continuity == "G1":
        assert r.joins[0].max_angle < 1e-2


def _quad(p00, p10, p01, p11):
    c = np.array([[p00, p01], [p10, p11]], float)
    return NurbsSurface(c, np.array([0, 0, 1, 1.0]), np.array([0, 0, 1, 1.0]), 1, 1)


@pytest.mark.slow
def test_mouth_of_a_shallow_pocket_is_not_a_hole():
    # floor and four walls 0.1 high: the walls' top edges chain into a loop of four free
    # edges, but the walls turn away from it by 90 degrees: an open boundary (issue 21
    # item 4), left open; the walls and floor stay closed to each other. With
    # fill="all" a patch is tried and lands on the floor (segments of length 2 d = 1 >
    # 0.1) off tol: no hole, left open all the same.
    z0, z1 = 0.0, 0.1
    c = [(0, 0), (1, 0), (1, 1), (0, 1)]
    walls = [_quad((*c[k], z0), (*c[(k + 1) % 4], z0), (*c[k], z1), (*c[(k + 1) % 4], z1))
             for k in range(4)]
    floor = _quad((0, 0, z0), (1, 0, z0), (0, 1, z0), (1, 1, z0))
    r = heal(compound([make_face(s) for s in walls + [floor]]))
    assert not any(p.origin.kind == "hole" for p in r.patches)
    (loop,) = r.report()["free_loops"]
    assert loop["kind"] == "open boundary" and loop["slope_deg"] > 80 and not loop["fill"]
    assert r.free_edges_after == 4 and r.valid_after
    forced = heal(compound([make_face(s) for s in walls + [floor]]), fill="all")
    assert not any(p.origin.kind == "hole" for p in forced.patches)
    assert any("not a hole" in s for s in forced.skipped)


def test_only_faces_with_a_defect_are_replaced_by_default():
    """A gap of 1e-3 between A and B, and C sharing A's other edge exactly: by default
    A and B are re-approximated and the gap closes, C keeps its exact geometry (an
    approximant in its place could only open the closed edge); replace="all" takes C
    too."""
    c = graph_patch(-1.0, 0.0, 0.0, 1.0)
    faces = [make_face(graph_patch(0.0, 1.0, 0.0, 1.0)), make_face(graph_patch(1.001, 2.0, 0.0, 1.0)),
             make_face(c)]
    r = heal(faces, gap_tol=0.01)
    assert sorted(p.origin.faces for p in r.patches) == [(0,), (1,)]
    assert r.report()["replace"] == "defects"
    assert any("1 faces without a gap" in s for s in r.skipped)
    surfaces = [to_nurbs(f).surface for f in r.model.faces]
    kept = [s for s in surfaces if s.n_control == c.n_control
            and np.allclose(s.control_points, c.control_points)]
    assert len(kept) == 1 and np.array_equal(kept[0].control_points, c.control_points)
    assert r.tight_free_edges_after < r.tight_free_edges_before
    assert r.valid_after
    every = heal(faces, gap_tol=0.01, replace="all")
    assert sorted(p.origin.faces for p in every.patches) == [(0,), (1,), (2,)]
    with pytest.raises(InvalidGeometryError, match="replace"):
        heal(faces, replace="some")


def test_taking_back_a_sub_patch_takes_back_its_whole_face():
    from surfprep.plugin.heal.jobs import Job, PatchOrigin
    from surfprep.plugin.heal.rollback import without_jobs

    def job(kind, index):
        return (Job(PatchOrigin(kind, (index,), index), None, None, None), None)
    done = [job("face", 3), job("face", 3), job("hole", 0), job("face", 5), job("directed", 1)]
    kept = without_jobs(done, {1, 2})
    assert [(j.origin.kind, j.origin.index) for j, _ in kept] == [("face", 5), ("directed", 1)]


def test_a_slot_through_a_plate_is_no_hole():
    """The walls of a slot meet the plate's faces along their inner loops: paired, no
    defect, nothing replaced. With the outer loops alone the walls' edges looked free,
    the slot's two mouths were "holes" given patches, and those put a third face on each
    mouth edge: 0 -> 12 free edges (occt_cornetta.stp 0 -> 18, occt_k1_alias.stp 0 -> 8)."""
    from helpers.heal_cases import slotted_plate

    r = heal(slotted_plate())
    assert r.patches == ()
    assert r.free_edges_before == r.free_edges_after == 0
    assert r.tight_free_edges_after == 0 and r.valid_after


def test_a_wall_two_solids_share_is_not_dropped():
    """Two boxes side by side, as two solids: their common wall is there twice and one of
    the two was dropped as a duplicate, leaving three faces on each of its four edges:
    0 -> 4 free edges (occt_s1_ideas.stp 0 -> 9). The drop is taken back, and said so."""
    from helpers.heal_cases import boxes_sharing_a_wall

    r = heal(boxes_sharing_a_wall())
    assert r.free_edges_after <= r.free_edges_before == 0
    assert r.dropped == () and r.report()["faces_out"] == 12
    (note,) = [s for s in r.skipped if "taken back" in s]
    assert "free edges 0 -> 4" in note and "face 6 (duplicate of face 1)" in note


def test_free_edges_the_pairing_misses_are_taken_back(monkeypatch):
    """The rollback compares the result with the input's free edges as OpenCascade's
    sewing finds them, not with our pairing: with the pairing blind to inner loops (as it
    was), the slot's mouths are patched and their walls replaced (0 -> 12 or more free edges),
    and all of those approximants are taken back."""
    from helpers.heal_cases import slotted_plate

    import surfprep.plugin.heal as heal_module
    from surfprep.algorithms.healing.adjacency import face_edges

    monkeypatch.setattr(heal_module, "face_edges",
                        lambda faces: [e for e in face_edges(faces) if e.k >= 0])
    # the mouths' walls turn away from them: open boundaries, filled only with fill="all"
    r = heal(slotted_plate(), fill="all")
    assert r.free_edges_after <= r.free_edges_before == 0
    assert r.patches == () and r.valid_after
    (note,) = [s for s in r.skipped if "taken back" in s]
    assert re.search(r"free edges 0 -> (\d+)", note) and int(re.search(
        r"free edges 0 -> (\d+)", note)[1]) >= 8            # the mouths' 8 edges at least
    assert all(f"face {i}" in note for i in (6, 7, 8, 9)) and "hole 0" in note



def test_a_slots_mouth_is_an_open_boundary_by_geometry(monkeypatch):
    """Issue 21 item 4: with the pairing blind to inner loops (as above) the slot's
    mouths are loops of free edges; their walls turn away from them by 90 degrees, so
    they are open boundaries and nothing is built over them (before, an approximant
    was built and taken back only because it left more free edges)."""
    from helpers.heal_cases import slotted_plate

    import surfprep.plugin.heal as heal_module
    from surfprep.algorithms.healing.adjacency import face_edges

    monkeypatch.setattr(heal_module, "face_edges",
                        lambda faces: [e for e in face_edges(faces) if e.k >= 0])
    r = heal(slotted_plate())
    loops = r.report()["free_loops"]
    assert loops and all(lp["kind"] == "open boundary" and not lp["fill"] for lp in loops)
    assert all(lp["slope_deg"] > 80 for lp in loops)
    assert r.patches == () and r.free_edges_after == r.free_edges_before == 0
