"""``surfprep compose A.g2 B.g2``: two trivariate NURBS solids composed (004)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ...errors import InputFileError
from .base import STDOUT, Command, Console, check_outputs, write_json_report

__all__ = ["COMMAND"]


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("a", type=Path, metavar="A", help="GoTools .g2 file holding a solid (class 700)")
    parser.add_argument("b", type=Path, metavar="B", help="GoTools .g2 file holding a solid")
    parser.add_argument("-o", "--output", type=Path, metavar="CURVES",
                        help="write the curves where the boundaries meet as edges to a STEP or "
                             "IGES file")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="tolerance in model units (default 1e-6 x the solids' box diagonal)")
    parser.add_argument("--classify", type=Path, metavar="POINTS",
                        help="CSV of points, one 'x,y,z' a line, to classify")
    parser.add_argument("--labels", type=Path, metavar="LABELS",
                        help="write one label a line for --classify's points: 0 outside both, "
                             "1 in A only, 2 in B only, 3 in both")
    parser.add_argument("--volumes", action="store_true",
                        help="also OpenCascade's volumes of A only, B only and both (the common "
                             "solid of the boundaries cut along the curves, integrated by "
                             "GProp), to cross-check ours")
    parser.add_argument("--shell", type=Path, metavar="OUT",
                        help="write a boundary as OpenCascade solids to a STEP or IGES file "
                             "(which one: --boundary)")
    parser.add_argument("--boundary", choices=("both", "union", "common", "A-B"),
                        default="both",
                        help="with --shell: both solids' boundaries (default), or the boundary "
                             "of their union, common part or A minus B (cut along the curves)")
    parser.add_argument("--plot", type=Path, metavar="PNG",
                        help="draw the boundaries, overlap boxes, local triangulations and "
                             "loops of 004's hierarchy (needs matplotlib)")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")


def _solid(path: Path):
    from ...algorithms.io import read_g2
    from ...algorithms.volume import NurbsVolume
    if not path.is_file():
        raise InputFileError(f"{path}: no such file")
    solids = [o for o in read_g2(path) if isinstance(o, NurbsVolume)]
    if len(solids) != 1:
        raise InputFileError(f"{path}: expected one solid (class 700), found {len(solids)}")
    return solids[0]


def _points(path: Path) -> np.ndarray:
    try:
        points = np.loadtxt(path, delimiter=",", ndmin=2)
    except (OSError, ValueError) as exc:
        raise InputFileError(f"{path}: cannot read points ({exc})") from None
    if points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise InputFileError(f"{path}: expected finite 'x,y,z' lines")
    return points


def _curves_report(result) -> list[dict]:
    faces_a, faces_b = result.a.exterior_faces(), result.b.exterior_faces()
    out = []
    for fa, fb, c in result.curves:
        out.append({"face_a": fa, "face_b": fb, "points": int(c.points.shape[0]),
                    "length": float(c.length), "closed": bool(c.closed),
                    "max_distance": float(c.max_deviation(faces_a[fa], faces_b[fb]).max)})
    return out


def _run(args: argparse.Namespace, console: Console) -> int:
    from ...algorithms.composition import compose
    from ...atomic_files import atomic_output
    inputs = (args.a, args.b) + ((args.classify,) if args.classify is not None else ())
    check_outputs(inputs, args.output, plot=args.plot, json_path=args.json_path)
    if (args.classify is None) != (args.labels is None):
        raise InputFileError("--classify and --labels go together")
    if args.labels is not None:
        check_outputs(inputs, args.labels, model=False)
    if args.shell is not None:
        check_outputs(inputs, args.shell)
    a, b = _solid(args.a), _solid(args.b)
    points = _points(args.classify) if args.classify is not None else None
    times = {}
    started = time.perf_counter()
    result = compose(a, b, tol=args.tol)
    times["curves"] = result.time_s
    clock = time.perf_counter()
    hierarchy = result.hierarchy
    times["hierarchy"] = time.perf_counter() - clock
    clock = time.perf_counter()
    volumes = result.volumes
    times["volumes"] = time.perf_counter() - clock
    labels = None
    if points is not None:
        clock = time.perf_counter()
        labels = result.classify(points)
        times["classification"] = time.perf_counter() - clock
    elapsed = time.perf_counter() - started
    report = {"a": str(args.a), "b": str(args.b), "tol": result.tol, "time_s": elapsed,
              "times": times,
              "volume_A": a.volume(), "volume_B": b.volume(), "volume_common": volumes.both,
              "volume_union": volumes.union, "volumes": volumes.as_dict(),
              "curves": _curves_report(result),
              "hierarchy": {**hierarchy.counts(), "mesh_tol": hierarchy.mesh_tol,
                            "candidates": hierarchy.candidates, "times": hierarchy.times,
                            "loop_gap": max((float(lp.gap.max()) for lp in hierarchy.loops),
                                            default=0.0)}}
    if labels is not None:
        report["labels"] = {str(k): int(np.sum(labels == k)) for k in range(4)}
        with atomic_output(args.labels) as temporary:
            temporary.write_text("".join(f"{int(x)}\n" for x in labels))
    if args.output is not None:
        report["output"] = _write_curves(result, args.output)
    if args.volumes:
        from ..volume_boundary import composed_volumes
        report["volumes_occ"] = composed_volumes(a, b, tol=args.tol).as_dict()
    if args.shell is not None:
        report["boundary"] = _write_boundary(a, b, args.shell, args.boundary, args.tol)
    if args.plot is not None:
        from .compose_plot import plot_composition
        report["plot"] = str(plot_composition(result, args.plot))
    if args.json_path is not None:
        write_json_report(report, args.json_path, console, protected=inputs)
    if args.json_path != STDOUT:
        _print(console, report, args)
    return 0


def _print(console: Console, report: dict, args: argparse.Namespace) -> None:
    h = report["hierarchy"]
    console.print(f"{len(report['curves'])} curve(s) where the boundaries meet; volumes A "
                  f"{report['volume_A']:.10g}, B {report['volume_B']:.10g}, common "
                  f"{report['volume_common']:.10g}, union {report['volume_union']:.10g}; "
                  f"{report['time_s']:.2f} s")
    console.print(f"hierarchy: {h['bezier_patches_a']} + {h['bezier_patches_b']} Bezier patches, "
                  f"{h['overlap_boxes']} overlap boxes, {h['triangles']} triangles, "
                  f"{h['loops']} loop(s)")
    if "labels" in report:
        console.print("labels: " + ", ".join(f"{k}: {v}" for k, v in report["labels"].items())
                      + f", written to {args.labels}")
    if "output" in report:
        console.print(f"curves written to {report['output']}")
    if args.volumes:
        v = report["volumes_occ"]
        console.print(f"OpenCascade's volumes: A only {v['A only']:.10g}, B only "
                      f"{v['B only']:.10g}, both {v['both']:.10g} ({v['time_s']:.2f} s)")
    if args.shell is not None:
        written = report["boundary"]
        console.print(f"{written['which']}: " + "; ".join(
            f"{k} {'solid' if w['closed'] else 'open shell'} of {len(w['faces'])} "
            f"face(s), OpenCascade volume {w['volume']:.10g}"
            for k, w in written["solids"].items()) + f", written to {written['output']}")
    if "plot" in report:
        console.print(f"plot written to {report['plot']}")


def _write_curves(result, path: Path) -> str | None:
    """The curves' 3D interpolants as edges; None (nothing written) when there is none."""
    from ..io import write
    curves = [c.curve3d for _, _, c in result.curves if c.curve3d is not None]
    return str(write(curves, path, overwrite=True)) if curves else None


#: --boundary's Boolean operations (surfprep.boolean's names)
_OPERATIONS = {"union": "fuse", "common": "common", "A-B": "cut"}


def _write_boundary(a, b, path: Path, which: str, tol) -> dict:
    """Both solids' boundaries, or the boundary of their union / common part / A minus B
    (:func:`surfprep.boolean` of the boundary solids), written to ``path``."""
    from ..io import write
    from ..occ.shapes import compound, count_free_edges
    from ..split import boolean
    from ..volume_boundary import boundary_solid
    solids = {"A": boundary_solid(a), "B": boundary_solid(b)}
    if which == "both":
        shape = compound([s.shape for s in solids.values()])
        figures = {k: {"faces": list(s.faces), "closed": s.closed, "free_edges": s.free_edges,
                       "volume": s.volume} for k, s in solids.items()}
    else:
        result = boolean(solids["A"].shape, solids["B"].shape, _OPERATIONS[which], tol=tol)
        shape = result.shape
        pieces = [f"A piece {k}" for k in range(result.kept[0])] + \
            [f"B piece {k}" for k in range(result.kept[1])]
        figures = {which: {"faces": pieces,
                           "closed": result.volume is not None,
                           "free_edges": count_free_edges(shape),
                           "volume": float("nan") if result.volume is None else result.volume}}
    return {"which": which, "solids": figures, "output": str(write(shape, path, overwrite=True))}


COMMAND = Command(
    name="compose",
    summary="two trivariate NURBS solids (.g2): where their boundaries meet, which points lie in which",
    description=(
        "Read two solids from GoTools .g2 files, intersect their exterior boundary surfaces "
        "(collapsed faces and seams left out) and report the curves, 004's hierarchy (Bezier "
        "patches, overlap boxes, local triangulations, loops) and the volumes of the common "
        "part and the union (divergence theorem over the faces cut along the curves); "
        "with --classify, label "
        "each point 0 outside both, 1 in A only, 2 in B only, 3 in both (ray parity on each "
        "solid's exact boundary); with --shell, write both solids' boundaries (their non-degenerate "
        "exterior faces, oriented outward, sewn) as OpenCascade solids to STEP or IGES, or "
        "with --boundary union|common|A-B the boundary of that region (the boundary solids "
        "cut along the curves); with --volumes, OpenCascade's volumes as a cross-check."),
    epilog=("examples:\n"
            "  surfprep compose a.g2 b.g2 --json r.json -o curves.step --plot composed.png\n"
            "  surfprep compose a.g2 b.g2 --classify points.csv --labels labels.csv\n"
            "  surfprep compose a.g2 b.g2 --shell both.step --volumes\n"
            "  surfprep compose a.g2 b.g2 --boundary common --shell lens.step"),
    add_arguments=_add_arguments,
    run=_run,
)
