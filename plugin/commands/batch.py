"""``surfprep batch PATTERN... --do VERB -o OUTDIR``: one command on many files.

The work is in :mod:`surfprep.plugin.batch` (standard library only), imported when
the command runs, so that ``surfprep --help`` does not pay for it.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ...errors import OutputFileError
from .base import STDOUT, Command, Console, write_json_report

if TYPE_CHECKING:
    from ..batch import FileRecord

__all__ = ["COMMAND", "format_table", "split_passthrough"]

#: verbs ``--do`` accepts (each must also be a command of the children's surfprep)
VERBS = ("info", "heal", "reparam", "intersect", "split", "grid", "prepare")

USAGE = ("surfprep batch PATTERN [PATTERN ...] --do VERB -o OUTDIR [--jobs N] [--timeout S]\n"
         "                      [--memory-limit M] [--scheduler local|tcp://HOST:PORT] "
         "[--resume]\n"
         "                      [--json R] [-- OPTIONS OF VERB ...]")


def split_passthrough(arguments: Sequence[str]) -> tuple[list[str], list[str]]:
    """The arguments before the first ``--`` and the ones after it (for the children).

    argparse cannot give a variable number of patterns and also keep what follows
    ``--`` apart, so the batch parser splits there before parsing.
    """
    items = list(arguments)
    if "--" not in items:
        return items, []
    cut = items.index("--")
    return items[:cut], items[cut + 1:]


def _keep_passthrough(parser: argparse.ArgumentParser) -> None:
    """Make ``parser`` put what follows ``--`` in ``args.passthrough``, unparsed."""
    parse_known_args = parser.parse_known_args

    def parse_known_args_with_passthrough(args=None, namespace=None):
        head, tail = split_passthrough(args if args is not None else sys.argv[1:])
        namespace, extras = parse_known_args(head, namespace)
        namespace.passthrough = tail
        return namespace, extras

    parser.parse_known_args = parse_known_args_with_passthrough  # type: ignore[method-assign]


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not (0 <= value < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a finite number of seconds >= 0, got {text}")
    return value


def _memory_size(text: str) -> int:
    from ..batch import parse_memory_size
    try:
        return parse_memory_size(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.usage = USAGE
    parser.add_argument("patterns", nargs="+", metavar="PATTERN",
                        help="STEP/IGES files or glob patterns ('parts/**/*.step': ** goes into "
                             "sub-folders; quote it so the shell leaves it to surfprep)")
    parser.add_argument("--do", required=True, choices=VERBS, dest="verb", metavar="VERB",
                        help="the command run on each file: " + ", ".join(VERBS)
                             + " (intersect and split: each file with itself)")
    parser.add_argument("-o", "--outdir", required=True, type=Path, metavar="OUTDIR",
                        help="folder of the outputs, reports, logs and summary (created if "
                             "missing)")
    parser.add_argument("--jobs", type=_positive_int, default=None, metavar="N",
                        help="files run at once by the local pool (default: the number of cores)")
    parser.add_argument("--timeout", type=_seconds, default=600.0, metavar="S",
                        help="seconds a file may run before it is killed and recorded as "
                             "'timeout' (default 600, 0 for none)")
    parser.add_argument("--memory-limit", type=_memory_size, default=None, metavar="M",
                        dest="memory_limit",
                        help="address-space limit of each file's process (4G, 500M); a file "
                             "that runs out of it is recorded as 'memory'")
    parser.add_argument("--scheduler", default="local", metavar="local|tcp://HOST:PORT",
                        help="'local' (default): a pool of child processes here; a Dask "
                             "scheduler's address: one task per file on its workers (needs "
                             "pip install \"surfprep[batch]\" and the files at the same paths "
                             "on the workers)")
    parser.add_argument("--resume", action="store_true",
                        help="skip the files an earlier batch into OUTDIR finished")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the batch report as JSON to PATH; '-' prints it to stdout "
                             "instead of the table")
    parser.set_defaults(passthrough=[])
    _keep_passthrough(parser)


def format_table(report: dict) -> str:
    """The final table of a batch report: file, status, seconds, MB; then the counts."""
    rows = [("file", "status", "seconds", "MB")]
    for r in report["files"]:
        rows.append((r["label"], r["status"],
                     "-" if r["seconds"] is None else f"{r['seconds']:.1f}",
                     "-" if r["peak_memory_mb"] is None else f"{r['peak_memory_mb']:.0f}"))
    widths = [max(len(row[c]) for row in rows) for c in range(4)]
    lines = ["  ".join(row[c].rjust(widths[c]) if c >= 2 else row[c].ljust(widths[c])
                       for c in range(4)).rstrip() for row in rows]
    counts = ", ".join(f"{n} {status}" for status, n in report["counts"].items())
    lines += ["", f"{report['n_files']} file(s) in {report['seconds']:.1f} s: {counts}",
              f"summary: {report['summary_json']} and {report['summary_csv']}"]
    return "\n".join(lines)


def _check_report_path(json_path: str | None) -> None:
    """``--json R`` goes to an existing, writable folder and is not a folder (before the work)."""
    if json_path is None or json_path == STDOUT:
        return
    target = Path(json_path)
    folder = target.absolute().parent
    if target.is_dir():
        raise OutputFileError(f"--json {target} is a directory, not a file")
    if not folder.is_dir():
        raise OutputFileError(f"--json {target}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputFileError(f"--json {target}: the folder {folder} is not writable")


def _run(args: argparse.Namespace, console: Console) -> int:
    from ..batch import run_batch

    _check_report_path(args.json_path)
    inherited = [flag for flag, on in (("--strict", getattr(args, "strict", False)),
                                       ("--debug", getattr(args, "debug", False))) if on]

    def progress(record: FileRecord, done: int, total: int) -> None:
        seconds = "" if record.seconds is None else f" {record.seconds:.1f} s"
        why = f": {record.message}" if record.failed and record.message else ""
        console.note(f"[{done}/{total}] {record.label} {record.status}{seconds}{why}")

    result = run_batch(args.patterns, verb=args.verb, outdir=args.outdir, jobs=args.jobs,
                       timeout=args.timeout, memory_limit=args.memory_limit,
                       scheduler=args.scheduler, resume=args.resume,
                       options=[*inherited, *args.passthrough], on_record=progress)
    report = result.report()
    if args.json_path == STDOUT:
        write_json_report(report, STDOUT, console)
        return result.exit_code
    console.print(format_table(report))
    if args.json_path is not None:
        written = write_json_report(report, args.json_path, console)
        console.note(f"report written to {written}")
    return result.exit_code


COMMAND = Command(
    name="batch",
    summary="run one command on many files, one process per file, with a summary",
    description=(
        "Run 'surfprep VERB' on every file the patterns match, each file in its own "
        "process: a file that crashes, hangs past --timeout or runs out of --memory-limit "
        "is recorded with that status and the others go on. Each file's outputs go to "
        "OUTDIR under a name made from its path (a/part.step: a__part.<verb>.json, "
        "a__part.<verb>.log, a__part.heal.step or a__part.cgns), and OUTDIR/summary.json "
        "and summary.csv (status, exit code, message, seconds, peak memory, outputs and "
        "the numeric fields of each file's report) are rewritten after every file, so an "
        "interrupted batch leaves a valid summary and --resume carries on from it.\n\n"
        "Options after '--' are passed to every file's command (not -o, --json or --plot: "
        "the batch names those). Exit status: 0 every file done (faces skipped included), "
        "1 some file failed, 2 nothing done (no file matched, OUTDIR not writable, "
        "VERB not a command)."),
    epilog=(
        "examples:\n"
        "  surfprep batch 'parts/**/*.step' --do info -o out/\n"
        "      the info report of every STEP file under parts/, one process per core\n"
        "  surfprep batch 'parts/*.igs' --do heal -o healed/ --jobs 2 --timeout 300 \\\n"
        "      --memory-limit 4G -- --continuity G1\n"
        "      heal with G1 joins, at most 2 files at once, 5 minutes and 4 GB each\n"
        "  surfprep batch 'parts/**/*.step' --do grid -o grids/ --resume -- --size 5\n"
        "      grids again, skipping the files an earlier run finished\n"
        "  surfprep batch 'parts/*.step' --do info -o out/ --scheduler tcp://head:8786\n"
        "      one Dask task per file on a cluster (files at the same paths on the workers)"),
    add_arguments=_add_arguments,
    run=_run,
)
