"""The bridge between OpenCascade topology and geometry and surfprep's NURBS types, by
topological level (as build123d's ``topology/``):

* :mod:`.geom`: ``Geom_BSplineSurface`` / ``Geom_BSplineCurve`` / ``Geom2d_BSplineCurve``
  to and from :class:`~surfprep.algorithms.NurbsSurface` /
  :class:`~surfprep.algorithms.NurbsCurve`, exactly;
* :mod:`.edges`: ``TopoDS_Edge`` to and from NURBS curves and
  :class:`~surfprep.algorithms.trimmed.TrimEdge`;
* :mod:`.faces`: ``TopoDS_Face`` to and from
  :class:`~surfprep.algorithms.trimmed.TrimmedFace`;
* :mod:`.shapes`: whole shapes (faces of a shape, compounds, face names, areas,
  sewing, free edges, validity);
* :mod:`.structure`: faces of a use-based non-manifold structure
  (:class:`~surfprep.algorithms.nonmanifold.NonManifoldModel`) built sharing its
  edges and vertices, no sewing.

Every builder's status is checked; failures raise
:class:`~surfprep.errors.OpenCascadeError`.
"""

from .edges import build_trim_edge, edge_to_nurbs, make_edge, read_trim_edge
from .faces import checked_or_fixed, face_to_nurbs, make_face, needs_nurbs_convert, trimmed_face_to_occ
from .geom import curve2d_to_occ, curve_from_occ, curve_to_occ, surface_from_occ, surface_to_occ
from .shapes import (
    FaceNames,
    all_faces,
    check_valid,
    compound,
    count_free_edges,
    face_area,
    is_valid,
    max_edge_tolerance,
    sew,
)

__all__ = [
    "FaceNames",
    "all_faces",
    "build_trim_edge",
    "check_valid",
    "checked_or_fixed",
    "compound",
    "count_free_edges",
    "curve2d_to_occ",
    "curve_from_occ",
    "curve_to_occ",
    "edge_to_nurbs",
    "face_area",
    "face_to_nurbs",
    "is_valid",
    "make_edge",
    "make_face",
    "max_edge_tolerance",
    "needs_nurbs_convert",
    "read_trim_edge",
    "sew",
    "surface_from_occ",
    "surface_to_occ",
    "trimmed_face_to_occ",
]
