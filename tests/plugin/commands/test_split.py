"""``surfprep split``: the pieces written and read back, the report, exit codes."""

from __future__ import annotations

import json

import cadquery as cq
import pytest
from helpers.cli import run

import surfprep


@pytest.fixture
def sphere_and_plate(tmp_path):
    a, b = tmp_path / "sphere.step", tmp_path / "plate.step"
    cq.exporters.export(cq.Workplane().sphere(10), str(a))
    cq.exporters.export(cq.Workplane().box(30, 30, 1).translate((0, 0, 5)), str(b))
    return a, b


def test_split_writes_the_pieces_and_a_report(tmp_path, capsys, sphere_and_plate):
    a, b = sphere_and_plate
    out, report = tmp_path / "cut.step", tmp_path / "cut.json"
    code, stdout, err = run(capsys, "split", a, b, "-o", out, "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())
    assert data["pieces"] == 7 and data["free_edges"] == 0 and data["valid"]
    assert data["edges_by_faces"]["4"] == 2
    # the sphere's face and the plate's two big faces became 3 + 2 + 2 pieces; 4 side faces uncut
    back = surfprep.read(out)
    assert back.n_faces == 7 + 4
    assert "7 piece(s)" in stdout
    # one shell in the file: read back, each circle is still one edge of four faces (STEP
    # holds two pcurves an edge, the reader recomputes the others), the pieces named
    from surfprep.plugin.occ.shapes import count_free_edges, is_valid
    from surfprep.plugin.split import _edge_uses
    assert _edge_uses(back.shape).get(4) == 2 and count_free_edges(back.shape) == 0 and is_valid(back.shape)
    assert sorted(n for n in back.face_names if n is not None and n.startswith("a")) == ["a0.1", "a0.2", "a0.3"]


def test_a_face_kept_whole_is_exit_1(tmp_path, capsys, monkeypatch, sphere_and_plate):
    """A face the split cannot cut is kept whole and named, and the exit code says so
    (the arrangement refusing the sphere's cuts, simulated)."""
    import surfprep.plugin.split as split_module
    from surfprep.errors import InvalidGeometryError
    real = split_module.split_face

    def refusing(face, cuts, **kw):
        if len(cuts) == 2:                       # the sphere's face: both circles
            raise InvalidGeometryError("two cuts end at one boundary point (simulated)")
        return real(face, cuts, **kw)
    monkeypatch.setattr(split_module, "split_face", refusing)
    a, b = sphere_and_plate
    code, stdout, _ = run(capsys, "split", a, b, "-o", tmp_path / "cut.step")
    assert code == 1 and "kept whole" in stdout and "simulated" in stdout


def test_a_fin_standing_on_a_sheet_shares_its_edge_with_the_sheet(tmp_path, capsys):
    """The curve stops inside the sheet: an INTERNAL edge of the sheet, the same edge as
    the one the fin's two pieces share (one edge, three faces). STEP has no internal
    edges (OpenCascade's writer leaves them out): read back, the sheet is whole and the
    fin's edge lies on it."""
    a, b = tmp_path / "sheet.step", tmp_path / "fin.step"
    cq.exporters.export(cq.Workplane("XY").rect(2, 2).extrude(0.001).faces(">Z"), str(a))
    cq.exporters.export(cq.Workplane("YZ").rect(1, 2).extrude(0.001).faces(">X"), str(b))
    out, report = tmp_path / "cut.step", tmp_path / "cut.json"
    code, _, err = run(capsys, "split", a, b, "-o", out, "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())
    assert data["valid"] and data["pieces"] == 3
    assert data["edges_by_faces"]["3"] == 1 and data["structure"]["edges_by_uses"]["3"] == 1
    faces = surfprep.to_nurbs(surfprep.read(out))
    assert len(faces) == 3 and not any(t.internal for t in faces)


def test_the_output_is_checked_before_the_work(tmp_path, capsys, sphere_and_plate):
    a, b = sphere_and_plate
    code, _, err = run(capsys, "split", a, b, "-o", tmp_path / "cut.txt")
    assert code == 2 and "unknown extension" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plate.step", "sphere.step"]


def test_boolean_common_writes_the_slab(tmp_path, capsys, sphere_and_plate):
    a, b = sphere_and_plate
    out, report = tmp_path / "common.step", tmp_path / "common.json"
    code, _, err = run(capsys, "split", a, b, "-o", out, "--boolean", "common", "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())["boolean"]
    assert data["operation"] == "common" and data["valid"]
    assert abs(data["volume"] - 235.3576496) < 1e-3
    back = surfprep.read(out)
    assert back.n_faces == 3                              # the zone and the two discs
    assert back.shape.ShapeType().name == "TopAbs_SOLID"
    # named after their faces: the sphere's zone and a piece of each of the plate's big faces
    assert sorted(n.split(".")[0] for n in back.face_names) == ["a0", "b4", "b5"]


def test_tool_writes_only_the_first_models_faces(tmp_path, capsys, sphere_and_plate):
    a, b = sphere_and_plate
    out = tmp_path / "cut.step"
    code, stdout, err = run(capsys, "split", a, b, "-o", out, "--tool")
    assert code == 0, err
    assert surfprep.read(out).n_faces == 3                # the sphere's three zones only
    assert "face b:" not in stdout


def test_the_report_names_every_output_face_and_measures_the_intersection_edges(
        tmp_path, capsys, sphere_and_plate):
    import math
    a, b = sphere_and_plate
    out, report, png = tmp_path / "cut.step", tmp_path / "cut.json", tmp_path / "curves.png"
    code, stdout, err = run(capsys, "split", a, b, "-o", out, "--json", report, "--compare-occ",
                            *(["--plot", png] if _has_matplotlib() else []))
    assert code == 0, err
    data = json.loads(report.read_text())
    faces = data["output_faces"]
    assert len(faces) == 11 and {f["operand"] for f in faces} == {"a", "b"}
    # the sphere's three zones: areas 2 pi R h (Archimedes), named after the sphere's face
    zones = sorted(f["area"] for f in faces if f["operand"] == "a")
    exact = sorted(2 * math.pi * 10 * h for h in (1.0, 10 - 5.5, 10 + 4.5))
    assert zones == pytest.approx(exact, rel=1e-6)
    assert all(f["name"].endswith((".1", ".2", ".3")) for f in faces if f["operand"] == "a")
    # the two circles z = 4.5 and 5.5 on the sphere of radius 10, within tol of both surfaces
    edges = data["intersection_edges"]
    lengths = sorted(e["length"] for e in edges)
    assert lengths == pytest.approx(sorted(2 * math.pi * math.sqrt(100 - z * z) for z in (4.5, 5.5)),
                                    rel=1e-6)
    tol = max(e["max_distance_a"] for e in edges)
    assert tol < 1e-4 and all(e["closed"] for e in edges)
    assert data["structure"]["edges_by_uses"]["4"] == 2
    occ = data["occ"]
    assert occ["method"].startswith("BRepAlgoAPI_BuilderAlgo") and occ["valid"]
    assert occ["area"] == pytest.approx(sum(f["area"] for f in faces), rel=1e-6)
    assert occ["faces"] == len(faces)
    assert "OpenCascade (BRepAlgoAPI_BuilderAlgo" in stdout
    if _has_matplotlib():
        assert png.read_bytes()[:4] == b"\x89PNG"


def test_op_is_the_boolean_and_compares_with_opencascade(tmp_path, capsys, sphere_and_plate):
    a, b = sphere_and_plate
    out, report = tmp_path / "common.step", tmp_path / "common.json"
    code, _, err = run(capsys, "split", a, b, "-o", out, "--op", "common", "--compare-occ",
                       "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())
    assert data["boolean"]["volume"] == pytest.approx(data["occ"]["volume"], rel=1e-6)
    assert data["occ"]["method"] == "BRepAlgoAPI_Common"
    code, _, err = run(capsys, "split", a, b, "-o", out, "--op", "fuse", "--boolean", "cut")
    assert code == 2 and "disagree" in err


def _has_matplotlib() -> bool:
    import importlib.util
    return importlib.util.find_spec("matplotlib") is not None


def test_op_trim_keeps_the_side_of_the_sheet(tmp_path, capsys):
    import math
    a, b = tmp_path / "sphere.step", tmp_path / "sheet.step"
    cq.exporters.export(cq.Workplane().sphere(10), str(a))
    cq.exporters.export(cq.Workplane("XY").rect(30, 30).extrude(0.001).faces(">Z").val()
                        .translate(cq.Vector(0, 0, 5 - 0.001)), str(b))
    out, report = tmp_path / "cap.step", tmp_path / "cap.json"
    code, _, err = run(capsys, "split", a, b, "-o", out, "--op", "trim", "--keep", "front",
                            "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())
    assert data["boolean"]["operation"] == "trim-front"
    from surfprep.plugin.occ.shapes import face_area
    assert face_area(surfprep.read(out).shape, 1e-9) == pytest.approx(2 * math.pi * 10 * 5, rel=1e-6)


def test_with_takes_more_solids_pairwise(tmp_path, capsys):
    """A cube minus two crossing cylinders (r = 2) from three files: 1000 - 80 pi + 128 / 3."""
    import math
    files = []
    for name, solid in (("cube", cq.Workplane().box(10, 10, 10)),
                        ("x", cq.Workplane("YZ").circle(2).extrude(20).translate((-10, 0, 0))),
                        ("y", cq.Workplane("XZ").circle(2).extrude(20).translate((0, 10, 0)))):
        files.append(tmp_path / f"{name}.step")
        cq.exporters.export(solid, str(files[-1]))
    out, report = tmp_path / "drilled.step", tmp_path / "r.json"
    code, _, err = run(capsys, "split", files[0], files[1], "-o", out, "--op", "cut", "--with", files[2],
                       "--json", report)
    assert code == 0, err
    data = json.loads(report.read_text())["boolean"]
    assert data["volume"] == pytest.approx(1000 - 80 * math.pi + 128 / 3, rel=1e-6)
    assert len(data["steps"]) == 2 and data["valid"]
    assert surfprep.read(out).shape.ShapeType().name == "TopAbs_SOLID"
    code, _, err = run(capsys, "split", files[0], files[1], "-o", tmp_path / "out.step", "--with", files[2])
    assert code != 0 and "--with needs --op" in err
