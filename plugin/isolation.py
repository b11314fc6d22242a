"""OpenCascade work that may crash or hang, run in a child process.

OCCT's STEP and IGES readers can take the whole process down on a corrupt file
(a dangling ``#`` reference in a STEP ``VECTOR``, an IGES B-spline of degree -1:
SIGSEGV, no Python exception) or spin forever (a NaN or 1e308 coordinate).
:func:`call_isolated` runs a function in a child forked from this process (the
modules already imported come along: no second import of OCP, a few
milliseconds), with a time limit, and returns what the function returned
(pickled through a pipe). A crash becomes :class:`ChildCrashed` naming the
signal, a hang :class:`ChildTimedOut` after the child is killed; an exception
raised in the child is raised again here.

Where ``os.fork`` does not exist (Windows) the function runs in this process
(:data:`AVAILABLE` is False). The child never returns into the caller's code: it
leaves by ``os._exit``, so no ``atexit`` handler, buffered output or pytest hook
of the parent runs twice.
"""

from __future__ import annotations

import faulthandler
import os
import pickle
import select
import signal
import time
from collections.abc import Callable
from typing import Any

__all__ = ["AVAILABLE", "ChildCrashed", "ChildTimedOut", "call_isolated"]

#: True where a child can be forked (POSIX)
AVAILABLE = hasattr(os, "fork")
#: exit status of a child whose function raised (the exception is in the payload)
_RAISED = 3
_CHUNK = 1 << 16


class ChildCrashed(RuntimeError):
    """The child died without answering (killed by ``signal``, or exited with ``status``)."""

    def __init__(self, signal_name: str | None, status: int | None) -> None:
        self.signal_name, self.status = signal_name, status
        super().__init__(f"killed by {signal_name}" if signal_name else f"exit status {status}")


class ChildTimedOut(RuntimeError):
    """The child did not answer within ``timeout`` seconds and was killed."""

    def __init__(self, timeout: float) -> None:
        self.timeout = timeout
        super().__init__(f"no answer within {timeout:g} s")


def call_isolated(fn: Callable[..., Any], *args: Any, timeout: float) -> Any:
    """``fn(*args)`` in a forked child, within ``timeout`` seconds.

    Returns what ``fn`` returned (it must pickle); raises what ``fn`` raised,
    :class:`ChildCrashed` when the child died (a signal, or an exit without an
    answer) and :class:`ChildTimedOut` when it did not answer in time.
    """
    if not AVAILABLE:                      # pragma: no cover - POSIX in CI
        return fn(*args)
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:                           # pragma: no cover - the child (coverage ends here)
        os.close(read_end)
        faulthandler.disable()             # a crash here is the parent's to report, not ours
        status = 0
        try:
            payload = pickle.dumps(("ok", fn(*args)), protocol=pickle.HIGHEST_PROTOCOL)
        except BaseException as exc:       # noqa: BLE001 - everything goes back to the parent
            status = _RAISED
            try:
                payload = pickle.dumps(("raised", exc), protocol=pickle.HIGHEST_PROTOCOL)
            except Exception:              # an exception that does not pickle
                payload = pickle.dumps(("raised", RuntimeError(f"{type(exc).__name__}: {exc}")))
        try:
            view = memoryview(payload)
            while view:
                view = view[os.write(write_end, view):]
        finally:
            os._exit(status)
    os.close(write_end)
    try:
        data = _read_all(read_end, pid, timeout)
    finally:
        os.close(read_end)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        raise ChildCrashed(signal.Signals(os.WTERMSIG(status)).name, None)
    if not data:
        raise ChildCrashed(None, os.WEXITSTATUS(status))
    kind, value = pickle.loads(data)
    if kind == "raised":
        raise value
    return value


def _read_all(fd: int, pid: int, timeout: float) -> bytes:
    """Everything the child writes until it closes the pipe; kill it after ``timeout``."""
    chunks, deadline = [], time.monotonic() + timeout
    while True:
        left = deadline - time.monotonic()
        ready = select.select([fd], [], [], max(left, 0.0))[0] if left > 0 else []
        if not ready:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            raise ChildTimedOut(timeout)
        chunk = os.read(fd, _CHUNK)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)
