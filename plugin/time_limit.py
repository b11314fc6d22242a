"""A time limit per step of a command: :func:`step_time_limit`.

The verbs cannot be interrupted from inside (numpy and numba work in bulk, with
no place to poll a clock), so the command line raises
:class:`~surfprep.errors.TimeLimitExceeded` into the step that runs too long,
from a ``SIGALRM`` timer, and the verb records that step as stopped and goes on
(:func:`surfprep.plugin.intersect.intersect`). The timer is armed by the command
for the duration of the verb only and re-armed after each step (from the
progress callback); the previous handler is put back afterwards. The library
itself installs no signal handler.
"""

from __future__ import annotations

import argparse
import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ..errors import TimeLimitExceeded

__all__ = ["REPEAT_S", "seconds_argument", "step_time_limit"]

#: after the first alarm, again every this many seconds until the step gives up
#: (a step that caught the first one by accident is stopped by the next)
REPEAT_S = 1.0


def seconds_argument(text: str) -> float:
    """An argparse type for a time limit: a finite number of seconds >= 0 (0: none)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not (value >= 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a finite number of seconds >= 0, got {text}")
    return value


@contextmanager
def step_time_limit(seconds: float | None, what: str) -> Iterator[Callable[..., None]]:
    """Within the block each step of ``what`` may run ``seconds``; yields
    ``restart(last=False)``, to call when the steps begin and whenever one ends (the
    next one gets its full time), with ``last=True`` when the last one has ended (the
    timer stops: what the verb does after its steps is not a step). Nothing is timed
    before the first call: reading and converting the input are not a step.

    ``seconds`` None or 0, or a caller outside the main thread (signals go to the
    main thread only): no limit, ``restart`` does nothing.
    """
    if not seconds or threading.current_thread() is not threading.main_thread():
        yield lambda last=False: None
        return

    def expired(signum, frame) -> None:
        raise TimeLimitExceeded(f"{what} ran longer than {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expired)

    def restart(last: bool = False) -> None:
        if last:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
        else:
            signal.setitimer(signal.ITIMER_REAL, seconds, REPEAT_S)

    try:
        yield restart
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
