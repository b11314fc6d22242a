"""How many faces of the real files a structured grid can cover, and as how many blocks.

For every face of every STEP/IGES file in ``../shared/data``: whether
:func:`surfprep.algorithms.grid.faces.face_region` takes it as one block (four-sided:
its surface's rectangle, or one loop of four edges) and whether
:func:`~surfprep.algorithms.grid.faces.face_regions` splits it into blocks (a loop of
three to sixteen corners round a centre, a disc or lens as a butterfly, one hole as
four blocks round it); per file and in total, with the reasons for the rest counted.
Only the split is computed (no grid): the figures say which faces ``surfprep grid``
would try.

Run:  python benchmarks/grid_coverage.py
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

from surfprep.algorithms.grid.faces import face_region, face_regions
from surfprep.errors import SurfprepError
from surfprep.plugin.io import read
from surfprep.plugin.occ.faces import face_to_nurbs

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
SUFFIXES = {".stp", ".step", ".igs", ".iges"}
#: the gap between consecutive loop edges accepted, as surfprep grid's default
RELATIVE_GAP = 1e-4


def _reason_kind(reason: str) -> str:
    for key in ("hole", "corners", "non-convex", "collapses", "cusp", "fold"):
        if key in reason:
            return key
    return "other"


def main() -> None:
    total, reasons = Counter(), Counter()
    print("| file | faces | one block (four-sided) | split into blocks | blocks |")
    print("|---|---:|---:|---:|---:|")
    for path in sorted(p for p in DATA.iterdir() if p.suffix.lower() in SUFFIXES):
        try:
            model = read(path)
        except SurfprepError as exc:
            print(f"| {path.name} | not read: {exc} | | | |")
            continue
        row = Counter()
        for face in model.faces:
            try:
                trimmed = face_to_nurbs(face)
            except SurfprepError:
                continue
            row["faces"] += 1
            row["four"] += not isinstance(face_region(trimmed), str)
            regions = face_regions(trimmed, gap_tol=RELATIVE_GAP * model.size)
            if isinstance(regions, str):
                reasons[_reason_kind(regions)] += 1
            else:
                row["split"] += 1
                row["blocks"] += len(regions)
        total.update(row)
        print(f"| {path.name} | {row['faces']} | {row['four']} | {row['split']} | "
              f"{row['blocks']} |")
    print(f"| all | {total['faces']} | {total['four']} | {total['split']} | "
          f"{total['blocks']} |")
    print()
    print("faces not split, by reason: " + ", ".join(f"{k} {n}" for k, n in reasons.most_common()))


if __name__ == "__main__":
    main()
