"""``surfprep.split``: faces cut along their intersection curves, the pieces sharing the cut edges.

:func:`split` intersects ``a`` with ``b`` (or ``a`` with itself) by
:func:`surfprep.intersect`, hands every face its curves as cuts in its own
parameters (each curve has a pcurve on both faces) to
:func:`~surfprep.algorithms.face_split.split_face`, rebuilds the pieces as
OpenCascade faces and sews them (non-manifold: where two surfaces cross, four
pieces share one intersection edge). A face whose curves cross each other, or that
the builder refuses, is kept whole and named with the reason; nothing is dropped.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from ..algorithms.face_split import Cut, split_face
from ..errors import OpenCascadeError, SurfprepError
from .intersect import IntersectionResult, intersect
from .io import as_model
from .occ.faces import trimmed_face_to_occ
from .occ.failures import describe, is_occ_failure
from .occ.shapes import compound, count_free_edges, is_valid

__all__ = ["SplitFace", "SplitResult", "split"]


@dataclass(frozen=True)
class SplitFace:
    """What became of one face: ``operand`` ``"a"`` or ``"b"``, its index there, the
    number of curves cutting it, the pieces (OpenCascade faces), or why it was kept whole."""

    operand: str
    index: int
    cuts: int
    pieces: tuple = ()
    kept: str | None = None


@dataclass(frozen=True)
class SplitResult:
    """The split model: every piece and every uncut face, sewn.

    Attributes
    ----------
    shape : TopoDS_Shape
        The faces sewn (a compound or shell; non-manifold where surfaces cross).
    faces : tuple of SplitFace
        One per face that had a curve.
    curves : IntersectionResult
    free_edges : int
        Edges of ``shape`` used by one face only.
    shared_edges : dict
        Number of edges by the number of faces using them (``{2: 31, 4: 1}``).
    valid : bool
        BRepCheck on every piece.
    """

    shape: Any
    faces: tuple[SplitFace, ...]
    curves: IntersectionResult
    free_edges: int
    shared_edges: dict
    valid: bool
    time_s: float = field(default=0.0, compare=False)

    @property
    def geometry(self) -> Any:
        return self.shape

    def report(self) -> dict:
        return {"faces": [{"operand": f.operand, "index": f.index, "cuts": f.cuts, "pieces": len(f.pieces),
                           "kept_whole": f.kept} for f in self.faces],
                "curves": len(self.curves), "pieces": sum(len(f.pieces) for f in self.faces),
                "free_edges": self.free_edges,
                "edges_by_faces": {str(k): v for k, v in sorted(self.shared_edges.items())},
                "valid": self.valid, "time_s": self.time_s}


def _edge_uses(shape) -> dict:
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    out: dict = {}
    for k in range(1, edge_faces.Extent() + 1):
        n = edge_faces.FindFromIndex(k).Size()
        out[n] = out.get(n, 0) + 1
    return out


def _sew_non_manifold(faces: list, tol: float):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    sewing = BRepBuilderAPI_Sewing(tol)
    sewing.SetNonManifoldMode(True)
    for f in faces:
        sewing.Add(f)
    try:
        sewing.Perform()
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"BRepBuilderAPI_Sewing failed: {describe(exc)}") from exc
    shape = sewing.SewedShape()
    if shape.IsNull():
        raise OpenCascadeError("BRepBuilderAPI_Sewing returned a null shape")
    return shape


def split(a: Any, b: Any = None, *, tol: float | None = None, method: str = "auto") -> SplitResult:
    """The faces of ``a`` and ``b`` (or of ``a`` alone) cut along their intersection curves.

    Parameters
    ----------
    a, b
        What :func:`surfprep.intersect` takes (paths, models, shapes, cadquery and
        build123d objects). With ``b`` None, the faces of ``a`` are cut along the
        curves where they meet one another.
    tol : float, optional
        The intersection's tolerance (model units; its default).
    method : str
        The intersection method.

    Returns
    -------
    SplitResult

    Examples
    --------
    >>> import cadquery as cq                                          # doctest: +SKIP
    >>> out = split(cq.Workplane().sphere(10), cq.Workplane().box(30, 30, 1))  # doctest: +SKIP
    >>> out.report()["pieces"]                                         # doctest: +SKIP
    4
    """
    started = time.perf_counter()
    model_a = as_model(a)
    model_b = None if b is None else as_model(b)
    curves = intersect(model_a, model_b, tol=tol, method=method)
    cuts: dict[tuple[str, int], list[Cut]] = {}
    trimmed: dict[tuple[str, int], Any] = {}
    for r in curves:
        c = r.curve
        for operand, face, pcurve in (("a", r.face_a, c.pcurve_a), ("b" if b is not None else "a", r.face_b,
                                                                      c.pcurve_b)):
            if pcurve is None:
                continue
            key = (operand, face.index)
            cuts.setdefault(key, []).append(Cut(pcurve, c.curve3d))
            trimmed[key] = face.trimmed
    done: list[SplitFace] = []
    faces = []
    cut_faces = set(cuts)
    for operand, model in (("a", model_a), ("b", model_b)):
        if model is None:
            continue
        for k, occ_face in enumerate(model.faces):
            key = (operand, k)
            if key not in cut_faces:
                faces.append(occ_face)
                continue
            try:
                regions = split_face(trimmed[key], cuts[key])
                pieces = tuple(trimmed_face_to_occ(region) for region in regions)
            except SurfprepError as exc:
                done.append(SplitFace(operand, k, len(cuts[key]), (occ_face,), str(exc)))
                faces.append(occ_face)
                continue
            done.append(SplitFace(operand, k, len(cuts[key]), pieces))
            faces.extend(pieces)
    size = model_a.size if model_b is None else max(model_a.size, model_b.size)
    sew_tol = max(1e-7 * size, 10.0 * (curves.tol or 0.0))
    shape = _sew_non_manifold(faces, sew_tol) if len(faces) > 1 else compound(faces)
    valid = all(is_valid(p) for f in done for p in f.pieces)
    return SplitResult(shape, tuple(done), curves, count_free_edges(shape), _edge_uses(shape), valid,
                       time.perf_counter() - started)
