"""Cold one-shot calls, as a user runs them: every command in a fresh process.

Each row runs one ``surfprep`` command line in a new interpreter (what typing it
in a shell does: start-up, imports, reading, the work, writing) and, beside it,
the one-shot OpenCascade script a user would write for the same job on the same
files (read with OpenCascade's reader, call the counterpart, write); ours and
theirs alternate, each ``--repeats`` times, and the medians are printed with the
ratio. Wall time is process start to exit; core time is user + system time of
the process and everything it waited for (``os.wait4``), so the reader's forked
child counts.

Rows: ``surfprep --help`` against ``python -c "import OCP"`` (the floor any OCP
tool pays); a one-line error (a missing file); ``info`` on the fuselage against a
read with the area and type of every face; ``intersect`` of a sphere and a slab
(two STEP files) against ``GeomAPI_IntSS`` on every face pair; ``reparam`` of the
fuselage against ``GeomAPI_PointsToBSplineSurface`` on a 30 x 30 sample of every
face (what it does not guarantee: the tolerance between the samples); ``heal`` of
the Mars capsule against ``BRepBuilderAPI_Sewing`` plus ``ShapeFix_Shape``.

Run:  python benchmarks/cold.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "step_samples"
FUSELAGE = SAMPLES / "occt_fuselage.stp"
CAPSULE = SAMPLES / "overture_marscapsule_proe.igs"
#: the children's environment: a user's shell writes byte code on the first import
#: and reads it afterwards (a sandbox may set PYTHONDONTWRITEBYTECODE, and every
#: fresh process would then recompile surfprep's sources, 0.1-0.2 s)
USER_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}

_READ = """
import sys
from OCP.STEPControl import STEPControl_Reader
from OCP.IGESControl import IGESControl_Reader
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_FACE
from OCP.TopoDS import TopoDS
def read(path):
    reader = IGESControl_Reader() if path.lower().endswith(('.igs', '.iges')) else STEPControl_Reader()
    assert reader.ReadFile(path) == 1
    reader.TransferRoots()
    shape = reader.OneShape()
    faces, ex = [], TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        faces.append(TopoDS.Face_s(ex.Current())); ex.Next()
    return shape, faces
"""

OCC_INFO = _READ + """
from OCP.BRep import BRep_Tool
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.GeomAdaptor import GeomAdaptor_Surface
shape, faces = read(sys.argv[1])
for f in faces:
    p = GProp_GProps(); BRepGProp.SurfaceProperties_s(f, p)
    print(GeomAdaptor_Surface(BRep_Tool.Surface_s(f)).GetType(), p.Mass())
"""

OCC_INTERSECT = _READ + """
from OCP.BRep import BRep_Tool
from OCP.GeomAPI import GeomAPI_IntSS
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.TopoDS import TopoDS_Compound
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
_, fa = read(sys.argv[1]); _, fb = read(sys.argv[2])
out, b = TopoDS_Compound(), BRep_Builder(); b.MakeCompound(out)
for x in fa:
    for y in fb:
        ss = GeomAPI_IntSS(BRep_Tool.Surface_s(x), BRep_Tool.Surface_s(y), 1e-7)
        for k in range(1, ss.NbLines() + 1):
            b.Add(out, BRepBuilderAPI_MakeEdge(ss.Line(k)).Edge())
w = STEPControl_Writer(); w.Transfer(out, STEPControl_AsIs); w.Write(sys.argv[3])
"""

OCC_REPARAM = _READ + """
import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools
from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface
from OCP.TColgp import TColgp_Array2OfPnt
shape, faces = read(sys.argv[1])
for f in faces:
    s = BRep_Tool.Surface_s(f)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(f)
    n = 30
    pts = TColgp_Array2OfPnt(1, n, 1, n)
    for i, u in enumerate(np.linspace(u0, u1, n)):
        for j, v in enumerate(np.linspace(v0, v1, n)):
            pts.SetValue(i + 1, j + 1, s.Value(u, v))
    fit = GeomAPI_PointsToBSplineSurface(pts, 3, 8, 2, 1e-4 * 63550.0)
    assert fit.IsDone()
"""

OCC_HEAL = _READ + """
from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.ShapeFix import ShapeFix_Shape
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
shape, faces = read(sys.argv[1])
sew = BRepBuilderAPI_Sewing(1e-3)
for f in faces:
    sew.Add(f)
sew.Perform()
fix = ShapeFix_Shape(sew.SewedShape()); fix.Perform()
w = STEPControl_Writer(); w.Transfer(fix.Shape(), STEPControl_AsIs); w.Write(sys.argv[2])
"""


def timed(argv: list[str]) -> tuple[float, float, int]:
    """Wall and core seconds of one process, and its exit code."""
    start = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               env=USER_ENV)
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    return time.perf_counter() - start, usage.ru_utime + usage.ru_stime, process.returncode


def operands(folder: Path) -> tuple[Path, Path]:
    """A sphere of radius 10 and a 30 x 30 x 1 slab through it at z = 5, as STEP files."""
    import cadquery as cq

    import surfprep
    a, b = folder / "sphere.step", folder / "slab.step"
    surfprep.write(cq.Workplane().sphere(10), a)
    surfprep.write(cq.Workplane().box(30, 30, 1).translate((0, 0, 5)), b)
    return a, b


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    py, ours = sys.executable, [sys.executable, "-m", "surfprep.plugin"]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        sphere, slab = operands(folder)
        rows = [
            ("--help", ours + ["--help"], [py, "-c", "import OCP.TopoDS"]),
            ("error: missing file", ours + ["info", str(folder / "missing.step")],
             [py, "-c", "import OCP.TopoDS"]),
            ("info fuselage", ours + ["info", str(FUSELAGE), "--json", str(folder / "i.json")],
             [py, "-c", OCC_INFO, str(FUSELAGE)]),
            ("intersect sphere x slab",
             ours + ["intersect", str(sphere), str(slab), "-o", str(folder / "c.step")],
             [py, "-c", OCC_INTERSECT, str(sphere), str(slab), str(folder / "c_occ.step")]),
            ("reparam fuselage", ours + ["reparam", str(FUSELAGE), "-o", str(folder / "r.step")],
             [py, "-c", OCC_REPARAM, str(FUSELAGE)]),
            ("heal capsule", ours + ["heal", str(CAPSULE), "-o", str(folder / "h.step")],
             [py, "-c", OCC_HEAL, str(CAPSULE), str(folder / "h_occ.step")]),
        ]
        print(f"cold one-shot calls, fresh processes, median of {args.repeats} "
              "(ours and OpenCascade's alternating)\n")
        print("| call | ours wall s | ours core s | OCC wall s | OCC core s | wall ours/OCC |")
        print("|---|---|---|---|---|---|")
        for name, mine, theirs in rows:
            a, b = [], []
            for _ in range(args.repeats):
                a.append(timed(mine))
                b.append(timed(theirs))
            ok = {code for _, _, code in a}
            wall_a, core_a = (statistics.median(x[k] for x in a) for k in (0, 1))
            wall_b, core_b = (statistics.median(x[k] for x in b) for k in (0, 1))
            print(f"| {name} (exit {','.join(map(str, sorted(ok)))}) | {wall_a:.2f} | {core_a:.2f} "
                  f"| {wall_b:.2f} | {core_b:.2f} | {wall_a / wall_b:.2f} |", flush=True)
        print("\nOCC rows: --help and the error against importing OCP (the floor of any OCP "
              "tool); info: read + type and area per face; intersect: GeomAPI_IntSS per face "
              "pair at 1e-7 + STEP; reparam: PointsToBSplineSurface on 30 x 30 samples per "
              "face; heal: sewing at 1e-3 + ShapeFix + STEP.")


if __name__ == "__main__":
    main()
