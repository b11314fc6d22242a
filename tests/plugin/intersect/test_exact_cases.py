"""surfprep.intersect on B-spline faces read back from STEP, against exact answers and OpenCascade.

Issue 3's evidence for the hard pairs: a wing-like x fuselage-like pair, two
near-tangential pairs and two grazing (touching) pairs. Each pair is built as
NurbsSurfaces, written to STEP with :func:`surfprep.write`, read back with
:func:`surfprep.read` and intersected as faces with :func:`surfprep.intersect`.

Every case asserts

* the branch count (:func:`connected_branches`: curves whose ends meet are one);
* every output point -- samples and the interpolant at 4 points per span --
  within ``tol`` of both surfaces, measured by OUR projection
  (:func:`surfprep.algorithms.projection.distance_to_surface`);
* coverage of the exact curve: every exact point within ``tol`` of our curves
  (densely evaluated interpolants), and our curves within ``tol`` of the exact
  polyline (a one-sided Hausdorff distance each way);
* OpenCascade's answer on the same pair (``GeomAPI_IntSS`` on the surfaces,
  ``BRepAlgoAPI_Section`` on the faces), with its branch count and distance to
  the exact curve pinned where either side misses something.

Exact curves: the wing is linear in its span parameter between three airfoil
sections and the fuselage is the exact rational cylinder ``y^2 + z^2 = R^2``,
so for every chord parameter ``u`` the crossing is the root of a quadratic;
sphere x plane is a circle; the cylinders ``x^2 + y^2 = 1``, ``y^2 + z^2 = r^2``
meet in ``(+-sqrt(1 - r^2 sin^2 t), r sin t, r cos t)``.

Findings (fixed: a folded or straying result is recomputed with a finer
tessellation, algorithms.intersection.pipeline; were strict xfails):

* near-tangential sphere x plane (plane at ``R (1 - 1e-3)`` from the centre):
  with the default ``mesh_tol`` the loop is lost: up to commit 1e917ff our
  result was ONE closed curve running over about half of the circle twice
  (forward, back), missing the other half (0.065 gap on a 0.045-radius loop);
  since then no curve at all. ``mesh_tol=1e-3`` gives the full circle.
* near-equal cylinders (radii 1 and 0.999): with the default ``mesh_tol`` two
  of the three refined curves break ``tol`` and are dropped: a whole loop is
  missed (GeomAPI_IntSS finds both); ``mesh_tol=1e-3`` finds both loops.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest
from helpers.measure import dense, dense_length, distance_to_curves
from OCP.Geom import Geom_CylindricalSurface, Geom_Plane, Geom_SphericalSurface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt

import surfprep
from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import connected_branches, curve_set_distance
from surfprep.algorithms.projection import distance_to_surface
from surfprep.plugin.intersect import face_operands
from surfprep.plugin.occ.geom import surface_from_occ
from surfprep.plugin.occ_reference import intersect_surfaces_occ, section_faces_occ

TAU = 2 * np.pi
TOL = 1e-7
OCC_SAMPLES = 4001
#: exact curves sampled this densely (chord sag at most about 1e-9 on these loops)
EXACT_SAMPLES = 100001
#: every this many exact points are projected onto our curves
COVER_STRIDE = 25


# ------------------------------------------------------------------ operands
def axes(origin=(0, 0, 0), normal=(0, 0, 1), xdir=None) -> gp_Ax3:
    if xdir is None:
        return gp_Ax3(gp_Pnt(*origin), gp_Dir(*normal))
    return gp_Ax3(gp_Pnt(*origin), gp_Dir(*normal), gp_Dir(*xdir))


def cylinder(r: float, half_length: float, **kw) -> NurbsSurface:
    return surface_from_occ(Geom_CylindricalSurface(axes(**kw), r),
                            (0, TAU, -half_length, half_length))


def sphere(r: float, **kw) -> NurbsSurface:
    return surface_from_occ(Geom_SphericalSurface(axes(**kw), r), (0, TAU, -np.pi / 2, np.pi / 2))


def plane(half_size: float, **kw) -> NurbsSurface:
    s = half_size
    return surface_from_occ(Geom_Plane(axes(**kw)), (-s, s, -s, s))


#: cambered airfoil control polygon (chord 1, leading edge near x = 0), closed at the
#: sharp trailing edge (1, 0): upper side first, then lower
AIRFOIL = np.array([[1, 0], [.7, .06], [.35, .11], [.05, .09], [0, .02], [.02, -.04],
                    [.35, -.045], [.7, -.015], [1, 0]], float)
FUSELAGE_RADIUS = 1.0
SPAN = 3.0


def wing(root=(1.6, 0.1, -0.4), tip=(0.8, 0.35, 0.3)) -> NurbsSurface:
    """Lofted cambered wing through the fuselage: cubic airfoil in u, linear in v
    between the sections at y = -SPAN, 0, +SPAN. ``root``/``tip`` give
    (chord, z offset, x of the leading edge): taper, dihedral and sweep."""
    n = AIRFOIL.shape[0]
    knots_u = np.concatenate([[0] * 3, np.linspace(0, 1, n - 2), [1] * 3])
    cp = np.empty((n, 3, 3))
    for j, (y, (chord, z0, x0)) in enumerate([(-SPAN, tip), (0.0, root), (SPAN, tip)]):
        cp[:, j] = np.stack([x0 + chord * AIRFOIL[:, 0], np.full(n, y),
                             z0 + chord * AIRFOIL[:, 1]], axis=1)
    return NurbsSurface(cp, knots_u, [0, 0, .5, 1, 1], 3, 1)


def fuselage() -> NurbsSurface:
    """Exact rational cylinder y^2 + z^2 = R^2 along x, seam at the bottom (z = -R)."""
    return cylinder(FUSELAGE_RADIUS, 3.0, normal=(1, 0, 0), xdir=(0, 0, -1))


def wing_fuselage_exact(w: NurbsSurface, n: int = EXACT_SAMPLES) -> list[np.ndarray]:
    """The two loops, one per wing half: for each u the wing is the segment
    P0 + s (P1 - P0) (root to tip), so |(P0 + s d)_yz|^2 = R^2 is a quadratic in s."""
    u = np.linspace(0, 1, n)
    loops = []
    for v_tip in (0.0, 1.0):
        p0 = w.evaluate(u, np.full(n, 0.5))
        d = w.evaluate(u, np.full(n, v_tip)) - p0
        a = d[:, 1] ** 2 + d[:, 2] ** 2
        b = 2 * (p0[:, 1] * d[:, 1] + p0[:, 2] * d[:, 2])
        c = p0[:, 1] ** 2 + p0[:, 2] ** 2 - FUSELAGE_RADIUS ** 2
        s = (-b + np.sqrt(b * b - 4 * a * c)) / (2 * a)
        assert np.all((s > 0) & (s < 1))
        loops.append(p0 + s[:, None] * d)
    return loops


NEAR = 1e-3
#: a general direction: the contact point is away from the sphere's seam and poles
DIRECTION = np.array([np.cos(1.0), np.sin(1.0), 0.3]) / np.linalg.norm([np.cos(1.0),
                                                                        np.sin(1.0), 0.3])


def circle_about(direction: np.ndarray, height: float) -> np.ndarray:
    """(EXACT_SAMPLES, 3) closed polyline of the unit sphere's circle at ``height``."""
    t = np.linspace(0, TAU, EXACT_SAMPLES)
    e1 = np.cross(direction, [0, 0, 1])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(direction, e1)
    r = np.sqrt(1 - height ** 2)
    return height * direction + r * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)


def cylinder_loops(r: float) -> list[np.ndarray]:
    t = np.linspace(0, TAU, EXACT_SAMPLES)
    return [np.stack([s * np.sqrt(1 - r * r * np.sin(t) ** 2), r * np.sin(t), r * np.cos(t)], 1)
            for s in (1.0, -1.0)]


def near_tangential_reach(sine: float, tol: float = TOL) -> float:
    """How far from the intersection a point within ``tol`` of two surfaces meeting
    at an angle whose sine is ``sine`` may lie (the coverage bound used there)."""
    return tol / sine


# ------------------------------------------------------------------ pairs
class Pair:
    """Two surfaces written to STEP and read back: the faces, and their surfaces as read."""

    def __init__(self, a: NurbsSurface, b: NurbsSurface, folder, name: str):
        paths = [surfprep.write(s, folder / f"{name}_{k}.step") for k, s in (("a", a), ("b", b))]
        self.face_a, self.face_b = (surfprep.read(p).faces[0] for p in paths)
        self.a, self.b = (face_operands(f)[0].surface for f in (self.face_a, self.face_b))
        self._ours: dict = {}
        self.times: dict = {}

    def ours(self, tol: float = TOL, **kw):
        """Our curves (computed once per set of arguments; ``times`` keeps the seconds)."""
        key = (tol, *sorted(kw.items()))
        if key not in self._ours:
            start = time.perf_counter()
            result = surfprep.intersect(self.face_a, self.face_b, tol=tol, **kw)
            self.times[key] = time.perf_counter() - start
            self._ours[key] = [r.curve for r in result]
        return self._ours[key]

    def intss(self, tol: float = TOL):
        return intersect_surfaces_occ(self.a, self.b, tol, samples=OCC_SAMPLES)

    def section(self, tol: float = TOL):
        return section_faces_occ(self.face_a, self.face_b, tol, samples=OCC_SAMPLES)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("ssi_exact")


def check_on_both(curves, a: NurbsSurface, b: NurbsSurface, tol: float = TOL) -> float:
    """Samples and the interpolant at a third and two thirds of every span within tol
    of both surfaces, measured by our projection; returns the largest distance."""
    assert curves, "no curve found"
    pts = np.concatenate(dense(curves, 3))
    worst = max(distance_to_surface(a, pts).max(), distance_to_surface(b, pts).max())
    assert worst <= tol, worst
    return float(worst)


def coverage(curves, exact: list[np.ndarray]) -> tuple[np.ndarray, float]:
    """One-sided distances between our curves and the exact ones.

    Returns ``(to_ours, to_exact)``: per exact branch, the largest distance of
    its points (every ``COVER_STRIDE``-th) to our nearest interpolant, by our
    closest-point projection (exact, whatever the samples' spacing); and the
    largest distance of our interpolants (3 points per span) to the exact
    polylines (sampled densely enough that their sag is far below tol).

    Where the surfaces meet at a small angle ``a``, a point within tol of both
    lies up to about ``tol / sin(a)`` from their intersection, so the
    near-tangential cases allow that much (:func:`near_tangential_reach`).
    OpenCascade's curves (``OccCurve``, sampled) are measured as polylines.
    """
    if curves and hasattr(curves[0], "curve3d"):
        to_ours = np.array([distance_to_curves(curves, e[::COVER_STRIDE], 1e-3 * TOL).max()
                            for e in exact])
        ours = dense(curves, 3)
    else:
        to_ours = curve_set_distance(exact, curves).a_to_b
        ours = curves
    to_exact = curve_set_distance(ours, exact).a_to_b
    return to_ours, float(to_exact.max()) if to_exact.size else 0.0


# ------------------------------------------------------------------ wing x fuselage
@pytest.fixture(scope="module")
def wing_fuselage(folder):
    w = wing()
    return Pair(w, fuselage(), folder, "wing_fuselage"), wing_fuselage_exact(w)


def test_wing_through_fuselage_two_loops(wing_fuselage):
    """Two loops (left and right wing roots), each with the trailing-edge corner
    where the airfoil closes: on both surfaces, covering the exact curves."""
    pair, exact = wing_fuselage
    curves = pair.ours()
    assert connected_branches(curves, 1e3 * TOL) == 2
    check_on_both(curves, pair.a, pair.b)
    to_ours, to_exact = coverage(curves, exact)
    assert to_ours.max() <= TOL, to_ours
    assert to_exact <= TOL, to_exact
    # on the fuselage exactly: y^2 + z^2 = R^2 at every sample
    p = np.concatenate([c.points for c in curves])
    np.testing.assert_allclose(np.hypot(p[:, 1], p[:, 2]), FUSELAGE_RADIUS, atol=TOL)


def test_wing_through_fuselage_opencascade(wing_fuselage):
    """Both OpenCascade answers find the two loops, less accurately than asked:
    IntSS's approximated curves lie about 1.6e-6 (16 tol) off the exact curve, and
    the Section leaves a stretch of about 1.8e-3 of one loop uncovered. Ours is
    nearer the exact curve than either."""
    pair, exact = wing_fuselage
    ours_far = max(np.max(d) for d in coverage(pair.ours(), exact))
    intss, section = pair.intss(), pair.section()
    assert connected_branches(intss, 1e3 * TOL) == 2
    assert connected_branches(section, 1e3 * TOL) == 2
    intss_far = max(np.max(d) for d in coverage(intss, exact))
    section_gap = coverage(section, exact)[0].max()
    assert intss_far > 10 * TOL            # pinned: IntSS misses the asked accuracy
    assert section_gap > 1e3 * TOL         # pinned: the Section misses part of a loop
    assert ours_far < intss_far and ours_far < section_gap


# ------------------------------------------------------------------ near-tangential
@pytest.fixture(scope="module")
def sphere_plane_near(folder):
    h = 1 - NEAR
    pair = Pair(sphere(1.0), plane(1.5, origin=tuple(h * DIRECTION), normal=tuple(DIRECTION)),
                folder, "sphere_plane_near")
    return pair, [circle_about(DIRECTION, h)]


def test_near_tangential_sphere_plane_default_mesh(sphere_plane_near):
    """With the default mesh_tol the triangle method traced one 'closed' curve over
    half the circle and back (a fold); it now recomputes folded or straying results
    with a finer tessellation: one branch, covering the circle, as with mesh_tol=1e-3."""
    pair, exact = sphere_plane_near
    curves = pair.ours()
    assert connected_branches(curves, 1e3 * TOL) == 1
    check_on_both(curves, pair.a, pair.b)
    to_ours, to_exact = coverage(curves, exact)
    reach = near_tangential_reach(np.sqrt(1 - (1 - NEAR) ** 2))      # 2.2e-6
    assert to_ours.max() <= reach and to_exact <= reach, (to_ours, to_exact)


def test_near_tangential_sphere_plane_fine_mesh(sphere_plane_near):
    """The small loop (radius 0.045, surfaces 2.6 degrees apart along it) with
    mesh_tol=1e-3: one closed branch, on both surfaces, covering the circle;
    IntSS finds it too (closer than 1e-6 both ways). Coverage is measured to
    ``tol / sin(angle)`` (2.2e-6; :func:`near_tangential_reach`).

    (Was a strict xfail, "9.5e-5 uncovered next to the first sample": a
    measuring fault, not the curve's -- the projection onto a closed curve was
    seeded at the domain end on the wrong side of the closure and stopped there;
    ssi_measure.distance_to_curves now tries both ends. Brute force: 1.4e-7.)"""
    pair, exact = sphere_plane_near
    curves = pair.ours(mesh_tol=1e-3)
    assert connected_branches(curves, 1e3 * TOL) == 1
    check_on_both(curves, pair.a, pair.b)
    to_ours, to_exact = coverage(curves, exact)
    reach = near_tangential_reach(np.sqrt(1 - (1 - NEAR) ** 2))      # 2.2e-6
    assert to_ours.max() <= reach and to_exact <= reach, (to_ours, to_exact)
    intss = pair.intss()
    assert connected_branches(intss, 1e3 * TOL) == 1
    assert max(np.max(d) for d in coverage(intss, exact)) <= 1e-6
    assert dense_length(curves) == pytest.approx(TAU * np.sqrt(1 - (1 - NEAR) ** 2),
                                                          rel=1e-6)


@pytest.fixture(scope="module")
def near_equal_cylinders(folder):
    r = 1 - NEAR
    pair = Pair(cylinder(1.0, 2.0), cylinder(r, 2.0, normal=(1, 0, 0)), folder, "cylinders_near")
    return pair, cylinder_loops(r)


@pytest.mark.slow
def test_near_equal_cylinders_default_mesh(near_equal_cylinders):
    """With the default mesh_tol 2 of 3 refined curves strayed beyond tol and were
    dropped (a whole loop missed; GeomAPI_IntSS finds both). A straying result is
    now recomputed with a finer tessellation: both loops, on both surfaces,
    covering the exact ones to tol / sin(angle)."""
    pair, exact = near_equal_cylinders
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        curves = pair.ours()
    assert connected_branches(curves, 1e3 * TOL) == 2
    check_on_both(curves, pair.a, pair.b)
    to_ours, to_exact = coverage(curves, exact)
    reach = near_tangential_reach(np.sqrt(1 - (1 - NEAR) ** 2))      # 2.2e-6
    assert to_ours.max() <= reach and to_exact <= reach, (to_ours, to_exact)


@pytest.mark.slow
def test_near_equal_cylinders_fine_mesh(near_equal_cylinders):
    """Two loops passing 0.089 apart where the surfaces are 2.6 degrees apart
    (near the equal-radii bifurcation): both found with mesh_tol=1e-3, on both
    surfaces, covering the exact loops; IntSS finds both too, but covers them
    only to about 1e-5 (100 tol)."""
    pair, exact = near_equal_cylinders
    curves = pair.ours(mesh_tol=1e-3)
    assert connected_branches(curves, 1e3 * TOL) == 2
    check_on_both(curves, pair.a, pair.b)
    to_ours, to_exact = coverage(curves, exact)
    reach = near_tangential_reach(np.sqrt(1 - (1 - NEAR) ** 2))      # 2.2e-6
    assert to_ours.max() <= reach and to_exact <= reach, (to_ours, to_exact)
    intss = pair.intss()
    assert connected_branches(intss, 1e3 * TOL) == 2
    intss_gap = coverage(intss, exact)[0].max()
    assert 10 * TOL < intss_gap < 1e-4          # pinned: IntSS's coverage, 100 x coarser
    assert connected_branches(pair.section(), 1e3 * TOL) == 2


# ------------------------------------------------------------------ grazing
@pytest.fixture(scope="module")
def sphere_touching_plane(folder):
    return Pair(sphere(1.0), plane(1.5, origin=tuple(DIRECTION), normal=tuple(DIRECTION)),
                folder, "sphere_touch")


def test_sphere_touching_plane_at_one_point(sphere_touching_plane):
    """A plane tangent to the sphere: the intersection is one point. Ours returns
    nothing (or only curves at the point); IntSS returns nothing; the Section
    returns a tiny edge (about 1e-3 long) at the contact point."""
    pair = sphere_touching_plane
    curves = pair.ours()
    for c in curves:
        assert np.linalg.norm(c.points - DIRECTION, axis=1).max() <= 1e-3
    if curves:
        check_on_both(curves, pair.a, pair.b)
    assert pair.intss() == []
    section = pair.section()
    assert len(section) == 1 and section[0].length < 2e-3                 # pinned
    assert np.linalg.norm(section[0].points - DIRECTION, axis=1).max() <= 1e-3


@pytest.fixture(scope="module")
def cylinder_touching_plane(folder):
    return Pair(cylinder(1.0, 2.0, normal=(1, 0, 0)), plane(2.5, origin=(0, 0, 1)), folder,
                "cylinder_touch")


def test_cylinder_touching_plane_along_a_line(cylinder_touching_plane):
    """A plane tangent to a cylinder along the line y = 0, z = 1, |x| <= 2. Ours finds
    the whole line, on both surfaces; IntSS misses it (no line); the Section finds it."""
    pair = cylinder_touching_plane
    x = np.linspace(-2, 2, EXACT_SAMPLES)
    exact = [np.stack([x, np.zeros_like(x), np.ones_like(x)], axis=1)]
    curves = pair.ours()
    assert connected_branches(curves, 1e3 * TOL) == 1
    check_on_both(curves, pair.a, pair.b)
    to_ours, to_exact = coverage(curves, exact)
    # tangent along the whole line: no angle to amplify the error, TOL holds as it is
    assert to_ours.max() <= TOL and to_exact <= TOL, (to_ours, to_exact)
    assert pair.intss() == []                                           # pinned: IntSS misses it
    section = pair.section()
    assert connected_branches(section, 1e3 * TOL) == 1
    assert max(np.max(d) for d in coverage(section, exact)) <= TOL
