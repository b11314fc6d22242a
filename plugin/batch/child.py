"""One child process: started through the launcher (:func:`measured_argv`) in a new
session, polled, killed with its process group past its deadline, reaped, and its
exit classified from its exit code, its log and its report (:class:`RunningChild`).
"""

from __future__ import annotations

import io
import json
import math
import os
import resource
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .records import (
    STATUS_ERROR,
    STATUS_FACES_SKIPPED,
    STATUS_MEMORY,
    STATUS_OK,
    STATUS_TIMEOUT,
    ChildLimits,
    FileJob,
    FileRecord,
    crashed_status,
    not_started,
)

__all__ = [
    "MEMORY_MARKERS",
    "RunningChild",
    "is_number",
    "measured_argv",
    "peak_file",
    "read_json",
]

#: what a child that ran out of memory leaves in its output
MEMORY_MARKERS = ("MemoryError", "bad_alloc", "Standard_OutOfMemory", "Unable to allocate",
                  "Cannot allocate memory", "out of memory")
#: an ended child can be seen without reaping it (Linux; macOS from Python 3.13)
_CAN_PEEK = hasattr(os, "waitid") and hasattr(os, "WNOWAIT")
_LOG_TAIL_BYTES = 1 << 16
_ERROR_PREFIX = "surfprep: error:"
_INTERNAL_PREFIX = "surfprep: internal error:"
_WARNING_PREFIX = "surfprep: warning:"


class RunningChild:
    """A started child: its process, start time and deadline; :meth:`poll` reaps it."""

    __slots__ = ("job", "limits", "log_stream", "process", "reaped", "started")

    def __init__(self, job: FileJob, process: subprocess.Popen[bytes], limits: ChildLimits,
                 started: float, log_stream: io.BufferedWriter) -> None:
        self.job, self.process, self.limits = job, process, limits
        self.started, self.log_stream = started, log_stream
        #: ``os.wait4``'s answer where the exit cannot be seen without reaping (no waitid)
        self.reaped: tuple[int, int, resource.struct_rusage] | None = None

    @classmethod
    def start(cls, job: FileJob, *, command: Sequence[str] | None,
              limits: ChildLimits) -> RunningChild | FileRecord:
        """Start ``job``'s child (stale outputs of an earlier run removed first); the
        error record when it cannot be started."""
        for stale in (*job.outputs, job.report):
            stale.unlink(missing_ok=True)
        peak = peak_file(job)
        peak.unlink(missing_ok=True)
        argv = measured_argv(job.argv(command), peak_file=peak, memory_bytes=limits.memory_bytes)
        try:
            log_stream = open(job.log, "wb")  # noqa: SIM115 - closed when the child is reaped
        except OSError as exc:
            return not_started(job, f"cannot write {job.log}: {exc.strerror or exc}")
        started = time.monotonic()
        try:
            process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log_stream,
                                       stderr=subprocess.STDOUT, start_new_session=True)
        except OSError as exc:
            log_stream.close()
            return not_started(job, f"cannot start the child: {exc.strerror or exc}")
        return cls(job, process, limits, started, log_stream)

    def poll(self) -> FileRecord | None:
        """The child's record once it has ended (killed first when past its deadline),
        None while it runs."""
        pid = self.process.pid
        if _CAN_PEEK:
            exited = _has_exited(pid)
        else:                                    # pragma: no cover - macOS before 3.13
            answer = os.wait4(pid, os.WNOHANG)
            self.reaped = answer if answer[0] == pid else None
            exited = self.reaped is not None
        timed_out = (not exited and self.limits.timeout_s is not None
                     and time.monotonic() - self.started > self.limits.timeout_s)
        if not (exited or timed_out):
            return None
        _kill_group(pid)          # the child's leftovers (or, on timeout, the child itself)
        return self._reap(timed_out=timed_out)

    def kill(self) -> None:
        """Kill the child's process group now and reap it (an interrupted batch)."""
        _kill_group(self.process.pid)
        self._reap(timed_out=False)

    def _reap(self, *, timed_out: bool) -> FileRecord:
        try:
            _, wait_status, usage = self.reaped or os.wait4(self.process.pid, 0)
        except ChildProcessError:            # reaped by someone else in this process
            self.log_stream.close()
            return not_started(self.job, "the child's exit status was lost (reaped elsewhere)")
        seconds = time.monotonic() - self.started
        self.process.returncode = os.waitstatus_to_exitcode(wait_status)   # Popen must not wait
        self.log_stream.close()
        peak = peak_file(self.job)
        try:                     # the command's own peak, measured by the launcher
            peak_mb = _peak_mb(int(peak.read_text()))
        except (OSError, ValueError):                   # killed before it could say
            peak_mb = _peak_mb(usage.ru_maxrss)
        peak.unlink(missing_ok=True)
        return _record(self.job, exit_code=self.process.returncode, timed_out=timed_out,
                       seconds=seconds, peak_memory_mb=peak_mb, limits=self.limits)


#: the launcher: a small interpreter that forks the command (with the address-space limit
#: set in the fork), waits for it, writes its ``ru_maxrss`` and ends as it ended
_LAUNCHER = """\
import os, resource, signal, sys
limit, peak, argv = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
pid = os.fork()
if pid == 0:
    if limit > 0:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    os.execvp(argv[0], argv)
_, status, usage = os.wait4(pid, 0)
with open(peak, "w") as f:
    f.write(str(usage.ru_maxrss))
code = os.waitstatus_to_exitcode(status)
if code < 0:
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    signal.signal(-code, signal.SIG_DFL)
    os.kill(os.getpid(), -code)
sys.exit(code)
"""


def peak_file(job: FileJob) -> Path:
    """Where the launcher writes ``job``'s peak memory (beside its log; removed when read)."""
    return job.log.with_name(job.log.name.removesuffix(".log") + ".peak")


def measured_argv(argv: Sequence[str], *, peak_file: Path, memory_bytes: int | None) -> list[str]:
    """``argv`` run by the launcher: at most ``memory_bytes`` of address space, and its peak
    resident memory written to ``peak_file``.

    The peak of a process forked from this one would start at this process's size
    (``ru_maxrss`` spans the ``exec``, and a ``vfork`` or ``posix_spawn`` child borrows
    this process's memory until it), so a batch run from a large process (a test
    worker, a Dask worker) would report its own size for every small file; forked from
    the launcher, the command's peak starts at a bare interpreter's.
    """
    return [sys.executable, "-c", _LAUNCHER, str(int(memory_bytes or 0)), str(peak_file), *argv]


def _has_exited(pid: int) -> bool:
    """True once ``pid`` has ended; it stays a zombie (not reaped), so its process group id
    cannot be reused before the group is killed."""
    try:
        return os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None
    except ChildProcessError:
        return True


def _kill_group(pid: int) -> None:
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _peak_mb(maxrss: int) -> float:
    """``ru_maxrss`` in MiB (kilobytes on Linux, bytes on macOS)."""
    scale = 1 << 20 if sys.platform == "darwin" else 1 << 10
    return round(maxrss / scale, 1)


def _record(job: FileJob, *, exit_code: int, timed_out: bool, seconds: float,
            peak_memory_mb: float, limits: ChildLimits) -> FileRecord:
    """Classify a reaped child from its exit code, its log and its report."""
    data = read_json(job.report)
    report = str(job.report) if isinstance(data, dict) else None
    figures = {k: v for k, v in data.items() if is_number(v)} if report else {}
    status, message = _classify(exit_code, _log_tail(job.log), timed_out=timed_out,
                                limits=limits, reported=report is not None)
    return FileRecord(file=str(job.source), label=job.label, verb=job.verb, status=status,
                      exit_code=exit_code, message=message, seconds=round(seconds, 3),
                      peak_memory_mb=peak_memory_mb,
                      outputs=tuple(str(p) for p in job.outputs if p.is_file()),
                      report=report, log=str(job.log), figures=figures)


def _classify(exit_code: int, lines: list[str], *, timed_out: bool, limits: ChildLimits,
              reported: bool) -> tuple[str, str]:
    """(status, message) of a child that ended with ``exit_code`` (``-N``: signal N), from
    the end of its output ``lines``; ``reported``: it wrote its JSON report."""
    if timed_out:
        return STATUS_TIMEOUT, f"killed after {limits.timeout_s:g} s"
    if exit_code == 0:
        return STATUS_OK, ""
    memory_line = next((line for line in reversed(lines)
                        if any(marker in line for marker in MEMORY_MARKERS)), None)
    if memory_line is not None:
        for prefix in (_ERROR_PREFIX, _INTERNAL_PREFIX):
            memory_line = memory_line.removeprefix(prefix).strip()
        return STATUS_MEMORY, memory_line
    last = lines[-1] if lines else ""
    if exit_code < 0:
        number = -exit_code
        if number == signal.SIGABRT and limits.memory_bytes is not None:
            return STATUS_MEMORY, f"aborted under the memory limit: {last}".rstrip(": ")
        return crashed_status(number), f"killed by {_signal_name(number)}"
    if exit_code == 1:
        internal = _last_with(lines, _INTERNAL_PREFIX)
        if internal is not None:
            return STATUS_ERROR, internal
        if not reported:                     # a traceback before the command ran, a lost report
            return STATUS_ERROR, f"exit status 1 without a report: {last}".rstrip(": ")
        return STATUS_FACES_SKIPPED, _last_with(lines, _WARNING_PREFIX) or ""
    if exit_code == 2:
        return STATUS_ERROR, _last_with(lines, _ERROR_PREFIX) or last
    return STATUS_ERROR, f"exit status {exit_code}" + (f": {last}" if last else "")


def _last_with(lines: list[str], prefix: str) -> str | None:
    """The last line starting with ``prefix``, without it."""
    for line in reversed(lines):
        if line.startswith(prefix):
            return line[len(prefix):].strip()
    return None


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def _log_tail(path: Path) -> list[str]:
    """The non-empty lines of the end of a child's log."""
    try:
        with open(path, "rb") as stream:
            stream.seek(max(0, os.fstat(stream.fileno()).st_size - _LOG_TAIL_BYTES))
            text = stream.read().decode("utf-8", errors="replace")
    except OSError:
        return []
    return [line.strip() for line in text.splitlines() if line.strip()]


def read_json(path: Path) -> Any:
    """The JSON in ``path``; None when it is missing or not valid JSON."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def is_number(value: Any) -> bool:
    """True for a finite int or float (not a bool): a report field kept as a figure."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)
