"""The README's Python examples run as written (from a folder holding step_samples/)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def test_readme_python_examples_run(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.DOTALL)
    assert len(blocks) >= 2
    (tmp_path / "step_samples").symlink_to(ROOT / "step_samples")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "README.md", "exec"), namespace)  # noqa: S102
    assert (tmp_path / "halves.step").stat().st_size > 0
    assert namespace["grid"].shape == (100, 50, 3)
    assert namespace["q"].worst > 10          # the fuselage is far from chord-length
    assert namespace["touch"] == [] and len(namespace["touch"].isolated_points) == 1
    assert abs(namespace["contact"][1] - 10) < 1e-6
    assert namespace["network"].joins_before[0].max_gap > 1e-3 > 1e3 * namespace["join"].max_gap
    assert len(namespace["blocks"]) == 8 and namespace["worst"]["folded_cells"] == 0
    assert namespace["caps"][0] == 10 and namespace["caps"][1] < 0.4
    assert namespace["pieces"].report()["pieces"] == 7 and namespace["pieces"].valid
    assert abs(namespace["lens"].volume - 108.908545) < 1e-4
    assert (tmp_path / "fuselage.cgns").stat().st_size > 0
    import build123d as bd
    import cadquery as cq
    assert [type(e) for e in namespace["circles"]] == [cq.Edge, cq.Edge]
    assert sorted(round(e.Center().z, 4) for e in namespace["circles"]) == [4.5, 5.5]
    assert type(namespace["zones"]) is cq.Compound and len(namespace["zones"].Faces()) == 11
    assert namespace["zones_result"].report()["pieces"] == 7
    assert [type(e) for e in namespace["rims"].vals()] == [cq.Edge, cq.Edge]
    assert not hasattr(cq.Workplane, "surface_intersections")
    assert type(namespace["solid"]) is bd.Solid and namespace["solid"].label == "bracket"
    assert abs(namespace["healed"].part.volume - 600.0) < 1e-6
    assert type(namespace["skin"]) is bd.Face
    assert namespace["status"] == ("reparametrized",) * 8
    assert [line.split(":")[0] for line in namespace["lines"]] == ["heal", "intersect", "reparam",
                                                                   "grid"]
    assert (tmp_path / "fuselage-ready.step").stat().st_size > 0
    first = namespace["wall"].points[1, 0] - namespace["wall"].points[0, 0]
    assert abs(float(np.linalg.norm(first)) - 5.0) < 5e-3
