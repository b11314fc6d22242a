"""Shared test fixtures: the real CAD files of the ``shared/data`` folder beside the repo,
and the hypothesis profile.

Under CI (the ``CI`` environment variable set, as ``.ci/run`` runs) hypothesis is
derandomized, so a submission is judged on the same examples every run; locally
each run draws new examples, which is how new failures get found.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from helpers.paths import DATA_DIR
from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")



@pytest.fixture(scope="session")
def data_dir() -> Path:
    if not DATA_DIR.is_dir():
        # The real CAD files are not part of the repository: they sit in ../shared/data
        # beside the checkout (CI has them). Without that folder only these tests are
        # left out; a file missing from a folder that is there is a failure, not a skip.
        pytest.skip(f"real-file test: CAD data folder {DATA_DIR} is not beside this checkout")
    return DATA_DIR
