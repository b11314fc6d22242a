"""The demo (``surfprep demo``): the whole pipeline, end to end, on a bundled sample.

Steps (later features append theirs to :func:`run_demo`):

1. read the sample (``step_samples/<name>`` next to the package) and print the
   ``info`` table;
2. convert every B-spline/Bezier face's surface to a
   :class:`~surfprep.algorithms.NurbsSurface` and back to OpenCascade, and on a
   dense grid over the face's UV bounds measure the largest distance between
   surfprep's evaluation and OpenCascade's evaluation of the face's own surface,
   and between the rebuilt OpenCascade surface and the original;
3. rebuild each face on the converted surface (with its trimming loops through
   :mod:`surfprep.plugin.occ.faces`, or with natural boundaries if that fails),
   write them to ``OUTDIR/<sample>-rebuilt.step`` and read that file back;
4. prepare the model (:func:`surfprep.prepare`: heal, intersect, reparametrize, and
   grid every four-sided face with point-matched blocks refined on the surface
   metric), write ``OUTDIR/<sample>-prepared.step`` (read back) and
   ``OUTDIR/<sample>-grid.xyz`` (Plot3D);
5. write ``OUTDIR/<sample>-report.json`` and ``OUTDIR/<sample>-report.html`` (the
   model in a 3-D view, the tables) and print a summary.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.TopoDS import TopoDS_Face

import surfprep

from ..algorithms import NurbsSurface
from ..errors import ConversionError, InputFileError, OutputFileError, SurfprepError
from .commands.base import Console, refuse_overwriting_inputs, write_json_report
from .describe import SPLINE_KINDS, SurfaceKind, format_table, model_report, surface_kind
from .io import CadModel, read, write
from .occ.faces import face_to_nurbs, make_face, trimmed_face_to_occ
from .occ.geom import surface_from_occ, surface_to_occ
from .occ.shapes import compound, face_area
from .occ_reference import evaluate_surface
from .prepare import PrepareResult, prepare
from .prepare_report import write_prepare_report

__all__ = [
    "DEVIATION_TOLERANCE",
    "GRID_SIZE",
    "FaceRoundTrip",
    "bundled_sample",
    "run_demo",
    "samples_dir",
]

#: Points per direction of the deviation grid on each face.
GRID_SIZE = 50
#: Largest accepted deviation, relative to the model size (bbox diagonal).
DEVIATION_TOLERANCE = 1e-9


def samples_dir() -> Path:
    """``step_samples/`` of the source tree the package runs from."""
    return Path(surfprep.__file__).resolve().parents[1] / "step_samples"


def bundled_sample(name: str) -> Path:
    """The bundled sample ``name`` in :func:`samples_dir` (InputFileError naming the others)."""
    directory = samples_dir()
    path = directory / name
    if not directory.is_dir():
        raise InputFileError(
            f"bundled samples not found: {directory} does not exist (surfprep is not "
            "running from its source tree; pass --input FILE instead)")
    if not path.is_file():
        available = sorted(p.name for p in directory.iterdir()
                           if p.suffix.lower() in (".step", ".stp", ".igs", ".iges"))
        raise InputFileError(f"no bundled sample {name!r} in {directory}; available: "
                             f"{', '.join(available) or 'none'}")
    return path


@dataclass(frozen=True)
class FaceRoundTrip:
    """Deviations of one spline face's NURBS round trip (model units, mm)."""

    index: int
    name: str | None
    surface_type: str
    max_dev_nurbs_vs_occ: float
    max_dev_rebuilt_vs_occ: float
    rebuilt_as: str            # "trimmed" or "natural boundary"
    rebuild_note: str | None
    area_original: float
    area_rebuilt: float


def _uv_grid(face: TopoDS_Face, surface: NurbsSurface, geom_surface, n: int):
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    u = np.linspace(u0, u1, n)
    v = np.linspace(v0, v1, n)
    # a periodic OCC surface may be trimmed outside its first period: wrap into
    # the clamped NurbsSurface's domain (same geometry, same parametrization)
    du0, du1, dv0, dv1 = surface.domain
    u_ours = _wrap(u, du0, du1) if geom_surface.IsUPeriodic() else u
    v_ours = _wrap(v, dv0, dv1) if geom_surface.IsVPeriodic() else v
    return u, v, u_ours, v_ours


def _wrap(t: np.ndarray, lo: float, hi: float) -> np.ndarray:
    period = hi - lo
    wrapped = lo + np.mod(t - lo, period)
    # keep the period's end rather than jumping back to its start
    return np.where((wrapped - lo < 1e-12 * period) & (t > lo), hi, wrapped)


def _rebuild(face: TopoDS_Face, surface: NurbsSurface, name: str | None):
    """The face on the converted surface: trimmed via plugin.occ.faces, else natural."""
    try:
        rebuilt = trimmed_face_to_occ(face_to_nurbs(face, name))
        return rebuilt, "trimmed", None
    except (SurfprepError, ImportError, AttributeError) as exc:
        return make_face(surface), "natural boundary", " ".join(str(exc).split())


def round_trip_face(face: TopoDS_Face, index: int, name: str | None,
                    grid_size: int = GRID_SIZE) -> tuple[FaceRoundTrip, TopoDS_Face]:
    """Convert a spline face to NurbsSurface and back; measure both deviations."""
    geom_surface = BRep_Tool.Surface_s(face)
    adaptor = GeomAdaptor_Surface(geom_surface)
    kind = surface_kind(adaptor)
    if kind not in SPLINE_KINDS:
        raise ConversionError(f"face {index} is a {kind.value} face, not a B-spline/Bezier one")
    basis = adaptor.BSpline() if kind is SurfaceKind.BSPLINE else adaptor.Bezier()
    nurbs = surface_from_occ(basis)
    u, v, u_ours, v_ours = _uv_grid(face, nurbs, basis, grid_size)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    reference = evaluate_surface(geom_surface, uu, vv)[..., 0, 0, :]   # (n, n, 3)
    ours = nurbs.evaluate_grid(u_ours, v_ours)
    uu_ours, vv_ours = np.meshgrid(u_ours, v_ours, indexing="ij")
    rebuilt_surface = evaluate_surface(surface_to_occ(nurbs), uu_ours, vv_ours)[..., 0, 0, :]
    rebuilt_face, how, note = _rebuild(face, nurbs, name)
    trip = FaceRoundTrip(
        index=index, name=name, surface_type=kind.value,
        max_dev_nurbs_vs_occ=float(np.max(np.linalg.norm(ours - reference, axis=-1))),
        max_dev_rebuilt_vs_occ=float(np.max(np.linalg.norm(rebuilt_surface - reference,
                                                           axis=-1))),
        rebuilt_as=how, rebuild_note=note,
        area_original=face_area(face), area_rebuilt=face_area(rebuilt_face))
    return trip, rebuilt_face


def run_demo(source: Path, outdir: Path, console: Console) -> tuple[dict, bool]:
    """Run every demo step on ``source``; returns (report, all checks passed)."""
    started = time.perf_counter()
    model = read(source)
    info = model_report(model, progress=console.progress)
    console.print(format_table(info))
    console.print("")

    spline_indices = [f["index"] for f in info["faces"]
                      if f["surface_type"] in {k.value for k in SPLINE_KINDS}]
    trips: list[FaceRoundTrip] = []
    rebuilt_faces, rebuilt_names = [], []
    for count, i in enumerate(spline_indices, start=1):
        console.progress(count, len(spline_indices), "round trip face")
        trip, rebuilt = round_trip_face(model.faces[i], i, model.face_names[i])
        trips.append(trip)
        rebuilt_faces.append(rebuilt)
        rebuilt_names.append(model.face_names[i] or f"face {i}")

    try:
        outdir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputFileError(f"cannot create output directory {outdir}: "
                              f"{exc.strerror or exc}") from None
    stem = source.name.rsplit(".", 1)[0]
    step_path = outdir / f"{stem}-rebuilt.step"
    report_path = outdir / f"{stem}-report.json"
    inputs = (model.path,)
    written = None
    reread_faces = 0
    if rebuilt_faces:
        refuse_overwriting_inputs(step_path, inputs)
        shape = rebuilt_faces[0] if len(rebuilt_faces) == 1 else compound(rebuilt_faces)
        rebuilt_model = CadModel(shape, tuple(rebuilt_faces), tuple(rebuilt_names),
                                 tuple(model.face_colors[t.index] for t in trips))
        written = write(rebuilt_model, step_path, overwrite=True)
        reread_faces = read(written).n_faces

    prepared, prepare_report = _prepare_step(model, outdir, stem, inputs, console)
    grid_report = prepare_report["grid"]
    grid_ok = grid_report.get("worst", {}).get("folded_cells", 0) == 0

    tolerance = DEVIATION_TOLERANCE * model.size
    worst_eval = max((t.max_dev_nurbs_vs_occ for t in trips), default=0.0)
    worst_rebuilt = max((t.max_dev_rebuilt_vs_occ for t in trips), default=0.0)
    checks = {
        "nurbs_matches_occ": worst_eval <= tolerance,
        "rebuilt_surface_matches_occ": worst_rebuilt <= tolerance,
        "rebuilt_file_face_count": reread_faces == len(rebuilt_faces),
        "grid_without_folds": grid_ok,
        "no_stage_failed": all(st.status != "failed" for st in prepared.stages),
        "prepared_file_face_count":
            prepare_report["prepared_step_faces_read_back"] == prepared.model.n_faces,
    }
    quality = [(f["param_quality"], f["index"]) for f in info["faces"]
               if f["param_quality"] is not None]
    report = {
        "input": str(model.path),
        "info": info,
        "round_trip": {
            "grid": [GRID_SIZE, GRID_SIZE],
            "tolerance": tolerance,
            "max_dev_nurbs_vs_occ": worst_eval,
            "max_dev_rebuilt_vs_occ": worst_rebuilt,
            "faces": [asdict(t) for t in trips],
        },
        "prepare": prepared.report(),
        "grid": grid_report,
        "outputs": {"rebuilt_step": str(written) if written else None,
                    "rebuilt_step_faces_read_back": reread_faces,
                    "prepared_step": prepare_report["prepared_step"],
                    "prepared_step_faces_read_back":
                        prepare_report["prepared_step_faces_read_back"],
                    "grid": grid_report.get("output"),
                    "html_report": prepare_report["html_report"],
                    "report": str(report_path.resolve())},
        "checks": checks,
        "seconds": round(time.perf_counter() - started, 3),
    }
    write_json_report(report, report_path, console, protected=inputs)

    worst_q = max(quality, default=None)
    n_trimmed = sum(t.rebuilt_as == "trimmed" for t in trips)
    console.print("summary:")
    console.print(f"  {len(trips)} of {model.n_faces} faces are B-spline/Bezier; "
                  f"converted to NurbsSurface and back to OpenCascade")
    console.print(f"  max deviation on a {GRID_SIZE}x{GRID_SIZE} grid per face: "
                  f"surfprep vs OpenCascade {worst_eval:.3g}, rebuilt vs original "
                  f"{worst_rebuilt:.3g} ({model.model_unit}; tolerance {tolerance:.3g})")
    if worst_q is not None:
        console.print(f"  worst parametrization mismatch (eqs. 29.1/29.2): "
                      f"{worst_q[0]:.3g} on face {worst_q[1]} (1 = chord-length)")
    if written:
        console.print(f"  rebuilt faces ({n_trimmed} trimmed, {len(trips) - n_trimmed} "
                      f"natural boundary): {written} ({reread_faces} faces read back)")
    console.print("  surfprep prepare (heal, intersect, reparametrize, grid):")
    for stage in prepared.stages:
        console.print(f"    {stage.line()}")
    console.print(f"  prepared model: {prepare_report['prepared_step']}")
    if grid_report.get("output"):
        worst = grid_report["worst"]
        console.print(f"  structured grid: {grid_report['blocks']} block(s), point-matched on "
                      f"{grid_report['interfaces']} shared edge(s), max skewness "
                      f"{worst['max_skewness']:.3f}, {worst['folded_cells']} folded cell(s): "
                      f"{grid_report['output']}")
    else:
        console.print(f"  structured grid: none ({grid_report.get('reason')})")
    console.print(f"  report: {report_path.resolve()}")
    console.print(f"  look at it: {prepare_report['html_report']} (open it in a browser)")
    failed = [name for name, ok in checks.items() if not ok]
    if failed:
        console.note(f"surfprep demo: check failed: {', '.join(failed)}")
    return report, not failed


def _prepare_step(model: CadModel, outdir: Path, stem: str, inputs, console: Console
                  ) -> tuple[PrepareResult, dict]:
    """:func:`surfprep.prepare` on the model with a grid (elliptic, default sizes): the
    prepared model to ``<stem>-prepared.step`` (read back), the blocks to
    ``<stem>-grid.xyz`` (Plot3D), the HTML report to ``<stem>-report.html``."""
    step_path, grid_path = outdir / f"{stem}-prepared.step", outdir / f"{stem}-grid.xyz"
    for target in (step_path, grid_path):
        refuse_overwriting_inputs(target, inputs)
    html_path = outdir / f"{stem}-report.html"
    refuse_overwriting_inputs(html_path, inputs)
    result = prepare(model, heal="G0", grid=True,
                     progress=lambda stage, done, total: console.progress(done, total, stage))
    written = write(result.model, step_path, overwrite=True)
    out = {"prepared_step": str(written), "prepared_step_faces_read_back": read(written).n_faces,
           "html_report": str(write_prepare_report(result, html_path,
                                                   title=f"surfprep demo: {stem}"))}
    grid_stage = result.stage("grid")
    if result.grid is None:
        out["grid"] = {"output": None, "reason": grid_stage.reason}
        return result, out
    grid_written = result.grid.write(grid_path)
    report = grid_stage.report
    out["grid"] = {"output": str(grid_written), "blocks": len(result.grid.blocks),
                   "interfaces": len(result.grid.network.interfaces), "worst": report["worst"],
                   "skipped": report["skipped"], "time_s": result.grid.time_s}
    return result, out
