"""Geometry of the local-approximant tests and of benchmarks/heal_table1.py: the kinds of
001's Figs. 5-8 (part of a single patch, a hole, intersecting surfaces, a highly
oscillating surface), all in the unit cube as in Table 1."""

from __future__ import annotations

import numpy as np
from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.intersection.mesh import TriangleMesh
from surfprep.algorithms.intersection.tessellation import tessellate
from surfprep.algorithms.tensor import Direction
from surfprep.algorithms.surface import NurbsSurface


def graph_surface(height, samples: int = 13) -> NurbsSurface:
    """Bicubic interpolant of ``z = height(x, y)`` over the unit square, ``(u, v) = (x, y)``
    at the samples."""
    s = np.linspace(0.0, 1.0, samples)
    x, y = np.meshgrid(s, s, indexing="ij")
    return interpolate_surface(np.stack([x, y, height(x, y)], axis=-1), params_u=s, params_v=s)


def smooth_surface() -> NurbsSurface:
    """A gently curved patch (001 Fig. 5 kind)."""
    return graph_surface(lambda x, y: 0.3 + 0.15 * np.sin(2.5 * x + 0.5) * np.cos(2.0 * y - 0.3),
                         samples=9)


def oscillating_surface() -> NurbsSurface:
    """Several waves in each direction (001 Fig. 8 kind)."""
    return graph_surface(lambda x, y: 0.5 + 0.04 * np.sin(5 * np.pi * x) * np.sin(4 * np.pi * y),
                         samples=41)


def iso_boundary(surface: NurbsSurface, u0: float, u1: float, v0: float, v1: float) -> list:
    """Four isocurves of ``surface`` bounding ``[u0, u1] x [v0, v1]``, bottom, right, top, left
    (top and left in the surface's directions: the boundary orients them)."""
    sub = surface.restrict(u0, u1, v0, v1)
    return [sub.isocurve(v0, Direction.V), sub.isocurve(u1, Direction.U),
            sub.isocurve(v1, Direction.V), sub.isocurve(u0, Direction.U)]


def surrounding_patches(surface: NurbsSurface, hole: tuple) -> list[NurbsSurface]:
    """Four patches of ``surface`` around the parameter rectangle ``hole`` (a hole in it)."""
    u0, u1, v0, v1 = hole
    return [surface.restrict(None, u0, None, None), surface.restrict(u1, None, None, None),
            surface.restrict(u0, u1, None, v0), surface.restrict(u0, u1, v1, None)]


def holed_mesh(surface: NurbsSurface, hole: tuple, tol: float = 2e-4) -> TriangleMesh:
    """Triangulation of ``surface`` with the triangles over ``hole`` cut out (with uv)."""
    mesh = tessellate(surface, tol).mesh
    c = mesh.triangle_uv().mean(axis=1)
    u0, u1, v0, v1 = hole
    inside = (c[:, 0] > u0) & (c[:, 0] < u1) & (c[:, 1] > v0) & (c[:, 1] < v1)
    return TriangleMesh.from_arrays(mesh.vertices, mesh.triangles[~inside], mesh.uv)


def _rising(x, y):
    return 0.45 + 0.35 * (x - 0.5) + 0.24 * y * (1.0 - y)


def _falling(x, y):
    return 0.45 - 0.35 * (x - 0.5) + 0.08 * (y - 0.5) ** 2


def crossing_surfaces() -> tuple[NurbsSurface, NurbsSurface]:
    """Two surfaces cutting through each other along a curve near ``x = 0.5`` (001 Fig. 7):
    one rising, one falling in x; their upper envelope has a crease there. Both heights
    are polynomials the bicubic interpolants reproduce exactly."""
    return graph_surface(_rising, samples=7), graph_surface(_falling, samples=7)


def upper_envelope(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Height of the upper envelope of :func:`crossing_surfaces` (exact)."""
    return np.maximum(_rising(x, y), _falling(x, y))


def envelope_boundary(x0: float, x1: float, y0: float, y1: float, samples: int = 81) -> list:
    """Four polylines on the upper envelope of :func:`crossing_surfaces` around a rectangle."""
    s = np.linspace(0.0, 1.0, samples)

    def line(p, q):
        x = p[0] + s * (q[0] - p[0])
        y = p[1] + s * (q[1] - p[1])
        return np.stack([x, y, upper_envelope(x, y)], axis=1)

    c = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return [line(c[k], c[(k + 1) % 4]) for k in range(4)]


def stepped_gap(step: float = 0.01, gap: tuple = (0.45, 0.55), samples: int = 81
                ) -> tuple[list, list[NurbsSurface]]:
    """Two surfaces with a gap between them and a step across it (001 Fig. 6 kind).

    The smooth surface is cut at ``x = gap[0]`` and ``x = gap[1]``; the right part is
    raised by ``step``. The boundary runs around ``[0.2, 0.8]^2``: on the surfaces
    where they exist, a straight bridge across the gap on the bottom and top sides.

    Returns
    -------
    boundary : four (n, 3) polylines
    sources : [left, right] NurbsSurface
    """
    smooth = smooth_surface()
    left = smooth.restrict(None, gap[0], None, None)
    right_part = smooth.restrict(gap[1], None, None, None)
    right = NurbsSurface(right_part.control_points + np.array([0.0, 0.0, step]),
                         right_part.knots_u, right_part.knots_v, 3, 3)

    def height(x, y):
        z = smooth.evaluate(x, y)[..., 2]
        z = np.where(x >= gap[1], z + step, z)
        z_left = smooth.evaluate(np.full_like(x, gap[0]), y)[..., 2]
        z_right = smooth.evaluate(np.full_like(x, gap[1]), y)[..., 2] + step
        bridge = (x - gap[0]) / (gap[1] - gap[0])
        inside = (x > gap[0]) & (x < gap[1])
        return np.where(inside, (1 - bridge) * z_left + bridge * z_right, z)

    s = np.linspace(0.0, 1.0, samples)

    def line(p, q):
        x = p[0] + s * (q[0] - p[0])
        y = p[1] + s * (q[1] - p[1])
        return np.stack([x, y, height(x, y)], axis=1)

    c = [(0.2, 0.2), (0.8, 0.2), (0.8, 0.8), (0.2, 0.8)]
    return [line(c[k], c[(k + 1) % 4]) for k in range(4)], [left, right]
