"""The public facade: every advertised name resolves, and numpy-only use does not load OCP."""

from __future__ import annotations

import subprocess
import sys

import surfprep


def test_every_public_name_resolves():
    for name in surfprep.__all__:
        assert getattr(surfprep, name) is not None, name
    assert set(surfprep.__all__) <= set(dir(surfprep))


def test_unknown_name_raises_attribute_error():
    try:
        surfprep.no_such_thing  # noqa: B018
    except AttributeError as exc:
        assert "no_such_thing" in str(exc)
    else:
        raise AssertionError("unknown attribute did not raise")


def test_numpy_only_import_does_not_load_opencascade():
    code = ("import sys, surfprep; s = surfprep.NurbsCurve([[0, 0], [1, 1]], [0, 0, 1, 1], 1);"
            "s.evaluate(0.5); print('OCP' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_errors_derive_from_builtin_types():
    assert issubclass(surfprep.InputFileError, OSError)
    assert issubclass(surfprep.InvalidGeometryError, ValueError)
    assert issubclass(surfprep.ConversionError, TypeError)
    assert issubclass(surfprep.NoFacesError, surfprep.InputFileError)
    for name in ("InvalidGeometryError", "InputFileError", "OpenCascadeError", "OutputFileError"):
        assert issubclass(getattr(surfprep, name), surfprep.SurfprepError)
