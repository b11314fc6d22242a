"""Whole models cut by planes: surfprep.intersect against BRepAlgoAPI_Section.

Sections of the fuselage (``occt_fuselage.stp``: 8 bicubic patches, OCCT bug
28366's plane-section case) and waterlines of the KCS container-ship hull
(``overture_kcs_hull_ideas.igs``: 18 bicubic patches up to 101 x 111 poles).
Each cut is ``surfprep.intersect(model, plane)`` with the plane given as a
cadquery face or as a bilinear B-spline plane (NurbsSurface), compared with
``BRepAlgoAPI_Section(model, plane)`` on the same plane face:

* branch count (:func:`connected_branches`: pieces of one waterline found on
  different faces join where their ends meet);
* both one-sided distances between the curve sets: OpenCascade's samples
  projected onto our interpolants (every Section point within ``2 tol`` of our
  curves: nothing missed), and our interpolants at 8 points per span to its
  edges as polylines of 4001 samples (within ``2 tol``, plus the patch gap on
  the unsewn hull, where the two answers' pieces may end differently);
* total length (relative ``1e-5``);
* every one of our points within tol of the plane (it is exact).

Times of both are printed (``-s``): the whole-model cut runs per face pair in
Python and is 2-25 x slower than the Section here -- a finding, not an
assertion (benchmarks/ holds timed comparisons).

Findings that were pinned as strict xfails (at commits ca89398 / bc6c808) and are now fixed:

* (fixed: hanging ends continued by marching, algorithms.intersection.extend)
  fuselage waterline at 40 % height: at the nose, where faces 0 and 1 close
  to a point, our pieces stopped 20.9 mm short on both sides (41 mm of 120.9 m
  missing); 5.7-9.3 s against the Section's 0.3-0.4 s (now about 2 s). (The Section there is
  itself up to 0.22 mm off the surfaces near the nose and 0.25 mm mid-body,
  ours within 0.014 mm; tol 0.064 mm.)
* (fixed: seam closure measured to 64 tol, not 4 mesh_tol) KCS waterline at
  30 % height: on hull face 1 (the transom, a plane x = 170.89 mm, 20.57 mm
  wide) our piece ran out about 10 mm and back instead of across: the face is
  narrower than 4 mesh_tol (37 mm), so its opposite sides "met" and the chain
  was cut as if at a seam of a closed surface (at bc6c808: 16 mm missing).
  (Before 1e917ff the 60 % waterline also lost 3.26 m on face 16: its curve
  strayed beyond tol and was dropped; it passes now.)
"""

from __future__ import annotations

import time
import warnings

import cadquery as cq
import numpy as np
import pytest
from helpers.measure import dense, dense_length, distance_to_curves

import surfprep
from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import (
    connected_branches,
    curve_set_distance,
)
from surfprep.algorithms.projection import distance_to_surface
from surfprep.plugin.intersect import face_operands
from surfprep.plugin.occ_reference import section_faces_occ

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


def one_sided(curves, occ, tol: float) -> tuple[float, float]:
    """``(occ_to_ours, ours_to_occ)``: OpenCascade's samples to our interpolants by
    closest-point projection, and our interpolants (8 points per span) to its
    polylines (4001 samples per edge); inf when either side is empty."""
    if not curves or not occ:
        return float("inf"), float("inf")
    occ_points = np.concatenate([c.points for c in occ])
    to_ours = distance_to_curves(curves, occ_points, 1e-3 * tol)
    return float(to_ours.max()), float(curve_set_distance(dense(curves, 8), occ).a_to_b.max())


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
        occ_to_ours, ours_to_occ = one_sided(ours, section, self.tol)
        figures = {
            "level": level, "t_ours": t_ours, "t_occ": t_occ,
            "branches": connected_branches(ours, join),
            "occ_branches": connected_branches(section, join),
            "length": dense_length(ours), "occ_length": sum(s.length for s in section),
            "occ_to_ours": occ_to_ours, "ours_to_occ": ours_to_occ,
            "hausdorff": max(occ_to_ours, ours_to_occ),
            "warnings": [str(w.message) for w in caught],
            "ours": ours, "section": section,
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


def check_agree(model: Model, f: dict, gap: float = 0.0, occ_off: float = 0.0) -> None:
    """Same branches and length as the Section; every Section point within
    ``2 tol + occ_off`` of our curves and ours within ``2 tol + gap`` of the
    Section's (``gap``: how far apart the model's patches are, where the two
    answers may end differently; ``occ_off``: how far the Section's own points lie
    from the model's surfaces, measured)."""
    assert f["branches"] == f["occ_branches"] >= 1, f
    assert f["off_plane"] <= model.tol
    assert f["occ_to_ours"] <= 2 * model.tol + occ_off, f
    assert f["ours_to_occ"] <= 2 * model.tol + gap, f
    assert f["length"] == pytest.approx(f["occ_length"], rel=1e-5)


@pytest.fixture(scope="module")
def fuselage(data_dir):
    path = data_dir / "occt_fuselage.stp"
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


def off_surfaces(model: Model, points: np.ndarray) -> np.ndarray:
    """Distance ``(n,)`` of each point to the nearest of the model's face surfaces."""
    surfaces = [op.surface for op in face_operands(model.model)]
    return np.min([distance_to_surface(s, points) for s in surfaces], axis=0)


@pytest.mark.slow
def test_fuselage_waterline(fuselage):
    """A horizontal cut along the whole fuselage (z at 40 % of its height).

    Was a strict xfail: at the nose, where faces 0 and 1 close to a point, our
    pieces stopped 20.9 mm short on both sides (hanging OPEN ends of the traced
    chains where the triangles near the pole are slivers); hanging ends are now
    continued on the exact surfaces (algorithms.intersection.extend) to the side
    where the faces meet. The Section's own points lie up to about 0.22 mm off
    the surfaces near the nose (measured here, pinned above 2 tol); ours lie
    within tol of them, and both one-sided distances are allowed that much more."""
    f = fuselage.cut(2, 0.4)
    occ_points = np.concatenate([c.points for c in f["section"]])
    occ_off = float(off_surfaces(fuselage, occ_points).max())
    ours_off = float(off_surfaces(fuselage, np.concatenate(dense(f["ours"], 3))).max())
    assert ours_off <= fuselage.tol, ours_off
    assert occ_off > 2 * fuselage.tol                        # pinned: the Section's error
    check_agree(fuselage, f, gap=occ_off, occ_off=occ_off)


# ------------------------------------------------------------------ ship hull (slow)
@pytest.fixture(scope="module")
def hull(data_dir):
    path = data_dir / "overture_kcs_hull_ideas.igs"
    return Model(path)


#: the hull's patches do not join: gaps up to about 1 mm (shared/data README)
HULL_GAP = 1.0


@pytest.mark.slow
@pytest.mark.parametrize("fraction", [0.3, 0.6])
def test_hull_waterlines(hull, fraction):
    """Waterlines of the KCS hull (z at 30 % and 60 % of its height): the Section's
    curves covered by ours to 2 tol; ours may end up to the patch gap away from
    the Section's pieces where the unsewn patches part."""
    check_agree(hull, hull.cut(2, fraction), gap=HULL_GAP)
