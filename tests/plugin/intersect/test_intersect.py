"""surfprep.intersect: faces of shapes, clipping to trimmed faces, shared edges, edges out."""

from __future__ import annotations

import cadquery as cq
import numpy as np
import pytest
from helpers.paths import SAMPLES
from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.Geom import Geom_SphericalSurface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt

import surfprep
from surfprep.algorithms.intersection import connected_branches, curve_set_distance, polyline_distance
from surfprep.errors import ConversionError, InvalidToleranceError
from surfprep.plugin.intersect import FaceIntersection, face_operands, intersect
from surfprep.plugin.occ_reference import section_faces_occ


def unit_sphere():
    return cq.Solid.makeSphere(1.0, angleDegrees1=-90, angleDegrees2=90)


def check_result(result: list[FaceIntersection], tol: float | None = None):
    """Every piece within tol of both surfaces (interpolants between samples too), and
    an edge with a pcurve on each face that BRepCheck accepts."""
    for r in result:
        assert r.max_deviation().max <= (tol or r.tol)
        (edge,) = r.to_edges()
        assert BRepCheck_Analyzer(edge).IsValid()
        for face in (r.face_a.face_for_edges(), r.face_b.face_for_edges()):
            assert BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0) is not None


def test_sphere_and_plane_face_give_the_circle():
    result = intersect(unit_sphere(), cq.Face.makePlane(4, 4, basePnt=(0, 0, 0.3)), tol=1e-7)
    check_result(result)
    assert len(result) == 1 and result[0].closed and result[0].faces == (0, 0)
    p = result[0].points
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1.0, atol=1e-7)
    np.testing.assert_allclose(p[:, 2], 0.3, atol=1e-7)
    assert result[0].length == pytest.approx(2 * np.pi * np.sqrt(0.91), rel=1e-6)


def test_curve_is_clipped_to_the_trimmed_face():
    """A 1 x 1 square over [0, 1]^2 at z = 0.3 keeps a quarter of the circle; the
    pieces end on the square's sides, and BRepAlgoAPI_Section agrees."""
    sphere, square = unit_sphere(), cq.Face.makePlane(1, 1, basePnt=(0.5, 0.5, 0.3))
    result = intersect(sphere, square, tol=1e-7)
    check_result(result)
    (piece,) = result
    ends = piece.points[[0, -1]]
    assert np.sort(np.abs(ends[:, :2]).min(axis=1)).max() <= 1e-7
    assert piece.length == pytest.approx(np.pi / 2 * np.sqrt(0.91), rel=1e-6)
    occ = section_faces_occ(sphere.Faces()[0].wrapped, square.wrapped)
    assert connected_branches(occ, 1e-6) == 1
    assert curve_set_distance([piece.curve], occ).hausdorff <= 1e-5


def test_hole_in_a_face_splits_the_curve():
    """A plane face with a round hole: the circle z = 0.3 on the sphere leaves the face
    where it crosses the hole (even-odd rule on outer loop + hole)."""
    plate = (cq.Workplane("XY", origin=(0, 0, 0.3)).rect(4, 4).extrude(0.1)
             .faces("<Z").workplane().center(0.95, 0).hole(0.4).faces("<Z").val())
    result = intersect(unit_sphere(), plate, tol=1e-7)
    check_result(result)
    assert len(result) == 1 and not result[0].closed
    p = result[0].points
    # the crossings are moved from the sampled loop polygon (up to 2.5e-4 inside the
    # hole's circle) onto the exact pcurve: the ends lie on the hole's rim
    # (the hole is at x = 0.95 or -0.95 depending on the workplane's orientation: the
    # circle passes 0.0039 from the other centre, so the hole is the farther one)
    hole = max(np.hypot(p[:, 0] - x, p[:, 1]).min() for x in (0.95, -0.95))
    assert hole == pytest.approx(0.2, abs=1e-7)
    assert result[0].length < 2 * np.pi * np.sqrt(0.91) - 0.3


def test_build123d_box_and_cylinder():
    import build123d as bd
    result = intersect(bd.Box(1, 1, 1), bd.Cylinder(0.3, 2), tol=1e-7)
    check_result(result)
    assert connected_branches([r.curve for r in result], 1e-6) == 2
    p = np.concatenate([r.points for r in result])
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 0.3, atol=1e-7)
    np.testing.assert_allclose(np.abs(p[:, 2]), 0.5, atol=1e-7)
    assert sum(r.length for r in result) == pytest.approx(2 * 2 * np.pi * 0.3, rel=1e-6)


def test_faces_of_one_box_share_edges_but_do_not_intersect():
    assert intersect(cq.Workplane().box(1, 1, 1)) == []


def test_two_overlapping_boxes_in_one_compound():
    two = cq.Compound.makeCompound([cq.Solid.makeBox(1, 1, 1),
                                    cq.Solid.makeBox(1, 1, 1, pnt=cq.Vector(0.5, 0.3, 0.2))])
    result = intersect(two, tol=1e-7)
    check_result(result)
    assert sorted(round(r.length, 9) for r in result) == [0.5, 0.5, 0.7, 0.7, 0.8, 0.8]
    # every piece on box 1's boundary and box 2's boundary
    for r in result:
        i, j = r.faces
        assert i < 6 <= j


def test_surface_inputs():
    sphere = Geom_SphericalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0)
    nurbs = surfprep.to_nurbs(cq.Face.makePlane(4, 4, basePnt=(0, 0, -0.5)))
    result = intersect(sphere, nurbs.surface, tol=1e-7)
    check_result(result)
    assert len(result) == 1 and result[0].closed
    assert result[0].length == pytest.approx(2 * np.pi * np.sqrt(0.75), rel=1e-6)
    result = intersect(nurbs, sphere, tol=1e-7)          # a TrimmedFace too
    assert len(result) == 1


def test_inside_face_even_odd_with_hole():
    plate = (cq.Workplane("XY").rect(2, 2).extrude(0.1).faces("<Z").workplane()
             .hole(1.0).faces("<Z").val())
    (face,) = face_operands(plate)
    s = face.surface
    # points in space -> (u, v) of the plane's own parametrization, by least squares
    x = np.array([[0.0, 0.0], [0.75, 0.0], [0.0, -0.9], [1.5, 0.0], [0.5, 0.0]])
    o = s.evaluate(0.0, 0.0)
    du, dv = s.evaluate(1.0, 0.0) - o, s.evaluate(0.0, 1.0) - o
    m = np.stack([du, dv], 1)
    uv = np.linalg.lstsq(m, (np.c_[x, np.zeros(len(x))] - o).T, rcond=None)[0].T
    assert face.region.contains(uv).tolist() == [False, True, True, False, True]


def test_inside_face_dense_against_the_exact_plate():
    """20000 random points at once (the cached loop index, the uv tree, the band
    measured in space) agree with the exact square-with-hole away from its edges."""
    plate = (cq.Workplane("XY").rect(2, 2).extrude(0.1).faces("<Z").workplane()
             .hole(1.0).faces("<Z").val())
    (face,) = face_operands(plate)
    s = face.surface
    u0, u1, v0, v1 = s.domain
    rng = np.random.default_rng(3)
    uv = np.c_[rng.uniform(u0, u1, 20000), rng.uniform(v0, v1, 20000)]
    xyz = s.evaluate(uv[:, 0], uv[:, 1])
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    exact = (np.abs(xyz[:, 0]) <= 1) & (np.abs(xyz[:, 1]) <= 1) & (r >= 0.5)
    margin = np.minimum(np.minimum(1 - np.abs(xyz[:, 0]), 1 - np.abs(xyz[:, 1])), r - 0.5)
    clear = np.abs(margin) > 1e-3                       # beyond the loop polygon's sag
    for tol in (0.0, 1e-7):
        got = face.region.contains(uv, tol)
        assert np.array_equal(got[clear], exact[clear])
        assert np.array_equal(face.region.contains(uv[::-1], tol), got[::-1])   # cache reused


@pytest.fixture(scope="module")
def debis(data_dir):
    path = data_dir / "occt_k1_catia_debis.stp"
    return surfprep.read(path)


def test_real_file_faces_across_and_within(debis):
    """Faces 9 and 11 share a sharp curved edge. Given as a and b, their intersection
    is that edge (the file's edge lies 5e-4 mm off the surfaces, within its tolerance);
    given together as a, the shared edge is not reported."""
    from OCP.BRep import BRep_Tool as Tool
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from surfprep.plugin.occ.edges import edge_to_nurbs
    fa, fb = debis.faces[9], debis.faces[11]
    result = intersect(fa, fb)
    check_result(result)
    assert len(result) == 1
    edges = []
    ex = TopExp_Explorer(fa, TopAbs_EDGE)
    while ex.More():
        edges.append(TopoDS.Edge_s(ex.Current()))
        ex.Next()
    ex = TopExp_Explorer(fb, TopAbs_EDGE)
    shared = None
    while ex.More():
        e = TopoDS.Edge_s(ex.Current())
        shared = e if any(e.IsSame(g) for g in edges) else shared
        ex.Next()
    curve = edge_to_nurbs(shared)
    samples = curve.evaluate(np.linspace(*curve.domain, 201))
    # the edge's tolerance bounds its distance to each face's pcurve image; the true
    # intersection may lie up to about twice that from the stored 3D curve
    assert polyline_distance(samples, [result[0].curve]).max() <= \
        2 * Tool.Tolerance_s(shared) + result[0].tol
    assert result[0].length == pytest.approx(np.linalg.norm(np.diff(samples, axis=0),
                                                            axis=1).sum(), rel=1e-3)
    assert result[0].tol == pytest.approx(1e-6 * np.linalg.norm(np.ptp(np.concatenate(
        [f.surface.bounding_box() for f in face_operands([fa, fb])]), axis=0)))
    assert intersect([fa, fb]) == []


@pytest.mark.parametrize("pair", [(2, 6), (12, 13), (5, 8)])
def test_real_file_faces_of_one_shape_give_no_remnants(debis, pair):
    """Faces of the closed debis model meet only along edges: intersected among
    themselves they give nothing, not even the short pieces where the surfaces'
    intersection runs within the (sloppy, up to 3e-3 mm) edge tolerance of a loop."""
    assert intersect([debis.faces[k] for k in pair]) == []


def test_progress_is_reported():
    calls = []
    intersect(unit_sphere(), cq.Face.makePlane(4, 4, basePnt=(0, 0, 0.3)),
              progress=lambda done, total: calls.append((done, total)))
    assert calls == [(0, 1), (1, 1)]                 # the pairs known, then each done


@pytest.mark.parametrize("tol", [0.0, -1.0, float("nan"), 1e-15, "x"])
def test_bad_tolerance(tol):
    with pytest.raises(InvalidToleranceError):
        intersect(unit_sphere(), cq.Face.makePlane(4, 4), tol=tol)


def test_bad_operand():
    with pytest.raises(ConversionError):
        intersect(object(), unit_sphere())


def test_public_name():
    assert surfprep.intersect is intersect


# ------------------------------------------------------------------ tangent joins
def _flat_crossing_faces(slope):
    from helpers.surfaces import flat_crossing
    a, b = flat_crossing(slope)
    return surfprep.make_face(a), surfprep.make_face(b)


def test_faces_of_one_shape_overlapping_within_tolerance_do_not_self_intersect():
    """Two faces of one shape overlapping over a strip 0.1 wide, their surfaces within
    7e-5 of each other there (crossing at 1e-3 rad), tol 1e-5: among the faces of one
    shape that is a tangent join, not a self-intersection (each face lies within 10 tol
    of the other all the way from the crossing to its edge); across two operands the
    crossing is an answer. At 2e-3 rad (1.4e-4 apart at the strip's edge) the faces
    truly cut through each other, and the crossing is reported within one shape too."""
    fa, fb = _flat_crossing_faces(1e-3)
    assert intersect([fa, fb], tol=1e-5) == []
    (across,) = intersect(fa, fb, tol=1e-5)
    assert across.length == pytest.approx(1.02, abs=0.01)
    fa, fb = _flat_crossing_faces(2e-3)
    (within,) = intersect([fa, fb], tol=1e-5)
    assert within.length == pytest.approx(1.02, abs=0.01)


@pytest.mark.slow
def test_bundled_fuselage_does_not_self_intersect():
    """step_samples/occt_fuselage.stp: its faces meet tangentially along their seams
    and overlap a little there (the surfaces' crossings wander up to 44 mm from the
    common edges, within 10 tol of each other); intersected among themselves they
    gave 38 remnant curves before the tangent-join test, now none."""
    model = surfprep.read(SAMPLES / "occt_fuselage.stp")
    result = intersect(model)
    assert list(result) == []


def test_a_tangential_contact_with_clustered_singular_points_ends(data_dir, monkeypatch):
    """pyocc_ventilator_catia5.stp faces 235 x 244 touch along a curve with their
    normals parallel: 27 singular points found close together on it. Re-splitting every
    trace at all of them every round multiplied the traces (60 -> 514951 in 7 rounds;
    the whole-model intersect sat there for good). Each trace is now split once per
    point, and nothing of OpenCascade's section curve is missed."""
    from surfprep.algorithms.characteristic import singular
    sizes = []
    real = singular._split_at_found

    def counted(*args):
        work, new = real(*args)
        sizes.append(len(work))
        if len(work) > 1000:
            raise AssertionError(f"the traces multiply round after round: {sizes}")
        return work, new

    monkeypatch.setattr(singular, "_split_at_found", counted)
    model = surfprep.read(data_dir / "pyocc_ventilator_catia5.stp")
    operands = face_operands(model)
    result = intersect(operands[235].trimmed, operands[244].trimmed)
    assert sizes and max(sizes) <= 2 * sizes[0]
    check_result(result)
    (occ,) = section_faces_occ(model.faces[235], model.faces[244])
    assert polyline_distance(occ.points, [c.curve for c in result]).max() <= result.tol


def test_a_pair_stopped_by_the_callers_time_limit_is_recorded_and_the_run_goes_on(monkeypatch):
    """TimeLimitExceeded raised into a pair (as the CLI's timer does): that pair is in
    ``stopped`` with a warning and none of its curves, the others are complete."""
    import surfprep.plugin.intersect as verb
    from surfprep.errors import TimeLimitExceeded
    real = verb.pair_curves
    seen = []

    def second_is_stopped(fa, fb, *args, **kwargs):
        seen.append((fa.index, fb.index))
        if len(seen) == 2:
            raise TimeLimitExceeded("a face pair ran longer than 1 s")
        return real(fa, fb, *args, **kwargs)

    monkeypatch.setattr(verb, "pair_curves", second_is_stopped)
    sphere = unit_sphere()
    planes = [cq.Face.makePlane(4, 4, basePnt=(0, 0, z)) for z in (0.3, 0.5, -0.4)]
    with pytest.warns(UserWarning, match="stopped by the time limit"):
        result = intersect(sphere, planes)
    assert [p.faces for p in result.stopped] == [seen[1]]
    assert len(result.records) == len(seen) - 1 == 2
    assert sorted(r.faces for r in result) == sorted(p for p in (seen[0], seen[2]))
    assert result.report()["stopped_pairs"][0]["faces"] == list(seen[1])


def test_faces_whose_own_boxes_are_apart_are_not_intersected():
    """Two small faces cut from crossing planes, both away from where the planes cross:
    the surfaces' boxes overlap, the faces' do not, and no pair is worked on; faces of
    the same planes that reach the crossing still give its segment."""
    from helpers.surfaces import straight_loop

    from surfprep import NurbsSurface, TrimmedFace

    def square(x0, x1):
        return straight_loop([[x0, 0.0], [x1, 0.0], [x1, 1.0], [x0, 1.0]])

    knots = [0, 0, 1, 1]
    flat = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]], float),
                        knots, knots, 1, 1)                      # z = 0
    slope = NurbsSurface(np.array([[[0, 0, -0.5], [0, 1, -0.5]], [[1, 0, 0.5], [1, 1, 0.5]]],
                                  float), knots, knots, 1, 1)      # z = x - 0.5
    apart = intersect(TrimmedFace(flat, (square(0.0, 0.2),)),
                      TrimmedFace(slope, (square(0.8, 1.0),)), tol=1e-7)
    assert len(apart) == 0 and len(apart.records) == 0
    meeting = intersect(TrimmedFace(flat, (square(0.3, 0.7),)),
                        TrimmedFace(slope, (square(0.4, 1.0),)), tol=1e-7)
    assert len(meeting) == 1 and len(meeting.records) == 1
    np.testing.assert_allclose(meeting[0].points[:, 0], 0.5, atol=1e-7)
    assert meeting[0].length == pytest.approx(1.0, abs=1e-7)
