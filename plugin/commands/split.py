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
                        help="STEP/IGES file for the pieces and the uncut faces (one shell), or "
                             "the result of --op")
    parser.add_argument("--tol", type=float, default=None, metavar="T",
                        help="intersection tolerance in mm (default 1e-6 x the faces' box diagonal)")
    parser.add_argument("--method", choices=METHODS, default="auto",
                        help="intersection method (as surfprep intersect)")
    parser.add_argument("--tool", action="store_true",
                        help="B only cuts: write A's faces split, not B's (a hull cut at a waterline)")
    parser.add_argument("--op", choices=("split", "fuse", "cut", "common", "trim"), default=None,
                        help="split (default: every piece), or fuse, cut (A minus B) or common of "
                             "two solids, or trim A by the sheet B (--keep): write the pieces "
                             "that operation keeps, sewn")
    parser.add_argument("--keep", choices=("front", "back"), default="front",
                        help="with --op trim: keep A's pieces on the side B's normal points to "
                             "(front, the default) or on the other")
    parser.add_argument("--with", dest="more", type=Path, action="append", default=[], metavar="C",
                        help="with --op fuse/cut/common: one more solid (repeatable), taken "
                             "pairwise: ((A op B) op C) ...; cut takes every one from A")
    parser.add_argument("--boolean", choices=("fuse", "cut", "common"), default=None, metavar="OP",
                        help="the same as --op OP")
    parser.add_argument("--compare-occ", action="store_true",
                        help="also run OpenCascade on the same input (the General Fuse, or "
                             "BRepAlgoAPI_Splitter with --tool, or BRepAlgoAPI_Fuse/Cut/Common) "
                             "and report its faces, validity, largest edge tolerance, area, "
                             "volume and time")
    parser.add_argument("--plot", type=Path, metavar="PNG",
                        help="draw the intersection curves in space and in each face's (u, v) "
                             "domain (needs matplotlib)")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = tuple(p for p in (args.a, args.b, *args.more) if p is not None)
    check_outputs(inputs, args.output, plot=args.plot, json_path=args.json_path)
    check_inputs(*inputs)
    from ...errors import InvalidGeometryError
    if args.op is not None and args.boolean is not None and args.op != args.boolean:
        raise InvalidGeometryError(f"--op {args.op} and --boolean {args.boolean} disagree")
    op = args.boolean or (args.op if args.op != "split" else None)
    if args.more and op not in ("fuse", "cut", "common"):
        raise InvalidGeometryError("--with needs --op fuse, cut or common")
    from ..io import staged_write
    from ..split import split
    model_a = read_model(args.a, console, strict=args.strict)
    model_b = read_model(args.b, console, strict=args.strict) if args.b is not None else None
    operation = None
    if op is not None:
        from ..split import boolean, boolean_all, trim
        if model_b is None:
            raise InvalidGeometryError(f"--op {op} needs two files, A and B")
        if args.more:
            more = [read_model(path, console, strict=args.strict) for path in args.more]
            operation = boolean_all([model_a, model_b, *more], op, tol=args.tol, method=args.method)
        else:
            operation = (trim(model_a, model_b, keep=args.keep, tol=args.tol, method=args.method)
                         if op == "trim" else boolean(model_a, model_b, op, tol=args.tol, method=args.method))
        result = operation.split
    else:
        result = split(model_a, model_b, tol=args.tol, method=args.method, tool=args.tool)
    kept = [f for f in result.faces if f.kept is not None]
    written_shape = result.as_model() if operation is None else operation.as_model()
    with staged_write(written_shape, args.output, overwrite=True) as staged:
        report = {"a": str(args.a), "b": None if args.b is None else str(args.b),
                  "output": str(staged.target), **result.report()}
        if operation is not None:
            report["boolean"] = {k: v for k, v in operation.report().items() if k != "split"}
        if args.compare_occ:
            report["occ"] = _occ_figures(model_a, model_b, op, args.tool or op == "trim")
        if args.plot is not None:
            from .intersect import plot_curves
            report["plot"] = str(plot_curves(result.curves, args.plot, two_models=model_b is not None))
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
            console.print(f"{op}: {operation.kept[0]} piece(s) of A and {operation.kept[1]} "
                          f"of B kept, {volume}, {'valid' if operation.valid else 'INVALID'}")
        if args.compare_occ:
            occ = report["occ"]
            volume = "" if occ["volume"] is None else f", volume {occ['volume']:.10g}"
            console.print(f"OpenCascade ({occ['method']}): {occ['faces']} face(s), "
                          f"{'valid' if occ['valid'] else 'INVALID'}, largest edge tolerance "
                          f"{occ['max_edge_tolerance']:.2g}{volume}; {occ['time_s']:.2f} s")
        if report_path is not None:
            console.note(f"report written to {report_path}")
    return done_code(model_a, model_b, skipped=bool(kept))


def _occ_figures(model_a, model_b, op: str | None, tool: bool) -> dict:
    """OpenCascade's answer on the same input: its Boolean (``op``), else the General
    Fuse of A and B (``BRepAlgoAPI_Splitter`` with ``tool``: B only cuts; A's faces
    against one another without B), with its figures (``IsDone`` checked)."""
    import time

    from OCP.BRepAlgoAPI import (
        BRepAlgoAPI_BuilderAlgo,
        BRepAlgoAPI_Common,
        BRepAlgoAPI_Cut,
        BRepAlgoAPI_Fuse,
        BRepAlgoAPI_Splitter,
    )
    from OCP.TopTools import TopTools_ListOfShape

    from ...errors import OpenCascadeError
    from ..occ.shapes import all_faces, face_area, is_valid, max_edge_tolerance
    start = time.perf_counter()
    if op is not None and op != "trim":
        method = {"fuse": "BRepAlgoAPI_Fuse", "cut": "BRepAlgoAPI_Cut", "common": "BRepAlgoAPI_Common"}[op]
        algo = {"fuse": BRepAlgoAPI_Fuse, "cut": BRepAlgoAPI_Cut,
                "common": BRepAlgoAPI_Common}[op](model_a.shape, model_b.shape)
    else:
        arguments, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
        if model_b is not None and tool:
            method, algo = "BRepAlgoAPI_Splitter", BRepAlgoAPI_Splitter()
            arguments.Append(model_a.shape)
            tools.Append(model_b.shape)
            algo.SetTools(tools)
        else:
            method, algo = "BRepAlgoAPI_BuilderAlgo (General Fuse)", BRepAlgoAPI_BuilderAlgo()
            for face in (model_a.faces if model_b is None else [model_a.shape, model_b.shape]):
                arguments.Append(face)
        algo.SetArguments(arguments)
    algo.Build()
    seconds = time.perf_counter() - start
    if not algo.IsDone():
        raise OpenCascadeError(f"{method} failed on this input")
    shape = algo.Shape()
    volume = None
    if op is not None and op != "trim":
        from OCP.BRepGProp import BRepGProp
        from OCP.GProp import GProp_GProps
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(shape, props, 1e-9)
        volume = abs(float(props.Mass()))
    # each face once: the General Fuse's result holds the split solids, which share the
    # faces between them (exploring would count those twice, and their area)
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopTools import TopTools_IndexedMapOfShape
    unique = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, unique)
    faces = [unique.FindKey(k) for k in range(1, unique.Extent() + 1)]
    return {"method": method, "faces": len(faces), "face_occurrences": len(all_faces(shape)),
            "valid": is_valid(shape), "max_edge_tolerance": max_edge_tolerance(shape),
            "area": float(sum(face_area(f, 1e-9) for f in faces)), "volume": volume,
            "time_s": seconds}


COMMAND = Command(
    name="split",
    summary="cut faces along their intersection curves; the pieces share the cut edges",
    description=(
        "Intersect A with B (or A's faces with one another, as surfprep intersect), cut every "
        "face along its curves in its own parameters (open curves from boundary to boundary, "
        "closed ones as islands) and write the pieces with the uncut faces as one shell built "
        "from their shared edges (no sewing): where two surfaces cross, four pieces share one "
        "intersection edge (non-manifold); faces of A and B lying on each other are one face. A "
        "curve that stops inside a face (a fin on a sheet, also one running in from the "
        "border) becomes an internal edge of it, shared with the fin's pieces; a face the "
        "cutting refuses is kept whole and named (exit 1). The report gives "
        "per face its curves and pieces, the edges by the number of faces using them, the free "
        "edges and BRepCheck validity, every output face's origin, name and area, every "
        "intersection edge's length and distance from both surfaces. With --op fuse|cut|common "
        "(or --boolean), two solids are fused, cut or intersected by keeping the pieces of "
        "each that lie outside (inside) the other (--with C: more solids, pairwise), written as "
        "a solid whose faces carry their origin's names. --compare-occ runs "
        "OpenCascade's General Fuse / Splitter / Boolean on the same input beside ours."),
    epilog=(
        "examples:\n"
        "  surfprep split wing.step fuselage.step -o cut.step\n"
        "  surfprep split a.step b.step -o common.step --op common --compare-occ\n"
        "  surfprep split block.step drill1.step -o drilled.step --op cut --with drill2.step\n"
        "  surfprep split hull.step waterplane.step -o below.step --op trim --keep back\n"
        "  surfprep split model.step -o cut.step --json r.json\n"
        "\n"
        "Lengths and tolerances are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
