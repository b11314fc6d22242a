"""``surfprep reparam``: report, output file, faces, plot and errors."""

from __future__ import annotations

import json
import sys

import pytest
from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer

import surfprep
from surfprep.plugin.cli import main
from surfprep.plugin.occ.geom import surface_from_occ


@pytest.fixture(scope="module")
def fuselage_run(data_dir, tmp_path_factory):
    """One run on face 0 of the fuselage."""
    out = tmp_path_factory.mktemp("reparam")
    source = data_dir / "occt_fuselage.stp"
    code = main(["reparam", str(source), "-o", str(out / "out.step"), "--faces", "0",
                 "--json", str(out / "r.json"), "--plot", str(out / "iso.png")])
    return code, out, source


def test_report_and_output(fuselage_run, capsys):
    code, out, source = fuselage_run
    assert code == 0
    report = json.loads((out / "r.json").read_text())
    (ok,) = report["faces"]
    assert ok["index"] == 0 and ok["status"] == "ok"
    assert ok["max_deviation"] <= ok["tol"]
    assert ok["mismatch_before"] > 10 and ok["mismatch_after"] < 1.5
    assert ok["poles_before"] == 40 and ok["poles_after"] > 40
    model = surfprep.read(out / "out.step")
    original = surfprep.read(source)
    assert model.n_faces == original.n_faces
    assert BRepCheck_Analyzer(model.shape).IsValid()
    new = surface_from_occ(BRep_Tool.Surface_s(model.faces[0]))
    assert new.n_control[0] * new.n_control[1] == ok["poles_after"]
    old4 = surface_from_occ(BRep_Tool.Surface_s(original.faces[4]))     # not asked for
    assert surface_from_occ(BRep_Tool.Surface_s(model.faces[4])).n_control == old4.n_control
    assert (out / "iso.png").stat().st_size > 10_000


def test_errors_are_one_line(data_dir, tmp_path, capsys):
    source = data_dir / "occt_fuselage.stp"
    code = main(["reparam", str(source), "-o", str(tmp_path / "o.step"), "--tol", "-1",
                 "--faces", "0"])
    err = capsys.readouterr().err
    assert code != 0 and "tol" in err and len(err.strip().splitlines()) == 1 + 0
    code = main(["reparam", str(source), "-o", str(source)])
    assert code != 0 and "refusing to overwrite" in capsys.readouterr().err
    code = main(["reparam", str(source), "-o", str(tmp_path / "o.step"), "--faces", "99"])
    assert code != 0 and "out of range" in capsys.readouterr().err


def test_failed_face_is_kept_and_reported(tmp_path, capsys):
    import cadquery as cq
    box = tmp_path / "box.step"
    surfprep.write(cq.Workplane().box(1, 2, 3).val(), box)
    code = main(["reparam", str(box), "-o", str(tmp_path / "o.step"), "--faces", "0",
                 "--json", "-"])                                  # JSON to stdout
    report = json.loads(capsys.readouterr().out)
    assert code == 1 and (tmp_path / "o.step").exists()
    assert report["faces"][0]["status"] == "skipped"
    assert "B-spline" in report["faces"][0]["error"]
    assert surfprep.read(tmp_path / "o.step").n_faces == 6


def test_plot_without_matplotlib(data_dir, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    code = main(["reparam", str(data_dir / "occt_fuselage.stp"), "-o", str(tmp_path / "o.step"),
                 "--faces", "0", "--plot", str(tmp_path / "p.png")])
    assert code != 0 and "matplotlib" in capsys.readouterr().err
    assert not (tmp_path / "o.step").exists()


def test_a_face_over_the_time_limit_is_kept_and_the_run_goes_on(data_dir, tmp_path, capsys):
    """--face-time-limit: a face running longer is stopped, kept as it was with that
    reason, and the next faces run (exit 1); the timer is off again afterwards."""
    import signal
    out, report = tmp_path / "out.step", tmp_path / "r.json"
    code = main(["reparam", str(data_dir / "occt_fuselage.stp"), "-o", str(out), "--faces",
                 "0", "1", "--face-time-limit", "0.05", "--json", str(report)])
    assert code == 1
    faces = json.loads(report.read_text())["faces"]
    assert [f["index"] for f in faces] == [0, 1]
    assert all("a face ran longer than 0.05 s" in f["error"] for f in faces)
    assert out.is_file() and BRepCheck_Analyzer(surfprep.read(out).shape).IsValid()
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert main(["reparam", str(data_dir / "occt_fuselage.stp"), "-o", str(out),
                 "--face-time-limit", "-1"]) == 2
