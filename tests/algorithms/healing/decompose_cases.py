"""Faces for the decomposition tests: loops of straight (u, v) lines or arcs on a wavy
bicubic surface, with 3D edges interpolated through the mapped pcurves."""

from __future__ import annotations

import numpy as np
from surfprep.algorithms.curve import NurbsCurve
from surfprep.algorithms.fitting import interpolate_curve, interpolate_surface
from surfprep.algorithms.healing.decompose import LoopEdge


def wavy_surface():
    """Bicubic graph over [0, 1]^2 (domain [0, 1]^2), a unit-size free-form patch."""
    x = np.linspace(0, 1, 9)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    z = 0.15 * np.sin(2.5 * gx) * np.cos(2.0 * gy) + 0.1 * gx * gy
    return interpolate_surface(np.stack([gx, gy, z], axis=-1))


def edge_from_uv(surface, uv_of_t, n=65) -> LoopEdge:
    """Edge with pcurve through ``uv_of_t(t)``, ``t`` in [0, 1], and its 3D curve."""
    t = np.linspace(0, 1, n)
    uv = uv_of_t(t)
    pcurve = interpolate_curve(uv, parameters=t)
    xyz = surface.evaluate(pcurve.evaluate(t)[:, 0], pcurve.evaluate(t)[:, 1])
    return LoopEdge(interpolate_curve(xyz, parameters=t), pcurve)


def line(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return lambda t: (1 - t)[:, None] * a + t[:, None] * b


def arc(centre, radius, a0, a1):
    c = np.asarray(centre, float)
    return lambda t: c + radius * np.column_stack([np.cos(a0 + t * (a1 - a0)),
                                                   np.sin(a0 + t * (a1 - a0))])


def polygon_loop(surface, corners):
    """Straight uv edges between consecutive corners (counter-clockwise)."""
    c = np.asarray(corners, float)
    return [edge_from_uv(surface, line(c[k], c[(k + 1) % len(c)])) for k in range(len(c))]


def triangle(surface):
    return polygon_loop(surface, [(0.1, 0.1), (0.9, 0.2), (0.4, 0.85)])


def pentagon(surface):
    a = np.pi / 2 + 2 * np.pi * np.arange(5) / 5
    return polygon_loop(surface, np.column_stack([0.5 + 0.4 * np.cos(a), 0.5 + 0.4 * np.sin(a)]))


def six_edges_two_smooth(surface):
    """A rounded rectangle in uv: four corners, two sides each made of two edges that
    continue each other smoothly (a straight side split in two, an arc split in two)."""
    return [edge_from_uv(surface, line((0.1, 0.1), (0.5, 0.1))),
            edge_from_uv(surface, line((0.5, 0.1), (0.9, 0.1))),
            edge_from_uv(surface, line((0.9, 0.1), (0.9, 0.8))),
            edge_from_uv(surface, arc((0.5, 0.45), np.hypot(0.4, 0.35),
                                      np.arctan2(0.35, 0.4), np.pi / 2)),
            edge_from_uv(surface, arc((0.5, 0.45), np.hypot(0.4, 0.35), np.pi / 2,
                                      np.pi - np.arctan2(0.35, 0.4))),
            edge_from_uv(surface, line((0.1, 0.8), (0.1, 0.1)))]


def disc(surface, pieces=1):
    """A circle in uv as ``pieces`` smooth arcs."""
    step = 2 * np.pi / pieces
    return [edge_from_uv(surface, arc((0.5, 0.5), 0.35, k * step, (k + 1) * step), n=129)
            for k in range(pieces)]


def notched(surface):
    """A deep U-shaped outline (very non-convex, eight corners)."""
    return polygon_loop(surface, [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.7, 0.9), (0.7, 0.3),
                                  (0.3, 0.3), (0.3, 0.9), (0.1, 0.9)])


def outline_uv(edges):
    return np.concatenate([e.pcurve.evaluate(np.linspace(0, 1, 200))[:-1] for e in edges])


__all__ = ["NurbsCurve", "disc", "edge_from_uv", "notched", "outline_uv", "pentagon",
           "polygon_loop", "six_edges_two_smooth", "triangle", "wavy_surface"]
