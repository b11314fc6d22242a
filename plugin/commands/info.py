"""``surfprep info FILE``: what a STEP/IGES file holds, face by face (:mod:`..describe`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ...errors import NoFacesError
from .base import (
    STDOUT,
    Command,
    Console,
    check_inputs,
    check_outputs,
    done_code,
    read_model,
    write_json_report,
)

__all__ = ["COMMAND"]


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE",
                        help="STEP (.step/.stp) or IGES (.igs/.iges) file")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH; '-' prints the JSON to "
                             "stdout instead of the table")
    parser.add_argument("--heal", action="store_true",
                        help="run OpenCascade's ShapeFix_Shape on the model first")


def _run(args: argparse.Namespace, console: Console) -> int:
    check_outputs((Path(args.file),), None, json_path=args.json_path)  # before the work
    check_inputs(args.file)
    from ..describe import format_table, model_report
    model = read_model(args.file, console, strict=args.strict, heal=args.heal,
                       require_faces=False)
    report = model_report(model, progress=console.progress)
    if not report["faces"] and not report["edges"]:
        raise NoFacesError(f"{args.file} holds neither faces nor curves to list")
    if args.json_path == STDOUT:
        write_json_report(report, STDOUT, console)
        return done_code(model)
    console.print(format_table(report))
    if args.json_path is not None:
        written = write_json_report(report, args.json_path, console, protected=(model.path,))
        console.note(f"report written to {written}")
    return done_code(model)


COMMAND = Command(
    name="info",
    summary="list the faces of a STEP/IGES file: surface type, degrees, area, parametrization",
    description=(
        "Read a STEP or IGES file and list every face: index (0-based, file order), "
        "name (from the file's XDE labels), surface type, for B-spline faces the "
        "degrees, pole counts, knot spans and whether it is rational, the area, and "
        "the parametrization figure: the worst mismatch between neighbouring chord "
        "lengths and parameter steps (eqs. 29.1/29.2; 1 = chord-length parametrized). "
        "The JSON report adds each face's UV bounds and bounding box."),
    epilog=(
        "examples:\n"
        "  surfprep info part.step                  table on stdout\n"
        "  surfprep info part.igs --json report.json  table, and the report in report.json\n"
        "  surfprep info part.stp --json -          JSON on stdout (no table)\n"
        "\n"
        "Coordinates, areas and boxes are in millimetres (OpenCascade converts the\n"
        "file's declared unit, which is shown as 'declared unit')."),
    add_arguments=_add_arguments,
    run=_run,
)
