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

This package imports only the standard library (Dask on the Dask path only), so
that the command line starts fast and a Dask worker needs nothing else to run a
task.

The modules: :mod:`.records` (statuses, jobs, records, the result), :mod:`.inputs`
(patterns, OUTDIR, output names, the checks before the first file), :mod:`.child`
(one child process), :mod:`.schedulers` (the local pool and Dask) and :mod:`.summary`
(``summary.json`` / ``summary.csv``, resume); this one runs a batch (:func:`run_batch`).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from ...errors import InputFileError, SurfprepError
from .child import measured_argv, peak_file
from .inputs import (
    VERB_OUTPUTS,
    check_passthrough,
    default_jobs,
    expand_inputs,
    plan_jobs,
    prepare_outdir,
    verb_is_available,
)
from .records import (
    DEFAULT_TIMEOUT_S,
    FAILED_STATUSES,
    STATUS_DONE_BEFORE,
    STATUS_ERROR,
    STATUS_FACES_SKIPPED,
    STATUS_MEMORY,
    STATUS_OK,
    STATUS_PENDING,
    STATUS_TIMEOUT,
    SUCCESS_STATUSES,
    SUMMARY_CSV,
    SUMMARY_JSON,
    BatchResult,
    ChildLimits,
    FileJob,
    FileRecord,
    crashed_status,
    default_command,
    is_failed,
    parse_memory_size,
)
from .schedulers import import_dask, run_dask, run_file_task, run_local
from .summary import done_before, load_previous_summary, write_summary

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
        import_dask()

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
        done = done_before(job, previous) if resume else None
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
