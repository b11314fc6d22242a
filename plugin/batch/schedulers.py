"""Where the children run: a local pool (:func:`run_local`) or one Dask task per file
(:func:`run_dask`, the task being :func:`run_file_task`); Dask is imported on that
path only (:func:`import_dask`).
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from ...errors import SurfprepError
from .child import RunningChild
from .records import ChildLimits, FileJob, FileRecord, not_started

__all__ = [
    "import_dask",
    "run_dask",
    "run_file_task",
    "run_local",
]

_POLL_S = 0.05


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
    child = RunningChild.start(job, command=task.get("command"), limits=limits)
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
    running: list[RunningChild] = []
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
                child = RunningChild.start(job, command=command, limits=limits)
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
    distributed = import_dask()
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
                record = not_started(jobs[k], f"Dask task failed: {type(exc).__name__}: {exc}")
            records[k] = record
            if on_record is not None:
                on_record(jobs[k], record)
    finally:
        if len(records) < len(futures):      # interrupted: no more children on the workers
            client.cancel(futures)
        client.close()
    return [records[k] for k in range(len(jobs))]


def import_dask() -> Any:
    """``dask.distributed``, imported now.

    Raises
    ------
    SurfprepError
        It is not installed.
    """
    try:
        from dask import distributed
    except ImportError:
        raise SurfprepError('a Dask scheduler needs dask.distributed: pip install "surfprep[batch]"'
                            ) from None
    return distributed
