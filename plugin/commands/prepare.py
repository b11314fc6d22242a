"""``surfprep prepare IN -o OUT``: heal, intersect, reparametrize and grid in one run
(:mod:`..prepare`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...errors import OutputFileError
from ..time_limit import seconds_argument
from .base import (
    STDOUT,
    Command,
    Console,
    check_inputs,
    check_outputs,
    done_code,
    publish,
    read_model,
)

__all__ = ["COMMAND", "DEFAULT_STEP_TIME_LIMIT"]

#: seconds one step (an approximant, a face, a face pair) may run (0: no limit)
DEFAULT_STEP_TIME_LIMIT = 120.0


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="IN", help="STEP or IGES file")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="the prepared model (.step/.stp/.igs/.iges)")
    parser.add_argument("--heal", choices=("G0", "G1", "off"), default="G0",
                        help="continuity of the healing joins, or off (default G0)")
    parser.add_argument("--no-reparam", action="store_false", dest="reparam",
                        help="leave the faces' parametrization as it is")
    parser.add_argument("--no-intersect", action="store_false", dest="intersect",
                        help="do not look for faces crossing one another")
    parser.add_argument("--curves", type=Path, metavar="CURVES",
                        help="write the intersection curves found (STEP/IGES edges)")
    parser.add_argument("--grid", type=Path, metavar="GRID",
                        help="grid the four-sided faces and write the blocks (.xyz Plot3D, "
                             ".cgns, .vts, .vtm)")
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--dims", type=int, nargs=2, metavar=("NI", "NJ"),
                      help="nodes per block in i and j (with --grid)")
    size.add_argument("--size", type=float, metavar="H",
                      help="target cell size in mm (with --grid)")
    parser.add_argument("--tol", type=float, metavar="T",
                        help="geometric tolerance of every stage in mm (default: each "
                             "stage's own, from the model's size)")
    parser.add_argument("--step-time-limit", type=seconds_argument,
                        default=DEFAULT_STEP_TIME_LIMIT, metavar="S", dest="step_time_limit",
                        help="stop a step (an approximant, a face, a face pair) that runs "
                             "longer than S seconds, report it and go on; 0 for no limit "
                             f"(default {DEFAULT_STEP_TIME_LIMIT:g})")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")
    parser.add_argument("--report", type=Path, metavar="HTML",
                        help="write a self-contained HTML report: the model in a 3-D view "
                             "(faces by what was done to them, curves, grids by skewness) "
                             "and every stage's tables")


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = (args.file,)
    check_outputs(inputs, args.output, json_path=args.json_path)
    if args.curves is not None:
        check_outputs(inputs, args.curves)
    if args.report is not None:
        check_outputs(inputs, args.report, model=False)
        if args.report.suffix.lower() not in (".html", ".htm"):
            raise OutputFileError(f"--report {args.report}: an HTML report is written to a "
                                  ".html file")
    if args.grid is not None:
        check_outputs(inputs, args.grid, model=False)
    elif args.dims is not None or args.size is not None:
        raise OutputFileError("--dims and --size are for --grid")
    check_inputs(args.file)
    from ..grid import grid_format
    from ..io import staged_write, write
    from ..prepare import prepare
    if args.grid is not None:
        grid_format(args.grid, None)                   # a known grid extension, before the work
    model = read_model(args.file, console, strict=args.strict)
    options = {k: v for k, v in (("dims", tuple(args.dims) if args.dims else None),
                                 ("size", args.size)) if v is not None}
    result = prepare(model, heal=args.heal, reparam=args.reparam, intersect=args.intersect,
                     grid=args.grid is not None, grid_options=options, tol=args.tol,
                     step_time_limit_s=args.step_time_limit or None,
                     progress=lambda stage, done, total: console.progress(done, total, stage))
    report = result.report()
    outputs = {}
    if args.grid is not None and result.grid is not None:
        outputs["grid"] = str(result.grid.write(args.grid))
    if args.curves is not None and result.curves:
        edges = [e for c in result.curves for e in c.to_edges()]
        outputs["curves"] = str(write(edges, args.curves, overwrite=True))
    if args.report is not None:
        from ..prepare_report import write_prepare_report
        outputs["report"] = str(write_prepare_report(result, args.report))
    with staged_write(result.model, args.output, overwrite=True) as staged:
        outputs["model"] = str(staged.target)
        report["outputs"] = outputs
        report_path = publish(staged, report, args.json_path, console, protected=inputs)
    failed = [s for s in result.stages if s.status == "failed"]
    if args.json_path != STDOUT:
        for stage in result.stages:
            console.print(stage.line())
        counts = report["face_status_counts"]
        console.print(f"{result.model.n_faces} faces: {counts['healed']} healed, "
                      f"{counts['reparametrized']} reparametrized, {counts['untouched']} "
                      f"untouched; {result.time_s:.1f} s")
        for what, path in outputs.items():
            console.print(f"{what} written to {path}")
        if report_path is not None:
            console.note(f"report written to {report_path}")
    return done_code(model, skipped=bool(failed))


COMMAND = Command(
    name="prepare",
    summary="heal, intersect, reparametrize and grid a model in one run, with one report",
    description=(
        "The whole preparation of a model for a mesher, each stage on what the one "
        "before made: heal (gaps, holes and overlaps replaced by joined bicubic "
        "approximants, G0 or G1), intersect (faces of the model crossing one another), "
        "reparam (every B-spline face on a chord-length surface within the tolerance), and "
        "with --grid, structured grids on the four-sided faces. A stage that does not "
        "apply is skipped with the reason; a stage that fails is reported and the chain "
        "goes on with the model as it was (exit 1). The report gives per stage its status, "
        "time, headline figures and its full report, and per face whether it was healed, "
        "reparametrized or left untouched."),
    epilog=(
        "examples:\n"
        "  surfprep prepare part.step -o ready.step\n"
        "  surfprep prepare hull.igs -o ready.step --heal G1 --grid hull.cgns --size 50\n"
        "  surfprep prepare part.step -o ready.step --no-intersect --json report.json\n"
        "  surfprep prepare part.step -o ready.step --grid part.xyz --report part.html\n"
        "\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
