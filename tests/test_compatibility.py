"""The versions surfprep states it supports are the ones installed and tested: the
README's compatibility table, pyproject.toml's pins and the environment agree."""

from __future__ import annotations

import re
import sys
import tomllib
from importlib.metadata import version
from pathlib import Path

import OCP
from packaging.specifiers import SpecifierSet
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[1]


def _requirements() -> dict[str, SpecifierSet]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    out = {}
    for line in project["dependencies"]:
        m = re.match(r"\s*([A-Za-z0-9_.-]+)(?:\[[^\]]*\])?\s*([^;#]*)", line)
        out[m.group(1).lower()] = SpecifierSet(m.group(2).strip())
    return out


def test_the_installed_set_is_the_pinned_set():
    """What CI installed satisfies every pin (so the suite tests the stated set)."""
    for name, spec in _requirements().items():
        assert Version(version(name)) in spec, f"{name} {version(name)} not in {spec}"
    assert Version(".".join(map(str, sys.version_info[:3]))) in SpecifierSet(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["requires-python"])


def test_the_readme_states_the_pins():
    """The README's compatibility table names each pinned range as pyproject.toml has it."""
    text = (ROOT / "README.md").read_text()
    table = text[text.index("## Compatibility"):]
    table = table[:table.index("\n## ", 3)]
    for name in ("cadquery", "build123d", "cadquery-ocp", "numpy", "scipy", "numba"):
        spec = str(_requirements()[name])
        assert f"`{name}`" in table and all(part in table for part in spec.split(",")), name
    assert OCP.__version__.startswith("7.9.3") and "7.9.3" in table
