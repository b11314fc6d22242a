"""The surfprep command line: info, demo, exit codes and one-line errors."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run
from helpers.paths import SAMPLES

import surfprep
from surfprep.plugin import cli
from surfprep.plugin.commands import COMMANDS
from surfprep.plugin.commands import info as info_command

FUSELAGE = SAMPLES / "occt_fuselage.stp"
SYNTHETIC = SAMPLES / "synthetic_named_faces.step"
CAPSULE = SAMPLES / "overture_marscapsule_proe.igs"



def assert_one_line_error(err: str, *words: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("surfprep: error: "), err
    assert "Traceback" not in err
    for word in words:
        assert word in lines[0], err


# ---------------------------------------------------------------- framework
def test_help_teaches(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0
    assert "examples:" in out and "exit codes" in out
    for command in COMMANDS:
        assert command.name in out
    code, out, _ = run(capsys, "info", "--help")
    assert code == 0 and "--json" in out and "examples:" in out
    code, out, _ = run(capsys, "demo", "--help")
    assert code == 0 and "--outdir" in out


def test_version(capsys):
    code, out, _ = run(capsys, "--version")
    assert code == 0
    assert out.startswith("surfprep ")


def test_usage_errors_exit_2(capsys):
    code, _, err = run(capsys)
    assert code == 2 and "no command" in err
    code, _, err = run(capsys, "info")
    assert code == 2 and "FILE" in err
    code, _, err = run(capsys, "frobnicate")
    assert code == 2
    code, _, _ = run(capsys, "info", str(FUSELAGE), "--no-such-option")
    assert code == 2


def test_commands_are_registered_once():
    names = [c.name for c in COMMANDS]
    assert len(names) == len(set(names))
    assert {"info", "demo"} <= set(names)


# --------------------------------------------------------------------- info
def test_info_text_table(capsys):
    code, out, err = run(capsys, "info", str(SYNTHETIC))
    assert code == 0, err
    assert "faces: 4" in out
    for name in ("uniform_patch", "cubic_u_patch", "plane", "cylinder"):
        assert name in out
    rows = [ln for ln in out.splitlines() if ln.split()[:1] in (["0"], ["1"], ["2"], ["3"])]
    assert len(rows) == 4
    assert "BSpline" in rows[0] and "Plane" in rows[2] and "Cylinder" in rows[3]
    assert "7 (u)" in rows[1]  # x = u**3: worst chord ratio 7 in u


def test_info_json_stdout(capsys):
    code, out, _ = run(capsys, "info", str(FUSELAGE), "--json", "-")
    assert code == 0
    report = json.loads(out)  # stdout is pure JSON: no table, no OCCT chatter
    assert report["n_faces"] == len(report["faces"]) == 8
    assert report["format"] == "STEP"
    assert report["declared_length_unit"] == "ft"
    face = report["faces"][0]
    assert face["surface_type"] == "BSpline"
    assert face["degree"] == [3, 3] and face["poles"] == [10, 4] and face["knot_spans"] == [3, 1]
    assert face["rational"] is False
    assert len(face["uv_bounds"]) == 4 and len(face["bounding_box"]) == 6
    assert face["area"] > 0 and face["param_quality"] > 1


def test_info_json_file_and_analytic_faces_have_null_quality(capsys, tmp_path):
    target = tmp_path / "report.json"
    code, out, err = run(capsys, "info", str(SYNTHETIC), "--json", str(target))
    assert code == 0
    assert "faces: 4" in out and str(target.resolve()) in err
    report = json.loads(target.read_text())
    types = [f["surface_type"] for f in report["faces"]]
    assert types == ["BSpline", "BSpline", "Plane", "Cylinder"]
    assert [f["param_quality"] is None for f in report["faces"]] == [False, False, True, True]
    assert report["faces"][1]["param_quality_u"] == pytest.approx(7.0)


def test_info_iges_with_duplicate_faces(capsys):
    code, out, _ = run(capsys, "info", str(CAPSULE), "--json", "-")
    assert code == 0
    assert json.loads(out)["n_faces"] == 36


def test_info_progress_on_request(capsys):
    code, _, err = run(capsys, "info", str(FUSELAGE), "--progress")
    assert code == 0
    assert "face 8/8" in err


def test_info_json_refuses_to_overwrite_input(capsys, tmp_path):
    copy = tmp_path / "part.step"
    shutil.copyfile(FUSELAGE, copy)
    before = copy.read_bytes()
    code, out, err = run(capsys, "info", str(copy), "--json", str(copy))
    assert code == 2 and out == ""  # refused before any work
    assert_one_line_error(err, "input file")
    assert copy.read_bytes() == before


# ------------------------------------------------------------- error cases
def test_missing_file(capsys, tmp_path):
    code, out, err = run(capsys, "info", str(tmp_path / "missing.step"))
    assert code == 2 and out == ""
    assert_one_line_error(err, "missing.step", "does not exist")


def test_empty_file(capsys, tmp_path):
    empty = tmp_path / "empty.stp"
    empty.write_bytes(b"")
    code, _, err = run(capsys, "info", str(empty))
    assert code == 2
    assert_one_line_error(err, "empty.stp", "empty")


def test_corrupt_file(capsys, tmp_path):
    cut = tmp_path / "cut.step"
    cut.write_bytes(FUSELAGE.read_bytes()[:9000])
    code, _, err = run(capsys, "info", str(cut))
    assert code == 2
    assert_one_line_error(err, "cut.step", "truncated")
    garbage = tmp_path / "garbage.igs"
    garbage.write_text("this is not an IGES file\n")
    code, _, err = run(capsys, "info", str(garbage))
    assert code == 2
    assert_one_line_error(err, "garbage.igs")


def test_wrong_extension(capsys, tmp_path):
    wrong = tmp_path / "part.igs"
    shutil.copyfile(FUSELAGE, wrong)
    code, _, err = run(capsys, "info", str(wrong))
    assert code == 2
    assert_one_line_error(err, "part.igs", "STEP")
    unknown = tmp_path / "part.dxf"
    shutil.copyfile(FUSELAGE, unknown)
    code, _, err = run(capsys, "info", str(unknown))
    assert code == 2
    assert_one_line_error(err, "unknown extension")


def test_directory_argument(capsys, tmp_path):
    code, _, err = run(capsys, "info", str(tmp_path))
    assert code == 2
    assert_one_line_error(err, "directory")


def test_unexpected_exception_exits_1_with_one_line(capsys, monkeypatch):
    def broken_read(*args, **kwargs):
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(info_command, "read_model", broken_read)
    code, _, err = run(capsys, "info", str(FUSELAGE))
    assert code == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "RuntimeError: boom second line" in lines[0]
    assert "--debug" in lines[0] and "Traceback" not in err
    code, _, err = run(capsys, "info", str(FUSELAGE), "--debug")
    assert code == 1 and "Traceback" in err


def test_debug_shows_traceback_for_expected_errors(capsys, tmp_path):
    code, _, err = run(capsys, "--debug", "info", str(tmp_path / "missing.step"))
    assert code == 2
    assert "Traceback" in err and err.strip().splitlines()[-1].startswith("surfprep: error:")


# --------------------------------------------------------------------- demo
def test_demo_writes_step_and_report(capsys, tmp_path):
    before = hashlib.sha256(FUSELAGE.read_bytes()).hexdigest()
    outdir = tmp_path / "out"
    code, out, err = run(capsys, "demo", "-o", str(outdir))
    assert code == 0, err
    step = outdir / "occt_fuselage-rebuilt.step"
    report_path = outdir / "occt_fuselage-report.json"
    assert step.is_file() and report_path.is_file()
    grid = outdir / "occt_fuselage-grid.xyz"
    prepared = outdir / "occt_fuselage-prepared.step"
    page = outdir / "occt_fuselage-report.html"
    assert sorted(p.name for p in outdir.iterdir()) == sorted(
        [step.name, report_path.name, grid.name, prepared.name, page.name])
    report = json.loads(report_path.read_text())
    assert all(report["checks"].values())
    assert [s["status"] for s in report["prepare"]["stages"]] == ["done"] * 4
    assert report["outputs"]["prepared_step_faces_read_back"] == 8
    assert report["grid"]["blocks"] == 8 and report["grid"]["interfaces"] == 14
    assert report["grid"]["worst"]["folded_cells"] == 0
    assert report["info"]["n_faces"] == 8
    assert len(report["round_trip"]["faces"]) == 8
    assert report["round_trip"]["max_dev_nurbs_vs_occ"] < 1e-6
    assert report["outputs"]["rebuilt_step_faces_read_back"] == 8
    assert "summary:" in out and "faces: 8" in out
    assert hashlib.sha256(FUSELAGE.read_bytes()).hexdigest() == before
    # a second run replaces its own outputs
    code, _, err = run(capsys, "demo", "-o", str(outdir))
    assert code == 0, err


def test_demo_on_another_bundled_sample(capsys, tmp_path):
    code, _, err = run(capsys, "demo", "--sample", SYNTHETIC.name, "-o", str(tmp_path))
    assert code == 0, err
    report = json.loads((tmp_path / "synthetic_named_faces-report.json").read_text())
    # only the two B-spline faces are converted; names go through XDE
    assert [f["name"] for f in report["round_trip"]["faces"]] == ["uniform_patch",
                                                                  "cubic_u_patch"]


def test_demo_unknown_sample(capsys, tmp_path):
    code, _, err = run(capsys, "demo", "--sample", "nope.step", "-o", str(tmp_path))
    assert code == 2
    assert_one_line_error(err, "nope.step", "occt_fuselage.stp")


def test_demo_with_input_inside_outdir_leaves_it_untouched(capsys, tmp_path):
    source = tmp_path / "occt_fuselage-rebuilt.step"
    shutil.copyfile(FUSELAGE, source)
    before = source.read_bytes()
    code, _, err = run(capsys, "demo", "--input", str(source), "-o", str(tmp_path))
    assert code == 0, err  # outputs are named after the input: <stem>-rebuilt.step
    assert source.read_bytes() == before


# --------------------------------------------------------------- processes
def test_module_entry_point_subprocess():
    done = subprocess.run(
        [sys.executable, "-m", "surfprep.plugin.cli", "info", str(FUSELAGE), "--json", "-"],
        check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["n_faces"] == 8


def test_console_script_error_exit_code(tmp_path):
    script = Path(sys.executable).with_name("surfprep")
    command = [str(script)] if script.exists() else [sys.executable, "-m", "surfprep.plugin"]
    done = subprocess.run(command + ["info", str(tmp_path / "missing.igs")],
                          check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert done.stdout == ""
    assert done.stderr.strip().startswith("surfprep: error: input file")
    assert len(done.stderr.strip().splitlines()) == 1


@pytest.mark.slow
@pytest.mark.parametrize("name", ["occt_k1_catia_debis.stp", "occt_deflettore_solidedge.igs"])
def test_demo_on_real_files(capsys, tmp_path, name, data_dir):
    path = data_dir / name
    code, _, err = run(capsys, "demo", "--input", str(path), "-o", str(tmp_path))
    assert code == 0, err
    report = json.loads(next(tmp_path.glob("*-report.json")).read_text())
    assert all(report["checks"].values())


# ------------------------------------------------------------------ console
class _Stream:
    def __init__(self, tty: bool):
        self.text = ""
        self._tty = tty

    def write(self, s: str) -> int:
        self.text += s
        return len(s)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return self._tty


def test_progress_is_shown_on_a_terminal_by_default():
    from surfprep.plugin.commands.base import Console

    tty = _Stream(tty=True)
    console = Console.for_streams(_Stream(False), tty)
    assert console.show_progress
    for i in range(1, 4):
        console.progress(i, 3, "face")
    assert tty.text == "\rface 1/3 (33 %)\rface 2/3 (67 %)\rface 3/3 (100 %)\n"
    pipe = _Stream(tty=False)
    quiet = Console.for_streams(_Stream(False), pipe)
    quiet.progress(1, 3, "face")
    assert not quiet.show_progress and pipe.text == ""
    forced = Console.for_streams(_Stream(False), pipe, progress=True)
    forced.progress(2, 3, "face")
    assert pipe.text == "face 2/3 (67 %)\n"


def test_progress_says_how_long_is_left():
    """After a second the line gives the time spent and the time left (mean per step so far
    times the steps to go); a shorter line clears what the longer one left on a terminal."""
    from dataclasses import replace

    from surfprep.plugin.commands.base import Console
    now = [100.0]
    tty = _Stream(tty=True)
    console = replace(Console.for_streams(_Stream(False), tty), clock=lambda: now[0])
    console.progress(0, 10, "pair")
    now[0] = 104.0
    console.progress(2, 10, "pair")                   # 2 s a step, 8 to go
    assert tty.text.endswith("\rpair 2/10 (20 %, 4 s, about 16 s left)")
    now[0] = 120.0
    console.progress(10, 10, "pair")
    last = tty.text.rsplit("\r", 1)[1]
    assert last.startswith("pair 10/10 (100 %, 20 s)") and last.endswith("\n")
    assert len(last) == len("pair 2/10 (20 %, 4 s, about 16 s left)") + 1   # padded over


def test_quiet_leaves_out_progress_and_notes_but_not_warnings():
    from surfprep.plugin.commands.base import Console
    err = _Stream(tty=True)
    console = Console.for_streams(_Stream(False), err, progress=True, quiet=True)
    console.progress(1, 2, "face")
    console.note("report written to x.json")
    console.note("surfprep: warning: something")
    assert err.text == "surfprep: warning: something\n"


# ------------------------------------- parametrization figure on OCC surfaces
def test_parametrization_figure_of_occ_converted_cylinder_and_sphere():
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeSphere

    from surfprep.plugin.describe import SurfaceKind, describe_face
    from surfprep.plugin.io import CadModel

    cylinder = CadModel.from_shape(
        BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeCylinder(1.0, 3.0).Shape(), True).Shape())
    lateral = describe_face(cylinder.faces[0], 0)
    assert lateral.surface_type is SurfaceKind.BSPLINE and lateral.rational
    assert lateral.param_quality_v == pytest.approx(1.0, abs=1e-9)   # straight generators
    assert 1.0 < lateral.param_quality_u < 1.2  # rational arcs: speed varies within a span
    caps = [describe_face(f, i) for i, f in enumerate(cylinder.faces[1:], start=1)]
    assert all(c.param_quality == pytest.approx(1.0) for c in caps)

    sphere = CadModel.from_shape(
        BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeSphere(2.0).Shape(), True).Shape())
    face = describe_face(sphere.faces[0], 0)
    # the poles collapse u-chords to zero: skipped, so the figure stays finite
    assert 1.0 < face.param_quality_u < 1.2 and 1.0 < face.param_quality_v < 1.2


def _only_command(monkeypatch, name: str, run_it) -> None:
    """The CLI with one command, ``name``, that runs ``run_it(args, console)``."""
    import dataclasses
    fake = dataclasses.replace(COMMANDS[0], name=name, run=run_it,
                               add_arguments=lambda parser: None)
    monkeypatch.setattr(cli, "COMMANDS", (fake,))


def test_warnings_are_one_line_each(capsys, monkeypatch):
    """A warning raised while a command runs is printed as ``surfprep: warning: ...`` (no
    file, line or source echo); with --debug it stays a Python warning."""
    import warnings

    def noisy(args, console):
        warnings.warn("3 of 7 intersection curves left out:\n  they stray", UserWarning)
        return 0

    _only_command(monkeypatch, "noisy", noisy)
    code, _out, err = run(capsys, "noisy")
    assert code == 0
    assert err.strip() == "surfprep: warning: 3 of 7 intersection curves left out: they stray"
    with pytest.warns(UserWarning, match="left out"):       # --debug: Python's warning
        code, _out, err = run(capsys, "noisy", "--debug")
    assert code == 0 and "surfprep: warning" not in err


# ------------------------------------------------- checked before the work (issue 20)
@pytest.mark.parametrize("argv, words", [
    (["heal", FUSELAGE, "-o", "{tmp}/h.step", "--tol", "1e-300"], ["tol=1e-300", "below"]),
    (["heal", FUSELAGE, "-o", "{tmp}/h.step", "--gap-tol", "1e9"], ["gap_tol=1e+09", "large"]),
    (["intersect", FUSELAGE, "-o", "{tmp}/i.step", "--tol", "1e9"], ["tol=1e+09", "large"]),
    (["intersect", FUSELAGE, "-o", "{tmp}/i.step", "--tol", "1e-300"], ["tol=1e-300", "below"]),
    (["reparam", FUSELAGE, "-o", "{tmp}/r.step", "--tol", "1e-300"], ["tol=1e-300", "below"]),
    (["info", FUSELAGE, "--json", "{tmp}/missing/r.json"], ["--json", "does not exist"]),
    (["heal", FUSELAGE, "-o", "{tmp}/h.txt"], ["unknown extension", ".txt"]),
    (["intersect", FUSELAGE, "-o", "{tmp}/i.step", "--json", "{tmp}/missing/r.json"],
     ["--json", "does not exist"]),
    (["reparam", FUSELAGE, "-o", "{tmp}"], ["is a directory"]),
])
def test_absurd_tolerances_and_bad_outputs_are_refused_before_the_work(argv, words, tmp_path,
                                                                       capsys):
    code, _out, err = run(capsys, *[str(a).format(tmp=tmp_path) for a in argv])
    assert code == 2
    assert_one_line_error(err, *words)
    assert list(tmp_path.iterdir()) == []                  # nothing written


def test_an_unwritable_json_folder_is_refused_before_the_model_is_written(tmp_path, capsys,
                                                                          monkeypatch):
    """As root every folder is writable, so the check is told this one is not."""
    from surfprep.plugin.commands import base
    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(base.os, "access",
                        lambda path, mode: False if Path(path) == locked else real_access(path, mode))
    code, _, err = run(capsys, "heal", FUSELAGE, "-o", tmp_path / "h.step", "--json", locked / "r.json")
    assert code == 2
    assert_one_line_error(err, "not writable")
    assert not (tmp_path / "h.step").exists()


@pytest.fixture(scope="module")
def crossing_file(tmp_path_factory):
    """Two B-spline patches over the unit square crossing along one curve."""
    from surfprep.algorithms.fitting import interpolate_surface
    from surfprep.plugin.occ.faces import make_face
    g = np.linspace(0, 1, 6)
    gx, gy = np.meshgrid(g, g, indexing="ij")
    patches = [interpolate_surface(np.stack(
        [gx, gy, 0.1 * np.sin(1.3 * gx) * np.cos(0.9 * gy) + dz + tilt * (gx - 0.5)], -1))
        for dz, tilt in ((0.0, 0.0), (0.02, 0.5))]
    path = tmp_path_factory.mktemp("crossing") / "crossing.step"
    surfprep.write([make_face(p) for p in patches], path)
    return path


@pytest.mark.parametrize("command", ["heal", "intersect", "reparam"])
def test_a_report_that_cannot_be_written_leaves_no_model(command, crossing_file, tmp_path,
                                                         capsys, monkeypatch):
    """The report is written before the model is moved into place: when writing it fails
    (a disk full, a folder taken away during the run), no model is left without it."""
    from surfprep.errors import OutputFileError
    from surfprep.plugin.commands import base

    def failing_report(report, destination, console, protected=()):
        raise OutputFileError(f"cannot write report {destination}: No space left on device")

    monkeypatch.setattr(base, "write_json_report", failing_report)
    out = tmp_path / "out.step"
    code, _, err = run(capsys, command, crossing_file, "-o", out, "--json", tmp_path / "r.json")
    assert code == 2
    assert_one_line_error(err, "No space left")
    assert list(tmp_path.iterdir()) == []                  # neither model nor temporary


@pytest.mark.parametrize("command", ["heal", "intersect", "reparam"])
def test_model_and_report_are_both_written(command, crossing_file, tmp_path, capsys):
    out, report = tmp_path / "out.step", tmp_path / "r.json"
    code, _, err = run(capsys, command, crossing_file, "-o", out, "--json", report)
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.step", "r.json"]
    assert json.loads(report.read_text())["output"] == str(out.resolve())
    assert surfprep.read(out, require_faces=False).shape is not None


def test_a_model_without_b_spline_faces_has_nothing_to_reparametrize(tmp_path, capsys):
    import cadquery as cq
    box = tmp_path / "box.step"
    surfprep.write(cq.Workplane().box(1, 2, 3).val(), box)
    code, _, err = run(capsys, "reparam", box, "-o", tmp_path / "o.step")
    assert code == 2
    assert_one_line_error(err, "nothing to reparametrize", "no B-spline face")
    assert not (tmp_path / "o.step").exists()


def test_info_lists_the_curves_of_a_file_without_faces(tmp_path, capsys):
    """What `surfprep intersect` writes (edges only) reads back: the curves listed."""
    import cadquery as cq
    cuts = surfprep.intersect(cq.Workplane().sphere(10),
                              cq.Workplane().box(30, 30, 1).translate((0, 0, 5)))
    path = tmp_path / "curves.step"
    surfprep.write(cuts.edges(), path)
    code, out, err = run(capsys, "info", path, "--json", "-")
    assert code == 0, err
    report = json.loads(out)
    assert report["n_faces"] == 0 and len(report["edges"]) == 2
    lengths = sorted(e["length"] for e in report["edges"])
    radii = sorted(np.sqrt(100 - z * z) for z in (5.5, 4.5))
    np.testing.assert_allclose(lengths, 2 * np.pi * np.array(radii), rtol=1e-6)
    assert all(e["closed"] for e in report["edges"])
    code, out, _ = run(capsys, "info", path)
    assert code == 0 and "edges bounding no face: 2" in out


def test_warnings_of_one_kind_are_counted_and_numerical_ones_say_so(capsys, monkeypatch):
    import warnings

    import numpy as np

    def noisy(args, console):
        for k in range(5):
            warnings.warn(f"{k + 1} of 7 intersection curves left out", UserWarning)
        with np.errstate(invalid="warn"):
            np.array([np.inf]) * 0.0
        return 0

    _only_command(monkeypatch, "noisy", noisy)
    code, _, err = run(capsys, "noisy")
    assert code == 0
    assert err.strip().splitlines() == [
        "surfprep: warning: 1 of 7 intersection curves left out (and 4 more like it)",
        ("surfprep: warning: numerical: invalid value encountered in multiply (in a step whose "
         "result is checked against the tolerance)")]


def test_heal_says_its_stages(capsys, tmp_path):
    """--progress: the stages without a count of their own are said as they begin."""
    code, _, err = run(capsys, "heal", SAMPLES / "occt_fuselage.stp", "-o", tmp_path / "h.step",
                       "--progress")
    assert code == 0
    lines = [ln.strip("\r") for ln in err.splitlines()]
    stages = [ln for ln in lines if ln.startswith("heal: ")]
    assert stages == ["heal: reading the faces", "heal: directed patches and overlaps",
                      "heal: finding gaps, holes and crossings",
                      "heal: triangulating the faces as sources", "heal: approximants",
                      "heal: joining, sewing and checking",
                      "heal: closing gaps in the geometry",
                      "heal: classifying the free edges"]
