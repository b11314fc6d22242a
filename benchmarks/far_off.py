"""A model far from the origin runs as fast, and gives the same answer, as at the origin.

Each bundled sample is written twice to STEP by ``surfprep.write``: as it is
("near") and moved by (1e6, 1e6, 1e6) mm with ``BRepBuilderAPI_Transform``
("far"), so both went through the same writer (a STEP file keeps about 15
digits: at 1e6 its coordinates are rounded to ~1e-9 mm, the far file is not
bit-for-bit the near one moved). Then ``surfprep reparam`` / ``heal`` /
``intersect`` run on each in a fresh process, as a user runs them, with
``--json``. Printed per run: wall time near and far, their ratio, and the
report's headline figures for both (they must agree to the tolerance).

Run:  python benchmarks/far_off.py [--offset 1e6] [--samples catia4 capsule]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.gp import gp_Trsf, gp_Vec

import surfprep

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = {"catia4": "occt_catia4_face_L1.igs", "capsule": "overture_marscapsule_proe.igs",
           "fuselage": "occt_fuselage.stp"}
COMMANDS = ("reparam", "heal", "intersect")


def write_pair(source: Path, folder: Path, offset: float) -> tuple[Path, Path]:
    """``source`` written as it is and moved by ``offset`` along (1, 1, 1)."""
    model = surfprep.read(source)
    move = gp_Trsf()
    move.SetTranslation(gp_Vec(offset, offset, offset))
    builder = BRepBuilderAPI_Transform(model.shape, move, True)
    if not builder.IsDone():
        raise RuntimeError(f"BRepBuilderAPI_Transform failed on {source.name}")
    near, far = folder / f"{source.stem}_near.step", folder / f"{source.stem}_far.step"
    surfprep.write(model.shape, near)
    surfprep.write(builder.Shape(), far)
    return near, far


def run(command: str, file: Path, folder: Path) -> tuple[float, dict | None, int]:
    """``surfprep COMMAND FILE -o ... --json ...`` in a fresh process: time, report, exit."""
    report = folder / f"{file.stem}_{command}.json"
    argv = [sys.executable, "-m", "surfprep.plugin", command, str(file),
            "-o", str(folder / f"{file.stem}_{command}.step"), "--json", str(report)]
    start = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, check=False)
    elapsed = time.perf_counter() - start
    return elapsed, json.loads(report.read_text()) if report.is_file() else None, done.returncode


def headline(command: str, report: dict | None) -> str:
    """The figures that must agree near and far."""
    if report is None:
        return "no report"
    if command == "reparam":
        faces = [f for f in report["faces"] if f.get("error") is None]
        return (f"{len(faces)}/{len(report['faces'])} faces, max dev "
                f"{max(f['max_deviation'] for f in faces):.6g}, poles "
                f"{sum(f['poles_after'] for f in faces)}")
    if command == "heal":
        free = report["free_edges"]
        gaps = [j["max_gap"] for j in report.get("shared_edges", [])]
        return (f"free edges {free['before']} -> {free['after']}, {len(report['patches'])} "
                f"patches, max gap {max(gaps, default=0.0):.2g}")
    length = sum(c["length"] for c in report["curves"])
    pairs = len({tuple(c["faces"]) for c in report["curves"]})
    return f"{len(report['curves'])} curves on {pairs} face pairs, length {length:.6g}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--offset", type=float, default=1e6)
    parser.add_argument("--samples", nargs="+", choices=sorted(SAMPLES), default=list(SAMPLES))
    parser.add_argument("--commands", nargs="+", choices=COMMANDS, default=list(COMMANDS))
    args = parser.parse_args()
    print(f"offset ({args.offset:g}, {args.offset:g}, {args.offset:g}) mm; one fresh process "
          "per run\n")
    print("| sample | command | near s | far s | far/near | near | far |")
    print("|---|---|---:|---:|---:|---|---|")
    with tempfile.TemporaryDirectory(prefix="surfprep_far_") as tmp:
        folder = Path(tmp)
        for name in args.samples:
            near, far = write_pair(ROOT / "step_samples" / SAMPLES[name], folder, args.offset)
            for command in args.commands:
                t_near, r_near, c_near = run(command, near, folder)
                t_far, r_far, c_far = run(command, far, folder)
                print(f"| {name} | {command} | {t_near:.2f} | {t_far:.2f} | "
                      f"{t_far / t_near:.2f} | exit {c_near}: {headline(command, r_near)} | "
                      f"exit {c_far}: {headline(command, r_far)} |", flush=True)


if __name__ == "__main__":
    main()
