"""surfprep.split: faces cut along their intersection curves, pieces sharing the cut edges."""

from __future__ import annotations

import math

import cadquery as cq
import numpy as np
import pytest
from helpers.paths import SAMPLES

from surfprep.plugin.occ.shapes import face_area, is_valid, max_edge_tolerance
from surfprep.plugin.split import split


def _sheet(plane: str, offset=(0, 0, 0)):
    return cq.Workplane(plane).rect(2, 2).extrude(0.001).faces(">Z" if plane == "XY" else (
        ">X" if plane == "YZ" else "<Y")).val().translate(cq.Vector(*offset))


def test_two_crossing_sheets_become_four_pieces_around_one_edge():
    out = split(_sheet("XY"), _sheet("YZ"))
    report = out.report()
    assert report["pieces"] == 4 and out.valid and report["assembled"] == "structure"
    assert out.shared_edges.get(4) == 1                   # the intersection edge: four faces
    assert out.free_edges == 12                           # the sheets' outer borders, cut in two
    # the same by our own structure, and the four faces alternate around the edge
    structure = out.structure
    assert structure.edges_by_uses() == {1: 12, 4: 1}
    (edge,) = [e for e in range(structure.n_edges) if len(structure.uses[e]) == 4]
    assert [structure.operand(f) for f in structure.faces_around(edge)] in (list("abab"), list("baba"))
    for f in out.faces:
        assert sum(face_area(p, 1e-9) for p in f.pieces) == pytest.approx(4.0, rel=1e-9)


def test_a_sphere_through_a_plate_is_cut_into_its_exact_zones():
    radius, half = 10.0, 0.5
    out = split(cq.Workplane().sphere(radius), cq.Workplane().box(30, 30, 2 * half).translate((0, 0, 5)))
    assert out.valid and out.free_edges == 0
    sphere = next(f for f in out.faces if f.operand == "a")
    areas = sorted(face_area(p, 1e-9) for p in sphere.pieces)
    assert len(areas) == 3
    # the zone between the plate's faces: 2 pi R h (Archimedes), the caps likewise
    np.testing.assert_allclose(areas, sorted([2 * math.pi * radius * 2 * half,
                                              2 * math.pi * radius * (radius - 5.5),
                                              2 * math.pi * radius * (radius + 4.5)]), rtol=1e-6)
    assert out.shared_edges.get(4) == 2                   # both circles bound four faces
    assert out.structure.edges_by_uses() == {2: 15, 4: 2} # ours: the same (poles are no edges)
    _built_from_the_structure(out)


def _built_from_the_structure(out) -> None:
    """The shape is the structure: one TopoDS_Edge per edge of it, used by the same number
    of faces, no edge tolerance beyond what the curves measure (here well under the
    sewing tolerance a sewing would have given them), one shell."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape
    assert out.assembled == "structure" and out.shape.ShapeType() == TopAbs_SHELL
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(out.shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    uses = sorted(edge_faces.FindFromIndex(k).Size() for k in range(1, edge_faces.Extent() + 1)
                  if not BRep_Tool.Degenerated_s(TopoDS.Edge_s(edge_faces.FindKey(k))))
    assert uses == sorted(out.structure.use_counts().tolist())
    assert max_edge_tolerance(out.shape) < 0.1 * out.sew_tol


def test_a_face_whose_curves_cross_is_cut_into_four():
    out = split(_sheet("XY"), [_sheet("YZ"), _sheet("XZ")])
    sheet = next(f for f in out.faces if f.operand == "a")
    assert sheet.kept is None and len(sheet.pieces) == 4 and out.valid
    assert sum(face_area(p, 1e-9) for p in sheet.pieces) == pytest.approx(4.0, rel=1e-9)


def test_a_fin_on_a_plate_is_an_internal_edge_shared_by_three_faces():
    """A fin half as wide as the plate: their curve stops inside the plate (on the fin's
    edge), so it divides nothing there: the plate keeps it as an INTERNAL edge, the
    same edge the fin's two pieces share -- a T-junction of three faces."""
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_INTERNAL
    from OCP.TopExp import TopExp_Explorer
    fin = cq.Workplane("YZ").rect(1, 2).extrude(0.001).faces(">X").val()
    out = split(_sheet("XY"), fin)
    assert all(f.kept is None for f in out.faces)
    assert [len(f.pieces) for f in out.faces] == [1, 2] and out.valid
    assert out.shared_edges.get(3) == 1 and out.structure.edges_by_uses().get(3) == 1
    internal, explorer = 0, TopExp_Explorer(out.shape, TopAbs_EDGE)
    while explorer.More():
        internal += explorer.Current().Orientation() == TopAbs_INTERNAL
        explorer.Next()
    assert internal == 1
    plate = out.structure.faces[0]
    assert len(plate.internal) == 1 and face_area(out.pieces_a[0], 1e-9) == pytest.approx(4.0, rel=1e-9)


def test_a_bent_fin_on_a_plate_leaves_a_path_of_two_internal_edges():
    """A fin of two faces meeting at a right angle (an L seen from above), standing on the
    plate inside it: its foot is two curves joined at the corner, both stopping inside the
    plate -- two internal edges of the plate, each shared with the two pieces of one fin
    face (two T-junctions of three faces)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.gp import gp_Pnt

    def rectangle(*corners):
        polygon = BRepBuilderAPI_MakePolygon()
        for c in corners:
            polygon.Add(gp_Pnt(*c))
        polygon.Close()
        return BRepBuilderAPI_MakeFace(polygon.Wire(), True).Face()
    legs = [rectangle((-0.5, 0, -0.5), (0, 0, -0.5), (0, 0, 0.5), (-0.5, 0, 0.5)),
            rectangle((0, 0, -0.5), (0, 0.5, -0.5), (0, 0.5, 0.5), (0, 0, 0.5))]
    out = split(_sheet("XY"), legs)
    assert all(f.kept is None for f in out.faces) and out.valid
    assert [len(f.pieces) for f in out.faces] == [1, 2, 2]
    plate = out.structure.faces[0]
    assert len(plate.internal) == 2 and face_area(out.pieces_a[0], 1e-9) == pytest.approx(4.0, rel=1e-9)
    assert out.structure.edges_by_uses().get(3) == 2 and out.shared_edges.get(3) == 2


def test_a_fin_over_the_sheets_border_is_a_spur_in_both_sharing_one_edge():
    """The fin stands over the sheet's border: the curve runs in from the sheet's border
    and stops inside it, and from the fin's border and stops inside the fin -- a spur in
    each, one edge of both faces, its ends on each face's border vertex there."""
    fin = cq.Workplane("YZ").rect(1, 2).extrude(0.001).faces(">X").val().translate(cq.Vector(0, 1.0, 0))
    out = split(_sheet("XY"), fin)
    assert all(f.kept is None and len(f.pieces) == 1 for f in out.faces) and out.valid
    assert is_valid(out.shape)
    assert out.shared_edges.get(2) == 1 and out.structure.edges_by_uses().get(2) == 1
    assert all(len(face.internal) == 1 for face in out.structure.faces)
    assert max_edge_tolerance(out.shape) <= 10 * out.curves.tol


@pytest.mark.parametrize("operation", ["common", "fuse", "cut"])
def test_booleans_are_selections_of_pieces_with_the_exact_volumes(operation):
    """A sphere (r = 10) and a 1 mm slab through it at z = 5: the common part is the
    spherical slab pi (r^2 h - (z1^3 - z0^3) / 3); fuse and cut follow."""
    from surfprep.plugin.split import boolean
    r = 10.0
    common = math.pi * (r * r * 1.0 - (5.5 ** 3 - 4.5 ** 3) / 3)
    exact = {"common": common, "fuse": 4 / 3 * math.pi * r ** 3 + 900 - common,
             "cut": 4 / 3 * math.pi * r ** 3 - common}[operation]
    out = boolean(cq.Workplane().sphere(r), cq.Workplane().box(30, 30, 1).translate((0, 0, 5)), operation)
    assert out.valid
    # the curves are computed to 1e-6 x the model's size: the volume follows to that order
    assert out.volume == pytest.approx(exact, rel=1e-6)
    assert out.kept == {"common": (1, 2), "fuse": (2, 6), "cut": (2, 2)}[operation]
    assert out.report()["operation"] == operation


def test_a_boolean_needs_solids_and_a_known_operation():
    from surfprep.errors import InvalidGeometryError, OpenCascadeError
    from surfprep.plugin.split import boolean
    with pytest.raises(InvalidGeometryError, match="unknown operation"):
        boolean(cq.Workplane().sphere(1), cq.Workplane().box(1, 1, 1), "xor")
    with pytest.raises(OpenCascadeError, match="closed solids"):
        boolean(_sheet("XY"), _sheet("YZ"), "fuse")


def test_two_spheres_cut_across_a_seam_give_the_lens():
    """The circle where two spheres meet crosses one sphere's seam (two curves that end on
    it) and lies inside the other's face (the same two curves joined end to end there)."""
    from surfprep.plugin.split import boolean
    r, d = 5.0, 6.0
    lens = math.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    out = boolean(cq.Workplane().sphere(r), cq.Workplane().sphere(r).translate((d, 0, 0)), "common")
    assert out.valid and out.volume == pytest.approx(lens, rel=1e-6)
    assert [len(f.pieces) for f in out.split.faces] == [3, 2]      # the cap in two halves across the seam


def _plane_across(model, fraction: float):
    """The height ``fraction`` of the way up a model, and a planar face there, normal +z,
    three times the model's width each way."""
    xmin, ymin, zmin, xmax, ymax, zmax = model.bounding_box
    z = zmin + fraction * (zmax - zmin)
    plane = cq.Workplane("XY").rect(3 * (xmax - xmin), 3 * (ymax - ymin)).extrude(0.001).faces(">Z").val()
    return z, plane.translate(cq.Vector((xmin + xmax) / 2, (ymin + ymax) / 2, z - 0.001))


def test_a_real_hull_cut_at_a_waterline(data_dir):
    """overture_kcs_hull_ideas.igs cut by a plane at 37 % of its depth (the plane only
    cuts): every hull face it crosses comes out in two valid pieces of the same area."""
    import surfprep
    model = surfprep.read(data_dir / "overture_kcs_hull_ideas.igs")
    z, plane = _plane_across(model, 0.37)
    out = split(model, plane, tool=True)
    assert len(out.faces) == 6 and all(f.kept is None and len(f.pieces) == 2 for f in out.faces)
    assert out.valid and out.shared_edges.get(4) is None          # the plane itself is not written
    for f in out.faces:
        whole = face_area(model.faces[f.index], 1e-9)
        assert sum(face_area(p, 1e-9) for p in f.pieces) == pytest.approx(whole, rel=1e-6)
        # the pieces lie on either side of the waterline
        from OCP.Bnd import Bnd_Box
        from OCP.BRepBndLib import BRepBndLib
        tops = []
        for piece in f.pieces:
            box = Bnd_Box()
            BRepBndLib.AddOptimal_s(piece, box, False, False)
            tops.append(box.CornerMax().Z())
        height = model.bounding_box[5] - model.bounding_box[2]
        assert min(tops) == pytest.approx(z, abs=1e-3 * height)


def test_the_fuselage_cut_by_a_wing_keeps_every_hole_with_its_face():
    """A real B-spline pair: the wing's root loops lie inside two fuselage faces, each an
    open curve cut at the wing's seam whose ends meet inside the face. Each face becomes
    its island and the rest with the island as a hole (the hole once went to the island
    and the face was refused), the areas adding up to the face's."""
    import surfprep
    fuselage = surfprep.read(SAMPLES / "occt_fuselage.stp")
    out = split(fuselage, SAMPLES / "synthetic_wing.step")
    assert out.valid
    cut = [f for f in out.faces if f.operand == "a"]
    assert [f.index for f in cut] == [2, 3]
    for f in cut:
        assert f.kept is None and len(f.pieces) == 2
        whole = face_area(fuselage.faces[f.index], 1e-9)
        assert sum(face_area(p, 1e-9) for p in f.pieces) == pytest.approx(whole, rel=1e-6)
    wing = next(f for f in out.faces if f.operand == "b")
    assert wing.kept is None and len(wing.pieces) == 3         # inside the body, and out on both sides
    assert out.shared_edges.get(4) == 2                  # each root loop: one edge, four faces
    assert out.structure.edges_by_uses() == {2: 19, 4: 2}
    assert len(out.structure.components()) == 1


def test_a_sphere_trimmed_by_a_sheet_keeps_one_side_by_its_normal():
    """The sheet z = 5 (normal +z) cuts the sphere of radius 10: in front of it the cap of
    height 5, behind it the rest; areas 2 pi R h (Archimedes)."""
    from surfprep.plugin.split import trim
    sphere = cq.Workplane().sphere(10.0)
    sheet = cq.Workplane("XY").rect(30, 30).extrude(0.001).faces(">Z").val().translate(cq.Vector(0, 0, 5 - 0.001))
    front = trim(sphere, sheet, keep="front")
    back = trim(sphere, sheet, keep="back")
    assert front.kept == (1, 0) and back.kept == (1, 0) and front.valid and back.valid
    assert face_area(front.shape, 1e-9) == pytest.approx(2 * math.pi * 10 * 5, rel=1e-6)
    assert face_area(back.shape, 1e-9) == pytest.approx(2 * math.pi * 10 * 15, rel=1e-6)
    assert front.operation == "trim-front"
    with pytest.raises(Exception, match="keep"):
        trim(sphere, sheet, keep="above")


@pytest.mark.parametrize(("offset", "volumes"), [
    ((10, 0, 0), {"fuse": 2000.0, "common": 0.0, "cut": 1000.0}),      # touching along x = 5
    # touching over part of a face: the edges beside the contact are split where it ends
    # (a T-junction otherwise: the fuse came out open)
    ((10, 3, 0), {"fuse": 2000.0, "common": 0.0, "cut": 1000.0}),
    ((5, 5, 0), {"fuse": 1750.0, "common": 250.0, "cut": 750.0}),       # top and bottom coplanar
])
def test_booleans_of_boxes_with_coincident_faces(offset, volumes):
    """Coincident faces count once: touching solids (normals opposed) lose the face they
    share in fuse, keep A's in cut; coplanar overlapping faces (normals along) keep one
    copy. Curves along the faces' edges divide nothing and are left out."""
    from surfprep.plugin.split import boolean
    a = cq.Workplane().box(10, 10, 10)
    b = cq.Workplane().box(10, 10, 10).translate(offset)
    for operation, exact in volumes.items():
        result = boolean(a, b, operation)
        assert result.valid and result.closed
        assert result.volume == pytest.approx(exact, rel=1e-9, abs=1e-9)


def test_coplanar_faces_of_two_solids_are_one_face_of_the_split():
    """Overlapping boxes: the regions where their tops (and bottoms) lie on each other are
    one face of the split (a's; b's piece is the same face), so the split's faces cover
    a's 600 and b's 600 less the 2 x 25 they share."""
    from surfprep.plugin.occ.shapes import all_faces
    out = split(cq.Workplane().box(10, 10, 10), cq.Workplane().box(10, 10, 10).translate((5, 5, 0)))
    assert len(out.coincident) == 2 and all(along for _, _, along in out.coincident)
    faces = all_faces(out.shape)
    assert len(faces) == len(out.structure.faces) - 2 and out.valid and out.free_edges == 0
    assert sum(face_area(f, 1e-9) for f in faces) == pytest.approx(1150.0, rel=1e-9)
    report = out.report()
    assert report["coincident_faces"] == 2
    assert sum("same_as" in f for f in report["output_faces"]) == 2


def test_one_split_serves_every_boolean():
    """The pieces are cut once; fuse, cut and common are selections of them."""
    from surfprep.errors import InvalidGeometryError
    cube = cq.Workplane().box(10, 10, 10)
    bar = cq.Workplane("YZ").circle(3).extrude(20).translate((-10, 0, 0))
    pieces = split(cube, bar)
    inside = math.pi * 9 * 10
    exact = {"common": inside, "fuse": 1000 + math.pi * 9 * 20 - inside, "cut": 1000 - inside}
    for operation, volume in exact.items():
        result = getattr(pieces, operation)()
        assert result.split is pieces and result.valid
        assert result.volume == pytest.approx(volume, rel=1e-6)
    with pytest.raises(InvalidGeometryError, match="two operands"):
        split(cube).select("fuse")
    with pytest.raises(InvalidGeometryError, match="unknown operation"):
        pieces.select("xor")


def _cylinder(axis: str, radius: float):
    """A cylinder of ``radius``, 20 long along x ("YZ") or y ("XZ"), centred at 0."""
    shift = (-10, 0, 0) if axis == "YZ" else (0, 10, 0)
    return cq.Workplane(axis).circle(radius).extrude(20).translate(shift)


def test_two_cylinders_crossing_at_right_angles():
    """Equal radii: the curves are two ellipses crossing at two double points where four
    faces meet; common = the Steinmetz solid 16 r^3 / 3. Unequal radii: common by the
    integral of the cross-sections 4 sqrt((r2^2 - z^2)(r1^2 - z^2)) (scipy quad)."""
    from scipy.integrate import quad
    for r2, common in ((3.0, 16 * 27 / 3),
                       (2.0, quad(lambda z: 4 * math.sqrt((4 - z * z) * (9 - z * z)), -2, 2,
                                  epsabs=1e-13, epsrel=1e-13)[0])):
        pieces = split(_cylinder("YZ", 3.0), _cylinder("XZ", r2))
        assert all(f.kept is None for f in pieces.faces)
        _built_from_the_structure(pieces)
        va, vb = math.pi * 9 * 20, math.pi * r2 * r2 * 20
        for operation, exact in (("common", common), ("fuse", va + vb - common), ("cut", va - common)):
            result = pieces.select(operation)
            assert result.valid and result.volume == pytest.approx(exact, rel=1e-6)


def test_a_box_minus_a_sphere_poking_out_of_its_top():
    box, ball = cq.Workplane().box(10, 10, 10), cq.Workplane().sphere(3).translate((0, 0, 5))
    half = 2 / 3 * math.pi * 27
    pieces = split(box, ball)
    for operation, exact in (("cut", 1000 - half), ("common", half), ("fuse", 1000 + half)):
        result = pieces.select(operation)
        assert result.valid and result.volume == pytest.approx(exact, rel=1e-6)


@pytest.mark.slow
def test_a_real_solid_cut_at_mid_height(data_dir):
    """occt_k1_catia_debis.stp (a closed CATIA solid, 70 trimmed faces) cut by the plane at
    half its height: no face is kept whole -- one is met at a corner of its loop, and a
    cut found a tolerance from the corner used to leave a sliver of the edge there (the
    face built was refused) -- and every cut face's pieces add up to its area. The
    result is built from the structure (the file's corners wider than the structure's
    tolerance joined, its edges' pcurves as far from their curves as they measure:
    0.014 mm on one seam the file says is within 0.006), closed, with no edge tolerance
    more than 10 % over the one OpenCascade's sewing of the same pieces gives (1.5e-2)."""
    import surfprep
    from surfprep.plugin.occ.shapes import count_free_edges
    model = surfprep.read(data_dir / "occt_k1_catia_debis.stp")
    _, plane = _plane_across(model, 0.5)
    out = split(model, plane, tool=True)
    assert out.valid and all(f.kept is None for f in out.faces)
    assert out.assembled == "structure" and count_free_edges(out.shape) == 0
    # face 21 (a pcurve leaving its pole along the pole's edge) in two, as the Splitter has it
    assert next(len(f.pieces) for f in out.faces if f.index == 21) == 2
    from surfprep.plugin.occ.faces import trimmed_face_to_occ
    from surfprep.plugin.occ.shapes import sew
    sewn, _ = sew([trimmed_face_to_occ(f) for f in out.structure.faces], out.sew_tol)
    assert max_edge_tolerance(out.shape) <= 1.1 * max_edge_tolerance(sewn)
    assert len(out.faces) >= 20
    for f in out.faces:
        whole = face_area(model.faces[f.index], 1e-9)
        assert sum(face_area(p, 1e-9) for p in f.pieces) == pytest.approx(whole, rel=1e-5)


def test_a_ball_resting_on_a_box_touches_it_at_one_point():
    """The ball touches the box's top in its middle -- the point a piece is classified by:
    that face's point is on the ball, its region's other pieces outside it, so it is
    outside too. Fuse = both volumes, common = 0."""
    from surfprep.plugin.split import boolean
    box, ball = cq.Workplane().box(10, 10, 10), cq.Workplane().sphere(5).translate((0, 0, 10))
    fused = boolean(box, ball, "fuse")
    assert fused.valid and fused.volume == pytest.approx(1000 + 4 / 3 * math.pi * 125, rel=1e-6)
    assert boolean(box, ball, "common").volume == pytest.approx(0.0, abs=1e-9)


def test_a_boolean_whose_curves_miss_a_tangential_contact_refuses_rather_than_answers():
    """A cylinder r = 5 through a 10 mm cube touches four of its faces along lines; the
    intersection finds two of them (the two at the cylinder's seam and opposite it, not
    the two between: tangential contact is the intersection's hardest case). The
    circles inscribed in the end faces are cut where they touch the sides and the lines
    split the circles where they end on them, but the box's region then holds pieces
    inside and outside the cylinder: the Boolean says so instead of giving a volume
    (it gave 0 and 1000 for fuse and common)."""
    from surfprep.errors import OpenCascadeError
    from surfprep.plugin.split import boolean
    cylinder = cq.Workplane("YZ").circle(5).extrude(20).translate((-10, 0, 0))
    out = split(cq.Workplane().box(10, 10, 10), cylinder)
    assert all(f.kept is None for f in out.faces)
    assert [len(f.pieces) for f in out.faces if f.operand == "a" and f.cuts == 1][:2] == [5, 5]
    with pytest.raises(OpenCascadeError, match="curve where it crosses or touches the other solid is missing"):
        boolean(cq.Workplane().box(10, 10, 10), cylinder, "common")


def test_booleans_of_n_solids_pairwise():
    """Three boxes fused (each step's result fused with the next; the third touches the
    first over part of a face and overlaps the second): 2200 exactly. A cube minus two
    crossing cylinders r = 2: 1000 - 2 (40 pi) + 16 r^3 / 3 (their Steinmetz common)."""
    from surfprep.errors import InvalidGeometryError
    from surfprep.plugin.split import boolean_all
    boxes = [cq.Workplane().box(10, 10, 10).translate((5 * k, 2 * k, 0)) for k in range(3)]
    fused = boolean_all(boxes, "fuse")
    assert fused.valid and fused.closed and fused.volume == pytest.approx(2200.0, rel=1e-9)
    assert [s["volume"] for s in fused.report()["steps"]] == pytest.approx([1600.0, 2200.0], rel=1e-9)
    cube = cq.Workplane().box(10, 10, 10)
    drilled = boolean_all([cube, _cylinder("YZ", 2.0), _cylinder("XZ", 2.0)], "cut")
    assert drilled.valid and drilled.volume == pytest.approx(1000 - 80 * math.pi + 16 * 8 / 3, rel=1e-6)
    with pytest.raises(InvalidGeometryError, match="at least two"):
        boolean_all([cube], "fuse")
    with pytest.raises(InvalidGeometryError, match="unknown operation"):
        boolean_all([cube, cube], "xor")
