"""Every real file in ``../shared/data`` through every command, as a user runs it.

Each cell is one fresh ``surfprep`` process (``python -m surfprep.plugin``, what
the ``surfprep`` script runs): ``info FILE``, ``intersect FILE`` (the model
against itself), ``heal FILE`` and ``reparam FILE``, each with ``--json`` to a
temporary file and outputs into a temporary folder. For each run: the wall time
(process start to exit, imports and reading included), the peak resident memory
(``ru_maxrss`` of the process and the reader's child, from ``wait4``), and the
outcome: the exit code (0 done, 1 done with something skipped, 2 nothing done)
with what the report says (faces, curves, free edges, faces done), ``timeout``
when the run passed ``--timeout`` seconds (it is killed), ``signal N`` when it
died. A cell must never be a signal or a traceback.

Run:  python benchmarks/real_files.py [--timeout 300] [--files k1 fuselage]
      [--commands info reparam]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
COMMANDS = ("info", "intersect", "heal", "reparam")
SUFFIXES = {".stp", ".step", ".igs", ".iges"}


@dataclass(frozen=True)
class Run:
    """One ``surfprep`` process: exit code (None on timeout), time, memory, report."""

    code: int | None
    signal: int | None
    time_s: float
    peak_mb: float
    report: dict | None
    error: str


@dataclass(frozen=True)
class Process:
    """A finished (or killed) process: exit code (None when killed by the timeout),
    signal, wall time, peak memory of it and its children, stdout and stderr."""

    code: int | None
    signal: int | None
    time_s: float
    peak_mb: float
    stdout: str
    stderr: str


def run_process(argv: list[str], timeout: float) -> Process:
    """``argv`` in a fresh process (its own session), killed after ``timeout`` seconds;
    peak memory from ``wait4`` (``ru_maxrss``: the process and its reaped children)."""
    start = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               start_new_session=True)
    timed_out = threading.Event()

    def kill() -> None:
        timed_out.set()
        os.killpg(process.pid, signal.SIGKILL)

    timer = threading.Timer(timeout, kill)
    timer.start()
    out: list[bytes] = []
    reader = threading.Thread(target=lambda: out.append(process.stdout.read()))
    reader.start()
    stderr = process.stderr.read().decode("utf-8", "replace")
    reader.join()
    _, status, usage = os.wait4(process.pid, 0)
    elapsed = time.perf_counter() - start
    timer.cancel()
    process.returncode = 0                       # reaped by wait4: keep Popen quiet
    killed = timed_out.is_set()
    return Process(code=None if killed else
                   (os.waitstatus_to_exitcode(status) if os.WIFEXITED(status) else None),
                   signal=os.WTERMSIG(status) if os.WIFSIGNALED(status) and not killed
                   else None,
                   time_s=elapsed, peak_mb=usage.ru_maxrss / 1024,
                   stdout=b"".join(out).decode("utf-8", "replace"), stderr=stderr)


def run(command: str, file: Path, workdir: Path, timeout: float) -> Run:
    """``surfprep COMMAND FILE`` in a fresh process, killed after ``timeout`` seconds."""
    report_path = workdir / f"{command}.json"
    argv = [sys.executable, "-m", "surfprep.plugin", command, str(file),
            "--json", str(report_path)]
    if command != "info":
        argv += ["-o", str(workdir / f"{command}.step")]
    done = run_process(argv, timeout)
    report = None
    if report_path.is_file():
        report = json.loads(report_path.read_text())
    errors = [line for line in done.stderr.splitlines() if line.startswith("surfprep: error:")]
    if "Traceback" in done.stderr:
        errors.insert(0, "TRACEBACK")
    return Run(code=done.code, signal=done.signal, time_s=done.time_s, peak_mb=done.peak_mb,
               report=report,
               error=errors[0].removeprefix("surfprep: error: ") if errors else "")


def outcome(command: str, result: Run, timeout: float) -> str:
    """A short cell: exit code and the report's headline, or what went wrong."""
    if result.signal is not None:
        return f"**signal {result.signal}**"
    if result.code is None:
        return f"timeout (> {timeout:.0f} s)"
    r = result.report
    if result.code == 2 or r is None:
        return f"exit {result.code}: {result.error[:60]}"
    dropped = len(r.get("dropped", []))
    tail = f", {dropped} dropped" if dropped else ""
    if command == "info":
        return f"exit {result.code}: {r['n_faces']} faces{tail}"
    if command == "intersect":
        coincident = len(r.get("coincident", []))
        return (f"exit {result.code}: {len(r['curves'])} curves"
                + (f", {coincident} coincident" if coincident else "") + tail)
    if command == "heal":
        free = r["free_edges"]
        skipped = len(r.get("skipped", []))
        loops = r.get("free_loops", [])
        holes = sum(lp["kind"] == "hole" for lp in loops)
        filled = len({p["index"] for p in r["patches"] if p["kind"] == "hole"})
        return (f"exit {result.code}: free edges {free['before']} -> {free['after']}, "
                f"{len(r['patches'])} patches" + (f", {skipped} skipped" if skipped else "")
                + (f", loops {len(loops)}: {holes} holes ({filled} filled), "
                   f"{len(loops) - holes} other" if loops else "") + tail)
    done = sum(1 for f in r["faces"] if f.get("error") is None)
    return f"exit {result.code}: {done}/{len(r['faces'])} faces{tail}"


def file_options(description: str) -> argparse.ArgumentParser:
    """A parser with ``--timeout`` and ``--files`` (what the real-file benchmarks share)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--timeout", type=float, default=300.0,
                        help="seconds before a run is killed and reported as a timeout")
    parser.add_argument("--files", nargs="+", default=None,
                        help="only files whose name contains one of these")
    return parser


def chosen_files(keys: list[str] | None) -> list[Path]:
    """The STEP/IGES files of ``../shared/data``, those whose name holds one of ``keys``."""
    files = sorted(p for p in DATA.iterdir() if p.suffix.lower() in SUFFIXES)
    return [p for p in files if any(key in p.name for key in keys)] if keys else files


def main() -> None:
    parser = file_options(__doc__.splitlines()[0])
    parser.add_argument("--commands", nargs="+", choices=COMMANDS, default=list(COMMANDS))
    args = parser.parse_args()
    files = chosen_files(args.files)
    print(f"{len(files)} files x {args.commands}, timeout {args.timeout:.0f} s, "
          f"one fresh process per cell\n")
    print("| file | MB | " + " | ".join(args.commands) + " |")
    print("|---|---:|" + "---|" * len(args.commands))
    for file in files:
        cells = []
        for command in args.commands:
            with tempfile.TemporaryDirectory(prefix="surfprep_bench_") as tmp:
                result = run(command, file, Path(tmp), args.timeout)
            cells.append(f"{outcome(command, result, args.timeout)}; "
                         f"{result.time_s:.1f} s, {result.peak_mb:.0f} MB")
        print(f"| {file.name} | {file.stat().st_size / 1e6:.2f} | " + " | ".join(cells) + " |",
              flush=True)


if __name__ == "__main__":
    main()
