"""The content of STEP and IGES files checked before OpenCascade sees it: dangling
references, non-finite and absurd numbers, IGES pointers past the end; no false alarm on
the bundled samples and the real files."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.paths import SAMPLES

import surfprep
from surfprep.errors import InputFileError
from surfprep.plugin.content_checks import content_problems

FUSELAGE = (SAMPLES / "occt_fuselage.stp").read_bytes()
CATIA = (SAMPLES / "occt_catia4_face_L1.igs").read_bytes()


def _point(value: bytes) -> bytes:
    return FUSELAGE.replace(b"#56=CARTESIAN_POINT('',(0.,", b"#56=CARTESIAN_POINT('',(" + value + b",", 1)


@pytest.mark.parametrize("value", [b"NaN", b"INF", b"-inf", b"1.E+308", b"-2.5E+200"])
def test_a_non_finite_or_absurd_coordinate_is_named(value):
    problems = content_problems(_point(value), "STEP")
    assert len(problems) == 1 and "#56 (CARTESIAN_POINT)" in problems[0]


def test_large_but_sane_numbers_pass():
    assert content_problems(_point(b"1.E+12"), "STEP") == []
    assert content_problems(_point(b"1.E-300"), "STEP") == []


def test_a_dangling_reference_is_named():
    broken = FUSELAGE.replace(b"#57,", b"#99999,", 1)
    (problem,) = content_problems(broken, "STEP")
    assert "#55 (B_SPLINE_SURFACE_WITH_KNOTS) refers to #99999" in problem


def test_a_reference_inside_a_string_is_not_one():
    named = FUSELAGE.replace(b"#56=CARTESIAN_POINT('',", b"#56=CARTESIAN_POINT('see #777; x',", 1)
    assert content_problems(named, "STEP") == []


def test_an_iges_pointer_past_the_end_is_named():
    lines = CATIA.split(b"\n")
    k = next(i for i, ln in enumerate(lines) if len(ln) > 72 and ln[72:73] == b"D")
    lines[k] = lines[k][:8] + b"   99999" + lines[k][16:]
    (problem,) = content_problems(b"\n".join(lines), "IGES")
    assert "directory entry 1 (type 144)" in problem and "99999" in problem


def test_an_iges_number_beyond_the_limit_is_named():
    lines = CATIA.split(b"\n")
    k = [i for i, ln in enumerate(lines) if len(ln) > 72 and ln[72:73] == b"P"][2]
    lines[k] = lines[k].replace(b"2.,2.,2.,", b"1.0D+300,", 1)   # same width
    (problem,) = content_problems(b"\n".join(lines), "IGES")
    assert problem.startswith("parameter line 3 holds the number 1.0D+300")


def test_read_refuses_such_a_file_with_one_message(tmp_path):
    path = tmp_path / "nan.stp"
    path.write_bytes(_point(b"NaN"))
    with pytest.raises(InputFileError, match=r"is corrupt: #56 \(CARTESIAN_POINT\) holds NaN"):
        surfprep.read(path)


@pytest.mark.parametrize("name", sorted(p.name for p in SAMPLES.iterdir()
                                        if p.suffix.lower() in (".stp", ".step", ".igs", ".iges")))
def test_no_false_alarm_on_the_samples(name):
    fmt = "STEP" if name.lower().endswith((".stp", ".step")) else "IGES"
    assert content_problems((SAMPLES / name).read_bytes(), fmt) == []


@pytest.mark.slow
def test_no_false_alarm_on_the_real_files(data_dir: Path):
    for path in sorted(data_dir.iterdir()):
        if path.suffix.lower() in (".stp", ".step", ".igs", ".iges"):
            fmt = "STEP" if path.suffix.lower() in (".stp", ".step") else "IGES"
            assert content_problems(path.read_bytes(), fmt) == [], path.name
