"""Whole models cut by planes: surfprep.intersect against BRepAlgoAPI_Section.

Sections of the fuselage (``occt_fuselage.stp``: 8 bicubic patches, OCCT bug
28366's plane-section case) and waterlines of the KCS container-ship hull
(``overture_kcs_hull_ideas.igs``: 18 bicubic patches up to 101 x 111 poles).
Each cut is ``surfprep.intersect(model, plane)`` with the plane given as a
cadquery face or as a bilinear B-spline plane (NurbsSurface), compared with
``BRepAlgoAPI_Section(model, plane)`` on the same plane face:

* branch count (:func:`connected_branches`: pieces of one waterline found on
  different faces join where their ends meet);
* the symmetric Hausdorff distance between the two curve sets (OpenCascade's
  samples projected onto our interpolants, our interpolants at 8 points per
  span measured to OpenCascade's edges as polylines of 4001 samples):
  both lie within tol of the surfaces and cross the plane at a steep angle,
  so they must agree to about ``2 tol``;
* total length (relative ``1e-5``);
* every one of our points within tol of the plane (it is exact).

Times of both are printed (``-s``) -- the whole-model cut runs per face pair in
Python: a finding, not an assertion (benchmarks/ holds the timed comparison).

Findings (strict xfails, reported): the fuselage waterline at 40 % height
loses 41 mm on face 3 (its refined curve strays beyond tol and is dropped),
and takes 9.3 s against the Section's 0.4 s. The KCS waterline at 60 % height crosses
hull face 16 (101 x 111 poles); our refined curve there strays beyond tol
and is dropped, so 3.26 m of the 7.3 m waterline are missing (OpenCascade
returns it). At 30 % height a 28 mm piece is lost the same way.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest
from ssi_measure import dense, dense_length, distance_to_curves
from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import (
    StrayCurves,
    connected_branches,
    curve_set_distance,
    intersect_surfaces,
)
from surfprep.plugin.intersect import face_operands
from surfprep.plugin.occ_reference import intersect_surfaces_occ, section_faces_occ

import surfprep
from surfprep.errors import InvalidGeometryError

cq = pytest.importorskip("cadquery")

OCC_SAMPLES = 4001
TOL_FACTOR = 1e-6


def bspline_plane(axis: int, level: float, lo: np.ndarray, hi: np.ndarray) -> NurbsSurface:
    """Bilinear B-spline plane ``x[axis] = level`` over the box ``lo..hi`` widened by 10 %."""
    pad = 0.1 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    others = [k for k in range(3) if k != axis]
    cp = np.empty((2, 2, 3))
    for i, a in enumerate((lo[others[0]], hi[others[0]])):
        for j, b in enumerate((lo[others[1]], hi[others[1]])):
            cp[i, j, axis], cp[i, j, others[0]], cp[i, j, others[1]] = level, a, b
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def plane_face(axis: int, level: float, centre: np.ndarray, size: float):
    origin = centre.copy()
    origin[axis] = level
    normal = np.zeros(3)
    normal[axis] = 1.0
    return cq.Face.makePlane(size, size, basePnt=cq.Vector(*origin), dir=cq.Vector(*normal))


def hausdorff(curves, occ, tol: float) -> float:
    """Symmetric Hausdorff distance of our curves and OpenCascade's: its samples to our
    interpolants by closest-point projection, our interpolants (8 points per span)
    to its polylines (4001 samples per edge)."""
    if not curves or not occ:
        return float("inf")
    occ_points = np.concatenate([c.points for c in occ])
    to_ours = distance_to_curves(curves, occ_points, 1e-3 * tol)
    return float(max(to_ours.max(), curve_set_distance(dense(curves, 8), occ).a_to_b.max()))


class Model:
    def __init__(self, path):
        self.model = surfprep.read(path)
        x0, y0, z0, x1, y1, z1 = self.model.bounding_box
        self.lo, self.hi = np.array([x0, y0, z0]), np.array([x1, y1, z1])
        self.tol = TOL_FACTOR * self.model.size

    def level(self, axis: int, fraction: float) -> float:
        return float(self.lo[axis] + fraction * (self.hi[axis] - self.lo[axis]))

    def cut(self, axis: int, fraction: float, *, bspline: bool = False) -> dict:
        """Ours and BRepAlgoAPI_Section on the same plane; figures of both."""
        level = self.level(axis, fraction)
        centre = 0.5 * (self.lo + self.hi)
        face = plane_face(axis, level, centre, 1.5 * float(np.max(self.hi - self.lo)))
        plane = bspline_plane(axis, level, self.lo, self.hi) if bspline else face
        start = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = surfprep.intersect(self.model, plane, tol=self.tol)
        t_ours = time.perf_counter() - start
        occ_plane = surfprep.to_occ(plane) if bspline else face.wrapped
        start = time.perf_counter()
        section = section_faces_occ(self.model.shape, occ_plane, self.tol, samples=OCC_SAMPLES)
        t_occ = time.perf_counter() - start
        ours = [r.curve for r in result]
        join = 1e3 * self.tol
        figures = {
            "level": level, "t_ours": t_ours, "t_occ": t_occ,
            "branches": connected_branches(ours, join),
            "occ_branches": connected_branches(section, join),
            "length": dense_length(ours), "occ_length": sum(s.length for s in section),
            "hausdorff": hausdorff(ours, section, self.tol),
            "warnings": [str(w.message) for w in caught],
            "off_plane": max((float(np.abs(p[:, axis] - level).max()) for p in dense(ours)),
                             default=0.0),
        }
        print(f"\n{self.model.path.name} cut {'xyz'[axis]} = {level:.6g} "
              f"({'B-spline' if bspline else 'cadquery'} plane): ours {figures['branches']} "
              f"branches, {figures['length']:.6g} long, {t_ours:.2f} s; Section "
              f"{figures['occ_branches']} branches, {figures['occ_length']:.6g} long, "
              f"{t_occ:.2f} s; Hausdorff {figures['hausdorff']:.2e} (tol {self.tol:.1e}); "
              f"{len(caught)} warnings")
        return figures


def check_agree(model: Model, f: dict) -> None:
    assert f["branches"] == f["occ_branches"] >= 1, f
    assert f["off_plane"] <= model.tol
    assert f["hausdorff"] <= 2 * model.tol, f
    assert f["length"] == pytest.approx(f["occ_length"], rel=1e-5)


@pytest.fixture(scope="module")
def fuselage(data_dir):
    path = data_dir / "occt_fuselage.stp"
    if not path.exists():
        pytest.skip(f"{path} not available")
    return Model(path)


@pytest.mark.parametrize("fraction", [0.1, 0.5, 0.9])
def test_fuselage_sections(fuselage, fraction):
    """Frames across the fuselage (x = const): one closed section each, as the Section's."""
    f = fuselage.cut(0, fraction)
    check_agree(fuselage, f)
    assert f["warnings"] == []


def test_fuselage_section_by_a_bspline_plane(fuselage):
    """The same frame cut by a bilinear B-spline plane (a NurbsSurface operand)."""
    check_agree(fuselage, fuselage.cut(0, 0.3, bspline=True))


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="BUG (reported): fuselage face 3 x the plane z = -630.57: "
                   "the refined curve strays beyond tol and is dropped; 41 mm of the 120.9 m "
                   "waterline missing (Hausdorff 21 mm); ours 9.3 s, Section 0.4 s")
def test_fuselage_waterline(fuselage):
    """A horizontal cut along the whole fuselage (z at 40 % of its height)."""
    check_agree(fuselage, fuselage.cut(2, 0.4))


# ------------------------------------------------------------------ ship hull (slow)
@pytest.fixture(scope="module")
def hull(data_dir):
    path = data_dir / "overture_kcs_hull_ideas.igs"
    if not path.exists():
        pytest.skip(f"{path} not available")
    return Model(path)


@pytest.mark.slow
@pytest.mark.parametrize("fraction", [
    pytest.param(0.3, marks=pytest.mark.xfail(strict=True, reason="BUG (reported): a 28 mm "
                                              "piece of the waterline is dropped as stray")),
    pytest.param(0.6, marks=pytest.mark.xfail(strict=True, reason="BUG (reported): hull face 16 "
                                              "x plane strays beyond tol and is dropped: 3.26 m "
                                              "of the 7.3 m waterline missing")),
])
def test_hull_waterlines(hull, fraction):
    f = hull.cut(2, fraction)
    check_agree(hull, f)


@pytest.mark.slow
def test_hull_face_16_waterline_strays(hull):
    """The reproducer of the 60 % waterline: hull face 16 x the plane z = 284.98 mm
    (tol 7.7e-3 mm). IntSS returns one 3.26 m curve; ours raises (strays beyond
    tol) and with DROP returns nothing. Pinned so a fix shows up here."""
    level = hull.level(2, 0.6)
    surface = face_operands(hull.model.faces[16])[0].surface
    plane = bspline_plane(2, level, hull.lo, hull.hi)
    occ = intersect_surfaces_occ(surface, plane, hull.tol)
    assert len(occ) == 1 and occ[0].length > 3000
    with pytest.raises(InvalidGeometryError, match="stray"):
        intersect_surfaces(surface, plane, tol=hull.tol)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert intersect_surfaces(surface, plane, tol=hull.tol, stray=StrayCurves.DROP) == []
