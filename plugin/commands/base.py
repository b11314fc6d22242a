"""What every subcommand shares: the :class:`Command` record, console output, JSON reports.

A subcommand is a module in :mod:`surfprep.plugin.commands` that defines one
``COMMAND = Command(...)``: its name, one-line help, description, epilog with
examples, a function adding its arguments to an ``argparse`` parser and a
function running it. :mod:`surfprep.plugin.commands` lists the commands;
:mod:`surfprep.plugin.cli` builds the parser from that list and handles errors.
"""

from __future__ import annotations

import argparse
import enum
import json
import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from ...atomic_files import write_text
from ...errors import InputFileError, OutputFileError
from ..dropped import dropped_report, repaired_report

if TYPE_CHECKING:
    from ..io import StagedFile

__all__ = [
    "STDOUT",
    "Command",
    "Console",
    "check_inputs",
    "check_outputs",
    "done_code",
    "dropped_report",
    "publish",
    "read_model",
    "repaired_report",
    "to_jsonable",
    "write_json_report",
]

#: Value of a report-path option meaning "print to standard output".
STDOUT = "-"


@dataclass(frozen=True)
class Console:
    """Where a command writes: results to ``out``, progress and notes to ``err``.

    ``quiet`` leaves out the progress and the notes (warnings and errors stay);
    ``clock`` gives the seconds progress lines measure (``time.monotonic``).
    """

    out: TextIO
    err: TextIO
    show_progress: bool = False
    quiet: bool = False
    clock: Callable[[], float] = time.monotonic
    _runs: dict = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def for_streams(cls, out: TextIO | None = None, err: TextIO | None = None,
                    progress: bool | None = None, quiet: bool = False) -> Console:
        """Streams default to ``sys.stdout``/``sys.stderr``; progress to "stderr is a TTY"."""
        out = sys.stdout if out is None else out
        err = sys.stderr if err is None else err
        if progress is None:
            progress = bool(getattr(err, "isatty", lambda: False)())
        return cls(out, err, progress and not quiet, quiet)

    def print(self, *parts: Any) -> None:
        print(*parts, file=self.out)

    def note(self, *parts: Any) -> None:
        """A line on ``err``; with ``quiet`` only warnings (``surfprep: warning: ...``)."""
        if self.quiet and not (parts and str(parts[0]).startswith("surfprep: warning")):
            return
        print(*parts, file=self.err)

    def stage(self, what: str) -> None:
        """``what`` on a line of its own when progress is shown: a stage beginning that has
        no count of its own (reading, sewing)."""
        if self.show_progress:
            tty = bool(getattr(self.err, "isatty", lambda: False)())
            self.err.write(("\r" if tty else "") + what + "\n")
            self.err.flush()

    def progress(self, done: int, total: int, what: str) -> None:
        """``what done/total (share, elapsed, time left)`` on one refreshed line (TTY) or one
        line per call. The time left is the mean time per step so far times the steps to
        go, shown once a second has passed; a count back at 0 starts ``what`` anew."""
        if not self.show_progress:
            return
        now = self.clock()
        start, width = self._runs.get(what, (None, 0))
        if start is None or done <= 0:
            start = now
        elapsed = now - start
        text = f"{what} {done}/{total}"
        if total > 0:
            extra = [f"{100.0 * done / total:.0f} %"]
            if elapsed >= 1.0:
                extra.append(f"{elapsed:.0f} s")
                if 0 < done < total:
                    extra.append(f"about {elapsed / done * (total - done):.0f} s left")
            text += f" ({', '.join(extra)})"
        tty = bool(getattr(self.err, "isatty", lambda: False)())
        self._runs[what] = (start, len(text))
        if tty:
            end = "\n" if done >= total else ""
            self.err.write("\r" + text.ljust(width) + end)
        else:
            self.err.write(text + "\n")
        self.err.flush()


@dataclass(frozen=True)
class Command:
    """One subcommand of ``surfprep``.

    Attributes
    ----------
    name : str
        Word typed after ``surfprep``.
    summary : str
        One line for ``surfprep --help``.
    description : str
        What the command does, for ``surfprep NAME --help``.
    epilog : str
        Examples and notes, printed after the options.
    add_arguments : callable(parser)
        Adds the command's arguments.
    run : callable(args, console) -> int
        Runs the command; returns the exit code. Raises
        :class:`~surfprep.errors.SurfprepError` for expected failures.
    """

    name: str
    summary: str
    description: str
    epilog: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace, Console], int]


def to_jsonable(value: Any) -> Any:
    """Plain JSON types: tuples to lists, Paths to str, enums to values, NaN/inf to None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, enum.Enum):
        return value.value
    if hasattr(value, "item") and callable(value.item):  # numpy scalar
        return to_jsonable(value.item())
    return value


def write_json_report(report: dict, destination: str | os.PathLike, console: Console,
                      protected: tuple[Path, ...] = ()) -> Path | None:
    """Write ``report`` as JSON to a file (atomically) or, for ``"-"``, to stdout.

    ``protected`` are input files the report must never replace.

    Returns the path written, or None for stdout.
    """
    text = json.dumps(to_jsonable(report), indent=2, allow_nan=False) + "\n"
    if str(destination) == STDOUT:
        console.out.write(text)
        return None
    target = Path(destination)
    refuse_overwriting_inputs(target, protected)
    if target.is_dir():
        raise OutputFileError(f"report path {target} is a directory")
    parent = target.resolve().parent
    if not parent.is_dir():
        raise OutputFileError(f"report directory {parent} does not exist")
    try:
        write_text(target, text)
    except OSError as exc:
        raise OutputFileError(f"cannot write report {target}: {exc.strerror or exc}") from None
    return target.resolve()


def publish(staged: StagedFile | None, report: dict, json_path: str | None, console: Console,
            protected: tuple[Path, ...] = ()) -> Path | None:
    """Put a command's results in place: the JSON report first, then the model.

    ``staged`` is the model written beside its target (:func:`~surfprep.plugin.io.staged_write`),
    None when there is none. The report file is written before the model is moved into
    place, so a report that cannot be written leaves no model; if the move then fails,
    the report is taken back. A report for standard output is printed after the move.
    Returns the report's path (None for none or stdout).
    """
    if json_path is None or json_path == STDOUT:
        if staged is not None:
            staged.commit()
        if json_path == STDOUT:
            write_json_report(report, STDOUT, console)
        return None
    path = write_json_report(report, json_path, console, protected=protected)
    if staged is not None:
        try:
            staged.commit()
        except OutputFileError:
            if path is not None:
                path.unlink(missing_ok=True)
            raise
    return path


def refuse_overwriting_inputs(target: Path, inputs: tuple[Path, ...]) -> None:
    """Raise OutputFileError if ``target`` is one of the ``inputs`` files."""
    if not target.exists():
        return
    for source in inputs:
        if source.exists() and os.path.samefile(source, target):
            raise OutputFileError(f"refusing to overwrite the input file {target}")


def check_inputs(*paths: Path | str) -> None:
    """Refuse a missing, empty, truncated or wrong-type STEP/IGES input now, in a fraction of
    a second and before OpenCascade is loaded (:class:`~surfprep.errors.InputFileError`);
    the full content check runs when the file is read."""
    from ..file_format import check_input_file
    for path in paths:
        check_input_file(Path(path), content=False)


def check_outputs(inputs: tuple[Path, ...], output: Path | None, *, plot: Path | None = None,
                  json_path: str | None = None, model: bool = True) -> None:
    """Fail before the work, not after (:class:`OutputFileError`): every output goes to an
    existing, writable folder, is not a folder itself and not one of the ``inputs``; the
    model ``output`` has a STEP/IGES extension (``model=False``: any output the caller
    checks itself, a grid file); ``--plot`` needs matplotlib."""
    from ..file_format import FileFormat
    from .plotting import require_matplotlib
    report = None if json_path in (None, STDOUT) else Path(json_path)
    for target, what in ((output, "output"), (plot, "--plot"), (report, "--json")):
        if target is not None:
            _check_target(Path(target), what, inputs)
    if model and output is not None and FileFormat.from_suffix(Path(output)) is None:
        known = ", ".join(s for fmt in FileFormat for s in fmt.suffixes)
        raise OutputFileError(f"output {output} has unknown extension "
                              f"{Path(output).suffix or '(none)'!r}; expected one of {known}")
    if plot is not None:
        require_matplotlib()


def _check_target(target: Path, what: str, inputs: tuple[Path, ...]) -> None:
    if target.is_dir():
        raise OutputFileError(f"{what} {target} is a directory, not a file")
    folder = target.resolve().parent
    if not folder.is_dir():
        raise OutputFileError(f"{what} {target}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputFileError(f"{what} {target}: the folder {folder} is not writable")
    refuse_overwriting_inputs(target, inputs)


#: dropped entities named in the warning line (the JSON report lists them all)
LISTED_DROPS = 3


def read_model(path, console: Console, *, strict: bool = False, **options):
    """:func:`surfprep.read` for a command: what the translation left out is a warning
    line on stderr (an error with ``strict``), never silent."""
    check_inputs(path)          # a bad file is refused before OpenCascade is loaded
    from ..io import read
    model = read(path, **options)
    if model.dropped:
        listed = "; ".join(str(d) for d in model.dropped[:LISTED_DROPS])
        more = len(model.dropped) - LISTED_DROPS
        message = (f"{Path(path).name}: OpenCascade did not translate {len(model.dropped)} "
                   f"entit{'y' if len(model.dropped) == 1 else 'ies'} of the file: {listed}"
                   + (f"; and {more} more (--json lists them)" if more > 0 else ""))
        if strict:
            raise InputFileError(message + " (--strict)")
        console.note(f"surfprep: warning: {message}")
    if model.repaired:
        console.note(f"surfprep: warning: {repairs_line(model)}")
    return model


def repairs_line(model) -> str:
    """One line saying which entities OpenCascade changed while reading ``model``: per
    message, how many and the first labels."""
    by_message: dict[str, list[str]] = {}
    for r in model.repaired:
        by_message.setdefault(r.repair, []).append(r.label)
    parts = []
    for message, labels in by_message.items():
        shown = ", ".join(labels[:LISTED_DROPS]) + (", ..." if len(labels) > LISTED_DROPS else "")
        parts.append(f"{message} ({len(labels)}: {shown})")
    n = len(model.repaired)
    return (f"{Path(model.path).name if model.path else 'model'}: OpenCascade changed {n} "
            f"entit{'y' if n == 1 else 'ies'} of the file while reading it: " + "; ".join(parts))


def done_code(*models, skipped: bool = False) -> int:
    """The exit code of a command that finished: 1 when faces were skipped (``skipped``,
    or an entity of an input the reader did not translate), else 0."""
    return 1 if skipped or any(m is not None and m.dropped for m in models) else 0
