"""``surfprep split A [B] -o OUT.step``: faces cut along their intersection curves."""

from __future__ import annotations

import argparse
from pathlib import Path

from .base import STDOUT, Command, Console, check_inputs, check_outputs, done_code, publish, read_model

__all__ = ["COMMAND"]

#: values of --method (plugin.intersect.Method; not imported to build the parser)
METHODS = ("auto", "mesh", "characteristic")


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("a", type=Path, metavar="A", help="STEP or IGES file")
    parser.add_argument("b", type=Path, nargs="?", metavar="B",
                        help="second STEP or IGES file (default: A's faces cut where they meet each other)")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="STEP/IGES file for the pieces and the uncut faces, sewn")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="intersection tolerance in mm (default 1e-6 x the faces' box diagonal)")
    parser.add_argument("--method", choices=METHODS, default="auto",
                        help="intersection method (as surfprep intersect)")
    parser.add_argument("--tool", action="store_true",
                        help="B only cuts: write A's faces split, not B's (a hull cut at a waterline)")
    parser.add_argument("--boolean", choices=("fuse", "cut", "common"), default=None, metavar="OP",
                        help="fuse, cut (A minus B) or common of two solids: write the pieces "
                             "that operation keeps, sewn, instead of all of them")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = tuple(p for p in (args.a, args.b) if p is not None)
    check_outputs(inputs, args.output, json_path=args.json_path)
    check_inputs(*inputs)
    from ..io import staged_write
    from ..split import split
    model_a = read_model(args.a, console, strict=args.strict)
    model_b = read_model(args.b, console, strict=args.strict) if args.b is not None else None
    operation = None
    if args.boolean is not None:
        from ...errors import InvalidGeometryError
        from ..split import boolean
        if model_b is None:
            raise InvalidGeometryError("--boolean needs two files, A and B")
        operation = boolean(model_a, model_b, args.boolean, tol=args.tol, method=args.method)
        result = operation.split
    else:
        result = split(model_a, model_b, tol=args.tol, method=args.method, tool=args.tool)
    kept = [f for f in result.faces if f.kept is not None]
    written_shape = result.shape if operation is None else operation.shape
    with staged_write(written_shape, args.output, overwrite=True) as staged:
        report = {"a": str(args.a), "b": None if args.b is None else str(args.b),
                  "output": str(staged.target), **result.report()}
        if operation is not None:
            report["boolean"] = {k: v for k, v in operation.report().items() if k != "split"}
        report_path = publish(staged, report, args.json_path, console, protected=inputs)
    if args.json_path != STDOUT:
        for f in result.faces:
            what = (f"kept whole: {f.kept}" if f.kept is not None
                    else f"{len(f.pieces)} piece(s)")
            console.print(f"face {f.operand}:{f.index}: {f.cuts} curve(s), {what}")
        uses = ", ".join(f"{n} by {k} face(s)" for k, n in sorted(result.shared_edges.items()))
        console.print(f"{len(result.curves)} curve(s), {sum(len(f.pieces) for f in result.faces)} "
                      f"piece(s); edges: {uses}; {result.free_edges} free; "
                      f"{'valid' if result.valid else 'INVALID'}; {result.time_s:.2f} s, "
                      f"written to {staged.target}")
        if operation is not None:
            volume = "open" if operation.volume is None else f"volume {operation.volume:.10g}"
            console.print(f"{args.boolean}: {operation.kept[0]} piece(s) of A and {operation.kept[1]} "
                          f"of B kept, {volume}, {'valid' if operation.valid else 'INVALID'}")
        if report_path is not None:
            console.note(f"report written to {report_path}")
    return done_code(model_a, model_b, skipped=bool(kept))


COMMAND = Command(
    name="split",
    summary="cut faces along their intersection curves; the pieces share the cut edges",
    description=(
        "Intersect A with B (or A's faces with one another, as surfprep intersect), cut every "
        "face along its curves in its own parameters (open curves from boundary to boundary, "
        "closed ones as islands) and write the pieces with the uncut faces, sewn: where two "
        "surfaces cross, four pieces share one intersection edge (a non-manifold shell). A "
        "face a curve stops inside is kept whole and named (exit 1). The report gives "
        "per face its curves and pieces, the edges by the number of faces using them, the free "
        "edges and BRepCheck validity. With --boolean, two solids are fused, cut or intersected "
        "by keeping the pieces of each that lie outside (inside) the other, sewn into the result."),
    epilog=(
        "examples:\n"
        "  surfprep split wing.step fuselage.step -o cut.step\n"
        "  surfprep split a.step b.step -o common.step --boolean common\n"
        "  surfprep split model.step -o cut.step --json r.json\n"
        "\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
