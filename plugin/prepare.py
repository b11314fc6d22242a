"""The whole preparation of a CAD model in one call: :func:`prepare`.

A user's job is a chain: read a model, heal it, reparametrize its faces, find the
intersections it should not have, grid it, write it for the mesher. Each stage
here is one of surfprep's verbs, run on what the stage before produced:

1. **heal** (:func:`surfprep.heal`, G0 or G1): gaps, holes and overlaps replaced
   by joined bicubic approximants, where there are defects;
2. **intersect** (:func:`surfprep.intersect`, the model with itself): faces
   crossing one another (common edges of adjacent faces are not crossings). It runs
   before the reparametrization: that moves each surface within its tolerance, and
   neighbours moved apart by a fraction of it cross along their common edges, which
   is not a fault of the model;
3. **reparam** (:func:`surfprep.plugin.reparam.reparametrize_model`): every
   B-spline face on a chord-length surface within the tolerance;
4. **grid** (:func:`surfprep.grid`, asked for): structured grids on the
   four-sided faces.

A stage that does not apply is *skipped* with the reason (no B-spline face to
reparametrize, one face only to intersect); a stage that fails is *failed* with
OpenCascade's or surfprep's message and the chain goes on with the model as it
was. Every stage's own report is kept whole, with a few headline figures beside
it (:class:`StageReport`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidToleranceError, SurfprepError
from .dropped import dropped_report, repaired_report
from .io import CadModel, as_model, write
from .occ.failures import describe, is_occ_failure
from .time_limit import step_time_limit

__all__ = ["STAGES", "PrepareResult", "StageReport", "face_status", "prepare"]

#: the stages in the order they run
STAGES = ("heal", "intersect", "reparam", "grid")
#: a face of the prepared model is the input's own when its area and centroid agree with
#: an input face's within this share of the model's size (else a healing approximant)
SAME_FACE = 1e-6


@dataclass(frozen=True)
class StageReport:
    """What one stage did.

    Attributes
    ----------
    name : str
        One of :data:`STAGES`.
    status : str
        ``"done"``, ``"skipped"`` (did not apply, or not asked for) or ``"failed"``.
    reason : str
        Why it was skipped or failed ("" when done).
    time_s : float
    summary : dict
        Headline figures (plain JSON): faces healed, free edges before and after,
        curves found, worst skewness...
    report : dict
        The verb's own full report (plain JSON), empty when not done.
    """

    name: str
    status: str
    reason: str = ""
    time_s: float = 0.0
    summary: dict = field(default_factory=dict)
    report: dict = field(default_factory=dict)

    def line(self) -> str:
        """One line for a person: ``heal: done in 1.2 s: 3 faces healed, ...``."""
        if self.status != "done":
            return f"{self.name}: {self.status}: {self.reason}"
        figures = ", ".join(f"{k.replace('_', ' ')} {_short(v)}" for k, v in self.summary.items())
        return f"{self.name}: done in {self.time_s:.2f} s" + (f": {figures}" if figures else "")

    def as_dict(self) -> dict:
        return {"stage": self.name, "status": self.status, "reason": self.reason,
                "time_s": self.time_s, "summary": self.summary, "report": self.report}


@dataclass(frozen=True, eq=False)
class PrepareResult:
    """What :func:`prepare` made.

    Attributes
    ----------
    model : CadModel
        The prepared model (the input's when no stage changed it).
    source : CadModel
        The model as read.
    stages : tuple of StageReport
        One per stage of :data:`STAGES`, in order.
    face_status : tuple of str
        Per face of :attr:`model`: ``"untouched"``, ``"healed"`` (an approximant, a face
        moved onto its neighbours' edges, or a
        filled hole) or ``"reparametrized"``.
    curves : IntersectionResult or None
        The intersect stage's curves.
    grid : GridResult or None
        The grid stage's blocks.
    time_s : float
    """

    model: CadModel
    source: CadModel
    stages: tuple[StageReport, ...]
    face_status: tuple[str, ...]
    curves: Any = None
    grid: Any = None
    time_s: float = 0.0

    @property
    def geometry(self):
        """The prepared ``TopoDS_Shape``."""
        return self.model.shape

    def stage(self, name: str) -> StageReport:
        """The report of the stage ``name``."""
        for s in self.stages:
            if s.name == name:
                return s
        raise KeyError(f"no stage {name!r}; the stages are {', '.join(STAGES)}")

    def report(self) -> dict:
        """Plain-JSON report: the input, per stage its status and figures, per face its
        status, what the reader dropped or repaired."""
        counts = {k: self.face_status.count(k) for k in ("untouched", "healed", "reparametrized")}
        return {"input": None if self.source.path is None else str(self.source.path),
                "faces_in": self.source.n_faces, "faces_out": self.model.n_faces,
                "face_status": list(self.face_status), "face_status_counts": counts,
                "time_s": self.time_s, "stages": [s.as_dict() for s in self.stages],
                "dropped": dropped_report(self.source),
                "repaired": repaired_report(self.source)}

    def write(self, path, *, overwrite: bool = False) -> Path:
        """Write the prepared model as STEP or IGES (:func:`surfprep.write`)."""
        return write(self.model, path, overwrite=overwrite)


def prepare(source: Any, *, heal: str | None = "G0", reparam: bool = True,
            intersect: bool = True, grid: bool = False,
            grid_options: Mapping[str, Any] | None = None, tol: float | None = None,
            step_time_limit_s: float | None = None,
            progress: Callable[[str, int, int], None] | None = None) -> PrepareResult:
    """Heal, intersect, reparametrize and grid a model, each stage on the one before.

    Parameters
    ----------
    source : path, CadModel or shape
        What :func:`surfprep.read` reads, a model, or anything :func:`surfprep.write`
        takes.
    heal : {"G0", "G1", None}
        Continuity of the healing joins; None (or "off") leaves healing out.
    reparam, intersect, grid : bool
        Whether to run those stages (grid is off unless asked for).
    grid_options : mapping, optional
        Keyword arguments of :func:`surfprep.grid` (``dims``, ``size``, ``spacing``...).
    tol : float, optional
        The geometric tolerance of every stage in model units (approximants,
        reparametrized surfaces and curves within it); default each stage's own, from
        the model's size.
    step_time_limit_s : float, optional
        A step (an approximant, a face, a face pair) that runs longer is stopped and
        reported, and the stage goes on (a ``SIGALRM`` timer, main thread only; none by
        default).
    progress : callable(stage, done, total), optional
        Called as each stage goes (``"heal"``, 3, 12).

    Returns
    -------
    PrepareResult

    Raises
    ------
    InvalidToleranceError
        ``tol`` not a finite positive number.
    InputFileError
        ``source`` cannot be read.

    Examples
    --------
    >>> result = surfprep.prepare("part.step", heal="G1", grid=True)   # doctest: +SKIP
    >>> for stage in result.stages:                                       # doctest: +SKIP
    ...     print(stage.line())
    """
    if tol is not None and not (np.isfinite(tol) and tol > 0):
        raise InvalidToleranceError(f"tol must be a finite number > 0, got {tol}")
    if heal is not None and str(heal).upper() not in ("G0", "G1", "OFF"):
        raise ValueError(f"heal must be 'G0', 'G1' or None, got {heal!r}")
    heal = None if heal is None or str(heal).upper() == "OFF" else str(heal).upper()
    started = time.perf_counter()
    source = as_model(source)
    model, stages = source, []
    healed, reparametrized = np.zeros(source.n_faces, bool), np.zeros(source.n_faces, bool)
    curves = grid_result = None

    def ticker(stage: str, restart) -> Callable[[int, int], None]:
        def tick(done: int, total: int) -> None:
            restart(last=done >= total)
            if progress is not None:
                progress(stage, done, total)
        return tick

    # heal
    if heal is None:
        stages.append(StageReport("heal", "skipped", "not asked for (heal off)"))
    else:
        report, out = _run_stage("heal", lambda tick: _heal(model, heal, tol, tick),
                                 step_time_limit_s, "an approximant", ticker)
        stages.append(report)
        if out is not None:
            model, healed = out
            reparametrized = np.zeros(model.n_faces, bool)   # over the healed model's faces
    # intersect
    if not intersect:
        stages.append(StageReport("intersect", "skipped", "not asked for"))
    elif model.n_faces < 2:
        stages.append(StageReport("intersect", "skipped", "the model has one face: nothing "
                                                          "to intersect it with"))
    else:
        report, curves = _run_stage("intersect", lambda tick: _intersect(model, tol, tick),
                                    step_time_limit_s, "a face pair", ticker)
        stages.append(report)
    # reparametrize
    if not reparam:
        stages.append(StageReport("reparam", "skipped", "not asked for"))
    else:
        report, out = _run_stage("reparam", lambda tick: _reparam(model, tol, tick),
                                 step_time_limit_s, "a face", ticker)
        stages.append(report)
        if out is not None:
            model, reparametrized = out
    # grid
    if not grid:
        stages.append(StageReport("grid", "skipped", "not asked for"))
    else:
        report, grid_result = _run_stage("grid", lambda tick: _grid(model, grid_options, tick),
                                         None, "a block", ticker)
        stages.append(report)
    status = face_status(model, healed, reparametrized)
    return PrepareResult(model, source, tuple(stages), status, curves, grid_result,
                         time.perf_counter() - started)


def face_status(model: CadModel, healed, reparametrized) -> tuple[str, ...]:
    """Per face of ``model``: "healed" (an approximant, reparametrized or not),
    "reparametrized" or "untouched" (``healed`` and ``reparametrized`` are boolean arrays
    over the faces)."""
    return tuple("healed" if h else ("reparametrized" if r else "untouched")
                 for h, r in zip(healed, reparametrized, strict=True))


# ------------------------------------------------------------------- stages
def _run_stage(name: str, run: Callable, limit: float | None, step: str, ticker
               ) -> tuple[StageReport, Any]:
    """Run one stage: ``run(tick)`` returns ``(summary, report, output)``; a SurfprepError
    or an OpenCascade failure makes the stage "failed" and the output None."""
    started = time.perf_counter()
    try:
        with step_time_limit(limit, step) as restart:
            summary, report, output = run(ticker(name, restart))
    except SurfprepError as exc:
        return StageReport(name, "failed", _one_line(exc), time.perf_counter() - started), None
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        return StageReport(name, "failed", f"OpenCascade failed: {describe(exc)}",
                           time.perf_counter() - started), None
    if output is None and "skipped" in summary:
        return StageReport(name, "skipped", summary["skipped"], time.perf_counter() - started), None
    return StageReport(name, "done", "", time.perf_counter() - started, summary, report), output


def _heal(model: CadModel, continuity: str, tol: float | None, tick):
    from .heal import heal
    result = heal(model, tol=tol, continuity=continuity, progress=tick)
    report = result.report()
    free = report["free_edges"]
    summary = {"patches": len(report["patches"]),
               "free_edges": f"{free['before']} -> {free['after']}",
               "valid": f"{report['valid']['before']} -> {report['valid']['after']}",
               "worst_deviation": max((p["deviation_from_input"] for p in report["patches"]),
                                      default=0.0)}
    moved = [m["face"] for m in report.get("closed_gaps", {}).get("faces_moved", [])]
    summary["faces_moved"] = len(moved)
    if not report["patches"] and not moved and result.model.n_faces == model.n_faces:
        summary["note"] = "nothing to heal"
    healed = _new_faces(model, result.model)
    healed[[k for k in moved if k < healed.size]] = True     # moved onto common edges
    return summary, report, (result.model, healed)


def _reparam(model: CadModel, tol: float | None, tick):
    from .reparam import is_bspline_face, reparametrize_model
    if not any(is_bspline_face(f) for f in model.faces):
        return ({"skipped": f"no B-spline face to reparametrize (of {model.n_faces} faces)"},
                {}, None)
    shape, entries = reparametrize_model(model, tol=tol, progress=tick)
    done = [e for e in entries if e.done is not None]
    out = CadModel.from_shape(shape)
    if out.n_faces != model.n_faces:
        raise SurfprepError(f"reparametrization changed the face count {model.n_faces} -> "
                            f"{out.n_faces}; the model is kept as it was")
    out = CadModel(out.shape, out.faces, model.face_names, model.face_colors,
                   model.length_unit, model.path, model.file_format)
    changed = np.zeros(model.n_faces, bool)
    changed[[e.index for e in done]] = True
    summary = {"faces": f"{len(done)} of {len(entries)}",
               "worst_mismatch": (f"{max(e.done.result.mismatch_before for e in done):.3g} -> "
                                  f"{max(e.done.result.mismatch_after for e in done):.3g}")
               if done else "-",
               "max_deviation": max((e.done.result.max_deviation for e in done), default=0.0)}
    report = {"tol": done[0].done.result.tol if done else tol,
              "faces": [e.report() for e in entries]}
    return summary, report, (out, changed)


def _intersect(model: CadModel, tol: float | None, tick):
    from .intersect import intersect
    results = intersect(model, tol=tol, progress=tick)
    report = results.report()
    summary = {"curves": len(results), "coincident": len(report.get("coincident", [])),
               "isolated_points": len(report.get("isolated_points", [])),
               "stopped_pairs": len(results.stopped)}
    return summary, report, results


def _grid(model: CadModel, options: Mapping[str, Any] | None, tick):
    from .grid import grid
    result = grid(model, progress=tick, **dict(options or {}))
    report = result.report()
    worst = report["worst"]
    if not result.blocks:
        reasons = "; ".join(f"face {s['face']}: {s['reason']}" for s in report["skipped"][:3])
        return {"skipped": f"no four-sided face to grid ({reasons})"}, {}, None
    summary = {"blocks": len(result.blocks), "skipped_faces": len(report["skipped"]),
               "max_skewness": worst.get("max_skewness"),
               "folded_cells": worst.get("folded_cells")}
    return summary, report, result


# ------------------------------------------------------------------ helpers
def _new_faces(before: CadModel, after: CadModel) -> np.ndarray:
    """Per face of ``after``: True when no face of ``before`` has its area and centroid
    (within :data:`SAME_FACE` x size): a face the healing made."""
    from .occ.shapes import area_and_centroid
    scale = max(before.size, 1e-300)
    old = np.array([(a, *c) for a, c in map(area_and_centroid, before.faces)]).reshape(-1, 4)
    new = np.array([(a, *c) for a, c in map(area_and_centroid, after.faces)]).reshape(-1, 4)
    if len(old) == 0:
        return np.ones(len(new), bool)
    area_tol = SAME_FACE * scale * scale
    same_area = np.abs(new[:, None, 0] - old[None, :, 0]) <= area_tol + SAME_FACE * old[None, :, 0]
    same_place = np.linalg.norm(new[:, None, 1:] - old[None, :, 1:], axis=2) <= SAME_FACE * scale
    return ~np.any(same_area & same_place, axis=1)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.3g}"
    return str(value)
