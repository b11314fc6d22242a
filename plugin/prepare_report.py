"""The HTML report of :func:`surfprep.prepare`: the prepared model to look at.

:func:`write_prepare_report` puts a :class:`~surfprep.plugin.prepare.PrepareResult`
into one self-contained page (:func:`surfprep.plugin.report_html.write_html_report`):
the faces in a 3-D view coloured by what the preparation did to them (healed,
reparametrized, untouched; a healed face by its distance from the input faces), the intersection curves found, the grid blocks
coloured by their cells' equiangle skewness, and the tables of every stage with
the figures of the JSON report.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..algorithms.grid.quality import cell_skewness
from .occ.mesh import face_triangles
from .prepare import PrepareResult
from .report_html import ReportTable, SceneGrid, SceneMesh, ScenePolyline, write_html_report

__all__ = ["DEFLECTION", "DEVIATION_LABEL", "DISTANCE_TOL", "scene_of", "tables_of",
           "write_prepare_report"]

#: triangulation deflection of the view, as a share of the model's size
DEFLECTION = 2e-3
#: convergence of the closest points behind the healed faces' colours, share of the size
DISTANCE_TOL = 1e-7
#: the scale bar of the healed faces' colours
DEVIATION_LABEL = "healed faces: distance from the input faces (mm)"


def write_prepare_report(result: PrepareResult, path: str | os.PathLike, *,
                         title: str | None = None) -> Path:
    """Write the report of ``result`` as one HTML file (atomically); its path.

    Parameters
    ----------
    result : PrepareResult
    path : str or os.PathLike
        The ``.html`` file; its folder must exist.
    title : str, optional
        Default: "surfprep prepare: <input file name>".
    """
    source = result.source.path.name if result.source.path is not None else "model"
    meshes, polylines, grids = scene_of(result)
    summary = [f"input: {result.source.path or 'a model in memory'}",
               (f"faces: {result.source.n_faces} in, {result.model.n_faces} out "
                f"({_counts(result)}); {result.time_s:.1f} s")]
    summary += [s.line() for s in result.stages]
    return write_html_report(path, title=title or f"surfprep prepare: {source}",
                             summary=summary, tables=tables_of(result), meshes=meshes,
                             polylines=polylines, grids=grids)


def scene_of(result: PrepareResult) -> tuple[list[SceneMesh], list[ScenePolyline], list[SceneGrid]]:
    """The 3-D scene: one mesh per face of the prepared model (group: its status; a healed
    face coloured by each vertex's distance from the input faces), one polyline per
    intersection curve, one grid per block with its cells' skewness."""
    model = result.model
    deflection = DEFLECTION * model.size if model.size > 0 else 1.0
    inputs = _input_faces(result) if "healed" in result.face_status else None
    meshes = []
    for k, (vertices, triangles) in enumerate(face_triangles(model.faces, deflection=deflection)):
        if len(triangles):
            name = model.face_names[k] or f"face {k}"
            values = None
            if result.face_status[k] == "healed" and inputs is not None:
                values = inputs.distance(vertices, tol=DISTANCE_TOL * model.size)
                values = np.where(np.isfinite(values), values, np.nan)
            meshes.append(SceneMesh(name, vertices, triangles, result.face_status[k], values,
                                    None if values is None else DEVIATION_LABEL))
    polylines = [ScenePolyline(f"curve {k} (faces {c.face_a.index}, {c.face_b.index})",
                               np.asarray(c.points, dtype=float), "intersection curves")
                 for k, c in enumerate(result.curves or ())]
    grids = []
    if result.grid is not None:
        faces = result.grid.faces
        for k, points in enumerate(result.grid.blocks):
            grids.append(SceneGrid(f"block {k} (face {faces[k]})", points,
                                   cell_skewness(points), "equiangle skewness"))
    return meshes, polylines, grids


def tables_of(result: PrepareResult) -> list[ReportTable]:
    """The stages, the faces, and each stage's details, as tables."""
    tables = [ReportTable("Stages", ("stage", "status", "time (s)", "figures or reason"),
                          tuple((s.name, s.status, s.time_s,
                                 s.reason or "; ".join(f"{k.replace('_', ' ')} {v}"
                                                       for k, v in s.summary.items()))
                                for s in result.stages)),
              ReportTable("Faces of the prepared model", ("face", "name", "status"),
                          tuple((k, name or "", status) for k, (name, status) in
                                enumerate(zip(result.model.face_names, result.face_status))))]
    heal, reparam, grid = (result.stage(n) for n in ("heal", "reparam", "grid"))
    if heal.status == "done" and heal.report["patches"]:
        tables.append(ReportTable(
            "Healing patches", ("kind", "input faces", "resolution", "max error",
                                "deviation from input", "tol"),
            tuple((p["kind"], ", ".join(map(str, p["faces"])), "x".join(map(str, p["resolution"])),
                   p["max_error"], p["deviation_from_input"], p["tol"])
                  for p in heal.report["patches"])))
    if reparam.status == "done":
        tables.append(ReportTable(
            "Reparametrized faces", ("face", "status", "mismatch before", "mismatch after",
                                     "max deviation", "poles before", "poles after"),
            tuple((f["index"], f["status"], f.get("mismatch_before"), f.get("mismatch_after"),
                   f.get("max_deviation"), f.get("poles_before"), f.get("poles_after"))
                  for f in reparam.report["faces"])))
    if result.curves:
        tables.append(ReportTable(
            "Intersection curves", ("curve", "faces", "points", "length", "found by"),
            tuple((k, f"{c.face_a.index}, {c.face_b.index}", len(c.points), c.length,
                   c.found_by.value) for k, c in enumerate(result.curves))))
    if grid.status == "done":
        tables.append(ReportTable(
            "Grid blocks", ("block", "face", "nodes", "max skewness", "min angle (deg)",
                            "folded cells"),
            tuple((k, b["face"], "x".join(map(str, b["dims"])), b["quality"]["max_skewness"],
                   b["quality"]["min_angle"], b["quality"]["folded_cells"])
                  for k, b in enumerate(grid.report["blocks"]))))
    return tables


def _input_faces(result: PrepareResult):
    """The input model's faces, prepared for distance queries (those that cannot be read
    as NURBS left out); None when none can."""
    from ..algorithms.healing.fidelity import InputFaces
    from ..errors import SurfprepError
    from .occ.faces import face_to_nurbs
    faces = []
    for face in result.source.faces:
        try:
            faces.append(face_to_nurbs(face))
        except SurfprepError:
            continue
    return InputFaces.of(faces) if faces else None


def _counts(result: PrepareResult) -> str:
    return ", ".join(f"{result.face_status.count(k)} {k}"
                     for k in ("healed", "reparametrized", "untouched"))
