"""Gaps closed in the geometry after sewing (plugin/heal/close_gaps.py): the faces along
an edge sewing closed by tolerance moved onto one common curve, measured densely on the
surfaces, the analytic faces and the faces far from the gap untouched."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
    BRepBuilderAPI_MakeWire,
)
from OCP.Geom import Geom_Plane
from OCP.gp import gp_Dir, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

from surfprep.algorithms.basis import greville_abscissae
from surfprep.algorithms.curve import NurbsCurve
from surfprep.algorithms.fitting import interpolate_curve, interpolate_surface
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.surface import NurbsSurface
from surfprep.algorithms.trimmed import TrimEdge, TrimLoop
from surfprep.plugin.heal.close_gaps import close_gaps
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.geom import curve_to_occ, surface_from_occ
from surfprep.plugin.occ.shapes import all_faces, is_valid, max_edge_tolerance, sew

TIGHT = 1e-7


def _patch(x0, x1, dz=0.0, n=6):
    x, y = np.meshgrid(np.linspace(x0, x1, n), np.linspace(0, 1, n), indexing="ij")
    return interpolate_surface(np.stack([x, y, 0.1 * np.sin(2 * x) * np.cos(y) + dz * (x >= 1.0 - 1e-12)],
                                        axis=-1))


def _shared(shape):
    """(edge, face a, face b) of every edge two faces share."""
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    out = []
    for k in range(1, edge_faces.Extent() + 1):
        faces = list(edge_faces.FindFromIndex(k))
        if len(faces) == 2:
            out.append((TopoDS.Edge_s(edge_faces.FindKey(k)), TopoDS.Face_s(faces[0]),
                        TopoDS.Face_s(faces[1])))
    return out


def _images(edge, face, n=2001):
    curve, surface = BRepAdaptor_Curve2d(edge, face), BRepAdaptor_Surface(face)
    t = np.linspace(curve.FirstParameter(), curve.LastParameter(), n)
    return np.array([surface.Value(*curve.Value(x).Coord()).Coord() for x in t])


def _gap(edge, a, b):
    """Largest distance between the two faces' points along the edge, at equal parameters."""
    return float(np.max(np.linalg.norm(_images(edge, a) - _images(edge, b), axis=1)))


def test_two_patches_a_step_apart_meet_in_the_geometry_after_closing():
    # the second patch lies 2e-4 higher: sewing at 1e-3 joins them by raising the edge's
    # tolerance; closing moves both onto one curve and the edge tolerance falls with it
    patches = [_patch(0.0, 1.0), _patch(1.0, 2.0, dz=2e-4)]
    shape, _ = sew([make_face(p) for p in patches], 1e-3)
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) == pytest.approx(2e-4, rel=1e-2)
    assert max_edge_tolerance(shape) >= 1e-4
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3)
    assert (closed.open_before, closed.open_after) == (1, 0)
    assert len(closed.moved) == 2 and all(m["moved"] <= 2e-4 for m in closed.moved)
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= TIGHT                        # measured on 2001 points
    assert BRep_Tool.Tolerance_s(edge) <= TIGHT
    assert is_valid(shape)
    # the free edges held: each face's far side is where it was
    v = np.linspace(0.0, 1.0, 201)
    for face in all_faces(shape):
        surface = BRep_Tool.Surface_s(face)
        left = surface.Value(0.5, 0.5).X() < 1.0
        patch, u = (patches[0], 0.0) if left else (patches[1], 1.0)
        new = np.array([surface.Value(u, x).Coord() for x in v])
        assert np.max(np.linalg.norm(new - patch.evaluate(np.full_like(v, u), v), axis=1)) <= TIGHT


def test_a_move_that_would_fold_a_face_over_is_refused_and_the_other_face_closes_alone(
        monkeypatch):
    # how far a move turns a face is measured on it (close_gaps._turned); here the right
    # patch's move is said to fold it (180 degrees): it keeps its surface, and the left
    # one moves the whole 2e-4 onto it
    from surfprep.plugin.heal import close_gaps as module

    measured = module._turned

    def turned(before, after, uv):
        right = before.evaluate(np.array([0.5]), np.array([0.5]))[0, 0] > 1.0
        return 180.0 if right else measured(before, after, uv)

    monkeypatch.setattr(module, "_turned", turned)
    patches = [_patch(0.0, 1.0), _patch(1.0, 2.0, dz=2e-4)]
    shape, _ = sew([make_face(p) for p in patches], 1e-3)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3)
    assert (closed.open_before, closed.open_after) == (1, 0)
    (moved,) = closed.moved
    assert moved["moved"] == pytest.approx(2e-4, rel=1e-2)
    assert moved["turned_deg"] < module.FOLD_DEG
    assert any("would fold over" in n for n in closed.notes)
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= TIGHT and is_valid(shape)
    # the right patch is the input's surface still
    right = next(f for f in all_faces(shape)
                 if BRep_Tool.Surface_s(f).Value(0.5, 0.5).X() > 1.0)
    v = np.linspace(0.0, 1.0, 21)
    got = np.array([BRep_Tool.Surface_s(right).Value(0.5, x).Coord() for x in v])
    assert np.abs(got - patches[1].evaluate(np.full_like(v, 0.5), v)).max() <= 1e-12


def test_an_analytic_plane_stays_and_the_b_spline_comes_to_it():
    plane = Geom_Plane(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))
    flat = BRepBuilderAPI_MakeFace(plane, -1.0, 0.0, 0.0, 1.0, 1e-7).Face()   # x in [-1, 0]
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    lifted = interpolate_surface(np.stack([x, y, 3e-4 * (1 - x) + 0.05 * x ** 2], axis=-1))
    shape, _ = sew([flat, make_face(lifted)], 1e-3)
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) == pytest.approx(3e-4, rel=1e-6)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3)
    assert closed.open_after == 0 and len(closed.moved) == 1
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= TIGHT
    planes = [f for f in all_faces(shape) if isinstance(BRep_Tool.Surface_s(f), Geom_Plane)]
    assert len(planes) == 1                                  # still a plane, z = 0
    s = BRepAdaptor_Surface(planes[0])
    assert s.Value(-0.5, 0.5).Z() == 0.0
    assert is_valid(shape)


def _stepped_planes(step):
    """Two faces of the planes z = 0 (x in [0, 1]) and z = ``step`` (x in [1, 2]), sewn."""
    flat = [BRepBuilderAPI_MakeFace(Geom_Plane(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)), x0, x0 + 1.0,
                                    0.0, 1.0, 1e-7).Face() for x0, z in ((0.0, 0.0), (1.0, step))]
    return sew(flat, 1e-3)[0]


def test_a_gap_no_b_spline_can_close_is_left_with_a_note():
    shape = _stepped_planes(2e-4)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3)
    assert (closed.open_before, closed.open_after) == (1, 1)
    assert closed.moved == () and closed.stuck == 1
    assert any("cannot move" in n for n in closed.notes)
    assert is_valid(shape)


def test_two_planes_a_step_apart_close_by_moving_one_as_a_b_spline():
    # neither face is a B-spline (the microstation K1 export's two tori, 2e-4 apart):
    # asked to (stuck=True), one is approximated in its own parameters and moved, the
    # other stays a plane
    shape = _stepped_planes(2e-4)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3, stuck=True)
    assert (closed.open_before, closed.open_after) == (1, 0)
    assert len(closed.moved) == 1 and closed.moved[0]["moved"] <= 2e-4 * 1.01
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= TIGHT                        # measured on 2001 points
    [plane], [moved] = _faces_by_type(shape)
    z = BRepAdaptor_Surface(plane).Value(0.5, 0.5).Z()
    assert z in (0.0, 2e-4)                                 # exact, where it was
    # the moved face's far side stays on its plane; its whole face within the step of it
    s = BRepAdaptor_Surface(moved)
    u0, u1, v0, v1 = s.FirstUParameter(), s.LastUParameter(), s.FirstVParameter(), s.LastVParameter()
    grid = np.array([[s.Value(u, v).Coord() for v in np.linspace(v0, v1, 21)]
                     for u in np.linspace(u0, u1, 21)])
    other = 2e-4 - z
    assert np.abs(grid[..., 2] - other).max() <= 2e-4 * 1.01
    far = np.isclose(grid[..., 0], 2.0 if other else 0.0, rtol=0, atol=1e-9)
    assert far.sum() == 21 and np.abs(grid[far][:, 2] - other).max() <= TIGHT
    assert closed.stuck == 0
    assert any("approximated as B-splines in their own parameters" in n for n in closed.notes)
    assert is_valid(shape)


def test_a_gap_no_face_can_close_is_left_with_a_note():
    shape = _stepped_planes(2e-4)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-4, stuck=True)   # each would move 2e-4
    assert (closed.open_before, closed.open_after) == (1, 1)
    assert closed.moved == ()
    assert any("cannot move" in n for n in closed.notes)
    assert is_valid(shape)


def _wavy_flat():
    """A face of the plane z = 0 over x in [-1, 0] whose side x = 0 waves within the
    plane, ``x = 2e-4 sin(3 pi y)`` (an exporter's approximate trimming curve)."""
    y = np.linspace(0.0, 1.0, 41)
    wave = curve_to_occ(interpolate_curve(np.stack([2e-4 * np.sin(3 * np.pi * y), y, 0 * y], axis=1)))
    polygon = BRepBuilderAPI_MakePolygon(gp_Pnt(0, 1, 0), gp_Pnt(-1, 1, 0), gp_Pnt(-1, 0, 0),
                                         gp_Pnt(0, 0, 0))
    wire = BRepBuilderAPI_MakeWire(polygon.Wire(), BRepBuilderAPI_MakeEdge(wave).Edge()).Wire()
    return BRepBuilderAPI_MakeFace(Geom_Plane(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), wire).Face()


def _faces_by_type(shape):
    """(faces on planes, the other faces) of ``shape``."""
    faces = all_faces(shape)
    flat = [isinstance(BRep_Tool.Surface_s(f), Geom_Plane) for f in faces]
    return ([f for f, p in zip(faces, flat) if p], [f for f, p in zip(faces, flat) if not p])


def test_a_plane_whose_trimming_waves_beside_its_neighbour_is_re_trimmed_not_moved():
    # the B-spline face rises from the line x = 0 of the plane: its side lies on the
    # plane, the plane's trimming curve waves 2e-4 beside it within the plane; the plane
    # takes the B-spline's side as its edge and neither surface moves
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    rising = interpolate_surface(np.stack([x, y, 0.3 * x + 0.05 * x ** 2], axis=-1))
    shape, _ = sew([_wavy_flat(), make_face(rising)], 1e-3)
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) == pytest.approx(2e-4, rel=1e-2)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3)
    assert (closed.open_before, closed.open_after) == (1, 0)
    assert closed.moved == () and len(closed.retrimmed) == 1
    assert closed.retrimmed[0]["moved"] == pytest.approx(2e-4, rel=1e-2)   # its boundary
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= TIGHT                        # measured on 2001 points
    assert BRep_Tool.Tolerance_s(edge) <= TIGHT
    planes, [curved] = _faces_by_type(shape)
    assert len(planes) == 1 and BRepAdaptor_Surface(planes[0]).Value(-0.5, 0.5).Z() == 0.0
    after = surface_from_occ(BRep_Tool.Surface_s(curved))  # the B-spline surface as it was
    u = np.linspace(0.0, 1.0, 41)
    assert np.max(np.abs(after.evaluate_grid(u, u) - rising.evaluate_grid(u, u))) <= 1e-12
    assert is_valid(shape)


def test_two_planes_meeting_at_an_angle_close_by_re_trimming_one():
    # neither face is a B-spline: the wavy plane takes the tilted plane's straight edge
    tilted = BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakePolygon(
        gp_Pnt(0, 0, 0), gp_Pnt(1, 0, 0.3), gp_Pnt(1, 1, 0.3), gp_Pnt(0, 1, 0), True).Wire(),
        True).Face()
    shape, _ = sew([_wavy_flat(), tilted], 1e-3)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-3)
    assert (closed.open_before, closed.open_after) == (1, 0)
    assert closed.moved == () and len(closed.retrimmed) == 1
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= TIGHT
    planes, others = _faces_by_type(shape)
    assert len(planes) == 2 and not others
    assert is_valid(shape)


def test_a_face_that_would_move_too_far_is_kept():
    faces = [make_face(_patch(0.0, 1.0)), make_face(_patch(1.0, 2.0, dz=2e-4))]
    shape, _ = sew(faces, 1e-3)
    closed = close_gaps(shape, tight=TIGHT, allowed=1e-5)
    assert closed.open_after == 1 and closed.moved == ()
    assert sum("would move" in n for n in closed.notes) == 2
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) == pytest.approx(2e-4, rel=1e-2)   # nothing changed
    assert is_valid(shape)


def _sheet(x0, x1, dz, n=7, p=3):
    """A cubic sheet over x in [x0 - 0.5, x1 + 0.5], y in [-0.5, 1.5], linear in its
    parameters (control points at the Greville abscissae)."""
    knots = np.concatenate([[0.0] * p, np.linspace(0.0, 1.0, n - p + 1), [1.0] * p])
    g = greville_abscissae(knots, p)
    x, y = np.meshgrid(x0 - 0.5 + g * (x1 - x0 + 1.0), -0.5 + 2.0 * g, indexing="ij")
    return NurbsSurface(np.stack([x, y, 0.1 * np.sin(2 * x) * np.cos(y) + dz], axis=-1),
                        knots, knots, p, p)


def _trimmed(surface, x0, x1, y0, y1):
    """``surface`` (a :func:`_sheet` over x in [x0 - 0.5, x1 + 0.5]) trimmed to
    [x0, x1] x [y0, y1]: its corners inside its domain."""
    u0, u1 = 0.5 / (x1 - x0 + 1.0), (x1 - x0 + 0.5) / (x1 - x0 + 1.0)
    v0, v1 = (y0 + 0.5) / 2.0, (y1 + 0.5) / 2.0
    c = np.array([(u0, v0), (u1, v0), (u1, v1), (u0, v1)])
    lines = [NurbsCurve(np.array([c[k], c[(k + 1) % 4]]), np.array([0.0, 0.0, 1.0, 1.0]), 1)
             for k in range(4)]
    return make_face(surface, [TrimLoop([TrimEdge(None, line, 0.0, 1.0) for line in lines])])


def test_corners_that_slid_along_the_edge_farther_than_allowed_still_close():
    # two trimmed sheets 2e-4 apart across x = 1, the second slid 0.03 along the edge:
    # sewing at 0.05 joins them, each vertex at the mean of the two corners 0.015 from
    # either; a face keeps its corners' parameters, so its surface stretches along
    # itself by 0.015 > allowed, but its shape moves by less than 1e-3. The move is
    # measured on the shape (closest points), and the faces close; at equal parameters
    # both were refused, the gap left at 0.03
    sheets = [_sheet(0.0, 1.0, 0.0), _sheet(1.0, 2.0, 2e-4)]
    shape, _ = sew([_trimmed(sheets[0], 0.0, 1.0, 0.0, 1.0),
                     _trimmed(sheets[1], 1.0, 2.0, 0.03, 1.03)], 0.05)
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) == pytest.approx(0.03, rel=1e-2)
    closed = close_gaps(shape, tight=1e-5, allowed=0.01)
    assert closed.open_after == 0 and len(closed.moved) >= 1
    [(edge, a, b)] = _shared(shape)
    assert _gap(edge, a, b) <= 1e-5                        # on 2001 points
    assert BRep_Tool.Tolerance_s(edge) <= 1e-5
    assert is_valid(shape)
    # each face's shape within 1e-3 of where it was, densely by closest points over
    # the face, and the report says no less
    moved = {m["face"]: m["moved"] for m in closed.moved}
    u, v = (x.ravel() for x in np.meshgrid(np.linspace(0.25, 0.75, 61),     # (inside both)
                                           np.linspace(0.265, 0.75, 61), indexing="ij"))
    for k, (face, before) in enumerate(zip(all_faces(shape), sheets)):
        after = surface_from_occ(BRep_Tool.Surface_s(face))
        off = float(project_to_surface(before, after.evaluate(u, v)).distance.max())
        assert off <= 1e-3
        assert moved.get(k, 0.0) >= 0.9 * off


def test_heal_moves_faces_on_a_copy_and_leaves_the_callers_model_as_it_was(tmp_path):
    # a shell sewn already: sewing it again in heal keeps its faces (the same TShapes),
    # and moving them in place changed the caller's model (41 of the 58 faces of
    # occt_k1_catia_debis.stp); the input is written out before and after, byte for byte
    from OCP.BRepTools import BRepTools

    import surfprep
    from surfprep.plugin.io import CadModel

    shape, _ = sew([make_face(_patch(0.0, 1.0)), make_face(_patch(1.0, 2.0, dz=2e-4))], 1e-3)
    model = CadModel.from_shape(shape)
    BRepTools.Write_s(model.shape, str(tmp_path / "before.brep"))
    healed = surfprep.heal(model)
    BRepTools.Write_s(model.shape, str(tmp_path / "after.brep"))
    assert len(healed.report()["closed_gaps"]["faces_moved"]) == 2     # it did move them
    [(edge, a, b)] = _shared(healed.model.shape)
    assert _gap(edge, a, b) <= 1e-6
    assert (tmp_path / "before.brep").read_bytes() == (tmp_path / "after.brep").read_bytes()
    [(edge, a, b)] = _shared(model.shape)
    assert _gap(edge, a, b) == pytest.approx(2e-4, rel=1e-2)   # the input's gap is there


@pytest.mark.slow
def test_heal_closes_the_capsules_gaps_unless_told_not_to():
    """The bundled Mars capsule: sewing closes its 10 open edges (up to 0.047 apart) by
    raising their tolerance to 0.049; heal moves the six B-spline faces along them onto
    common curves (largest edge tolerance 4.1e-6, each face within gap_tol of where it
    was); --no-close-gaps / close_gaps=False leaves them as sewing does."""
    from helpers.paths import SAMPLES

    import surfprep

    path = SAMPLES / "overture_marscapsule_proe.igs"
    closed = surfprep.heal(path)
    report = closed.report()["closed_gaps"]
    assert report["open_edges_before"] == 10 and report["open_edges_after"] == 0
    assert all(m["moved"] <= closed.gap_tol for m in report["faces_moved"])
    assert closed.max_edge_tolerance < 1e-5 and closed.valid_after
    kept = surfprep.heal(path, close_gaps=False)
    assert kept.report()["closed_gaps"] == {}
    assert kept.max_edge_tolerance > 0.04
    assert kept.tight_free_edges_after > closed.tight_free_edges_after
