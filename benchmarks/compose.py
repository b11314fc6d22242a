"""Two trivariate NURBS solids composed (004) against OpenCascade on their boundaries.

OpenCascade has no trivariate type; what a user of it would do is take each solid's
boundary as a B-rep solid (``surfprep.boundary_solid``, checked valid, volumes
within 1e-7 of the exact ones) and run its Booleans. Three pairs with exact answers:

* two balls of radius 5, 6 apart: the curve is the circle x = 3, radius 4; the
  common part is a lens of volume pi (4R + d)(2R - d)^2 / 12;
* a ball of radius 5 and the block [3, 7] x [-2, 2] x [-2, 2]: arcs of the sphere on
  the block's faces y = +-2, z = +-2; the common volume is the integral of
  sqrt(25 - y^2 - z^2) - 3 over the square (scipy ``dblquad`` to 1e-13);
* a torus R 3, r 1 and a ball of radius 1.5 at (3, 0, 0): the curve lies on both
  ``|p - c| = 1.5`` and ``(sqrt(x^2 + y^2) - 3)^2 + z^2 = 1`` (no closed-form volume:
  the two common volumes are compared with each other);
* two misaligned tori R 3, r 1 (004 Fig. 8), the second centred at (1, 0.5, 0.3)
  with its axis along (0.2, 0.1, 1): two loops on both tori's implicit equations.

Measured, each on the same solids, warm, best of 3:

* curves: ``surfprep.compose`` (the exterior faces intersected where their boxes
  overlap) vs ``BRepAlgoAPI_Section`` of the two boundary solids: time and the
  largest distance of the curve points (ours: the curves' points; OpenCascade: 50
  points per section edge) from the exact surfaces;
* volumes: ``Composition.volumes`` (the divergence theorem over the faces cut along
  our curves, in the math layer) vs ``BRepAlgoAPI_Common`` (``IsDone`` checked)
  integrated by ``BRepGProp.VolumeProperties`` at 1e-9: time and the error against
  the exact volume;
* classification of 2000 random points in the pair's box: ``Composition.classify``
  (Newton inversion into each solid) vs one ``BRepClass3d_SolidClassifier`` call per
  point and solid; disagreements between the two counted.

004's hierarchy (second table), on the same pairs: the counts per level (004 §7
reports 16 Bézier patches, 17 overlap boxes, 26 sub-patch triangulations and two
loops for its tori, whose placement it does not give), its time with the triangle
pairs found by the box-tree descent and by 004's kd-tree sweep (the same pairs; the
candidate stage alone in brackets), the loops' largest distance from the exact
surfaces, the surface--surface intersection's time for the same curves, and the
hierarchy's time per stage (level 1: the Bezier patches and their boxes; overlap
boxes with their sub-patches; tessellation; candidate pairs; segments and their
lists; triple-plane correction; merging the boxes' chains into loops).

Run:  python benchmarks/compose.py
"""

from __future__ import annotations

import time

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Section
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepGProp import BRepGProp
from OCP.gp import gp_Pnt
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_EDGE, TopAbs_IN, TopAbs_ON
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from scipy.integrate import dblquad

import surfprep
from surfprep.algorithms.composition.regions import region_volumes
from surfprep.algorithms.volume_builders import block, solid_sphere, solid_torus

REPEATS = 3
POINTS = 2000


def _sphere(centre, radius):
    return lambda p: np.abs(np.linalg.norm(p - np.asarray(centre), axis=1) - radius)


def _torus(major, minor):
    return lambda p: np.abs(np.hypot(np.hypot(p[:, 0], p[:, 1]) - major, p[:, 2]) - minor)


def _tilted_torus(centre, axis, major, minor):
    c, n = np.asarray(centre, float), np.asarray(axis, float) / np.linalg.norm(axis)

    def distance(p):
        q = p - c
        z = q @ n
        rho = np.linalg.norm(q - z[:, None] * n, axis=1)
        return np.abs(np.hypot(rho - major, z) - minor)
    return distance


def _block_faces(lo, hi):
    """Distance to the nearest face plane of the box (points on its surface)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return lambda p: np.min(np.abs(np.concatenate([p - lo, p - hi], axis=1)), axis=1)


def _ball_block_volume():
    value, _ = dblquad(lambda z, y: max(0.0, np.sqrt(max(25 - y * y - z * z, 0.0)) - 3.0),
                       -2, 2, -2, 2, epsabs=1e-13, epsrel=1e-13)
    return value


CASES = (
    ("two balls r 5, 6 apart", solid_sphere(5.0), solid_sphere(5.0, (6.0, 0.0, 0.0)),
     _sphere((0, 0, 0), 5), _sphere((6, 0, 0), 5), np.pi * 26 * 16 / 12),
    ("ball r 5 and a 4 x 4 x 4 block", solid_sphere(5.0),
     block((4.0, 4.0, 4.0), origin=(3.0, -2.0, -2.0)),
     _sphere((0, 0, 0), 5), _block_faces((3, -2, -2), (7, 2, 2)), None),
    ("torus R 3 r 1 and a ball r 1.5 on it", solid_torus(3.0, 1.0),
     solid_sphere(1.5, (3.0, 0.0, 0.0)), _torus(3, 1), _sphere((3, 0, 0), 1.5), None),
    ("two misaligned tori (004 Fig. 8)", solid_torus(3.0, 1.0),
     solid_torus(3.0, 1.0, (1.0, 0.5, 0.3), (0.2, 0.1, 1.0)), _torus(3, 1),
     _tilted_torus((1.0, 0.5, 0.3), (0.2, 0.1, 1.0), 3, 1), None),
)


def _best(run):
    best, out = np.inf, None
    for _ in range(REPEATS):
        start = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - start)
    return best, out


def _occ_volume(shape):
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-9)
    return props.Mass()


def _edge_points(shape, n=50):
    out, ex = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge_s(ex.Current()))
        for t in np.linspace(curve.FirstParameter(), curve.LastParameter(), n):
            p = curve.Value(t)
            out.append((p.X(), p.Y(), p.Z()))
        ex.Next()
    return np.array(out).reshape(-1, 3)


def _classify_occ(solid_a, solid_b, points, tol):
    labels = np.zeros(points.shape[0], int)
    for k, p in enumerate(points):
        for bit, solid in ((1, solid_a), (2, solid_b)):
            state = BRepClass3d_SolidClassifier(solid, gp_Pnt(*p), tol).State()
            if state in (TopAbs_IN, TopAbs_ON):
                labels[k] |= bit
    return labels


def _case(name, a, b, dist_a, dist_b, both) -> list[str]:
    """The three rows of one pair."""
    out = []
    if both is None and "block" in name:
        both = _ball_block_volume()
    ba, bb = surfprep.boundary_solid(a), surfprep.boundary_solid(b)
    t_ours, comp = _best(lambda: surfprep.compose(a, b))
    pts = np.concatenate([c.points for _, _, c in comp.curves]) if comp.curves else \
        np.empty((0, 3))
    dev_ours = float(max(dist_a(pts).max(), dist_b(pts).max())) if pts.size else float("nan")

    def section():
        s = BRepAlgoAPI_Section(ba.shape, bb.shape)
        s.Build()
        return s
    t_occ, sec = _best(section)
    occ_pts = _edge_points(sec.Shape()) if sec.IsDone() else np.empty((0, 3))
    dev_occ = float(max(dist_a(occ_pts).max(), dist_b(occ_pts).max())) if occ_pts.size \
        else float("nan")
    out.append(f"| {name} | curves | {t_ours:.3f} | {dev_ours:.2g} | {t_occ:.3f} | "
               f"{dev_occ:.2g} (IsDone {sec.IsDone()}) | {t_ours / t_occ:.1f} |")
    tv_ours, vol = _best(lambda: region_volumes(comp))

    def common():
        c = BRepAlgoAPI_Common(ba.shape, bb.shape)
        c.Build()
        return c
    tv_occ, com = _best(common)
    v_occ = _occ_volume(com.Shape()) if com.IsDone() else float("nan")
    if both is None:
        err_ours = f"{vol.both:.10g}"
        err_occ = f"{v_occ:.10g}"
    else:
        err_ours = f"{abs(vol.both / both - 1):.2g}"
        err_occ = f"{abs(v_occ / both - 1):.2g}"
    out.append(f"| | common volume | {tv_ours:.3f} | {err_ours} | {tv_occ:.3f} | "
               f"{err_occ} (IsDone {com.IsDone()}) | {tv_ours / tv_occ:.1f} |")
    box = np.vstack([a.bounding_box(), b.bounding_box()])
    points = np.random.default_rng(7).uniform(box.min(axis=0), box.max(axis=0), (POINTS, 3))
    tc_ours, labels = _best(lambda: comp.classify(points))
    tol = 1e-7 * float(np.linalg.norm(np.ptp(box, axis=0)))
    start = time.perf_counter()
    occ_labels = _classify_occ(ba.shape, bb.shape, points, tol)
    tc_occ = time.perf_counter() - start
    differ = int(np.count_nonzero(labels != occ_labels))
    out.append(f"| | classify {POINTS} points | {tc_ours:.3f} | {differ} label(s) differ | "
               f"{tc_occ:.3f} | | {tc_ours / tc_occ:.2f} |")
    return out


def rows() -> list[str]:
    out = [line for case in CASES for line in _case(*case)]
    head = [("| pair | task | surfprep s | surfprep: largest distance from the exact surfaces "
             "/ volume error | OpenCascade s | OpenCascade: the same | time ratio |"),
            "|---|---|---|---|---|---|---|"]
    return head + out


def _hierarchy_row(name, a, b, dist_a, dist_b) -> str:
    comp = surfprep.compose(a, b)
    t_ssi, _ = _best(lambda: surfprep.compose(a, b))
    timed = {}
    for candidates in ("descent", "sweep"):
        timed[candidates] = _best(lambda c=candidates: comp.build_hierarchy(candidates=c))
    h = timed["descent"][1]
    k = h.counts()
    pts = np.concatenate([lp.points for lp in h.loops]) if h.loops else np.empty((0, 3))
    dev = float(max(dist_a(pts).max(), dist_b(pts).max())) if pts.size else float("nan")
    stage = {c: t[1].times["candidates"] * 1e3 for c, t in timed.items()}
    return (f"| {name} | {k['bezier_patches_a']} / {k['bezier_patches_b']} | "
            f"{k['patch_box_pairs']} | {k['overlap_boxes']} | {k['subpatches']} | "
            f"{k['triangles']} | {k['closed_loops']} of {k['loops']} | {dev:.2g} | "
            f"{timed['descent'][0]:.3f} ({stage['descent']:.1f} ms) | "
            f"{timed['sweep'][0]:.3f} ({stage['sweep']:.1f} ms) | {t_ssi:.3f} | "
            + ", ".join(f"{k} {v * 1e3:.0f}" for k, v in h.times.items()) + " |")


def hierarchy_rows() -> list[str]:
    head = [("| pair | Bezier patches A / B | patch box pairs | overlap boxes | sub-patches | "
             "triangles | closed loops | loops' largest distance from the exact surfaces | "
             "hierarchy s, descent (candidates) | hierarchy s, kd-tree sweep (candidates) | "
             "SSI curves s | stages, descent (ms) |"),
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    return head + [_hierarchy_row(name, a, b, da, db) for name, a, b, da, db, _ in CASES]


def main() -> None:
    for line in rows():
        print(line)
    print()
    for line in hierarchy_rows():
        print(line)


if __name__ == "__main__":
    main()
