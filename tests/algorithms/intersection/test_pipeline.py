"""intersect_surfaces end to end against exact answers and against OpenCascade's GeomAPI_IntSS.

The operands are B-spline surfaces made by OpenCascade from analytic ones
(``Geom_SphericalSurface`` etc. -> ``surface_from_occ`` with bounds), a free-form
bicubic height field, and face pairs of a real STEP file. Every case checks the
branch count, the exact equations at the samples and at the interpolants'
span midpoints, ``max_deviation`` (three points per span) against ``tol``, the
coverage of the exact curve, and OpenCascade's answer on the same pair.

Branches are counted with :func:`connected_branches` (curves whose ends meet
count as one), because both answers split loops at seams and bifurcations
differently. Where either side misses a branch, the test says so in a comment
(none does on these cases).
"""

from __future__ import annotations

import numpy as np
import OCP  # noqa: F401  (the OpenCascade cross-checks below)
import pytest
from helpers.measure import check_on_surfaces
from helpers.occ_shapes import TAU, cylinder, plane, sphere, torus
from helpers.surfaces import bumpy, flat

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import (
    EndKind,
    SmallAngleWarning,
    StrayCurves,
    StrayCurveWarning,
    closed_in_space,
    connected_branches,
    curve_set_distance,
    hausdorff,
    intersect_surfaces,
    polyline_distance,
)
from surfprep.errors import InvalidGeometryError, InvalidToleranceError
from surfprep.plugin.occ_reference import intersect_surfaces_occ

TOL = 1e-7
#: OpenCascade's curves sampled this densely (chord sag about 1e-8 on a unit circle)
OCC_SAMPLES = 20001


# ---------------------------------------------------------------- checks
def dense_points(curves, per_span: int = 3) -> np.ndarray:
    """Samples and interpolant points between them (quarter, mid, three quarters of each span)."""
    out = []
    for c in curves:
        out.append(c.points)
        out.append(c.curve3d.evaluate(c.span_parameters(per_span).ravel()))
    return np.concatenate(out)


def polylines(curves, per_span: int = 64) -> list[np.ndarray]:
    """Our curves as dense polylines through their cubic interpolants (``per_span`` chords
    per span; closed curves end where they start): what the distances to exact and
    OpenCascade curves are measured to (the samples alone are only as dense as the
    interpolants need)."""
    out = []
    for c in curves:
        t = c.parameters
        s = np.arange(per_span) / per_span
        dense = np.append((t[:-1, None] + s[None, :] * np.diff(t)[:, None]).ravel(), t[-1])
        out.append(c.curve3d.evaluate(dense))
    return out


def check_against_occ(curves, a, b, tol=TOL, expect_branches=None, match=1e-5):
    """Same branches as GeomAPI_IntSS, each side within a small distance of the other.

    Our interpolants lie within tol of the true curve, so OpenCascade's points
    (on the true curve to its own accuracy) must be near dense polylines through
    them and ours near its dense polylines.
    Returns OpenCascade's curves.
    """
    occ = intersect_surfaces_occ(a, b, tol, samples=OCC_SAMPLES)
    if expect_branches is not None:
        assert connected_branches(occ, 1e3 * tol) == expect_branches
    distance = curve_set_distance(polylines(curves), occ)
    assert distance.unmatched_a(match).size == 0, distance.a_to_b     # nothing spurious
    assert distance.unmatched_b(match).size == 0, distance.b_to_a     # nothing missed
    return occ, distance


# ---------------------------------------------------------------- plane x sphere
def test_plane_sphere_circle_through_the_seam():
    a, b = plane(2, origin=(0, 0, 0.3)), sphere(1.0)
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    p = dense_points(curves)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1.0, atol=TOL)
    np.testing.assert_allclose(p[:, 2], 0.3, atol=TOL)
    assert connected_branches(curves, 1e3 * TOL) == 1
    # the circle crosses the sphere's seam: one open curve whose ends meet
    (c,) = curves
    assert not c.closed and closed_in_space(c, TOL)
    assert c.start_kind is EndKind.BOUNDARY and c.end_kind is EndKind.BOUNDARY
    assert c.uv_b[:, 0].min() == pytest.approx(0.0, abs=1e-9)
    assert c.uv_b[:, 0].max() == pytest.approx(TAU, abs=1e-9)
    exact = TAU * np.sqrt(1 - 0.09)
    assert c.length == pytest.approx(exact, rel=1e-6)      # coverage: the whole circle
    occ, distance = check_against_occ(curves, a, b, expect_branches=1)
    assert distance.hausdorff <= 1e-6


def test_plane_sphere_circle_off_the_seam_is_closed():
    a, b = plane(2, origin=(-0.5, 0, 0), normal=(1, 0, 0)), sphere(1.0)
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    (c,) = curves
    assert c.closed and c.start_kind is EndKind.CLOSED
    p = dense_points(curves)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1.0, atol=TOL)
    np.testing.assert_allclose(p[:, 0], -0.5, atol=TOL)
    assert c.length == pytest.approx(TAU * np.sqrt(0.75), rel=1e-6)
    check_against_occ(curves, a, b, expect_branches=1)


def test_curve_ends_on_the_domain_sides():
    """A unit square at z = 0.3 cuts a quarter of the circle; its ends lie on the
    square's sides x = 0 and y = 0 (not a mesh error inside), so it covers the arc."""
    cp = np.array([[[0, 0, 0.3], [0, 1, 0.3]], [[1, 0, 0.3], [1, 1, 0.3]]], float)
    a, b = NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1), sphere(1.0)
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    (c,) = curves
    assert c.start_kind is EndKind.BOUNDARY and c.end_kind is EndKind.BOUNDARY
    ends = c.points[[0, -1]]
    assert np.sort(np.abs(ends[:, :2]).min(axis=1)).max() <= TOL     # x = 0 or y = 0
    r = np.sqrt(0.91)
    assert c.length == pytest.approx(np.pi / 2 * r, rel=1e-6)
    check_against_occ(curves, a, b, expect_branches=1)


# ---------------------------------------------------------------- cylinder x cylinder
def exact_cylinders(r_small: float, n: int = 20001) -> np.ndarray:
    """Both loops of x^2 + y^2 = 1, y^2 + z^2 = r^2: (2, n, 3) samples."""
    t = np.linspace(0, TAU, n)
    y, z = r_small * np.cos(t), r_small * np.sin(t)
    x = np.sqrt(1 - y ** 2)
    return np.stack([np.stack([x, y, z], 1), np.stack([-x, y, z], 1)])


def test_cylinder_cylinder_unequal_radii_two_loops():
    a, b = cylinder(1.0, 1.5), cylinder(0.5, 2.0, normal=(1, 0, 0))
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    p = dense_points(curves)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 1.0, atol=TOL)
    np.testing.assert_allclose(np.hypot(p[:, 1], p[:, 2]), 0.5, atol=TOL)
    assert connected_branches(curves, 1e3 * TOL) == 2
    assert all(closed_in_space(c, TOL) or c.start_kind is EndKind.BOUNDARY for c in curves)
    exact = exact_cylinders(0.5)
    length = np.linalg.norm(np.diff(exact, axis=1), axis=2).sum()
    assert sum(c.length for c in curves) == pytest.approx(length, rel=1e-6)
    assert polyline_distance(exact.reshape(-1, 3), polylines(curves)).max() <= 1e-6     # coverage
    check_against_occ(curves, a, b, expect_branches=2)


def test_cylinder_cylinder_equal_radii_two_ellipses_crossing():
    """x^2 + y^2 = 1 and y^2 + z^2 = 1: the ellipses x = z and x = -z, crossing where the
    cylinders touch, at (0, +-1, 0).

    What we get: the pieces between the two singular points and the seams
    (7 here, like GeomAPI_IntSS), all within tol of both surfaces, covering
    both ellipses within tol, ending exactly at the double points (located and
    joined along their branch directions, :mod:`.branches`), so the pieces do
    not overlap: the total length is the exact one.
    """
    a, b = cylinder(1.0, 1.5), cylinder(1.0, 2.0, normal=(1, 0, 0))
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    p = dense_points(curves)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 1.0, atol=TOL)
    # on the ellipses within tol, the singular points included (within tol of both
    # surfaces alone would allow about sqrt(tol R) there, where they touch)
    np.testing.assert_allclose(np.abs(p[:, 0]), np.abs(p[:, 2]), atol=TOL)
    assert connected_branches(curves, 1e3 * TOL) == 1       # the two ellipses cross
    t = np.linspace(0, TAU, 20001)
    ellipses = np.concatenate([np.stack([np.cos(t), np.sin(t), s * np.cos(t)], 1)
                               for s in (1.0, -1.0)])
    coverage = polyline_distance(ellipses, polylines(curves))
    assert coverage.max() <= 3 * TOL                        # chords of the polylines
    exact_length = 2 * np.linalg.norm(np.diff(ellipses[:20001], axis=0), axis=1).sum()
    total = sum(c.length for c in curves)
    assert total == pytest.approx(exact_length, rel=1e-6)
    ends = np.array([c.points[k] for c in curves for k, kind in ((0, c.start_kind),
                     (-1, c.end_kind)) if kind is EndKind.BIFURCATION])
    assert len(ends) == 8                                   # four at each double point
    np.testing.assert_allclose(np.abs(ends), np.tile([0.0, 1.0, 0.0], (8, 1)), atol=1e-9)
    # OpenCascade splits the same way (7 lines); both answers are near-tangential
    # there, so they agree to about sqrt(tol), not tol
    occ = intersect_surfaces_occ(a, b, TOL, samples=OCC_SAMPLES)
    assert connected_branches(occ, 1e-4) == 1
    assert curve_set_distance(polylines(curves), occ).hausdorff <= 3 * np.sqrt(TOL)


# ---------------------------------------------------------------- sphere x cylinder
def test_sphere_cylinder_viviani_figure_eight():
    """Sphere r = 2 at the origin, cylinder r = 1 around (1, 0, z): Viviani's curve
    ``(1 + cos t, sin t, 2 sin(t / 2))``, double point (2, 0, 0) where they touch."""
    a = sphere(2.0, normal=(0, 1, 0), xdir=(-1, 0, 0))     # poles and seam off the curve
    b = cylinder(1.0, 2.5, origin=(1, 0, 0))
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    p = dense_points(curves)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 2.0, atol=TOL)
    np.testing.assert_allclose(np.hypot(p[:, 0] - 1, p[:, 1]), 1.0, atol=TOL)
    assert connected_branches(curves, 1e3 * TOL) == 1
    t = np.linspace(0, 2 * TAU, 40001)
    viviani = np.stack([1 + np.cos(t), np.sin(t), 2 * np.sin(t / 2)], 1)
    assert polyline_distance(viviani, polylines(curves)).max() <= 1e-5                 # coverage
    exact_length = np.linalg.norm(np.diff(viviani, axis=0), axis=1).sum()
    assert sum(c.length for c in curves) == pytest.approx(exact_length, rel=1e-5)
    check_against_occ(curves, a, b, expect_branches=1)


# ---------------------------------------------------------------- torus x plane
def test_torus_plane_through_the_axis_two_circles():
    a = torus(2.0, 0.5, xdir=(1, 1, 0))                   # u-seam off the cutting plane
    b = plane(3, normal=(0, 1, 0))
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    p = dense_points(curves)
    np.testing.assert_allclose(p[:, 1], 0.0, atol=TOL)
    np.testing.assert_allclose(np.hypot(np.abs(p[:, 0]) - 2, p[:, 2]), 0.5, atol=TOL)
    assert connected_branches(curves, 1e3 * TOL) == 2
    assert sum(c.length for c in curves) == pytest.approx(2 * np.pi, rel=1e-6)
    for side in (1, -1):
        mine = [c for c in curves if np.sign(c.points[0, 0]) == side]
        assert sum(c.length for c in mine) == pytest.approx(np.pi, rel=1e-6)
    check_against_occ(curves, a, b, expect_branches=2)



def test_misaligned_tori_curves_cut_at_seams_do_not_run_past_their_ends():
    """Two tori of 004 Fig. 8 (rational biquadratic, both directions closed): the chains
    cut at B's seam used to keep refined samples beyond the cut, so the curve's end
    point lay behind its last samples and the result was refused as folded."""
    from surfprep.algorithms.volume_builders import solid_torus
    a = solid_torus(3.0, 1.0).exterior_faces()["u1"]
    b = solid_torus(3.0, 1.0, (1.0, 0.5, 0.3), (0.2, 0.1, 1.0)).exterior_faces()["u1"]
    tol = 1e-6
    curves = intersect_surfaces(a, b, tol=tol)
    check_on_surfaces(curves, a, b, tol)
    for c in curves:       # no chord turns back on the one before it
        d = np.diff(c.points, axis=0)
        cos = np.einsum("ij,ij->i", d[:-1], d[1:]) / (
            np.linalg.norm(d[:-1], axis=1) * np.linalg.norm(d[1:], axis=1))
        assert cos.min() > -0.5
    assert connected_branches(curves, 1e3 * tol) == 2
    check_against_occ(curves, a, b, tol=tol, expect_branches=2)


def test_a_plane_through_the_sides_of_a_face_and_across_it():
    """A face whose sides lie in the plane (a solid cut at its plane of symmetry, where
    faces meet along edges lying in it) and which crosses the plane inside: the traced
    curve ran along a side and then across the face and was refused as folded; the
    stretches along the sides now go to the side curves and the crossing is kept."""
    from surfprep.algorithms.fitting import interpolate_surface
    u, v = np.meshgrid(np.linspace(0, 1, 13), np.linspace(0, 1, 9), indexing="ij")
    a = interpolate_surface(np.stack([10 * u, 6 * v, 3 * np.sin(2 * np.pi * u) * np.sin(np.pi * v)],
                                     axis=-1))
    cp = np.zeros((2, 2, 3))
    cp[..., 0], cp[..., 1] = np.meshgrid([-5.0, 15.0], [-5.0, 11.0], indexing="ij")
    cp[..., 2] = -1e-6                                   # a hair below the sides, within tol
    b = NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    tol = 1e-4
    curves = intersect_surfaces(a, b, tol=tol)
    check_on_surfaces(curves, a, b, tol)
    # the crossing: from side v = 0 to side v = 1 in the middle of the face (the sides
    # u = 0, 1 and v = 0, 1 lie in the plane too and come back as side curves)
    inside = [c for c in curves if 0.05 < c.uv_a[:, 0].mean() < 0.95 and np.ptp(c.uv_a[:, 1]) > 0.99]
    assert len(inside) == 1
    np.testing.assert_allclose(inside[0].uv_a[:, 0], 0.5, atol=0.01)

# ---------------------------------------------------------------- free form
def contour_reference(surface: NurbsSurface, level: float, n: int = 1201):
    """Marching-squares contour of z(u, v) = level on an n x n grid, mapped to 3D."""
    import contourpy
    u = np.linspace(0, 1, n)
    z = surface.evaluate(u[:, None], u[None, :])[..., 2]
    lines = contourpy.contour_generator(u, u, z.T).lines(level)
    return [surface.evaluate(uv[:, 0], uv[:, 1]) for uv in lines]


def test_bumpy_bspline_plane_four_loops():
    a, b = bumpy(), flat(0.2)
    curves = intersect_surfaces(a, b, tol=TOL)
    check_on_surfaces(curves, a, b)
    np.testing.assert_allclose(dense_points(curves)[:, 2], 0.2, atol=TOL)
    assert len(curves) == 4 and all(c.closed for c in curves)
    lengths = sorted(c.length for c in curves)
    assert lengths[-1] > 3 * lengths[0]                      # loops of different sizes
    reference = contour_reference(a, 0.2)
    assert len(reference) == 4
    distance = curve_set_distance(polylines(curves), reference)
    assert distance.hausdorff <= 3e-5                        # the grid's own error
    for r, mine in zip(sorted(np.linalg.norm(np.diff(r, axis=0), axis=1).sum()
                              for r in reference), lengths):
        assert mine == pytest.approx(r, rel=1e-4)
    check_against_occ(curves, a, b, expect_branches=4)


def test_small_loop_needs_a_finer_mesh_tolerance():
    """A loop only a few mesh tolerances across may be missed with the default mesh_tol;
    a smaller mesh_tol finds it. Level: 2e-4 below the top of the smallest bump."""
    a = bumpy()
    u = np.linspace(0.7, 0.9, 401)
    top = a.evaluate(u[:, None], u[None, :])[..., 2].max()
    b = flat(top - 2e-4)
    fine = intersect_surfaces(a, b, tol=TOL, mesh_tol=1e-5)
    check_on_surfaces(fine, a, b)
    small = [c for c in fine if np.linalg.norm(c.points.mean(axis=0)[:2] - [0.8, 0.78]) < 0.05]
    assert len(small) == 1 and small[0].closed and small[0].length < 0.05
    # every loop OpenCascade finds, we find; GeomAPI_IntSS (OCP 7.9.3) MISSES the small
    # loop here (about 0.03 long): the only branch of ours it has no counterpart for
    occ = intersect_surfaces_occ(a, b, TOL, samples=OCC_SAMPLES)
    distance = curve_set_distance(polylines(fine), occ)
    assert distance.unmatched_b(1e-5).size == 0
    missed_by_occ = {int(i) for i in distance.unmatched_a(1e-5)}
    assert missed_by_occ == {i for i, c in enumerate(fine) if c is small[0]}   # pinned
    assert len(occ) == len(fine) - 1


# ---------------------------------------------------------------- real file
@pytest.fixture(scope="module")
def debis(data_dir):
    path = data_dir / "occt_k1_catia_debis.stp"
    import surfprep
    from surfprep.plugin.occ.faces import face_to_nurbs
    model = surfprep.read(path)
    return model, [face_to_nurbs(f) for f in model.faces]


def shared_edge_points(model, ia: int, ib: int, n: int = 201):
    """Samples of the edge shared by faces ia and ib, and its tolerance."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from surfprep.plugin.occ.edges import edge_to_nurbs

    def edges(face):
        out, ex = [], TopExp_Explorer(face, TopAbs_EDGE)
        while ex.More():
            out.append(TopoDS.Edge_s(ex.Current()))
            ex.Next()
        return out

    for e in edges(model.faces[ia]):
        if any(e.IsSame(g) for g in edges(model.faces[ib])):
            curve = edge_to_nurbs(e)
            return curve.evaluate(np.linspace(*curve.domain, n)), BRep_Tool.Tolerance_s(e)
    raise AssertionError(f"faces {ia} and {ib} share no edge")


@pytest.mark.parametrize("ia, ib, exact", [
    (18, 22, True),     # perpendicular B-spline faces, straight shared edge on both to 4e-14 mm
    (9, 11, False),     # 27 deg, curved edge; CATIA's edge lies 5e-4 mm off both surfaces
    (45, 47, False),    # 82 deg, curved edge 7e-5 mm off the surfaces
])
def test_real_file_shared_sharp_edge_is_the_intersection(debis, ia, ib, exact):
    model, faces = debis
    a, b = faces[ia].surface, faces[ib].surface
    tol = 1e-6 * model.size
    curves = intersect_surfaces(a, b, tol=tol)
    check_on_surfaces(curves, a, b, tol)
    assert connected_branches(curves, 10 * tol) == 1
    edge, edge_tol = shared_edge_points(model, ia, ib)
    # the stored edge is covered by our curve, within its own tolerance
    assert polyline_distance(edge, polylines(curves)).max() <= (tol if exact else edge_tol + tol)
    # GeomAPI_IntSS (asked for the same tol) agrees to within a few tol
    occ, distance = check_against_occ(curves, a, b, tol, expect_branches=1, match=10 * tol)


# ---------------------------------------------------------------- contract
def test_far_apart_operands_give_nothing():
    assert intersect_surfaces(sphere(1.0), sphere(1.0, origin=(5, 0, 0))) == []


@pytest.mark.parametrize("tol", [0.0, -1e-7, float("nan"), float("inf"), 0.5, 1e-30, "x"])
def test_bad_tol(tol):
    with pytest.raises(InvalidToleranceError):
        intersect_surfaces(plane(2, origin=(0, 0, 0.3)), sphere(1.0), tol=tol)


@pytest.mark.parametrize("mesh_tol", [0.0, float("nan"), 10.0, 1e-9])
def test_bad_mesh_tol(mesh_tol):
    with pytest.raises(InvalidToleranceError):
        intersect_surfaces(plane(2, origin=(0, 0, 0.3)), sphere(1.0), tol=1e-7,
                           mesh_tol=mesh_tol)


def test_bad_operand():
    with pytest.raises(InvalidGeometryError):
        intersect_surfaces(sphere(1.0), np.zeros((3, 3)))


def test_mesh_operand_projects_onto_the_exact_side():
    from surfprep.algorithms.intersection import mesh_segments
    a, b = plane(2, origin=(0, 0, 0.3)), sphere(1.0)
    mesh = mesh_segments(a, b, tol=1e-3).mesh_b                    # a triangulated sphere part
    curves = intersect_surfaces(a, mesh, tol=TOL)
    assert curves and all(c.uv_b is None for c in curves)
    p = np.concatenate([c.points for c in curves])
    np.testing.assert_allclose(p[:, 2], 0.3, atol=TOL)              # on the exact plane
    assert np.abs(np.linalg.norm(p, axis=1) - 1).max() <= 2e-3     # near the mesh sphere


def test_hausdorff_is_symmetric_and_exact():
    x = np.array([[0.0, 0, 0], [1, 0, 0]])
    y = np.array([[0.0, 0, 0], [1, 0, 0], [1, 2, 0]])
    assert hausdorff(x, y) == hausdorff(y, x) == pytest.approx(2.0)
    assert hausdorff(x, x) == 0.0
    assert hausdorff(x, np.zeros((0, 3))) == float("inf")


# ---------------------------------------------------------------- slow: every sharp edge
def sharp_edge_pairs(model, faces, min_angle=20.0):
    """(face i, face j, edge samples, edge tolerance) of every edge shared by two
    different faces whose normals differ by more than min_angle degrees along it."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

    from surfprep.algorithms.projection import project_to_surface
    from surfprep.plugin.occ.edges import edge_to_nurbs
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(model.shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    def face_index(f):
        return next(i for i, g in enumerate(model.faces) if g.IsSame(f))

    out = []
    for k in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(k))
        owners = list(ancestors.FindFromIndex(k))
        if len(owners) != 2 or BRep_Tool.Degenerated_s(edge) or owners[0].IsSame(owners[1]):
            continue
        i, j = face_index(owners[0]), face_index(owners[1])
        curve = edge_to_nurbs(edge)
        samples = curve.evaluate(np.linspace(*curve.domain, 101))
        a, b = faces[i].surface, faces[j].surface
        pa, pb = project_to_surface(a, samples[::10]), project_to_surface(b, samples[::10])
        na = a.normals(pa.uv[:, 0], pa.uv[:, 1])
        nb = b.normals(pb.uv[:, 0], pb.uv[:, 1])
        angle = np.degrees(np.arccos(np.clip(np.abs((na * nb).sum(axis=1)), 0, 1))).min()
        if angle > min_angle:
            out.append((i, j, samples, BRep_Tool.Tolerance_s(edge)))
    return out


@pytest.mark.slow
def test_every_sharp_edge_of_a_real_file(debis):
    """All sharp edges of occt_k1_catia_debis.stp: intersect the two surfaces, the
    stored edge must lie on our curves (within twice its tolerance plus tol), our
    curves within tol of both surfaces, and IntSS must find no branch we miss."""
    model, faces = debis
    tol = 1e-6 * model.size
    pairs = sharp_edge_pairs(model, faces)
    assert len(pairs) > 20
    misses = []
    for i, j, samples, edge_tol in pairs:
        a, b = faces[i].surface, faces[j].surface
        curves = intersect_surfaces(a, b, tol=tol)
        check_on_surfaces(curves, a, b, tol)
        if polyline_distance(samples, polylines(curves)).max() > 2 * edge_tol + tol:
            misses.append((i, j))
            continue
        occ = intersect_surfaces_occ(a, b, tol, samples=4001)
        distance = curve_set_distance(polylines(curves), occ)
        assert distance.unmatched_b(10 * tol).size == 0, (i, j, distance.b_to_a)
    assert not misses, misses


@pytest.mark.slow
def test_stray_curves_of_near_tangential_surfaces_raise_or_are_dropped(debis):
    """Faces 41 and 53 of the debis file meet tangentially: some refined curves do
    not reach tol. By default that raises; with DROP only curves within tol remain."""
    model, faces = debis
    a, b = faces[41].surface, faces[53].surface
    tol = 1e-6 * model.size
    with pytest.raises(InvalidGeometryError, match="stray"), pytest.warns(SmallAngleWarning):
        intersect_surfaces(a, b, tol=tol)
    with pytest.warns(StrayCurveWarning, match="left out"), pytest.warns(SmallAngleWarning):
        kept = intersect_surfaces(a, b, tol=tol, stray=StrayCurves.DROP)
    for c in kept:
        assert c.max_deviation(a, b).max <= tol
