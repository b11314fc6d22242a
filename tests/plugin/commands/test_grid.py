"""``surfprep grid``: files, report, exit codes, outputs checked before the work."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run
from helpers.grid_cases import side_angles
from helpers.paths import SAMPLES

from surfprep.algorithms.grid.io import read_plot3d

FUSELAGE = SAMPLES / "occt_fuselage.stp"
CATIA_FACE = SAMPLES / "occt_catia4_face_L1.igs"


def test_grid_writes_plot3d_and_a_report(tmp_path, capsys):
    out, report = tmp_path / "f.xyz", tmp_path / "f.json"
    code, stdout, _ = run(capsys, "grid", FUSELAGE, "-o", out, "--size", "2000", "--json", report)
    assert code == 0, stdout
    data = json.loads(report.read_text())
    blocks = read_plot3d(out)
    assert len(blocks) == len(data["blocks"]) == 8
    for block, entry in zip(blocks, data["blocks"], strict=True):
        assert list(block.shape[:2]) == entry["dims"]
        assert entry["quality"]["folded_cells"] == 0
    assert "8 block(s), 14 shared edge(s)" in stdout


def test_dims_and_spacing_reach_the_file(tmp_path, capsys):
    out = tmp_path / "c.xyz"
    code, stdout, _ = run(capsys, "grid", CATIA_FACE, "-o", out, "--whole-surfaces", "--dims", "21",
                          "17", "--first-spacing", "2.0", "--binary")
    assert code == 0, stdout
    (block,) = read_plot3d(out)
    assert block.shape == (21, 17, 3)
    assert np.linalg.norm(block[1, 0] - block[0, 0]) == pytest.approx(2.0, rel=1e-3)


def test_the_sides_orthogonality_is_on_by_default_and_can_be_turned_off(tmp_path, capsys):
    """The catia4 surface's plain grid leaves its sides up to 11 degrees off 90; by default the
    lines leave them square (measured here on the written nodes, one-sided across the side)."""
    angles = {}
    for flag in ((), ("--no-orthogonal",)):
        out, report = tmp_path / f"c{len(flag)}.xyz", tmp_path / f"c{len(flag)}.json"
        code, stdout, _ = run(capsys, "grid", CATIA_FACE, "-o", out, "--whole-surfaces", "--dims", "41",
                              "41", "--json", report, *flag)
        assert code == 0, stdout
        (entry,) = json.loads(report.read_text())["blocks"]
        assert entry["quality"]["folded_cells"] == 0
        (block,) = read_plot3d(out)
        angles[flag] = max(float(np.abs(a - 90).max()) for a in side_angles(block))
        assert (entry["elliptic"]["sides_misfit"] <= 1.0) if not flag else entry["elliptic"]["sides_misfit"] == 0
    assert angles[()] < 0.5
    assert angles[("--no-orthogonal",)] > 8.0


def test_nothing_to_grid_is_one_line_and_exit_2(tmp_path, capsys):
    out = tmp_path / "c.xyz"
    code, _, err = run(capsys, "grid", CATIA_FACE, "-o", out)
    assert code == 2
    assert "not split into four-sided blocks" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("argv, message", [
    (["-o", "{tmp}/g.step"], "unknown extension"),
    (["-o", "{tmp}/missing/g.xyz"], "does not exist"),
    (["-o", "{tmp}/g.cgns", "--binary"], "--binary is for Plot3D"),
    (["-o", "{tmp}/g.xyz", "--growth", "1.2", "--first-spacing", "1"], "not both"),
])
def test_outputs_and_options_are_checked_before_the_work(tmp_path, capsys, argv, message):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    code, _, err = run(capsys, "grid", FUSELAGE, *argv)
    assert code == 2 and message in err
    assert not [p for p in tmp_path.iterdir() if p.is_file()]


def test_plot_draws_the_grids(tmp_path, capsys):
    pytest.importorskip("matplotlib", reason="--plot needs matplotlib")
    out, png = tmp_path / "f.vtm", tmp_path / "f.png"
    code, _, _ = run(capsys, "grid", FUSELAGE, "-o", out, "--size", "3000", "--plot", png)
    assert code == 0 and png.stat().st_size > 10_000


def test_the_input_is_never_overwritten(tmp_path, capsys):
    copy = tmp_path / "f.xyz"
    copy.write_bytes(FUSELAGE.read_bytes())
    code, _, err = run(capsys, "grid", copy, "-o", copy)
    assert code == 2 and "refusing to overwrite" in err


def test_held_curves_from_a_file_become_grid_lines(tmp_path, capsys):
    import surfprep
    from surfprep.algorithms.projection import distance_to_curve
    face = surfprep.to_nurbs(surfprep.read(FUSELAGE).faces[0])
    held = face.surface.isocurve(1.7, "u")                  # across face 0, from v0 to v1
    curves = tmp_path / "held.step"
    surfprep.write(held, curves)
    out, report = tmp_path / "f.xyz", tmp_path / "f.json"
    code, _, err = run(capsys, "grid", FUSELAGE, "-o", out, "--size", "2000", "--hold", curves,
                       "--json", report)
    assert code == 0, err
    block = read_plot3d(out)[0]
    on = [i for i, line in enumerate(block) if distance_to_curve(held, line).max() < 1e-6 * 47000]
    assert len(on) == 1
    assert json.loads(report.read_text())["blocks"][0]["held_lines"] == [f"i={on[0]}"]


def test_a_held_curve_on_no_face_is_refused(tmp_path, capsys):
    import surfprep
    from surfprep import NurbsCurve
    stray = NurbsCurve(np.array([[0.0, 0.0, 1e5], [1.0, 0.0, 1e5]]), [0, 0, 1, 1], 1)
    curves = tmp_path / "stray.step"
    surfprep.write(stray, curves)
    code, _, err = run(capsys, "grid", FUSELAGE, "-o", tmp_path / "f.xyz", "--hold", curves)
    assert code == 2 and "held curve 0 runs across no gridded face" in err


def test_dims_on_faces_split_into_blocks_take_the_larger_count_with_a_note(tmp_path, capsys):
    """The Mars capsule's n-sided faces are split into blocks round a centre, whose i and
    j directions meet along the spokes: --dims 11 21 used to be refused; now those
    directions get 21 and the report and a note say which."""
    out, report = tmp_path / "g.xyz", tmp_path / "g.json"
    code, _, err = run(capsys, "grid", SAMPLES / "overture_marscapsule_proe.igs", "-o", out,
                       "--dims", "11", "21", "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())
    assert data["dims_changed"] and all(d["nodes"] == 21 and d["direction"] == "i" for d in data["dims_changed"])
    assert all(b["dims"][0] in (11, 21) and b["dims"][1] == 21 for b in data["blocks"])
    assert "not the --dims asked" in err


def test_a_ball_read_from_step_is_gridded(tmp_path, capsys):
    """The face of a solid sphere (was refused: 'sides j0 and j1 are both collapsed'): two
    blocks round its poles, exit 0."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere

    import surfprep
    ball = tmp_path / "ball.step"
    surfprep.write(BRepPrimAPI_MakeSphere(5.0).Shape(), ball)
    out, report = tmp_path / "ball.cgns", tmp_path / "ball.json"
    code, stdout, _ = run(capsys, "grid", ball, "-o", out, "--json", report)
    assert code == 0, stdout
    data = json.loads(report.read_text())
    assert len(data["blocks"]) == 2 and data["worst"]["folded_cells"] == 0 and not data["skipped"]


def test_pole_caps_h_grids_a_sphere_without_a_pole_cell(tmp_path, capsys):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere

    import surfprep
    ball, out, report = tmp_path / "ball.step", tmp_path / "ball.xyz", tmp_path / "ball.json"
    surfprep.write(BRepPrimAPI_MakeSphere(2.0).Shape(), ball)
    code, stdout, _ = run(capsys, "grid", ball, "-o", out, "--size", "0.3", "--pole-caps", "h",
                          "--json", report)
    assert code == 0, stdout
    data = json.loads(report.read_text())
    assert len(read_plot3d(out)) == len(data["blocks"]) == 10
    assert all(not b["collapsed_sides"] for b in data["blocks"])
    code, stdout, _ = run(capsys, "grid", ball, "-o", tmp_path / "o.xyz", "--size", "0.3")
    assert code == 0 and len(read_plot3d(tmp_path / "o.xyz")) == 2
