"""Many files through one ``surfprep`` command: ``surfprep batch``.

Each file runs as one child process ``python -m surfprep.plugin VERB FILE -o OUT
--json REPORT ...`` (:class:`FileJob`), in a new session so that a timeout kills
the child with everything it started (:func:`os.killpg`). A child that crashes,
hangs or runs out of memory becomes one :class:`FileRecord` with that status; the
other files go on. The children run in a local pool (:func:`run_local`: at most
``jobs`` at a time, each seen to end by polling its pid and reaped with
:func:`os.wait4`, which gives the child's own peak memory) or as one task per file on a Dask cluster
(:func:`run_dask`; the task, :func:`run_file_task`, runs the same child on the
worker and returns a plain dict).

After every finished file ``OUTDIR/summary.json`` and ``OUTDIR/summary.csv`` are
rewritten atomically (:func:`write_summary`), so an interrupted batch leaves a
valid summary, and ``resume=True`` skips what an earlier run finished.

This module imports only the standard library (Dask on the Dask path only), so
that the command line starts fast and a Dask worker needs nothing else to run a
task.
"""

from __future__ import annotations

import csv
import glob
import io
import json
import math
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
import uuid
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..errors import InputFileError, OutputFileError, SurfprepError

__all__ = [
    "DEFAULT_TIMEOUT_S",
    "FAILED_STATUSES",
    "STATUS_DONE_BEFORE",
    "STATUS_ERROR",
    "STATUS_FACES_SKIPPED",
    "STATUS_MEMORY",
    "STATUS_OK",
    "STATUS_PENDING",
    "STATUS_TIMEOUT",
    "SUCCESS_STATUSES",
    "SUMMARY_CSV",
    "SUMMARY_JSON",
    "VERB_OUTPUTS",
    "BatchResult",
    "ChildLimits",
    "FileJob",
    "FileRecord",
    "check_passthrough",
    "crashed_status",
    "default_command",
    "default_jobs",
    "expand_inputs",
    "is_failed",
    "load_previous_summary",
    "measured_argv",
    "parse_memory_size",
    "peak_file",
    "plan_jobs",
    "prepare_outdir",
    "run_batch",
    "run_dask",
    "run_file_task",
    "run_local",
    "verb_is_available",
    "write_summary",
]

#: seconds a child may run before it is killed (``--timeout``)
DEFAULT_TIMEOUT_S = 600.0
#: per verb, the suffix of its model/grid output in OUTDIR (None: the JSON report only)
VERB_OUTPUTS: Mapping[str, str | None] = {
    "info": None,
    "heal": ".heal.step",
    "reparam": ".reparam.step",
    "intersect": ".intersect.step",
    "split": ".split.step",
    "prepare": ".prepare.step",
    "grid": ".cgns",
}
SUMMARY_JSON = "summary.json"
SUMMARY_CSV = "summary.csv"

STATUS_OK = "ok"
STATUS_FACES_SKIPPED = "ok (faces skipped)"
STATUS_ERROR = "error"
STATUS_TIMEOUT = "timeout"
STATUS_MEMORY = "memory"
STATUS_DONE_BEFORE = "skipped (done)"
STATUS_PENDING = "pending"
#: statuses of a file whose work is done (the batch exits 0 when every file has one)
SUCCESS_STATUSES = frozenset({STATUS_OK, STATUS_FACES_SKIPPED, STATUS_DONE_BEFORE})
#: statuses of a file whose work failed (``crashed (signal N)`` too: see :func:`is_failed`)
FAILED_STATUSES = frozenset({STATUS_ERROR, STATUS_TIMEOUT, STATUS_MEMORY})

#: options of the per-file command that the batch sets itself (refused after ``--``)
RESERVED_OPTIONS = ("--output", "--json", "--plot")
#: what a child that ran out of memory leaves in its output
MEMORY_MARKERS = ("MemoryError", "bad_alloc", "Standard_OutOfMemory", "Unable to allocate",
                  "Cannot allocate memory", "out of memory")
_UNITS = {"": 1, "B": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}
_POLL_S = 0.05
#: an ended child can be seen without reaping it (Linux; macOS from Python 3.13)
_CAN_PEEK = hasattr(os, "waitid") and hasattr(os, "WNOWAIT")
_LOG_TAIL_BYTES = 1 << 16
_ERROR_PREFIX = "surfprep: error:"
_INTERNAL_PREFIX = "surfprep: internal error:"
_WARNING_PREFIX = "surfprep: warning:"


# ----------------------------------------------------------------- records
@dataclass(frozen=True)
class ChildLimits:
    """What one child may use.

    Attributes
    ----------
    timeout_s : float or None
        Wall-clock seconds before the child's process group is killed; None: no limit.
    memory_bytes : int or None
        Address-space limit (``RLIMIT_AS``) set in the child before it starts; None: none.
    """

    timeout_s: float | None = DEFAULT_TIMEOUT_S
    memory_bytes: int | None = None


@dataclass(frozen=True)
class FileJob:
    """One input file of a batch and the paths its child writes.

    Attributes
    ----------
    source : Path
        The input file (absolute).
    label : str
        The file as shown in progress lines and tables (relative to the inputs' common folder).
    name : str
        Base name of the file's outputs in OUTDIR, unique in the batch
        (``sub__part`` for ``sub/part.step``).
    verb : str
        The ``surfprep`` command run on it.
    report : Path
        The child's JSON report, ``OUTDIR/<name>.<verb>.json``.
    log : Path
        The child's standard output and error, ``OUTDIR/<name>.<verb>.log``.
    outputs : tuple of Path
        The model or grid files the child writes (empty for ``info``).
    arguments : tuple of str
        The child's arguments after the command (verb, file, outputs, options).
    """

    source: Path
    label: str
    name: str
    verb: str
    report: Path
    log: Path
    outputs: tuple[Path, ...]
    arguments: tuple[str, ...]

    def argv(self, command: Sequence[str] | None = None) -> list[str]:
        """The child's full command line: ``command`` (default :func:`default_command`)
        followed by :attr:`arguments`."""
        return [*(default_command() if command is None else command), *self.arguments]

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON types (for a Dask task)."""
        return {"source": str(self.source), "label": self.label, "name": self.name,
                "verb": self.verb, "report": str(self.report), "log": str(self.log),
                "outputs": [str(p) for p in self.outputs], "arguments": list(self.arguments)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> FileJob:
        """The job :meth:`as_dict` described."""
        return cls(source=Path(data["source"]), label=data["label"], name=data["name"],
                   verb=data["verb"], report=Path(data["report"]), log=Path(data["log"]),
                   outputs=tuple(Path(p) for p in data["outputs"]),
                   arguments=tuple(data["arguments"]))


@dataclass(frozen=True)
class FileRecord:
    """What became of one file: a row of ``summary.json`` / ``summary.csv``.

    Attributes
    ----------
    file : str
        The input file (absolute path).
    label : str
        The file as shown (relative to the inputs' common folder).
    verb : str
        The command run on it.
    status : str
        ``ok``, ``ok (faces skipped)``, ``error``, ``timeout``, ``memory``,
        ``crashed (signal N)``, ``skipped (done)`` or ``pending`` (not finished yet).
    exit_code : int or None
        The child's exit status (``-N`` when killed by signal N); None when it did not run.
    message : str
        Why it failed (the child's ``surfprep: error:`` line...), or a warning; may be empty.
    seconds : float or None
        Wall-clock time of the child.
    peak_memory_mb : float or None
        The child's peak resident memory (``ru_maxrss`` from :func:`os.wait4`), MiB.
    outputs : tuple of str
        The model or grid files it wrote.
    report : str or None
        Its JSON report, when it wrote a valid one.
    log : str or None
        Its standard output and error.
    figures : Mapping[str, float]
        The top-level numeric fields of its report (``n_faces``, ``size``... for ``info``).
    """

    file: str
    label: str
    verb: str
    status: str
    exit_code: int | None = None
    message: str = ""
    seconds: float | None = None
    peak_memory_mb: float | None = None
    outputs: tuple[str, ...] = ()
    report: str | None = None
    log: str | None = None
    figures: Mapping[str, float] = field(default_factory=dict)

    @property
    def succeeded(self) -> bool:
        """True when the file's work is done (:data:`SUCCESS_STATUSES`)."""
        return self.status in SUCCESS_STATUSES

    @property
    def failed(self) -> bool:
        """True when the file's work failed (error, timeout, memory, crash)."""
        return is_failed(self.status)

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON types, in the order of the summary's columns."""
        return {"file": self.file, "label": self.label, "verb": self.verb, "status": self.status,
                "exit_code": self.exit_code, "message": self.message, "seconds": self.seconds,
                "peak_memory_mb": self.peak_memory_mb, "outputs": list(self.outputs),
                "report": self.report, "log": self.log, "figures": dict(self.figures)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> FileRecord:
        """The record :meth:`as_dict` described."""
        return cls(file=data["file"], label=data.get("label", Path(data["file"]).name),
                   verb=data.get("verb", ""), status=data["status"],
                   exit_code=data.get("exit_code"), message=data.get("message") or "",
                   seconds=data.get("seconds"), peak_memory_mb=data.get("peak_memory_mb"),
                   outputs=tuple(data.get("outputs") or ()), report=data.get("report"),
                   log=data.get("log"), figures=dict(data.get("figures") or {}))


@dataclass(frozen=True)
class BatchResult:
    """A finished batch.

    Attributes
    ----------
    verb : str
        The command run on every file.
    outdir : Path
        Where the outputs and the summary are.
    records : tuple of FileRecord
        One per input file, in input order.
    seconds : float
        Wall-clock time of the whole batch.
    scheduler : str
        ``local`` or the Dask scheduler's address.
    """

    verb: str
    outdir: Path
    records: tuple[FileRecord, ...]
    seconds: float
    scheduler: str = "local"

    @property
    def summary_json(self) -> Path:
        """``OUTDIR/summary.json``."""
        return self.outdir / SUMMARY_JSON

    @property
    def summary_csv(self) -> Path:
        """``OUTDIR/summary.csv``."""
        return self.outdir / SUMMARY_CSV

    @property
    def exit_code(self) -> int:
        """0 when every file's work is done, 1 when some failed (the batch itself finished)."""
        return 0 if all(r.succeeded for r in self.records) else 1

    def counts(self) -> dict[str, int]:
        """How many files ended with each status, most frequent first."""
        return dict(Counter(r.status for r in self.records).most_common())

    def report(self) -> dict[str, Any]:
        """The batch as plain JSON: settings, counts and every file's record."""
        return {"verb": self.verb, "outdir": str(self.outdir), "scheduler": self.scheduler,
                "n_files": len(self.records), "seconds": self.seconds, "counts": self.counts(),
                "exit_code": self.exit_code, "summary_json": str(self.summary_json),
                "summary_csv": str(self.summary_csv),
                "files": [r.as_dict() for r in self.records]}


def crashed_status(signal_number: int) -> str:
    """The status of a child killed by ``signal_number``: ``crashed (signal 11)``."""
    return f"crashed (signal {signal_number})"


def is_failed(status: str) -> bool:
    """True for the statuses of a failed file (error, timeout, memory, any crash)."""
    return status in FAILED_STATUSES or status.startswith("crashed")


# ----------------------------------------------------------------- settings
def parse_memory_size(text: str) -> int:
    """Bytes from a size such as ``4G``, ``500M``, ``1.5g``, ``800000K`` or ``1000000``.

    Parameters
    ----------
    text : str
        A positive number with an optional unit K, M, G or T (powers of 1024; a
        trailing ``B``/``iB`` is accepted: ``4GiB``, ``500MB``).

    Returns
    -------
    int
        The size in bytes.

    Raises
    ------
    ValueError
        Not a positive size.
    """
    cleaned = text.strip().upper().removesuffix("IB").removesuffix("B")
    unit = cleaned[-1:] if cleaned[-1:] in _UNITS else ""
    number = cleaned[:len(cleaned) - len(unit)]
    try:
        value = float(number)
    except ValueError:
        raise ValueError(f"not a memory size: {text!r} (e.g. 4G, 500M)") from None
    size = value * _UNITS[unit]
    if not (math.isfinite(size) and size >= 1):
        raise ValueError(f"memory size must be positive: {text!r}")
    return int(size)


def default_jobs() -> int:
    """The number of cores this process may run on (the default ``--jobs``)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def default_command() -> tuple[str, ...]:
    """The command a child runs, before its arguments: this interpreter's ``surfprep``."""
    return (sys.executable, "-m", "surfprep.plugin")


def check_passthrough(options: Sequence[str]) -> None:
    """Refuse per-file options that the batch sets itself (``-o``, ``--json``, ``--plot``).

    Raises
    ------
    SurfprepError
        One of ``options`` (or an abbreviation argparse would accept) names an output.
    """
    for option in options:
        if option == "-o" or (option.startswith("-o") and not option.startswith("--")):
            raise SurfprepError(f"option {option!r} after '--': the batch names each file's "
                                "output itself (OUTDIR/<name>.<verb>...)")
        name = option.split("=", 1)[0]
        if name.startswith("--") and len(name) > 3:
            for reserved in RESERVED_OPTIONS:
                if reserved.startswith(name):
                    raise SurfprepError(f"option {option!r} after '--': the batch sets {reserved} "
                                        "for each file itself (OUTDIR/<name>.<verb>...)")


def verb_is_available(verb: str, *, command: Sequence[str] | None = None,
                      timeout_s: float = 120.0) -> bool:
    """True when ``command VERB --help`` succeeds, i.e. the children's ``surfprep`` has VERB.

    The children's own command line answers (the commands it registers), so a verb
    added to :mod:`surfprep.plugin.commands` later (``prepare``) is found without
    this module knowing the list.

    Raises
    ------
    SurfprepError
        The command cannot be started or does not answer within ``timeout_s``.
    """
    argv = [*(default_command() if command is None else command), verb, "--help"]
    try:
        completed = subprocess.run(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL, timeout=timeout_s, check=False)
    except OSError as exc:
        raise SurfprepError(f"cannot start {argv[0]}: {exc.strerror or exc}") from None
    except subprocess.TimeoutExpired:
        raise SurfprepError(f"'{' '.join(argv)}' did not answer within {timeout_s:g} s") from None
    return completed.returncode == 0


# ------------------------------------------------------------------ inputs
def expand_inputs(patterns: Sequence[str | os.PathLike[str]], *,
                  exclude: Path | None = None) -> tuple[Path, ...]:
    """The files that ``patterns`` name, absolute, each once, in the order given.

    Parameters
    ----------
    patterns : sequence of str or path
        Glob patterns (``**`` matches folders recursively; each pattern's matches are
        sorted) or plain paths of files.
    exclude : Path, optional
        A folder whose files a pattern never matches (OUTDIR: the outputs of an earlier
        run are not inputs).

    Returns
    -------
    tuple of Path
        Possibly empty when no pattern matched a file.

    Raises
    ------
    InputFileError
        A plain path (no ``*?[``) that is not an existing file.
    """
    excluded = None if exclude is None else exclude.resolve()
    found: dict[Path, None] = {}
    for pattern in patterns:
        text = os.fspath(pattern)
        if glob.has_magic(text):
            matches = sorted(Path(p) for p in glob.glob(text, recursive=True))
            for path in matches:
                resolved = path.resolve()
                if path.is_file() and not (excluded is not None and excluded in resolved.parents):
                    found.setdefault(resolved)
            continue
        path = Path(text)
        if path.is_dir():
            raise InputFileError(f"input {text} is a folder; give a pattern such as "
                                 f"'{Path(text) / '**' / '*.step'}'")
        if not path.is_file():
            raise InputFileError(f"input file {text} does not exist")
        found.setdefault(path.resolve())
    return tuple(found)


def prepare_outdir(outdir: str | os.PathLike[str]) -> Path:
    """Create OUTDIR if missing and check that files can be written in it.

    Returns
    -------
    Path
        The folder, absolute.

    Raises
    ------
    OutputFileError
        It is a file, cannot be created, or a file cannot be written in it.
    """
    folder = Path(outdir).absolute()
    if folder.exists() and not folder.is_dir():
        raise OutputFileError(f"output folder {outdir} is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe, name = tempfile.mkstemp(prefix=".surfprep-batch.", suffix=".probe", dir=folder)
        os.close(probe)
        os.unlink(name)
    except OSError as exc:
        raise OutputFileError(f"cannot write in the output folder {outdir}: "
                              f"{exc.strerror or exc}") from None
    return folder


def plan_jobs(files: Sequence[Path], *, verb: str, outdir: Path,
              options: Sequence[str] = ()) -> tuple[FileJob, ...]:
    """One :class:`FileJob` per file, with output names unique in the batch.

    A file's name is its path relative to the files' common folder, folders joined by
    ``__`` and without the suffix (``a/part.step`` and ``b/part.step`` give ``a__part``
    and ``b__part``); files that would still share a name keep their suffix
    (``part_step``, ``part_igs``).

    Parameters
    ----------
    files : sequence of Path
        Absolute input files (:func:`expand_inputs`).
    verb : str
        A key of :data:`VERB_OUTPUTS`.
    outdir : Path
        Absolute output folder.
    options : sequence of str
        Options appended to every child's command line (after ``--``).

    Raises
    ------
    SurfprepError
        An unknown verb.
    OutputFileError
        An output of one file would replace another input.
    """
    if verb not in VERB_OUTPUTS:
        raise SurfprepError(f"unknown verb {verb!r}; expected one of {', '.join(VERB_OUTPUTS)}")
    labels, names = _names(files)
    suffix = VERB_OUTPUTS[verb]
    jobs = []
    for source, label, name in zip(files, labels, names):
        outputs = () if suffix is None else (outdir / f"{name}{suffix}",)
        report, log = outdir / f"{name}.{verb}.json", outdir / f"{name}.{verb}.log"
        output_options = [arg for out in outputs for arg in ("-o", str(out))]
        arguments = (verb, str(source), *output_options, "--json", str(report), *options)
        jobs.append(FileJob(source=source, label=label, name=name, verb=verb, report=report,
                            log=log, outputs=outputs, arguments=arguments))
    inputs = set(files)
    for job in jobs:
        for target in (*job.outputs, job.report, job.log):
            if target.resolve() in inputs:
                raise OutputFileError(f"the output {target} of {job.label} would replace an "
                                      "input file; choose another OUTDIR")
    return tuple(jobs)


def _names(files: Sequence[Path]) -> tuple[list[str], list[str]]:
    """Display labels and unique output names of ``files`` (see :func:`plan_jobs`)."""
    if not files:
        return [], []
    base = Path(os.path.commonpath([str(f.parent) for f in files]))
    relative = [f.relative_to(base) for f in files]
    labels = [r.as_posix() for r in relative]
    names = ["__".join(r.with_suffix("").parts) for r in relative]
    clashes = Counter(names)
    names = [("__".join(r.parts).replace(".", "_") if clashes[n] > 1 else n)
             for r, n in zip(relative, names)]
    unique: list[str] = []
    taken: set[str] = set()
    for n in names:
        candidate, k = n, 2
        while candidate in taken:
            candidate, k = f"{n}-{k}", k + 1
        taken.add(candidate)
        unique.append(candidate)
    return labels, unique


# ------------------------------------------------------------- one child
class _RunningChild:
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
              limits: ChildLimits) -> _RunningChild | FileRecord:
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
            return _not_started(job, f"cannot write {job.log}: {exc.strerror or exc}")
        started = time.monotonic()
        try:
            process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log_stream,
                                       stderr=subprocess.STDOUT, start_new_session=True)
        except OSError as exc:
            log_stream.close()
            return _not_started(job, f"cannot start the child: {exc.strerror or exc}")
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
            return _not_started(self.job, "the child's exit status was lost (reaped elsewhere)")
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


def _not_started(job: FileJob, message: str) -> FileRecord:
    return FileRecord(file=str(job.source), label=job.label, verb=job.verb, status=STATUS_ERROR,
                      message=message)


def _record(job: FileJob, *, exit_code: int, timed_out: bool, seconds: float,
            peak_memory_mb: float, limits: ChildLimits) -> FileRecord:
    """Classify a reaped child from its exit code, its log and its report."""
    data = _read_json(job.report)
    report = str(job.report) if isinstance(data, dict) else None
    figures = {k: v for k, v in data.items() if _is_number(v)} if report else {}
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


def _read_json(path: Path) -> Any:
    """The JSON in ``path``; None when it is missing or not valid JSON."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)


# -------------------------------------------------------------- schedulers
def run_file_task(task: Mapping[str, Any]) -> dict[str, Any]:
    """Run one file's child and wait for it: the Dask task (plain dicts in and out).

    Parameters
    ----------
    task : mapping
        ``{"job": FileJob.as_dict(), "command": list or None, "timeout_s": float or
        None, "memory_bytes": int or None}``.

    Returns
    -------
    dict
        The file's :meth:`FileRecord.as_dict`.
    """
    job = FileJob.from_dict(task["job"])
    limits = ChildLimits(timeout_s=task.get("timeout_s"), memory_bytes=task.get("memory_bytes"))
    child = _RunningChild.start(job, command=task.get("command"), limits=limits)
    if isinstance(child, FileRecord):
        return child.as_dict()
    try:
        while (record := child.poll()) is None:
            time.sleep(_POLL_S)
    except BaseException:
        child.kill()
        raise
    return record.as_dict()


def run_local(jobs: Sequence[FileJob], *, workers: int, limits: ChildLimits,
              command: Sequence[str] | None = None,
              on_record: Callable[[FileJob, FileRecord], None] | None = None) -> list[FileRecord]:
    """Run the jobs' children here, at most ``workers`` at a time.

    Parameters
    ----------
    jobs : sequence of FileJob
        The files to run.
    workers : int
        How many children run at once.
    limits : ChildLimits
        Time and memory of each child.
    command : sequence of str, optional
        The command before each job's arguments (default :func:`default_command`).
    on_record : callable(job, record), optional
        Called as each file finishes, in the order they finish.

    Returns
    -------
    list of FileRecord
        In the order of ``jobs``. On an interrupt (``KeyboardInterrupt``) the running
        children are killed and the interrupt goes on.
    """
    waiting = list(reversed(jobs))
    running: list[_RunningChild] = []
    records: dict[int, FileRecord] = {}
    order = {id(job): k for k, job in enumerate(jobs)}

    def finish(job: FileJob, record: FileRecord) -> None:
        records[order[id(job)]] = record
        if on_record is not None:
            on_record(job, record)

    try:
        while waiting or running:
            while waiting and len(running) < workers:
                job = waiting.pop()
                child = _RunningChild.start(job, command=command, limits=limits)
                if isinstance(child, FileRecord):
                    finish(job, child)
                else:
                    running.append(child)
            still_running = []
            for child in running:
                record = child.poll()
                if record is None:
                    still_running.append(child)
                else:
                    finish(child.job, record)
            running = still_running
            if running and (len(running) >= workers or not waiting):
                time.sleep(_POLL_S)
    finally:
        for child in running:                 # only left on an interrupt or an error
            child.kill()
    return [records[k] for k in range(len(jobs))]


def run_dask(jobs: Sequence[FileJob], *, scheduler: str, limits: ChildLimits,
             command: Sequence[str] | None = None,
             on_record: Callable[[FileJob, FileRecord], None] | None = None) -> list[FileRecord]:
    """Run the jobs as one Dask task each (:func:`run_file_task`) on a cluster.

    The workers must see the input files and OUTDIR at the same paths (a shared
    file system) and have surfprep installed; each task starts the child with the
    worker's own Python unless ``command`` is given.

    Parameters
    ----------
    jobs : sequence of FileJob
        The files to run.
    scheduler : str
        The Dask scheduler's address (``tcp://HOST:PORT``).
    limits : ChildLimits
        Time and memory of each child (enforced on the worker).
    command : sequence of str, optional
        The command before each job's arguments.
    on_record : callable(job, record), optional
        Called as each file finishes.

    Returns
    -------
    list of FileRecord
        In the order of ``jobs``; a task that failed on the worker (a lost worker) is
        an ``error`` record naming the failure.

    Raises
    ------
    SurfprepError
        dask.distributed is not installed, or the scheduler cannot be reached.
    """
    distributed = _import_dask()
    try:
        client = distributed.Client(scheduler, timeout="30s")
    except (OSError, TimeoutError) as exc:
        raise SurfprepError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
    batch_id = uuid.uuid4().hex[:8]
    records: dict[int, FileRecord] = {}
    futures: list[Any] = []
    try:
        index: dict[str, int] = {}
        for k, job in enumerate(jobs):
            task = {"job": job.as_dict(), "command": None if command is None else list(command),
                    "timeout_s": limits.timeout_s, "memory_bytes": limits.memory_bytes}
            future = client.submit(run_file_task, task, key=f"surfprep-batch-{batch_id}-{k}",
                                   pure=False)
            futures.append(future)
            index[future.key] = k
        for future in distributed.as_completed(futures):
            k = index[future.key]
            try:
                record = FileRecord.from_dict(future.result())
            except Exception as exc:          # noqa: BLE001 - a task's failure is its file's
                record = _not_started(jobs[k], f"Dask task failed: {type(exc).__name__}: {exc}")
            records[k] = record
            if on_record is not None:
                on_record(jobs[k], record)
    finally:
        if len(records) < len(futures):      # interrupted: no more children on the workers
            client.cancel(futures)
        client.close()
    return [records[k] for k in range(len(jobs))]


def _import_dask() -> Any:
    try:
        from dask import distributed
    except ImportError:
        raise SurfprepError('a Dask scheduler needs dask.distributed: pip install "surfprep[batch]"'
                            ) from None
    return distributed


# ----------------------------------------------------------------- summary
def load_previous_summary(outdir: Path) -> dict[str, FileRecord]:
    """The records of an earlier ``OUTDIR/summary.json`` by file; empty when there is
    none or it is not a summary."""
    data = _read_json(outdir / SUMMARY_JSON)
    if not isinstance(data, list):
        return {}
    previous = {}
    for item in data:
        try:
            record = FileRecord.from_dict(item)
        except (KeyError, TypeError, AttributeError):
            continue
        previous[record.file] = record
    return previous


def write_summary(records: Sequence[FileRecord], outdir: Path) -> tuple[Path, Path]:
    """Write ``summary.json`` (a list of :meth:`FileRecord.as_dict`) and ``summary.csv``
    (the same fields, one column per figure: ``figures.n_faces``...), each atomically.

    Returns
    -------
    tuple of Path
        The JSON and the CSV file.
    """
    rows = [r.as_dict() for r in records]
    json_text = json.dumps(rows, indent=2, allow_nan=False) + "\n"
    fields = [name for name in FileRecord.__dataclass_fields__ if name != "figures"]
    figure_names = sorted({name for r in records for name in r.figures})
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*fields, *(f"figures.{name}" for name in figure_names)])
    for row in rows:
        cells = [row[name] for name in fields] + [row["figures"].get(n) for n in figure_names]
        writer.writerow(["" if v is None else ";".join(v) if isinstance(v, list) else v
                         for v in cells])
    json_path, csv_path = outdir / SUMMARY_JSON, outdir / SUMMARY_CSV
    _write_atomically(json_path, json_text)
    _write_atomically(csv_path, buffer.getvalue())
    return json_path, csv_path


def _write_atomically(path: Path, text: str) -> None:
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as stream:
            stream.write(text)
        os.chmod(name, _new_file_mode())
        os.replace(name, path)
    except OSError as exc:
        raise OutputFileError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        Path(name).unlink(missing_ok=True)


def _new_file_mode() -> int:
    """The mode ``open()`` gives a new file under the umask (read from ``/proc``, as
    :func:`surfprep.algorithms.io.atomic.new_file_mode` does; not imported: it loads numpy)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    return 0o644


def _done_before(job: FileJob, previous: Mapping[str, FileRecord]) -> FileRecord | None:
    """The ``skipped (done)`` record of a file an earlier run finished, else None.

    Done: its report exists and is valid JSON, and the earlier summary does not say that
    this file's run of this verb failed.
    """
    data = _read_json(job.report)
    if not isinstance(data, dict):
        return None
    before = previous.get(str(job.source))
    if before is not None and before.verb == job.verb and before.failed:
        return None
    figures = {k: v for k, v in data.items() if _is_number(v)}
    outputs = tuple(str(p) for p in job.outputs if p.is_file())
    if before is not None and before.verb == job.verb:
        return replace(before, label=job.label, status=STATUS_DONE_BEFORE, outputs=outputs,
                       report=str(job.report), figures=figures)
    return FileRecord(file=str(job.source), label=job.label, verb=job.verb,
                      status=STATUS_DONE_BEFORE, outputs=outputs, report=str(job.report),
                      log=str(job.log) if job.log.is_file() else None, figures=figures)


# -------------------------------------------------------------------- batch
def run_batch(patterns: Sequence[str | os.PathLike[str]], *, verb: str,
              outdir: str | os.PathLike[str], jobs: int | None = None,
              timeout: float | None = DEFAULT_TIMEOUT_S, memory_limit: int | str | None = None,
              scheduler: str | None = None, resume: bool = False,
              options: Sequence[str] = (), command: Sequence[str] | None = None,
              on_record: Callable[[FileRecord, int, int], None] | None = None) -> BatchResult:
    """Run ``surfprep VERB`` on every file ``patterns`` match, one child process per file.

    Everything is checked before the first file runs: the verb is a command of the
    children's ``surfprep``, a file matched, OUTDIR is (or can be made) a writable
    folder, no output would replace an input, Dask is there when a scheduler is given.
    Then each file's child runs (:func:`run_local` or :func:`run_dask`) and the summary
    is rewritten after each one.

    Parameters
    ----------
    patterns : sequence of str or path
        Glob patterns (``**`` recursive) and plain file paths (:func:`expand_inputs`);
        files inside OUTDIR are never matched by a pattern.
    verb : str
        ``info``, ``heal``, ``reparam``, ``intersect`` (the file with itself), ``split``,
        ``grid`` or ``prepare`` (:data:`VERB_OUTPUTS`).
    outdir : str or path
        Folder of every output: ``<name>.<verb>.json`` reports, ``<name>.<verb>.log``
        logs, ``<name>.<verb>.step`` models or ``<name>.cgns`` grids, ``summary.json``
        and ``summary.csv``. Created if missing. Files in it named as this batch's
        outputs are replaced.
    jobs : int, optional
        Children at a time in the local pool (default :func:`default_jobs`).
    timeout : float or None
        Seconds a child may run before its process group is killed (status
        ``timeout``); None or 0: no limit.
    memory_limit : int or str, optional
        Address-space limit of each child, bytes or a size such as ``"4G"``; a child
        that runs out of it is recorded as ``memory``.
    scheduler : str, optional
        ``"local"`` or None: the local pool; an address such as ``tcp://HOST:PORT``:
        one Dask task per file on that scheduler's workers.
    resume : bool
        Skip the files an earlier run into OUTDIR finished (their report is there and the
        earlier summary does not record a failure); they are ``skipped (done)``.
    options : sequence of str
        Options passed to every child after its own (``--tol 1e-3``); options naming
        outputs (``-o``, ``--json``, ``--plot``) are refused.
    command : sequence of str, optional
        The command before each child's arguments, default ``python -m surfprep.plugin``
        with this interpreter (tests put a stand-in here).
    on_record : callable(record, done, total), optional
        Called as each file finishes (and for each skipped file first).

    Returns
    -------
    BatchResult
        The records in input order; ``exit_code`` 0 when all are done, 1 when some failed.

    Raises
    ------
    InputFileError
        No file matched, or a plain path is not a file.
    OutputFileError
        OUTDIR cannot be used, or an output would replace an input.
    SurfprepError
        An unknown verb, a refused option, or Dask missing or unreachable.

    Examples
    --------
    >>> result = run_batch(["parts/**/*.step"], verb="info", outdir="out")  # doctest: +SKIP
    >>> result.counts()                                                      # doctest: +SKIP
    {'ok': 11, 'timeout': 1}
    """
    began = time.monotonic()
    if verb not in VERB_OUTPUTS:
        raise SurfprepError(f"unknown verb {verb!r}; expected one of {', '.join(VERB_OUTPUTS)}")
    check_passthrough(options)
    workers = default_jobs() if jobs is None else int(jobs)
    if workers < 1:
        raise SurfprepError(f"jobs must be at least 1, got {jobs}")
    if timeout is not None and not (timeout >= 0 and math.isfinite(timeout)):
        raise SurfprepError(f"timeout must be a finite number of seconds >= 0, got {timeout}")
    memory_bytes = parse_memory_size(memory_limit) if isinstance(memory_limit, str) \
        else memory_limit
    limits = ChildLimits(timeout_s=timeout or None, memory_bytes=memory_bytes)
    address = None if scheduler in (None, "", "local") else str(scheduler)
    if address is not None:
        if "://" not in address:
            raise SurfprepError(f"scheduler {scheduler!r}: expected 'local' or an address such "
                                "as tcp://HOST:PORT")
        _import_dask()

    folder = Path(outdir).absolute()
    files = expand_inputs(patterns, exclude=folder)
    if not files:
        raise InputFileError("no file matches " + " ".join(repr(os.fspath(p)) for p in patterns))
    folder = prepare_outdir(folder)
    planned = plan_jobs(files, verb=verb, outdir=folder, options=options)
    if not verb_is_available(verb, command=command):
        raise SurfprepError(f"'{verb}' is not a command of this surfprep "
                            "(see 'surfprep --help')")

    previous = load_previous_summary(folder) if resume else {}
    records: list[FileRecord] = []
    to_run: list[FileJob] = []
    for job in planned:
        done = _done_before(job, previous) if resume else None
        records.append(done or FileRecord(file=str(job.source), label=job.label, verb=verb,
                                          status=STATUS_PENDING))
        if done is None:
            to_run.append(job)
    write_summary(records, folder)
    position = {id(job): k for k, job in enumerate(planned)}
    finished = 0
    for record in records:
        if record.status == STATUS_DONE_BEFORE:
            finished += 1
            if on_record is not None:
                on_record(record, finished, len(planned))

    def record_finished(job: FileJob, record: FileRecord) -> None:
        nonlocal finished
        finished += 1
        records[position[id(job)]] = record
        write_summary(records, folder)
        if on_record is not None:
            on_record(record, finished, len(planned))

    try:
        if address is None:
            run_local(to_run, workers=workers, limits=limits, command=command,
                      on_record=record_finished)
        elif to_run:
            run_dask(to_run, scheduler=address, limits=limits, command=command,
                     on_record=record_finished)
    finally:
        write_summary(records, folder)
    return BatchResult(verb=verb, outdir=folder, records=tuple(records),
                       seconds=round(time.monotonic() - began, 3),
                       scheduler="local" if address is None else address)
