"""Whole shapes: faces of a shape, compounds, face names, areas, sewing and validity.

The topological level above :mod:`.faces` (build123d's ``composite.py`` /
``shape_core.py``): what the readers, the writers and the verbs share about a
``TopoDS_Shape`` as a whole.

* :func:`all_faces`, :func:`compound`, :class:`FaceNames` (a face's name looked
  up whatever its location and orientation);
* :func:`face_area` (``BRepGProp``);
* :func:`sew` (``BRepBuilderAPI_Sewing`` into a shell, a solid when closed);
* :func:`count_free_edges`, :func:`is_valid`, :func:`check_valid`,
  :func:`max_edge_tolerance`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.ShapeFix import ShapeFix_Shell, ShapeFix_Solid
from OCP.TopAbs import (
    TopAbs_EDGE,
    TopAbs_FACE,
    TopAbs_FORWARD,
    TopAbs_SHELL,
    TopAbs_VERTEX,
    TopAbs_WIRE,
)
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Edge, TopoDS_Face, TopoDS_Shape, TopoDS_Shell
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from ...errors import OpenCascadeError
from .failures import describe, is_occ_failure

__all__ = [
    "FaceNames",
    "all_faces",
    "area_and_centroid",
    "boundary_edge_points",
    "check_failures",
    "check_valid",
    "compound",
    "count_free_edges",
    "distinct_faces",
    "face_area",
    "free_edges_of",
    "is_valid",
    "max_edge_tolerance",
    "sew",
    "shell_or_solid",
]


def compound(shapes: Sequence[TopoDS_Shape]) -> TopoDS_Compound:
    """A compound of ``shapes`` (no copy: the shapes are shared)."""
    builder = BRep_Builder()
    compound = TopoDS_Compound()
    builder.MakeCompound(compound)
    for s in shapes:
        builder.Add(compound, s)
    return compound


def all_faces(shape: TopoDS_Shape) -> tuple[TopoDS_Face, ...]:
    """Every face occurrence of ``shape`` in exploration (file) order.

    A face the file references twice (same definition, e.g. from two IGES
    groups) appears twice, as ``TopExp_Explorer`` visits it twice: the face
    count then matches what other tools report for the file.
    """
    faces = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        faces.append(TopoDS.Face_s(explorer.Current()))
        explorer.Next()
    return tuple(faces)


class FaceNames:
    """Names of face definitions, looked up by face whatever its location/orientation.

    OCP's ``TopoDS_Shape.__eq__`` is not ``IsSame``, so the lookup buckets by
    hash of the unlocated face and confirms with ``IsSame``.
    """

    def __init__(self) -> None:
        self._buckets: dict[int, list[tuple[TopoDS_Shape, str]]] = {}

    @staticmethod
    def _key(face: TopoDS_Shape) -> TopoDS_Shape:
        return face.Located(TopLoc_Location()).Oriented(TopAbs_FORWARD)

    def add(self, face: TopoDS_Shape, name: str) -> None:
        key = self._key(face)
        bucket = self._buckets.setdefault(hash(key), [])
        if not any(k.IsSame(key) for k, _ in bucket):
            bucket.append((key, name))

    def get(self, face: TopoDS_Shape) -> str | None:
        key = self._key(face)
        for k, name in self._buckets.get(hash(key), ()):
            if k.IsSame(key):
                return name
        return None


def free_edges_of(shape: TopoDS_Shape) -> tuple[TopoDS_Edge, ...]:
    """The edges of ``shape`` that bound no face (curves standing on their own), in
    exploration order, each once."""
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    return tuple(TopoDS.Edge_s(edge_faces.FindKey(k)) for k in range(1, edge_faces.Extent() + 1)
                 if edge_faces.FindFromIndex(k).Size() == 0)


def distinct_faces(faces) -> int:
    """How many distinct face definitions ``faces`` hold (occurrences of one face placed
    elsewhere or reversed count once)."""
    seen = TopTools_IndexedMapOfShape()
    for face in faces:
        seen.Add(face.Located(TopLoc_Location()).Oriented(TopAbs_FORWARD))
    return seen.Extent()


def face_area(shape: TopoDS_Shape, rel_tol: float | None = None) -> float:
    """Area of a face or of all faces of a shape (``BRepGProp.SurfaceProperties_s``).

    ``rel_tol`` None: OpenCascade's fixed-order Gauss integration; a float: the
    adaptive integration to that relative error, or the fixed order where the
    adaptive one fails. The adaptive form matters on badly parametrized faces: the
    fixed order is off by 0.35 % on the fuselage faces of ``occt_fuselage.stp``.
    """
    props = GProp_GProps()
    if rel_tol is None:
        BRepGProp.SurfaceProperties_s(shape, props)
        return float(props.Mass())
    try:
        BRepGProp.SurfaceProperties_s(shape, props, rel_tol)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        # the adaptive integration indexes past its arrays on some faces (face 21 of
        # occt_k1_catia_debis.stp with a 5278-span pcurve: Standard_OutOfRange,
        # tests/plugin/occ/test_shapes_area.py); the fixed order still gives an area
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(shape, props)
    return float(props.Mass())


def area_and_centroid(shape: TopoDS_Shape) -> tuple[float, tuple[float, float, float]]:
    """Area and centre of area of a face or of all faces of a shape (OpenCascade's
    fixed-order Gauss integration, as :func:`face_area` without ``rel_tol``)."""
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    c = props.CentreOfMass()
    return float(props.Mass()), (c.X(), c.Y(), c.Z())


def sew(faces: list[TopoDS_Shape], tol: float, *,
        non_manifold: bool = False) -> tuple[TopoDS_Shape, BRepBuilderAPI_Sewing]:
    """Faces sewn at ``tol`` into a shell (a solid when closed), orientations fixed.

    ``non_manifold``: an edge may join more than two faces (four pieces round the edge
    where two surfaces cross); the sewn shape is returned as the sewing makes it.
    """
    sewing = BRepBuilderAPI_Sewing(tol)
    sewing.SetNonManifoldMode(non_manifold)
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
    return (shape if non_manifold else shell_or_solid(shape)), sewing


def shell_or_solid(shape: TopoDS_Shape) -> TopoDS_Shape:
    """A shell with its orientations fixed (``ShapeFix_Shell``), made a solid when it
    closes (``BRepBuilderAPI_MakeSolid``, ``ShapeFix_Solid``); a lone face is put in a
    shell first (sewing one face returns the face: a ball's sphere, a torus); other
    shapes as they are."""
    if shape.ShapeType() == TopAbs_FACE:
        builder, shell = BRep_Builder(), TopoDS_Shell()
        builder.MakeShell(shell)
        builder.Add(shell, shape)
        shape = shell
    if shape.ShapeType() != TopAbs_SHELL:
        return shape
    fixer = ShapeFix_Shell(TopoDS.Shell_s(shape))
    fixer.Perform()
    shell = fixer.Shell()
    if not BRep_Tool.IsClosed_s(shell):
        return shell
    maker = BRepBuilderAPI_MakeSolid(shell)
    if not maker.IsDone():
        return shell
    fix = ShapeFix_Solid(maker.Solid())
    fix.Perform()
    return fix.Solid()


def count_free_edges(shape: TopoDS_Shape) -> int:
    """Edges used by exactly one face (degenerated edges not counted)."""
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    count = 0
    for k in range(1, edge_faces.Extent() + 1):
        edge = TopoDS.Edge_s(edge_faces.FindKey(k))
        if BRep_Tool.Degenerated_s(edge):
            continue
        if edge_faces.FindFromIndex(k).Size() == 1:
            count += 1
    return count


def boundary_edge_points(shape: TopoDS_Shape, samples: int = 5) -> list:
    """Per edge used by exactly one face (degenerated edges left out): ``(samples, 3)``
    points along it, ends included."""
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    out = []
    for k in range(1, edge_faces.Extent() + 1):
        edge = TopoDS.Edge_s(edge_faces.FindKey(k))
        if BRep_Tool.Degenerated_s(edge) or edge_faces.FindFromIndex(k).Size() != 1:
            continue
        curve = BRepAdaptor_Curve(edge)
        t = np.linspace(curve.FirstParameter(), curve.LastParameter(), samples)
        out.append(np.array([[p.X(), p.Y(), p.Z()] for p in map(curve.Value, t)]))
    return out


def is_valid(shape: TopoDS_Shape) -> bool:
    """``BRepCheck_Analyzer(shape).IsValid()``."""
    return bool(BRepCheck_Analyzer(shape).IsValid())


def check_failures(shape: TopoDS_Shape) -> frozenset[tuple[str, str]]:
    """What ``BRepCheck_Analyzer`` finds wrong with ``shape`` and its wires, edges and
    vertices: ``(sub-shape type, status)`` pairs, e.g. ``("WIRE", "NotClosed")``, the
    statuses in the context of ``shape`` among them (empty when valid).

    Tells a change that made a shape invalid from one that left it as invalid as it
    was: a face read invalid (its wire not closed where a file's gaps are) can still
    be moved onto its neighbours' edges, as long as nothing new fails."""
    analyzer = BRepCheck_Analyzer(shape)
    out = set()
    subs = [shape]
    for kind in (TopAbs_WIRE, TopAbs_EDGE, TopAbs_VERTEX):
        explorer = TopExp_Explorer(shape, kind)
        while explorer.More():
            subs.append(explorer.Current())
            explorer.Next()
    for sub in subs:
        result = analyzer.Result(sub)
        if result is None:
            continue
        statuses = list(result.Status())
        try:
            statuses += list(result.StatusOnShape(shape))
        except Exception as exc:            # no status recorded in that context
            if not is_occ_failure(exc):
                raise
        kind = sub.ShapeType().name.removeprefix("TopAbs_")
        out.update((kind, st.name.removeprefix("BRepCheck_")) for st in statuses
                   if st.name != "BRepCheck_NoError")
    return frozenset(out)


def max_edge_tolerance(shape: TopoDS_Shape) -> float:
    """The largest tolerance of the edges of ``shape`` (0 without edges)."""
    out = 0.0
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        out = max(out, BRep_Tool.Tolerance_s(TopoDS.Edge_s(explorer.Current())))
        explorer.Next()
    return out


def check_valid(shape, what: str = "shape") -> None:
    """Raise :class:`OpenCascadeError` unless ``BRepCheck_Analyzer`` finds ``shape`` valid."""
    if not BRepCheck_Analyzer(shape).IsValid():
        raise OpenCascadeError(f"the {what} built is not valid (BRepCheck_Analyzer)")
