"""Table 1 of Hamann & Jean 1996 (paper 001) with our local approximant.

The paper gives the error of §7 (max over the points e, f, g of eq. 19, cells over
holes left out), times 1e-3, for geometries in a unit cube at sampling resolutions
4x4 ... 12x12. We build the same kinds of geometry (tests/helpers/heal_cases.py,
shared with the tests) and print ours beside theirs, with the RMS, the share of
artificial (filled) points, a dense check (the largest distance of a
61 x 61 grid of approximant points to the originals, holes left out) and the time.

Pure algorithms (no OpenCascade): there is no OpenCascade counterpart of one local
approximant; benchmarks/heal.py compares the healing against OpenCascade's fillers.

Run: ``python benchmarks/heal_table1.py``
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))   # tests/helpers

from helpers.heal_cases import (
    crossing_surfaces,
    envelope_boundary,
    iso_boundary,
    oscillating_surface,
    smooth_surface,
    stepped_gap,
    surrounding_patches,
)

from surfprep.algorithms.healing import Interpolant, local_approximant
from surfprep.algorithms.projection import distance_to_surface

RESOLUTIONS = (4, 6, 8, 10, 12)
PAPER = {
    "Fig. 5 part of a single patch": (0.377, 0.142, 0.074, 0.045, 0.119),
    "Fig. 6 with a hole": (35.262, 26.344, 26.534, 39.807, 31.183),
    "Fig. 6 gap with a 0.01 step": (35.262, 26.344, 26.534, 39.807, 31.183),
    "Fig. 7 intersecting surfaces": (8.890, 3.503, 3.076, 2.333, 3.011),
    "Fig. 8 highly oscillating": (14.515, 6.466, 3.434, 3.935, 3.526),
}
HOLE = (0.4, 0.6, 0.4, 0.6)
GAP = (0.45, 0.55, -1.0, 2.0)


def cases() -> dict:
    smooth = smooth_surface()
    wavy = oscillating_surface()
    crossing = crossing_surfaces()
    return {
        "Fig. 5 part of a single patch": (iso_boundary(smooth, 0.2, 0.8, 0.2, 0.8), [smooth],
                                          None),
        "Fig. 6 with a hole": (iso_boundary(smooth, 0.2, 0.8, 0.2, 0.8),
                               surrounding_patches(smooth, HOLE), HOLE),
        "Fig. 6 gap with a 0.01 step": (*stepped_gap(), GAP),
        "Fig. 7 intersecting surfaces": (envelope_boundary(0.2, 0.8, 0.2, 0.8), list(crossing),
                                         None),
        "Fig. 8 highly oscillating": (iso_boundary(wavy, 0.1, 0.9, 0.1, 0.9), [wavy], None),
    }


def dense_error(result, sources, hole) -> float:
    s = np.linspace(0.0, 1.0, 61)
    pts = result.surface.evaluate_grid(s, s).reshape(-1, 3)
    if hole is not None:               # the smooth surface's (u, v) are its (x, y)
        u0, u1, v0, v1 = hole
        pad = 0.05
        over = ((pts[:, 0] > u0 - pad) & (pts[:, 0] < u1 + pad)
                & (pts[:, 1] > v0 - pad) & (pts[:, 1] < v1 + pad))
        pts = pts[~over]
    return float(np.min([distance_to_surface(src, pts) for src in sources], axis=0).max())


def main() -> None:
    print("Errors x 1e-3 in a unit cube (001 Table 1 vs ours; max of eq. 19 points, holes "
          "left out)\n")
    header = "| geometry | row | " + " | ".join(f"{m}x{m}" for m in RESOLUTIONS) + " |"
    print(header)
    print("|" + "---|" * (2 + len(RESOLUTIONS)))
    for name, (boundary, sources, hole) in cases().items():
        rows = {"paper 001": [f"{x:.3f}" for x in PAPER[name]], "ours max": [],
                "ours RMS": [], "ours dense": [], "artificial %": [], "time s": []}
        for m in RESOLUTIONS:
            t0 = time.perf_counter()
            r = local_approximant(boundary, sources, resolution=(m, m), max_resolution=(m, m))
            dt = time.perf_counter() - t0
            rows["ours max"].append(f"{1e3 * r.max_error:.3f}")
            rows["ours RMS"].append(f"{1e3 * r.rms_error:.3f}")
            rows["ours dense"].append(f"{1e3 * dense_error(r, sources, hole):.3f}")
            rows["artificial %"].append(f"{100 * r.artificial_share:.1f}")
            rows["time s"].append(f"{dt:.2f}")
        for row, values in rows.items():
            print(f"| {name} | {row} | " + " | ".join(values) + " |")
    wavy = oscillating_surface()
    t0 = time.perf_counter()
    r = local_approximant(iso_boundary(wavy, 0.1, 0.9, 0.1, 0.9), [wavy], tol=1e-3)
    steps = ", ".join(f"{h.resolution[0]}x{h.resolution[1]}: {1e3 * h.max_error:.3f}"
                      for h in r.history)
    print(f"\nFig. 8 kind with tol = 1e-3 (resolution loop from 8x8): converged={r.converged} "
          f"at {r.resolution[0]}x{r.resolution[1]} in {time.perf_counter() - t0:.2f} s "
          f"({steps}, x 1e-3)")
    continuity()


def knot_jumps(surface, order: int) -> float:
    """Largest jump of the ``order``-th u- or v-derivative across the interior knot lines,
    from the one-sided values of the restricted surfaces (relative to the derivative's size)."""
    others = np.linspace(0.0, 1.0, 41)
    worst, size = 0.0, 0.0
    for knot in np.unique(surface.knots_u)[1:-1]:
        a = surface.restrict(None, knot, None, None).derivatives(knot, others, order)
        b = surface.restrict(knot, None, None, None).derivatives(knot, others, order)
        worst = max(worst, float(np.abs(a[:, order, 0] - b[:, order, 0]).max()))
        size = max(size, float(np.abs(a[:, order, 0]).max()))
    for knot in np.unique(surface.knots_v)[1:-1]:
        a = surface.restrict(None, None, None, knot).derivatives(others, knot, order)
        b = surface.restrict(None, None, knot, None).derivatives(others, knot, order)
        worst = max(worst, float(np.abs(a[:, 0, order] - b[:, 0, order]).max()))
        size = max(size, float(np.abs(a[:, 0, order]).max()))
    return worst / size


def continuity() -> None:
    smooth = smooth_surface()
    boundary = iso_boundary(smooth, 0.2, 0.8, 0.2, 0.8)
    print("\nC1 (001, triple knots) vs C2 (003) interpolant, part of a single patch at 8x8 "
          "(derivative jumps across knot lines measured on the surfaces, relative):\n")
    print("| interpolant | control net | max error x1e-3 | dense x1e-3 | 1st-derivative jump "
          "| 2nd-derivative jump |")
    print("|---|---|---|---|---|---|")
    for kind in Interpolant:
        r = local_approximant(boundary, [smooth], resolution=(8, 8), max_resolution=(8, 8),
                              interpolant=kind)
        print(f"| {kind.name} | {r.surface.n_control[0]}x{r.surface.n_control[1]} "
              f"| {1e3 * r.max_error:.3f} | {1e3 * dense_error(r, [smooth], None):.3f} "
              f"| {knot_jumps(r.surface, 1):.1e} | {knot_jumps(r.surface, 2):.1e} |")


if __name__ == "__main__":
    main()
