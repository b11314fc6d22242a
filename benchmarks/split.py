"""Booleans from split pieces: ``surfprep.boolean`` against OpenCascade's BRepAlgoAPI.

Three pairs of solids whose fuse, cut and common volumes are known exactly: a
sphere (r = 10) through a 1 mm slab, a cylinder (r = 3, length 20) through a
10 mm cube, two spheres (r = 5) 6 apart (a lens: pi (4r + d)(2r - d)^2 / 12).
For each operation: our volume and OpenCascade's (GProp at 1e-9, not timed), their
errors against the exact value, validity, and the times of the calls in one warm
process (the intersection, the splitting, the classification and the sewing for
ours; the Boolean for OpenCascade).

Real B-spline models cut by a plane, ``surfprep.split(model, plane, tool=True)``
against ``BRepAlgoAPI_Splitter`` (the model as argument, the plane as tool), warm:
overture_kcs_hull_ideas.igs (a ship hull of trimmed B-spline faces) at a waterline
(37 % of its depth) and occt_k1_catia_debis.stp (a closed CATIA solid, 70 trimmed
faces) at half its height: the pieces, validity, the largest edge tolerance of the
result (OpenCascade raises tolerances where its section curves are poor), the area
kept, and the exact answer: every cut edge lies in the plane, so its largest
|z - z0| on 200 points an edge is the error of the section curves.

Two B-spline surfaces: the bundled fuselage (``step_samples/occt_fuselage.stp``, 8
bicubic faces) cut by a wing-like B-spline solid (``step_samples/synthetic_wing.step``:
a closed cambered spline section lofted through the body), ``surfprep.split(fuselage, wing)`` against OpenCascade's
General Fuse of the two (``BRepAlgoAPI_BuilderAlgo``, both as arguments, which splits
both), ours at its default tolerance (1e-6 of the size) and at 1e-3 mm: faces,
validity, the largest edge tolerance, the time, and the intersection
edges (the result's edges lying on both inputs) measured densely -- the largest
distance of 50 points an edge from the fuselage and from the wing
(``BRepExtrema_DistShapeShape``).

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


DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def _cut_edges_off_plane(shape, z0: float, band: float) -> tuple[int, float]:
    """Edges of ``shape`` lying within ``band`` of the plane z = z0 at their middle (the
    cut edges), and the largest |z - z0| on 200 points of each."""
    import numpy as np
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    count, worst = 0, 0.0
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current()))
        t = np.linspace(curve.FirstParameter(), curve.LastParameter(), 200)
        z = np.array([curve.Value(x).Z() for x in t])
        if abs(z[100] - z0) < band and np.ptp(z) < band:
            count += 1
            worst = max(worst, float(np.max(np.abs(z - z0))))
        explorer.Next()
    return count, worst


def _plane_cut(name: str, fraction: float, label: str) -> list[str]:
    """A real model cut by the plane at ``fraction`` of its height: ours against
    BRepAlgoAPI_Splitter (see the module doc)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Splitter
    from OCP.TopTools import TopTools_ListOfShape

    import surfprep
    from surfprep.plugin.occ.shapes import all_faces, face_area, max_edge_tolerance
    from surfprep.plugin.split import split
    model = surfprep.read(DATA / name)
    xmin, ymin, zmin, xmax, ymax, zmax = model.bounding_box
    z0 = zmin + fraction * (zmax - zmin)
    plane = cq.Workplane("XY").rect(3 * (xmax - xmin), 3 * (ymax - ymin)).extrude(0.001)
    plane = plane.faces(">Z").val().translate(cq.Vector((xmin + xmax) / 2, (ymin + ymax) / 2,
                                                        z0 - 0.001))
    area = face_area(model.shape, 1e-9)
    band = 1e-3 * (zmax - zmin)
    split(model, plane, tool=True)            # warm: the kernels load on the first call
    start = time.perf_counter()
    ours = split(model, plane, tool=True)
    t_ours = time.perf_counter() - start
    kept_whole = sum(f.kept is not None for f in ours.faces)
    start = time.perf_counter()
    splitter = BRepAlgoAPI_Splitter()
    arguments, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
    arguments.Append(model.shape)
    tools.Append(plane.wrapped)
    splitter.SetArguments(arguments)
    splitter.SetTools(tools)
    splitter.Build()
    t_occ = time.perf_counter() - start
    rows = [(f"| {label} | faces out | valid | max edge tolerance | area kept (rel.) | "
             "cut edges | largest \\|z - z0\\| on them | s |"),
            "|---|---|---|---|---|---|---|---|"]
    for who, shape, seconds, ok in ((f"surfprep.split ({kept_whole} face(s) kept whole)", ours.shape,
                                     t_ours, ours.valid),
                                    ("BRepAlgoAPI_Splitter", splitter.Shape(), t_occ,
                                     BRepCheck_Analyzer(splitter.Shape()).IsValid())):
        edges, off = _cut_edges_off_plane(shape, z0, band)
        kept = abs(face_area(shape, 1e-9) - area) / area
        rows.append(f"| {who} | {len(all_faces(shape))} | {ok} | {max_edge_tolerance(shape):.1e} | "
                    f"{kept:.1e} | {edges} | {off:.1e} | {seconds:.2f} |")
        print(rows[-1], flush=True)
    return rows


def _on_both(shape, a, b, near: float, samples: int = 50) -> tuple[int, float]:
    """Edges of ``shape`` whose middle lies within ``near`` of both ``a`` and ``b`` (the
    intersection edges), and the largest distance from either of ``samples`` points on
    each."""
    import numpy as np
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedMapOfShape

    def distance(point, target) -> float:
        d = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(point).Vertex(), target)
        return d.Value() if d.IsDone() else float("inf")
    count, worst = 0, 0.0
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)           # each edge once, however many faces use it
    for k in range(1, edges.Extent() + 1):
        curve = BRepAdaptor_Curve(TopoDS.Edge_s(edges.FindKey(k)))
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        middle = curve.Value(0.5 * (t0 + t1))
        if distance(middle, a) > near or distance(middle, b) > near:
            continue
        count += 1
        for t in np.linspace(t0, t1, samples):
            p = curve.Value(t)
            worst = max(worst, distance(p, a), distance(p, b))
    return count, worst


def _wing_fuselage() -> list[str]:
    """The fuselage cut by the wing: ours against OpenCascade's General Fuse."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_BuilderAlgo
    from OCP.TopTools import TopTools_ListOfShape

    import surfprep
    from surfprep.plugin.occ.shapes import max_edge_tolerance
    from surfprep.plugin.split import split
    samples = Path(__file__).resolve().parents[1] / "step_samples"
    fuselage = surfprep.read(samples / "occt_fuselage.stp")
    wing = surfprep.read(samples / "synthetic_wing.step")
    split(fuselage, wing)                 # warm: the kernels load on the first call
    runs = []
    for tol in (None, 1e-3):
        start = time.perf_counter()
        ours = split(fuselage, wing, tol=tol)
        runs.append((f"surfprep.split, tol {ours.curves.tol:.2g}" + (" (default)" if tol is None else ""),
                     ours.shape, time.perf_counter() - start, ours.valid))
    start = time.perf_counter()
    builder = BRepAlgoAPI_BuilderAlgo()
    arguments = TopTools_ListOfShape()
    arguments.Append(fuselage.shape)
    arguments.Append(wing.shape)
    builder.SetArguments(arguments)
    builder.Build()
    t_occ = time.perf_counter() - start
    near = 1e-5 * fuselage.size
    rows = [("| fuselage cut by a wing | faces out | valid | max edge tolerance | intersection "
             "edges | their largest distance from fuselage / wing | s |"),
            "|---|---|---|---|---|---|---|"]
    runs.append(("BRepAlgoAPI_BuilderAlgo (General Fuse)", builder.Shape(), t_occ,
                 builder.IsDone() and BRepCheck_Analyzer(builder.Shape()).IsValid()))
    for name, shape, seconds, ok in runs:
        edges, off = _on_both(shape, fuselage.shape, wing.shape, near)
        rows.append(f"| {name} | {_unique_faces(shape)} | {ok} | {max_edge_tolerance(shape):.1e} | "
                    f"{edges} | {off:.1e} | {seconds:.2f} |")
        print(rows[-1], flush=True)
    return rows


def _unique_faces(shape) -> int:
    """Faces of ``shape``, each once (the General Fuse's split solids share faces, which
    exploring would visit once per solid)."""
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopTools import TopTools_IndexedMapOfShape
    unique = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, unique)
    return unique.Extent()


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
    for k, (name, a, b, exact) in enumerate(_pairs()):
        if k == 0:
            boolean(a, b, "common")           # warm: the kernels load on the first call
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
    lines += ["", *_wing_fuselage()]
    if DATA.is_dir():
        lines += ["", *_plane_cut("overture_kcs_hull_ideas.igs", 0.37, "hull at a waterline")]
        lines += ["", *_plane_cut("occt_k1_catia_debis.stp", 0.5, "K1 solid (CATIA) at mid-height")]
    text = "\n".join(lines) + "\n"
    if not args.no_write:
        RESULTS.write_text(text)
        print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
