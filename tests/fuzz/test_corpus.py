"""A thousand and more corrupt STEP/IGES files through ``surfprep info FILE --json -``.

The corpus is made from the bundled samples by a seeded generator
(:mod:`helpers.mutations`: byte flips, chunks cut with the trailer kept, dangling
and self references, NaN/INF/1e308 coordinates, decreasing knots, bad degrees,
zero and negative weights, dropped pole rows, ragged nets, IGES pointers past the
end, bytes that are not UTF-8); nothing of it is stored. Every run must end as a
user can read: exit 0 with a report, exit 1 with the entities the reader left out
said on stderr and listed in the report, or exit 2 with one ``surfprep: error:``
line. Never a signal, a hang, a traceback, an internal error, or fewer faces than
the unmutated file without a word. Each file runs in a forked child (a user's
process), so a crash or a hang anywhere, not only in the reader, shows.

The outcome table of the README: ``python tests/helpers/mutations.py``.
"""

from __future__ import annotations

from collections import Counter

import pytest

from helpers.mutations import SOURCES, corpus, run_info, source_faces, warm_up

MUTANTS = corpus()
#: the corpus is run in this many parts (so pytest-xdist spreads them)
PARTS = 24


def test_the_corpus_is_large_and_varied():
    assert len(MUTANTS) >= 1000
    kinds = Counter(m.kind for m in MUTANTS)
    for kind in ("byte_flips", "chunk_cut", "dangling_or_wrong_ref", "self_reference",
                 "bad_coordinate", "decreasing_knots", "bad_degree", "bad_weight",
                 "dropped_pole_row", "ragged_net", "pointer_past_end", "non_utf8"):
        assert kinds[kind] >= 30, kind
    assert corpus()[17].data == MUTANTS[17].data          # seeded: the same files every run


@pytest.fixture(scope="module")
def faces_of_sources() -> dict[str, int]:
    warm_up()
    return {source: source_faces(source) for source in SOURCES}


@pytest.mark.slow
@pytest.mark.parametrize("part", range(PARTS))
def test_every_corrupt_file_ends_as_a_user_can_read(part, faces_of_sources, tmp_path):
    failures = []
    for mutant in MUTANTS[part::PARTS]:
        outcome = run_info(mutant, tmp_path, source_faces=faces_of_sources[mutant.source])
        if outcome.failed:
            failures.append(f"{mutant.name}: {outcome.kind} (exit {outcome.code}) "
                            f"{outcome.stderr.strip()[:200]}")
    assert not failures, f"{len(failures)} failure(s):\n" + "\n".join(failures)
