"""What a batch is made of: the statuses, each file's :class:`FileJob` and
:class:`FileRecord`, a child's :class:`ChildLimits` and the finished
:class:`BatchResult`.
"""

from __future__ import annotations

import math
import sys
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

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
    "BatchResult",
    "ChildLimits",
    "FileJob",
    "FileRecord",
    "crashed_status",
    "default_command",
    "is_failed",
    "not_started",
    "parse_memory_size",
]

#: seconds a child may run before it is killed (``--timeout``)
DEFAULT_TIMEOUT_S = 600.0
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

_UNITS = {"": 1, "B": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


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


def not_started(job: FileJob, message: str) -> FileRecord:
    """The ``error`` record of ``job`` whose child did not run or whose exit was lost."""
    return FileRecord(file=str(job.source), label=job.label, verb=job.verb, status=STATUS_ERROR,
                      message=message)


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


def default_command() -> tuple[str, ...]:
    """The command a child runs, before its arguments: this interpreter's ``surfprep``
    (here beside :class:`FileJob`, whose :meth:`~FileJob.argv` defaults to it)."""
    return (sys.executable, "-m", "surfprep.plugin")
