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

    def first_hangs(fa, fb, *args, **kwargs):
        calls.append((fa.index, fb.index))
        if len(calls) == 1:
            clock.sleep(60)
        return real(fa, fb, *args, **kwargs)

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


# ------------------------------------------------------------------ --plot
def test_plot_axes_are_equal_and_not_blown_up_from_noise():
    from surfprep.plugin.commands.intersect import equal_extent, widen_flat_axis
    from surfprep.plugin.commands.plotting import pyplot
    centre, half = equal_extent(np.array([[0.0, 0.0, 5.0], [10.0, 2.0, 5.0 + 1e-12]]), 1e-3)
    assert np.allclose(centre, [5.0, 1.0, 5.0]) and half == pytest.approx(5.25)
    _, half = equal_extent(np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0 + 1e-13]]), 1e-3)
    assert half == 1e-3                                 # a point's noise is not the extent
    plt = pyplot()
    fig, ax = plt.subplots()
    ax.plot([0.0, 6.0], [0.48, 0.48 + 1e-9])            # a constant-v curve over rounding noise
    widen_flat_axis(ax)
    lo, hi = ax.get_ylim()
    assert hi - lo == pytest.approx(6.0) and lo < 0.48 < hi
    plt.close(fig)


def test_plot_draws_each_face_in_its_own_domain(files, tmp_path, monkeypatch):
    """Sphere x slab: the 3-D view and one (u, v) panel per face (the sphere's and the
    slab faces the curves lie on), each spanning that face's own domain; with no curve the
    figure says so instead of drawing empty axes."""
    import surfprep.plugin.commands.intersect as command
    from surfprep.plugin.commands import plotting
    result = surfprep.intersect(files["sphere"], str(files["slab"]))   # files, as the README says
    assert len(result) == 2
    seen = []

    def keep(fig, path):
        seen.append({ax.get_title(): (ax.get_xlim(), ax.get_ylim(), ax) for ax in fig.axes})
        return plotting.save_figure(fig, path)

    monkeypatch.setattr(command, "save_figure", keep)
    command.plot_curves(result, tmp_path / "a.png", two_models=True)
    panels = {t: v for t, v in seen[0].items() if "(u, v) domain" in t}
    faces = {("A", c.face_a.index): c.face_a for c in result}
    faces.update({("B", c.face_b.index): c.face_b for c in result})
    assert len(panels) == len(faces) == 3                # the sphere's face, two slab faces
    for title, (xlim, ylim, _) in panels.items():
        words = title.split()
        u0, u1, v0, v1 = faces[(words[3].rstrip(":"), int(words[1]))].surface.domain
        assert xlim == (u0, u1) and ylim == (v0, v1)
    command.plot_curves([], tmp_path / "b.png")
    (view,) = [ax for _, _, ax in seen[1].values()]
    assert view.get_title().startswith("0 curve(s)")
    assert any(t.get_text() == "no intersection curve" for t in view.texts)
