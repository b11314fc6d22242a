"""Surface-surface intersection (issue 3): ours against GeomAPI_IntSS, accuracy and scaling.

Part 1, exact pairs. Per pair and tolerance it runs, on the same B-spline
surfaces (analytic ones converted by OpenCascade, and a bicubic height field),

* ours: ``intersect_surfaces(a, b, tol=tol)`` (everything: tessellation,
  tracing, refinement, sampling, interpolants, the tolerance check);
* OpenCascade: ``GeomAPI_IntSS(a, b, tol)`` on the already converted
  ``Geom_BSplineSurface``s (``intersect_surfaces_occ``, curves sampled at
  only 2 points inside the timing; densely sampled again afterwards),

and prints the time of each (best of ``--repeat``), their ratio, the branches
found against the exact count (curves whose ends meet count as one), the
largest deviation of each answer from both surfaces (measured by us:
projection of our samples and three interpolant points per span, of 20 001
points per OpenCascade curve, onto both surfaces), and the coverage gap: the
largest distance from the exact curve (20 001+ samples) to the answer (to
our interpolants by Newton on ``curve3d``, to OpenCascade's dense polylines).

Part 2, scaling. A bicubic height field with n x n poles (n = 23 ... 323, the
same four-bump shape, so the curves keep their length) cut by a B-spline
plane and by a second bicubic n x n surface; our time, OpenCascade's, their
ratio and our sample count. OpenCascade's time grows about with the cube of n;
``--quick`` (the default) skips its runs above 163^2 poles, ``--full`` does them
(about 90 s at 323^2 against the plane).

Part 0, first call. The timings above are of warm processes (a warm-up call
first). Our kernels are compiled by numba on first use and cached on disk, so the
first call in a fresh process pays for loading them (cache present) or compiling
them (cache empty, e.g. a fresh checkout); printed beside OpenCascade's first call.

Run:  python benchmarks/ssi.py [--full] [--repeat 3] [--skip-cold]     (markdown tables)
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from intersect import bumpy, cylinder, deviation, flat, plane, sphere, torus
from intersect import densely as dense_points

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import (
    connected_branches,
    intersect_surfaces,
    polyline_distance,
)
from surfprep.plugin.occ.geom import surface_to_occ
from surfprep.plugin.occ_reference import intersect_surfaces_occ

TAU = 2 * np.pi
DENSE = 20001
OCC_QUICK_LIMIT = 163


# ------------------------------------------------------------------ exact curves
def circle(center, radius, normal_axis: int, n: int = DENSE) -> np.ndarray:
    t = np.linspace(0, TAU, n)
    axes = [i for i in range(3) if i != normal_axis]
    p = np.tile(np.asarray(center, float), (n, 1))
    p[:, axes[0]] += radius * np.cos(t)
    p[:, axes[1]] += radius * np.sin(t)
    return p


def two_cylinders(r_small: float, n: int = DENSE) -> list[np.ndarray]:
    t = np.linspace(0, TAU, n)
    y, z = r_small * np.cos(t), r_small * np.sin(t)
    x = np.sqrt(1 - y ** 2)
    return [np.stack([x, y, z], 1), np.stack([-x, y, z], 1)]


def ellipses(n: int = DENSE) -> list[np.ndarray]:
    t = np.linspace(0, TAU, n)
    return [np.stack([np.cos(t), np.sin(t), s * np.cos(t)], 1) for s in (1.0, -1.0)]


def viviani(n: int = 2 * DENSE) -> list[np.ndarray]:
    t = np.linspace(0, 2 * TAU, n)
    return [np.stack([1 + np.cos(t), np.sin(t), 2 * np.sin(t / 2)], 1)]


def level_curves(surface: NurbsSurface, level: float, grid: int = 801) -> list[np.ndarray]:
    """Exact level curves z = level of a height field: marching squares (contourpy)
    on a grid, each point then moved onto z = level by Newton along grad z."""
    import contourpy
    u = np.linspace(0, 1, grid)
    z = surface.evaluate(u[:, None], u[None, :])[..., 2]
    out = []
    for uv in contourpy.contour_generator(u, u, z.T).lines(level):
        uv = uv.copy()
        for _ in range(8):
            d = surface.derivatives(uv[:, 0], uv[:, 1], 1)
            g = np.stack([d[:, 1, 0, 2], d[:, 0, 1, 2]], 1)
            uv -= ((d[:, 0, 0, 2] - level) / np.einsum("ij,ij->i", g, g))[:, None] * g
        # densify: the curve between grid crossings by linear uv, Newton again
        s = np.linspace(0, 1, 9)[:-1]
        dense = (uv[:-1, None] * (1 - s)[None, :, None] + uv[1:, None] * s[None, :, None])
        dense = np.vstack([dense.reshape(-1, 2), uv[-1:]])
        for _ in range(8):
            d = surface.derivatives(dense[:, 0], dense[:, 1], 1)
            g = np.stack([d[:, 1, 0, 2], d[:, 0, 1, 2]], 1)
            dense -= ((d[:, 0, 0, 2] - level) / np.einsum("ij,ij->i", g, g))[:, None] * g
        out.append(surface.evaluate(dense[:, 0], dense[:, 1]))
    return out


def exact_pairs():
    """(name, a, b, exact curves, exact branch count)."""
    bump = bumpy(20)
    return [
        ("plane x sphere", plane(2, origin=(0, 0, 0.3)), sphere(1.0),
         [circle((0, 0, 0.3), np.sqrt(0.91), 2)], 1),
        ("cylinder x cylinder, r 1 / 0.5", cylinder(1.0, 1.5),
         cylinder(0.5, 2.0, normal=(1, 0, 0)), two_cylinders(0.5), 2),
        ("cylinder x cylinder, equal r", cylinder(1.0, 1.5), cylinder(1.0, 2.0, normal=(1, 0, 0)),
         ellipses(), 1),
        ("sphere x cylinder (Viviani)", sphere(2.0, normal=(0, 1, 0), xdir=(-1, 0, 0)),
         cylinder(1.0, 2.5, origin=(1, 0, 0)), viviani(), 1),
        ("torus x plane through axis", torus(2.0, 0.5, xdir=(1, 1, 0)), plane(3, normal=(0, 1, 0)),
         [circle((2, 0, 0), 0.5, 1), circle((-2, 0, 0), 0.5, 1)], 2),
        ("bumpy 20^2 x plane (4 loops)", bump, flat(0.2), level_curves(bump, 0.2), 4),
    ]


# ------------------------------------------------------------------ measuring
def best_time(fn, repeat: int):
    best, out = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - start)
        if best > 5.0:
            break
    return out, best


def coverage_gap(exact: list[np.ndarray], curves) -> float:
    if not curves:
        return float("inf")
    return float(polyline_distance(np.concatenate(exact), curves).max())


def occ_run(ga, gb, tol, repeat):
    """OpenCascade's time (curves sampled at 2 points inside it) and its dense curves."""
    _, t = best_time(lambda: intersect_surfaces_occ(ga, gb, tol, samples=2), repeat)
    return intersect_surfaces_occ(ga, gb, tol, samples=DENSE), t


def exact_rows(tols, repeat: int) -> list[dict]:
    rows = []
    for name, a, b, exact, truth in exact_pairs():
        ga, gb = surface_to_occ(a), surface_to_occ(b)
        for tol in tols:
            intersect_surfaces(a, b, tol=tol)                       # warm-up
            ours, t_ours = best_time(lambda a=a, b=b, tol=tol: intersect_surfaces(a, b, tol=tol),
                                     repeat)
            occ, t_occ = occ_run(ga, gb, tol, repeat)
            join = 1e3 * tol if tol >= 1e-9 else 1e-6
            rows.append({
                "case": name, "tol": tol, "t_ours": t_ours, "t_occ": t_occ,
                "ratio": t_ours / t_occ,
                "branches": f"{connected_branches(ours, join)} / {connected_branches(occ, join)} / {truth}",
                "samples": sum(c.points.shape[0] for c in ours),
                "dev_ours": deviation(dense_points(ours), a, b),
                "dev_occ": deviation(dense_points(occ), a, b),
                "cov_ours": coverage_gap(exact, ours),
                "cov_occ": coverage_gap(exact, occ),
            })
            print(f"  {name} tol {tol:g}: ours {t_ours:.3f} s, OCC {t_occ:.3f} s", flush=True)
    return rows


# ------------------------------------------------------------------ scaling
def wavy(n: int) -> NurbsSurface:
    """A second bicubic n x n surface crossing the bumps: z = 0.25 + 0.08 sin(5x) cos(4y)."""
    x = np.linspace(-0.05, 1.05, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    Z = 0.25 + 0.08 * np.sin(5 * X) * np.cos(4 * Y)
    k = np.concatenate([[0.0] * 3, np.linspace(0, 1, n - 2), [1.0] * 3])
    return NurbsSurface(np.stack([X, Y, Z], -1), k, k, 3, 3)


def scaling_rows(sizes, full: bool, repeat: int, tol: float = 1e-7) -> list[dict]:
    rows = []
    for n in sizes:
        a = bumpy(n)
        for other, b in (("plane", flat(0.2)), ("bicubic", wavy(n))):
            intersect_surfaces(a, b, tol=tol)                        # warm-up
            ours, t_ours = best_time(lambda a=a, b=b: intersect_surfaces(a, b, tol=tol),
                                     repeat if n <= 83 else 1)
            row = {"n": n, "other": other, "t_ours": t_ours,
                   "samples": sum(c.points.shape[0] for c in ours),
                   "branches_ours": connected_branches(ours, 1e3 * tol),
                   "length": sum(c.length for c in ours),
                   "t_occ": float("nan"), "branches_occ": "-"}
            if full or n <= OCC_QUICK_LIMIT:
                ga, gb = surface_to_occ(a), surface_to_occ(b)
                occ, t_occ = best_time(lambda ga=ga, gb=gb: intersect_surfaces_occ(
                    ga, gb, tol, samples=2001), 1)
                row["t_occ"], row["branches_occ"] = t_occ, connected_branches(occ, 1e3 * tol)
            rows.append(row)
            print(f"  {n}^2 x {other}: ours {t_ours:.3f} s, OCC {row['t_occ']:.3f} s",
                  flush=True)
    return rows


# ------------------------------------------------------------------ cold start
_FIRST_CALL = """
import sys, time
sys.path.insert(0, {bench!r})
from intersect import plane, sphere
a, b = plane(2, origin=(0, 0, 0.3)), sphere(1.0)
start = time.perf_counter()
if {occ}:
    from surfprep.plugin.occ.geom import surface_to_occ
    from surfprep.plugin.occ_reference import intersect_surfaces_occ
    ga, gb = surface_to_occ(a), surface_to_occ(b)
    start = time.perf_counter()
    intersect_surfaces_occ(ga, gb, 1e-7, samples=2)
else:
    from surfprep.algorithms.intersection import intersect_surfaces
    intersect_surfaces(a, b, tol=1e-7)
print(time.perf_counter() - start)
"""


def first_call(occ: bool, numba_cache: str | None = None) -> float:
    """Seconds of the first plane x sphere intersection in a fresh process (ours with
    its import; OpenCascade after converting the surfaces); ``numba_cache`` a numba
    cache folder (an empty one: the compiled kernels are built from scratch)."""
    import os
    import subprocess
    import sys
    env = dict(os.environ)
    if numba_cache is not None:
        env["NUMBA_CACHE_DIR"] = numba_cache
    code = _FIRST_CALL.format(bench=os.path.dirname(os.path.abspath(__file__)), occ=occ)
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                         capture_output=True, text=True)
    return float(out.stdout.strip().splitlines()[-1])


def cold_start_table() -> str:
    """First-call costs: ours with numba's cache emptied (every kernel compiled), ours
    with the cache in place (the normal case after the first run), OpenCascade."""
    import tempfile
    with tempfile.TemporaryDirectory() as empty:
        cold = first_call(False, empty)
    warm, occ = first_call(False), first_call(True)
    return ("| first plane x sphere call in a fresh process | s |\n|---|---|\n"
            f"| ours, numba cache empty (all kernels compiled) | {cold:.2f} |\n"
            f"| ours, numba cache present | {warm:.2f} |\n"
            f"| OpenCascade GeomAPI_IntSS | {occ:.3f} |")


# ------------------------------------------------------------------ tables
def exact_table(rows) -> str:
    lines = [("| case | tol | ours s | OCC s | ours/OCC | branches ours / OCC / exact | samples "
             "| max dev ours | max dev OCC | coverage gap ours | coverage gap OCC |"),
             "|" + "---|" * 11]
    for r in rows:
        lines.append(f"| {r['case']} | {r['tol']:.0e} | {r['t_ours']:.3f} | {r['t_occ']:.3f} | "
                     f"{r['ratio']:.2f} | {r['branches']} | {r['samples']} | "
                     f"{r['dev_ours']:.1e} | {r['dev_occ']:.1e} | {r['cov_ours']:.1e} | "
                     f"{r['cov_occ']:.1e} |")
    for tol in sorted({r["tol"] for r in rows}, reverse=True):
        ratios = np.array([r["ratio"] for r in rows if r["tol"] == tol])
        lines.append("")
        lines.append(f"tol {tol:.0e}: median time ratio ours/OCC {np.median(ratios):.2f} "
                     f"(min {ratios.min():.2f}, max {ratios.max():.2f})")
    return "\n".join(lines)


def scaling_table(rows) -> str:
    lines = [("| poles | cut by | ours s | OCC s | ours/OCC | branches ours / OCC | samples | "
             "curve length |"), "|" + "---|" * 8]
    for r in rows:
        ratio = r["t_ours"] / r["t_occ"] if np.isfinite(r["t_occ"]) else float("nan")
        occ = f"{r['t_occ']:.3f}" if np.isfinite(r["t_occ"]) else "skipped"
        lines.append(f"| {r['n']}^2 | {r['other']} | {r['t_ours']:.3f} | {occ} | "
                     f"{ratio:.3f} | {r['branches_ours']} / {r['branches_occ']} | "
                     f"{r['samples']} | {r['length']:.3f} |")
    for other in ("plane", "bicubic"):
        rs = [r for r in rows if r["other"] == other]
        if len(rs) >= 2:
            n = np.array([r["n"] for r in rs], float)
            t = np.array([r["t_ours"] for r in rs])
            slope = np.polyfit(np.log(n), np.log(t), 1)[0]
            occ = [(r["n"], r["t_occ"]) for r in rs if np.isfinite(r["t_occ"])]
            text = f"ours ~ n^{slope:.2f}"
            if len(occ) >= 2:
                no, to = np.array(occ, float).T
                text += f", OCC ~ n^{np.polyfit(np.log(no), np.log(to), 1)[0]:.2f}"
            lines.append("")
            lines.append(f"cut by {other}: time growth with poles per side n: {text}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true",
                        help="run OpenCascade on every size (about 90 s and more at 323^2)")
    parser.add_argument("--repeat", type=int, default=3, help="timing runs, best kept")
    parser.add_argument("--skip-exact", action="store_true")
    parser.add_argument("--skip-scaling", action="store_true")
    parser.add_argument("--skip-cold", action="store_true",
                        help="skip the first-call costs (fresh processes, numba compile)")
    args = parser.parse_args()
    if not args.skip_cold:
        print("\n## First call (JIT compile and cache load, not in the tables below)\n")
        print(cold_start_table())
    if not args.skip_exact:
        rows = exact_rows((1e-7, 1e-10), args.repeat)
        print("\n## Exact pairs\n")
        print(exact_table(rows))
    if not args.skip_scaling:
        rows = scaling_rows((23, 43, 83, 163, 323), args.full, args.repeat)
        print("\n## Scaling (bicubic height field n x n poles, tol 1e-7)\n")
        print(scaling_table(rows))


if __name__ == "__main__":
    main()
