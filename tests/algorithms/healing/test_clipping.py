"""Trimmed faces as sources (:mod:`surfprep.algorithms.healing.clipping`): a face
trimmed narrow on a flat surface keeps a triangulation of its inside.

The chord tolerance alone triangulates a flat Bézier patch with two triangles;
a lens 4 mm wide on a 25 mm patch (the shape of occt_k1_catia_theorem.stp faces
0 and 57) then kept no triangle, or a few, and projections onto the face missed:
its approximant was filled where the face is and stayed 0.1 mm off it at every
resolution.
"""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.healing import SurfaceSource
from surfprep.algorithms.healing.approximant import local_approximant
from surfprep.algorithms.healing.clipping import TRIM_CELLS, trim_regions, trimmed_source
from surfprep.algorithms.surface import NurbsSurface

SIZE = 25.0
WIDTH = 0.08                     # the lens's half-width in v at its middle
A, B = 0.1, 0.9                  # its tips in u


def _flat() -> NurbsSurface:
    """x = 25 u, y = 25 v, z = 0: one bicubic Bézier patch (linear precision)."""
    g = np.linspace(0.0, 1.0, 4)
    gx, gy = np.meshgrid(g, g, indexing="ij")
    net = np.stack([SIZE * gx, SIZE * gy, np.zeros_like(gx)], axis=-1)
    knots = [0, 0, 0, 0, 1, 1, 1, 1]
    return NurbsSurface(net, knots, knots, 3, 3)


def _arc(u0: float, u1: float, sign: float, n: int = 65) -> np.ndarray:
    """(n, 2) float: ``v = 1/2 + sign WIDTH sin(pi (u - A) / (B - A))`` from u0 to u1."""
    u = np.linspace(u0, u1, n)
    return np.stack([u, 0.5 + sign * WIDTH * np.sin(np.pi * (u - A) / (B - A))], axis=-1)


def _lens_loop() -> np.ndarray:
    return np.concatenate([_arc(A, B, -1.0), _arc(B, A, 1.0)[1:]])


def test_trim_regions_resolve_the_loops_box():
    surface, loop = _flat(), _lens_loop()
    rects = trim_regions(surface, [loop])
    lo, hi = loop.min(axis=0), loop.max(axis=0)
    assert np.all(rects[:, 1] - rects[:, 0] <= (hi[0] - lo[0]) / TRIM_CELLS)
    assert np.all(rects[:, 3] - rects[:, 2] <= (hi[1] - lo[1]) / TRIM_CELLS)
    # they tile the box (disjoint dyadic pieces of the patch that cover it)
    area = np.sum((rects[:, 1] - rects[:, 0]) * (rects[:, 3] - rects[:, 2]))
    inner = np.clip(rects, np.repeat(lo, 2), np.repeat(hi, 2))         # [u0, u1, v0, v1]
    covered = np.sum((inner[:, 1] - inner[:, 0]) * (inner[:, 3] - inner[:, 2]))
    assert covered == pytest.approx(np.prod(hi - lo), rel=1e-12)
    assert area < 4 * np.prod(hi - lo)


def _area(source) -> float:
    tri = source.mesh.vertices[source.mesh.triangles]                    # (t, 3, 3)
    return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                axis=-1).sum()


def test_a_narrow_lens_keeps_its_inside():
    """Its area to 15 % by the triangles whose centroid is inside; with the triangles
    across the rim (the default) more, by at most a band of one triangle."""
    surface, loop = _flat(), _lens_loop()
    exact = 2 * WIDTH * (B - A) * 2 / np.pi * SIZE ** 2                  # 2 w (B - A) 2 / pi
    inside = trimmed_source(surface, [loop], straddle=False)
    assert _area(inside) == pytest.approx(exact, rel=0.15)
    centroids = inside.mesh.triangle_uv().mean(axis=1)
    v_edge = 0.5 + WIDTH * np.sin(np.pi * (centroids[:, 0] - A) / (B - A))
    assert np.all(np.abs(centroids[:, 1] - 0.5) <= np.abs(v_edge - 0.5) + 1e-12)
    across = trimmed_source(surface, [loop])
    assert exact < _area(across) < 1.5 * exact
    assert across.mesh.triangles.shape[0] > inside.mesh.triangles.shape[0]


def test_the_approximant_of_a_lens_lies_on_its_face():
    """Four sides (tip, middle of the lower arc, tip, middle of the upper arc): every
    segment lands on the face and the approximant is the plane, densely."""
    surface = _flat()
    source = SurfaceSource(surface, trimmed_source(surface, [_lens_loop()]).mesh)
    to3d = [surface.evaluate(c[:, 0], c[:, 1]) for c in (
        _arc(A, 0.5, -1.0), _arc(0.5, B, -1.0), _arc(B, 0.5, 1.0), _arc(0.5, A, 1.0))]
    result = local_approximant(to3d, [source], tol=0.014)
    assert result.converged and result.artificial_share == 0.0
    s = np.linspace(0.0, 1.0, 61)
    dense = result.surface.evaluate_grid(s, s)
    assert np.abs(dense[..., 2]).max() <= 0.014
