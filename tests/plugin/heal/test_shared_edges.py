"""The shared edges of a sewn shape as close_gaps reads them
(plugin/heal/shared_edges.py): feet on a face's surface, analytic or B-spline."""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepTools import BRepTools
from OCP.Geom import Geom_CylindricalSurface, Geom_ToroidalSurface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_VERTEX
from OCP.TopExp import TopExp
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.plugin.heal.shared_edges import (
    analytic_as_nurbs,
    feet_on_face,
    images_on_face,
    pcurve_points,
    read_edge,
)
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


def _face_map(face):
    faces = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(face, TopAbs_FACE, faces)
    return faces


def test_a_torus_face_as_a_b_spline_in_its_own_parameters():
    # a quarter of a torus (R 20, r 2) past its seam: u in [5, 6.5], v in [-1, 2]
    torus = Geom_ToroidalSurface(gp_Ax3(gp_Pnt(1, 2, 3), gp_Dir(0, 0, 1)), 20.0, 2.0)
    face = BRepBuilderAPI_MakeFace(torus, 5.0, 6.5, -1.0, 2.0, 1e-7).Face()
    nurbs = analytic_as_nurbs(_face_map(face), 1, 1e-7)
    assert nurbs is not None and nurbs.weights is None
    # (OpenCascade puts the face's v in [0, 2 pi) + ...: its parameters are the face's)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    np.testing.assert_allclose(nurbs.domain, (u0, u1, v0, v1))
    assert (u0, u1) == (5.0, 6.5) and v1 - v0 == 3.0
    # dense, at random parameters: the same point at the same parameters
    rng = np.random.default_rng(3)
    u, v = rng.uniform(u0, u1, 4000), rng.uniform(v0, v1, 4000)
    exact = np.array([torus.Value(a, b).Coord() for a, b in zip(u, v)])
    assert np.linalg.norm(nurbs.evaluate(u, v) - exact, axis=1).max() <= 1e-7
    # too tight for the samples allowed: none
    assert analytic_as_nurbs(_face_map(face), 1, 1e-13, max_samples=65) is None
