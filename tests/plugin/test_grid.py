"""surfprep.grid on models, faces and surfaces: blocks, orientation, refusals, files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.grid_cases import warped_plane
from helpers.paths import SAMPLES

import surfprep
from surfprep.algorithms.grid.io import read_plot3d, side_nodes
from surfprep.errors import InvalidGeometryError, OutputFileError

FUSELAGE = SAMPLES / "occt_fuselage.stp"
CATIA_FACE = SAMPLES / "occt_catia4_face_L1.igs"


def _assert_point_matched(result):
    """Every shared edge of the network: the two blocks' nodes along it are the same."""
    for f in result.network.interfaces:
        a = side_nodes(result.blocks[f.block], f.side)
        b = side_nodes(result.blocks[f.other], f.other_side)
        assert np.array_equal(a[::-1] if f.reversed else a, b)


def _cells_area(block):
    """Area of a block's cells (two triangles' worth each, by the diagonals)."""
    d1, d2 = block[1:, 1:] - block[:-1, :-1], block[:-1, 1:] - block[1:, :-1]
    return 0.5 * np.linalg.norm(np.cross(d1, d2), axis=-1).sum()


@pytest.fixture(scope="module")
def fuselage():
    return surfprep.grid(FUSELAGE, size=1500.0)


def test_every_face_of_the_fuselage_is_a_point_matched_block(fuselage):
    model = surfprep.read(FUSELAGE)
    assert fuselage.faces == tuple(range(model.n_faces)) and not fuselage.skipped
    assert len(fuselage.network.interfaces) == 14
    _assert_point_matched(fuselage)
    # the faces are sewn: the nodes moved onto a neighbour's side by a rounding only
    assert fuselage.network.snap < 1e-6 * model.size
    worst = fuselage.report()["worst"]
    assert worst["folded_cells"] == 0 and worst["max_skewness"] < 0.5


def test_blocks_follow_the_faces_outward_normals(fuselage):
    model = surfprep.read(FUSELAGE)
    for k, block in zip(fuselage.faces, fuselage.blocks, strict=True):
        face = surfprep.to_nurbs(model.faces[k])
        mid = tuple(n // 2 for n in block.shape[:2])
        x = block
        cross = np.cross(x[mid[0] + 1, mid[1]] - x[mid[0] - 1, mid[1]],
                         x[mid[0], mid[1] + 1] - x[mid[0], mid[1] - 1])
        uv = fuselage.network.blocks[fuselage.faces.index(k)].parameters[mid]
        if face.reversed:                                  # the block's surface is v-reversed
            v0, v1 = face.surface.domain[2:]
            uv = (uv[0], v0 + v1 - uv[1])
        normal = face.surface.normals(uv[0], uv[1]) * (-1 if face.reversed else 1)
        assert np.dot(cross, normal) > 0


def test_a_trimmed_face_is_refused_with_its_reason_or_gridded_whole():
    # 47 edges round a very non-convex outline: not split into four-sided blocks
    with pytest.raises(InvalidGeometryError, match="centre of the split lies outside the face"):
        surfprep.grid(CATIA_FACE)
    result = surfprep.grid(CATIA_FACE, whole_surfaces=True, dims=(61, 41))
    block = result.network.blocks[0]
    assert block.dims == (61, 41)
    # the surface's parameters are awful (its Bezier patches run at speeds ~2700x apart: blended
    # in them, the start grid's worst cell had skewness 0.997); blended in its knots re-spaced
    # at the C0 joins, the start is already fair
    assert block.start_quality.max_skewness < 0.3 and block.start_quality.folded_cells == 0
    assert block.quality.max_skewness < 0.3 and block.quality.folded_cells == 0


def test_surfaces_and_lists_of_surfaces():
    one = surfprep.grid(warped_plane(), dims=(9, 7))
    assert one.faces == (0,) and one.blocks[0].shape == (9, 7, 3)
    a, b = warped_plane().split(0.5, "u")
    two = surfprep.grid([a, b], size=0.1)
    assert len(two.network.interfaces) == 1


def test_bad_face_indices_and_arguments():
    with pytest.raises(InvalidGeometryError, match="out of range"):
        surfprep.grid(FUSELAGE, faces=[99])
    with pytest.raises(InvalidGeometryError, match="gap"):
        surfprep.grid(FUSELAGE, gap=-1.0)


@pytest.mark.parametrize("name, reader", [("g.xyz", "plot3d"), ("g.x", "plot3d-binary"),
                                          ("g.cgns", "cgns"), ("g.vtm", "vtm")])
def test_written_files_hold_the_blocks(tmp_path, fuselage, name, reader):
    path = fuselage.write(tmp_path / name, binary=reader == "plot3d-binary")
    assert path.exists()
    if reader.startswith("plot3d"):
        blocks = read_plot3d(path)
        assert len(blocks) == len(fuselage.blocks)
        for got, want in zip(blocks, fuselage.blocks, strict=True):
            np.testing.assert_array_equal(got, want)
    elif reader == "cgns":
        from vtkmodules.vtkIOCGNSReader import vtkCGNSReader
        r = vtkCGNSReader()
        r.SetFileName(str(path))
        r.Update()
        base = r.GetOutput().GetBlock(0)
        assert base.GetNumberOfBlocks() == len(fuselage.blocks)
    else:
        assert len(list((tmp_path / "g_blocks").glob("*.vts"))) == len(fuselage.blocks)


def test_a_single_block_format_refuses_many_blocks(tmp_path, fuselage):
    with pytest.raises(OutputFileError, match="one block"):
        fuselage.write(tmp_path / "g.vts")
    with pytest.raises(OutputFileError, match="unknown extension"):
        fuselage.write(tmp_path / "g.step")
    assert not list(tmp_path.iterdir())


def test_report_is_plain_json(fuselage):
    report = fuselage.report()
    json.dumps(report, allow_nan=False)
    assert {b["face"] for b in report["blocks"]} == set(fuselage.faces)
    assert all("residuals" in b["elliptic"] for b in report["blocks"])


def test_trimmed_four_sided_faces_of_a_real_model(data_dir):
    """occt_k1_catia_debis.stp: every face is trimmed inside its surface; those bounded by
    one loop of four edges are gridded on that loop, those of one loop of other numbers
    of edges as blocks around a centre (where the split fits), point-matched, without a
    fold."""
    model = surfprep.read(data_dir / "occt_k1_catia_debis.stp")
    result = surfprep.grid(model)
    loops = [surfprep.to_nurbs(f).loops for f in model.faces]
    four = [k for k, lp in enumerate(loops) if len(lp) == 1 and len(lp[0].edges) == 4]
    assert set(four) <= set(result.faces) and len(four) >= 40
    others = set(result.faces) - set(four)
    assert others and all(len(loops[k]) in (1, 2) for k in others)       # one hole at most
    assert all("not split" in reason or "hole" in reason or "corner(s)" in reason
               for _, reason in result.skipped)
    report = result.report()
    assert report["worst"]["folded_cells"] == 0
    # four-sided faces: good cells; the split ones fair (three-sided faces of this part
    # come out with cells of 140-166 degrees in one block, a face with a hole near its
    # rim with skewness 0.93; no fold anywhere)
    skew = [b["quality"]["max_skewness"] for b in report["blocks"]]
    # (0.50 before faces were cut at T-junctions: a slanted cut leaves a piece at 0.52)
    assert max(q for q, k in zip(skew, result.faces) if k in four) < 0.55
    assert max(q for q, k in zip(skew, result.faces) if k in others) < 0.95
    # cut where a block's corner lies inside another's side, the faces meet node for node
    # along 701 shared edges (180 before: most of the split faces' sides met their
    # neighbours at T-junctions); 26 corners are left when the cuts stop
    assert result.network.cuts > 100 and len(result.network.interfaces) >= 600
    assert result.network.t_junctions_left <= 30
    _assert_point_matched(result)
    # the blocks lie on their faces: every node within the model's tolerance of the face's surface
    from surfprep.algorithms.projection import distance_to_surface
    for k, block in zip(result.faces, result.blocks, strict=True):
        surface = surfprep.to_nurbs(model.faces[k]).surface
        assert distance_to_surface(surface, block.reshape(-1, 3)).max() < 1e-2


def _loop_face(case):
    """A TrimmedFace on a wavy bicubic patch bounded by ``case``'s loop, read back from
    OpenCascade."""
    from helpers.heal_cases import wavy_surface

    from surfprep.algorithms.trimmed import TrimEdge, TrimLoop
    from surfprep.plugin.occ.faces import face_to_nurbs, make_face
    surface = wavy_surface()
    loop = TrimLoop([TrimEdge(e.curve, e.pcurve, 0.0, 1.0) for e in case(surface)])
    return face_to_nurbs(make_face(surface, [loop]))


@pytest.mark.parametrize(("case", "n", "min_angle"), [("triangle", 3, 55.0),
                                                       ("pentagon", 5, 65.0)])
def test_a_face_of_n_sides_is_gridded_as_n_blocks_around_a_centre(case, n, min_angle):
    from helpers import heal_cases

    from surfprep.algorithms.face_region import FaceRegion
    from surfprep.algorithms.projection import project_to_surface
    face = _loop_face(getattr(heal_cases, case))
    result = surfprep.grid(face, size=0.04)
    assert len(result.blocks) == n and result.faces == (0,) * n and not result.skipped
    # the blocks share their spokes node for node
    assert len(result.network.interfaces) == n
    _assert_point_matched(result)
    worst = result.report()["worst"]
    assert worst["folded_cells"] == 0 and worst["min_angle"] > min_angle
    # the shared edges slid without crowding the cells at the centre, where n blocks meet
    # (the Winslow stencil across an edge pulled its nodes there: growth 2.11 for the triangle)
    assert worst["max_growth_ratio"] < 1.25
    # every node on the face: on its surface and inside its loop
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    foot = project_to_surface(face.surface, nodes)
    assert foot.distance.max() < 1e-9
    assert FaceRegion(face).contains(foot.uv, 1e-9).all()
    # together they cover the face: area of the cells against the face's area
    from surfprep.plugin.occ.faces import make_face
    from surfprep.plugin.occ.shapes import face_area
    exact = face_area(make_face(face.surface, face.loops))
    assert sum(_cells_area(b) for b in result.blocks) == pytest.approx(exact, rel=2e-3)


def test_a_disc_is_gridded_as_a_butterfly_not_with_180_degree_corners():
    """A face bounded by one circle: an inner quad and four around it (its O-grid as an
    H-grid), point-matched on all eight shared sides; one block on four split points
    of the circle (what healing's single patch is) had corners of 180 degrees and
    cells of 6.6 degrees (skewness 0.93)."""
    from helpers import heal_cases

    from surfprep.algorithms.projection import project_to_surface
    face = _loop_face(heal_cases.disc)
    result = surfprep.grid(face, size=0.04)
    assert len(result.blocks) == 5 and len(result.network.interfaces) == 8
    _assert_point_matched(result)
    worst = result.report()["worst"]
    assert worst["folded_cells"] == 0 and worst["min_angle"] > 40 and worst["max_skewness"] < 0.6
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    assert project_to_surface(face.surface, nodes).distance.max() < 1e-9
    # four corners made of six edges (two pairs continuing each other) stay one block
    result = surfprep.grid(_loop_face(heal_cases.six_edges_two_smooth), size=0.04)
    assert len(result.blocks) == 1 and result.report()["worst"]["folded_cells"] == 0


def test_a_face_with_a_hole_is_gridded_as_four_blocks_round_it():
    """The plane trimmed to a square with a disc hole: the O-grid round the hole in four
    blocks, spokes from the square's corners to the hole (45 degrees at the corners, which
    the spokes bisect), every node on the face and outside the hole."""
    from helpers.heal_cases import HOLE_CENTRE, HOLE_RADIUS, plane_with_hole
    result = surfprep.grid(plane_with_hole(), size=0.04)
    assert len(result.blocks) == 4 and len(result.network.interfaces) == 4
    _assert_point_matched(result)
    worst = result.report()["worst"]
    assert worst["folded_cells"] == 0 and worst["min_angle"] > 44.9 and worst["max_skewness"] < 0.51
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    assert np.abs(nodes[:, 2]).max() < 1e-12
    r = np.linalg.norm(nodes[:, :2] - HOLE_CENTRE, axis=1)
    assert r.min() > HOLE_RADIUS * (1 - 1e-9)
    assert np.all((nodes[:, :2] > 0.1 - 1e-9) & (nodes[:, :2] < 0.9 + 1e-9))
    # cells add up to the square less the disc
    assert sum(_cells_area(b) for b in result.blocks) == pytest.approx(0.64 - np.pi * 0.09, rel=2e-3)


def test_the_blocks_of_one_face_get_zone_names_of_their_own(tmp_path):
    """A face gridded as four blocks round its hole: CGNS zones Face0_0 .. Face0_3 (one name
    for all four was refused by the writer, and the whole file with it)."""
    import h5py
    from helpers.heal_cases import plane_with_hole
    result = surfprep.grid(plane_with_hole(), size=0.04)
    assert result.faces == (0, 0, 0, 0)
    path = result.write(tmp_path / "hole.cgns")
    with h5py.File(path, "r") as f:
        (base,) = [k for k in f if k not in (" format", " hdf5version", "CGNSLibraryVersion")]
        zones = sorted(k for k in f[base] if f[base][k].attrs.get("label", b"").startswith(b"Zone_t"))
    assert zones == ["Face0_0", "Face0_1", "Face0_2", "Face0_3"]


def test_a_hexagon_with_a_hole_is_gridded_as_six_blocks_round_it():
    """One block per outer corner: six, spokes from the corners to the hole, every cell
    unfolded and the cells adding up to the hexagon less the disc."""
    from helpers.heal_cases import HOLE_CENTRE, HOLE_RADIUS, plane_with_hole
    angles = np.radians(60.0 * np.arange(6))
    hexagon = [tuple(HOLE_CENTRE + 0.45 * np.array([np.cos(a), np.sin(a)])) for a in angles]
    result = surfprep.grid(plane_with_hole(hexagon), size=0.04)
    assert len(result.blocks) == 6 and len(result.network.interfaces) == 6
    _assert_point_matched(result)
    assert result.report()["worst"]["folded_cells"] == 0
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    assert np.linalg.norm(nodes[:, :2] - HOLE_CENTRE, axis=1).min() > HOLE_RADIUS * (1 - 1e-9)
    exact = 1.5 * np.sqrt(3) * 0.45 ** 2 - np.pi * HOLE_RADIUS ** 2
    assert sum(_cells_area(b) for b in result.blocks) == pytest.approx(exact, rel=2e-3)


def test_a_spoke_through_a_collapsed_point_is_a_reason_not_a_crash(data_dir):
    """occt_turbine_euclid.stp face 1 has a hole round a point where its surface collapses:
    the spokes of the four blocks round the hole run through it (their points coincide
    in space). Found by splitting every face of the real files: the grid of the whole
    model raised; now that face is named with the reason and the others are gridded."""
    from surfprep.algorithms.grid.faces import face_regions
    model = surfprep.read(data_dir / "occt_turbine_euclid.stp")
    reasons = {}
    for k, f in enumerate(model.faces):
        regions = face_regions(surfprep.to_nurbs(f), gap_tol=1e-4 * model.size)
        if isinstance(regions, str):
            reasons[k] = regions
    assert "surface collapses" in reasons[1]


def test_a_sphere_is_gridded_as_two_blocks_round_its_poles():
    """A sphere's rectangle runs from pole to pole (both of its sides along u collapse: no
    block can have two): it is split at its longest parallel, the equator, into two blocks
    round one pole each, sharing the equator and each its seam; every node on the sphere."""
    from helpers.occ_shapes import sphere

    from surfprep.algorithms.grid.faces import pole_halves
    ball = sphere(5.0)
    low, high = pole_halves(ball)
    assert low.domain[3] == pytest.approx(0.0, abs=1e-12) == high.domain[2]   # at the equator
    result = surfprep.grid(ball, size=0.5)
    assert len(result.blocks) == 2 and len(result.network.interfaces) == 3
    _assert_point_matched(result)
    assert {(f.block, f.other) for f in result.network.interfaces} == {(0, 0), (1, 1), (0, 1)}
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    assert np.abs(np.linalg.norm(nodes, axis=1) - 5.0).max() < 1e-9
    assert result.report()["worst"]["folded_cells"] == 0
    # the two blocks cover the sphere: their cells add up to its area
    assert sum(_cells_area(b) for b in result.blocks) == pytest.approx(4 * np.pi * 25, rel=5e-3)


def test_a_surface_with_one_pole_stays_one_block():
    from helpers.grid_cases import pole_patch

    from surfprep.algorithms.grid.faces import pole_halves
    patch = pole_patch()
    assert pole_halves(patch) == [patch]


def test_a_capsule_with_h_type_caps_is_cut_to_meet_them(tmp_path):
    """A cylinder between two hemispheres: with pole_caps="h" each cap's rim is split in
    four by its butterfly, and the cylinder is cut where those corners lie on its ends
    (T-junctions), so every shared edge is matched node for node and no cell touches a
    pole; with the default O-type caps the three faces are three blocks."""
    import cadquery as cq
    path = tmp_path / "capsule.step"
    solid = (cq.Workplane().cylinder(4, 1).union(cq.Workplane().sphere(1).translate((0, 0, 2)))
             .union(cq.Workplane().sphere(1).translate((0, 0, -2))).clean())
    surfprep.write(solid.val(), path)
    plain = surfprep.grid(path, size=0.2)
    assert len(plain.blocks) == 3 and plain.network.cuts == 0
    result = surfprep.grid(path, size=0.2, pole_caps="h")
    net = result.network
    assert net.cuts > 0 and net.t_junctions_left == 0 and not result.skipped
    assert all(not b.collapsed_sides for b in net.blocks)
    _assert_point_matched(result)
    # every block side lies on another block's side or nowhere: all sides shared (a closed solid)
    shared = {(f.block, f.side) for f in net.interfaces} | {(f.other, f.other_side) for f in net.interfaces}
    assert len(shared) == 4 * len(net.blocks)
    worst = result.report()["worst"]
    assert worst["folded_cells"] == 0 and worst["max_skewness"] < 0.4
    area = sum(_cells_area(b) for b in result.blocks)
    assert area == pytest.approx(4 * np.pi + 2 * np.pi * 4, rel=5e-3)
