"""``surfprep intersect``: files in, edges out, JSON report, plot, OpenCascade beside ours."""

from __future__ import annotations

import json
from pathlib import Path

import cadquery as cq
import numpy as np
import pytest
from helpers.cli import run
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer

import surfprep


def count(shape, kind) -> int:
    n, ex = 0, TopExp_Explorer(shape, kind)
    while ex.More():
        n += 1
        ex.Next()
    return n


def read_step_shape(path: Path):
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    return reader.OneShape()


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A unit sphere and a slab 0.3 <= z <= 0.5 (two circles), and a box alone."""
    d = tmp_path_factory.mktemp("cli_intersect")
    sphere = cq.Solid.makeSphere(1.0, angleDegrees1=-90, angleDegrees2=90)
    slab = cq.Solid.makeBox(3, 3, 0.2, pnt=cq.Vector(-1.5, -1.5, 0.3))
    paths = {"sphere": d / "sphere.step", "slab": d / "slab.step", "box": d / "box.step"}
    surfprep.write(sphere, paths["sphere"])
    surfprep.write(slab, paths["slab"])
    surfprep.write(cq.Solid.makeBox(1, 1, 1), paths["box"])
    return paths


def test_two_files_json_plot_and_occ(files, tmp_path, capsys):
    out, report, plot = tmp_path / "cut.step", tmp_path / "r.json", tmp_path / "p.png"
    code, stdout, err = run(capsys, "intersect", files["sphere"], files["slab"], "-o", out,
                            "--json", report, "--plot", plot, "--compare-occ", "--tol", "1e-7")
    assert code == 0, err
    assert "2 intersection curve(s)" in stdout and "OpenCascade: 2 branch(es)" in stdout
    r = json.loads(report.read_text())
    assert r["n_curves"] == 2 and r["tol"] == 1e-7 and r["time_s"] > 0
    radii = sorted(np.sqrt(1 - z * z) for z in (0.3, 0.5))
    lengths = sorted(c["length"] for c in r["curves"])
    np.testing.assert_allclose(lengths, 2 * np.pi * np.array(radii), rtol=1e-6)
    for c in r["curves"]:
        assert c["closed"] and c["points"] > 10
        assert c["max_distance_a"] <= 1e-7 and c["max_distance_b"] <= 1e-7
        assert len(c["faces"]) == 2
    occ = r["occ"]
    assert occ["branches"] == occ["our_branches"] == 2
    assert occ["hausdorff"] <= 1e-6
    assert occ["length"] == pytest.approx(sum(lengths), rel=1e-5)
    shape = read_step_shape(out)
    assert count(shape, TopAbs_EDGE) == 2 and count(shape, TopAbs_FACE) == 0
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_json_on_stdout(files, tmp_path, capsys):
    code, stdout, err = run(capsys, "intersect", files["sphere"], files["slab"],
                            "-o", tmp_path / "c.step", "--json", "-")
    assert code == 0, err
    r = json.loads(stdout)
    assert r["n_curves"] == 2 and r["tol"] > 0


def test_one_file_without_intersections(files, tmp_path, capsys):
    out = tmp_path / "none.step"
    code, stdout, err = run(capsys, "intersect", files["box"], "-o", out, "--compare-occ")
    assert code == 0, err
    assert "0 intersection curve(s)" in stdout and not out.exists()


def assert_one_line_error(err: str, *words: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("surfprep: error: "), err
    for word in words:
        assert word in lines[0], err


def test_missing_input(tmp_path, capsys):
    code, _, err = run(capsys, "intersect", tmp_path / "nope.step", "-o", tmp_path / "o.step")
    assert code == 2
    assert_one_line_error(err, "nope.step")


def test_bad_tolerance(files, tmp_path, capsys):
    code, _, err = run(capsys, "intersect", files["sphere"], files["slab"],
                       "-o", tmp_path / "o.step", "--tol", "nan")
    assert code == 2
    assert_one_line_error(err, "tol")


def test_refuses_to_overwrite_an_input(files, capsys):
    before = files["slab"].read_bytes()
    code, _, err = run(capsys, "intersect", files["sphere"], files["slab"], "-o", files["slab"])
    assert code == 2
    assert_one_line_error(err, "input")
    assert files["slab"].read_bytes() == before


def test_listed_in_help(capsys):
    code, stdout, _ = run(capsys, "--help")
    assert code == 0 and "intersect" in stdout


def test_a_pair_over_the_time_limit_is_stopped_and_the_run_goes_on(files, tmp_path, capsys,
                                                                   monkeypatch):
    """The first face pair hangs (as a pathological pair would); --pair-time-limit stops
    it, the other pairs give their curves, the report names the stopped pair, exit 1."""
    import time as clock

    import surfprep.plugin.intersect as verb
    real = verb.pair_curves
    calls = []

    def first_hangs(fa, fb, *args):
        calls.append((fa.index, fb.index))
        if len(calls) == 1:
            clock.sleep(60)
        return real(fa, fb, *args)

    monkeypatch.setattr(verb, "pair_curves", first_hangs)
    report = tmp_path / "r.json"
    start = clock.perf_counter()
    code, stdout, err = run(capsys, "intersect", files["sphere"], files["slab"], "-o",
                            tmp_path / "c.step", "--json", report, "--pair-time-limit", "0.5")
    assert clock.perf_counter() - start < 30
    assert code == 1, err
    r = json.loads(report.read_text())
    (stopped,) = r["stopped_pairs"]
    assert stopped["faces"] == list(calls[0]) and 0.45 <= stopped["time_s"] < 10
    assert len(calls) > 1 and len(r["pairs"]) == len(calls) - 1
    assert "stopped after" in err and "--pair-time-limit" in err
    assert "Traceback" not in err
    import signal
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)        # disarmed afterwards


@pytest.mark.parametrize("value", ["-1", "nan", "inf", "soon"])
def test_a_bad_pair_time_limit_is_a_usage_error(value, files, tmp_path, capsys):
    code, _, err = run(capsys, "intersect", files["sphere"], "-o", tmp_path / "c.step",
                       "--pair-time-limit", value)
    assert code == 2
    assert "--pair-time-limit" in err
