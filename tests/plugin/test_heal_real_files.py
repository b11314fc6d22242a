"""surfprep.heal on a real file with faults (data_dir README): overture_marscapsule_proe.igs
holds every one of its 18 faces twice; the healed shape has each once, is valid, and the
approximants' joins are closed in the geometry."""

from __future__ import annotations

import pytest

import surfprep


@pytest.mark.slow
def test_marscapsule_duplicates_dropped(data_dir):
    path = data_dir / "overture_marscapsule_proe.igs"
    if not path.exists():
        pytest.skip("shared data not available")
    r = surfprep.heal(path)
    rep = r.report()
    assert rep["faces_in"] == 36
    assert len(r.dropped) == 18 and rep["faces_out"] == 18      # no doubled area
    assert r.valid_before and r.valid_after
    assert all(j.max_gap < 1e-9 for j in r.joins)
    assert all(p.max_error < 1e-2 * r.model.size for p in r.patches if p.converged)
