"""The command line's time limit per step (plugin.commands.time_limit)."""

from __future__ import annotations

import signal
import threading
import time

import pytest

from surfprep.errors import TimeLimitExceeded
from surfprep.plugin.time_limit import step_time_limit


def test_a_step_over_the_limit_is_interrupted_and_the_handler_put_back():
    before = signal.getsignal(signal.SIGALRM)
    with step_time_limit(0.2, "a step") as restart:
        time.sleep(0.4)                                   # not timed before the first restart
        restart()
        with pytest.raises(TimeLimitExceeded, match="a step ran longer than 0.2 s"):
            time.sleep(5)
        restart()
        time.sleep(0.05)                                  # a quick step is left alone
        restart()
    assert signal.getsignal(signal.SIGALRM) is before
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_after_the_last_step_nothing_is_timed():
    """What a verb does after its steps (building its result) is not a step."""
    with step_time_limit(0.1, "a step") as restart:
        restart()
        restart(last=True)
        assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
        time.sleep(0.3)                                   # no TimeLimitExceeded


@pytest.mark.parametrize("seconds", [None, 0])
def test_no_limit(seconds):
    with step_time_limit(seconds, "a step") as restart:
        restart()
        time.sleep(0.05)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_outside_the_main_thread_there_is_no_limit():
    """Signals reach the main thread only: a worker thread runs unlimited, not broken."""
    seen = []

    def worker():
        with step_time_limit(0.01, "a step") as restart:
            restart()
            time.sleep(0.05)
            seen.append(signal.getitimer(signal.ITIMER_REAL))

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join()
    assert seen == [(0.0, 0.0)]
