"""``surfprep compose``: solids from .g2 files, curves and point labels."""

from __future__ import annotations

import json

import numpy as np
from helpers.cli import run

from surfprep.algorithms.io import write_g2
from surfprep.algorithms.volume_builders import solid_sphere


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
    assert "curve(s) where the boundaries meet" in stdout


def test_compose_refuses_files_without_a_solid_and_half_options(tmp_path, capsys):
    a = tmp_path / "a.g2"
    write_g2(a, [solid_sphere(1.0).isosurface(0.5, "u")])          # a surface, no solid
    code, _, err = run(capsys, "compose", a, a)
    assert code == 2 and "expected one solid" in err and len(err.strip().splitlines()) == 1
    b = tmp_path / "b.g2"
    write_g2(b, [solid_sphere(1.0)])
    code, _, err = run(capsys, "compose", b, b, "--classify", b)
    assert code == 2 and "--classify and --labels go together" in err
