"""Test surfaces with exact (or exactly known) intersections for the characteristic method.

Height fields are built on Greville abscissae, so ``x(u) = u`` and ``y(v) = v``
exactly (linear precision of B-splines): two of them are graphs over the same
(x, y), and their intersection is the zero set of the difference of heights.
numpy only (no OCP).
"""

from __future__ import annotations

import numpy as np

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.basis import greville_abscissae

R2 = np.sqrt(0.5)


def clamped(n: int, p: int) -> np.ndarray:
    return np.concatenate([[0.0] * p, np.linspace(0, 1, n - p + 1), [1.0] * p])


def height_field(z: np.ndarray, p: int = 3) -> NurbsSurface:
    """Graph ``(u, v, f(u, v))`` over [0, 1]^2 with heights ``z (n, m)`` at Greville points."""
    n, m = z.shape
    ku, kv = clamped(n, p), clamped(m, p)
    x, y = greville_abscissae(ku, p), greville_abscissae(kv, p)
    X, Y = np.meshgrid(x, y, indexing="ij")
    return NurbsSurface(np.stack([X, Y, z], -1), ku, kv, p, p)


def bumps_net(n: int, bumps, p: int = 3) -> np.ndarray:
    """Heights ``(n, n)`` at the Greville points of a sum of Gaussian bumps
    ``(cx, cy, sigma, height)``."""
    x = greville_abscissae(clamped(n, p), p)
    X, Y = np.meshgrid(x, x, indexing="ij")
    return sum(h * np.exp(-((X - cx) ** 2 + (Y - cy) ** 2) / (2 * s * s)) for cx, cy, s, h in bumps)


def plane_patch(centre, normal, half: float = 0.5) -> NurbsSurface:
    """Bilinear square of side ``2 half`` through ``centre`` with unit ``normal``."""
    c = np.asarray(centre, float)
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    t1 = np.cross(n, [0, 0, 1.0]) if abs(n[2]) < 0.9 else np.cross(n, [1.0, 0, 0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    cp = np.array([[c - half * t1 - half * t2, c - half * t1 + half * t2],
                   [c + half * t1 - half * t2, c + half * t1 + half * t2]])
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def sphere_band(r: float = 1.0) -> NurbsSurface:
    """Rational biquadratic sphere zone between latitudes -45 and 45 degrees (exact)."""
    circ = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                     [1, 0]], float)
    wc = np.array([1, R2, 1, R2, 1, R2, 1, R2, 1])
    mer = np.array([[R2, -R2], [2 * R2, 0.0], [R2, R2]])
    cp = np.empty((9, 3, 3))
    cp[..., 0] = circ[:, None, 0] * mer[None, :, 0]
    cp[..., 1] = circ[:, None, 1] * mer[None, :, 0]
    cp[..., 2] = mer[None, :, 1]
    ku = [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1]
    return NurbsSurface(cp * r, ku, [0, 0, 0, 1, 1, 1], 2, 2,
                        wc[:, None] * np.array([1, R2, 1])[None, :])


#: the direction (in the middle of the first quarter patch of the band) the planes face
DIAGONAL = np.array([R2, R2, 0.0])


def sphere_and_plane(loop_radius: float) -> tuple[NurbsSurface, NurbsSurface, np.ndarray, float]:
    """Unit sphere band and a plane cutting a circle of ``loop_radius`` (0: tangent).

    Returns the two surfaces, the circle's centre and its radius.
    """
    d = np.sqrt(1.0 - loop_radius ** 2)
    return sphere_band(), plane_patch(d * DIAGONAL, DIAGONAL), d * DIAGONAL, loop_radius


def touching_bumps(n: int = 8) -> tuple[NurbsSurface, NurbsSurface, np.ndarray]:
    """A bicubic bump and its mirror image touching it at the top (one contact point)."""
    z = bumps_net(n, [(0.5, 0.5, 0.15, 0.4)])
    a = height_field(z)
    top = a.evaluate(0.5, 0.5)
    b = height_field(2 * top[2] - z)
    return a, b, top


def several_bumps(n: int = 16) -> NurbsSurface:
    """Bicubic height field with three bumps (the third one lower)."""
    return height_field(bumps_net(n, [(0.28, 0.3, 0.1, 0.5), (0.72, 0.3, 0.1, 0.5),
                                      (0.5, 0.72, 0.1, 0.42)]))


def horizontal_plane(z: float) -> NurbsSurface:
    cp = np.array([[[-0.1, -0.1, z], [-0.1, 1.1, z]], [[1.1, -0.1, z], [1.1, 1.1, z]]])
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def degree_six_pair(n: int = 14) -> tuple[NurbsSurface, NurbsSurface]:
    """Two degree-6 graphs crossing in three closed loops (002 Figure 4 kind): three
    bumps through a gently waving sheet."""
    a = height_field(bumps_net(n, [(0.25, 0.3, 0.1, 0.3), (0.72, 0.3, 0.09, 0.33),
                                   (0.48, 0.74, 0.1, 0.3)], p=6), p=6)
    x = greville_abscissae(clamped(n, 6), 6)
    X, Y = np.meshgrid(x, x, indexing="ij")
    b = height_field(0.15 + 0.01 * np.sin(2 * np.pi * X) * np.cos(np.pi * Y), p=6)
    return a, b


def near_coincident(eps: float, n: int = 5) -> tuple[NurbsSurface, NurbsSurface]:
    """Two biquadratic graphs ``f`` and ``f + eps (x - 1/2)``: they cross along ``x = 1/2``
    (002 Figure 6 kind); ``eps = 0``: the same surface."""
    x = greville_abscissae(clamped(n, 2), 2)
    X, Y = np.meshgrid(x, x, indexing="ij")
    z = 0.2 * np.sin(2.5 * X) * np.cos(1.7 * Y) + 0.1 * X * Y
    return height_field(z, p=2), height_field(z + eps * (X - 0.5), p=2)


def torus(major: float = 1.0, minor: float = 0.3) -> NurbsSurface:
    """Rational biquadratic torus about the z axis (exact): ``u`` around the axis,
    ``v`` around the tube (``v = 1/4`` is the top circle, height ``minor``)."""
    circ = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                     [1, 0]], float)
    wc = np.array([1, R2, 1, R2, 1, R2, 1, R2, 1])
    cp = np.empty((9, 9, 3))
    radius = major + minor * circ[None, :, 0]
    cp[..., 0] = circ[:, None, 0] * radius
    cp[..., 1] = circ[:, None, 1] * radius
    cp[..., 2] = minor * circ[None, :, 1]
    knots = [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1]
    return NurbsSurface(cp, knots, knots, 2, 2, wc[:, None] * wc[None, :])


def torus_and_plane(gap: float, major: float = 1.0, minor: float = 0.3
                    ) -> tuple[NurbsSurface, NurbsSurface]:
    """A torus and the plane ``z = minor - gap`` normal to its axis: two circles of
    radii ``major +- sqrt(minor^2 - (minor - gap)^2)`` (gap > 0), the top circle
    (gap = 0: a tangential curve), nothing (gap < 0)."""
    z = minor - gap
    half = 1.5 * (major + minor)
    cp = np.array([[[-half, -half, z], [-half, half, z]], [[half, -half, z], [half, half, z]]])
    return torus(major, minor), NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def flat_crossing(slope: float, n: int = 8) -> tuple[NurbsSurface, NurbsSurface]:
    """Two bicubic sheets over overlapping strips, ``[0, 0.55]`` and ``[0.45, 1]`` in x,
    of the graph ``0.2 sin(2x) cos(1.5y)``, the second tilted by ``slope (x - 1/2 -
    0.02 sin 6y)``: they cross at the angle ``slope`` along the wavy curve ``x = 1/2 +
    0.02 sin 6y`` (y in [0, 1]), one branch of length about 1.02."""
    from surfprep.algorithms.fitting import interpolate_surface

    def sheet(x0: float, x1: float, tilt: float) -> NurbsSurface:
        x, y = np.meshgrid(np.linspace(x0, x1, n), np.linspace(0, 1, n), indexing="ij")
        z = 0.2 * np.sin(2 * x) * np.cos(1.5 * y) + tilt * (x - 0.5 - 0.02 * np.sin(6 * y))
        return interpolate_surface(np.stack([x, y, z], axis=-1))

    return sheet(0.0, 0.55, 0.0), sheet(0.45, 1.0, slope)
