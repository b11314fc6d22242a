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
from surfprep.plugin.dropped import DroppedEntity, iges_face_count

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


def _iges(directory: list[tuple[int, int, str, int]], parameters: list[str]) -> bytes:
    """An IGES text with the given directory entries ``(type, first P line, status, form)``
    (one P line each unless the parameters say otherwise) and parameter lines."""
    lines = ["1H,,1H;,4Htest;".ljust(72) + "G      1"]
    for k, (kind, start, status, form) in enumerate(directory):
        lines.append(f"{kind:8d}{start:8d}{'':48}{status:>8}".ljust(72) + f"D{2 * k + 1:7d}")
        lines.append(f"{kind:8d}{'':16}{1:8d}{form:8d}".ljust(72) + f"D{2 * k + 2:7d}")
    for k, text in enumerate(parameters):
        lines.append(text.ljust(64) + f"{'':8}P{k + 1:7d}")
    return "\n".join(lines).encode() + b"\n"


def test_iges_faces_are_counted_by_the_standards_rules():
    data = _iges(
        [(128, 1, "00010000", 0),     # D1: trimmed by the 144 below: not a face of its own
         (144, 2, "00000000", 0),     # D3: one face
         (128, 3, "", 0),             # D5: blank status = independent: one face
         (128, 4, "00010000", 0),     # D7: physically dependent (used by something): none
         (108, 5, "00000000", 0),     # D9: unbounded plane: none
         (108, 6, "00000000", 1),     # D11: bounded plane: one face
         (510, 7, "00010000", 0),     # D13: a face of a shell: one face (its surface D15 is not)
         (128, 8, "00000000", 0),     # D15: pointed to by the 510, independent by its status
         (128, 9, "00020000", 0)],    # D17: logically dependent (a group's member): one face
        ["128,1;", "144,1,1,0,0;", "128,1;", "128,1;", "108,0;", "108,1;", "510,15,1,1,0;",
         "128,1;", "128,1;"])
    assert iges_face_count(data) == 5


@pytest.mark.slow
def test_iges_face_counts_of_real_files_agree_with_opencascade(data_dir: Path):
    """The directory count equals the faces OpenCascade translates on every real IGES file
    but the Mars capsule, whose groups make OpenCascade translate 9 trimmed surfaces 4 times
    (36 faces): more than counted is never called a loss."""
    counted = {}
    for path in sorted(data_dir.iterdir()):
        if path.suffix.lower() in (".igs", ".iges"):
            counted[path.name] = (iges_face_count(path.read_bytes()), surfprep.read(path).n_faces)
    assert counted.pop("overture_marscapsule_proe.igs") == (9, 36)
    assert len(counted) >= 8
    for name, (count, translated) in counted.items():
        assert count == translated, name


def test_a_face_that_lost_its_boundary_is_reported(tmp_path, capsys):
    """A trimming curve of degree 0: OpenCascade makes the face with natural bounds (the
    whole surface) and says so only in a check; that is a face dropped, named."""
    path = tmp_path / "boundary.step"
    path.write_bytes(SYNTHETIC.replace(b"#27 = B_SPLINE_CURVE_WITH_KNOTS('',3,",
                                       b"#27 = B_SPLINE_CURVE_WITH_KNOTS('',0,", 1))
    model = surfprep.read(path)
    assert model.n_faces == 4
    assert [d.label for d in model.dropped] == ["#17"]
    assert "natural bounds" in model.dropped[0].reason
    assert "untrimmed surface" in model.dropped[0].reason
    code, out, err = run(capsys, "info", path, "--json", "-")
    assert code == 1 and "#17" in err and json.loads(out)["dropped"][0]["entity"] == "#17"


@pytest.mark.slow
def test_repairs_are_named_and_said(data_dir: Path, capsys):
    """occt_k1_catia_debis.stp: OpenCascade corrects three edge loops whose edges cross
    while reading; each is named in the model, in one warning line and in the JSON."""
    path = data_dir / "occt_k1_catia_debis.stp"
    model = surfprep.read(path)
    assert model.dropped == ()
    assert len(model.repaired) == 3
    assert {r.kind for r in model.repaired} == {"StepShape_EdgeLoop"}
    assert all("corrected" in r.repair for r in model.repaired)
    text = path.read_bytes()
    for r in model.repaired:                           # the labels are the file's own
        assert f"\n{r.label}=EDGE_LOOP(".encode() in text, r.label
    assert not any("corrected" in message for _, message, _ in model.translation_notes)
    code, out, err = run(capsys, "info", path, "--json", "-")
    assert code == 0                                   # repaired is not dropped
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("surfprep: warning: ")
    assert all(r.label in lines[0] for r in model.repaired)
    assert [r["entity"] for r in json.loads(out)["repaired"]] == [r.label for r in model.repaired]
