"""surfprep.heal on rings (issue 21 item 2, gaps wider than gap_tol): a tube whose wall
has two skins and whose end faces are missing, as the spaceship's nozzles. Each end is
two loops of free edges 0.05 apart all round; heal bridges them by strips, and the
strips are measured on the surfaces: in the end planes, between the two radii."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import cylinder_z

from surfprep.algorithms.surface import NurbsSurface
from surfprep.plugin.heal import heal
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import compound

OUTER, INNER, HALF = 1.0, 0.95, 0.5


def _turned(surface: NurbsSurface) -> NurbsSurface:
    """The half cylinder turned by 180 degrees about z."""
    cp = surface.control_points.copy()
    cp[..., :2] *= -1
    return NurbsSurface(cp, surface.knots_u, surface.knots_v, surface.degree_u,
                        surface.degree_v, surface.weights)


def _tube():
    skins = [cylinder_z(r, HALF) for r in (OUTER, INNER)]
    return compound([make_face(s) for skin in skins for s in (skin, _turned(skin))])


@pytest.fixture(scope="module")
def bridged():
    return heal(_tube(), gap_tol=0.01)


def test_the_ends_of_a_two_skinned_tube_are_bridged_by_strips(bridged):
    report = bridged.report()
    rings = report["rings"]
    assert len(rings) == 2 and all(r["bridged"] and r["strips"] == 2 for r in rings)
    assert all(r["width"] == pytest.approx(OUTER - INNER, abs=1e-3) for r in rings)
    assert sorted(sorted(r["edges"]) for r in rings) == [[2, 2], [2, 2]]
    # the four ends' free edges closed: the shell is closed, in the geometry too
    assert report["free_edges"]["tight_before"] == 8
    assert report["free_edges"]["after"] == 0 and report["free_edges"]["tight_after"] == 0
    assert report["valid"]["after"]
    loops = report["free_loops"]
    assert len(loops) == 4 and all("one side of ring" in lp["why"] for lp in loops)


def test_strips_lie_in_the_end_planes_between_the_skins(bridged):
    strips = [(p, s) for p, s in zip(bridged.patches, bridged.network.patches)
              if p.origin.kind == "ring"]
    assert len(strips) == 4
    t = np.linspace(0.0, 1.0, 41)
    u, v = np.meshgrid(t, t, indexing="ij")
    ends = []
    for patch, surface in strips:
        pts = surface.evaluate(u.ravel(), v.ravel())
        z = float(np.median(pts[:, 2]))
        ends.append(np.sign(z))
        assert np.abs(pts[:, 2] - np.sign(z) * HALF).max() < patch.tol
        r = np.hypot(pts[:, 0], pts[:, 1])
        assert r.min() > INNER - patch.tol and r.max() < OUTER + patch.tol
        assert patch.name.startswith("heal_ring_")
    assert sorted(ends) == [-1, -1, 1, 1]


def test_fill_none_leaves_rings_open():
    report = heal(_tube(), gap_tol=0.01, fill="none").report()
    assert [r["fill"] for r in report["rings"]] == [False, False]
    assert all(not r["bridged"] and "fill='none'" in r["why"] for r in report["rings"])
    assert report["free_edges"]["tight_after"] == 8


def test_loops_within_gap_tol_are_sewn_not_bridged():
    # at gap_tol 0.06 the skins' rims are sewn to each other (a wall of no thickness at
    # its ends), so no ring is planned
    report = heal(_tube(), gap_tol=0.06).report()
    assert report["rings"] == []


def test_the_command_says_how_many_rings_it_bridged(tmp_path, capsys):
    from surfprep.plugin import cli
    from surfprep.plugin.io import write

    src = write(_tube(), tmp_path / "tube.step")
    assert cli.main(["heal", str(src), "-o", str(tmp_path / "out.step"), "--gap-tol", "0.01"]) == 0
    out = capsys.readouterr().out
    assert "4 approximant(s) (0 hole(s) filled, 2 ring(s) bridged)" in out
    assert "2 ring(s) of two loops beside each other: 2 bridged by strips" in out
    assert "free edges 8 -> 0 (at gap_tol 0.01 mm), 8 -> 0 (geometric)" in out
