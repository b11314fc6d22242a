"""``surfprep reparam IN.step -o OUT.step``: chord-length (RCA) reparametrization of faces."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ..time_limit import seconds_argument, step_time_limit
from .base import (
    STDOUT,
    Command,
    Console,
    check_inputs,
    check_outputs,
    done_code,
    dropped_report,
    publish,
    read_model,
    repaired_report,
)
from .plotting import pyplot, save_figure

__all__ = ["COMMAND", "plot_isolines"]

#: Isoparametric lines per direction in the plot, and faces plotted at most.
PLOT_LINES, PLOT_FACES = 16, 4


def _isolines(surface, n: int = PLOT_LINES, samples: int = 120) -> list[np.ndarray]:
    u0, u1, v0, v1 = surface.domain
    lines = []
    for u in np.linspace(u0, u1, n):
        lines.append(surface.evaluate(np.full(samples, u), np.linspace(v0, v1, samples)))
    for v in np.linspace(v0, v1, n):
        lines.append(surface.evaluate(np.linspace(u0, u1, samples), np.full(samples, v)))
    return lines


def _plane(points: np.ndarray) -> np.ndarray:
    """The two principal directions of ``points (m, 3)``: ``(3, 2)``."""
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return vt[:2].T


def plot_isolines(pairs, path: Path, *, shown_of: int | None = None) -> Path:
    """Isoparametric lines at equal parameter steps, before and after (Fig. 29.5).

    ``pairs`` is a list of ``(label, old NurbsSurface, new NurbsSurface)``; each
    face is drawn in the plane of its two principal directions. ``shown_of``: how many
    faces were reparametrized, when ``pairs`` holds only some (the title says so).
    """
    plt = pyplot()
    rows = max(1, len(pairs))
    fig, axes = plt.subplots(rows, 2, figsize=(11, 4.2 * rows), squeeze=False)
    for row, (label, old, new) in enumerate(pairs):
        before, after = _isolines(old), _isolines(new)
        basis = _plane(np.vstack(before))
        for ax, lines, title in ((axes[row, 0], before, "before"), (axes[row, 1], after, "after")):
            for k, line in enumerate(lines):
                xy = line @ basis
                ax.plot(xy[:, 0], xy[:, 1], lw=0.7, color="tab:blue" if k < PLOT_LINES
                        else "tab:red")
            ax.set_aspect("equal")
            ax.set_title(f"{label}: {title} (u blue, v red, equal parameter steps)",
                         fontsize="small")
    if shown_of is not None:
        fig.suptitle(f"{len(pairs)} of {shown_of} reparametrized faces shown", fontsize="medium")
    fig.tight_layout()
    return save_figure(fig, path)


#: default --face-time-limit (s): faces of the real files take seconds each
DEFAULT_FACE_TIME_LIMIT = 120.0


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="IN", help="STEP or IGES file")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="STEP/IGES file to write the model with the new faces to")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="tolerance in mm (default 1e-4 x the model's bounding-box diagonal)")
    parser.add_argument("--faces", type=int, nargs="+", metavar="K",
                        help="face indices (file order, from 0); default every B-spline face")
    parser.add_argument("--face-time-limit", type=seconds_argument,
                        default=DEFAULT_FACE_TIME_LIMIT, metavar="S", dest="face_time_limit",
                        help="stop a face that runs longer than S seconds, keep it as it "
                             "was with that reason (exit 1) and go on with the others; 0 for "
                             f"no limit (default {DEFAULT_FACE_TIME_LIMIT:g})")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")
    parser.add_argument("--plot", type=Path, metavar="PNG",
                        help="isoparametric lines before and after (needs matplotlib)")


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = (args.file,)
    check_outputs(inputs, args.output, plot=args.plot, json_path=args.json_path)
    check_inputs(args.file)
    from ..io import staged_write
    from ..occ.geom import surface_from_occ
    from ..reparam import reparametrize_model
    model = read_model(args.file, console, strict=args.strict)
    start = time.perf_counter()
    with step_time_limit(args.face_time_limit, "a face") as restart:
        def progress(done: int, total: int) -> None:
            restart(last=done >= total)
            console.progress(done, total, "face")
        shape, entries = reparametrize_model(model, tol=args.tol, faces=args.faces,
                                             progress=progress)
    elapsed = time.perf_counter() - start
    ok = [e for e in entries if e.done is not None]
    with staged_write(shape, args.output, overwrite=True) as staged:
        written = staged.target
        report = {"file": str(args.file), "output": str(written), "time_s": elapsed,
                  "tol": ok[0].done.result.tol if ok else args.tol,
                  "faces": [e.report() for e in entries], "dropped": dropped_report(model),
                  "repaired": repaired_report(model)}
        if args.plot is not None:
            from OCP.BRep import BRep_Tool
            pairs = [(f"face {e.index}",
                      surface_from_occ(BRep_Tool.Surface_s(model.faces[e.index])),
                      e.done.result.surface) for e in ok[:PLOT_FACES]]
            report["plot"] = str(plot_isolines(
                pairs, args.plot, shown_of=len(ok) if len(ok) > len(pairs) else None))
        report_path = publish(staged, report, args.json_path, console, protected=inputs)
    if args.json_path != STDOUT:
        for e in entries:
            if e.done is None:
                console.print(f"face {e.index}: skipped: {e.error}")
                continue
            r, d = e.done.result, e.done
            console.print(
                f"face {e.index}: mismatch {r.mismatch_before:.3g} -> {r.mismatch_after:.4g}, "
                f"max deviation {r.max_deviation:.3g} (tol {r.tol:.3g}), poles "
                f"{d.poles_before} -> {d.poles_after}, {e.time_s:.2f} s")
        console.print(f"{len(ok)} of {len(entries)} face(s) reparametrized in {elapsed:.2f} s, "
                      f"written to {written}")
        if report_path is not None:
            console.note(f"report written to {report_path}")
    return done_code(model, skipped=len(ok) != len(entries))


COMMAND = Command(
    name="reparam",
    summary="chord-length (RCA) reparametrization of B-spline faces within a tolerance",
    description=(
        "Replace the surface of every B-spline face (or the listed ones) by a C2 bicubic "
        "B-spline whose parameters follow arc length (Hamann, Jean, Razdan, section 29.2): "
        "within the tolerance of the original both ways, measured densely (>= 10 x 10 "
        "points per knot span, closest-point projection). The faces keep their edges, "
        "with new pcurves, so shells stay connected. Per face the report gives the "
        "chord-length mismatch (eqs. 29.1/29.2, 1 = perfect) before and after, the "
        "max deviation, the pole counts and the areas. Creases (knot lines where the "
        "surface turns) stay creases (C0 knot lines of the new surface). A face that "
        "cannot be done (not a B-spline, tolerance not reached, mismatch would get "
        "worse) keeps its surface and is reported as skipped; the exit code is then 1."),
    epilog=(
        "examples:\n"
        "  surfprep reparam fuselage.stp -o fuselage_rca.stp\n"
        "  surfprep reparam part.step -o out.step --faces 0 3 --tol 0.01 --json r.json\n"
        "  surfprep reparam part.step -o out.step --plot isolines.png\n"
        "\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
