"""Gmsh's transfinite quad grid of one face, in a process of its own (used by ``grid.py``).

Gmsh's Python module bundles its own OpenCascade, which must not be loaded into
a process that has OCP's, so ``benchmarks/grid.py`` runs this script once per
grid: ``python benchmarks/gmsh_transfinite.py SPEC.json``. The spec names the
file, the face (its index and area, to find Gmsh's surface), the face's four
corner points in surfprep's order (``(u0, v0)``, ``(u1, v0)``, ``(u0, v1)``,
``(u1, v1)``), the node counts ``ni`` (along u) and ``nj`` (along v), the
smoothing and where to write the nodes. The script

1. imports the file with ``gmsh.model.occ.importShapes`` and picks the surface
   of nearest area (reporting its relative area error and whether it is the one
   of the same index);
2. gives each bounding curve ``ni`` or ``nj`` nodes (``setTransfiniteCurve``,
   uniform), by matching the curve's end points with the corners (a curve
   without end points is the collapsed side named in the spec);
3. ``setTransfiniteSurface`` + ``setRecombine``, the smoothing (``"none"``;
   ``"option N"``: the global ``Mesh.Smoothing = N``, which runs ``N - 1`` sweeps
   of Gmsh's transfinite elliptic smoother; ``"face N"``:
   ``gmsh.model.mesh.setSmoothing(2, tag, N)``, N sweeps on this face only),
   then times ``gmsh.model.mesh.generate(2)`` (the median of ``repeat`` runs,
   the mesh cleared between them);
4. rebuilds Gmsh's structured node table ``(L + 1, H + 1, 3)`` from the quads
   (and, on a face with a collapsed side, the triangles at the pole) in the
   order Gmsh creates them, checks every element against it, and saves it as
   ``.npy`` in Gmsh's own i/j orientation (``grid.py`` turns it to surfprep's).

It prints one JSON line: the timings, the matching, the counts and the check.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np


def _point(tag: int) -> np.ndarray:
    import gmsh
    return np.asarray(gmsh.model.getValue(0, tag, []), dtype=float)


def _curve_nodes(curve: int, corners: np.ndarray, ni: int, nj: int, collapsed: list[str],
                 tol: float) -> tuple[int, str, float]:
    """Node count of a bounding curve: the side whose corners its end points are."""
    import gmsh
    ends = [p for _, p in gmsh.model.getBoundary([(1, curve)], oriented=False)]
    if len(ends) < 2:                               # a degenerated curve: the pole
        if not collapsed:
            raise RuntimeError(f"curve {curve} has no end points but no side is collapsed")
        side = collapsed[0]
        return (ni if side.startswith("j") else nj), side, 0.0
    a, b = _point(ends[0]), _point(ends[1])
    sides = {"j0": (0, 1, ni), "j1": (2, 3, ni), "i0": (0, 2, nj), "i1": (1, 3, nj)}
    best = None
    for name, (p, q, n) in sides.items():
        miss = min(max(np.linalg.norm(a - corners[p]), np.linalg.norm(b - corners[q])),
                   max(np.linalg.norm(a - corners[q]), np.linalg.norm(b - corners[p])))
        if best is None or miss < best[2]:
            best = (n, name, float(miss))
    if best[2] > tol:
        raise RuntimeError(f"curve {curve}: end points {a}, {b} miss the face's corners by {best[2]:.3g}")
    return best


def _table(tag: int) -> tuple[np.ndarray, dict]:
    """Gmsh's transfinite node table from the elements, in creation order, checked.

    Gmsh may reverse the elements afterwards (to follow the face's orientation):
    the table is tried with the elements as they are and reversed."""
    import gmsh
    types, _, nodes = gmsh.model.mesh.getElements(2, tag)
    elements = {}
    for t, conn in zip(types, nodes):
        name = gmsh.model.mesh.getElementProperties(t)[0]
        if not name.startswith(("Quadrilateral", "Triangle")):
            raise RuntimeError(f"unexpected element type {name}")
        elements[name[0]] = np.asarray(conn, dtype=np.int64).reshape(-1, 4 if name[0] == "Q" else 3)
    if "Q" not in elements:
        raise RuntimeError("no quadrangles")
    failures = []
    for reverse in (False, True):
        quads, tris = elements["Q"], elements.get("T")
        if reverse:
            quads = quads[:, [0, 3, 2, 1]]
            tris = None if tris is None else tris[:, [0, 2, 1]]
        try:
            points, info = _structured(tag, quads, tris)
        except (RuntimeError, ValueError, IndexError) as error:
            failures.append(f"{'reversed' if reverse else 'as created'}: {error}")
            continue
        info["reversed_elements"] = reverse
        return points, info
    raise RuntimeError("; ".join(failures))


def _structured(tag: int, quads: np.ndarray, tris: np.ndarray | None) -> tuple[np.ndarray, dict]:
    import gmsh
    n_quads, n_tris = len(quads), 0 if tris is None else len(tris)
    info = {"quads": n_quads, "triangles": n_tris}
    # H (cells along Gmsh's j): consecutive quads of one i-column share tab[i][j+1]
    if tris is None:
        H = next((k + 1 for k in range(n_quads - 1) if quads[k, 3] != quads[k + 1, 0]), n_quads)
        L = n_quads // H
        tab = np.zeros((L + 1, H + 1), dtype=np.int64)
        q = quads.reshape(L, H, 4)
        tab[:L, :H], tab[L, :H], tab[:L, H], tab[L, H] = q[:, :, 0], q[-1, :, 1], q[:, -1, 3], q[-1, -1, 2]
        first = 0
    else:                                           # 3 corners: triangles at the pole first
        H = n_tris
        L = n_quads // H + 1
        tab = np.zeros((L + 1, H + 1), dtype=np.int64)
        tab[0, :] = tris[0, 0]
        tab[1, :H], tab[1, H] = tris[:, 1], tris[-1, 2]
        q = quads.reshape(L - 1, H, 4)
        tab[1:L, :H], tab[L, :H], tab[1:L, H], tab[L, H] = q[:, :, 0], q[-1, :, 1], q[:, -1, 3], q[-1, -1, 2]
        first = 1
        if np.any(tris[:, 0] != tris[0, 0]) or np.any(tris[:, 1] != tab[1, :H]) \
                or np.any(tris[:, 2] != tab[1, 1:]):
            raise RuntimeError("pole triangles do not fit the table")
    if n_quads != (L - first) * H:
        raise RuntimeError(f"{n_quads} quads are not {L - first} x {H}")
    # every quad must be (tab[i][j], tab[i+1][j], tab[i+1][j+1], tab[i][j+1])
    want = np.stack([tab[first:-1, :-1], tab[first + 1:, :-1], tab[first + 1:, 1:],
                     tab[first:-1, 1:]], axis=-1).reshape(-1, 4)
    if not np.array_equal(want, quads):
        raise RuntimeError("quads do not form a structured grid in creation order")
    node_tags, coords, _ = gmsh.model.mesh.getNodes(2, tag, includeBoundary=True)
    xyz = dict(zip(np.asarray(node_tags, dtype=np.int64).tolist(),
                   np.asarray(coords, dtype=float).reshape(-1, 3)))
    missing = [t for t in np.unique(tab).tolist() if t not in xyz]
    if missing:
        raise RuntimeError(f"{len(missing)} table nodes have no coordinates")
    points = np.array([[xyz[t] for t in row] for row in tab.tolist()])
    unique = len(np.unique(tab[first:]))            # the pole row is one node
    info.update(L=int(L), H=int(H), unique_nodes=int(unique + (1 if first else 0)),
                mesh_nodes=len(xyz), corners=4 - first)
    if unique != (L + 1 - first) * (H + 1):
        raise RuntimeError("a node appears twice in the table")
    return points, info


def main() -> None:
    spec = json.loads(Path(sys.argv[1]).read_text())
    started = time.perf_counter()
    import gmsh
    out = {"ok": False}
    gmsh.initialize(["gmsh", "-nopopup"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.logger.start()
        t = time.perf_counter()
        gmsh.model.occ.importShapes(spec["file"])
        gmsh.model.occ.synchronize()
        out["import_s"] = time.perf_counter() - t
        surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
        areas = {tag: gmsh.model.occ.getMass(2, tag) for tag in surfaces}
        tag = min(surfaces, key=lambda s: abs(areas[s] - spec["area"]))
        out.update(tag=tag, n_surfaces=len(surfaces),
                   area_error=abs(areas[tag] - spec["area"]) / spec["area"],
                   same_index=surfaces.index(tag) == spec["index"])
        # mesh this face only: generate(2) meshes every entity of the model
        t = time.perf_counter()
        gmsh.model.occ.remove(gmsh.model.getEntities(3), recursive=False)
        gmsh.model.occ.remove([(2, s) for s in surfaces if s != tag], recursive=True)
        gmsh.model.occ.synchronize()
        out["isolate_s"] = time.perf_counter() - t
        left = [s for _, s in gmsh.model.getEntities(2)]
        if left != [tag] or abs(gmsh.model.occ.getMass(2, tag) - areas[tag]) > 1e-9 * areas[tag]:
            raise RuntimeError(f"isolating surface {tag} left surfaces {left}")
        out["entities_left"] = [len(gmsh.model.getEntities(d)) for d in range(4)]
        corners = np.asarray(spec["corners"], dtype=float)
        tol = 1e-4 * float(spec["diag"])
        curves = [abs(c) for _, c in gmsh.model.getBoundary([(2, tag)], oriented=False)]
        out["curves"] = {}
        for c in curves:
            n, side, miss = _curve_nodes(c, corners, spec["ni"], spec["nj"], spec["collapsed"], tol)
            gmsh.model.mesh.setTransfiniteCurve(c, n)
            out["curves"][str(c)] = [side, n, miss]
        corner_tags = []
        if spec["collapsed"]:
            # a collapsed side is a degenerated curve; Gmsh then finds 4 "corners" with the
            # pole twice and gives up: name the 3 corners, the pole first (Gmsh's tab[0][*])
            points = sorted({p for _, p in gmsh.model.getBoundary([(2, tag)], oriented=False,
                                                                   recursive=True)})
            side = {"i0": 0, "i1": 1, "j0": 0, "j1": 2}[spec["collapsed"][0]]
            pole = min(points, key=lambda p: np.linalg.norm(_point(p) - corners[side]))
            corner_tags = [pole] + [p for p in points if p != pole]
            out["corner_tags"] = corner_tags
        gmsh.model.mesh.setTransfiniteSurface(tag, cornerTags=corner_tags)
        gmsh.model.mesh.setRecombine(2, tag)
        kind, _, value = spec["smoothing"].partition(" ")
        if kind == "option":
            gmsh.option.setNumber("Mesh.Smoothing", int(value))
        elif kind == "face":
            gmsh.model.mesh.setSmoothing(2, tag, int(value))
        elif kind != "none":
            raise RuntimeError(f"unknown smoothing {spec['smoothing']!r}")
        times = []
        for run in range(int(spec.get("repeat", 1))):
            if run:
                gmsh.model.mesh.clear()
            t = time.perf_counter()
            gmsh.model.mesh.generate(2)
            times.append(time.perf_counter() - t)
        out["generate_s"], out["generate_runs_s"] = float(np.median(times)), times
        points, info = _table(tag)
        out.update(info)
        np.save(spec["out"], points)
        out["ok"] = True
    except Exception as error:  # noqa: BLE001 - gmsh raises Exception; grid.py prints it
        out["error"] = f"{type(error).__name__}: {error}"
    finally:
        log = gmsh.logger.get()
        out["log"] = [m for m in log if m.startswith(("Warning", "Error"))][:10]
        gmsh.finalize()
    out["script_s"] = time.perf_counter() - started
    print(json.dumps(out))


if __name__ == "__main__":
    main()
