"""Work in a forked child: answers come back, exceptions are raised again, a crash or a
hang becomes an exception here, and the caller's process survives."""

from __future__ import annotations

import os
import signal
import time

import pytest

from surfprep.plugin.isolation import AVAILABLE, ChildCrashed, ChildTimedOut, call_isolated

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="no os.fork on this platform")


def _crash():
    os.kill(os.getpid(), signal.SIGSEGV)


def _sleep():
    time.sleep(30)


def _fail():
    raise ValueError("bad input in the child")


def test_the_answer_comes_back():
    assert call_isolated(pow, 2, 10, timeout=10) == 1024
    big = call_isolated(bytes, 3_000_000, timeout=10)          # more than a pipe holds
    assert len(big) == 3_000_000


def test_an_exception_is_raised_again():
    with pytest.raises(ValueError, match="bad input in the child"):
        call_isolated(_fail, timeout=10)


def test_a_crash_is_an_exception_and_this_process_lives_on():
    with pytest.raises(ChildCrashed) as caught:
        call_isolated(_crash, timeout=10)
    assert caught.value.signal_name == "SIGSEGV"
    assert call_isolated(abs, -3, timeout=10) == 3


def test_a_hang_is_stopped_at_the_time_limit():
    start = time.monotonic()
    with pytest.raises(ChildTimedOut):
        call_isolated(_sleep, timeout=0.5)
    assert time.monotonic() - start < 10


def test_an_exit_without_answer_is_a_crash():
    with pytest.raises(ChildCrashed, match="exit status 7"):
        call_isolated(os._exit, 7, timeout=10)
