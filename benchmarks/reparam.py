"""Chord-length reparametrization: surfprep's RCA method against two OpenCascade fits.

The same surfaces (three synthetic ones with known bad parametrizations and
faces 0, 2 and 4 of occt_fuselage.stp, 4 with creases) at the same tolerance
``tol`` (1e-4 of each surface's control-net diagonal):

* **ours**: ``surfprep.algorithms.reparam.reparametrize_surface``;
* **OCC points**: ``GeomAPI_PointsToBSplineSurface`` with ``Approx_ChordLength``,
  C2, degree 3..8, ``Tol3D = tol``, on the original sampled 10 x 10 per knot
  span (at least 41 x 41, uniform in the original parameters);
* **OCC approx**: ``GeomConvert_ApproxSurface`` of the original, C2 both ways,
  degree <= 8, ``Tol3d = tol`` (keeps the original parametrization).

Every result is measured the same way, by OUR closest-point projection (seeded,
not the method's own map): the result sampled 10 x 10 per knot span projected
onto the original, and the original sampled 10 x 10 per knot span (>= 200 per
direction) projected onto the result; the larger distance is reported
("max dev", OpenCascade's tolerance holds only at its sample points). Also the
worst chord-length mismatch (eqs. 29.1/29.2, 1 = perfect), the pole count and
the time (fit only, median of ``--repeat`` runs). Run:  python benchmarks/reparam.py
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from OCP.Approx import Approx_ParametrizationType
from OCP.BRep import BRep_Tool
from OCP.GeomAbs import GeomAbs_Shape
from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface
from OCP.GeomConvert import GeomConvert_ApproxSurface
from OCP.gp import gp_Pnt
from OCP.TColgp import TColgp_Array2OfPnt

import surfprep
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.parametrization import parametrization_quality
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.reparam import default_tolerance, reparametrize_surface
from surfprep.algorithms.reparam.deviation import subdivide
from surfprep.algorithms.reparam.rca import crease_knots
from surfprep.plugin.occ.geom import surface_from_occ, surface_to_occ

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


def _sheet(warp, n: int = 12) -> surfprep.NurbsSurface:
    t = np.linspace(0.0, 1.0, n)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    a, b = warp(uu, vv)
    points = np.stack([2 * a, 1.5 * b, 0.4 * np.sin(np.pi * a) * np.cos(0.8 * np.pi * (b - 0.5))], -1)
    return interpolate_surface(points, params_u=t, params_v=t)


def inputs() -> list[tuple[str, surfprep.NurbsSurface]]:
    cases = [
        ("sheet u^3", _sheet(lambda u, v: (u ** 3, v))),
        ("sheet clustered ends", _sheet(lambda u, v: (0.5 - 0.5 * np.cos(np.pi * u),
                                                      0.5 - 0.5 * np.cos(np.pi * v)))),
        ("sheet shear u^(1+1.5 sin pi v)", _sheet(lambda u, v: (u ** (1 + 1.5 * np.sin(np.pi * v)), v))),
    ]
    model = surfprep.read(DATA / "occt_fuselage.stp")
    for k in (0, 2, 4):              # 1, 3 mirror 0, 2; 4 has creases (5-7 are alike)
        surface = surface_from_occ(BRep_Tool.Surface_s(model.faces[k]))
        creased = any(c.size for c in crease_knots(surface))
        cases.append((f"fuselage face {k}" + (" (creases)" if creased else ""), surface))
    return cases


def _breaks(surface, axis: int) -> np.ndarray:
    knots = surface.knots_u if axis == 0 else surface.knots_v
    degree = surface.degree_u if axis == 0 else surface.degree_v
    n = surface.n_control[axis]
    return np.unique(knots[degree:n + 1])


def dense_grid(surface, per_span: int = 10, least: int = 41) -> tuple[np.ndarray, np.ndarray]:
    out = []
    for axis in (0, 1):
        breaks = _breaks(surface, axis)
        out.append(subdivide(breaks, max(per_span, -(-least // (len(breaks) - 1)))))
    return out[0], out[1]


def max_deviation(original, result) -> float:
    """Both ways, our seeded projection, 10 x 10 per knot span (see module docstring)."""
    forward = project_to_surface(original, result.evaluate_grid(*dense_grid(result)),
                                 n_seeds=1).distance.max()
    backward = project_to_surface(result, original.evaluate_grid(*dense_grid(original, least=200)),
                                  n_seeds=1).distance.max()
    return float(max(forward, backward))


def occ_points(original, tol: float):
    u, v = dense_grid(original)
    points = original.evaluate_grid(u, v)
    array = TColgp_Array2OfPnt(1, len(u), 1, len(v))
    for i in range(len(u)):
        for j in range(len(v)):
            array.SetValue(i + 1, j + 1, gp_Pnt(*points[i, j]))
    start = time.perf_counter()
    fit = GeomAPI_PointsToBSplineSurface()
    fit.Init(array, Approx_ParametrizationType.Approx_ChordLength, 3, 8, GeomAbs_Shape.GeomAbs_C2,
             tol)
    if not fit.IsDone():
        return None, time.perf_counter() - start
    surface = fit.Surface()
    return surface_from_occ(surface), time.perf_counter() - start


def occ_approx(original, tol: float):
    geom = surface_to_occ(original)
    start = time.perf_counter()
    approx = GeomConvert_ApproxSurface(geom, tol, GeomAbs_Shape.GeomAbs_C2,
                                       GeomAbs_Shape.GeomAbs_C2, 8, 8, 1000, 0)
    elapsed = time.perf_counter() - start
    if not (approx.IsDone() and approx.HasResult()):
        return None, elapsed
    return surface_from_occ(approx.Surface()), elapsed


def ours(original, tol: float):
    start = time.perf_counter()
    result = reparametrize_surface(original, tol=tol)
    return result.surface, time.perf_counter() - start


def _row(name, method, original, surface, seconds, tol):
    if surface is None:
        return {"case": name, "method": method, "dev": np.nan, "mismatch": np.nan,
                "poles": 0, "time": seconds, "tol": tol}
    return {"case": name, "method": method, "dev": max_deviation(original, surface),
            "mismatch": parametrization_quality(surface).worst,
            "poles": int(np.prod(surface.n_control)), "time": seconds, "tol": tol}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rel-tol", type=float, default=1e-4,
                        help="tolerance as a fraction of the control-net diagonal (default 1e-4)")
    parser.add_argument("--repeat", type=int, default=1, help="runs per fit (median time)")
    args = parser.parse_args()
    rows = []
    cases = inputs()
    ours(cases[0][1], default_tolerance(cases[0][1]))   # warm: kernels loaded (cold calls: cold.py)
    for name, original in cases:
        tol = default_tolerance(original) * args.rel_tol / 1e-4
        before = parametrization_quality(original).worst
        rows.append({"case": name, "method": "original", "dev": 0.0, "mismatch": before,
                     "poles": int(np.prod(original.n_control)), "time": 0.0, "tol": tol})
        for method, fit in (("ours (RCA)", ours), ("OCC PointsToBSplineSurface chord",
                                                   occ_points),
                            ("OCC GeomConvert_ApproxSurface", occ_approx)):
            runs = [fit(original, tol) for _ in range(args.repeat)]
            seconds = float(np.median([r[1] for r in runs]))
            rows.append(_row(name, method, original, runs[0][0], seconds, tol))
        print(f"done: {name}", flush=True)
    print()
    print("| case | method | max dev / tol | mismatch | poles | time s |")
    print("| --- | --- | ---: | ---: | ---: | ---: |")
    for r in rows:
        print(f"| {r['case']} | {r['method']} | {r['dev'] / r['tol']:.3g} | {r['mismatch']:.3g} "
              f"| {r['poles']} | {r['time']:.3f} |")
    print()
    print("ratios, ours / OCC (poles, time):")
    for name in dict.fromkeys(r["case"] for r in rows):
        mine = next(r for r in rows if r["case"] == name and r["method"].startswith("ours"))
        for r in rows:
            if r["case"] == name and r["method"].startswith("OCC") and r["poles"]:
                print(f"  {name} vs {r['method']}: poles {mine['poles'] / r['poles']:.2f}, "
                      f"time {mine['time'] / max(r['time'], 1e-9):.1f}x")


if __name__ == "__main__":
    main()
