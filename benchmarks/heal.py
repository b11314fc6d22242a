"""Healing against OpenCascade, measured the same way for both (by us).

1. **Four-sided hole**: a 3 x 3 grid of bicubic patches of the graph
   ``z = 0.3 sin(1.3 x) cos(0.9 y) + 0.1 x y`` over the unit square, the middle
   patch missing. Filled by

   * surfprep: ``surfprep.heal(grid, continuity=G0 / G1)`` (hole detected from
     the free edges; approximant over the hole filled by the thin-plate spline of
     the positions found on its rim and on a ring of projections beyond it; network
     joined G0 / G1; sewn and checked);
   * ``BRepOffsetAPI_MakeFilling`` with the four neighbour edges as C0, and as G1
     constraints on their faces (``IsDone`` checked);
   * ``GeomFill_BSplineCurves(..., GeomFill_CoonsStyle)`` on the four edge curves.

   Deviation: the largest distance from points of the true graph over the hole
   (41 x 41) to the filling surface (closest points). Angle: along the four hole
   edges (101 samples each), the angle between the normals of the filling
   surface and of the neighbour face at the closest points. Time: the filling
   alone for OpenCascade; the whole ``heal`` call for surfprep (which also
   rebuilds the eight neighbours and sews).

2. **Gap**: two patches of the graph with a 1e-3 gap and mismatched
   parametrization along the shared side. surfprep ``heal`` vs
   ``BRepBuilderAPI_Sewing(2e-3)`` + ``ShapeFix_Shape``: the geometric gap left
   (samples of one face's boundary to the other face's surface), free edges,
   validity, largest edge tolerance, time.

Run:  python benchmarks/heal.py
"""

from __future__ import annotations

import time

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeFilling
from OCP.GeomAbs import GeomAbs_C0, GeomAbs_G1
from OCP.GeomFill import GeomFill_BSplineCurves, GeomFill_CoonsStyle
from OCP.ShapeFix import ShapeFix_Shape
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.projection import project_to_surface
from surfprep.plugin.convert import to_nurbs
from surfprep.plugin.edges import edge_to_nurbs
from surfprep.plugin.faces import make_face
from surfprep.plugin.geom import curve_to_occ, surface_from_occ
from surfprep.plugin.heal_topology import (
    count_free_edges,
    is_valid,
    max_edge_tolerance,
    sew,
)

import surfprep


def graph(x, y):
    return 0.3 * np.sin(1.3 * x) * np.cos(0.9 * y) + 0.1 * x * y


def graph_patch(x0, x1, y0, y1, nu=6, nv=6, dz=0.0):
    x, y = np.linspace(x0, x1, nu), np.linspace(y0, y1, nv)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, graph(gx, gy) + dz], axis=-1))


def compound(shapes):
    out = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(out)
    for s in shapes:
        b.Add(out, s)
    return out


def edges_of(face):
    out, ex = [], TopExp_Explorer(face, TopAbs_EDGE)
    while ex.More():
        out.append(TopoDS.Edge_s(ex.Current()))
        ex.Next()
    return out


# ----------------------------------------------------------------- the hole
def hole_grid():
    """Eight faces and, for the hole, its four (edge, neighbour face, NurbsSurface) sides."""
    faces, sides = {}, []
    for i in range(3):
        for j in range(3):
            if (i, j) != (1, 1):
                s = graph_patch(i / 3, (i + 1) / 3, j / 3, (j + 1) / 3, 5 + i, 5 + j)
                faces[(i, j)] = (make_face(s), s)
    for key, mid in (((1, 0), (0.5, 1 / 3)), ((2, 1), (2 / 3, 0.5)), ((1, 2), (0.5, 2 / 3)),
                     ((0, 1), (1 / 3, 0.5))):
        face, surface = faces[key]
        target = np.array([mid[0], mid[1], graph(*mid)])
        best = min(edges_of(face), key=lambda e: _edge_mid_distance(e, target))
        sides.append((best, face, surface))
    return [f for f, _ in faces.values()], sides


def _edge_mid_distance(edge, target):
    c = edge_to_nurbs(edge)
    t0, t1 = c.domain
    return float(np.linalg.norm(c.evaluate(0.5 * (t0 + t1)) - target))


def measure_fill(surface, sides, neighbours=None):
    """(deviation from the true graph over the hole, max normal angle along its sides,
    max gap): ``neighbours`` replaces the sides' faces by what the output holds
    (surfprep rebuilds the neighbours as approximants too)."""
    t = np.linspace(1 / 3, 2 / 3, 41)
    gx, gy = np.meshgrid(t, t, indexing="ij")
    truth = np.stack([gx, gy, graph(gx, gy)], axis=-1).reshape(-1, 3)
    deviation = float(project_to_surface(surface, truth).distance.max())
    worst_angle, worst_gap = 0.0, 0.0
    for k, (edge, _, neighbour) in enumerate(sides):
        neighbour = neighbour if neighbours is None else neighbours[k]
        c = edge_to_nurbs(edge)
        pts = c.evaluate(np.linspace(*c.domain, 101))
        fa, fb = project_to_surface(surface, pts), project_to_surface(neighbour, pts)
        na = surface.normals(fa.uv[:, 0], fa.uv[:, 1])
        nb = neighbour.normals(fb.uv[:, 0], fb.uv[:, 1])
        angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(na, nb), axis=1),
                                      np.abs(np.sum(na * nb, axis=1))))
        worst_angle = max(worst_angle, float(angle.max()))
        worst_gap = max(worst_gap, float(fa.distance.max()))
    return deviation, worst_angle, worst_gap


def fill_ours(faces, sides, continuity):
    start = time.perf_counter()
    result = surfprep.heal(compound(faces), continuity=continuity)
    elapsed = time.perf_counter() - start
    (k,) = [n for n, p in enumerate(result.patches) if p.origin.kind == "hole"]
    patches = result.network.patches
    # the output neighbour of each hole side: the approximant of the face it came from
    index = {faces_key: n for n, p in enumerate(result.patches)
             for faces_key in p.origin.faces if p.origin.kind == "face"}
    neighbours = [patches[index[_face_index(faces, face)]] for _, face, _ in sides]
    assert result.valid_after
    note = f"valid {result.valid_after}, free edges {result.free_edges_after}"
    return patches[k], elapsed, note, neighbours


def _face_index(faces, face):
    return next(n for n, f in enumerate(faces) if f.IsSame(face))


def fill_occ_filling(sides, order):
    start = time.perf_counter()
    filling = BRepOffsetAPI_MakeFilling()
    for edge, face, _ in sides:
        if order is GeomAbs_C0:
            filling.Add(edge, GeomAbs_C0)
        else:
            filling.Add(edge, face, order)
    filling.Build()
    elapsed = time.perf_counter() - start
    if not filling.IsDone():
        return None, elapsed, "IsDone() False", None
    shape = filling.Shape()
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    face = TopoDS.Face_s(ex.Current())
    return (to_nurbs(face).surface, elapsed, f"IsDone, G0 error {filling.G0Error():.2g}",
            None)


def fill_occ_coons(sides):
    start = time.perf_counter()
    curves = [curve_to_occ(edge_to_nurbs(e)) for e, _, _ in sides]
    try:
        fill = GeomFill_BSplineCurves(*curves, GeomFill_CoonsStyle)
    except Exception as exc:                                   # noqa: BLE001
        return None, time.perf_counter() - start, f"failed: {exc}", None
    surface = surface_from_occ(fill.Surface())
    return surface, time.perf_counter() - start, "GeomFill_CoonsStyle", None


def hole_table() -> list[str]:
    faces, sides = hole_grid()
    rows = []
    for label, run in (
            ("surfprep heal G0", lambda: fill_ours(faces, sides, "G0")),
            ("surfprep heal G1", lambda: fill_ours(faces, sides, "G1")),
            ("MakeFilling C0", lambda: fill_occ_filling(sides, GeomAbs_C0)),
            ("MakeFilling G1", lambda: fill_occ_filling(sides, GeomAbs_G1)),
            ("GeomFill Coons", lambda: fill_occ_coons(sides))):
        surface, elapsed, note, neighbours = run()
        if surface is None:
            rows.append(f"| {label} | - | - | - | {elapsed:.3f} | {note} |")
            continue
        dev, angle, gap = measure_fill(surface, sides, neighbours)
        rows.append(f"| {label} | {dev:.3g} | {angle:.3g} | {gap:.2g} | {elapsed:.3f} | {note} |")
    head = [("| 4-sided hole (unit square, 1/3 x 1/3 hole) | deviation from true surface | "
            "max normal angle to the neighbours in the output (deg) | max distance of the "
            "original hole edges to the fill | time (s) | "
            "note |"), "|---|---|---|---|---|---|"]
    return head + rows


# ------------------------------------------------------------------ the gap
def gap_table() -> list[str]:
    a = graph_patch(0, 1, 0, 1, 6, 6)
    b = graph_patch(1, 2, 0, 1, 9, 7, dz=1e-3)
    fa, fb = make_face(a), make_face(b)
    side = a.isocurve(1.0, "u")
    pts = side.evaluate(np.linspace(0, 1, 201))
    rows = []
    start = time.perf_counter()
    result = surfprep.heal(compound([fa, fb]), continuity="G1")
    t_ours = time.perf_counter() - start
    (join,) = result.joins
    rows.append(f"| surfprep heal G1 | {join.max_gap:.2g} | {result.free_edges_after} | "
                f"{result.tight_free_edges_after} | {result.valid_after} | "
                f"{result.max_edge_tolerance:.2g} | {t_ours:.3f} |")
    start = time.perf_counter()
    sewn, _ = sew([fa, fb], 2e-3)
    fixer = ShapeFix_Shape(sewn)
    fixer.Perform()
    fixed = fixer.Shape()
    t_occ = time.perf_counter() - start
    faces = [to_nurbs(TopoDS.Face_s(f)).surface for f in _faces(fixed)]
    right = max(faces, key=lambda s: s.evaluate(0.5, 0.5)[0])     # the face beyond x = 1
    left = float(project_to_surface(right, pts).distance.max())
    tight, _ = sew(_faces(fixed), 1e-7)
    rows.append(f"| Sewing(2e-3) + ShapeFix | {left:.2g} | {count_free_edges(fixed)} | "
                f"{count_free_edges(tight)} | {is_valid(fixed)} | "
                f"{max_edge_tolerance(fixed):.2g} | {t_occ:.3f} |")
    head = [("| gap 1e-3 between two patches | geometric gap left (boundary of one face to "
            "the other surface) | free edges | free edges after re-sewing at 1e-7 | valid | "
            "max edge tolerance | time (s) |"),
            "|---|---|---|---|---|---|---|"]
    return head + rows


def _faces(shape):
    out, ex = [], TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        out.append(TopoDS.Face_s(ex.Current()))
        ex.Next()
    return out


def main() -> None:
    for line in hole_table():
        print(line)
    print()
    for line in gap_table():
        print(line)


if __name__ == "__main__":
    main()
