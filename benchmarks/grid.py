"""Structured surface grids: surfprep's ``grid_surface`` against Gmsh's transfinite quads.

The same face, the same node counts ``ni x nj`` (i along the surface's u), on
four faces at 41 x 41 and 201 x 201 nodes:

* **fuselage 0**: ``step_samples/occt_fuselage.stp`` face 0, a collapsed side
  (the pole at the nose);
* **catia4 L1**: ``step_samples/occt_catia4_face_L1.igs`` face 0, chord-length
  mismatch ~2900. The face is trimmed (47 edges); both tools grid its whole
  surface: Gmsh reads it from a temporary STEP file holding the untrimmed
  surface (written by ``surfprep.make_face`` + ``surfprep.write``);
* **KCS hull**: the largest untrimmed B-spline face of
  ``../shared/data/overture_kcs_hull_ideas.igs`` (by area; face 17);
* **NIST half cylinder**: ``../shared/data/nist_ctc_02_rc.stp`` face 1, an
  untrimmed half cylinder (the clean case).

Tools:

* **ours none / ours elliptic**: ``grid_surface(face.surface, dims=..., smooth=...)``
  (arc-length side nodes, distribution mesh; then elliptic refinement on the
  surface metric, by default with the lines leaving the sides at right angles;
  "sides free": ``orthogonal=False``, Thomas--Middlecoff control only). Time: in-process, warm (numba compiled), the call alone (median of
  ``--repeat`` calls, default 3);
  "whole call": a fresh ``python`` process that reads the file and grids the
  face (elliptic), as a user's one-shot script runs (numba's on-disk cache
  present, as on any run after the first).
* **Gmsh**: ``benchmarks/gmsh_transfinite.py`` in a fresh process (Gmsh bundles
  its own OpenCascade, which must not share a process with OCP):
  ``gmsh.model.occ.importShapes``, the surface of the same area, transfinite
  curves with ``ni`` / ``nj`` uniform nodes (matched to the corners),
  ``setTransfiniteSurface`` + ``setRecombine``, ``generate(2)``. Variants: no
  smoothing (TFI); ``Mesh.Smoothing = 10``, which for a transfinite surface
  runs ``10 - 1`` sweeps of Gmsh's transfinite elliptic (Winslow) smoother in
  the (u, v) plane (Gmsh has no ``Mesh.TransfiniteSmoothing`` option; see
  ``meshGFaceTransfinite.cpp``); and the same smoother for 1000 sweeps on that
  face (``gmsh.model.mesh.setSmoothing(2, tag, 1000)``), closer to converged.
  Time: ``generate(2)`` alone (median of ``--repeat`` runs in that process),
  and the whole subprocess (Python start, import, meshing, writing the nodes)
  as a user runs it. Gmsh meshes only that face (the other surfaces and
  volumes are removed first: ``generate`` meshes the whole model).

Every grid is measured by the same code, ``grid_quality(points, normals)`` on
the NurbsSurface's normals: Gmsh's nodes are projected onto the surface
(``project_to_surface``; the largest distance is reported, ours are on the
surface by construction) and its node table is turned to our i/j orientation by
matching the four corners (the boundary nodes of the two tools are then compared
as a check: both space them uniformly in arc length). Columns: orthogonality
(min/max angle between grid lines at the nodes, degrees), the sides' orthogonality
(largest angle off 90 degrees between a side and the lines leaving it, away from
the corners: farther than three nodes and ``0.1 (1 + 3 |cos(corner angle)|)`` of
the side), max equiangle
skewness, min scaled Jacobian, folded cells, max growth ratio, max node
distance to the surface (Gmsh), time; on the smoothed Gmsh rows the ratios ours
elliptic / that row for time and max skewness (below 1: ours faster / less skewed).

The elliptic refinement's exit residual and whether it converged are in the
notes column. Faster runs: ``--dims 41``, ``--repeat 1``.

Run:  python benchmarks/grid.py   (writes benchmarks/results/grid.txt; about 2 minutes)
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps

import surfprep
from surfprep.algorithms.grid import grid_quality, grid_surface
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.trimmed import is_natural

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
HELPER = Path(__file__).resolve().with_name("gmsh_transfinite.py")
RESULT = Path(__file__).resolve().parent / "results" / "grid.txt"

#: (label, file, face index or "largest untrimmed")
FACES = (
    ("fuselage 0 (pole)", ROOT / "step_samples" / "occt_fuselage.stp", 0),
    ("catia4 L1 (mismatch ~2900)", ROOT / "step_samples" / "occt_catia4_face_L1.igs", 0),
    ("KCS hull, largest untrimmed", DATA / "overture_kcs_hull_ideas.igs", "largest"),
    ("NIST half cylinder (clean)", DATA / "nist_ctc_02_rc.stp", 1),
)
DIMS = ((41, 41), (201, 201))
#: (label, smoothing passed to gmsh_transfinite.py)
GMSH = (("Gmsh TFI", "none"), ("Gmsh Mesh.Smoothing=10", "option 10"),
        ("Gmsh setSmoothing 1000", "face 1000"))

COLD = """
import sys, numpy as np, surfprep
from surfprep.algorithms.grid import grid_surface
path, k, ni, nj, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
face = surfprep.to_nurbs(surfprep.read(path).faces[k])
np.save(out, grid_surface(face.surface, dims=(ni, nj), smooth="elliptic").points)
"""


def area(face) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return props.Mass()


def load(path: Path, which, folder: Path) -> dict:
    """The face, its surface, and the file/index/area Gmsh is to find it by."""
    model = surfprep.read(path)
    if which == "largest":
        natural = [k for k, f in enumerate(model.faces) if is_natural(surfprep.to_nurbs(f))]
        which = max(natural, key=lambda k: area(model.faces[k]))
    face = surfprep.to_nurbs(model.faces[which])
    case = {"path": path, "index": which, "surface": face.surface,
            "gmsh_file": path, "gmsh_index": which, "gmsh_area": area(model.faces[which])}
    if not is_natural(face):            # Gmsh gets the whole surface, as grid_surface grids it
        untrimmed = surfprep.make_face(face.surface)
        case["gmsh_file"] = folder / f"{path.stem}_untrimmed.step"
        surfprep.write(untrimmed, case["gmsh_file"])
        case["gmsh_index"], case["gmsh_area"] = 0, area(untrimmed)
    s = face.surface
    u0, u1, v0, v1 = s.domain
    case["corners"] = s.evaluate(np.array([u0, u1, u0, u1]), np.array([v0, v0, v1, v1]))
    case["diag"] = float(np.linalg.norm(np.ptp(s.bounding_box(), axis=0)))
    return case


def run_gmsh(case: dict, dims, smoothing: str, collapsed, folder: Path,
             repeat: int) -> tuple[np.ndarray | None, dict]:
    out = folder / "gmsh_nodes.npy"
    out.unlink(missing_ok=True)
    spec = {"file": str(case["gmsh_file"]), "index": case["gmsh_index"], "area": case["gmsh_area"],
            "corners": case["corners"].tolist(), "diag": case["diag"], "ni": dims[0],
            "nj": dims[1], "collapsed": list(collapsed), "smoothing": smoothing, "out": str(out),
            "repeat": repeat}
    spec_file = folder / "gmsh_spec.json"
    spec_file.write_text(json.dumps(spec))
    start = time.perf_counter()
    done = subprocess.run([sys.executable, str(HELPER), str(spec_file)], capture_output=True,
                          text=True, check=False)
    wall = time.perf_counter() - start
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
    meta = json.loads(lines[-1]) if lines else {"ok": False, "error": done.stderr[-500:]}
    meta["wall_s"] = wall
    return (np.load(out) if meta.get("ok") else None), meta


def orient(raw: np.ndarray, ours: np.ndarray) -> tuple[np.ndarray, float]:
    """Gmsh's table turned to our (i, j): the transpose/flips whose corners match ours."""
    best = None
    for transpose in (False, True):
        grid = raw.transpose(1, 0, 2) if transpose else raw
        if grid.shape != ours.shape:
            continue
        for fi in (False, True):
            for fj in (False, True):
                g = grid[::-1] if fi else grid
                g = g[:, ::-1] if fj else g
                miss = max(np.linalg.norm(g[a, b] - ours[a, b]) for a in (0, -1) for b in (0, -1))
                if best is None or miss < best[1]:
                    best = (np.ascontiguousarray(g), miss)
    if best is None:
        raise RuntimeError(f"Gmsh's table {raw.shape[:2]} does not fit {ours.shape[:2]}")
    return best


def boundary_gap(a: np.ndarray, b: np.ndarray) -> float:
    return float(max(np.abs(a[0] - b[0]).max(), np.abs(a[-1] - b[-1]).max(),
                     np.abs(a[:, 0] - b[:, 0]).max(), np.abs(a[:, -1] - b[:, -1]).max()))


def measure(surface, points: np.ndarray):
    """``grid_quality`` on the surface's normals at the closest points, and the distance."""
    foot = project_to_surface(surface, points, n_seeds=1)
    normals = surface.normals(foot.uv[..., 0], foot.uv[..., 1])
    return grid_quality(points, normals), float(foot.distance.max())


def cold_ours(case: dict, dims, folder: Path) -> float:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", COLD, str(case["path"]), str(case["index"]),
                           str(dims[0]), str(dims[1]), str(folder / "ours_nodes.npy")],
                          capture_output=True, text=True, check=False)
    if done.returncode:
        raise RuntimeError(done.stderr[-1000:])
    return time.perf_counter() - start


def side_angle_off(points: np.ndarray) -> float:
    """Largest angle (degrees) off 90 between a side and the lines leaving it (one-sided across
    the side, central along it), away from the corners, whose angles are the face's: farther
    than three nodes and than ``0.1 (1 + 3 |cos(corner angle)|)`` of the side's length (the
    blend of ``surfprep.algorithms.grid.orthogonal``). A collapsed side (a pole) is left out."""
    worst = 0.0
    views = (points, points[:, ::-1], np.swapaxes(points, 0, 1), np.swapaxes(points, 0, 1)[:, ::-1])
    longest = max(float(np.linalg.norm(np.diff(v[:, 0], axis=0), axis=1).sum()) for v in views)
    for view in views:
        side = view[:, 0]
        run = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(side, axis=0), axis=1))])
        if run[-1] <= 1e-9 * longest:
            continue
        with np.errstate(invalid="ignore", divide="ignore"):
            along, across = side[2:] - side[:-2], view[1:-1, 1] - side[1:-1]
            cos = np.einsum("ij,ij->i", along, across) / np.linalg.norm(along, axis=1) \
                / np.linalg.norm(across, axis=1)
            ends = [abs(float(np.dot(leg, view[i, 1] - view[i, 0]) / np.linalg.norm(leg)
                              / np.linalg.norm(view[i, 1] - view[i, 0])))
                    for i, leg in ((0, side[1] - side[0]), (-1, side[-1] - side[-2]))]
        ends = np.nan_to_num(ends)
        s = run[1:-1] / run[-1]
        k = np.arange(1, view.shape[0] - 1)
        inside = (s > 0.1 * (1 + 3 * ends[0])) & (1 - s > 0.1 * (1 + 3 * ends[1])) & (k >= 3) \
            & (k <= view.shape[0] - 4) & np.isfinite(cos)
        if inside.any():
            worst = max(worst, float(np.abs(np.degrees(np.arccos(np.clip(cos[inside], -1, 1))) - 90).max()))
    return worst


def row(label, tool, q, dist, seconds, whole, note="", ratio=("", "", ""), side=None) -> str:
    side = "" if side is None else f"{side:.1f}"
    return (f"| {label} | {tool} | {q.min_angle:.1f} | {q.max_angle:.1f} | {side} | {q.max_skewness:.3f} | "
            f"{q.min_scaled_jacobian:.3f} | {q.folded_cells} | {q.max_growth_ratio:.2f} | {dist} | "
            f"{seconds:.3f} | {whole} | {ratio[0]} | {ratio[1]} | {ratio[2]} | {note} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dims", type=int, nargs="+", default=[d[0] for d in DIMS],
                        help="square node counts to run (default 41 201)")
    parser.add_argument("--repeat", type=int, default=3,
                        help="in-process runs per grid, median time (default 3)")
    parser.add_argument("--no-write", action="store_true", help="do not write results/grid.txt")
    args = parser.parse_args()
    started = time.perf_counter()
    out: list[str] = []

    def say(line: str = "") -> None:
        print(line, flush=True)
        out.append(line)

    rows, checks = [], []
    with tempfile.TemporaryDirectory(prefix="surfprep_grid_") as tmp:
        folder = Path(tmp)
        warm = load(FACES[0][1], FACES[0][2], folder)["surface"]
        grid_surface(warm, dims=(9, 9))                 # compile the kernels outside the timings
        for label, path, which in FACES:
            case = load(path, which, folder)
            surface = case["surface"]
            name = f"{label} [{path.name} #{case['index']}]"
            for n in args.dims:
                dims = (n, n)
                tag = f"{name} {n}x{n}"
                ours, seconds = {}, {}
                for smooth, orthogonal in (("none", True), ("plain", False), ("elliptic", True)):
                    runs = [grid_surface(surface, dims=dims, smooth="none" if smooth == "none" else "elliptic",
                                         orthogonal=orthogonal) for _ in range(args.repeat)]
                    ours[smooth], seconds[smooth] = runs[0], float(np.median([r.time_s for r in runs]))
                ell = ours["elliptic"]
                whole_ours = cold_ours(case, dims, folder)
                rows.append(row(tag, "ours none", ours["none"].quality, "on", seconds["none"], "",
                                side=side_angle_off(ours["none"].points)))
                for kind, label in (("plain", "ours elliptic, sides free"), ("elliptic", "ours elliptic")):
                    e = ours[kind].elliptic
                    note = (f"{'converged' if e.converged else 'NOT converged'}, {e.sweeps} sweeps, "
                            f"residual {e.residuals[-1]:.2g}")
                    if ours[kind].orthogonal_dropped:
                        note += f"; {ours[kind].orthogonal_dropped}"
                    rows.append(row(tag, label, ours[kind].quality, "on", seconds[kind],
                                    f"{whole_ours:.2f}" if kind == "elliptic" else "", note,
                                    side=side_angle_off(ours[kind].points)))
                tfi = None
                for tool, smoothing in GMSH:
                    raw, meta = run_gmsh(case, dims, smoothing, ell.collapsed_sides, folder,
                                         args.repeat)
                    if raw is None:
                        rows.append(f"| {tag} | {tool} | failed: {meta.get('error')} "
                                    f"{' '.join(meta.get('log', []))} |" + " |" * 14)
                        continue
                    points, corner_miss = orient(raw, ell.points)
                    q, dist = measure(surface, points)
                    note = []
                    if meta.get("corners") == 3:
                        note.append("3-corner TFI (pole)")
                    if smoothing == "none":
                        tfi = points
                    elif tfi is not None and np.array_equal(points, tfi):
                        note.append("nodes identical to Gmsh TFI: the smoother did not run")
                    if meta.get("log"):
                        note.append("; ".join(meta["log"]))
                    if corner_miss > 1e-6 * case["diag"]:
                        note.append(f"corners off ours by {corner_miss / case['diag']:.1e} diag")
                    ratio = ("", "", "")
                    if smoothing != "none":
                        ratio = (f"{seconds['elliptic'] / meta['generate_s']:.2f}",
                                 f"{whole_ours / meta['wall_s']:.2f}",
                                 f"{ell.quality.max_skewness / q.max_skewness:.2f}"
                                 if q.max_skewness > 1e-3 else "both ~0")
                    rows.append(row(tag, tool, q, f"{dist:.1e}", meta["generate_s"],
                                    f"{meta['wall_s']:.2f}", ", ".join(note), ratio,
                                    side=side_angle_off(points)))
                    if smoothing == "none":
                        checks.append(
                            f"{tag}: Gmsh surface {meta['tag']} of {meta['n_surfaces']} "
                            f"(same index: {meta['same_index']}, area error {meta['area_error']:.1e}; meshed "
                            f"alone: {'/'.join(map(str, meta['entities_left']))} points/curves/"
                            f"surfaces/volumes left), "
                            f"curves {' '.join(f'{c}={v[0]}:{v[1]}' for c, v in meta['curves'].items())}, "
                            f"{meta['quads']} quads + {meta['triangles']} triangles, table "
                            f"{meta['L'] + 1}x{meta['H'] + 1} checked; corners off by "
                            f"{corner_miss / case['diag']:.1e} diag, boundary nodes off ours by "
                            f"{boundary_gap(points, ell.points) / case['diag']:.1e} diag")
                print(f"done: {tag} ({time.perf_counter() - started:.0f} s)", flush=True)
    say(f"Gmsh {importlib.metadata.version('gmsh')}; surfprep {surfprep.__version__}; one process at a "
        f"time; times in s: 'time (call)' the median of {args.repeat} in-process runs (grid_surface / "
        "Gmsh's generate(2)), 'whole call' one fresh process (read + grid + save)")
    say()
    say("| face, nodes | tool | min angle | max angle | sides off 90 | max skew | min scaled Jac | folded | "
        "max growth | max dist to surface | time (call) | whole call | time ratio ours ell / this "
        "(call) | (whole call) | skew ratio ours ell / this | notes |")
    say("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for line in rows:
        say(line)
    say()
    say("Checks (Gmsh's face and node table; distances relative to the surface's box diagonal):")
    for line in checks:
        say(f"- {line}")
    say()
    say(f"total {time.perf_counter() - started:.0f} s")
    if not args.no_write:
        RESULT.write_text("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
