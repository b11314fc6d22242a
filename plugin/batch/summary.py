"""``OUTDIR/summary.json`` and ``OUTDIR/summary.csv``: written atomically after every
file (:func:`write_summary`), read back to resume (:func:`load_previous_summary`,
:func:`done_before`).
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path

from ...atomic_files import write_text
from ...errors import OutputFileError
from .child import is_number, read_json
from .records import STATUS_DONE_BEFORE, SUMMARY_CSV, SUMMARY_JSON, FileJob, FileRecord

__all__ = [
    "done_before",
    "load_previous_summary",
    "write_summary",
]


def load_previous_summary(outdir: Path) -> dict[str, FileRecord]:
    """The records of an earlier ``OUTDIR/summary.json`` by file; empty when there is
    none or it is not a summary."""
    data = read_json(outdir / SUMMARY_JSON)
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
    try:
        write_text(path, text, newline="")
    except OSError as exc:
        raise OutputFileError(f"cannot write {path}: {exc.strerror or exc}") from None


def done_before(job: FileJob, previous: Mapping[str, FileRecord]) -> FileRecord | None:
    """The ``skipped (done)`` record of a file an earlier run finished, else None.

    Done: its report exists and is valid JSON, and the earlier summary does not say that
    this file's run of this verb failed.
    """
    data = read_json(job.report)
    if not isinstance(data, dict):
        return None
    before = previous.get(str(job.source))
    if before is not None and before.verb == job.verb and before.failed:
        return None
    figures = {k: v for k, v in data.items() if is_number(v)}
    outputs = tuple(str(p) for p in job.outputs if p.is_file())
    if before is not None and before.verb == job.verb:
        return replace(before, label=job.label, status=STATUS_DONE_BEFORE, outputs=outputs,
                       report=str(job.report), figures=figures)
    return FileRecord(file=str(job.source), label=job.label, verb=job.verb,
                      status=STATUS_DONE_BEFORE, outputs=outputs, report=str(job.report),
                      log=str(job.log) if job.log.is_file() else None, figures=figures)
