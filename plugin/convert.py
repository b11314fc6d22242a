"""The public conversion entry points: :func:`to_nurbs` and :func:`to_occ`.

``to_nurbs`` accepts OpenCascade geometry and topology as well as cadquery and
build123d objects (recognised by their ``wrapped`` attribute, so neither
library is imported here); ``to_occ`` turns surfprep's types back into
OpenCascade objects.
"""

from __future__ import annotations

from typing import Any

from OCP.Geom import Geom_Curve, Geom_Surface
from OCP.Geom2d import Geom2d_Curve
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopoDS import TopoDS, TopoDS_Shape

from ..algorithms import NurbsCurve, NurbsSurface
from ..algorithms.trimmed import TrimmedFace
from ..errors import ConversionError
from .io import CadModel
from .occ.edges import edge_to_nurbs
from .occ.faces import face_to_nurbs, trimmed_face_to_occ
from .occ.geom import curve2d_to_occ, curve_from_occ, curve_to_occ, surface_from_occ, surface_to_occ
from .occ.shapes import all_faces

__all__ = ["to_nurbs", "to_occ", "unwrap"]


def unwrap(x: Any) -> Any:
    """The OCP object inside a cadquery / build123d wrapper, or a list of them.

    cadquery's ``Workplane`` has no ``wrapped`` but ``vals()``; cadquery and
    build123d shapes hold their ``TopoDS_Shape`` in ``wrapped``; a build123d
    ``ShapeList`` is a list of shapes.
    """
    if isinstance(x, (TopoDS_Shape, Geom_Surface, Geom_Curve, Geom2d_Curve)):
        return x
    wrapped = getattr(x, "wrapped", None)
    if wrapped is not None and not callable(wrapped):
        return wrapped
    vals = getattr(x, "vals", None)
    if callable(vals) and type(x).__module__.startswith("cadquery"):
        return [unwrap(v) for v in vals()]
    if isinstance(x, (list, tuple)):
        return [unwrap(v) for v in x]
    return x


def to_nurbs(x: Any) -> NurbsSurface | NurbsCurve | TrimmedFace | list[TrimmedFace]:
    """Convert OpenCascade / cadquery / build123d input to surfprep's NURBS types.

    ==========================================  ==========================================
    input                                       result
    ==========================================  ==========================================
    ``Geom_Surface`` (B-spline exactly; a        :class:`NurbsSurface`
    finite analytic surface by GeomConvert)
    ``Geom_Curve`` / ``Geom2d_Curve``            :class:`NurbsCurve` (d = 3 / 2)
    ``TopoDS_Face``, ``cadquery.Face``,          :class:`TrimmedFace`
    ``build123d.Face``
    :class:`~surfprep.plugin.io.CadModel`        ``list[TrimmedFace]`` in file order, each
                                                 with the face's name from the file
    ``TopoDS_Edge``, cadquery/build123d Edge     :class:`NurbsCurve` (3D, edge range,
                                                 location applied)
    any other ``TopoDS_Shape`` (shell, solid,    ``list[TrimmedFace]``, one per face
    compound), cadquery ``Shape`` /
    ``Workplane``, build123d ``Shape`` /
    ``ShapeList``, a list of these
    ==========================================  ==========================================

    Raises
    ------
    ConversionError
        For an unsupported type, or a shape without face.
    """
    if isinstance(x, CadModel):
        return [face_to_nurbs(f, name=n) for f, n in zip(x.faces, x.face_names)]
    obj = unwrap(x)
    if isinstance(obj, Geom_Surface):
        return surface_from_occ(obj)
    if isinstance(obj, (Geom_Curve, Geom2d_Curve)):
        return curve_from_occ(obj)
    if isinstance(obj, TopoDS_Shape):
        if obj.IsNull():
            raise ConversionError("cannot convert a null TopoDS_Shape")
        if obj.ShapeType() == TopAbs_FACE:
            return face_to_nurbs(TopoDS.Face_s(obj))
        if obj.ShapeType() == TopAbs_EDGE:
            return edge_to_nurbs(TopoDS.Edge_s(obj))
        faces = all_faces(obj)
        if not faces:
            raise ConversionError(
                f"the {type(obj).__name__} ({obj.ShapeType().name}) has no face to convert")
        return [face_to_nurbs(f) for f in faces]
    if isinstance(obj, list):
        faces = []
        for item in obj:
            converted = to_nurbs(item)
            if isinstance(converted, TrimmedFace):
                faces.append(converted)
            elif isinstance(converted, list):
                faces.extend(converted)
            else:
                raise ConversionError(
                    f"a list to convert must hold faces or shapes with faces, got "
                    f"{type(item).__name__}")
        if not faces:
            raise ConversionError("nothing with a face to convert (empty list or workplane)")
        return faces
    raise ConversionError(f"cannot convert an object of type {type(x).__module__}."
                          f"{type(x).__qualname__} to NURBS")


def to_occ(x: NurbsSurface | NurbsCurve | TrimmedFace) -> Any:
    """Convert surfprep's types to OpenCascade.

    :class:`NurbsSurface` → ``Geom_BSplineSurface``; :class:`NurbsCurve` →
    ``Geom_BSplineCurve`` (d = 3) or ``Geom2d_BSplineCurve`` (d = 2);
    :class:`TrimmedFace` → ``TopoDS_Face`` (validated by BRepCheck).
    """
    if isinstance(x, NurbsSurface):
        return surface_to_occ(x)
    if isinstance(x, NurbsCurve):
        if x.dimension == 3:
            return curve_to_occ(x)
        if x.dimension == 2:
            return curve2d_to_occ(x)
        raise ConversionError(f"OpenCascade curves are 2D or 3D; this one has dimension {x.dimension}")
    if isinstance(x, TrimmedFace):
        return trimmed_face_to_occ(x)
    raise ConversionError(f"cannot convert an object of type {type(x).__module__}."
                          f"{type(x).__qualname__} to OpenCascade")
