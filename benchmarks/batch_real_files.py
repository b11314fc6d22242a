"""Every real file of ``../shared/data`` through ``surfprep batch``, twice: on the local
pool (``--jobs 2``) and on a two-worker Dask ``LocalCluster`` (``--scheduler``), each
batch as a user runs it (a fresh ``surfprep batch`` process). Prints the local pool's
table (status, seconds, peak memory per file) and whether the cluster's records agree
(same files, statuses, exit codes and report figures).

Run:  python benchmarks/batch_real_files.py [--do info] [--timeout 300]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
PATTERNS = [str(DATA / "*.st*p"), str(DATA / "*.ig*s")]


def run_batch(outdir: Path, verb: str, timeout: float, scheduler: str | None) -> tuple[list, float]:
    argv = [sys.executable, "-m", "surfprep.plugin", "batch", *PATTERNS, "--do", verb,
            "-o", str(outdir), "--jobs", "2", "--timeout", str(timeout), "--quiet"]
    if scheduler is not None:
        argv += ["--scheduler", scheduler]
    start = time.perf_counter()
    subprocess.run(argv, stdout=subprocess.DEVNULL, check=False)
    elapsed = time.perf_counter() - start
    return json.loads((outdir / "summary.json").read_text()), elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--do", default="info")
    parser.add_argument("--timeout", type=float, default=300.0)
    args = parser.parse_args()
    from dask.distributed import LocalCluster
    with tempfile.TemporaryDirectory() as tmp:
        local, local_s = run_batch(Path(tmp) / "local", args.do, args.timeout, None)
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster:
            dask, dask_s = run_batch(Path(tmp) / "dask", args.do, args.timeout,
                                     cluster.scheduler_address)
    print(f"surfprep batch --do {args.do} over {len(local)} files of shared/data, --jobs 2: "
          f"{local_s:.1f} s; on a two-worker LocalCluster: {dask_s:.1f} s\n")
    print("| file | status | s | peak MB |")
    print("|---|---|---|---|")
    for r in local:
        print(f"| {Path(r['file']).name} | {r['status']} | {r['seconds']:.1f} | "
              f"{r['peak_memory_mb']:.0f} |")

    def key(records):
        return {Path(r["file"]).name: (r["status"], r["exit_code"], r.get("figures"))
                for r in records}
    same = key(local) == key(dask)
    print(f"\nLocalCluster records equal to the local pool's (file, status, exit code, "
          f"figures): {same}")
    if not same:
        for name in sorted(set(key(local)) | set(key(dask))):
            if key(local).get(name) != key(dask).get(name):
                print(f"  {name}: local {key(local).get(name)} / dask {key(dask).get(name)}")


if __name__ == "__main__":
    main()
