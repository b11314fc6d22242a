"""``surfprep intersect A.step [B.step] -o OUT.step``: intersection curves of faces as edges."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ...errors import OutputFileError
from ..io import read, write
from .base import STDOUT, Command, Console, refuse_overwriting_inputs, write_json_report

__all__ = ["COMMAND", "intersection_report", "compare_with_occ", "plot_curves"]

#: samples per OpenCascade section edge (chord sag about 3e-7 of a unit circle)
OCC_SAMPLES = 4001


def intersection_report(results, time_s: float, tol: float | None, files) -> dict:
    """The JSON report: time, tolerance and one entry per curve."""
    curves = []
    for k, r in enumerate(results):
        dev = r.max_deviation()
        curves.append({
            "index": k,
            "faces": list(r.faces),
            "face_names": [r.face_a.name, r.face_b.name],
            "closed": r.closed,
            "points": int(r.points.shape[0]),
            "length": r.length,
            "max_distance_a": dev.to_a,
            "max_distance_b": dev.to_b,
            "start": r.curve.start_kind,
            "end": r.curve.end_kind,
        })
    return {"files": [str(f) for f in files], "tol": tol, "time_s": time_s,
            "n_curves": len(results), "curves": curves}


def compare_with_occ(results, model_a, model_b) -> dict:
    """OpenCascade's answer beside ours.

    With two files: ``BRepAlgoAPI_Section`` of the two shapes. With one file:
    ``BRepAlgoAPI_Section`` of each face pair we report curves for (a section of
    a shape with itself means nothing; the shared edges of adjacent faces, which
    OpenCascade returns, are left out by taking only our pairs).
    """
    from ...algorithms.intersection import connected_branches, curve_set_distance
    from ..occ_reference import section_faces_occ
    start = time.perf_counter()
    if model_b is not None:
        occ = section_faces_occ(model_a.shape, model_b.shape, samples=OCC_SAMPLES)
        scope = "shapes"
    else:
        occ, seen = [], set()
        for r in results:
            if r.faces in seen:
                continue
            seen.add(r.faces)
            occ.extend(section_faces_occ(model_a.faces[r.faces[0]], model_a.faces[r.faces[1]],
                                         samples=OCC_SAMPLES))
        scope = "face pairs with curves"
    occ_time = time.perf_counter() - start
    ours = [r.curve for r in results]
    join = 10 * max((r.tol for r in results), default=1e-7)
    distance = curve_set_distance(ours, occ) if ours and occ else None
    return {
        "method": "BRepAlgoAPI_Section", "scope": scope, "time_s": occ_time,
        "curves": len(occ), "branches": connected_branches(occ, join),
        "our_branches": connected_branches(ours, join),
        "hausdorff": None if distance is None else distance.hausdorff,
        "length": float(sum(c.length for c in occ)),
        "our_length": float(sum(c.length for c in ours)),
    }


def plot_curves(results, path: Path) -> Path:
    """3D view and both parameter domains of every curve, written to ``path`` (Agg)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=(15, 5))
    ax3 = fig.add_subplot(1, 3, 1, projection="3d")
    axa, axb = fig.add_subplot(1, 3, 2), fig.add_subplot(1, 3, 3)
    colors = plt.get_cmap("tab10")
    for k, r in enumerate(results):
        c = colors(k % 10)
        p = r.points if not r.curve.closed else np.vstack([r.points, r.points[:1]])
        ax3.plot(p[:, 0], p[:, 1], p[:, 2], color=c, lw=1)
        for ax, uv in ((axa, r.curve.uv_a), (axb, r.curve.uv_b)):
            if uv is not None:
                ax.plot(uv[:, 0], uv[:, 1], color=c, lw=1, label=f"{k}: faces {r.faces}")
    ax3.set_title("curves in space")
    axa.set_title("(u, v) on the first face of each pair")
    axb.set_title("(u, v) on the second face of each pair")
    for ax in (axa, axb):
        ax.set_xlabel("u")
        ax.set_ylabel("v")
    if results and len(results) <= 12:
        axb.legend(fontsize="small")
    fig.tight_layout()
    try:
        fig.savefig(path, dpi=110)
    except OSError as exc:
        raise OutputFileError(f"cannot write plot {path}: {exc.strerror or exc}") from None
    finally:
        plt.close(fig)
    return path.resolve()


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file_a", type=Path, metavar="A", help="STEP or IGES file")
    parser.add_argument("file_b", type=Path, metavar="B", nargs="?",
                        help="second file; without it, the faces of A are intersected "
                             "with each other (shared edges left out)")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="STEP/IGES file to write the curves to, as edges")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="tolerance in mm (default 1e-6 x the size of the faces)")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")
    parser.add_argument("--plot", type=Path, metavar="PNG",
                        help="draw the curves in 3D and in the parameter domains")
    parser.add_argument("--compare-occ", action="store_true",
                        help="also run OpenCascade's BRepAlgoAPI_Section and report both")


def _run(args: argparse.Namespace, console: Console) -> int:
    from ..intersect import intersect
    inputs = tuple(p for p in (args.file_a, args.file_b) if p is not None)
    for target in (args.output, args.plot,
                   None if args.json_path in (None, STDOUT) else Path(args.json_path)):
        if target is not None:                       # fail before the work, not after
            refuse_overwriting_inputs(Path(target), inputs)
    model_a = read(args.file_a)
    model_b = read(args.file_b) if args.file_b is not None else None
    start = time.perf_counter()
    results = intersect(model_a, model_b, tol=args.tol,
                        progress=lambda done, total: console.progress(done, total, "face pair"))
    elapsed = time.perf_counter() - start
    tol = results[0].tol if results else args.tol
    report = intersection_report(results, elapsed, tol, inputs)
    if results:
        edges = [e for r in results for e in r.to_edges()]
        written = write(edges, args.output, overwrite=True)
        report["output"] = str(written)
    else:
        report["output"] = None
    if args.compare_occ:
        report["occ"] = compare_with_occ(results, model_a, model_b)
    if args.plot is not None:
        report["plot"] = str(plot_curves(results, args.plot))
    if args.json_path == STDOUT:
        write_json_report(report, STDOUT, console)
    else:
        console.print(f"{len(results)} intersection curve(s) in {elapsed:.3f} s"
                      + (f", written to {report['output']}" if results else
                         f"; nothing written to {args.output}"))
        if args.compare_occ:
            occ = report["occ"]
            h = "-" if occ["hausdorff"] is None else f"{occ['hausdorff']:.3g}"
            console.print(f"OpenCascade: {occ['branches']} branch(es) vs our "
                          f"{occ['our_branches']}, Hausdorff {h}, {occ['time_s']:.3f} s")
        if args.json_path is not None:
            path = write_json_report(report, args.json_path, console, protected=inputs)
            console.note(f"report written to {path}")
    return 0


COMMAND = Command(
    name="intersect",
    summary="intersection curves of the faces of one or two STEP/IGES files, as edges",
    description=(
        "Intersect every pair of faces of A with every face of B (or the faces of A "
        "with each other) whose boxes overlap, clip the curves to both trimmed faces "
        "and write them as edges, each with its 3D curve and a pcurve on both faces. "
        "Every curve lies within the tolerance of both surfaces (checked between the "
        "samples too). The JSON report gives the time spent intersecting (without "
        "start-up and file I/O) and, per curve, the faces, whether it is closed, its "
        "points, length and largest distance from each surface."),
    epilog=(
        "examples:\n"
        "  surfprep intersect wing.step fuselage.step -o cut.step\n"
        "  surfprep intersect part.step -o self.step --json report.json --plot curves.png\n"
        "  surfprep intersect a.stp b.stp -o c.stp --tol 1e-5 --compare-occ --json -\n"
        "\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
