"""surfprep.prepare and ``surfprep prepare``: the stages run on one another's output,
skip with a reason where they do not apply, fail without stopping the chain, and the
prepared faces stay on the input's geometry (measured densely, not taken from the
stages' own figures)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run
from helpers.paths import SAMPLES

import surfprep
from surfprep.algorithms.projection import project_to_surface
from surfprep.plugin.prepare import STAGES, prepare

FUSELAGE = SAMPLES / "occt_fuselage.stp"
CAPSULE = SAMPLES / "overture_marscapsule_proe.igs"
SINGLE_FACE = SAMPLES / "occt_catia4_face_L1.igs"


@pytest.fixture(scope="module")
def fuselage():
    return prepare(FUSELAGE, grid=True, grid_options={"dims": (9, 11)})


def test_every_stage_runs_on_the_fuselage(fuselage):
    assert [s.name for s in fuselage.stages] == list(STAGES)
    assert [s.status for s in fuselage.stages] == ["done"] * 4
    heal, intersect, reparam, grid = fuselage.stages
    assert heal.summary["patches"] == 0 and heal.summary["note"] == "nothing to heal"
    assert reparam.summary["faces"] == "8 of 8"
    assert intersect.summary["curves"] == 0            # adjacent faces only share edges
    assert grid.summary["blocks"] == 8 and grid.summary["folded_cells"] == 0
    assert fuselage.model.n_faces == 8
    assert fuselage.face_status == ("reparametrized",) * 8
    assert [b.shape for b in fuselage.grid.blocks] == [(9, 11, 3)] * 8


def test_the_prepared_faces_lie_on_the_input(fuselage):
    """Every prepared face, sampled 30 x 30 over its surface, lies within the reparam
    stage's tolerance of the input (closest points on every input surface: the healing
    stage may give the faces another order)."""
    tol = fuselage.stage("reparam").report["tol"]
    inputs = [surfprep.to_nurbs(f).surface for f in fuselage.source.faces]
    for after in fuselage.model.faces:
        new = surfprep.to_nurbs(after).surface
        u0, u1, v0, v1 = new.domain
        pts = new.evaluate_grid(np.linspace(u0, u1, 30), np.linspace(v0, v1, 30)).reshape(-1, 3)
        distance = np.min([project_to_surface(old, pts).distance for old in inputs], axis=0)
        assert np.max(distance) <= tol * (1 + 1e-6)
        assert np.max(distance) > 0.0                  # the faces did change


def test_the_report_is_plain_json_with_every_stage(fuselage):
    report = json.loads(json.dumps(fuselage.report(), allow_nan=False))
    assert [s["stage"] for s in report["stages"]] == list(STAGES)
    assert report["faces_in"] == report["faces_out"] == 8
    assert report["face_status_counts"] == {"untouched": 0, "healed": 0, "reparametrized": 8}
    reparam = report["stages"][2]
    assert len(reparam["report"]["faces"]) == 8
    assert all(f["status"] == "ok" for f in reparam["report"]["faces"])


def test_stages_that_do_not_apply_say_why():
    result = prepare(SINGLE_FACE, heal=None)
    status = {s.name: (s.status, s.reason) for s in result.stages}
    assert status["heal"] == ("skipped", "not asked for (heal off)")
    assert status["intersect"][0] == "skipped" and "one face" in status["intersect"][1]
    assert status["grid"] == ("skipped", "not asked for")
    assert status["reparam"][0] == "done"


def test_a_model_without_bspline_faces_is_not_reparametrized():
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    box = BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape()
    result = prepare(box, heal=None, intersect=False)
    reparam = result.stage("reparam")
    assert reparam.status == "skipped" and "no B-spline face" in reparam.reason
    assert result.face_status == ("untouched",) * 6


def test_a_failing_stage_is_reported_and_the_chain_goes_on():
    """A grid of 1 x 1 nodes cannot be made: the grid stage fails with surfprep's reason,
    the stages before it stay done and the model is the reparametrized one."""
    result = prepare(FUSELAGE, heal=None, intersect=False, grid=True,
                     grid_options={"dims": (1, 1)})
    grid = result.stage("grid")
    assert grid.status == "failed" and grid.reason
    assert result.stage("reparam").status == "done"
    assert result.grid is None and result.face_status == ("reparametrized",) * 8


def test_bad_arguments_are_refused():
    with pytest.raises(surfprep.InvalidToleranceError):
        prepare(FUSELAGE, tol=-1.0)
    with pytest.raises(ValueError, match="heal must be"):
        prepare(FUSELAGE, heal="G2")


@pytest.mark.slow
def test_healed_faces_are_told_apart():
    """The Mars capsule: the faces the healing replaced or moved onto their neighbours'
    edges are 'healed' (its approximants are taken back: they opened gaps in the
    geometry; six faces are moved to close the gaps sewing covered by tolerance), the
    others are the input's own (reparametrized or untouched), and the copies of faces
    the file holds twice are gone."""
    result = prepare(CAPSULE, intersect=False)
    heal = result.stage("heal")
    assert heal.status == "done"
    changed = heal.summary["patches"] + heal.summary["faces_moved"]
    assert heal.summary["faces_moved"] == 6
    assert result.face_status.count("healed") == changed
    dropped = len(heal.report["dropped_overlaps"])        # its faces come twice in the file
    assert dropped > 0 and result.model.n_faces == result.source.n_faces - dropped


def test_the_command_writes_model_grid_and_report(capsys, tmp_path):
    out, grid, report = tmp_path / "ready.step", tmp_path / "ready.xyz", tmp_path / "r.json"
    page = tmp_path / "ready.html"
    code, stdout, err = run(capsys, "prepare", FUSELAGE, "-o", out, "--grid", grid,
                            "--dims", 5, 6, "--no-intersect", "--json", report, "--report", page)
    assert code == 0, err
    assert "reparam: done" in stdout and "intersect: skipped: not asked for" in stdout
    data = json.loads(report.read_text())
    assert data["outputs"] == {"grid": str(grid.resolve()), "model": str(out.resolve()),
                               "report": str(page.resolve())}
    assert "surfprep prepare: occt_fuselage.stp" in page.read_text()
    assert surfprep.read(out).n_faces == 8
    assert grid.stat().st_size > 0


@pytest.mark.parametrize("argv, words", [
    (("--dims", "5", "6"), "--dims and --size are for --grid"),
    (("--grid", "out.txt"), "extension"),
    (("--report", "out.txt"), "HTML report"),
])
def test_the_command_refuses_before_the_work(capsys, tmp_path, argv, words):
    code, _, err = run(capsys, "prepare", FUSELAGE, "-o", tmp_path / "x.step",
                       *[str(tmp_path / a) if a.endswith(".txt") else a for a in argv])
    assert code == 2
    assert err.strip().startswith("surfprep: error:") and words in err
    assert not (tmp_path / "x.step").exists()


def test_a_step_past_its_time_limit_is_stopped_and_reported(fuselage):
    """Every face given 10 ms: each reparametrization is stopped, the face kept as it
    was with the reason, and the chain finishes. (``fuselage`` first: an alarm that
    falls inside numba's loading of a cached kernel is swallowed by its ctypes callback,
    so the kernels are loaded before the timing starts.)"""
    result = prepare(FUSELAGE, heal=None, intersect=False, step_time_limit_s=0.01)
    reparam = result.stage("reparam")
    assert reparam.status == "done" and reparam.summary["faces"] == "0 of 8"
    assert all("longer than 0.01 s" in f["error"] for f in reparam.report["faces"])
    assert result.face_status == ("untouched",) * 8


@pytest.mark.slow
def test_healing_that_drops_faces_without_reparametrizing():
    """The capsule holds its faces twice; healed with the reparametrization off, the status
    is given for each face of the healed model (36 in, 18 out)."""
    result = prepare(CAPSULE, intersect=False, reparam=False)
    assert result.model.n_faces == 18 and len(result.face_status) == 18
    assert result.face_status.count("reparametrized") == 0
