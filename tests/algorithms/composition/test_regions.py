"""Volumes and boundaries of the regions of two composed solids, against exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from surfprep.algorithms.composition import compose
from surfprep.algorithms.composition.regions import (
    BoundaryPiece,
    RegionVolumes,
    boundary_pieces,
    face_integral,
    region_volumes,
)
from surfprep.algorithms.face_region import inside_loops
from surfprep.algorithms.surface import NurbsSurface
from surfprep.algorithms.trimmed import TrimmedFace, loop_uv
from surfprep.algorithms.volume_builders import block, revolve, solid_sphere, solid_torus
from surfprep.errors import InvalidGeometryError

R, D = 5.0, 6.0
LENS = math.pi * (4 * R + D) * (2 * R - D) ** 2 / 12        # common part of the two balls
BALL = 4 / 3 * math.pi * R ** 3
CAP = 2 * math.pi * R * (R - D / 2)                           # area of each spherical cap
#: the volumes come out within ~1e-13 (pcurves corrected onto the true intersection);
#: a missing piece or a wrong orientation changes them by percents
VOLUME_RTOL = 1e-8
#: the pieces are bounded by the pcurves themselves (within the curves' tolerance)
PIECE_RTOL = 1e-6


def cylinder(radius: float, axis_xy: tuple[float, float], z0: float, z1: float):
    """A solid cylinder about the vertical line through ``axis_xy``: a rectangle revolved."""
    rectangle = NurbsSurface(np.array([[[0, 0, z0], [radius, 0, z0]], [[0, 0, z1], [radius, 0, z1]]],
                                      float), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    return revolve(rectangle, (0, 0, 0), (0, 0, 1)).translated([axis_xy[0], axis_xy[1], 0.0])


@pytest.fixture(scope="module")
def balls():
    return compose(solid_sphere(R, (0, 0, 0)), solid_sphere(R, (D, 0, 0)))


@pytest.fixture(scope="module")
def cylinder_through_block():
    return compose(block(10.0), cylinder(2.0, (5.0, 5.0), -5.0, 15.0))


def test_two_balls_give_the_lens_and_the_union(balls):
    v = region_volumes(balls)
    assert isinstance(v, RegionVolumes)
    assert v.both == pytest.approx(LENS, rel=VOLUME_RTOL)
    assert v.a_only == pytest.approx(BALL - LENS, rel=VOLUME_RTOL)
    assert v.b_only == pytest.approx(BALL - LENS, rel=VOLUME_RTOL)
    assert v.union == pytest.approx(2 * BALL - LENS, rel=VOLUME_RTOL)
    assert v.as_dict() == {"A only": v.a_only, "B only": v.b_only, "both": v.both, "union": v.union}
    assert balls.volume("common") == pytest.approx(LENS, rel=VOLUME_RTOL)
    assert balls.volume("A-B") == balls.volume("A only") == pytest.approx(BALL - LENS, rel=VOLUME_RTOL)
    assert balls.volume("union") == pytest.approx(2 * BALL - LENS, rel=VOLUME_RTOL)
    assert balls.volume("B") == pytest.approx(BALL, rel=1e-12)


def test_a_ball_inside_a_block_and_two_disjoint_balls():
    inside = compose(block(10.0, origin=(-5, -5, -5)), solid_sphere(2.0, (1, 1, 1)))
    assert inside.curves == ()
    ball = 4 / 3 * math.pi * 8
    v = region_volumes(inside)
    assert v.both == pytest.approx(ball, rel=1e-12)
    assert v.a_only == pytest.approx(1000 - ball, rel=1e-12)
    assert v.b_only == pytest.approx(0.0, abs=1e-10)
    assert v.union == pytest.approx(1000.0, rel=1e-12)
    apart = compose(solid_sphere(1.0), solid_sphere(1.0, (3, 0, 0)))
    v = region_volumes(apart)
    assert v.both == 0.0
    assert v.union == pytest.approx(2 * 4 / 3 * math.pi, rel=1e-12)
    assert boundary_pieces(apart, "common") == []


def test_a_block_and_a_cylinder_through_a_block(cylinder_through_block):
    bar = compose(block(10.0), block((2, 2, 20), origin=(2, 2, -5)))
    v = region_volumes(bar)
    assert v.both == pytest.approx(40.0, rel=VOLUME_RTOL)
    assert v.b_only == pytest.approx(40.0, rel=VOLUME_RTOL)
    v = region_volumes(cylinder_through_block)
    assert v.both == pytest.approx(40 * math.pi, rel=VOLUME_RTOL)
    assert v.b_only == pytest.approx(40 * math.pi, rel=VOLUME_RTOL)
    assert v.a_only == pytest.approx(1000 - 40 * math.pi, rel=VOLUME_RTOL)


def test_half_a_torus_in_a_block_crosses_both_seams():
    # the plane x = 0 cuts the torus along two tube circles; the half inside the block
    # spans the torus face's seam phi = 0 and the tube's seam
    c = compose(block((10, 20, 10), origin=(0, -10, -5)), solid_torus(3.0, 1.0))
    half = math.pi ** 2 * 3.0
    assert c.volume("common") == pytest.approx(half, rel=VOLUME_RTOL)
    assert c.volume("B only") == pytest.approx(half, rel=VOLUME_RTOL)
    pieces = c.boundary("common")
    assert sum(p.flux() for p in pieces) == pytest.approx(half, rel=PIECE_RTOL)
    on_torus = [p for p in pieces if p.operand == "B"]
    assert sum(p.area() for p in on_torus) == pytest.approx(2 * math.pi ** 2 * 3.0, rel=PIECE_RTOL)


def _grid_area(face: TrimmedFace, n: int = 500) -> float:
    """Area of a trimmed face by the midpoint rule on an n x n grid of its domain, cells
    kept where their centre is inside the loops (independent of Green's theorem)."""
    u0, u1, v0, v1 = face.surface.domain
    du, dv = (u1 - u0) / n, (v1 - v0) / n
    u, v = np.meshgrid(u0 + du * (np.arange(n) + 0.5), v0 + dv * (np.arange(n) + 0.5), indexing="ij")
    uv = np.column_stack([u.ravel(), v.ravel()])
    keep = inside_loops(uv, [loop_uv(loop) for loop in face.loops])
    d = face.surface.derivatives(uv[keep, 0], uv[keep, 1], 1)
    return float(np.linalg.norm(np.cross(d[:, 1, 0], d[:, 0, 1]), axis=1).sum() * du * dv)



def test_a_ball_cut_by_a_block_whose_edges_the_curve_crosses():
    """The curve of a ball r 5 and the block [3, 7] x [-2, 2]^2 passes over four faces of
    the block; on the ball it is four curves whose ends, computed on different face
    pairs, meet only to the tolerance: the region's boundary must close there.
    Exact common volume: integral of sqrt(25 - y^2 - z^2) - 3 over the square (smooth:
    a 200-point Gauss rule is exact to rounding)."""
    x, w = np.polynomial.legendre.leggauss(200)
    y, z = np.meshgrid(2 * x, 2 * x)
    exact = float(np.sum(np.outer(2 * w, 2 * w) * (np.sqrt(25 - y ** 2 - z ** 2) - 3)))
    ball, box = solid_sphere(5.0), block((4.0, 4.0, 4.0), origin=(3.0, -2.0, -2.0))
    c = compose(ball, box)
    assert c.volume("common") == pytest.approx(exact, rel=1e-10)
    assert c.volume("union") == pytest.approx(ball.volume() + 64.0 - exact, rel=1e-12)

def test_the_common_boundary_of_two_balls_is_two_caps(balls):
    pieces = boundary_pieces(balls, "common")
    assert all(isinstance(p, BoundaryPiece) and p.inside_other and not p.reversed for p in pieces)
    assert {p.operand for p in pieces} == {"A", "B"}
    for operand in "AB":
        mine = [p for p in pieces if p.operand == operand]
        assert sum(p.area() for p in mine) == pytest.approx(CAP, rel=PIECE_RTOL)
        assert sum(_grid_area(p.face) for p in mine) == pytest.approx(CAP, rel=2e-2)
    # the caps close: the divergence theorem over them gives the lens, whatever the origin
    for origin in ((0, 0, 0), (3, -2, 7)):
        assert sum(p.flux(origin) for p in pieces) == pytest.approx(LENS, rel=PIECE_RTOL)
    assert balls.boundary("common")[0].face_name == "u1"


@pytest.mark.parametrize("which", ["A", "B", "union", "A-B"])
def test_the_boundaries_of_two_balls_close_on_their_volumes(balls, which):
    expected = {"A": BALL, "B": BALL, "union": 2 * BALL - LENS, "A-B": BALL - LENS}[which]
    pieces = boundary_pieces(balls, which)
    assert sum(p.flux((1, 2, 3)) for p in pieces) == pytest.approx(expected, rel=PIECE_RTOL)
    areas = {"A": 4 * math.pi * R * R, "B": 4 * math.pi * R * R,
             "union": 2 * (4 * math.pi * R * R - CAP), "A-B": 4 * math.pi * R * R}[which]
    assert sum(p.area() for p in pieces) == pytest.approx(areas, rel=PIECE_RTOL)
    if which == "A-B":
        # B's cap inside A, turned to face out of A - B
        assert all(p.reversed == (p.operand == "B") for p in pieces)
        assert all(p.inside_other == (p.operand == "B") for p in pieces)


@pytest.mark.parametrize("which", ["union", "common", "A-B"])
def test_the_boundaries_of_a_cylinder_through_a_block_close(cylinder_through_block, which):
    v = region_volumes(cylinder_through_block)
    expected = {"union": v.union, "common": v.both, "A-B": v.a_only}[which]
    pieces = cylinder_through_block.boundary(which)
    assert sum(p.flux((5, 5, 5)) for p in pieces) == pytest.approx(expected, rel=PIECE_RTOL)
    if which == "common":
        # two disks of the block's faces and the side of the cylinder between them
        assert sorted(round(p.area(), 4) for p in pieces) == \
            sorted(round(x, 4) for x in (4 * math.pi, 4 * math.pi, 40 * math.pi))


def test_whole_faces_integrate_to_the_solid():
    ball = solid_sphere(2.0, (1, 1, 1))
    face = TrimmedFace(ball.exterior_faces()["u1"])
    assert face_integral(face, "area") == pytest.approx(16 * math.pi, rel=1e-12)
    assert face_integral(face, "flux", (4, 0, 0)) == pytest.approx(32 / 3 * math.pi, rel=1e-12)


def test_unknown_regions_are_refused(balls):
    with pytest.raises(InvalidGeometryError, match="which must be one of"):
        balls.volume("intersection")
    with pytest.raises(InvalidGeometryError, match="which must be one of"):
        balls.boundary("A only")
    with pytest.raises(InvalidGeometryError, match="which must be one of"):
        boundary_pieces(balls, "cut")
    with pytest.raises(InvalidGeometryError, match="kind"):
        face_integral(TrimmedFace(solid_sphere(1.0).exterior_faces()["u1"]), "volume")
