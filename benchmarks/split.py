"""Booleans from split pieces: ``surfprep.boolean`` against OpenCascade's BRepAlgoAPI.

Three pairs of solids whose fuse, cut and common volumes are known exactly: a
sphere (r = 10) through a 1 mm slab, a cylinder (r = 3, length 20) through a
10 mm cube, two spheres (r = 5) 6 apart (a lens: pi (4r + d)(2r - d)^2 / 12).
For each operation: our volume and OpenCascade's (GProp at 1e-9), their errors
against the exact value, validity, and the times of the calls in one warm
process (the intersection, the splitting and the sewing for ours; the Boolean
for OpenCascade).

Run:  python benchmarks/split.py [--no-write]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import cadquery as cq
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps

from surfprep.plugin.split import boolean

RESULTS = Path(__file__).resolve().parent / "results" / "split.txt"


def _pairs():
    r = 10.0
    slab = math.pi * (r * r * 1.0 - (5.5 ** 3 - 4.5 ** 3) / 3)
    sphere = 4 / 3 * math.pi * r ** 3
    yield ("sphere r10 / slab 1 mm", cq.Workplane().sphere(r), cq.Workplane().box(30, 30, 1).translate((0, 0, 5)),
           {"common": slab, "fuse": sphere + 900 - slab, "cut": sphere - slab})
    cyl = math.pi * 9 * 20
    inside = math.pi * 9 * 10
    yield ("cube 10 / cylinder r3", cq.Workplane().box(10, 10, 10),
           cq.Workplane("YZ").circle(3).extrude(20).translate((-10, 0, 0)),
           {"common": inside, "fuse": 1000 + cyl - inside, "cut": 1000 - inside})
    d, rr = 6.0, 5.0
    lens = math.pi * (4 * rr + d) * (2 * rr - d) ** 2 / 12
    ball = 4 / 3 * math.pi * rr ** 3
    yield ("two spheres r5, 6 apart", cq.Workplane().sphere(rr), cq.Workplane().sphere(rr).translate((d, 0, 0)),
           {"common": lens, "fuse": 2 * ball - lens, "cut": ball - lens})


def _volume(shape) -> float:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-9)
    return abs(float(props.Mass()))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args()
    occ_ops = {"fuse": BRepAlgoAPI_Fuse, "cut": BRepAlgoAPI_Cut, "common": BRepAlgoAPI_Common}
    lines = [("| pair | operation | exact volume | ours: rel. error | ours valid | ours s | OCC: rel. error "
             "| OCC valid | OCC s | time ours / OCC |"), "|---|---|---|---|---|---|---|---|---|---|"]
    for name, a, b, exact in _pairs():
        for op in ("common", "fuse", "cut"):
            start = time.perf_counter()
            ours = boolean(a, b, op)
            t_ours = time.perf_counter() - start
            start = time.perf_counter()
            occ = occ_ops[op](a.val().wrapped, b.val().wrapped)
            occ.Build()
            t_occ = time.perf_counter() - start
            v_occ = _volume(occ.Shape()) if occ.IsDone() else float("nan")
            e_ours = abs(ours.volume - exact[op]) / exact[op] if ours.volume is not None else float("nan")
            e_occ = abs(v_occ - exact[op]) / exact[op]
            lines.append(f"| {name} | {op} | {exact[op]:.6f} | {e_ours:.1e} | {ours.valid} | {t_ours:.2f} | "
                         f"{e_occ:.1e} | {BRepCheck_Analyzer(occ.Shape()).IsValid()} | {t_occ:.3f} | "
                         f"{t_ours / t_occ:.0f}x |")
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    if not args.no_write:
        RESULTS.write_text(text)
        print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
