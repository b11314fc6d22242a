"""``surfprep intersect A.step [B.step] -o OUT.step``: intersection curves of faces as edges."""

from __future__ import annotations

import argparse
import time
from contextlib import ExitStack
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

__all__ = [
    "COMMAND",
    "PLOT_FACE_PANELS",
    "compare_with_occ",
    "equal_extent",
    "intersection_report",
    "plot_characteristic",
    "plot_curves",
    "widen_flat_axis",
]

#: values of --method (plugin.intersect_methods.Method; not imported to build the parser)
METHODS = ("auto", "mesh", "characteristic")
#: default --pair-time-limit (s): the slowest pair of the real files takes 14 s
DEFAULT_PAIR_TIME_LIMIT = 120.0
#: samples per OpenCascade section edge (chord sag about 3e-7 of a unit circle)
OCC_SAMPLES = 4001


def intersection_report(results, time_s: float, tol: float | None, files) -> dict:
    """The JSON report: the files, the tolerance, the time and what the result reports
    (:meth:`surfprep.plugin.intersect.IntersectionResult.report`)."""
    return {"files": [str(f) for f in files], "tol": tol, "time_s": time_s, **results.report()}


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


#: at most this many faces get a (u, v) panel in --plot (the title says how many more)
PLOT_FACE_PANELS = 8


def equal_extent(points: np.ndarray, floor: float) -> tuple[np.ndarray, float]:
    """Centre and half-width of a cube (or square) holding ``points (m, d)``, the half-width
    at least ``floor``: equal axes that do not blow rounding noise up to the whole plot."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    return 0.5 * (lo + hi), max(0.5 * float(np.max(hi - lo)) * 1.05, floor)


def widen_flat_axis(ax) -> None:
    """An axis whose data spans less than 1e-6 of the other's (a curve along an
    iso-parameter line, drawn over rounding noise) gets the other's span, centred."""
    ax.relim()
    (x0, y0), (x1, y1) = ax.dataLim.get_points()
    wx, wy = x1 - x0, y1 - y0
    if not (np.isfinite(wx) and np.isfinite(wy)):
        return
    if wy < 1e-6 * wx:
        ax.set_ylim(0.5 * (y0 + y1) - 0.5 * wx, 0.5 * (y0 + y1) + 0.5 * wx)
    elif wx < 1e-6 * wy:
        ax.set_xlim(0.5 * (x0 + x1) - 0.5 * wy, 0.5 * (x0 + x1) + 0.5 * wy)


def plot_curves(results, path: Path, *, two_models: bool = True) -> Path:
    """The curves in space (equal axes) and in each face's own (u, v) domain, one panel
    per face, written to ``path`` (Agg); ``two_models`` False when a model was intersected
    with itself (every face is then of the same model)."""
    plt = pyplot()
    pairs = _characteristic_pairs(results)
    faces: dict[tuple[str, int], list] = {}
    for k, r in enumerate(results):
        for side, operand, uv in (("A", r.face_a, r.curve.uv_a), ("B", r.face_b, r.curve.uv_b)):
            if uv is not None:
                key = (side if two_models else "A", operand.index)
                faces.setdefault(key, [operand.surface.domain]).append((k, uv, r.curve.closed))
    shown = sorted(faces)[:PLOT_FACE_PANELS]
    cols = 3
    top = 1 + len(shown)
    top_rows = -(-top // cols)
    rows = top_rows + len(pairs)
    fig = plt.figure(figsize=(15, 5 * rows))
    ax3 = fig.add_subplot(rows, cols, 1, projection="3d")
    colors = plt.get_cmap("tab10")
    if not results:
        ax3.set_axis_off()
        ax3.text2D(0.5, 0.5, "no intersection curve", ha="center", va="center",
                   transform=ax3.transAxes, fontsize="large")
    else:
        everything = np.vstack([r.points for r in results])
        size = float(np.linalg.norm(everything.max(axis=0) - everything.min(axis=0)))
        scale = max(size, float(np.max(np.abs(everything))), 1.0)
        centre, half = equal_extent(everything, 1e-6 * scale)
        for k, r in enumerate(results):
            p = r.points if not r.curve.closed else np.vstack([r.points, r.points[:1]])
            ax3.plot(p[:, 0], p[:, 1], p[:, 2], color=colors(k % 10), lw=1)
        for axis, c in zip("xyz", centre):
            getattr(ax3, f"set_{axis}lim")(c - half, c + half)
        ax3.set_box_aspect((1, 1, 1))
        ax3.set_xlabel("x")
        ax3.set_ylabel("y")
        ax3.set_zlabel("z")
    hidden = len(faces) - len(shown)
    ax3.set_title(f"{len(results)} curve(s) in space (equal axes)"
                  + (f"; {hidden} more face(s) not drawn in (u, v)" if hidden else ""))
    for slot, key in enumerate(shown, start=2):
        ax = fig.add_subplot(rows, cols, slot)
        (u0, u1, v0, v1), *curves = faces[key]
        for k, uv, closed in curves:
            uv = np.vstack([uv, uv[:1]]) if closed else uv
            ax.plot(uv[:, 0], uv[:, 1], color=colors(k % 10), lw=1, label=f"curve {k}")
        ax.set_xlim(u0, u1)                                 # the face's own domain
        ax.set_ylim(v0, v1)
        ax.set_xlabel("u")
        ax.set_ylabel("v")
        ax.set_title(f"face {key[1]} of {key[0] if two_models else 'the model'}: (u, v) domain")
        if len(curves) <= 8:
            ax.legend(fontsize="small")
    for k, pair in enumerate(pairs):
        base = cols * (top_rows + k)
        ax_r, ax_q = fig.add_subplot(rows, cols, base + 1), fig.add_subplot(rows, cols, base + 2)
        plot_characteristic(ax_r, ax_q, pair)
        note = fig.add_subplot(rows, cols, base + 3)
        note.axis("off")
        counts = pair.record.counts()
        text = "\n".join([f"{kind}: {n}" for kind, n in sorted(counts.items())]
                         + [f"characteristic curves: {len(pair.record.characteristic_curves)}",
                            f"curves (before clipping): {len(pair.curves)}",
                            f"found only by characteristic: {len(pair.record.added)}",
                            "curves: red mesh, black characteristic",
                            "dashed: u- (blue), v- (green)",
                            "        characteristic curves"])
        note.text(0.0, 1.0, text, va="top", fontsize="small", family="monospace")
    fig.tight_layout()
    return save_figure(fig, path)


#: marker and colour of each characteristic point kind in --plot (paper Fig. 3 style)
_KIND_STYLE = {
    "border": ("s", "black"), "edge_root_u": ("|", "tab:blue"), "edge_root_v": ("_", "tab:green"),
    "turning_u": ("<", "tab:green"), "turning_v": ("^", "tab:blue"),
    "maximum": ("o", "tab:red"), "minimum": ("o", "tab:purple"), "saddle": ("X", "tab:orange"),
    "degenerate": ("D", "grey"), "isolated": ("*", "magenta"), "double_point": ("P", "brown"),
    "cusp": ("d", "brown"),
}


def plot_characteristic(ax_r, ax_q, pair) -> None:
    """One face pair on two axes: ``phi``'s domain (characteristic curves, points by kind,
    intersection curves) and the other surface's domain (curves, points' feet)."""
    rec = pair.record
    swapped = rec.phi_on == "b"
    for c in rec.characteristic_curves:
        style = {"color": "tab:blue" if c.kind.value == "u" else "tab:green", "lw": 0.7, "ls": "--"}
        ax_r.plot(c.uv[:, 0], c.uv[:, 1], **style)
        ax_q.plot(c.st[:, 0], c.st[:, 1], **style)
    for curve, how in zip(rec.curves, rec.found_by):
        color = "tab:red" if how.value == "mesh" else "black"
        for ax, uv in ((ax_r, curve.uv_b if swapped else curve.uv_a),
                       (ax_q, curve.uv_a if swapped else curve.uv_b)):
            if uv is None:
                continue
            uv = np.vstack([uv, uv[:1]]) if curve.closed else uv
            ax.plot(uv[:, 0], uv[:, 1], color=color, lw=1.6)
    seen = set()
    for p in rec.points:
        marker, color = _KIND_STYLE.get(p.kind.value, (".", "grey"))
        on_r, on_q = (p.uv_b, p.uv_a) if swapped else (p.uv_a, p.uv_b)
        label = p.kind.value if p.kind.value not in seen else None
        seen.add(p.kind.value)
        ax_r.plot(*on_r, marker=marker, color=color, ls="", ms=6, label=label)
        ax_q.plot(*on_q, marker=marker, color=color, ls="", ms=6)
    faces = (pair.face_a.index, pair.face_b.index)
    names = ("b", "a") if swapped else ("a", "b")
    for ax in (ax_r, ax_q):
        widen_flat_axis(ax)
    ax_r.set_title(f"faces {faces}: phi on {names[0]} (u, v)", fontsize="small")
    ax_q.set_title(f"faces {faces}: feet on {names[1]} (s, t)", fontsize="small")
    if seen:
        ax_r.legend(fontsize="x-small", loc="best")


def _characteristic_pairs(results, limit: int = 4) -> list:
    records = getattr(results, "records", [])
    with_points = [r for r in records if r.record is not None and (r.record.points or r.curves)]
    return with_points[:limit]


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file_a", type=Path, metavar="A",
                        help="STEP or IGES file, or a mesh: STL, OBJ or a Plot3D surface grid "
                             "(.xyz .p3d .x .g .grd; then B is needed)")
    parser.add_argument("file_b", type=Path, metavar="B", nargs="?",
                        help="second file (STEP, IGES, STL, OBJ or Plot3D); without it, the faces of "
                             "A are intersected with each other (shared edges left out)")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="STEP/IGES file to write the curves to, as edges")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="tolerance in mm (default 1e-6 x the size of the faces)")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")
    parser.add_argument("--plot", type=Path, metavar="PNG",
                        help="draw the curves in 3D and in the parameter domains, and for "
                             "up to 4 face pairs the characteristic curves and points by "
                             "kind in both domains (paper 002, Fig. 3)")
    parser.add_argument("--compare-occ", action="store_true",
                        help="also run OpenCascade's BRepAlgoAPI_Section and report both")
    parser.add_argument("--method", choices=METHODS, default="auto",
                        help="auto (default): triangles, then characteristic points as a "
                             "certificate (missed loops traced and added), and the "
                             "characteristic method for pairs that cross at a small angle; "
                             "mesh: triangles only; characteristic: the characteristic-curve "
                             "method only")
    parser.add_argument("--pair-time-limit", type=seconds_argument, default=DEFAULT_PAIR_TIME_LIMIT,
                        metavar="S",
                        help="stop a face pair that runs longer than S seconds, report it "
                             "(its curves are missing, exit 1) and go on with the others; "
                             f"0 for no limit (default {DEFAULT_PAIR_TIME_LIMIT:g})")


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = tuple(p for p in (args.file_a, args.file_b) if p is not None)
    check_outputs(inputs, args.output, plot=args.plot, json_path=args.json_path)
    from ..file_format import is_mesh_file
    if any(is_mesh_file(p) for p in inputs):
        return _run_with_mesh(args, console, inputs)
    check_inputs(*inputs)
    from ..intersect import intersect
    from ..io import staged_write
    model_a = read_model(args.file_a, console, strict=args.strict)
    model_b = read_model(args.file_b, console, strict=args.strict) if args.file_b is not None \
        else None
    start = time.perf_counter()
    with step_time_limit(args.pair_time_limit, "a face pair") as restart:
        def progress(done: int, total: int) -> None:
            restart(last=done >= total)
            console.progress(done, total, "face pair")
        results = intersect(model_a, model_b, tol=args.tol, method=args.method,
                            progress=progress)
    elapsed = time.perf_counter() - start
    tol = results[0].tol if results else args.tol
    report = intersection_report(results, elapsed, tol, inputs)
    report["dropped"] = dropped_report(model_a, model_b)
    report["repaired"] = repaired_report(model_a, model_b)
    with ExitStack() as stack:
        staged = None
        if results:
            edges = [e for r in results for e in r.to_edges()]
            staged = stack.enter_context(staged_write(edges, args.output, overwrite=True))
        report["output"] = None if staged is None else str(staged.target)
        if args.compare_occ:                 # one OpenCascade call: say what runs, and for how long
            console.progress(0, 1, "OpenCascade section (BRepAlgoAPI_Section)")
            report["occ"] = compare_with_occ(results, model_a, model_b)
            console.progress(1, 1, "OpenCascade section (BRepAlgoAPI_Section)")
        if args.plot is not None:
            report["plot"] = str(plot_curves(results, args.plot,
                                             two_models=args.file_b is not None))
        report_path = publish(staged, report, args.json_path, console, protected=inputs)
    if args.json_path == STDOUT:
        return done_code(model_a, model_b, skipped=bool(results.stopped))
    console.print(f"{len(results)} intersection curve(s) in {elapsed:.3f} s"
                  + (f", written to {report['output']}" if results else
                     f"; nothing written to {args.output}"))
    added = sum(1 for c in report["curves"] if c["found_by"] == "characteristic")
    if args.method == "auto" and added:
        console.print(f"{added} of them found only by the characteristic method")
    if report.get("isolated_points"):
        console.print(f"{len(report['isolated_points'])} isolated (tangential contact) "
                      "point(s)")
    for c in report.get("coincident", []):
        console.print(f"faces {c['faces']} coincide over {100 * c['share']:.0f} % of one of "
                      f"them (within {c['max_distance']:.2g})")
    if args.compare_occ:
        occ = report["occ"]
        h = "-" if occ["hausdorff"] is None else f"{occ['hausdorff']:.3g}"
        console.print(f"OpenCascade: {occ['branches']} branch(es) vs our "
                      f"{occ['our_branches']}, Hausdorff {h}, {occ['time_s']:.3f} s")
    for p in results.stopped:
        console.note(f"note: faces {p.faces[0]} and {p.faces[1]} stopped after "
                     f"{p.time_s:.0f} s (--pair-time-limit): their curves are missing")
    if report_path is not None:
        console.note(f"report written to {report_path}")
    return done_code(model_a, model_b, skipped=bool(results.stopped))


def _run_with_mesh(args: argparse.Namespace, console: Console, inputs) -> int:
    """An STL mesh or a Plot3D surface grid against the faces of a STEP/IGES file
    (:func:`surfprep.plugin.intersect.mesh_operand.intersect_mesh`)."""
    from ...errors import InputFileError
    from ..file_format import is_mesh_file
    from ..intersect.mesh_operand import intersect_mesh, read_mesh
    meshes = [p for p in inputs if is_mesh_file(p)]
    if len(inputs) < 2 or len(meshes) == 2:
        raise InputFileError("a mesh (STL or Plot3D) is intersected with the faces of a STEP or "
                             "IGES file: give one of each")
    if args.plot is not None or args.compare_occ:
        raise InputFileError("--plot and --compare-occ are for two STEP/IGES files, not a mesh")
    mesh_path = meshes[0]
    cad_path = next(p for p in inputs if p is not mesh_path)
    if not Path(mesh_path).is_file():
        raise InputFileError(f"input file {mesh_path} does not exist")
    check_inputs(cad_path)
    from ..io import staged_write
    model = read_model(cad_path, console, strict=args.strict)
    mesh = read_mesh(mesh_path)
    start = time.perf_counter()
    with step_time_limit(args.pair_time_limit, "a face") as restart:
        def progress(done: int, total: int) -> None:
            restart(last=done >= total)
            console.progress(done, total, "face")
        results = intersect_mesh(mesh, model, tol=args.tol, progress=progress)
    elapsed = time.perf_counter() - start
    report = {"files": [str(f) for f in inputs], "mesh_file": str(mesh_path), **results.report(),
              "time_s": elapsed, "dropped": dropped_report(model),
              "repaired": repaired_report(model)}
    with ExitStack() as stack:
        staged = None
        if results:
            staged = stack.enter_context(staged_write(results.edges(), args.output,
                                                      overwrite=True))
        report["output"] = None if staged is None else str(staged.target)
        report_path = publish(staged, report, args.json_path, console, protected=inputs)
    if args.json_path != STDOUT:
        console.print(f"{len(results)} intersection curve(s) of the mesh ({mesh.n_triangles} "
                      f"triangles) with {results.pairs} face(s) in {elapsed:.3f} s"
                      + (f", written to {report['output']}" if results else
                         f"; nothing written to {args.output}"))
        if report_path is not None:
            console.note(f"report written to {report_path}")
    return done_code(model)


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
        "points, length, largest distance from each surface and how it was found "
        "(found_by: mesh or characteristic); tangential contact points and faces that "
        "coincide over a region are reported too."),
    epilog=(
        "examples:\n"
        "  surfprep intersect wing.step fuselage.step -o cut.step\n"
        "  surfprep intersect part.step -o self.step --json report.json --plot curves.png\n"
        "  surfprep intersect a.stp b.stp -o c.stp --tol 1e-5 --compare-occ --json -\n"
        "  surfprep intersect a.stp b.stp -o c.stp --method characteristic --plot p.png\n"
        "\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
