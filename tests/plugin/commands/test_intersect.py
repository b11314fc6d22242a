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
