"""check_failures: what BRepCheck finds wrong with a face, so a change can be judged by
what it breaks rather than by whether the face was valid to begin with."""

from __future__ import annotations

import itertools

from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
    BRepBuilderAPI_MakeWire,
)
from OCP.gp import gp_Pln, gp_Pnt

from surfprep.plugin.occ.shapes import check_failures, is_valid


def square_face(close: bool):
    corners = [gp_Pnt(0, 0, 0), gp_Pnt(1, 0, 0), gp_Pnt(1, 1, 0), gp_Pnt(0, 1, 0)]
    if close:
        polygon = BRepBuilderAPI_MakePolygon()
        for p in corners:
            polygon.Add(p)
        polygon.Close()
        wire = polygon.Wire()
    else:                                      # three sides: the wire is open
        maker = BRepBuilderAPI_MakeWire()
        for a, b in itertools.pairwise(corners):
            maker.Add(BRepBuilderAPI_MakeEdge(a, b).Edge())
        wire = maker.Wire()
    builder = BRepBuilderAPI_MakeFace(gp_Pln(), wire, True)
    assert builder.IsDone()
    return builder.Face()


def test_a_valid_face_has_no_failure():
    face = square_face(close=True)
    assert is_valid(face) and check_failures(face) == frozenset()


def test_a_face_whose_wire_is_open_says_so():
    face = square_face(close=False)
    failures = check_failures(face)
    assert not is_valid(face)
    assert ("WIRE", "NotClosed") in failures
    assert all(isinstance(kind, str) and isinstance(status, str) and
               not status.startswith("BRepCheck_") for kind, status in failures)
