"""``surfprep heal IN.step -o OUT.step``: gaps, holes and duplicates replaced by joined
bicubic approximants (:func:`surfprep.plugin.heal.heal`)."""

from __future__ import annotations

import argparse
import math
from collections import Counter
from pathlib import Path

import numpy as np

from ...errors import InputFileError
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

__all__ = ["COMMAND", "plot_deviation"]


def plot_deviation(result, path: Path) -> Path:
    """Deviation map: the §7 error points of every approximant coloured by distance to
    the originals, plus each shared edge's measured gap and angle (Agg)."""
    plt = pyplot()
    fig = plt.figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    bars = fig.add_subplot(1, 2, 2)
    pts = [la.error.points for la in result.approximants if la.error.n_points]
    dist = [la.error.distance for la in result.approximants if la.error.n_points]
    if pts:
        p, d = np.concatenate(pts), np.concatenate(dist)
        art = ax.scatter(p[:, 0], p[:, 1], p[:, 2], c=d, s=6, cmap="viridis")
        fig.colorbar(art, ax=ax, shrink=0.7, label="distance to originals (mm)")
    ax.set_title(f"approximant deviation ({len(result.approximants)} patches)")
    joins = result.joins
    if joins:
        k = np.arange(len(joins))
        bars.bar(k - 0.2, [j.max_angle for j in joins], 0.4, label="max normal angle (deg)")
        gap_axis = bars.twinx()
        gap_axis.bar(k + 0.2, [max(j.max_gap, 1e-18) for j in joins], 0.4, color="tab:red",
                     label="max gap (mm)")
        gap_axis.set_yscale("log")
        bars.set_xlabel("shared edge")
        bars.legend(loc="upper left", fontsize="small")
        gap_axis.legend(loc="upper right", fontsize="small")
    bars.set_title(f"measured joins ({result.continuity.value})")
    fig.tight_layout()
    return save_figure(fig, path)


#: default --job-time-limit (s): approximants of the real files take seconds each
DEFAULT_JOB_TIME_LIMIT = 120.0


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", type=Path, metavar="IN", help="STEP or IGES file")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="STEP/IGES file to write the healed shape to")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="largest approximant error in mm (default relative to each patch)")
    parser.add_argument("--continuity", choices=("G0", "G1"), default="G0",
                        help="how approximants meet along shared edges (default G0)")
    parser.add_argument("--gap-tol", type=float, default=None, metavar="G", dest="gap_tol",
                        help="edges closer than this (mm) are one edge (default "
                             "min(1e-3 x size, 0.01 x median edge length))")
    parser.add_argument("--patches", type=Path, default=None, metavar="SPEC.json",
                        help="directed patches: four corners or four curves each")
    parser.add_argument("--mesh", type=Path, action="append", default=[], metavar="MESH",
                        dest="meshes",
                        help="discrete geometry the approximants may also be projected onto "
                             "(STL, OBJ or a Plot3D surface grid; repeatable): a scan over a "
                             "hole gives the patch its shape")
    parser.add_argument("--overlap", choices=("trim", "union"), default="trim",
                        help="a strip overlap of two four-sided faces: trim the later face "
                             "back (default) or replace both by one approximant over their "
                             "union when it is four-sided")
    parser.add_argument("--split-faces", action=argparse.BooleanOptionalAction, default=True,
                        dest="split_faces",
                        help="also replace faces that are not four-sided, split into "
                             "four-sided sub-patches on the face (default; "
                             "--no-split-faces keeps them as they are)")
    parser.add_argument("--replace", choices=("defects", "all"), default="defects",
                        help="re-approximate only the faces with a gap, a hole or an "
                             "overlap at their edges (default; the others keep their exact "
                             "geometry) or every face")
    parser.add_argument("--fill", choices=("holes", "all", "none"), default="holes",
                        help="which loops of free edges to fill: holes, whose surroundings "
                             "continue across them (default), also open boundaries such as "
                             "a sheet's edge or a pipe's end (all), or none; rings (two "
                             "loops beside each other all round, wider apart than gap_tol) "
                             "are bridged by strips unless none")
    parser.add_argument("--no-close-gaps", action="store_false", dest="close_gaps",
                        help="leave the edges sewing closed by raising their tolerance as they "
                             "are (by default the B-spline faces along them are moved onto "
                             "one common curve per edge: the gaps close in the geometry)")
    parser.add_argument("--no-trim-crossings", action="store_false", dest="trim_crossings",
                        help="leave faces that cut through each other as they are (by "
                             "default, where a face runs on past the curve where it meets "
                             "another, both are cut along the curve and the overshooting "
                             "pieces dropped)")
    parser.add_argument("--job-time-limit", type=seconds_argument,
                        default=DEFAULT_JOB_TIME_LIMIT, metavar="S", dest="job_time_limit",
                        help="stop an approximant that takes longer than S seconds to build, "
                             "keep its face as it was (or leave its hole open) with a note "
                             f"and go on; 0 for no limit (default {DEFAULT_JOB_TIME_LIMIT:g})")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")
    parser.add_argument("--plot", type=Path, metavar="PNG", help="draw the deviation map")


#: loops of interior free edges the summary names, widest gap first
_LOOPS_SAID = 3


def _plural(kind: str) -> str:
    """A loop kind of the report in the plural ("open boundaries", "not capped")."""
    if kind == "not capped":
        return kind
    return kind[:-1] + "ies" if kind.endswith("ry") else kind + "s"


def _summary(report: dict) -> list[str]:
    patches, joins = report["patches"], report["shared_edges"]
    free, valid = report["free_edges"], report["valid"]
    worst_err = max((p["max_error"] for p in patches if p["max_error"] is not None),
                    default=float("nan"))
    worst_dev = max((p["deviation_from_input"] for p in patches), default=float("nan"))
    errors = ""                  # no approximant, or none measured: no figure, not "nan"
    if math.isfinite(worst_err):
        errors += f", largest error {worst_err:.3g} mm"
    if math.isfinite(worst_dev):
        errors += f" (largest distance from the input faces, dense: {worst_dev:.3g} mm)"
    lines = [(f"{len(patches)} approximant(s) "
             f"({len({p['index'] for p in patches if p['kind'] == 'hole'})} hole(s) "
             f"filled, {len({p['index'] for p in patches if p['kind'] == 'ring'})} ring(s) "
             f"bridged){errors}, {len(report['dropped_overlaps'])} duplicate "
             f"face(s) dropped, {report['time_s']:.2f} s")]
    cuts, partial = report.get("cuts", []), report.get("partial_overlaps", [])
    if cuts:
        lines.append(f"directed patches cut away {sum(c['area_cut'] for c in cuts):.4g} mm2 "
                     f"of {len({c['face'] for c in cuts})} face(s) under them")
    if partial or report.get("trimmed_overlaps"):
        lines.append(f"overlaps trimmed back: {len(partial)} partial "
                     f"({sum(o['area_cut'] for o in partial):.4g} mm2 of doubled area cut), "
                     f"{len(report.get('trimmed_overlaps', []))} strip(s)")
    stages = report.get("stage_times_s", {})
    if stages:
        lines.append("time per stage: " + ", ".join(f"{name} {t:.2f} s" for name, t in stages.items()
                                                    if t >= 0.005))
    crossings = report.get("crossings", [])
    if crossings:
        trimmed = [c for c in crossings if c["action"] == "trimmed back"]
        lines.append(f"{len(crossings)} curve(s) where faces cut through each other: "
                     f"{len(trimmed)} trimmed back "
                     f"({sum(sum(c['area_cut']) for c in trimmed):.4g} mm2 of overshoot cut), "
                     f"{len(crossings) - len(trimmed)} left")
    if joins:
        lines.append(f"{len(joins)} shared edge(s): max gap "
                     f"{max(j['max_gap'] for j in joins):.3g} mm, max normal angle "
                     f"{max(j['max_angle_deg'] for j in joins):.3g} deg "
                     f"({report['continuity']})")
    loops = report.get("free_loops", [])
    if loops:
        kinds = Counter(lp["kind"] for lp in loops)
        lines.append(f"{len(loops)} loop(s) of free edges: "
                     + ", ".join(f"{n} {_plural(kind) if n > 1 else kind}"
                                 for kind, n in sorted(kinds.items()))
                     + f"; fill tried on {sum(lp['fill'] for lp in loops)}")
    rings = report.get("rings", [])
    if rings:
        lines.append(f"{len(rings)} ring(s) of two loops beside each other: "
                     f"{sum(r['bridged'] for r in rings)} bridged by strips")
    lines.append(f"free edges {free['before']} -> {free['after']} (at gap_tol "
                 f"{report['gap_tol']:.3g} mm), {free['tight_before']} -> "
                 f"{free['tight_after']} (geometric); valid {valid['before']} -> "
                 f"{valid['after']}")
    after = report.get("free_boundary", {}).get("after")
    if after:
        kinds, widest = after["edges"], after["widest_gap"]
        lines.append(f"free edges left in the geometry: {after['interior']} interior "
                     f"({kinds['gap']} along gaps"
                     + (f" up to {widest:.3g} mm wide" if widest is not None else "")
                     + f", {kinds['hole']} around holes), {kinds['open boundary']} on the "
                     f"open boundary")
        for loop in after.get("interior_loops", [])[:_LOOPS_SAID]:
            what = ("a hole" if loop["widest_gap"] is None else
                    f"a gap up to {loop['widest_gap']:.3g} mm wide")
            lines.append(f"  {what}: {loop['edges']} edge(s) of face(s) "
                         f"{', '.join(map(str, loop['faces'][:8]))}"
                         + (", ..." if len(loop["faces"]) > 8 else "")
                         + f", {loop['length']:.4g} mm long")
        more = len(after.get("interior_loops", [])) - _LOOPS_SAID
        if more > 0:
            lines.append(f"  and {more} more (the report's free_boundary)")
    return lines


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = tuple(p for p in (args.input, args.patches, *args.meshes) if p is not None)
    check_outputs(inputs, args.output, plot=args.plot, json_path=args.json_path)
    check_inputs(args.input)
    for mesh in args.meshes:
        if not mesh.is_file():
            raise InputFileError(f"--mesh {mesh} does not exist or is not a file")
    from ..heal import heal
    from ..io import staged_write
    from .notes import grouped
    model = read_model(args.input, console, strict=args.strict)
    with step_time_limit(args.job_time_limit, "an approximant") as restart:
        def progress(done: int, total: int) -> None:
            restart(last=done >= total)
            console.progress(done, total, "approximant")
        result = heal(model, tol=args.tol, continuity=args.continuity, gap_tol=args.gap_tol,
                      patches=args.patches, overlap=args.overlap,
                      split_faces=args.split_faces, replace=args.replace,
                      meshes=args.meshes, fill=args.fill, close_gaps=args.close_gaps,
                      trim_crossings=args.trim_crossings, progress=progress,
                      stage=lambda what: console.stage(f"heal: {what}"))
    report = {"input": str(args.input), **result.report(), "dropped": dropped_report(model),
              "repaired": repaired_report(model)}
    with staged_write(result.model, args.output, overwrite=True) as staged:
        report["output"] = str(staged.target)
        if args.plot is not None:
            report["plot"] = str(plot_deviation(result, args.plot))
        report_path = publish(staged, report, args.json_path, console, protected=inputs)
    if args.json_path == STDOUT:
        return done_code(model)
    for line in _summary(report):
        console.print(line)
    console.print(f"written to {report['output']}")
    for note in grouped(report["skipped"] + report["topology_violations"]):
        console.note(f"note: {note}")
    if report_path is not None:
        console.note(f"report written to {report_path}")
    return done_code(model)


COMMAND = Command(
    name="heal",
    summary="replace gaps, holes, overlaps and crossings by joined bicubic approximants",
    description=(
        "Every four-sided face with a defect (a gap to a neighbour not closed in the "
        "geometry, an edge on a hole, an overlap; every face with --replace all) gets a "
        "bicubic B-spline approximant over its own four edges, projected onto all "
        "original faces (Hamann & Jean 1996), and is kept as it was where the "
        "approximant lies farther than tol from the input faces; loops of free edges "
        "of neighbouring faces are classified by their surroundings: holes (the "
        "surroundings continue across them) are filled, four-sided ones by one "
        "approximant, others by four-sided patches around a centre on a thin-plate "
        "cap continuing the surroundings; open boundaries stay open unless --fill all; "
        "two loops beside each other all round, wider apart than gap_tol (the missing "
        "end face of a tube with two skins), are bridged by four-sided strips; faces "
        "lying on other faces are dropped, a face "
        "lying partly on another is trimmed back to the other's boundary, faces cutting "
        "through each other (each running on past the curve where they meet) are cut "
        "along it and the overshoots dropped; directed "
        "patches come from --patches and replace what they cover (the faces under "
        "them are cut away). The approximants are joined G0 (shared control "
        "rows averaged) or G1 (tangent planes at corners, collinear control triples "
        "along edges), the result is sewn into a shell (a solid when closed) and checked "
        "with BRepCheck; approximants (and duplicate drops) that leave more free edges "
        "than the input had are taken back, all of them if need be. The report gives per "
        "patch its resolution, error (max, RMS), largest distance from the input faces "
        "on a dense sample and share of artificial points, per shared edge the measured "
        "gap and normal angle, and free edges and validity before and after."),
    epilog=(
        "examples:\n"
        "  surfprep heal hull.igs -o healed.step\n"
        "  surfprep heal part.step -o healed.step --continuity G1 --json report.json "
        "--plot deviation.png\n"
        "  surfprep heal part.step -o healed.step --patches spec.json --gap-tol 0.05\n"
        "\n"
        "A patch spec: {\"patches\": [{\"corners\": [[x,y,z] x 4]}, {\"curves\": "
        "[{\"edge\": [face, k]}, {\"points\": [[x,y,z], ...]}, ...]}]}.\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
