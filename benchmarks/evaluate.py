"""Evaluation speed: surfprep's vectorized NURBS evaluation against OpenCascade, in one run.

For each surface, the same parameter values are evaluated by

* surfprep: ``NurbsSurface.derivatives(u, v, order)`` on scattered points and
  ``NurbsSurface.derivatives_grid(u, v, order)`` on a tensor grid (one call each);
* OpenCascade through OCP, once per point from Python (OCCT 7.9 has no batch
  evaluator): ``Geom_BSplineSurface.D0/D2`` (via ``occ_reference.evaluate_surface``)
  and ``GeomAdaptor_Surface.D0/D2``, which keeps a span cache (BSplSLib_Cache).

It prints wall times, microseconds per point, the agreement between the two
answers, our peak extra memory (tracemalloc), and the ratio OpenCascade / ours
(> 1: ours faster). Run:  python benchmarks/evaluate.py [--points N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from pathlib import Path

import numpy as np
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Pnt, gp_Vec

import surfprep
from surfprep.plugin import occ_reference
from surfprep.plugin.occ.geom import curve_to_occ, surface_to_occ

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


def best_time(fn, repeat: int) -> tuple[float, object]:
    """Smallest wall time of ``repeat`` calls, and the last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def peak_memory(fn) -> float:
    """Peak memory allocated by ``fn`` in MiB (tracemalloc, numpy arrays included)."""
    tracemalloc.start()
    fn()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def max_relative_difference(ours: np.ndarray, ref: np.ndarray) -> float:
    """Largest |ours - ref| per derivative, relative to that derivative's largest
    magnitude over the sample (entries OpenCascade does not give are NaN, skipped)."""
    diff = np.linalg.norm(ours - ref, axis=-1)
    size = np.linalg.norm(ref, axis=-1)
    axes = tuple(range(diff.ndim - (ref.ndim - 2)))   # the point axes
    given = ~np.all(np.isnan(size), axis=axes)        # derivatives OpenCascade gives
    scale = np.max(np.where(np.isnan(size), 0.0, size), axis=axes)[given]
    worst = np.max(np.where(np.isnan(diff), 0.0, diff), axis=axes)[given]
    return float(np.max(worst / np.where(scale > 0, scale, 1.0)))


def adaptor_loop(occ_surface, u, v, order: int) -> np.ndarray:
    """GeomAdaptor_Surface (span-cached) evaluation, one OCP call per point."""
    adaptor = GeomAdaptor_Surface(occ_surface)
    p, du, dv, duu, dvv, duv = gp_Pnt(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    out = np.empty((u.size, 3))
    for i, (a, b) in enumerate(zip(u.tolist(), v.tolist())):
        if order == 0:
            adaptor.D0(a, b, p)
        else:
            adaptor.D2(a, b, p, du, dv, duu, dvv, duv)
        out[i] = p.Coord()
    return out


def random_surface(rng, degree: tuple[int, int], n: tuple[int, int], rational: bool):
    def knots(k, p):
        inner = np.sort(rng.uniform(0.0, 1.0, k - p - 1))
        return np.r_[[0.0] * (p + 1), inner, [1.0] * (p + 1)]
    cp = rng.normal(size=n + (3,))
    w = rng.uniform(0.5, 2.0, n) if rational else None
    return surfprep.NurbsSurface(cp, knots(n[0], degree[0]), knots(n[1], degree[1]),
                                 degree[0], degree[1], w)


def real_surfaces() -> list[tuple[str, surfprep.NurbsSurface]]:
    """The B-spline face with the most poles from a few real files (when present)."""
    out = []
    for name in ("occt_fuselage.stp", "overture_kcs_hull_ideas.igs"):
        path = ROOT / "step_samples" / name
        path = path if path.exists() else DATA / name
        if not path.exists():
            continue
        model = surfprep.read(path)
        faces = [surfprep.to_nurbs(f).surface for f in model.faces]
        big = max(faces, key=lambda s: s.n_control[0] * s.n_control[1])
        out.append((f"{name} largest face", big))
    return out


def bench_surface(label: str, srf: surfprep.NurbsSurface, n_points: int, repeat: int,
                  rng) -> list[str]:
    u0, u1, v0, v1 = srf.domain
    u = rng.uniform(u0, u1, n_points)
    v = rng.uniform(v0, v1, n_points)
    side = int(np.sqrt(n_points))
    gu, gv = np.linspace(u0, u1, side), np.linspace(v0, v1, side)
    GU, GV = (a.reshape(-1) for a in np.meshgrid(gu, gv, indexing="ij"))
    occ = surface_to_occ(srf)
    rows = []
    shape = f"{srf.degree_u}x{srf.degree_v}, {srf.n_control[0]}x{srf.n_control[1]} poles" + (
        ", rational" if srf.weights is not None else "")
    for order in (0, 2):
        t_ours, ours = best_time(lambda: srf.derivatives(u, v, order), repeat)
        t_grid, grid = best_time(lambda: srf.derivatives_grid(gu, gv, order), repeat)
        t_geom, ref = best_time(lambda: occ_reference.evaluate_surface(occ, u, v, order), 1)
        t_adap, _ = best_time(lambda: adaptor_loop(occ, GU, GV, order), 1)
        mem = peak_memory(lambda: srf.derivatives(u, v, order))
        err = max_relative_difference(ours, ref)
        n_grid = GU.size
        rows.append(
            f"| {label} ({shape}) | D{order} | {n_points} | "
            f"{1e6 * t_ours / n_points:.3f} | {1e6 * t_grid / n_grid:.3f} | "
            f"{1e6 * t_geom / n_points:.2f} | {1e6 * t_adap / n_grid:.2f} | "
            f"**{t_geom / t_ours:.0f}x** | **{(t_adap / n_grid) / (t_grid / n_grid):.0f}x** | "
            f"{err:.1e} | {mem:.1f} |")
    return rows


def bench_curve(n_points: int, repeat: int, rng) -> list[str]:
    p, n = 5, 40
    knots = np.r_[[0.0] * (p + 1), np.sort(rng.uniform(0, 1, n - p - 1)), [1.0] * (p + 1)]
    crv = surfprep.NurbsCurve(rng.normal(size=(n, 3)), knots, p, rng.uniform(0.5, 2, n))
    t = rng.uniform(0, 1, n_points)
    occ = curve_to_occ(crv)
    rows = []
    for order in (0, 2):
        t_ours, ours = best_time(lambda: crv.derivatives(t, order), repeat)
        t_occ, ref = best_time(lambda: occ_reference.evaluate_curve(occ, t, order), 1)
        err = max_relative_difference(ours, ref)
        rows.append(f"| random curve (degree {p}, {n} poles, rational) | D{order} | {n_points} | "
                    f"{1e6 * t_ours / n_points:.3f} | – | {1e6 * t_occ / n_points:.2f} | – | "
                    f"**{t_occ / t_ours:.0f}x** | – | {err:.1e} | – |")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=40_000, help="points per case")
    parser.add_argument("--repeat", type=int, default=3, help="repeats of our (fast) calls")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    cases = [("random bicubic", random_surface(rng, (3, 3), (12, 12), False)),
             ("random rational", random_surface(rng, (5, 5), (10, 10), True))]
    cases += real_surfaces()
    print("| surface | eval | points | ours µs/pt | ours grid µs/pt | OCC Geom µs/pt "
          "| OCC Adaptor µs/pt | OCC Geom / ours | OCC Adaptor / ours grid | max rel. diff | ours peak MiB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, srf in cases:
        for row in bench_surface(label, srf, args.points, args.repeat, rng):
            print(row, flush=True)
    for row in bench_curve(args.points, args.repeat, rng):
        print(row, flush=True)


if __name__ == "__main__":
    main()
