"""Chord-length (RCA) reparametrization of surfaces and trimmed faces (000 §29.2).

:func:`reparametrize` is the public entry point (``surfprep.reparametrize``):

=========================================  ==========================================
input                                      ``.geometry`` of the result
=========================================  ==========================================
:class:`NurbsSurface`, ``Geom_Surface``     :class:`NurbsSurface`
``TopoDS_Face``                             ``TopoDS_Face``
``cadquery.Face`` / ``build123d.Face``      the same class, wrapping the new face
:class:`TrimmedFace`                        :class:`TrimmedFace`
=========================================  ==========================================

A face keeps its boundary: the new face is built on the new surface with the
*same* edges (3D curves and vertices untouched, so in a shell it stays
connected to its neighbours); each edge gets a new pcurve, computed by
projecting dense samples of its 3D curve onto the new surface (start:
the old pcurve mapped through the reparametrization) and interpolating them
with a C2 cubic over the edge's range, refined until the pcurve mapped through
the new surface is within ``tol / 2`` of the 3D curve. The face is checked by
``BRepCheck_Analyzer`` and its area compared with the original's.

The input is never modified: faces are copied (``BRepBuilderAPI_Copy``) first.
The default tolerance is 1e-4 of the control-net bounding-box diagonal.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.Geom import Geom_BSplineSurface, Geom_Surface
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Face

from ..algorithms import NurbsCurve, NurbsSurface
from ..algorithms.fitting import approximate_curve, interpolate_curve, knots_from_breakpoints
from ..algorithms.projection import project_to_surface
from ..algorithms.reparam import ReparametrizationResult, reparametrize_surface
from ..algorithms.reparam.deviation import inverse_map
from ..algorithms.trimmed import DEFAULT_TOLERANCE, TrimEdge, TrimmedFace
from ..errors import (
    ConversionError,
    InvalidGeometryError,
    InvalidShapeWarning,
    OpenCascadeError,
)
from .convert import unwrap
from .occ.edges import read_trim_edge
from .occ.faces import checked_or_fixed, face_to_nurbs, trimmed_face_to_occ
from .occ.failures import describe, is_occ_failure
from .occ.geom import curve2d_to_occ, surface_from_occ, surface_to_occ
from .occ.shapes import all_faces, face_area, is_valid

__all__ = [
    "FaceReparametrization",
    "ReparametrizeResult",
    "fit_report",
    "ModelFace",
    "is_bspline_face",
    "reparametrize",
    "reparametrize_face",
    "reparametrize_model",
]

#: Pcurve samples per knot span of the edge's curves, and at least.
PCURVE_PER_SPAN, PCURVE_MIN = 10, 33
#: Default model tolerance: this fraction of the model's bounding-box diagonal.
DEFAULT_MODEL_RELATIVE_TOL = 1e-4
#: Doublings of the pcurve samples at most.
PCURVE_ROUNDS = 4
#: Halvings of the new pcurve's worst spans at most before it interpolates every sample.
PCURVE_REFINEMENTS = 12
#: relative error of the adaptive area integration in the report (the fixed-order
#: default is off by 0.35 % on the badly parametrized fuselage faces)
AREA_REL_TOL = 1e-7


@dataclass(frozen=True)
class FaceReparametrization:
    """A reparametrized face and its figures.

    Attributes
    ----------
    face : TopoDS_Face
        On the new surface, same edges, valid for ``BRepCheck_Analyzer``.
    result : ReparametrizationResult
        The surface-level result (deviation, mismatch, iterations...).
    area_before, area_after : float
        Face areas (``BRepGProp``).
    pcurve_deviation : float
        Largest distance between an edge's 3D curve and its new pcurve mapped
        through the new surface (dense: 4 points between pcurve samples).
    poles_before, poles_after : int
        Control points of the old and new surface.
    """

    face: TopoDS_Face
    result: ReparametrizationResult
    area_before: float
    area_after: float
    pcurve_deviation: float
    poles_before: int
    poles_after: int

    def report(self) -> dict:
        """Plain-JSON figures: the fit's (:func:`fit_report`) and the face's areas and
        pcurve deviation."""
        out = fit_report(self.result, self.poles_before, self.poles_after)
        out.update({"area_before": self.area_before, "area_after": self.area_after,
                    "pcurve_deviation": self.pcurve_deviation})
        return out


def fit_report(result: ReparametrizationResult, poles_before: int, poles_after: int) -> dict:
    """Plain-JSON figures of a fit: tolerance, deviation measured densely, chord-length
    mismatch before and after, poles, grid, rounds."""
    return {
        "tol": result.tol, "max_deviation": result.max_deviation,
        "mismatch_before": result.mismatch_before, "mismatch_after": result.mismatch_after,
        "poles_before": poles_before, "poles_after": poles_after,
        "grid": list(result.grid_shape), "iterations": result.iterations,
        "knots_inserted": result.knots_inserted, "lines_removed": result.lines_removed,
        "relocation_sweeps": result.relocation_sweeps,
    }


@dataclass(frozen=True, eq=False)
class ReparametrizeResult:
    """What :func:`surfprep.reparametrize` made: the geometry and its figures.

    Attributes
    ----------
    geometry : NurbsSurface, TopoDS_Face, cadquery / build123d Face or TrimmedFace
        The reparametrized surface or face, of the kind given.
    fit : ReparametrizationResult
        The surface's figures: deviation measured densely both ways, chord-length
        mismatch before and after, grid, rounds.
    face : FaceReparametrization or None
        For a face: the rebuilt face's areas and pcurve deviation.
    poles_before : int
        Control points of the original surface.
    time_s : float
    """

    geometry: Any
    fit: ReparametrizationResult
    face: FaceReparametrization | None
    poles_before: int
    time_s: float

    def report(self) -> dict:
        """Plain-JSON report (the figures of ``face`` or of ``fit``, and the time)."""
        out = self.face.report() if self.face is not None else fit_report(
            self.fit, self.poles_before, int(np.prod(self.fit.surface.n_control)))
        out["time_s"] = self.time_s
        return out


def is_bspline_face(face: TopoDS_Face) -> bool:
    """True when the face lies on a ``Geom_BSplineSurface``."""
    return isinstance(BRep_Tool.Surface_s(face), Geom_BSplineSurface)


def _require_within(result: ReparametrizationResult) -> ReparametrizationResult:
    if not result.within_tolerance:
        raise InvalidGeometryError(
            f"reparametrization reached a deviation of {result.max_deviation:.3g} > tol = "
            f"{result.tol:.3g} after {result.iterations} rounds "
            f"({result.grid_shape[0]} x {result.grid_shape[1]} points); raise tol or "
            "max_iterations")
    return result


def _samples(edge: TrimEdge) -> np.ndarray:
    spans = 0
    for curve in (edge.curve3d, edge.pcurve):
        if curve is not None:
            spans = max(spans, len(np.unique(curve.knots)) - 1)
    return np.linspace(edge.t0, edge.t1, max(PCURVE_MIN, PCURVE_PER_SPAN * spans + 1))


def _new_pcurve(edge: TrimEdge, pcurve: NurbsCurve, old: NurbsSurface,
                result: ReparametrizationResult, tol: float) -> tuple[NurbsCurve, float]:
    """Pcurve of ``edge`` on the new surface (see module docstring) and its deviation."""
    new = result.surface
    t = _samples(edge)
    for _ in range(PCURVE_ROUNDS):
        uv_old = pcurve.evaluate(t)
        guess = _snap(inverse_map(result.params_u, result.params_v, result.uv, uv_old),
                      uv_old, old.domain, new.domain)
        if edge.degenerated or edge.curve3d is None:
            target = old.evaluate(uv_old[:, 0], uv_old[:, 1])
        else:
            target = edge.curve3d.evaluate(t)
        uv = project_to_surface(new, target, guess=guess).uv
        if edge.degenerated:
            uv = _keep_guess_at_poles(new, target, guess, uv, tol)
        # the edge lies on the old surface, up to tol off the new one: the pcurve is held
        # to tol / 2 beyond that, not to what no pcurve can reach
        foot = float(np.linalg.norm(new.evaluate(uv[:, 0], uv[:, 1]) - target, axis=1).max())
        goal = max(0.5 * tol, foot + 0.25 * tol)
        check = np.sort(np.concatenate([t, _between(t, 4)]))
        if edge.degenerated or edge.curve3d is None:
            uv_c = pcurve.evaluate(check)
            reference = old.evaluate(uv_c[:, 0], uv_c[:, 1])
        else:
            reference = edge.curve3d.evaluate(check)
        fit, deviation = _fewest_knots(uv, t, check, reference, new, _breakpoints(edge), goal)
        if deviation <= goal:
            break
        t = np.sort(np.concatenate([t, _between(t, 1)]))
    return fit, deviation


def _breakpoints(edge: TrimEdge) -> np.ndarray:
    """Where the new pcurve's knots start: the edge's ends and its 3D curve's knots."""
    inner = [] if edge.curve3d is None else edge.curve3d.knots[
        (edge.curve3d.knots > edge.t0) & (edge.curve3d.knots < edge.t1)]
    return np.unique(np.concatenate([[edge.t0, edge.t1], inner]))


def _span_errors(fit: NurbsCurve, breaks: np.ndarray, check: np.ndarray,
                 reference: np.ndarray, new: NurbsSurface) -> np.ndarray:
    """Largest distance per knot span ``(len(breaks) - 1,)`` of the pcurve mapped
    through ``new`` from the ``reference`` points at ``check``."""
    on = fit.evaluate(check)
    error = np.linalg.norm(new.evaluate(on[:, 0], on[:, 1]) - reference, axis=1)
    span = np.clip(np.searchsorted(breaks, check, side="right") - 1, 0, breaks.size - 2)
    out = np.zeros(breaks.size - 1)
    np.maximum.at(out, span, error)
    return out


def _fewest_knots(uv: np.ndarray, t: np.ndarray, check: np.ndarray, reference: np.ndarray,
                  new: NurbsSurface, breaks: np.ndarray, goal: float) -> tuple[NurbsCurve, float]:
    """The pcurve through the samples ``uv`` at ``t`` with as few knots as ``goal``
    allows (the largest distance from ``reference`` mapped through ``new``): a
    least-squares C2 cubic (ends interpolated, A9.7 of [PT]) on ``breaks``, whose
    spans off by more are halved, until within or a span holds too few samples; then
    the interpolant of all samples (a knot at each). Interpolating every sample gave a
    5278-span pcurve on an edge of occt_k1_catia_debis.stp face 21 (its old pcurve had
    528 spans), on which OpenCascade's adaptive area integration ran 44 s and failed."""
    for _ in range(PCURVE_REFINEMENTS):
        knots = np.concatenate([np.full(3, breaks[0]), breaks, np.full(3, breaks[-1])])
        n_control = knots.size - 4
        counts = np.diff(np.searchsorted(t, breaks, side="left"))
        if n_control >= t.size or counts.min() < 2:
            break
        try:
            fit = approximate_curve(uv, n_control, parameters=t, knots=knots)
        except InvalidGeometryError:          # a singular least-squares system
            break
        errors = _span_errors(fit, breaks, check, reference, new)
        if errors.max() <= goal:
            return fit, float(errors.max())
        bad = errors > goal
        breaks = np.unique(np.concatenate([breaks, 0.5 * (breaks[:-1] + breaks[1:])[bad]]))
    fit = interpolate_curve(uv, parameters=t, knots=knots_from_breakpoints(t, 3))
    return fit, float(_span_errors(fit, t, check, reference, new).max())


def _keep_guess_at_poles(new: NurbsSurface, target: np.ndarray, guess: np.ndarray,
                         projected: np.ndarray, tol: float) -> np.ndarray:
    """Pcurve samples of a degenerated edge: the mapped guess where it lies on the
    point (a pole: a whole side of the domain is a foot there, projection is ill-posed
    and the guess already sits on the right side), the projection where it does not (a
    tiny edge inside the face that a reader marked degenerated: the inverse map alone
    was 0.145 off at tol 0.017 on occt_catia4_face_L1 read back from STEP)."""
    on_point = np.linalg.norm(new.evaluate(guess[:, 0], guess[:, 1]) - target, axis=1) \
        <= 0.25 * tol
    return np.where(on_point[:, None], guess, projected)


def _snap(guess: np.ndarray, uv_old: np.ndarray, old_domain, new_domain) -> np.ndarray:
    """Points on a side of the old domain go to the same side of the new one
    (the reparametrization maps sides to sides; a pole edge lies on one)."""
    out = guess.copy()
    for axis in (0, 1):
        lo, hi = old_domain[2 * axis:2 * axis + 2]
        new_lo, new_hi = new_domain[2 * axis:2 * axis + 2]
        eps = 1e-9 * (hi - lo)
        out[np.abs(uv_old[:, axis] - lo) <= eps, axis] = new_lo
        out[np.abs(uv_old[:, axis] - hi) <= eps, axis] = new_hi
    return out


def _between(t: np.ndarray, k: int) -> np.ndarray:
    steps = np.arange(1, k + 1) / (k + 1)
    return (t[:-1, None] + steps * np.diff(t)[:, None]).ravel()


def _unique_edges(face: TopoDS_Face):
    seen, explorer = [], TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        explorer.Next()
        if not any(edge.IsSame(e) for e in seen):
            seen.append(edge)
    return seen


def _rebuild(forward: TopoDS_Face, result: ReparametrizationResult, old: NurbsSurface,
             tol: float) -> tuple[TopoDS_Face, float]:
    """New FORWARD face on ``result.surface`` with the edges of ``forward`` (a copy)."""
    brep = BRep_Builder()
    occ_surface = surface_to_occ(result.surface)
    face = TopoDS_Face()
    brep.MakeFace(face, occ_surface, TopLoc_Location(), max(BRep_Tool.Tolerance_s(forward),
                                                            DEFAULT_TOLERANCE))
    wires = TopExp_Explorer(forward, TopAbs_WIRE)
    while wires.More():
        brep.Add(face, wires.Current())
        wires.Next()
    worst, cache = 0.0, []
    for edge in _unique_edges(forward):
        edge_fwd = TopoDS.Edge_s(edge.Oriented(TopAbs_FORWARD))
        trim = read_trim_edge(edge_fwd, forward, cache)
        first, dev = _new_pcurve(trim, trim.pcurve, old, result, tol)
        etol = max(BRep_Tool.Tolerance_s(edge), 1.5 * dev, DEFAULT_TOLERANCE)
        if trim.is_seam:
            second, dev2 = _new_pcurve(trim, trim.seam_pcurve, old, result, tol)
            dev = max(dev, dev2)
            etol = max(etol, 1.5 * dev)
            brep.UpdateEdge(edge_fwd, curve2d_to_occ(first), curve2d_to_occ(second), face, etol)
        else:
            brep.UpdateEdge(edge_fwd, curve2d_to_occ(first), face, etol)
        for vertex in _vertices(edge_fwd):
            if BRep_Tool.Tolerance_s(vertex) < etol:
                brep.UpdateVertex(vertex, etol)
        worst = max(worst, dev)
    return checked_or_fixed(face, tol), worst


#: how far from 1 a location's scale factor may be (a rigid motion's is 1 to rounding)
LOCATION_SCALE_TOL = 1e-12


def _vertices(edge):
    return [v for v in (TopExp.FirstVertex_s(edge), TopExp.LastVertex_s(edge)) if not v.IsNull()]


def reparametrize_face(face: TopoDS_Face, *, tol: float | None = None, copy: bool = True,
                       **options) -> FaceReparametrization:
    """Reparametrize one B-spline face (see the module docstring).

    Parameters
    ----------
    face : TopoDS_Face
        On a ``Geom_BSplineSurface``. A located face (an assembly's part, a face
        read back from STEP) is reparametrized in its own frame and the new face
        carries the same location; a location that scales is refused.
    tol : float, optional
        Model units; default 1e-4 of the surface's control-net diagonal.
    copy : bool
        Copy the face first (default) so the input keeps its edges untouched;
        False adds the new pcurves to the edges of ``face`` itself (for shapes
        already copied, whose faces must keep sharing their edges).
    **options
        Passed to :func:`~surfprep.algorithms.reparam.reparametrize_surface`.

    Raises
    ------
    ConversionError
        Not a B-spline face, or a face whose location scales.
    InvalidGeometryError
        The tolerance was not reached within the limits.
    OpenCascadeError
        The new face is not valid.
    """
    if not isinstance(face, TopoDS_Face) or face.IsNull():
        raise ConversionError(f"expected a non-null TopoDS_Face, got {type(face).__name__}")
    if not is_bspline_face(face):
        raise ConversionError("only faces on B-spline surfaces are reparametrized, this one is "
                              f"on a {type(BRep_Tool.Surface_s(face)).__name__}")
    location = face.Location()
    if not location.IsIdentity():
        scale = location.Transformation().ScaleFactor()
        if abs(abs(scale) - 1.0) > LOCATION_SCALE_TOL:
            raise ConversionError(f"the face's location scales it (factor {scale:.6g}); "
                                  "tolerances and deviations would change units: apply the "
                                  "location first (BRepBuilderAPI_Transform with copy)")
        # in its own frame: the same TShape, surface and edges, distances unchanged
        face = TopoDS.Face_s(face.Located(TopLoc_Location()))
    if copy:
        copier = BRepBuilderAPI_Copy(face)
        if not copier.IsDone():
            raise OpenCascadeError("BRepBuilderAPI_Copy failed")
        face = TopoDS.Face_s(copier.Shape())
    orientation = face.Orientation()
    forward = TopoDS.Face_s(face.Oriented(TopAbs_FORWARD))
    old = surface_from_occ(BRep_Tool.Surface_s(forward))
    result = _require_within(reparametrize_surface(old, tol=tol, **options))
    new_face, deviation = _rebuild(forward, result, old, result.tol)
    if orientation == TopAbs_REVERSED:
        new_face = TopoDS.Face_s(new_face.Reversed())
    if not BRepCheck_Analyzer(new_face).IsValid():
        raise OpenCascadeError("the reparametrized face is not valid (BRepCheck_Analyzer)")
    if not location.IsIdentity():
        face, new_face = (TopoDS.Face_s(f.Located(location)) for f in (face, new_face))
    return FaceReparametrization(
        face=new_face, result=result, area_before=face_area(face, AREA_REL_TOL),
        area_after=face_area(new_face, AREA_REL_TOL), pcurve_deviation=deviation,
        poles_before=int(np.prod(old.n_control)),
        poles_after=int(np.prod(result.surface.n_control)))


@dataclass(frozen=True)
class ModelFace:
    """What happened to one face of a model: ``done`` or an ``error`` message."""

    index: int
    name: str | None
    done: FaceReparametrization | None
    error: str | None
    time_s: float

    def report(self) -> dict:
        """Plain-JSON entry: index, name, time, ``status`` ok/skipped, error, and the
        figures of :meth:`FaceReparametrization.report` when done."""
        out = {"index": self.index, "name": self.name, "time_s": self.time_s,
               "status": "ok" if self.done is not None else "skipped", "error": self.error}
        if self.done is not None:
            out.update(self.done.report())
        return out


def reparametrize_model(model, *, tol: float | None = None, faces: list[int] | None = None,
                        progress=None, **options) -> tuple[Any, list[ModelFace]]:
    """Reparametrize B-spline faces of a :class:`~surfprep.plugin.io.CadModel`.

    The shape is copied, the chosen faces are rebuilt on their new surfaces
    with the copy's edges (so shells stay connected) and substituted
    (``BRepTools_ReShape``). A face that fails, or whose chord-length mismatch
    would get worse, keeps its old surface and its entry carries the reason.

    Parameters
    ----------
    model : CadModel
    tol : float, optional
        Default: 1e-4 of the model's bounding-box diagonal (one tolerance for all faces).
    faces : list of int, optional
        Face indices (file order); default every face on a B-spline surface.
    progress : callable(done, total), optional
        Called with 0 before the first face and after each face (a caller's time
        limit per face raises :class:`~surfprep.errors.TimeLimitExceeded` into the face
        running: that face is kept, with the reason in its entry).

    Returns
    -------
    (TopoDS_Shape, list of ModelFace)
        The new shape (checked by ``BRepCheck_Analyzer``) and one entry per chosen face.
    """
    from OCP.BRepTools import BRepTools_ReShape

    from ..algorithms.tolerance import check_tolerance
    from ..errors import SurfprepError
    tol = DEFAULT_MODEL_RELATIVE_TOL * model.size if tol is None else tol
    tol = check_tolerance(tol, "tol", low=1e-9 * model.size, high=0.1 * model.size)
    copier = BRepBuilderAPI_Copy(model.shape)
    if not copier.IsDone():
        raise OpenCascadeError("BRepBuilderAPI_Copy failed")
    shape = copier.Shape()
    copied = all_faces(shape)
    if len(copied) != model.n_faces:
        raise OpenCascadeError("the copied shape has a different number of faces")
    if faces is None:
        chosen = [k for k, f in enumerate(copied) if is_bspline_face(f)]
        if not chosen:
            where = model.path.name if model.path is not None else "the model"
            raise InvalidGeometryError(f"nothing to reparametrize: {where} has no B-spline face "
                                       f"(of its {model.n_faces} faces)")
    else:
        bad = [k for k in faces if not 0 <= k < model.n_faces]
        if bad:
            raise InvalidGeometryError(f"face indices {bad} out of range 0..{model.n_faces - 1}")
        chosen = list(dict.fromkeys(faces))
    reshape, entries = BRepTools_ReShape(), []
    if progress is not None:
        progress(0, len(chosen))
    for count, k in enumerate(chosen):
        start = time.perf_counter()
        try:
            done = reparametrize_face(copied[k], tol=tol, copy=False, **options)
            r = done.result
            if r.mismatch_after > r.mismatch_before:
                raise InvalidGeometryError(
                    f"the new surface is within tol but not better parametrized (mismatch "
                    f"{r.mismatch_before:.3g} -> {r.mismatch_after:.3g}; the relocation did "
                    f"not settle: {r.relocation_sweeps} sweeps); the face is kept")
            reshape.Replace(copied[k], done.face)
            entries.append(ModelFace(k, model.face_names[k], done, None,
                                     time.perf_counter() - start))
        except SurfprepError as exc:
            entries.append(ModelFace(k, model.face_names[k], None, " ".join(str(exc).split()),
                                     time.perf_counter() - start))
        except Exception as exc:         # one face OpenCascade fails on skips that face only
            if not is_occ_failure(exc):
                raise
            entries.append(ModelFace(k, model.face_names[k], None,
                                     f"OpenCascade failed: {describe(exc)}",
                                     time.perf_counter() - start))
        if progress is not None:
            progress(count + 1, len(chosen))
    result = reshape.Apply(shape)
    _check_no_new_faults(model, result)
    return result, entries


def _check_no_new_faults(model, result) -> None:
    """The result must be valid (``BRepCheck_Analyzer``) -- or, when the input was not,
    hold no face invalid that was valid (occt_b1_euclid.stp comes with two faces that
    fail the check alone: its 415 faces were refused for them); a warning names them."""
    if is_valid(result):
        return
    if is_valid(model.shape):
        raise OpenCascadeError("the shape with the reparametrized faces is not valid "
                               "(BRepCheck_Analyzer), though the input was")
    before = {k for k, f in enumerate(model.faces) if not is_valid(f)}
    after = {k for k, f in enumerate(all_faces(result)) if not is_valid(f)}
    if after - before:
        raise OpenCascadeError(f"faces {sorted(after - before)} are not valid "
                               "(BRepCheck_Analyzer) after the reparametrization")
    where = model.path.name if model.path is not None else "the input"
    warnings.warn(InvalidShapeWarning(
        f"{where} is not valid (BRepCheck_Analyzer) before the reparametrization"
        + (f"; faces {sorted(before)} fail the check alone" if before else
           "; its faces pass the check alone (the fault is in how they are joined)")
        + ": the result keeps those faults and adds none"), stacklevel=3)


def reparametrize(face_or_surface: Any, *, tol: float | None = None,
                  **options) -> ReparametrizeResult:
    """Chord-length (RCA) reparametrization of a surface or a face within ``tol``.

    Parameters
    ----------
    face_or_surface : NurbsSurface, Geom_Surface, TopoDS_Face, cadquery/build123d Face, TrimmedFace
    tol : float, optional
        Largest distance between the new and the original surface (both ways,
        measured densely), model units. Default: 1e-4 of the control-net
        bounding-box diagonal.
    **options
        ``max_iterations``, ``max_points``, ``per_span`` of
        :func:`~surfprep.algorithms.reparam.reparametrize_surface`.

    Returns
    -------
    ReparametrizeResult
        ``.geometry`` is a NurbsSurface for a surface; for a face the same kind
        of face (TopoDS_Face, cadquery.Face, build123d Face, TrimmedFace) on the
        new surface with the same boundary (see the module docstring);
        ``.report()`` the figures.

    Raises
    ------
    InvalidGeometryError
        The tolerance could not be reached (the message gives the deviation
        reached).
    DegenerateGeometryError, InvalidToleranceError, ConversionError, OpenCascadeError

    Examples
    --------
    >>> import numpy as np, surfprep
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> t = np.linspace(0, 1, 9)
    >>> u, v = np.meshgrid(t, t, indexing="ij")                    # x = u^3: badly parametrized
    >>> sheet = interpolate_surface(np.stack([u**3, v, 0.1 * np.sin(3 * u**3)], axis=-1),
    ...                             params_u=t, params_v=t)
    >>> round(surfprep.parametrization_quality(sheet).worst, 1)   # chord-length mismatch
    7.0
    >>> result = surfprep.reparametrize(sheet, tol=1e-4)
    >>> surfprep.parametrization_quality(result.geometry).worst < 1.1
    True
    >>> result.report()["max_deviation"] <= 1e-4                  # measured densely, both ways
    True
    """
    start = time.perf_counter()
    if isinstance(face_or_surface, NurbsSurface):
        fit = _require_within(reparametrize_surface(face_or_surface, tol=tol, **options))
        return ReparametrizeResult(fit.surface, fit, None, int(np.prod(face_or_surface.n_control)),
                                   time.perf_counter() - start)
    if isinstance(face_or_surface, TrimmedFace):
        occ = trimmed_face_to_occ(face_or_surface)
        done = reparametrize_face(occ, tol=tol, **options)
        return ReparametrizeResult(face_to_nurbs(done.face, name=face_or_surface.name),
                                   done.result, done, done.poles_before,
                                   time.perf_counter() - start)
    obj = unwrap(face_or_surface)
    if isinstance(obj, Geom_Surface):
        surface = surface_from_occ(obj)
        fit = _require_within(reparametrize_surface(surface, tol=tol, **options))
        return ReparametrizeResult(fit.surface, fit, None, int(np.prod(surface.n_control)),
                                   time.perf_counter() - start)
    if isinstance(obj, TopoDS_Face):
        done = reparametrize_face(obj, tol=tol, **options)
        new = done.face if obj is face_or_surface else type(face_or_surface)(done.face)
        return ReparametrizeResult(new, done.result, done, done.poles_before,
                                   time.perf_counter() - start)
    raise ConversionError(f"reparametrize takes a surface or a face, got "
                          f"{type(face_or_surface).__module__}.{type(face_or_surface).__qualname__}")
