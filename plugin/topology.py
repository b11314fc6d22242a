"""Faces and edges between OpenCascade topology and surfprep's NURBS types.

The public names of :mod:`surfprep.plugin.faces` (trimmed faces: reading with
:func:`face_to_nurbs`, building with :func:`make_face`) and
:mod:`surfprep.plugin.edges` (:class:`TrimEdge`, :func:`edge_to_nurbs`,
:func:`make_edge`) in one place.
"""

from __future__ import annotations

from .edges import DEFAULT_TOLERANCE, TrimEdge, check_valid, edge_to_nurbs, make_edge
from .faces import TrimLoop, TrimmedFace, face_to_nurbs, make_face, trimmed_face_to_occ

__all__ = [
    "DEFAULT_TOLERANCE",
    "TrimEdge",
    "TrimLoop",
    "TrimmedFace",
    "check_valid",
    "edge_to_nurbs",
    "face_to_nurbs",
    "make_edge",
    "make_face",
    "trimmed_face_to_occ",
]
