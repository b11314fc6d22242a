"""Folders of the repository the tests read from."""

from __future__ import annotations

from pathlib import Path

#: the repository checkout
REPO = Path(__file__).resolve().parents[2]
#: the bundled samples (``step_samples/``)
SAMPLES = REPO / "step_samples"
#: files the tests read (stored reports, faces that break OpenCascade)
TEST_DATA = REPO / "tests" / "data"
#: stored copies of the CLI's JSON reports (tests/plugin/commands/test_reports.py)
STORED_REPORTS = TEST_DATA / "reports"
#: ``shared/data`` next to the repository checkout (same layout locally and in CI): the
#: real CAD files, not part of the repository
DATA_DIR = REPO / ".." / "shared" / "data"
