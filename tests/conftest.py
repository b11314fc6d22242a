"""Shared test fixtures: the real CAD files of the ``shared/data`` folder beside the repo,
and the hypothesis profile.

hypothesis is derandomized by default (profile ``ci``), so the README's test command,
which CI runs, is judged on the same examples every run; ``pytest
--hypothesis-profile=explore`` draws new examples each run, which is how new failures
get found (one that does is pinned as a plain test).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.paths import DATA_DIR
from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", deadline=None, print_blob=True)
settings.load_profile("ci")



@pytest.fixture(scope="session")
def data_dir() -> Path:
    if not DATA_DIR.is_dir():
        # The real CAD files are not part of the repository: they sit in ../shared/data
        # beside the checkout (CI has them). Without that folder only these tests are
        # left out; a file missing from a folder that is there is a failure, not a skip.
        pytest.skip(f"real-file test: CAD data folder {DATA_DIR} is not beside this checkout")
    return DATA_DIR
