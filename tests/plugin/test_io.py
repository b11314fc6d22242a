"""STEP/IGES reading and writing: round trips, names/colours, bad input, atomic writes."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import numpy as np
import pytest
from helpers.paths import SAMPLES
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepGProp import BRepGProp
from OCP.gp import gp_Pnt
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_VERTEX
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.errors import ConversionError, InputFileError, NoFacesError, OutputFileError, SurfprepError
from surfprep.plugin import io as sio
from surfprep.plugin.io import CadModel, FileFormat, read, write
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import area_and_centroid
from surfprep.plugin.step_iges import TranslationError

FUSELAGE = SAMPLES / "occt_fuselage.stp"
CAPSULE = SAMPLES / "overture_marscapsule_proe.igs"
CATIA_FACE = SAMPLES / "occt_catia4_face_L1.igs"
SYNTHETIC = SAMPLES / "synthetic_named_faces.step"

SYNTHETIC_NAMES = ("uniform_patch", "cubic_u_patch", "plane", "cylinder")


# ------------------------------------------------------------------ helpers
def area(shape_or_faces) -> float:
    faces = shape_or_faces if isinstance(shape_or_faces, (list, tuple)) else [shape_or_faces]
    total = 0.0
    for face in faces:
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        total += props.Mass()
    return total


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def wavy_patch(shift: float = 0.0) -> NurbsSurface:
    x, y = np.meshgrid(np.linspace(0, 4, 5), np.linspace(0, 3, 4), indexing="ij")
    z = 0.3 * np.sin(x) * np.cos(y)
    knots_u = [0, 0, 0, 0, 0.3, 1, 1, 1, 1]
    knots_v = [0, 0, 0, 1, 1.5, 1.5, 1.5]  # non-normalized domain on purpose
    return NurbsSurface(np.stack([x + shift, y, z], axis=-1), knots_u, knots_v, 3, 2)


def rational_patch() -> NurbsSurface:
    s2 = np.sqrt(0.5)
    arc = np.array([[1, 0], [1, 1], [0, 1]], float)
    cp = np.zeros((3, 2, 3))
    cp[:, :, :2] = arc[:, None, :]
    cp[:, 1, 2] = 2.0
    w = np.array([[1, 1], [s2, s2], [1, 1]])
    return NurbsSurface(cp, [0, 0, 0, 1, 1, 1], [0, 0, 1, 1], 2, 1, w)


def no_temp_files(directory: Path) -> bool:
    return not any(p.name.endswith(".tmp") or p.name.startswith(".") for p in directory.iterdir())


@pytest.fixture
def fuselage_copy(tmp_path) -> Path:
    target = tmp_path / "input" / FUSELAGE.name
    target.parent.mkdir()
    shutil.copyfile(FUSELAGE, target)
    return target


# ------------------------------------------------------------------ reading
@pytest.mark.parametrize("path, n_faces, unit, fmt", [
    (FUSELAGE, 8, "ft", FileFormat.STEP),
    (CAPSULE, 36, "mm", FileFormat.IGES),
    (CATIA_FACE, 1, "mm", FileFormat.IGES),
    (SYNTHETIC, 4, "mm", FileFormat.STEP),
])
def test_read_samples(path, n_faces, unit, fmt):
    model = read(path)
    assert isinstance(model, CadModel)
    assert model.n_faces == len(model.faces) == n_faces
    assert len(model.face_names) == len(model.face_colors) == n_faces
    assert model.length_unit == unit
    assert model.file_format is fmt
    assert model.path == path.resolve()
    assert isinstance(model.shape, TopoDS_Shape) and not model.shape.IsNull()
    x0, y0, z0, x1, y1, z1 = model.bounding_box
    assert x0 < x1 and y0 < y1 and z0 <= z1
    assert model.size == pytest.approx(np.linalg.norm([x1 - x0, y1 - y0, z1 - z0]))


def test_foot_file_is_scaled_to_millimetres():
    model = read(FUSELAGE)
    assert model.model_unit == "mm"
    assert 60_000 < model.size < 70_000  # ~208 ft long fuselage


def test_names_and_colours_from_xde():
    model = read(SYNTHETIC)
    assert model.face_names == SYNTHETIC_NAMES
    assert model.face_colors[0] == pytest.approx((0.8, 0.2, 0.2), abs=1e-6)
    one = read(CATIA_FACE)
    assert one.face_names == ("FAC418(1681)",)
    assert one.face_colors == ((0.0, 1.0, 0.0),)
    assert read(FUSELAGE).face_names == (None,) * 8


def test_extension_is_case_insensitive(tmp_path):
    upper = tmp_path / "PART.STP"
    shutil.copyfile(FUSELAGE, upper)
    assert read(upper).n_faces == 8
    iges = tmp_path / "face.IGES"
    shutil.copyfile(CATIA_FACE, iges)
    assert read(iges).file_format is FileFormat.IGES


def test_read_with_heal_keeps_faces_and_names():
    model = read(SYNTHETIC, heal=True)
    assert model.n_faces == 4
    assert model.face_names == SYNTHETIC_NAMES


def test_read_leaves_input_byte_identical(fuselage_copy):
    before = digest(fuselage_copy)
    model = read(fuselage_copy)
    write(model, fuselage_copy.with_name("out.step"))
    assert digest(fuselage_copy) == before


# ---------------------------------------------------------------- bad input
def _expect_input_error(path, error=InputFileError, *words):
    with pytest.raises(error) as info:
        read(path)
    message = str(info.value)
    assert "\n" not in message
    assert str(path) in message or Path(path).name in message
    for word in words:
        assert word in message, message
    return message


def test_missing_file(tmp_path):
    _expect_input_error(tmp_path / "nope.step", InputFileError, "does not exist")


def test_directory(tmp_path):
    d = tmp_path / "dir.step"
    d.mkdir()
    _expect_input_error(d, InputFileError, "directory")


def test_empty_file(tmp_path):
    empty = tmp_path / "empty.stp"
    empty.write_bytes(b"")
    _expect_input_error(empty, InputFileError, "empty")


def test_unknown_extension(tmp_path):
    other = tmp_path / "part.txt"
    shutil.copyfile(FUSELAGE, other)
    _expect_input_error(other, InputFileError, "unknown extension", ".step")


def test_step_file_named_igs(tmp_path):
    wrong = tmp_path / "part.igs"
    shutil.copyfile(FUSELAGE, wrong)
    _expect_input_error(wrong, InputFileError, "STEP", ".igs", "rename")


def test_iges_file_named_step(tmp_path):
    wrong = tmp_path / "face.step"
    shutil.copyfile(CATIA_FACE, wrong)
    _expect_input_error(wrong, InputFileError, "IGES", ".step")


def test_step_cut_in_half(tmp_path):
    half = tmp_path / "half.step"
    data = FUSELAGE.read_bytes()
    half.write_bytes(data[: len(data) // 2])
    _expect_input_error(half, InputFileError, "truncated")


def test_iges_cut_in_half(tmp_path):
    half = tmp_path / "half.igs"
    data = CATIA_FACE.read_bytes()
    half.write_bytes(data[: len(data) // 2])
    _expect_input_error(half, InputFileError, "truncated")


def test_step_cut_in_half_with_trailer_restored(tmp_path):
    # passes the cheap checks; OpenCascade reads no face from what is left
    cut = tmp_path / "cut.step"
    data = FUSELAGE.read_bytes()
    cut.write_bytes(data[: len(data) // 2] + b"\nENDSEC;\nEND-ISO-10303-21;\n")
    _expect_input_error(cut, InputFileError)


def test_random_bytes(tmp_path):
    junk = tmp_path / "junk.step"
    junk.write_bytes(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8).tobytes())
    _expect_input_error(junk, InputFileError, "not a STEP file")


def test_step_garbage_body(tmp_path, capfd):
    bad = tmp_path / "bad.step"
    bad.write_text("ISO-10303-21;\nHEADER;\nnot step at all;\nENDSEC;\nDATA;\n#1=FOO(;\n"
                   "ENDSEC;\nEND-ISO-10303-21;\n")
    _expect_input_error(bad, InputFileError, "cannot read")
    out, _ = capfd.readouterr()
    assert out == ""  # OCCT's parser messages do not reach stdout


def test_step_without_data(tmp_path):
    empty_data = tmp_path / "nodata.step"
    empty_data.write_text(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
        "FILE_NAME('a','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\n"
        "ENDSEC;\nDATA;\nENDSEC;\nEND-ISO-10303-21;\n")
    _expect_input_error(empty_data, InputFileError)


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_file_without_faces(tmp_path, suffix):
    curve = NurbsCurve(np.array([[0, 0, 0], [1, 1, 0], [2, 0, 0.0]]), [0, 0, 0, 1, 1, 1], 2)
    path = write(curve, tmp_path / f"curve{suffix}")
    message = _expect_input_error(path, NoFacesError, "no faces")
    assert "NoFaces" not in message


def test_every_read_error_is_a_surfprep_error(tmp_path):
    for content, name in [(b"", "a.step"), (b"hello", "b.step"), (b"hello", "c.igs"),
                          (FUSELAGE.read_bytes()[:100], "d.stp")]:
        path = tmp_path / name
        path.write_bytes(content)
        with pytest.raises(SurfprepError):
            read(path)


# ------------------------------------------------------------- round trips
@pytest.mark.parametrize("suffix", [".step", ".stp", ".igs", ".iges"])
def test_nurbs_surfaces_round_trip(tmp_path, suffix):
    surfaces = [wavy_patch(), wavy_patch(shift=6.0), rational_patch()]
    expected = area([make_face(s) for s in surfaces])
    path = write(surfaces, tmp_path / f"patches{suffix}")
    assert path == (tmp_path / f"patches{suffix}").resolve()
    model = read(path)
    assert model.n_faces == 3
    assert area(model.faces) == pytest.approx(expected, rel=1e-6)


def test_single_nurbs_surface_and_shapes(tmp_path):
    import build123d as bd
    import cadquery as cq

    assert read(write(wavy_patch(), tmp_path / "one.step")).n_faces == 1
    box = cq.Workplane().box(1, 2, 3)
    assert read(write(box, tmp_path / "wp.step")).n_faces == 6
    assert read(write(box.val(), tmp_path / "solid.igs")).n_faces == 6
    part = read(write(bd.Box(1, 2, 3), tmp_path / "bd.stp"))
    assert area(part.faces) == pytest.approx(22.0, rel=1e-9)
    mixed = [box.val().wrapped, make_face(wavy_patch(shift=5))]
    assert read(write(mixed, tmp_path / "mixed.step")).n_faces == 7


@pytest.mark.parametrize("sample", [FUSELAGE, CAPSULE, CATIA_FACE, SYNTHETIC],
                         ids=lambda p: p.name)
@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_samples_round_trip(tmp_path, sample, suffix):
    model = read(sample)
    again = read(write(model, tmp_path / f"copy{suffix}"))
    assert again.n_faces == model.n_faces
    # trimmed faces get their pcurves recomputed by the writer: areas agree closely
    assert area(again.faces) == pytest.approx(area(model.faces), rel=1e-4)
    assert again.size == pytest.approx(model.size, rel=1e-6)


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_names_and_colours_survive_write(tmp_path, suffix):
    model = read(SYNTHETIC)
    again = read(write(model, tmp_path / f"named{suffix}"))
    assert again.face_names == SYNTHETIC_NAMES
    for got, want in zip(again.face_colors, model.face_colors):
        assert got == pytest.approx(want, abs=1e-6)


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_lone_face_name_and_colour_survive_write(tmp_path, suffix):
    lone = read(CATIA_FACE)  # the file is one face, no shell or compound
    again = read(write(lone, tmp_path / f"face{suffix}"))
    assert again.face_names == ("FAC418(1681)",)
    assert again.face_colors == ((0.0, 1.0, 0.0),)


def test_in_memory_model_with_names(tmp_path):
    faces = (make_face(wavy_patch()), make_face(rational_patch()))
    model = CadModel(sio.to_shape(list(faces)), faces, ("a", None), (None, (1.0, 0.0, 0.0)))
    again = read(write(model, tmp_path / "m.step"))
    assert again.face_names == ("a", None)
    assert again.face_colors[1] == pytest.approx((1.0, 0.0, 0.0))


# ------------------------------------------------------ overwrite, atomicity
def test_refuses_to_overwrite_the_input_even_with_overwrite(fuselage_copy):
    model = read(fuselage_copy)
    before = digest(fuselage_copy)
    for target in (fuselage_copy, fuselage_copy.parent / ".." / "input" / fuselage_copy.name):
        with pytest.raises(OutputFileError, match="input file"):
            write(model, target, overwrite=True)
    assert digest(fuselage_copy) == before
    assert no_temp_files(fuselage_copy.parent)


def test_refuses_input_through_a_symlink(fuselage_copy):
    link = fuselage_copy.parent / "link.step"
    link.symlink_to(fuselage_copy)
    with pytest.raises(OutputFileError, match="input file"):
        write(read(fuselage_copy), link, overwrite=True)


def test_existing_output_needs_overwrite(tmp_path):
    target = tmp_path / "out.step"
    target.write_text("keep me")
    with pytest.raises(OutputFileError, match="already exists"):
        write(wavy_patch(), target)
    assert target.read_text() == "keep me"
    write(wavy_patch(), target, overwrite=True)
    assert read(target).n_faces == 1
    assert no_temp_files(tmp_path)


def test_successful_write_leaves_only_the_target(tmp_path):
    write(read(CAPSULE), tmp_path / "capsule.step")
    assert [p.name for p in tmp_path.iterdir()] == ["capsule.step"]
    assert (tmp_path / "capsule.step").stat().st_mode & 0o044  # not owner-only


def test_a_staged_file_appears_only_when_committed(tmp_path):
    target = tmp_path / "staged.step"
    with sio.staged_write(wavy_patch(), target) as staged:
        assert not target.exists()
        assert [p.parent for p in tmp_path.iterdir()] == [tmp_path]    # the temporary
        assert staged.target == target.resolve()
    assert list(tmp_path.iterdir()) == []                  # left without commit: gone
    with sio.staged_write(wavy_patch(), target) as staged:
        assert staged.commit() == target.resolve()
    assert [p.name for p in tmp_path.iterdir()] == ["staged.step"]
    assert read(target).n_faces == 1


def test_a_failure_between_staging_and_commit_leaves_nothing(tmp_path):
    target = tmp_path / "staged.step"
    with pytest.raises(RuntimeError, match="report failed"), \
            sio.staged_write(wavy_patch(), target):
        raise RuntimeError("report failed")
    assert list(tmp_path.iterdir()) == []


def test_failed_writer_leaves_no_temp_file_and_keeps_old_target(tmp_path, monkeypatch):
    target = tmp_path / "out.step"
    target.write_text("previous content")

    def failing_writer(path, *args, **kwargs):
        Path(path).write_text("half a file")
        raise TranslationError("simulated writer failure")

    monkeypatch.setattr(sio, "write_file", failing_writer)
    with pytest.raises(OutputFileError, match="simulated writer failure"):
        write(wavy_patch(), target, overwrite=True)
    assert target.read_text() == "previous content"
    assert [p.name for p in tmp_path.iterdir()] == ["out.step"]


def test_writer_producing_nothing_is_an_error(tmp_path, monkeypatch):
    monkeypatch.setattr(sio, "write_file", lambda *a, **k: None)
    with pytest.raises(OutputFileError, match="wrote nothing"):
        write(wavy_patch(), tmp_path / "out.igs")
    assert list(tmp_path.iterdir()) == []


def test_output_errors(tmp_path):
    with pytest.raises(OutputFileError, match="unknown extension"):
        write(wavy_patch(), tmp_path / "out.obj")
    with pytest.raises(OutputFileError, match="does not exist"):
        write(wavy_patch(), tmp_path / "missing" / "out.step")
    (tmp_path / "d.step").mkdir()
    with pytest.raises(OutputFileError, match="directory"):
        write(wavy_patch(), tmp_path / "d.step")


def test_unwritable_directory():
    # /proc refuses new files even to root (a chmod-ed folder would not stop root)
    with pytest.raises(OutputFileError, match="cannot create a file in /proc"):
        write(wavy_patch(), "/proc/surfprep-out.step")


def test_unsupported_objects(tmp_path):
    for bad in (42, "surface", [], [wavy_patch(), object()], TopoDS_Shape()):
        with pytest.raises(ConversionError):
            write(bad, tmp_path / "x.step")
    assert list(tmp_path.iterdir()) == []


def test_file_format_from_suffix():
    assert FileFormat.from_suffix("a.STEP") is FileFormat.STEP
    assert FileFormat.from_suffix("a.Stp") is FileFormat.STEP
    assert FileFormat.from_suffix(Path("x/y.IgS")) is FileFormat.IGES
    assert FileFormat.from_suffix("a.iges") is FileFormat.IGES
    assert FileFormat.from_suffix("a.brep") is None
    assert FileFormat.from_suffix("step") is None


def test_sniff_format():
    assert sio.sniff_format(FUSELAGE.read_bytes()[:4096]) is FileFormat.STEP
    assert sio.sniff_format(CAPSULE.read_bytes()[:4096]) is FileFormat.IGES
    assert sio.sniff_format(b"\x00\x01binary") is None
    assert sio.sniff_format(b"solid ascii stl") is None


# ------------------------------------------------------- real files (slow)
# face counts from /work/shared/data/README.md
REAL_FILES = {
    "nist_ctc_02_rc.stp": 664, "occt_b1_euclid.stp": 415, "occt_cornetta.stp": 110,
    "occt_k1_alias.stp": 57, "occt_k1_catia_debis.stp": 58, "occt_k1_catia_theorem.stp": 59,
    "occt_k1geo_autocad.stp": 60, "occt_k1geo_microstation.stp": 39, "occt_s1_ideas.stp": 134,
    "occt_spaceship_alias.stp": 94, "occt_t4m_euclid.stp": 12, "occt_turbine_euclid.stp": 53,
    "pyocc_ventilator_catia5.stp": 305, "occt_bearing_euclid.iges": 213,
    "occt_deflettore_solidedge.igs": 18, "occt_hammer_euclid.iges": 45,
    "overture_asmo_icem.igs": 255, "overture_heartvalve_rhino.igs": 17,
    "overture_kcs_hull_ideas.igs": 18, "overture_ship_napa_part5.igs": 215,
    "pyiges_impeller_solidworks.igs": 277,
}


@pytest.mark.slow
@pytest.mark.parametrize("name, n_faces", sorted(REAL_FILES.items()))
def test_real_files_read_with_catalogue_face_counts(name, n_faces, data_dir):
    path = data_dir / name
    model = read(path)
    assert model.n_faces == n_faces
    assert model.size > 0


@pytest.mark.slow
@pytest.mark.parametrize("name", ["occt_k1_catia_debis.stp", "occt_s1_ideas.stp",
                                  "pyocc_ventilator_catia5.stp"])
def test_real_step_face_names_survive_step_round_trip(tmp_path, name, data_dir):
    path = data_dir / name
    model = read(path)
    assert all(n is not None for n in model.face_names)
    again = read(write(model, tmp_path / "copy.step"))
    assert again.face_names == model.face_names
    assert area(again.faces) == pytest.approx(area(model.faces), rel=1e-4)


# ------------------------------------------------------ fallback and OCCT state
def test_plain_reader_fallback_when_xde_fails(monkeypatch):
    from surfprep.plugin import step_iges

    def broken_xde(path, fmt):
        raise TranslationError("simulated XDE failure")

    monkeypatch.setattr(step_iges, "_read_xde", broken_xde)
    model = read(SYNTHETIC)
    assert model.n_faces == 4
    assert model.face_names == (None,) * 4  # names need XDE
    assert model.length_unit == "mm"


def test_occt_static_parameters_are_restored(tmp_path):
    from OCP.Interface import Interface_Static

    read(SYNTHETIC, isolate=False)  # makes sure the STEP controller (and its parameters) exist here
    for key in ("read.stepcaf.subshapes.name", "write.stepcaf.subshapes.name"):
        assert Interface_Static.IsPresent_s(key)
    before = {k: Interface_Static.IVal_s(k)
              for k in ("read.stepcaf.subshapes.name", "write.stepcaf.subshapes.name")}
    write(read(SYNTHETIC), tmp_path / "again.step")
    after = {k: Interface_Static.IVal_s(k) for k in before}
    assert after == before


def test_a_copied_model_has_its_own_faces_in_the_same_order_names_kept():
    model = read(SYNTHETIC)
    copy = model.copy()
    assert copy.face_names == model.face_names and copy.n_faces == model.n_faces
    for f, g in zip(model.faces, copy.faces, strict=True):
        assert not f.IsSame(g) and f.Orientation() == g.Orientation()
        (a, c), (b, d) = area_and_centroid(f), area_and_centroid(g)
        assert b == pytest.approx(a, rel=1e-12) and d == pytest.approx(c, abs=1e-9)
    # a vertex of the copy moved in place leaves the model's where it was
    def first_vertex(face):
        return TopoDS.Vertex_s(TopExp_Explorer(face, TopAbs_VERTEX).Current())

    BRep_Builder().UpdateVertex(first_vertex(copy.faces[0]), gp_Pnt(1e3, 1e3, 1e3), 1e-7)
    assert BRep_Tool.Pnt_s(first_vertex(copy.faces[0])).X() == 1e3
    assert BRep_Tool.Pnt_s(first_vertex(model.faces[0])).X() < 100
