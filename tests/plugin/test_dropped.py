"""What the translation leaves out is reported, never silent: the entity, its type, the
faces using it and OpenCascade's reason, in the model, on stderr and in the JSON; exit 1,
or an error with --strict. Real files report nothing."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.paths import SAMPLES

import surfprep
from surfprep.plugin.dropped import DroppedEntity

FUSELAGE = (SAMPLES / "occt_fuselage.stp").read_bytes()
SYNTHETIC = (SAMPLES / "synthetic_named_faces.step").read_bytes()


@pytest.fixture
def decreasing_knots(tmp_path) -> Path:
    path = tmp_path / "knots.stp"
    path.write_bytes(FUSELAGE.replace(b"(4,3,3,4),(4,4),(0.,1.,2.,3.)", b"(4,3,3,4),(4,4),(0.,2.,1.,3.)", 1))
    return path


def test_a_surface_with_decreasing_knots_is_reported(decreasing_knots):
    model = surfprep.read(decreasing_knots)
    assert model.n_faces == 7                                  # one of 8 lost ...
    (dropped,) = model.dropped                                 # ... and said
    assert dropped.label == "#55" and "BSplineSurfaceWithKnots" in dropped.kind
    assert "not mapped" in dropped.reason


def test_a_face_lost_names_the_face(tmp_path):
    broken = SYNTHETIC.replace(b"#34 = B_SPLINE_SURFACE_WITH_KNOTS('',3,3,",
                               b"#34 = B_SPLINE_SURFACE_WITH_KNOTS('',3,-1,", 1)
    path = tmp_path / "degree.step"
    path.write_bytes(broken)
    model = surfprep.read(path)
    assert model.n_faces == 3
    assert any("uniform_patch" in " ".join(d.faces) for d in model.dropped), model.dropped


def test_the_cli_warns_exits_1_and_lists_it(decreasing_knots, capsys):
    code, out, err = run(capsys, "info", decreasing_knots, "--json", "-")
    assert code == 1
    (line,) = err.strip().splitlines()
    assert line.startswith("surfprep: warning: knots.stp: OpenCascade did not translate 1 entity")
    assert "#55" in line
    report = json.loads(out)
    assert report["dropped"] == [{"file": "knots.stp", "entity": "#55",
                                  "type": "StepGeom_BSplineSurfaceWithKnots",
                                  "reason": "Entity not mapped to TopoDS", "faces": []}]


def test_strict_makes_it_an_error(decreasing_knots, capsys):
    code, _, err = run(capsys, "info", decreasing_knots, "--strict")
    assert code == 2 and err.startswith("surfprep: error: ") and "(--strict)" in err


def test_an_intact_file_reports_nothing(capsys):
    code, out, err = run(capsys, "info", SAMPLES / "occt_fuselage.stp", "--json", "-")
    assert code == 0 and err == "" and json.loads(out)["dropped"] == []


def test_the_record_reads_well():
    d = DroppedEntity("#17", "StepShape_AdvancedFace", "Entity not mapped to TopoDS", ("#17 'wing'",))
    assert str(d) == "#17 StepShape_AdvancedFace (used by face #17 'wing'): Entity not mapped to TopoDS"
    assert d.as_dict()["faces"] == ["#17 'wing'"]


@pytest.mark.slow
def test_real_files_lose_nothing(data_dir: Path):
    for path in sorted(data_dir.iterdir()):
        if path.suffix.lower() in (".stp", ".step", ".igs", ".iges"):
            assert surfprep.read(path).dropped == (), path.name
