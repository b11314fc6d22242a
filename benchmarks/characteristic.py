"""The characteristic-curve method (paper 002) against the triangle method and OpenCascade.

Per pair, in one run:

* ``mesh``: :func:`surfprep.algorithms.intersection.intersect_surfaces` alone;
* ``char``: :func:`surfprep.algorithms.characteristic.characteristic_intersection`,
  split into the characteristic stage (grid, side roots, characteristic curves,
  critical and turning points) and the intersection-curve stage (tracing eq. 33
  and refining to tol); the paper reports the first at 10-200 % of the second;
* ``auto``: what ``surfprep.intersect`` does by default (:func:`auto_intersection`):
  the characteristic stage, the triangle method (skipped when the stage finds the
  surfaces coincident over the whole grid; told the tangential curves the stage
  traced, so their fragments are left out), then the certificate
  (:func:`surfprep.algorithms.characteristic.certify`); the certificate's share
  (stage and finish) is its own column, and auto's cost is given as a ratio to
  ``mesh``;
* ``occ``: ``GeomAPI_IntSS(a, b, tol)``.

Branches found are counted against the truth of each construction (curves whose
ends meet count as one branch; an isolated contact point is reported apart).
Times are the best of ``REPEAT`` runs, the four methods interleaved.

Run:  python benchmarks/characteristic.py        (prints a markdown table)
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))          # the tests' operand builders (tests/helpers)

from helpers.surfaces import (
    degree_six_pair,
    flat_crossing,
    horizontal_plane,
    near_coincident,
    several_bumps,
    sphere_and_plane,
    torus_and_plane,
    touching_bumps,
)

from surfprep.algorithms.characteristic import (
    auto_intersection,
    characteristic_intersection,
)
from surfprep.algorithms.intersection import (
    StrayCurves,
    connected_branches,
    intersect_surfaces,
)
from surfprep.algorithms.projection import distance_to_surface
from surfprep.plugin.occ_reference import intersect_surfaces_occ

TOL = 1e-9
REPEAT = 5


def bumps_level() -> float:
    from scipy.optimize import minimize
    s = several_bumps()
    top = -minimize(lambda x: -s.evaluate(x[0], x[1])[2], [0.5, 0.72], method="Nelder-Mead",
                    options={"xatol": 1e-12, "fatol": 1e-16}).fun
    return top - 6e-6


def bumpy_flat():
    """The bumpy bicubic x plane of the SSI benchmark (issue 3): four loops."""
    from helpers.surfaces import bumps_net, height_field
    z = bumps_net(20, [(0.25, 0.25, 0.08, 0.5), (0.72, 0.3, 0.06, 0.45), (0.4, 0.7, 0.12, 0.6),
                       (0.8, 0.78, 0.05, 0.4)])
    return height_field(z), horizontal_plane(0.2)


def cases():
    """``(name, a, b, true branches, true contact points)``."""
    out = []
    for radius in (2e-2, 2e-3, 2e-4):
        a, b, _, _ = sphere_and_plane(radius)
        out.append((f"sphere x plane, loop r = {radius / 2:g} x size", a, b, 1, 0))
    a, b, _, _ = sphere_and_plane(0.0)
    out.append(("sphere tangent to plane", a, b, 0, 1))
    a, b, _ = touching_bumps()
    out.append(("two bicubic bumps touching", a, b, 0, 1))
    out.append(("3 bumps x plane, one loop 100x smaller", several_bumps(),
                horizontal_plane(bumps_level()), 3, 0))
    a, b = degree_six_pair()
    out.append(("degree 6 x degree 6, three loops", a, b, 3, 0))
    a, b = near_coincident(1e-4)
    out.append(("near-coincident quadratics (1e-4)", a, b, 1, 0))
    a, b = near_coincident(0.0)
    out.append(("coincident quadratics", a, b, 0, 0))
    a, b = bumpy_flat()
    out.append(("bumpy bicubic x plane (issue 3)", a, b, 4, 0))
    a, b = torus_and_plane(1e-6)
    out.append(("torus x plane normal to its axis, 1e-6 below the top", a, b, 2, 0))
    a, b = torus_and_plane(0.0)
    out.append(("torus x plane touching its top circle", a, b, 1, 0))
    for slope in (5e-4, 5e-3):
        a, b = flat_crossing(slope)
        out.append((f"sheets crossing at {slope:g} rad (wavy line)", a, b, 1, 0))
    return out


def best(*fns):
    """``[(value, best time)]`` of each function, the runs interleaved (one of each per
    repetition, ``REPEAT`` times): this shared machine's speed drifts by tens of per
    cent over seconds, and a ratio of two bests taken a minute apart drifts with it."""
    values, elapsed = [None] * len(fns), [np.inf] * len(fns)
    for _ in range(REPEAT):
        for i, fn in enumerate(fns):
            start = time.perf_counter()
            try:
                values[i] = fn()
            except Exception as exc:  # noqa: BLE001 - the row says what failed
                values[i] = exc
            elapsed[i] = min(elapsed[i], time.perf_counter() - start)
    return list(zip(values, elapsed))


def branches(curves) -> int | str:
    if isinstance(curves, Exception):
        return f"error ({type(curves).__name__})"
    return connected_branches(list(curves), 1e-6) if curves else 0


def auto_run(a, b):
    """``surfprep.intersect``'s default on one pair (``auto_intersection``), with the time
    its triangle method took inside: ``(record, seconds outside the triangles)``."""
    inside = [0.0]

    def triangles(tangential):
        start = time.perf_counter()
        curves = intersect_surfaces(a, b, tol=TOL, stray=StrayCurves.DROP, tangential=tangential)
        inside[0] += time.perf_counter() - start
        return curves

    start = time.perf_counter()
    record = auto_intersection(a, b, tol=TOL, triangles=triangles)
    return record, time.perf_counter() - start - inside[0]


def run_case(name, a, b, truth, contacts):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        (mesh, t_mesh), (char, _t_char), (auto, t_auto), (occ, t_occ) = best(
            lambda: intersect_surfaces(a, b, tol=TOL, stray=StrayCurves.DROP),
            lambda: characteristic_intersection(a, b, tol=TOL),
            lambda: auto_run(a, b),
            lambda: intersect_surfaces_occ(a, b, TOL))
        cert, t_cert = auto
    row = {
        "case": name, "truth": truth, "contacts": contacts,
        "mesh": branches(mesh), "t_mesh": t_mesh,
        "char": branches(char.curves), "char_contacts": len(char.isolated_points),
        "coincident": bool(char.coincident),
        "t_char_stage": char.characteristic_time_s, "t_curve_stage": char.intersection_time_s,
        "auto": branches(cert.curves), "auto_added": len(cert.added),
        "auto_contacts": len(cert.isolated_points), "t_auto": t_auto,
        "route": cert.extra.get("route", "-"),
        "t_cert": t_cert,
        "occ": branches(occ), "t_occ": t_occ,
        "occ_dev": occ_deviation(occ, a, b),
    }
    return row


def occ_deviation(curves, a, b) -> float:
    """Largest distance of OpenCascade's curve samples from either surface (by us)."""
    if isinstance(curves, Exception) or not curves:
        return float("nan")
    points = np.concatenate([c.points for c in curves])
    return float(max(distance_to_surface(a, points).max(), distance_to_surface(b, points).max()))


def table(rows) -> str:
    head = ("| pair | truth | mesh | char | auto (added) | auto route | OCC IntSS | OCC dev "
            "| char stage / curve stage | mesh s | certificate s | auto s (x mesh) | char s "
            "| OCC s |")
    lines = [head, "|" + "---|" * 14]
    for r in rows:
        truth = f"{r['truth']}" + (f" + {r['contacts']} pt" if r["contacts"] else "")
        char = f"{r['char']}" + (f" + {r['char_contacts']} pt" if r["char_contacts"] else "") \
            + (" + coincident region" if r["coincident"] else "")
        auto = f"{r['auto']} ({r['auto_added']})" + \
            (f" + {r['auto_contacts']} pt" if r["auto_contacts"] else "")
        stage = (f"{100 * r['t_char_stage'] / r['t_curve_stage']:.0f} %"
                 if r["char"] not in (0, "0") and r["t_curve_stage"] > 0 else "- (no curve)")
        lines.append(
            f"| {r['case']} | {truth} | {r['mesh']} | {char} | {auto} | {r['route']} "
            f"| {r['occ']} | {r['occ_dev']:.1e} | {stage} "
            f"| {r['t_mesh']:.3f} | {r['t_cert']:.3f} "
            f"| {r['t_auto']:.3f} ({r['t_auto'] / max(r['t_mesh'], 1e-9):.1f}x) "
            f"| {r['t_char_stage'] + r['t_curve_stage']:.3f} | {r['t_occ']:.3f} |")
    found = [r for r in rows if isinstance(r["auto"], int)]
    ratios = [r["t_auto"] / max(r["t_mesh"], 1e-9) for r in found if isinstance(r["mesh"], int)]
    lines.append("")
    lines.append(f"auto / mesh time: median {np.median(ratios):.2f}x, max {np.max(ratios):.2f}x; "
                 f"pairs where auto finds every branch: "
                 f"{sum(r['auto'] == r['truth'] for r in found)}/{len(rows)}, mesh: "
                 f"{sum(r['mesh'] == r['truth'] for r in rows)}/{len(rows)}, OCC: "
                 f"{sum(r['occ'] == r['truth'] for r in rows)}/{len(rows)}")
    # the aim: auto ahead of OpenCascade where OpenCascade finds everything
    full = [r for r in rows if r["occ"] == r["truth"] and r["truth"] and not r["contacts"]]
    if full:
        lines.append("where OCC finds every branch: " + "; ".join(
            f"{r['case']}: auto {r['t_auto']:.3f} s ({r['route']}) vs OCC {r['t_occ']:.3f} "
            f"({r['t_auto'] / max(r['t_occ'], 1e-9):.1f}x)"
            for r in full))
    return "\n".join(lines)


def main() -> None:
    rows = []
    for name, a, b, truth, contacts in cases():
        rows.append(run_case(name, a, b, truth, contacts))
        print(f"done: {name}", file=sys.stderr)
    print(table(rows))


if __name__ == "__main__":
    main()
