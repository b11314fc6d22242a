"""Sharp edges of real files are intersection curves: ours and OpenCascade's against them.

A sharp edge shared by two B-spline faces (their normals differ by more than
``MIN_ANGLE`` degrees all along it) is an intersection curve that the writing
CAD system computed. For each such edge the two faces' UNDERLYING surfaces are
intersected -- by :func:`intersect_surfaces` (as :func:`surfprep.intersect`
calls it: curves that break ``tol`` left out) and by ``GeomAPI_IntSS`` at the
same ``tol`` -- and the stored edge (101 samples of its 3D curve) must be
covered by one answer's curves within ``2 (edge tolerance + tol)``: the edge
may lie its tolerance off each surface, a curve within ``tol`` of both
surfaces up to about ``tol`` off their true intersection at these angles.

Distances to our curves are measured to the interpolants by closest-point
projection (``ssi_measure.distance_to_curves``), to OpenCascade's as polylines
of 1001 samples (chord sag far below the limits here).

Each edge is classified by how many of the two surfaces it runs along a
domain side of (0, 1 or 2): I-DEAS writes every face as a B-spline whose
domain ends at the face's edges, so in ``occt_s1_ideas.stp`` most edges lie on
the boundary of one or both surfaces -- the intersection then runs along (or
ends exactly on) a surface's boundary, the hardest case for any SSI.

Findings that were pinned as strict xfails and are now fixed (kept as the history of each case):

* (fixed by algorithms.intersection.sides) an intersection running along the
  domain side of one surface (e.g. a plane cap x a surface of revolution ending
  on it, s1_ideas faces 42 x 43) came out in many pieces with gaps (8 curves,
  5.4 mm of the edge uncovered); now one curve along the side, as IntSS (2e-5 mm).
* (fixed by bc6c808) s1_ideas faces 121 x 128 and 130 x 133 raised
  DegenerateGeometryError (coincident consecutive samples interpolated).
* (fixed: seam cut moved only the jumping surface's (u, v)) s1_ideas faces
  61 x 65 (a plane and a periodic cylinder crossing at 90 degrees, edge
  interior to both surfaces): one of the three refined curves strayed beyond
  tol and was dropped; the stored edge it carries (about 1 mm) was missed.
  IntSS finds all three curves (to 1e-9 mm), and so do we now.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np
import pytest
from helpers.measure import distance_to_curves
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_BSplineSurface
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

import surfprep
from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import (
    StrayCurves,
    intersect_surfaces,
    polyline_distance,
)
from surfprep.errors import SurfprepError
from surfprep.plugin.intersect import face_operands
from surfprep.plugin.occ_reference import intersect_surfaces_occ

#: an edge is sharp when its faces' normals differ by more than this (degrees) all along it
MIN_ANGLE = 10.0
#: intersection tolerance relative to the model's size (surfprep.intersect's default)
TOL_FACTOR = 1e-6
EDGE_SAMPLES = 101
OCC_SAMPLES = 1001


@dataclass(frozen=True)
class SharpEdge:
    """A sharp edge between two B-spline faces.

    Attributes
    ----------
    faces : (int, int)
        Indices of the two faces in the model.
    samples : (EDGE_SAMPLES, 3) float
        Points of the edge's 3D curve, location applied.
    tolerance : float
        The edge's tolerance as stored.
    angle : float
        Smallest angle between the faces' normals along the edge (degrees).
    on_sides : int
        Of how many of the two surfaces the edge runs along a domain side.
    """

    faces: tuple[int, int]
    samples: np.ndarray
    tolerance: float
    angle: float
    on_sides: int


def _on_side(surface: NurbsSurface, uv: np.ndarray, rel: float = 1e-6) -> bool:
    u0, u1, v0, v1 = surface.domain
    eu, ev = rel * (u1 - u0), rel * (v1 - v0)
    return bool(np.all((np.abs(uv[:, 0] - u0) <= eu) | (np.abs(uv[:, 0] - u1) <= eu)
                       | (np.abs(uv[:, 1] - v0) <= ev) | (np.abs(uv[:, 1] - v1) <= ev)))


def sharp_edges(model, surfaces: list[NurbsSurface], min_angle: float = MIN_ANGLE
                ) -> list[SharpEdge]:
    """Every edge shared by two different B-spline faces meeting at more than
    ``min_angle`` degrees. Normals and domain sides are taken at 11 points of
    the edge's pcurve on each face (B-spline faces keep OpenCascade's (u, v))."""
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(model.shape, TopAbs_EDGE, TopAbs_FACE, ancestors)

    def index(face) -> int:
        return next(i for i, g in enumerate(model.faces) if g.IsSame(face))

    out = []
    for k in range(1, ancestors.Extent() + 1):
        edge = TopoDS.Edge_s(ancestors.FindKey(k))
        owners = [TopoDS.Face_s(f) for f in ancestors.FindFromIndex(k)]
        if len(owners) != 2 or owners[0].IsSame(owners[1]) or BRep_Tool.Degenerated_s(edge):
            continue
        if any(BRepAdaptor_Surface(f).GetType() != GeomAbs_BSplineSurface for f in owners):
            continue
        i, j = index(owners[0]), index(owners[1])
        normals, sides = [], 0
        for face, surface in ((owners[0], surfaces[i]), (owners[1], surfaces[j])):
            pcurve = BRepAdaptor_Curve2d(edge, face)
            t = np.linspace(pcurve.FirstParameter(), pcurve.LastParameter(), 11)
            uv = np.array([pcurve.Value(x).Coord() for x in t.tolist()])
            normals.append(surface.normals(uv[:, 0], uv[:, 1]))
            sides += _on_side(surface, uv)
        cosine = np.abs(np.sum(normals[0] * normals[1], axis=1))
        angle = float(np.degrees(np.arccos(np.clip(cosine, 0, 1))).min())
        if angle <= min_angle:
            continue
        curve = BRepAdaptor_Curve(edge)
        t = np.linspace(curve.FirstParameter(), curve.LastParameter(), EDGE_SAMPLES)
        samples = np.array([curve.Value(x).Coord() for x in t.tolist()])
        out.append(SharpEdge((i, j), samples, BRep_Tool.Tolerance_s(edge), angle, sides))
    return out


@dataclass
class EdgeMatch:
    """How far the stored edge is from each answer (inf: nothing near it)."""

    edge: SharpEdge
    tol: float
    ours: float
    occ: float
    ours_curves: int
    occ_curves: int
    ours_worst_deviation: float
    ours_time: float
    occ_time: float
    ours_error: str | None = None

    @property
    def limit(self) -> float:
        return 2 * (self.edge.tolerance + self.tol)

    @property
    def ours_matches(self) -> bool:
        return self.ours <= self.limit

    @property
    def occ_matches(self) -> bool:
        return self.occ <= self.limit


def match_edge(edge: SharpEdge, a: NurbsSurface, b: NurbsSurface, tol: float) -> EdgeMatch:
    start = time.perf_counter()
    error = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # StrayCurveWarning: counted as a miss
        try:
            curves = intersect_surfaces(a, b, tol=tol, stray=StrayCurves.DROP)
        except SurfprepError as exc:             # surfprep.intersect skips such a pair
            curves, error = [], f"{type(exc).__name__}: {exc}"
    ours_time = time.perf_counter() - start
    start = time.perf_counter()
    occ = intersect_surfaces_occ(a, b, tol, samples=OCC_SAMPLES)
    occ_time = time.perf_counter() - start
    ours = float(distance_to_curves(curves, edge.samples, 1e-3 * tol).max()) if curves \
        else float("inf")
    far = float(polyline_distance(edge.samples, occ).max()) if occ else float("inf")
    worst = max((c.max_deviation(a, b).max for c in curves), default=0.0)
    return EdgeMatch(edge, tol, ours, far, len(curves), len(occ), worst, ours_time, occ_time,
                     error)


class RealFile:
    """A model, its faces' surfaces and its sharp B-spline edges (read once per module)."""

    def __init__(self, path):
        self.model = surfprep.read(path)
        self.surfaces = [op.surface for op in face_operands(self.model)]
        self.tol = TOL_FACTOR * self.model.size
        self._edges = None

    @property
    def edges(self) -> list[SharpEdge]:
        if self._edges is None:
            self._edges = sharp_edges(self.model, self.surfaces)
        return self._edges

    def edges_between(self, i: int, j: int) -> list[SharpEdge]:
        return [e for e in self.edges if set(e.faces) == {i, j}]

    def match(self, edge: SharpEdge) -> EdgeMatch:
        i, j = edge.faces
        return match_edge(edge, self.surfaces[i], self.surfaces[j], self.tol)


@pytest.fixture(scope="module")
def s1_ideas(data_dir):
    path = data_dir / "occt_s1_ideas.stp"
    return RealFile(path)


# ------------------------------------------------------------------ fast: a handful
def test_sharp_edges_are_found(s1_ideas):
    """The README's count: over 200 sharp B-spline edges in occt_s1_ideas.stp,
    every one on both its surfaces to within its tolerance."""
    edges = s1_ideas.edges
    assert len(edges) > 200
    assert all(e.angle > MIN_ANGLE for e in edges)
    assert sum(e.on_sides == 0 for e in edges) > 40


@pytest.mark.parametrize("faces", [(40, 41), (43, 44), (30, 38)])
def test_edge_inside_both_surfaces_is_covered(s1_ideas, faces):
    """Edges inside both surfaces' domains (72, 72 and 88 degrees): ours and IntSS
    both cover the stored edge; our curves lie within tol of both surfaces."""
    (edge,) = [e for e in s1_ideas.edges_between(*faces)][:1]
    m = s1_ideas.match(edge)
    assert m.ours_worst_deviation <= m.tol
    assert m.ours_matches, (m.ours, m.limit)
    assert m.occ_matches, (m.occ, m.limit)


def test_edge_along_a_surface_boundary_is_covered(s1_ideas):
    """s1_ideas faces 42 x 43: a plane cap and a surface of revolution whose domain
    side v = 0 is a full circle lying on the plane. The tessellations only touch
    there; this came out in 8 pieces with gaps (5.4 mm of the edge uncovered) until
    the side was intersected directly (algorithms.intersection.sides)."""
    (edge,) = s1_ideas.edges_between(42, 43)
    assert edge.on_sides == 1
    m = s1_ideas.match(edge)
    assert m.occ_matches, (m.occ, m.limit)
    assert m.ours_matches, (m.ours, m.limit)


def test_edge_on_a_dropped_stray_curve(s1_ideas):
    """s1_ideas faces 61 x 65: a plane crossing a closed (periodic) cylinder at 90
    degrees; one loop passes the cylinder's seam 0.2 mm from the plane's side. Its
    short piece beyond the seam was dropped as stray: the seam cut moved the
    PLANE's (u, v) of the seam point to the plane's far side too (its v changed by
    more than half the domain between the piece's two sparse samples). Fixed: only
    the surface that jumps is moved."""
    edges = s1_ideas.edges_between(61, 65)
    assert edges and all(e.on_sides == 0 for e in edges)
    matches = [s1_ideas.match(e) for e in edges]
    assert all(m.occ_matches for m in matches)
    assert all(m.ours_matches for m in matches), [(m.ours, m.limit) for m in matches]


def test_narrow_strip_across_a_side(s1_ideas):
    """s1_ideas faces 104 x 105: a closed cylinder (three rational 120-degree arcs,
    seam at the top) ends on a plane strip only 3 mm wide; its end circle crosses the
    strip twice, in arcs of 1.5 + 1.5 mm (split by the seam) and 3 mm. Each run held
    one or two of the side's regular samples (7.5 degrees apart), fewer than a run
    needs: only half of the bottom arc came out, from a touching triangle pair.
    Short stretches of near samples are now sampled densely: all three arcs, as IntSS."""
    edges = s1_ideas.edges_between(104, 105)
    assert len(edges) == 2 and all(e.on_sides == 1 for e in edges)
    matches = [s1_ideas.match(e) for e in edges]
    assert all(m.ours_matches for m in matches), [(m.ours, m.limit) for m in matches]
    a, b = s1_ideas.surfaces[104], s1_ideas.surfaces[105]
    curves = intersect_surfaces(a, b, tol=s1_ideas.tol)
    assert sorted(round(c.length, 3) for c in curves) == [1.502, 1.502, 3.003]
    occ = intersect_surfaces_occ(a, b, s1_ideas.tol)
    assert sorted(round(c.length, 3) for c in occ) == [1.502, 1.502, 3.003]


@pytest.mark.parametrize("file, faces, why", [
    ("occt_b1_euclid.stp", (28, 37), "side 1e-5..3e-5 from the plane: run stopped half-way"),
    ("occt_k1_alias.stp", (20, 23), "side into the other surface's seam: foot on its far line"),
    ("occt_cornetta.stp", (3, 39), "end met the side away from the corner the curve runs into"),
])
def test_side_runs_that_ended_early(data_dir, file, faces, why):
    """Edges along a domain side that only IntSS reproduced at the start of the 2026-12
    session. b1_euclid 28 x 37: the side lies 1e-5..3e-5 from the other surface (tol
    3e-4) and the triangles leave one segment ending 2e-5 of the extent inside it; the
    side was not examined (points counted as on it within 1e-9 of the extent) and a
    run ended where the gap passed tol / 16. k1_alias 20 x 23: a side ending in the
    seam of a closed surface, whose first foot landed on the seam's far line; the
    pcurve's jump of the whole period made the curve stray by 9e5 and it was dropped.
    cornetta 3 x 39: the curve runs into a corner of one domain; the traced end met
    the side 0.05 mm from it, beyond the reach of the end's solve on the side, and
    stayed there; such ends are now marched to the side. All match the stored edge,
    as IntSS."""
    real = RealFile(data_dir / file)
    (edge,) = real.edges_between(*faces)[:1]
    m = real.match(edge)
    assert m.occ_matches, (m.occ, m.limit)
    assert m.ours_matches, (why, m.ours, m.limit)
    assert m.ours_worst_deviation <= m.tol


# ------------------------------------------------------------------ slow: every sharp edge
@dataclass(frozen=True)
class Summary:
    """Match counts over a file's sharp edges, per number of domain sides."""

    matches: list

    def count(self, who: str, sides: int | None = None) -> int:
        ms = [m for m in self.matches if sides is None or m.edge.on_sides == sides]
        return sum(getattr(m, f"{who}_matches") for m in ms)

    def total(self, sides: int | None = None) -> int:
        return sum(sides is None or m.edge.on_sides == sides for m in self.matches)

    def table(self, name: str) -> str:
        rows = [f"{name}: sharp B-spline edges matched within 2 (edge tol + tol)",
                "| edges on a domain side of | edges | ours | IntSS |", "|---|---|---|---|"]
        for sides, label in ((0, "neither surface"), (1, "one surface"), (2, "both surfaces"),
                             (None, "all")):
            rows.append(f"| {label} | {self.total(sides)} | {self.count('ours', sides)} | "
                        f"{self.count('occ', sides)} |")
        ours = [m.ours for m in self.matches if m.ours_matches]
        occ = [m.occ for m in self.matches if m.occ_matches]
        t_ours = sum(m.ours_time for m in self.matches)
        t_occ = sum(m.occ_time for m in self.matches)
        rows.append(f"median distance of matched edges: ours {np.median(ours):.1e}, "
                    f"IntSS {np.median(occ):.1e}; time ours {t_ours:.1f} s, IntSS {t_occ:.1f} s; "
                    f"ours only {sum(m.ours_matches and not m.occ_matches for m in self.matches)}, "
                    f"IntSS only {sum(m.occ_matches and not m.ours_matches for m in self.matches)}, "
                    f"errors {sum(m.ours_error is not None for m in self.matches)}")
        return "\n".join(rows)


@pytest.fixture(scope="module")
def s1_summary(s1_ideas):
    summary = Summary([s1_ideas.match(e) for e in s1_ideas.edges])
    print("\n" + summary.table("occt_s1_ideas.stp"))
    return summary


@pytest.mark.slow
def test_all_sharp_edges_our_curves_keep_tol(s1_summary):
    """Whatever is returned lies within tol of both surfaces, on every pair, and no
    pair raises (faces 121 x 128 and 130 x 133 raised DegenerateGeometryError,
    'points 0 and 1 have the same parameter', at ca89398; fixed by bc6c808)."""
    assert all(m.ours_worst_deviation <= m.tol for m in s1_summary.matches)
    assert [m.edge.faces for m in s1_summary.matches if m.ours_error] == []


@pytest.mark.slow
def test_all_sharp_edges_regression_floor(s1_summary):
    """At commit ca89398 ours matched 56 of the 58 edges inside both domains and
    101 of 234 in all (IntSS 58 and 172); with the curves along domain sides
    (algorithms.intersection.sides) and the seam fix, 230 of 234 and 58 of 58;
    232 at the start of the 2026-12 session (faces 104 x 105: IntSS only), all
    234 with short side runs sampled densely."""
    assert s1_summary.count("ours", 0) == s1_summary.total(0)
    assert s1_summary.count("ours") == s1_summary.total()


@pytest.mark.slow
def test_all_sharp_edges_inside_domains_as_many_as_occ(s1_summary):
    assert s1_summary.count("ours", 0) >= s1_summary.count("occ", 0)


@pytest.mark.slow
def test_all_sharp_edges_as_many_as_occ(s1_summary):
    assert s1_summary.count("ours") >= s1_summary.count("occ")
