"""What a model holds, face by face: the report of ``surfprep info``.

:func:`describe_face` gives one face's surface type, B-spline data, bounds, area,
box and parametrization figure (:class:`FaceInfo`); :func:`model_report` the
whole model's (faces, edges bounding no face, what the translation dropped and
noted) as plain JSON types; :func:`format_table` its text form.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS_Face
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..algorithms.parametrization import parametrization_quality
from ..errors import OpenCascadeError
from .dropped import dropped_report, repaired_report
from .io import CadModel, bounding_box
from .occ.failures import describe, is_occ_failure
from .occ.geom import surface_from_occ
from .occ.shapes import face_area, free_edges_of

__all__ = [
    "SPLINE_KINDS",
    "FaceInfo",
    "SurfaceKind",
    "describe_face",
    "format_table",
    "model_report",
    "surface_kind",
]


class SurfaceKind(enum.Enum):
    """Type of a face's surface, from ``GeomAdaptor_Surface.GetType``."""

    PLANE = "Plane"
    CYLINDER = "Cylinder"
    CONE = "Cone"
    SPHERE = "Sphere"
    TORUS = "Torus"
    BEZIER = "Bezier"
    BSPLINE = "BSpline"
    REVOLUTION = "Revolution"
    EXTRUSION = "Extrusion"
    OFFSET = "Offset"
    OTHER = "Other"


_KIND_OF = {
    GeomAbs_SurfaceType.GeomAbs_Plane: SurfaceKind.PLANE,
    GeomAbs_SurfaceType.GeomAbs_Cylinder: SurfaceKind.CYLINDER,
    GeomAbs_SurfaceType.GeomAbs_Cone: SurfaceKind.CONE,
    GeomAbs_SurfaceType.GeomAbs_Sphere: SurfaceKind.SPHERE,
    GeomAbs_SurfaceType.GeomAbs_Torus: SurfaceKind.TORUS,
    GeomAbs_SurfaceType.GeomAbs_BezierSurface: SurfaceKind.BEZIER,
    GeomAbs_SurfaceType.GeomAbs_BSplineSurface: SurfaceKind.BSPLINE,
    GeomAbs_SurfaceType.GeomAbs_SurfaceOfRevolution: SurfaceKind.REVOLUTION,
    GeomAbs_SurfaceType.GeomAbs_SurfaceOfExtrusion: SurfaceKind.EXTRUSION,
    GeomAbs_SurfaceType.GeomAbs_OffsetSurface: SurfaceKind.OFFSET,
    GeomAbs_SurfaceType.GeomAbs_OtherSurface: SurfaceKind.OTHER,
}
#: Kinds whose own parametrization is a NURBS one, so the chord-length figure applies.
SPLINE_KINDS = (SurfaceKind.BSPLINE, SurfaceKind.BEZIER)


@dataclass(frozen=True)
class FaceInfo:
    """One row of ``surfprep info``. B-spline fields are None for other surface kinds.

    ``param_quality*`` is the worst chord-length mismatch of eqs. 29.1/29.2
    (:mod:`surfprep.algorithms.parametrization`; 1.0 = chord-length), computed on
    the face's whole B-spline/Bezier surface; None for analytic faces, whose
    native parametrization is not the NURBS one a conversion would produce.
    """

    index: int
    name: str | None
    surface_type: SurfaceKind
    degree: tuple[int, int] | None
    poles: tuple[int, int] | None
    knot_spans: tuple[int, int] | None
    rational: bool | None
    uv_bounds: tuple[float, float, float, float]
    area: float
    bounding_box: tuple[float, float, float, float, float, float]
    param_quality: float | None
    param_quality_u: float | None
    param_quality_v: float | None

    def as_dict(self) -> dict:
        out = asdict(self)
        out["surface_type"] = self.surface_type.value
        return out


def surface_kind(adaptor: GeomAdaptor_Surface) -> SurfaceKind:
    """The :class:`SurfaceKind` of an adapted surface."""
    return _KIND_OF.get(adaptor.GetType(), SurfaceKind.OTHER)


def describe_face(face: TopoDS_Face, index: int, name: str | None = None) -> FaceInfo:
    """Surface type, B-spline data, UV bounds, area, box and parametrization figure."""
    try:
        geom_surface = BRep_Tool.Surface_s(face)
        adaptor = GeomAdaptor_Surface(geom_surface)
        kind = surface_kind(adaptor)
        uv = tuple(float(x) for x in BRepTools.UVBounds_s(face))
        area = face_area(face)
        degree = poles = spans = rational = None
        quality = None
        if kind is SurfaceKind.BSPLINE:
            bspline = adaptor.BSpline()
            degree = (bspline.UDegree(), bspline.VDegree())
            poles = (bspline.NbUPoles(), bspline.NbVPoles())
            spans = (bspline.NbUKnots() - 1, bspline.NbVKnots() - 1)
            rational = bool(bspline.IsURational() or bspline.IsVRational())
            quality = parametrization_quality(surface_from_occ(bspline))
        elif kind is SurfaceKind.BEZIER:
            bezier = adaptor.Bezier()
            degree = (bezier.UDegree(), bezier.VDegree())
            poles = (bezier.NbUPoles(), bezier.NbVPoles())
            spans = (1, 1)
            rational = bool(bezier.IsURational() or bezier.IsVRational())
            quality = parametrization_quality(surface_from_occ(bezier))
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"cannot describe face {index}: {describe(exc)}") from exc
    return FaceInfo(
        index=index, name=name, surface_type=kind, degree=degree, poles=poles,
        knot_spans=spans, rational=rational, uv_bounds=uv, area=area,
        bounding_box=bounding_box(face),
        param_quality=None if quality is None else _finite(quality.worst),
        param_quality_u=None if quality is None else _finite(quality.worst_u),
        param_quality_v=None if quality is None else _finite(quality.worst_v),
    )


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def describe_edge(edge, index: int) -> dict:
    """An edge that bounds no face: its curve type, length and whether it is closed."""
    curve = BRepAdaptor_Curve(edge)
    props = GProp_GProps()
    BRepGProp.LinearProperties_s(edge, props)
    kind = curve.GetType().name.removeprefix("GeomAbs_")
    return {"index": index, "curve_type": kind, "length": float(props.Mass()),
            "closed": bool(BRep_Tool.IsClosed_s(edge))}


def _union_box(model: CadModel, face_boxes: list, edges) -> tuple[float, ...]:
    """The model's box as the union of its faces' boxes (already computed) and its
    standalone edges' boxes: the shape's box (:attr:`CadModel.bounding_box`) without
    a second pass over every face (0.1 s of a cold ``info`` call on the fuselage);
    that box itself when the faces listed are not every face of the shape."""
    shape_faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(model.shape, TopAbs_FACE, shape_faces)
    if not face_boxes or shape_faces.Extent() != model.n_faces:
        return model.bounding_box
    boxes = np.array(face_boxes + [bounding_box(e) for e in edges], dtype=float)
    return tuple(float(x) for x in (*boxes[:, :3].min(axis=0), *boxes[:, 3:].max(axis=0)))


def model_report(model: CadModel, *, progress: Callable[[int, int, str], None] | None = None
                 ) -> dict:
    """The ``info`` report of a model: file data and one :class:`FaceInfo` dict per face.

    ``progress(done, total, "face")`` is called after each face when given.
    """
    faces = []
    for i, (face, name) in enumerate(zip(model.faces, model.face_names)):
        if progress is not None:
            progress(i + 1, model.n_faces, "face")
        faces.append(describe_face(face, i, name).as_dict())
    standalone = free_edges_of(model.shape)
    x0, y0, z0, x1, y1, z1 = _union_box(model, [f["bounding_box"] for f in faces], standalone)
    size = float(np.linalg.norm([x1 - x0, y1 - y0, z1 - z0]))
    return {
        "file": str(model.path) if model.path else None,
        "format": model.file_format.value if model.file_format else None,
        "declared_length_unit": model.length_unit,
        "model_unit": model.model_unit,
        "n_faces": model.n_faces,
        "bounding_box": {"min": [x0, y0, z0], "max": [x1, y1, z1]},
        "size": size,
        "faces": faces,
        "edges": [describe_edge(e, k) for k, e in enumerate(standalone)],
        "dropped": dropped_report(model),
        "repaired": repaired_report(model),
        "translation_notes": [{"type": kind, "message": message, "count": count}
                              for kind, message, count in model.translation_notes],
    }


# ------------------------------------------------------------------ text
def _pair(p) -> str:
    return "-" if p is None else f"{p[0]}x{p[1]}"


def _quality(face: dict) -> str:
    q = face["param_quality"]
    if q is None:
        return "-"
    worse = "u" if (face["param_quality_u"] or 0) >= (face["param_quality_v"] or 0) else "v"
    return f"{q:.3g} ({worse})"


def _table(rows: list[tuple[str, ...]], right: set[int]) -> list[str]:
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    return ["  ".join(r[c].rjust(widths[c]) if c in right else r[c].ljust(widths[c])
                      for c in range(len(rows[0]))).rstrip() for r in rows]


def format_table(report: dict) -> str:
    """The human-readable form of :func:`model_report`."""
    faces = report["faces"]
    n_spline = sum(f["surface_type"] in {k.value for k in SPLINE_KINDS} for f in faces)
    lo, hi = report["bounding_box"]["min"], report["bounding_box"]["max"]
    lines = [
        f"file: {report['file']}",
        (f"format: {report['format']}   declared unit: {report['declared_length_unit']}   "
        f"coordinates in: {report['model_unit']}"),
        (f"faces: {report['n_faces']} ({n_spline} B-spline/Bezier)   size (bbox diagonal): "
        f"{report['size']:.6g}"),
        "bbox: (" + ", ".join(f"{x:.6g}" for x in lo) + ") .. ("
        + ", ".join(f"{x:.6g}" for x in hi) + ")",
        "",
    ]
    header = ("#", "name", "type", "degree", "poles", "spans", "rat", "area", "param")
    rows = [header]
    for f in faces:
        name = f["name"] or ""
        rows.append((
            str(f["index"]), name if len(name) <= 18 else name[:17] + "~", f["surface_type"],
            _pair(f["degree"]), _pair(f["poles"]), _pair(f["knot_spans"]),
            "-" if f["rational"] is None else ("yes" if f["rational"] else "no"),
            f"{f['area']:.6g}", _quality(f)))
    if faces:
        lines += _table(rows, right={0, 7})
    edges = report.get("edges", [])
    if edges:
        lines.append(f"edges bounding no face: {len(edges)}")
        lines.append("")
        rows = [("#", "curve", "length", "closed")]
        rows += [(str(e["index"]), e["curve_type"], f"{e['length']:.6g}",
                  "yes" if e["closed"] else "no") for e in edges]
        lines += _table(rows, right={0, 2})
    lines.append("")
    lines.append("param: worst chord-length mismatch of eqs. 29.1/29.2 (1 = chord-length "
                 "parametrized), worse direction in brackets; '-' for analytic faces")
    return "\n".join(lines)
