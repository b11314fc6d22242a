"""Whole-model self-intersection of every real file, ours against OpenCascade's, as a user runs it.

For each file of ``../shared/data``, two fresh processes, one after the other:

* ours: ``surfprep intersect FILE`` (the model against itself: every pair of its
  faces whose boxes overlap, curves along the faces' shared edges dropped), with
  ``--json``; the curves it reports are faces crossing each other;
* OpenCascade's: a script that reads the file with OCP's STEP/IGES reader and runs
  ``BOPAlgo_CheckerSI`` on the shape (the self-interference check of
  ``BOPAlgo_ArgumentAnalyzer``; ``BRepAlgoAPI_Section`` of a shape with itself
  answers nothing about it), single-threaded as ours is; it reports the face pairs
  that interfere with section curves and how many curves (those along shared edges
  included: OpenCascade keeps them as interferences).

Printed per file: wall time of each process (start to exit, imports and reading
included), peak memory (``ru_maxrss``), our curves and pairs worked on, OpenCascade's
face/face interferences with curves, and the time ratio. A run over ``--timeout`` is
killed and shown as such.

Run:  python benchmarks/self_intersect.py [--timeout 300] [--files bearing nist]
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

from real_files import chosen_files, file_options, run, run_process

OCC_SCRIPT = r"""
import json, os, sys, time
from OCP.BOPAlgo import BOPAlgo_CheckerSI
from OCP.IGESControl import IGESControl_Reader
from OCP.STEPControl import STEPControl_Reader
from OCP.TopTools import TopTools_ListOfShape
path = sys.argv[1]
reader = IGESControl_Reader() if path.lower().endswith((".igs", ".iges")) else STEPControl_Reader()
reader.ReadFile(path)
reader.TransferRoots()
shape = reader.OneShape()
start = time.perf_counter()
checker = BOPAlgo_CheckerSI()
arguments = TopTools_ListOfShape()
arguments.Append(shape)
checker.SetArguments(arguments)
checker.SetRunParallel(False)
checker.Perform()
elapsed = time.perf_counter() - start
ff = checker.PDS().InterfFF()
curves = [ff.Value(i).Curves().Length() for i in range(ff.Length())]
print(json.dumps({"time_s": elapsed, "pairs_with_curves": sum(c > 0 for c in curves),
                  "curves": sum(curves), "errors": checker.HasErrors()}), flush=True)
os._exit(0)      # OCP's destructors at exit can corrupt the heap after a check
"""


def occ_check(file: Path, timeout: float):
    """OpenCascade's self-interference check of ``file`` in a fresh process."""
    done = run_process([sys.executable, "-c", OCC_SCRIPT, str(file)], timeout)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    return done, (json.loads(lines[-1]) if lines and done.code == 0 else None)


def main() -> None:
    args = file_options(__doc__.splitlines()[0]).parse_args()
    files = chosen_files(args.files)
    print(f"{len(files)} files, timeout {args.timeout:.0f} s, one fresh process per run\n")
    print("| file | ours s | ours MB | our curves (pairs worked on) | OCC s | OCC MB "
          "| OCC pairs with curves (curves) | ours / OCC |")
    print("|---|---:|---:|---|---:|---:|---|---:|")
    for file in files:
        with tempfile.TemporaryDirectory(prefix="surfprep_bench_") as tmp:
            ours = run("intersect", file, Path(tmp), args.timeout)
        occ, found = occ_check(file, args.timeout)
        r = ours.report
        if ours.code is None:
            mine = "timeout"
        elif r is None:
            mine = f"exit {ours.code}"
        else:
            mine = f"{len(r['curves'])} ({len(r['pairs'])})"
        if occ.code is None:
            theirs = "timeout"
        elif found is None:
            theirs = f"exit {occ.code}" if occ.signal is None else f"signal {occ.signal}"
        else:
            theirs = f"{found['pairs_with_curves']} ({found['curves']})"
        print(f"| {file.name} | {ours.time_s:.1f} | {ours.peak_mb:.0f} | {mine} "
              f"| {occ.time_s:.1f} | {occ.peak_mb:.0f} | {theirs} "
              f"| {ours.time_s / occ.time_s:.2f} |", flush=True)


if __name__ == "__main__":
    main()
