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

1b. **Holes of 3, 5 and 6 sides** (``nsided_table``): a fan of ``n`` bicubic patches
   of the same graph around a regular ``n``-gon hole of circumradius 0.15
   (``tests/helpers/heal_cases.fan_around_hole``). surfprep ``heal`` G0 / G1 (the
   hole classed by its surroundings, capped by the thin-plate spline of the rim
   and the faces near it, ``n`` four-sided patches around a centre; neighbours
   untouched) vs ``BRepOffsetAPI_MakeFilling`` (the front end of
   ``BRepFill_Filling``) with the ``n`` edges as C0, and as G1 constraints on their
   faces. Deviation from the true graph over the hole's inscribed disc (900
   points, closest points to the union of the fill's patches); the largest normal
   angle along the rim against the input faces (41 points per rim side); the
   largest distance of the fill's rim from the input faces (the gap left); for
   surfprep also the angle across its own spokes; time as above (surfprep: the
   whole ``heal`` call, reading, classing, sewing and checks included).

2. **Gap**: two patches of the graph with a 1e-3 gap and mismatched
   parametrization along the shared side. surfprep ``heal`` vs
   ``BRepBuilderAPI_Sewing(2e-3)`` + ``ShapeFix_Shape``: the geometric gap left
   (samples of one face's boundary to the other face's surface), free edges,
   validity, largest edge tolerance, time.

3. **Faces cutting through each other** (001 Fig. 7 kind): two bent sheets,
   each overshooting their crossing line by 0.2. surfprep ``heal`` with a
   directed patch over the crossing (the faces under it cut away) vs
   OpenCascade's way to remove the overshoot: ``BOPAlgo_Builder`` (general fuse)
   splits both faces along their intersection, the two overshoot pieces are
   deleted (chosen by hand, by their side of the crossing) and the rest sewn.
   Measured: crossings left (samples of one face within 0.02 of another's
   interior), free edges after re-sewing at 1e-7, validity, the largest normal
   angle across the joins (degrees; the crease for OpenCascade), the deviation
   from the creased true surface, time. And ``heal`` without a spec: the crossing
   found from the free edges and both faces trimmed back to it (crossings left: points
   of OpenCascade's section of the two output faces off their shared edge).

3b. **A box whose walls and lid overshoot each other** (``box_table``): surfprep
   ``heal`` (defaults) vs ``BOPAlgo_MakerVolume`` (OpenCascade's solid from faces that
   intersect: splits them and keeps what bounds a volume) vs sewing + ShapeFix:
   result type, free edges, validity, area, volume, time.

4. **Table 1 of 001, "intersecting surfaces" row**: the error of §7 of our
   approximant over the crossing at the paper's sampling resolutions 4x4 ..
   12x12 (model ~ 2 x 1 x 0.6, x 1e-3).

5. **Real files** (``files_table``; data in ``../shared/data``): the whole
   ``surfprep.heal`` (defaults) vs ``BRepBuilderAPI_Sewing(gap_tol)`` +
   ``ShapeFix_Shape`` on the same faces, ``gap_tol`` heal's default: CPU and wall
   time, free edges at ``gap_tol``, free edges when the output faces are sewn at
   1e-7 x size (gaps not closed in the geometry; for sewing the input's, as it
   moves no geometry and closes gaps by raising edge tolerances), validity,
   largest edge tolerance.

Run:  python benchmarks/heal.py [table names, e.g. files_table]
"""

from __future__ import annotations

import time

import numpy as np
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeFilling
from OCP.GeomAbs import GeomAbs_C0, GeomAbs_G1
from OCP.GeomFill import GeomFill_BSplineCurves, GeomFill_CoonsStyle
from OCP.ShapeFix import ShapeFix_Shape
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

import surfprep
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.projection import project_to_surface
from surfprep.plugin.convert import to_nurbs
from surfprep.plugin.occ.edges import edge_to_nurbs
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.geom import curve_to_occ, surface_from_occ
from surfprep.plugin.occ.shapes import compound, count_free_edges, is_valid, max_edge_tolerance, sew


def graph(x, y):
    return 0.3 * np.sin(1.3 * x) * np.cos(0.9 * y) + 0.1 * x * y


def graph_patch(x0, x1, y0, y1, nu=6, nv=6, dz=0.0):
    x, y = np.linspace(x0, x1, nu), np.linspace(y0, y1, nv)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, graph(gx, gy) + dz], axis=-1))


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


def make_filling(edges_faces, order):
    """``BRepOffsetAPI_MakeFilling`` over ``(edge, face)`` pairs, the edges as C0
    constraints or on their faces at ``order``: ``(surface or None, seconds, note)``."""
    start = time.perf_counter()
    filling = BRepOffsetAPI_MakeFilling()
    for edge, face in edges_faces:
        if order is GeomAbs_C0:
            filling.Add(edge, GeomAbs_C0)
        else:
            filling.Add(edge, face, order)
    filling.Build()
    elapsed = time.perf_counter() - start
    if not filling.IsDone():
        return None, elapsed, "IsDone() False"
    face = TopoDS.Face_s(TopExp_Explorer(filling.Shape(), TopAbs_FACE).Current())
    return to_nurbs(face).surface, elapsed, f"IsDone, G0 error {filling.G0Error():.2g}"


def fill_occ_filling(sides, order):
    surface, elapsed, note = make_filling([(edge, face) for edge, face, _ in sides], order)
    return surface, elapsed, note, None


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


# ------------------------------------------------------------ n-sided holes
def _normal_angle(n1, n2):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1),
                                 np.abs(np.sum(n1 * n2, axis=1))))


def _along(surface, uv, others):
    """(largest normal angle, largest distance) along ``uv`` on ``surface`` against the
    nearest of ``others``."""
    pts = surface.evaluate(uv[:, 0], uv[:, 1])
    best = None
    for other in others:
        foot = project_to_surface(other, pts)
        if best is None or foot.distance.max() < best[1]:
            angle = _normal_angle(surface.normals(uv[:, 0], uv[:, 1]),
                                  other.normals(foot.uv[:, 0], foot.uv[:, 1])).max()
            best = (float(angle), float(foot.distance.max()))
    return best


def _nsided_truth(heal_cases, n):
    xy = heal_cases.inside_regular_polygon(n)
    return np.column_stack([xy, heal_cases.gentle_height(xy[:, 0], xy[:, 1])])


def _nsided_ours(heal_cases, n, continuity):
    fan = heal_cases.fan_around_hole(n)
    shape = compound([make_face(s) for s in fan])
    start = time.perf_counter()
    result = surfprep.heal(shape, continuity=continuity)
    elapsed = time.perf_counter() - start
    holes = [s for p, s in zip(result.patches, result.network.patches)
             if p.origin.kind == "hole"]
    truth = _nsided_truth(heal_cases, n)
    dev = float(np.min([project_to_surface(h, truth).distance for h in holes], axis=0).max())
    t = np.linspace(0.02, 0.98, 41)
    rim = [_along(h, uv, fan) for h in holes
           for uv in (np.column_stack([t, 0 * t]), np.column_stack([0 * t, t]))]
    spokes = [_along(h, uv, [o for o in holes if o is not h])[0] for h in holes
              for uv in (np.column_stack([1 + 0 * t, t]), np.column_stack([t, 1 + 0 * t]))]
    note = (f"{len(holes)} patches, spokes {max(spokes):.2g} deg, free edges "
            f"{result.free_edges_before} -> {result.free_edges_after} (the fan's outer "
            f"edge stays open), valid {result.valid_after}")
    return dev, max(a for a, _ in rim), max(d for _, d in rim), elapsed, note


def _nsided_occ(heal_cases, n, order):
    fan = heal_cases.fan_around_hole(n)
    faces = [make_face(s) for s in fan]
    sides = []
    for face, surface in zip(faces, fan):
        target = surface.evaluate(0.5, 0.0)          # the hole's edge is the fan face's v = 0
        sides.append((min(edges_of(face), key=lambda e: _edge_mid_distance(e, target)), face))
    surface, elapsed, note = make_filling(sides, order)
    if surface is None:
        return None, None, None, elapsed, note
    dev = float(project_to_surface(surface, _nsided_truth(heal_cases, n)).distance.max())
    worst_angle, worst_gap = 0.0, 0.0
    for (edge, _), neighbour in zip(sides, fan):
        c = edge_to_nurbs(edge)
        pts = c.evaluate(np.linspace(*c.domain, 43)[1:-1])
        fa, fb = project_to_surface(surface, pts), project_to_surface(neighbour, pts)
        angle = _normal_angle(surface.normals(fa.uv[:, 0], fa.uv[:, 1]),
                              neighbour.normals(fb.uv[:, 0], fb.uv[:, 1]))
        worst_angle = max(worst_angle, float(angle.max()))
        worst_gap = max(worst_gap, float(fa.distance.max()))
    return dev, worst_angle, worst_gap, elapsed, note


def nsided_table() -> list[str]:
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from helpers import heal_cases
    rows = []
    runs = (("surfprep heal G0", _nsided_ours, "G0"), ("surfprep heal G1", _nsided_ours, "G1"),
            ("MakeFilling C0", _nsided_occ, GeomAbs_C0), ("MakeFilling G1", _nsided_occ, GeomAbs_G1))
    for n in (3, 5, 6):
        for label, run, how in runs:
            dev, angle, gap, elapsed, note = run(heal_cases, n, how)
            if dev is None:
                rows.append(f"| {n} | {label} | - | - | - | {elapsed:.3f} | {note} |")
                continue
            rows.append(f"| {n} | {label} | {dev:.2g} | {angle:.2g} | {gap:.2g} | "
                        f"{elapsed:.3f} | {note} |")
    head = [("| sides | method | deviation from true surface | max normal angle to the input "
             "faces along the rim (deg) | max distance of the fill's rim from the input faces "
             "| time (s) | note |"), "|---|---|---|---|---|---|---|"]
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


# ---------------------------------------------------------- faces crossing
def _crossing():
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from helpers import heal_cases  # the geometry of tests/plugin/heal/test_cut.py, one definition
    return heal_cases


def _max_join_angle(faces, gap: float) -> float:
    """Largest angle (deg) between the normals of two faces at points of one face's
    boundary lying within ``gap`` of the other."""
    worst = 0.0
    for i, f in enumerate(faces):
        u0, u1, v0, v1 = f.domain
        t = np.linspace(0, 1, 101)
        border = np.concatenate([np.stack([u0 + t * (u1 - u0), np.full(101, c)], 1)
                                 for c in (v0, v1)] +
                                [np.stack([np.full(101, c), v0 + t * (v1 - v0)], 1)
                                 for c in (u0, u1)])
        pts = f.evaluate(border[:, 0], border[:, 1])
        n_f = f.normals(border[:, 0], border[:, 1])
        for j, g in enumerate(faces):
            if i == j:
                continue
            foot = project_to_surface(g, pts)
            close = foot.distance < gap
            if np.any(close):
                n_g = g.normals(foot.uv[close, 0], foot.uv[close, 1])
                cos = np.abs(np.sum(n_f[close] * n_g, axis=1)).clip(0, 1)
                worst = max(worst, float(np.degrees(np.arccos(cos)).max()))
    return worst


def _deviation(cross, faces) -> float:
    worst = 0.0
    for f in faces:
        u0, u1, v0, v1 = f.domain
        pts = f.evaluate_grid(np.linspace(u0, u1, 41), np.linspace(v0, v1, 41)).reshape(-1, 3)
        worst = max(worst, float(np.abs(pts[:, 2] - cross.truth(pts[:, 0], pts[:, 1])).max()))
    return worst


def crossing_table() -> list[str]:
    from OCP.BOPAlgo import BOPAlgo_Builder
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    cross = _crossing()
    a, b = cross.sheet(0.0, 1.2, 0.0), cross.sheet(0.8, 2.0, cross.SLOPE)
    shape = cross.compound([make_face(a), make_face(b)])
    rows = []
    start = time.perf_counter()
    r = surfprep.heal(shape, patches=[{"corners": cross.corners()}])
    t_ours = time.perf_counter() - start
    out = [to_nurbs(f).surface for f in _faces(r.model.shape)]
    rows.append(f"| surfprep heal + directed patch | {cross.crossings(out)} | "
                f"{r.tight_free_edges_after} | {r.valid_after} | "
                f"{_max_join_angle(out, 1e-3):.3g} | {_deviation(cross, out):.3g} | "
                f"{t_ours:.3f} |")
    start = time.perf_counter()
    r = surfprep.heal(shape)                  # no spec: the crossing found and trimmed back
    t_trim = time.perf_counter() - start
    faces = _faces(r.model.shape)
    rows.append(f"| surfprep heal, no spec (crossing found, both trimmed back to it) | "
                f"{_section_off(faces, cross.X_CROSS)} | {r.tight_free_edges_after} | "
                f"{r.valid_after} | {_crease_angle(cross):.3g} (the crease) | 0 | "
                f"{t_trim:.3f} |")
    start = time.perf_counter()
    builder = BOPAlgo_Builder()
    builder.AddArgument(make_face(a))
    builder.AddArgument(make_face(b))
    builder.Perform()
    pieces = _faces(builder.Shape())
    keep = []
    for f in pieces:                 # the piece's centre of area: which side it is on
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(f, props)
        c = props.CentreOfMass()
        on_a = abs(c.Z() - float(cross.bend(c.X(), c.Y()))) < 1e-3
        if (on_a and c.X() < cross.X_CROSS) or (not on_a and c.X() > cross.X_CROSS):
            keep.append(f)
    sewn, _ = sew(keep, 1e-6)
    t_occ = time.perf_counter() - start
    tight, _ = sew(keep, 1e-7)
    rows.append(f"| general fuse + overshoots deleted by hand + sew | 0 (split at the "
                f"intersection) | {count_free_edges(tight)} | {is_valid(sewn)} | "
                f"{_crease_angle(cross):.3g} (the crease) | 0 | {t_occ:.3f} |")
    head = [("| two sheets cutting through each other | crossings left | free edges at "
             "1e-7 | valid | max normal angle across joins (deg) | deviation from the "
             "creased truth | time (s) |"), "|---|---|---|---|---|---|---|"]
    return head + rows


def _section_off(faces, x: float) -> int:
    """Points of OpenCascade's section of two faces (33 per section edge) farther than
    1e-6 from the plane ``x``: where they cross other than along their shared edge."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
    section = BRepAlgoAPI_Section(faces[0], faces[1])
    section.Build()
    assert section.IsDone()
    off, ex = 0, TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while ex.More():
        c = BRepAdaptor_Curve(TopoDS.Edge_s(ex.Current()))
        off += sum(abs(c.Value(t).X() - x) > 1e-6
                   for t in np.linspace(c.FirstParameter(), c.LastParameter(), 33))
        ex.Next()
    return off


def box_table() -> list[str]:
    """A unit box whose four walls run 0.1 above its lid and whose lid reaches 0.1
    beyond the walls (``tests/plugin/heal/test_crossings.overshooting_box``): surfprep
    heal (defaults) vs BOPAlgo_MakerVolume (OpenCascade's solid from intersecting faces)
    and vs sewing + ShapeFix at the same gap_tol."""
    from OCP.BOPAlgo import BOPAlgo_MakerVolume
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopTools import TopTools_ListOfShape
    cross = _crossing()

    faces = [make_face(f) for f in cross.overshooting_box(0.1, 1.1)]
    shape = cross.compound(faces)

    def volume(s) -> float:
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(s, props)
        return abs(float(props.Mass()))

    def area(s) -> float:
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(s, props)
        return float(props.Mass())
    rows = []
    for when in ("first", "second"):          # the first pays for loading the kernels
        start = time.perf_counter()
        r = surfprep.heal(shape)
        t = time.perf_counter() - start
        rows.append(f"| surfprep heal (defaults), {when} call in the process | "
                    f"{r.model.shape.ShapeType().name[7:].lower()} | "
                    f"{count_free_edges(r.model.shape)} | {r.valid_after} | "
                    f"{area(r.model.shape):.6g} | {volume(r.model.shape):.6g} | {t:.3f} |")
    start = time.perf_counter()
    maker = BOPAlgo_MakerVolume()
    args = TopTools_ListOfShape()
    for f in faces:
        args.Append(f)
    maker.SetArguments(args)
    maker.Perform()
    t = time.perf_counter() - start
    assert not maker.HasErrors()
    solid = maker.Shape()
    rows.append(f"| BOPAlgo_MakerVolume | {solid.ShapeType().name[7:].lower()} | "
                f"{count_free_edges(solid)} | {is_valid(solid)} | {area(solid):.6g} | "
                f"{volume(solid):.6g} | {t:.3f} |")
    start = time.perf_counter()
    fixed = ShapeFix_Shape(sew(faces, 1e-3)[0])
    fixed.Perform()
    t = time.perf_counter() - start
    rows.append(f"| sewing (1e-3) + ShapeFix_Shape | {fixed.Shape().ShapeType().name[7:].lower()} | "
                f"{count_free_edges(fixed.Shape())} | {is_valid(fixed.Shape())} | "
                f"{area(fixed.Shape()):.6g} | - | {t:.3f} |")
    head = [("| box, walls and lid overshooting each other by 0.1 | result | free edges | valid | "
             "area (truth 6) | volume (truth 1) | time (s) |"), "|---|---|---|---|---|---|---|"]
    return head + rows


def _crease_angle(cross) -> float:
    return float(np.degrees(np.arctan(cross.SLOPE)))


def table1_rows() -> list[str]:
    from surfprep.algorithms.healing import corners_boundary, local_approximant
    from surfprep.plugin.heal.cut import boundary_on_faces
    from surfprep.plugin.occ.faces import face_to_nurbs
    cross = _crossing()
    a, b = cross.sheet(0.0, 1.2, 0.0), cross.sheet(0.8, 2.0, cross.SLOPE)
    tfs = [face_to_nurbs(make_face(a)), face_to_nurbs(make_face(b))]
    bnd = boundary_on_faces(corners_boundary(*np.array(cross.corners())), tfs, 0.3)
    cells = []
    for m in (4, 6, 8, 10, 12):
        la = local_approximant(bnd, [a, b], resolution=(m, m), max_resolution=(m, m))
        cells.append(f"{1e3 * la.max_error:.3f}")
    return ["| 001 Table 1 (x 1e-3) | 4x4 | 6x6 | 8x8 | 10x10 | 12x12 |",
            "|---|---|---|---|---|---|",
            "| paper, Fig. 7 intersecting surfaces | 8.890 | 3.503 | 3.076 | 2.333 | 3.011 |",
            "| surfprep, two bent sheets crossing | " + " | ".join(cells) + " |"]


#: real files of ``files_table``: those ../shared/data/README.md describes as gappy (the
#: impeller, last, takes 13 to 18 minutes of the table's 20 to 25; name files to run fewer)
FILES = ("overture_heartvalve_rhino.igs", "occt_k1geo_microstation.stp",
         "occt_k1_catia_theorem.stp", "occt_k1geo_autocad.stp", "occt_k1_alias.stp",
         "overture_ship_napa_part5.igs", "occt_t4m_euclid.stp", "overture_kcs_hull_ideas.igs",
         "overture_asmo_icem.igs", "occt_spaceship_alias.stp", "occt_bearing_euclid.iges",
         "occt_hammer_euclid.iges", "occt_turbine_euclid.stp",
         "pyiges_impeller_solidworks.igs")


def _loops(result) -> str:
    """The report's loops of free edges counted by kind, how many were filled, and the
    rings (two loops beside each other all round) bridged."""
    loops = result.report().get("free_loops", [])
    if not loops:
        return "none"
    kinds = {}
    for lp in loops:
        kinds[lp["kind"]] = kinds.get(lp["kind"], 0) + 1
    filled = len({p.origin.index for p in result.patches if p.origin.kind == "hole"})
    rings = result.report().get("rings", [])
    bridged = (f"; {len(rings)} ring(s) of two loops, {sum(r['bridged'] for r in rings)} "
               "bridged" if rings else "")
    return ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) + f"; {filled} filled" \
        + bridged


def files_table(files=FILES) -> list[str]:
    from pathlib import Path

    from surfprep.plugin.io import read
    data = Path(__file__).resolve().parents[2] / "shared" / "data"
    head = [("| file | method | CPU (s) | wall (s) | free edges (gap_tol) | free edges at "
            "1e-7 x size | of which interior (widest gap) + open boundary | valid | max edge "
            "tolerance | loops of free edges | faces moved (largest turn) |"),
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    rows = []
    for name in files:
        path = data / name
        if not path.exists():
            continue
        cpu, wall = time.process_time(), time.perf_counter()
        r = surfprep.heal(path)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        kinds = r.extra.get("free_boundary", {})
        rows.append(f"| {name} | input | | | {r.free_edges_before} | "
                    f"{r.tight_free_edges_before} | {_kinds(kinds.get('before'))} | "
                    f"{r.valid_before} | | | |")
        rows.append(f"| | surfprep heal | {cpu:.1f} | {wall:.1f} | {r.free_edges_after} | "
                    f"{r.tight_free_edges_after} | {_kinds(kinds.get('after'))} | "
                    f"{r.valid_after} | "
                    f"{r.max_edge_tolerance:.2g} | {_loops(r)} | {_moved(r)} |")
        model = read(path)
        cpu, wall = time.process_time(), time.perf_counter()
        sewn, _ = sew(list(model.faces), r.gap_tol)
        fixer = ShapeFix_Shape(sewn)
        fixer.Perform()
        fixed = fixer.Shape()
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        # sewing moves no geometry: its faces' gaps are the input's (re-sewing its output
        # at 1e-7 would count shared edges, closed by tolerance, as closed)
        rows.append(f"| | Sewing(gap_tol) + ShapeFix | {cpu:.1f} | {wall:.1f} | "
                    f"{count_free_edges(fixed)} | {r.tight_free_edges_before} (input) | | "
                    f"{is_valid(fixed)} | {max_edge_tolerance(fixed):.2g} | | 0 |")
    return head + rows


def _kinds(free: dict | None) -> str:
    """The free edges in the geometry by kind, as the heal report's ``free_boundary``
    gives them: interior (along gaps, around holes; the widest gap) + open boundary."""
    if not free:
        return ""
    widest = f" ({free['widest_gap']:.2g})" if free["widest_gap"] is not None else ""
    return f"{free['interior']}{widest} + {free['edges']['open boundary']}"


def _moved(result) -> str:
    """How many faces closing gaps moved, and the largest angle by which one of them
    turned its tangent planes (degrees), as the heal report gives them."""
    closed = result.extra.get("closed_gaps")
    if not closed:
        return "0"
    faces = {m["face"] for m in closed["faces_moved"]}
    return f"{len(faces)} ({closed['largest_turn_deg']:.2g}°)" if faces else "0"


def main() -> None:
    import sys
    tables = (box_table, hole_table, nsided_table, gap_table, crossing_table, table1_rows,
              files_table)
    names = [a for a in sys.argv[1:] if "." not in a]
    # file names select the files of files_table: python benchmarks/heal.py files_table
    # overture_asmo_icem.igs
    files = tuple(a for a in sys.argv[1:] if "." in a) or FILES
    if names:                              # e.g. python benchmarks/heal.py crossing_table
        tables = tuple(t for t in tables if t.__name__ in names)
    for table in tables:
        for line in (table(files) if table is files_table else table()):
            print(line)
        print()


if __name__ == "__main__":
    main()
