"""``surfprep compose``: solids from .g2 files, curves and point labels."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.cli import run

from surfprep.algorithms.io import write_g2
from surfprep.algorithms.volume_builders import solid_sphere, solid_torus


def test_compose_labels_points_as_the_implicit_answer(tmp_path, capsys):
    a, b = tmp_path / "a.g2", tmp_path / "b.g2"
    write_g2(a, [solid_sphere(5.0, (0, 0, 0))])
    write_g2(b, [solid_sphere(5.0, (6, 0, 0))])
    points = np.random.default_rng(3).uniform([-6, -6, -6], [12, 6, 6], (400, 3))
    csv, labels, report = tmp_path / "p.csv", tmp_path / "l.txt", tmp_path / "r.json"
    np.savetxt(csv, points, delimiter=",")
    code, stdout, err = run(capsys, "compose", a, b, "--classify", csv, "--labels", labels, "--json", report)
    assert code == 0, err
    got = np.loadtxt(labels, dtype=int)
    exact = (np.linalg.norm(points, axis=1) <= 5).astype(int) \
        + 2 * (np.linalg.norm(points - [6, 0, 0], axis=1) <= 5).astype(int)
    assert np.array_equal(got, exact)
    data = json.loads(report.read_text())
    assert data["curves"] and abs(sum(c["length"] for c in data["curves"]) - 2 * np.pi * 4) < 1e-2
    assert abs(data["volume_A"] - 4 / 3 * np.pi * 125) < 1e-9
    lens = np.pi * (4 * 5 + 6) * (2 * 5 - 6) ** 2 / 12
    assert data["volume_common"] == pytest.approx(lens, rel=1e-9)
    assert data["volume_union"] == pytest.approx(2 * 4 / 3 * np.pi * 125 - lens, rel=1e-9)
    assert all(c["max_distance"] <= data["tol"] for c in data["curves"])
    h = data["hierarchy"]
    assert h["bezier_patches_a"] == h["bezier_patches_b"] == 8 and h["loops"] == 1
    assert h["overlap_boxes"] > 0 and h["triangles"] > 0 and h["loop_gap"] <= data["tol"]
    assert set(data["times"]) == {"curves", "hierarchy", "volumes", "classification"}
    assert "curve(s) where the boundaries meet" in stdout and "overlap boxes" in stdout


def test_compose_writes_the_curves_and_a_plot(tmp_path, capsys):
    pytest.importorskip("matplotlib", reason="--plot needs matplotlib")
    a, b = tmp_path / "a.g2", tmp_path / "b.g2"
    write_g2(a, [solid_torus(3.0, 1.0)])
    write_g2(b, [solid_torus(3.0, 1.0, (1.0, 0.5, 0.3), (0.2, 0.1, 1.0))])
    curves, png = tmp_path / "curves.step", tmp_path / "tori.png"
    report = tmp_path / "r.json"
    code, stdout, err = run(capsys, "compose", a, b, "-o", curves, "--plot", png, "--json", report)
    assert code == 0, err
    assert png.stat().st_size > 20_000 and png.read_bytes()[:4] == b"\x89PNG"
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(curves)) == IFSelect_RetDone
    reader.TransferRoots()
    edges, ex = 0, TopExp_Explorer(reader.OneShape(), TopAbs_EDGE)
    while ex.More():
        edges, _ = edges + 1, ex.Next()
    data = json.loads(report.read_text())
    assert edges == len(data["curves"]) >= 2
    assert data["hierarchy"]["loops"] == data["hierarchy"]["closed_loops"] == 2
    assert data["hierarchy"]["bezier_patches_a"] == 16
    assert "2 loop(s)" in stdout


def test_compose_refuses_files_without_a_solid_and_half_options(tmp_path, capsys):
    a = tmp_path / "a.g2"
    write_g2(a, [solid_sphere(1.0).isosurface(0.5, "u")])          # a surface, no solid
    code, _, err = run(capsys, "compose", a, a)
    assert code == 2 and "expected one solid" in err and len(err.strip().splitlines()) == 1
    b = tmp_path / "b.g2"
    write_g2(b, [solid_sphere(1.0)])
    code, _, err = run(capsys, "compose", b, b, "--classify", b)
    assert code == 2 and "--classify and --labels go together" in err
