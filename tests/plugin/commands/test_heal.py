"""``surfprep heal``: a STEP file with a 1e-3 gap in, a sewn shell out, report and plot."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run

import surfprep
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.plugin.occ.faces import make_face


def graph_patch(x0, x1, nu, dz):
    x, y = np.linspace(x0, x1, nu), np.linspace(0, 1, 6)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    z = 0.3 * np.sin(1.3 * gx) * np.cos(0.9 * gy) + dz
    return interpolate_surface(np.stack([gx, gy, z], axis=-1))


@pytest.fixture(scope="module")
def gap_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("cli_heal") / "gap.step"
    surfprep.write([make_face(graph_patch(0, 1, 6, 0.0)), make_face(graph_patch(1, 2, 8, 1e-3))],
                   path)
    return path


def test_heal_gap_file(gap_file, tmp_path, capsys):
    out, report, plot = tmp_path / "healed.step", tmp_path / "r.json", tmp_path / "d.png"
    code, stdout, err = run(capsys, "heal", gap_file, "-o", out, "--continuity", "G1",
                            "--json", report, "--plot", plot)
    assert code == 0, err
    assert "2 approximant(s)" in stdout and "valid True -> True" in stdout
    rep = json.loads(report.read_text())
    assert rep["continuity"] == "G1" and len(rep["shared_edges"]) == 1
    edge = rep["shared_edges"][0]
    assert edge["max_gap"] < 1e-12 and edge["max_angle_deg"] < 1e-2
    assert rep["shared_edges_before"][0]["max_gap"] > 9e-4
    assert rep["free_edges"]["tight_before"] == 8 and rep["free_edges"]["tight_after"] == 6
    for p in rep["patches"]:
        assert set(p) >= {"resolution", "max_error", "rms_error", "artificial_share"}
    assert plot.stat().st_size > 10_000
    healed = surfprep.read(out)
    assert healed.n_faces == 2
    # what is left free is said: the gap is closed, the outer border is no defect
    assert ("free edges left in the geometry: 0 interior (0 along gaps, 0 around holes), "
            "6 on the open boundary") in stdout


def test_the_summary_names_loop_kinds_in_the_plural():
    from surfprep.plugin.commands.heal import _summary

    report = {"patches": [], "shared_edges": [], "dropped_overlaps": [], "time_s": 1.0,
              "continuity": "G0", "gap_tol": 0.3,
              "free_edges": {"before": 10, "after": 10, "tight_before": 158,
                             "tight_after": 46},
              "valid": {"before": False, "after": False},
              "free_loops": [{"kind": k, "fill": False} for k in
                             ("open boundary", "open boundary", "not capped", "not capped",
                              "gap", "gap", "hole")],
              "free_boundary": {"after": {
                  "edges": {"gap": 46, "open boundary": 0, "hole": 0},
                  "interior": 46, "widest_gap": 1.19,
                  "interior_loops": [
                      {"kind": "gap", "edges": 2, "faces": [13, 16], "length": 118.0,
                       "widest_gap": 1.19},
                      {"kind": "hole", "edges": 9, "faces": list(range(20, 29)),
                       "length": 57.5, "widest_gap": None},
                      {"kind": "gap", "edges": 2, "faces": [3, 4], "length": 10.0,
                       "widest_gap": 0.5},
                      {"kind": "gap", "edges": 2, "faces": [5, 6], "length": 10.0,
                       "widest_gap": 0.4}]}}}
    lines = _summary(report)
    assert ("7 loop(s) of free edges: 2 gaps, 1 hole, 2 not capped, 2 open boundaries; "
            "fill tried on 0") in lines
    assert ("free edges left in the geometry: 46 interior (46 along gaps up to 1.19 mm "
            "wide, 0 around holes), 0 on the open boundary") in lines
    at = lines.index("free edges left in the geometry: 46 interior (46 along gaps up to "
                     "1.19 mm wide, 0 around holes), 0 on the open boundary")
    assert lines[at + 1:] == [
        "  a gap up to 1.19 mm wide: 2 edge(s) of face(s) 13, 16, 118 mm long",
        "  a hole: 9 edge(s) of face(s) 20, 21, 22, 23, 24, 25, 26, 27, ..., 57.5 mm long",
        "  a gap up to 0.5 mm wide: 2 edge(s) of face(s) 3, 4, 10 mm long",
        "  and 1 more (the report's free_boundary)"]


def test_heal_errors_are_one_line(gap_file, tmp_path, capsys):
    code, _, err = run(capsys, "heal", gap_file, "-o", gap_file)
    assert code != 0 and "overwrite" in err and len(err.strip().splitlines()) == 1
    bad = tmp_path / "spec.json"
    bad.write_text("{not json")
    code, _, err = run(capsys, "heal", gap_file, "-o", tmp_path / "x.step", "--patches", bad)
    assert code != 0 and "JSON" in err
    code, _, err = run(capsys, "heal", gap_file, "-o", tmp_path / "y.step", "--gap-tol", "-1")
    assert code != 0 and "gap_tol" in err


@pytest.mark.slow
def test_heal_directed_patch_over_crossing(tmp_path, capsys):
    # two sheets cutting through each other and a patch spec over the crossing: the
    # faces under the patch are cut away, the summary and the JSON say how much
    def sheet(x0, x1, slope):
        x, y = np.linspace(x0, x1, 9), np.linspace(0, 1, 6)
        gx, gy = np.meshgrid(x, y, indexing="ij")
        z = 0.05 * np.sin(2 * gy) + slope * (gx - 1.0)
        return interpolate_surface(np.stack([gx, gy, z], axis=-1))
    src = tmp_path / "crossing.step"
    surfprep.write([make_face(sheet(0, 1.2, 0.0)), make_face(sheet(0.8, 2, 0.4))], src)
    z = [0.0, 0.12, 0.12 + 0.05 * np.sin(2), 0.05 * np.sin(2)]
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"patches": [{"name": "over", "corners": [
        [0.7, 0, z[0]], [1.3, 0, z[1]], [1.3, 1, z[2]], [0.7, 1, z[3]]]}]}))
    out, report = tmp_path / "healed.step", tmp_path / "r.json"
    code, stdout, err = run(capsys, "heal", src, "-o", out, "--patches", spec,
                            "--json", report)
    assert code == 0, err
    assert "directed patches cut away" in stdout and "of 2 face(s)" in stdout
    rep = json.loads(report.read_text())
    assert sorted(c["face"] for c in rep["cuts"]) == [0, 1]
    assert all(0.4 < c["area_cut"] < 0.6 for c in rep["cuts"])
    assert rep["valid"]["after"] and surfprep.read(out).n_faces == 3


def test_heal_trims_a_crossing_without_a_spec(tmp_path, capsys):
    # the same sheets without a spec: cut along their crossing, the overshoots dropped;
    # --no-trim-crossings leaves them
    def sheet(x0, x1, slope):
        x, y = np.linspace(x0, x1, 9), np.linspace(0, 1, 6)
        gx, gy = np.meshgrid(x, y, indexing="ij")
        return interpolate_surface(np.stack([gx, gy, 0.05 * np.sin(2 * gy) + slope * (gx - 1.0)],
                                            axis=-1))
    src = tmp_path / "crossing.step"
    surfprep.write([make_face(sheet(0, 1.2, 0.0)), make_face(sheet(0.8, 2, 0.4))], src)
    out, report = tmp_path / "healed.step", tmp_path / "r.json"
    code, stdout, err = run(capsys, "heal", src, "-o", out, "--json", report)
    assert code == 0, err
    assert "1 curve(s) where faces cut through each other: 1 trimmed back" in stdout
    rep = json.loads(report.read_text())
    assert [c["action"] for c in rep["crossings"]] == ["trimmed back"]
    assert rep["free_edges"]["before"] == 8 and rep["free_edges"]["after"] == 6
    code, stdout, err = run(capsys, "heal", src, "-o", tmp_path / "left.step", "--json", report,
                            "--no-trim-crossings")
    assert code == 0, err
    rep = json.loads(report.read_text())
    assert rep["crossings"] == [] and rep["free_edges"]["after"] == 8


@pytest.mark.parametrize("overlap, faces_out", [("trim", 2), ("union", 1)])
def test_heal_overlap_option(tmp_path, capsys, overlap, faces_out):
    # a strip overlap of two four-sided sheets: --overlap trim keeps two faces (the later
    # one trimmed back), --overlap union replaces both by one approximant
    src = tmp_path / "overlap.step"
    surfprep.write([make_face(graph_patch(0, 1, 6, 0.0)), make_face(graph_patch(0.7, 1.7, 7, 0.0))],
                   src)
    out, report = tmp_path / f"{overlap}.step", tmp_path / f"{overlap}.json"
    code, _, err = run(capsys, "heal", src, "-o", out, "--overlap", overlap, "--json", report)
    assert code == 0, err
    rep = json.loads(report.read_text())
    action = "union" if overlap == "union" else "trimmed back"
    assert [t["action"] for t in rep["trimmed_overlaps"]] == [action]
    assert surfprep.read(out).n_faces == faces_out
    code, _, err = run(capsys, "heal", src, "-o", tmp_path / "x.step", "--overlap", "merge")
    assert code != 0 and "overlap" in err


def test_heal_split_faces_option(tmp_path, capsys):
    # a three-sided face with no defect: kept by default (--replace defects); with
    # --replace all three sub-patches (--split-faces, the default), kept as it is with
    # --no-split-faces
    from helpers.heal_cases import occ_triangle_face
    src = tmp_path / "triangle.step"
    surfprep.write([occ_triangle_face()], src)
    every = ("--replace", "all")
    for flags, faces_out in (((), 1), (every, 3), (("--split-faces", *every), 3),
                             (("--no-split-faces", *every), 1)):
        out = tmp_path / f"out{'_'.join(flags)}.step"
        code, _, err = run(capsys, "heal", src, "-o", out, *flags)
        assert code == 0, err
        assert surfprep.read(out).n_faces == faces_out


def test_an_approximant_over_the_time_limit_is_left_out(gap_file, tmp_path, capsys):
    """--job-time-limit: an approximant taking longer is stopped, its face kept as it
    was with a note, and the run goes on to a written, valid model; the timer is off
    afterwards."""
    import signal
    out, report = tmp_path / "out.step", tmp_path / "r.json"
    code, _, err = run(capsys, "heal", gap_file, "-o", out, "--job-time-limit", "0.001",
                       "--json", report)
    assert code == 0, err
    r = json.loads(report.read_text())
    stopped = [s for s in r["skipped"] if "an approximant ran longer than 0.001 s" in s]
    assert len(stopped) == 2 and r["patches"] == []
    assert surfprep.read(out).n_faces == 2 and r["valid"]["after"]
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    code, _, err = run(capsys, "heal", gap_file, "-o", tmp_path / "x.step",
                       "--job-time-limit", "nan")
    assert code == 2 and "job-time-limit" in err
