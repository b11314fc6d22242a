"""``surfprep compose --plot``: two composed solids as 004 draws them (Figs. 2 and 8) -- the
boundaries, the overlap boxes, the local triangulations under them and the loops."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .intersect import equal_extent
from .plotting import pyplot, save_figure

__all__ = ["plot_composition"]

#: iso-lines per direction drawn on each boundary face
ISO_LINES = 12
#: at most this many triangles of the local triangulations drawn (evenly thinned)
MAX_TRIANGLES = 6000

#: the 12 edges of a box as pairs of corner indices (corner k: bit 0 x, bit 1 y, bit 2 z)
_BOX_EDGES = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7),
              (0, 4), (1, 5), (2, 6), (3, 7)]


def _iso_lines(surface, n: int = ISO_LINES, samples: int = 60) -> list[np.ndarray]:
    u0, u1, v0, v1 = surface.domain
    s, t = np.linspace(u0, u1, samples), np.linspace(v0, v1, samples)
    lines = [surface.evaluate(np.full(samples, u), t) for u in np.linspace(u0, u1, n)]
    return lines + [surface.evaluate(s, np.full(samples, v)) for v in np.linspace(v0, v1, n)]


def _box_lines(box: np.ndarray) -> list[np.ndarray]:
    corners = np.array([[box[(k >> axis) & 1, axis] for axis in range(3)] for k in range(8)])
    return [corners[[i, j]] for i, j in _BOX_EDGES]


def _equal_axes(ax, points: np.ndarray) -> None:
    centre, half = equal_extent(points, 1e-9 * max(float(np.max(np.abs(points))), 1.0))
    for axis, c in zip("xyz", centre):
        getattr(ax, f"set_{axis}lim")(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")


def plot_composition(composition, path: Path) -> Path:
    """Draw ``composition`` (its :attr:`hierarchy`) to ``path``: the whole scene (boundary
    iso-lines of A in blue and B in orange, overlap boxes in grey, loops in red), the
    local triangulations under the overlap boxes with the loops, and the counts."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
    plt = pyplot()
    h = composition.hierarchy
    fig = plt.figure(figsize=(16, 6.5))
    whole = fig.add_subplot(1, 3, 1, projection="3d")
    everything = []
    for patches, colour in ((h.a, "tab:blue"), (h.b, "tab:orange")):
        lines = [line for s in patches.surfaces for line in _iso_lines(s)]
        everything.extend(lines)
        whole.add_collection3d(Line3DCollection(lines, colors=colour, linewidths=0.4, alpha=0.5))
    boxes = [edge for o in h.boxes for edge in _box_lines(o.box)]
    if boxes:
        whole.add_collection3d(Line3DCollection(boxes, colors="0.4", linewidths=0.5))
    for loop in h.loops:
        p = np.vstack([loop.points, loop.points[:1]]) if loop.closed else loop.points
        whole.plot(p[:, 0], p[:, 1], p[:, 2], color="red", lw=1.8)
    _equal_axes(whole, np.vstack(everything))
    whole.set_title(f"boundaries (A blue, B orange), {len(h.boxes)} overlap boxes, "
                    f"{len(h.loops)} loop(s)", fontsize="medium")
    local = fig.add_subplot(1, 3, 2, projection="3d")
    triangles = [m.vertices[m.triangles] for o in h.boxes for m in (o.mesh_a, o.mesh_b)]
    sides = [c for o in h.boxes for c in ("tab:blue", "tab:orange")]
    total = sum(t.shape[0] for t in triangles)
    step = max(1, -(-total // MAX_TRIANGLES))
    for tri, colour in zip(triangles, sides):
        if tri.shape[0]:
            local.add_collection3d(Poly3DCollection(tri[::step], facecolors=colour,
                                                    edgecolors="0.3", linewidths=0.1, alpha=0.35))
    for loop in h.loops:
        p = np.vstack([loop.points, loop.points[:1]]) if loop.closed else loop.points
        local.plot(p[:, 0], p[:, 1], p[:, 2], color="red", lw=1.8)
    if total:
        _equal_axes(local, np.vstack([t.reshape(-1, 3) for t in triangles if t.shape[0]]))
    local.set_title(f"local triangulations ({total} triangles"
                    + (f", 1 in {step} drawn" if step > 1 else "") + ") and loops",
                    fontsize="medium")
    note = fig.add_subplot(1, 3, 3)
    note.axis("off")
    counts = h.counts()
    text = [f"{k.replace('_', ' ')}: {v}" for k, v in counts.items()]
    text += ["", f"tol {h.tol:.3g}, mesh tol {h.mesh_tol:.3g}", f"candidates: {h.candidates}"]
    text += [f"{k}: {v * 1e3:.1f} ms" for k, v in h.times.items()]
    note.text(0.0, 1.0, "\n".join(text), va="top", family="monospace", fontsize="small")
    fig.tight_layout()
    return save_figure(fig, path)
