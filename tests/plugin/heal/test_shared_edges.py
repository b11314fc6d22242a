"""The shared edges of a sewn shape as close_gaps reads them
(plugin/heal/shared_edges.py): feet on a face's surface, analytic or B-spline."""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.Geom import Geom_CylindricalSurface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.plugin.heal.shared_edges import feet_on_face, images_on_face, pcurve_points, read_edge
from surfprep.plugin.occ.faces import make_face


def _edges(face):
    faces, vertices = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(face, TopAbs_FACE, faces)
    TopExp.MapShapes_s(face, TopAbs_VERTEX, vertices)
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(face, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    shared: dict = {}
    return faces, [read_edge(edge_faces, k, faces, vertices, shared)
                   for k in range(1, edge_faces.Extent() + 1)]


def test_feet_on_a_cylinder_stay_in_the_period_of_the_face():
    # a cylinder face over u in [2 pi - 0.5, 2 pi + 0.5], across the seam: points 1e-3 off its sides
    # come back at the side's u, not a period away
    cylinder = Geom_CylindricalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0)
    face = BRepBuilderAPI_MakeFace(cylinder, 2 * np.pi - 0.5, 2 * np.pi + 0.5, 0.0, 1.0, 1e-7).Face()
    faces, edges = _edges(face)
    s = np.linspace(0.0, 1.0, 33)
    for e in edges:
        if e.degenerated:
            continue
        image = images_on_face(e, 0, faces, s)
        radial = image * np.array([1.0, 1.0, 0.0]) / 2.0
        uv, feet = feet_on_face(e, 0, faces, image + 1e-3 * radial, s)
        assert np.max(np.abs(uv - pcurve_points(e, 0, faces, s))) < 1e-9
        assert np.max(np.linalg.norm(feet - image, axis=1)) < 1e-9


def test_feet_on_a_b_spline_face_are_its_closest_points():
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    surface = interpolate_surface(np.stack([x, y, 0.2 * np.sin(3 * x) * y], axis=-1))
    faces, edges = _edges(make_face(surface))
    s = np.linspace(0.0, 1.0, 33)
    for e in edges:
        image = images_on_face(e, 0, faces, s)
        du = surface.derivatives(*pcurve_points(e, 0, faces, s).T, 1)
        normal = np.cross(du[:, 1, 0], du[:, 0, 1])
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        uv, feet = feet_on_face(e, 0, faces, image + 1e-4 * normal, s)
        assert np.max(np.linalg.norm(feet - image, axis=1)) < 1e-9
        assert np.max(np.linalg.norm(surface.evaluate(uv[:, 0], uv[:, 1]) - feet, axis=1)) < 1e-12
