"""surfprep.heal on holes that are not four-sided (issue 21 item 3) and on loops of free
edges that are not holes (item 4): a fan of faces around an n-gon hole in a smooth
graph, filled G0/G1; the fan's outer edge left open; fill rules.

The fill is measured against the graph the fan was cut from (closest points from a
dense sample of the hole's inscribed disc), the normal angle against the input
faces along the rim and between the sub-patches along their spokes, on the surfaces.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from helpers.heal_cases import fan_around_hole, gentle_height, inside_regular_polygon

from surfprep.algorithms.projection import project_to_surface
from surfprep.errors import InvalidGeometryError
from surfprep.plugin.heal import heal
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import compound

T = np.linspace(0.02, 0.98, 41)


def _angle(n1, n2):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1),
                                 np.abs(np.einsum("kc,kc->k", n1, n2))))


def _side_angle(patch, uv, others):
    """Largest normal angle along a side of ``patch`` against the nearest of ``others``,
    and that one's distance."""
    pts = patch.evaluate(uv[:, 0], uv[:, 1])
    best = None
    for other in others:
        foot = project_to_surface(other, pts)
        if best is None or foot.distance.max() < best[1].max():
            best = (_angle(patch.normals(uv[:, 0], uv[:, 1]),
                           other.normals(foot.uv[:, 0], foot.uv[:, 1])), foot.distance)
    return float(best[0].max()), float(best[1].max())


def _measure(result, n, fan):
    holes = [s for p, s in zip(result.patches, result.network.patches) if p.origin.kind == "hole"]
    truth_xy = inside_regular_polygon(n)
    truth = np.column_stack([truth_xy, gentle_height(truth_xy[:, 0], truth_xy[:, 1])])
    deviation = np.min([project_to_surface(h, truth).distance for h in holes], axis=0).max()
    rim, gap, spoke = 0.0, 0.0, 0.0
    for h in holes:
        for uv in (np.column_stack([T, 0 * T]), np.column_stack([0 * T, T])):    # rim sides
            a, d = _side_angle(h, uv, fan)
            rim, gap = max(rim, a), max(gap, d)
        for uv in (np.column_stack([1 + 0 * T, T]), np.column_stack([T, 1 + 0 * T])):
            spoke = max(spoke, _side_angle(h, uv, [o for o in holes if o is not h])[0])
    return len(holes), deviation, rim, gap, spoke


@pytest.mark.parametrize("n", [3, 5, 6])
def test_an_n_sided_hole_is_filled_g1_by_n_patches(n):
    fan = fan_around_hole(n)
    result = heal(compound([make_face(s) for s in fan]), continuity="G1")
    count, deviation, rim, gap, spoke = _measure(result, n, fan)
    assert count == n
    # the hole's n edges are closed in the geometry; the fan's outer n stay free
    assert result.free_edges_before == 2 * n
    assert result.free_edges_after == n and result.tight_free_edges_after == n
    assert result.valid_after
    assert deviation < 1e-5                      # MakeFilling G1 on the same hole: 3e-6..8e-6
    assert gap < 1e-9                            # the rim sides are the faces' edges
    assert rim < 0.02                            # degrees; MakeFilling G1: 0.007-0.014
    assert spoke < 0.05                          # sub-patches joined G1 along the spokes
    # the neighbours keep their exact geometry (nothing replaced but the hole)
    assert all(p.origin.kind == "hole" for p in result.patches)
    loops = {lp["kind"]: lp for lp in result.report()["free_loops"]}
    assert loops["hole"]["fill"] and loops["hole"]["sub_patches"] == n
    assert loops["hole"]["slope_deg"] < 10
    assert not loops["open boundary"]["fill"]
    assert "faces lie over its inside" in loops["open boundary"]["why"]


def test_fill_none_leaves_every_loop_open_and_says_so():
    fan = fan_around_hole(5)
    result = heal(compound([make_face(s) for s in fan]), fill="none")
    assert result.patches == () and result.free_edges_after == 10
    assert all(not lp["fill"] and "fill='none'" in lp["why"]
               for lp in result.report()["free_loops"])
    # what is left is said: the hole's five edges are interior, the fan's outer five its
    # open boundary
    after = result.report()["free_boundary"]["after"]
    assert after["edges"] == {"gap": 0, "open boundary": 5, "hole": 5}
    assert after["interior"] == 5 and after["loops"] == {"hole": 1, "open boundary": 1}


def test_fill_all_still_never_covers_a_sheet_twice():
    fan = fan_around_hole(5)
    result = heal(compound([make_face(s) for s in fan]), fill="all")
    loops = {lp["kind"]: lp for lp in result.report()["free_loops"]}
    assert loops["hole"]["fill"] and not loops["open boundary"]["fill"]
    assert result.free_edges_after == 5


def test_an_unknown_fill_rule_is_refused():
    with pytest.raises(InvalidGeometryError, match="fill must be one of"):
        heal(compound([make_face(s) for s in fan_around_hole(3)]), fill="some")


def test_a_sliver_between_faces_is_a_gap_not_a_hole():
    from surfprep.algorithms.fitting import interpolate_curve
    from surfprep.algorithms.healing.adjacency import FaceEdge
    from surfprep.plugin.heal.loops import plan_loops

    x = np.linspace(0.0, 10.0, 21)
    lower = interpolate_curve(np.column_stack([x, 0 * x, 0 * x]))
    upper = interpolate_curve(np.column_stack([x[::-1], 0.02 * np.sin(np.pi * x[::-1] / 10),
                                               0 * x]))
    edges = [FaceEdge(k, 0, c, c.evaluate(np.linspace(0, 1, 33))) for k, c in
             enumerate((lower, upper))]
    (loop,) = plan_loops([edges], [None, None])
    assert loop.kind == "gap" and not loop.fill and "0.02 wide along 20" in loop.why
    assert "left open" in loop.why
    # within gap_tol it is no gap left open: sewing joins it (one edge against several)
    (sewn,) = plan_loops([edges], [None, None], gap_tol=0.05)
    assert sewn.kind == "gap" and not sewn.fill and "sewn" in sewn.why
    assert "left open" not in sewn.why


def test_the_command_counts_holes_not_sub_patches(tmp_path, capsys):
    from helpers.cli import run

    from surfprep.plugin.io import write
    source = tmp_path / "fan.step"
    write(compound([make_face(s) for s in fan_around_hole(5)]), source)
    code, out, err = run(capsys, "heal", source, "-o", tmp_path / "healed.step")
    assert code == 0, err
    assert "5 approximant(s) (1 hole(s) filled, 0 ring(s) bridged)" in out
    assert "2 loop(s) of free edges: 1 hole, 1 open boundary; fill tried on 1" in out
    code, out, err = run(capsys, "heal", source, "-o", tmp_path / "open.step", "--fill", "none")
    assert code == 0, err
    assert "0 approximant(s)" in out and "fill tried on 0" in out


def _circle_edges(radius, z, pieces, face0):
    """``pieces`` FaceEdges around the circle of ``radius`` at height ``z``, the k-th of
    face ``face0 + k``."""
    from surfprep.algorithms.fitting import interpolate_curve
    from surfprep.algorithms.healing.adjacency import FaceEdge

    out = []
    for k in range(pieces):
        t = np.linspace(2 * np.pi * k / pieces, 2 * np.pi * (k + 1) / pieces, 33)
        c = interpolate_curve(np.column_stack([radius * np.cos(t), radius * np.sin(t),
                                               z + 0 * t]))
        out.append(FaceEdge(face0 + k, 0, c, c.evaluate(np.linspace(*c.domain, 33))))
    return out


def test_a_pipe_mouth_beside_the_hole_it_should_meet_is_a_gap_not_a_boundary():
    # the spaceship's nozzles: a pipe's rim (two half circles, faces 0 and 1) 0.05 off
    # the rim of the body's hole (one circle, face 2), each a loop of its own: the pipe's
    # loop is no sliver by itself, and without the other free edges it is capped and
    # classed by its surroundings; with them it is a gap between the two loops, and not
    # filled even with fill="all"
    from surfprep.plugin.heal.loops import plan_loops

    mouth = _circle_edges(1.0, 0.0, 2, 0)
    hole = _circle_edges(1.05, 0.0, 1, 2)
    (alone,) = plan_loops([mouth], [None, None, None], fill="all", gap_tol=0.01)
    assert alone.kind != "gap"
    (loop,) = plan_loops([mouth], [None, None, None], fill="all", gap_tol=0.01,
                         free=mouth + hole)
    assert loop.kind == "gap" and not loop.fill and not loop.boundaries
    wide = float(re.search(r"up to ([0-9.e-]+) wide", loop.why).group(1))
    assert wide == pytest.approx(0.05, rel=0.01) and "left open" in loop.why
    # within gap_tol it is said to be sewn
    (sewn,) = plan_loops([mouth], [None, None, None], gap_tol=0.1, free=mouth + hole)
    assert sewn.kind == "gap" and "sewn" in sewn.why
    # a mouth with nothing beside it stays what its surroundings make it
    far = _circle_edges(1.5, 0.0, 1, 2)
    (open_,) = plan_loops([mouth], [None, None, None], gap_tol=0.01, free=mouth + far)
    assert open_.kind == alone.kind
