"""Closest-point projection: surfprep's vectorized Newton against GeomAPI_ProjectPointOnSurf.

The same query points (scattered around each surface, some beyond its
boundary) are projected by

* surfprep: ``surfprep.algorithms.projection.project_to_surface`` (one call);
* OpenCascade: ``GeomAPI_ProjectPointOnSurf`` per point from Python
  (``occ_reference.project_point_on_surface``).

It prints both times, the ratio, and who found the closer foot point: the
distance difference ``ours - OCC`` (negative: ours closer), as the worst case
and the count of points where one is worse than the other by more than 1e-9 of
the model size. Run:  python benchmarks/projection.py [--points N]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import surfprep
from surfprep.algorithms.projection import project_to_surface
from surfprep.plugin import occ_reference
from surfprep.plugin.occ.geom import surface_to_occ

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


def query_points(srf: surfprep.NurbsSurface, n: int, rng) -> np.ndarray:
    """Points off the surface by up to 5 % of its size, 20 % of them beyond the boundary."""
    u0, u1, v0, v1 = srf.domain
    u = rng.uniform(u0, u1, n)
    v = rng.uniform(v0, v1, n)
    size = np.linalg.norm(np.ptp(srf.control_points.reshape(-1, 3), axis=0))
    offset = rng.normal(size=(n, 3)) * 0.05 * size
    points = srf.evaluate(u, v) + offset
    beyond = rng.random(n) < 0.2
    edge = srf.evaluate(np.full(beyond.sum(), u1), v[beyond])
    points[beyond] = edge + np.abs(rng.normal(size=(beyond.sum(), 3))) * 0.1 * size
    return points


def surfaces(rng) -> list[tuple[str, surfprep.NurbsSurface]]:
    def knots(k, p):
        return np.r_[[0.0] * (p + 1), np.sort(rng.uniform(0, 1, k - p - 1)), [1.0] * (p + 1)]
    def net(n, noise):
        g = np.linspace(0, 1, n)
        x, y = np.meshgrid(g, g, indexing="ij")
        return np.stack([x, y, np.zeros_like(x)], axis=-1) + noise * rng.normal(size=(n, n, 3))
    out = [("wavy bicubic 12x12", surfprep.NurbsSurface(net(12, 0.05), knots(12, 3), knots(12, 3),
                                                        3, 3)),
           ("rational 5x5, 10x10", surfprep.NurbsSurface(net(10, 0.1), knots(10, 5), knots(10, 5),
                                                         5, 5, rng.uniform(0.5, 2, (10, 10))))]
    for name in ("occt_fuselage.stp", "overture_kcs_hull_ideas.igs"):
        path = ROOT / "step_samples" / name
        path = path if path.exists() else DATA / name
        if path.exists():
            faces = [f.surface for f in surfprep.to_nurbs(surfprep.read(path))]
            big = max(faces, key=lambda s: s.n_control[0] * s.n_control[1])
            out.append((f"{name} largest face {big.n_control[0]}x{big.n_control[1]}", big))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=5000)
    args = parser.parse_args()
    rng = np.random.default_rng(7)
    print("| surface | points | ours s | OCC s | OCC / ours | worst (ours - OCC) / size "
          "| ours closer | OCC closer | ours not converged |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, srf in surfaces(rng):
        pts = query_points(srf, args.points, rng)
        size = np.linalg.norm(np.ptp(pts, axis=0))
        t0 = time.perf_counter()
        ours = project_to_surface(srf, pts)
        t_ours = time.perf_counter() - t0
        occ = surface_to_occ(srf)
        t0 = time.perf_counter()
        _, d_occ = occ_reference.project_point_on_surface(occ, pts)
        t_occ = time.perf_counter() - t0
        diff = (ours.distance - d_occ) / size
        print(f"| {label} | {args.points} | {t_ours:.3f} | {t_occ:.3f} | **{t_occ / t_ours:.1f}x** "
              f"| {diff.max():+.1e} | {(diff < -1e-9).sum()} | {(diff > 1e-9).sum()} "
              f"| {(~ours.converged).sum()} |", flush=True)


if __name__ == "__main__":
    main()
