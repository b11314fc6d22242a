"""Shared test fixtures: the real CAD files of the ``shared/data`` folder beside the repo."""

from __future__ import annotations

from pathlib import Path

import pytest

#: ``shared/data`` next to the repository checkout (same layout locally and in CI).
DATA_DIR = Path(__file__).resolve().parents[1] / ".." / "shared" / "data"


@pytest.fixture(scope="session")
def data_dir() -> Path:
    if not DATA_DIR.is_dir():
        pytest.skip(f"CAD data folder not found: {DATA_DIR}")
    return DATA_DIR
