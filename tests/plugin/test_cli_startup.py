"""The command line starts without loading what it does not need.

``surfprep --help``, a subcommand's help and the one-line errors about files
(missing input, output folder missing) must not import OpenCascade, numba, scipy
or the geometry package: that is what makes them answer in a fraction of a
second. Each case runs in a fresh interpreter, as a user's shell would.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

SAMPLE = Path(__file__).resolve().parents[2] / "step_samples" / "occt_fuselage.stp"
#: modules whose import costs most of a second or more
HEAVY = ("OCP", "numba", "scipy", "surfprep.algorithms", "matplotlib", "h5py")

_PROBE = """
import contextlib, io, json, sys
from surfprep.plugin.cli import main
err = io.StringIO()
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
    code = main(sys.argv[1:])
print(json.dumps({"code": code, "err": err.getvalue(),
                  "loaded": [m for m in %r if m in sys.modules]}))
""" % (HEAVY,)


def _probe(*argv: str) -> dict:
    done = subprocess.run([sys.executable, "-c", _PROBE, *argv], capture_output=True,
                          text=True, timeout=120, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("argv", [
    ("--help",),
    ("info", "--help"),
    ("heal", "--help"),
    ("intersect", "--help"),
    ("grid", "--help"),
    ("batch", "--help"),
    ("--version",),
])
def test_help_loads_nothing_heavy(argv):
    result = _probe(*argv)
    assert result["code"] == 0
    assert result["loaded"] == []


@pytest.mark.parametrize("argv, words", [
    (("info", "/nonexistent/part.step"), "does not exist"),
    (("intersect", str(SAMPLE), "/nonexistent/b.step", "-o", "/tmp/never.step"), "does not exist"),
    (("heal", str(SAMPLE), "-o", "/nonexistent/out.step"), "does not exist"),
    (("reparam", str(SAMPLE), "-o", "out.txt"), "unknown extension"),
    (("info", str(SAMPLE), "--json", "/nonexistent/r.json"), "does not exist"),
])
def test_file_errors_come_before_opencascade(argv, words):
    result = _probe(*argv)
    assert result["code"] == 2
    lines = result["err"].strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("surfprep: error:") and words in lines[0]
    assert result["loaded"] == []


def test_a_real_run_still_loads_opencascade():
    """The probe sees imports: a command that does work loads OCP (the test can fail)."""
    result = _probe("info", str(SAMPLE), "--json", "-")
    assert result["code"] == 0
    assert "OCP" in result["loaded"]


def test_info_loads_neither_numba_nor_scipy():
    """``info`` describes every face (types, areas, the parametrization figure on a grid)
    with numpy alone: numba's import and context (half a second) and scipy's (0.3 s)
    are for the commands whose hot loops need them."""
    result = _probe("info", str(SAMPLE), "--json", "-")
    assert result["code"] == 0
    assert "surfprep.algorithms" in result["loaded"]
    assert "numba" not in result["loaded"] and "scipy" not in result["loaded"]
