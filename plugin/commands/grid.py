"""``surfprep grid IN.step -o OUT.xyz``: structured surface grids on the four-sided faces."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ...errors import OutputFileError
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
from .plotting import pyplot, save_figure

__all__ = ["COMMAND", "plot_grids"]

#: blocks drawn at most by --plot
PLOT_BLOCKS = 4


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="IN", help="STEP or IGES file")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="OUT",
                        help="grid file: .xyz/.p3d/.x/.g/.grd (Plot3D), .cgns, .vts (one block) "
                             "or .vtm (VTK multiblock)")
    parser.add_argument("--format", choices=("plot3d", "cgns", "vts", "vtm"), default=None,
                        help="output format (default from the extension)")
    parser.add_argument("--binary", action="store_true",
                        help="Plot3D as Fortran unformatted (default formatted text)")
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--dims", type=int, nargs=2, metavar=("NI", "NJ"),
                      help="NI x NJ nodes per block (i along the face's u; a face split into blocks, "
                           "or cut where a neighbour's corner meets its side, gets them per block); where "
                           "shared edges link an i direction to a j direction those take the larger, and "
                           "a note says so")
    size.add_argument("--size", type=float, metavar="H",
                      help="target cell size in mm (default: the median face's longest side / 40)")
    parser.add_argument("--first-spacing", type=float, metavar="D", dest="first",
                        help="first interval of every grid line in mm (tanh stretching)")
    parser.add_argument("--last-spacing", type=float, metavar="D", dest="last",
                        help="last interval of every grid line in mm")
    parser.add_argument("--growth", type=float, metavar="R",
                        help="geometric spacing: each interval R times the one before")
    parser.add_argument("--faces", type=int, nargs="+", metavar="K",
                        help="face indices (file order, from 0); default every four-sided face")
    parser.add_argument("--smooth", choices=("elliptic", "none"), default="elliptic",
                        help="elliptic refinement on the surface metric (default) or the "
                             "algebraic (TFI) grid")
    parser.add_argument("--no-orthogonal", action="store_false", dest="orthogonal",
                        help="do not force the grid lines to leave the face sides at 90 degrees "
                             "(by default they do, blended to the faces' own corner angles)")
    parser.add_argument("--whole-surfaces", action="store_true", dest="whole_surfaces",
                        help="grid the whole surface of a trimmed face (its trims ignored) "
                             "instead of leaving the face out")
    parser.add_argument("--pole-caps", choices=("o", "h"), default="o", dest="pole_caps",
                        help="a cap round a pole (a hemisphere, a nose of revolution): o = one "
                             "block round the pole, its cells there triangles (default); h = five "
                             "blocks, a square over the pole and four round it (no cell touches "
                             "the pole)")
    parser.add_argument("--hold", type=Path, metavar="CURVES",
                        help="STEP/IGES file of curves (edges) to keep as grid lines: each must "
                             "cross one face from a side to the opposite side (e.g. the curves "
                             "surfprep intersect wrote)")
    parser.add_argument("--gap", type=float, metavar="G",
                        help="largest gap in mm between two face sides taken as one shared "
                             "edge (default 1e-4 x the model's size)")
    parser.add_argument("--json", metavar="PATH", dest="json_path",
                        help="write the report as JSON to PATH ('-' for stdout)")
    parser.add_argument("--plot", type=Path, metavar="PNG",
                        help="the grids in their parameter domain and on the surface, cells "
                             "coloured by skewness, before and after refinement (needs matplotlib)")


def _spacing(args: argparse.Namespace):
    from ...algorithms.grid import Spacing
    if args.growth is not None and (args.first is not None or args.last is not None):
        from ...errors import InvalidGeometryError
        raise InvalidGeometryError("give --growth or --first-spacing/--last-spacing, not both")
    return Spacing(first=args.first, last=args.last, growth=args.growth)


def _held_curves(path: Path, console: Console) -> list:
    """The edges of a STEP/IGES file as 3D NURBS curves."""
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from ...errors import InputFileError
    from ..occ.edges import edge_to_nurbs
    model = read_model(path, console, require_faces=False)
    curves, explorer = [], TopExp_Explorer(model.shape, TopAbs_EDGE)
    while explorer.More():
        curves.append(edge_to_nurbs(TopoDS.Edge_s(explorer.Current())))
        explorer.Next()
    if not curves:
        raise InputFileError(f"--hold file {path} holds no curve")
    return curves


def _run(args: argparse.Namespace, console: Console) -> int:
    inputs = (args.file,) + ((args.hold,) if args.hold is not None else ())
    check_outputs(inputs, args.output, plot=args.plot, json_path=args.json_path, model=False)
    check_inputs(args.file)
    from ..grid import grid, grid_format
    fmt = grid_format(args.output, args.format)
    if args.binary and fmt != "plot3d":
        raise OutputFileError("--binary is for Plot3D output only")
    spacing = _spacing(args)
    held = _held_curves(args.hold, console) if args.hold is not None else []
    model = read_model(args.file, console, strict=args.strict)
    start = time.perf_counter()
    result = grid(model, faces=args.faces, dims=tuple(args.dims) if args.dims else None, size=args.size,
                  spacing=spacing, smooth=args.smooth, orthogonal=args.orthogonal, gap=args.gap,
                  whole_surfaces=args.whole_surfaces, pole_caps=args.pole_caps,
                  hold=held,
                  progress=lambda done, total: console.progress(done, total, "face"))
    elapsed = time.perf_counter() - start
    report = {"file": str(args.file), "output": str(args.output), "format": fmt,
              **result.report(), "time_s": elapsed}
    if args.whole_surfaces:
        report["note"] = "trimmed faces were gridded over their whole surface (--whole-surfaces)"
    if args.plot is not None:
        report["plot"] = str(plot_grids(result, args.plot))
    report_path = None
    if args.json_path is not None and args.json_path != STDOUT:
        report_path = write_json_report(report, args.json_path, console, protected=inputs)
    try:
        written = result.write(args.output, format=fmt, binary=args.binary)
    except (OSError, ValueError) as exc:
        if report_path is not None:
            report_path.unlink(missing_ok=True)
        if isinstance(exc, OutputFileError):
            raise
        raise OutputFileError(f"cannot write {args.output}: {exc}") from None
    if args.json_path == STDOUT:
        write_json_report(report, STDOUT, console)
        return done_code(model, skipped=bool(result.skipped))
    for face, block in zip(result.faces, result.network.blocks, strict=True):
        q, q0 = block.quality, block.start_quality
        ell = block.elliptic
        how = ("algebraic" if ell is None else
               f"elliptic {'converged' if ell.converged else 'stopped'} at residual "
               f"{ell.residuals[-1]:.2g} in {ell.sweeps} sweeps" if ell.residuals else "elliptic")
        console.print(f"face {face}: {block.dims[0]} x {block.dims[1]}, skewness "
                      f"{q0.max_skewness:.3f} -> {q.max_skewness:.3f}, angles "
                      f"{q.min_angle:.1f}-{q.max_angle:.1f} deg, {q.folded_cells} folded, {how}, "
                      f"{block.time_s:.2f} s")
        if block.kept_start:
            console.note(f"face {face}: {block.kept_start}")
        if block.orthogonal_dropped:
            console.note(f"face {face}: {block.orthogonal_dropped}")
    for face, reason in result.skipped:
        console.print(f"face {face}: not gridded: {reason}")
    net = result.network
    if net.dims_changed:
        console.note(f"{len(net.dims_changed)} block direction(s) got {max(n for *_, n in net.dims_changed)} "
                     "nodes, not the --dims asked: shared edges link them to directions of the other kind "
                     "(faces split into blocks, faces meeting i to j)")
    if net.cuts:
        console.note(f"{net.cuts} cut(s) through faces so that no block corner lies inside another "
                     "block's side (T-junctions): every shared edge is a whole side of both blocks")
    if net.t_junctions_left:
        console.note(f"{net.t_junctions_left} block corner(s) still lie inside another block's side: "
                     "the grids do not meet there")
    console.print(f"{len(net.blocks)} block(s), {len(net.interfaces)} shared edge(s) point-matched "
                  f"(largest snap {net.snap:.2g} mm, kink {net.kink:.1f} deg) in {elapsed:.2f} s, "
                  f"written to {written}")
    if report_path is not None:
        console.note(f"report written to {report_path}")
    return done_code(model, skipped=bool(result.skipped))


def _cells(ax, xy: np.ndarray, skew: np.ndarray, cmap) -> None:
    from matplotlib.collections import PolyCollection
    quads = np.stack([xy[:-1, :-1], xy[1:, :-1], xy[1:, 1:], xy[:-1, 1:]], axis=2).reshape(-1, 4, 2)
    coll = PolyCollection(quads, array=np.nan_to_num(skew.reshape(-1)), cmap=cmap, clim=(0.0, 1.0),
                          edgecolors="k", linewidths=0.2)
    ax.add_collection(coll)
    ax.autoscale_view()
    ax.set_aspect("equal")
    return coll


def plot_grids(result, path: Path) -> Path:
    """The first blocks in their parameter domain before (TFI) and after the refinement
    and on the surface (in its principal plane), cells coloured by the equiangle
    skewness measured on the surface."""
    from ...algorithms.grid.quality import cell_skewness
    plt = pyplot()
    blocks = list(zip(result.faces, result.network.blocks, strict=True))[:PLOT_BLOCKS]
    fig, axes = plt.subplots(len(blocks), 3, figsize=(13, 3.8 * len(blocks)), squeeze=False)
    coll = None
    for row, (face, block) in enumerate(blocks):
        start_uv = block.parameters if block.start_parameters is None else block.start_parameters
        start_xyz = block.points if block.start_points is None else block.start_points
        for ax, uv, xyz, title in ((axes[row, 0], start_uv, start_xyz, "start (TFI)"),
                                   (axes[row, 1], block.parameters, block.points, "final")):
            coll = _cells(ax, uv, cell_skewness(xyz), "viridis")
            ax.set_title(f"face {face}: (u, v), {title}", fontsize="small")
        centred = block.points - block.points.reshape(-1, 3).mean(axis=0)
        _, _, vt = np.linalg.svd(centred.reshape(-1, 3), full_matrices=False)
        coll = _cells(axes[row, 2], centred @ vt[:2].T, cell_skewness(block.points), "viridis")
        axes[row, 2].set_title(f"face {face}: final, on the surface (principal plane)", fontsize="small")
    if coll is not None:
        fig.colorbar(coll, ax=axes, shrink=0.6, label="equiangle skewness (on the surface)")
    return save_figure(fig, path)


COMMAND = Command(
    name="grid",
    summary="structured surface grids on the four-sided faces (TFI + elliptic on the surface)",
    description=(
        "Grid every four-sided face (or the listed ones) with one structured block: nodes "
        "spread along the sides in exact arc length (uniform, or tanh / geometric stretching "
        "to a first spacing measured in mm), the interior from the normalized arc-length "
        "distribution mesh (Soni and Hamann's weighted TFI), then refined by the elliptic "
        "system of the surface's own metric (their eqs. 8-9; boundaries held, a step that would "
        "fold a cell refused). Faces that share an edge get the same nodes along it (identical "
        "coordinates), and the nodes slide along smooth shared edges so grid lines cross them "
        "without a kink. Faces that are not four-sided (holes, trims inside the surface, "
        "n-sided) are named with the reason: heal or split them first. The report gives per "
        "block the orthogonality, skewness, aspect and growth ratios, scaled Jacobian and folds, "
        "measured on the surface, before and after the refinement, and its residual history."),
    epilog=(
        "examples:\n"
        "  surfprep grid fuselage.stp -o fuselage.xyz\n"
        "  surfprep grid part.step -o part.cgns --size 5 --json r.json\n"
        "  surfprep grid wing.step -o wing.vtm --dims 101 41 --first-spacing 0.05\n"
        "  surfprep grid face.igs -o face.xyz --whole-surfaces --plot grid.png\n"
        "\n"
        "Plot3D is written as a multi-block, whole, 3-D grid with k = 1 (x, then y, then z per "
        "block, i fastest). Lengths are in millimetres."),
    add_arguments=_add_arguments,
    run=_run,
)
