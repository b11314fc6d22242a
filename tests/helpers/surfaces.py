"""Test surfaces with exact (or exactly known) intersections: the one copy of every operand
builder of the intersection and characteristic tests.

Height fields are built on Greville abscissae, so ``x(u) = u`` and ``y(v) = v``
exactly (linear precision of B-splines): two of them are graphs over the same
(x, y), and their intersection is the zero set of the difference of heights.
numpy only (no OCP).
"""

from __future__ import annotations

import numpy as np

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.algorithms.basis import greville_abscissae
from surfprep.algorithms.trimmed import TrimEdge, TrimLoop

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


def sphere_band(r: float = 1.0, centre=None) -> NurbsSurface:
    """Rational biquadratic sphere zone between latitudes -45 and 45 degrees, 4 x 1
    patches, radius ``r`` around ``centre`` (the origin by default; exact: every
    point is at distance r)."""
    circ = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                     [1, 0]], float)
    wc = np.array([1, R2, 1, R2, 1, R2, 1, R2, 1])
    mer = np.array([[R2, -R2], [2 * R2, 0.0], [R2, R2]])
    cp = np.empty((9, 3, 3))
    cp[..., 0] = circ[:, None, 0] * mer[None, :, 0]
    cp[..., 1] = circ[:, None, 1] * mer[None, :, 0]
    cp[..., 2] = mer[None, :, 1]
    ku = [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1]
    poles = cp * r if centre is None else cp * r + np.asarray(centre, float)
    return NurbsSurface(poles, ku, [0, 0, 0, 1, 1, 1], 2, 2,
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


# ------------------------------------------------ closed-form patches (refinement tests)
S2 = np.sqrt(0.5)
R_SPHERE = 2.0


def plane_z(c: float, half: float = 2.0) -> NurbsSurface:
    """z = c over [-half, half]^2; (u, v) in [0, 1]^2 with x = -half + 2 half u."""
    g = np.array([-half, half])
    cp = np.stack([*np.meshgrid(g, g, indexing="ij"), np.full((2, 2), c)], axis=-1)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def plane_uv(points: np.ndarray, half: float = 2.0) -> np.ndarray:
    return (points[:, :2] + half) / (2 * half)


def paraboloid() -> NurbsSurface:
    """z = x^2 + y^2 on [-1, 1]^2 (biquadratic); x = 2u - 1, y = (2v - 1) / 3 ... on v in [-1, 2]."""
    g, a = np.array([-1.0, 0.0, 1.0]), np.array([1.0, -1.0, 1.0])
    x, y = np.meshgrid(g, g, indexing="ij")
    return NurbsSurface(np.stack([x, y, a[:, None] + a[None, :]], -1),
                        [0, 0, 0, 1, 1, 1], [-1, -1, -1, 2, 2, 2], 2, 2)


def paraboloid_uv(points: np.ndarray) -> np.ndarray:
    return np.stack([(points[:, 0] + 1) / 2, (points[:, 1] + 1) * 1.5 - 1], axis=1)


def sphere_patch(r: float = R_SPHERE) -> NurbsSurface:
    """Rational biquadratic: longitudes 0..90 deg (u), latitudes -45..45 deg (v)."""
    circ, wc = np.array([[1, 0], [1, 1], [0, 1]], float), np.array([1, S2, 1])
    mer, wm = np.array([[S2, -S2], [np.sqrt(2), 0], [S2, S2]]), np.array([1, S2, 1])
    cp = np.empty((3, 3, 3))
    cp[..., 0] = r * mer[None, :, 0] * circ[:, None, 0]
    cp[..., 1] = r * mer[None, :, 0] * circ[:, None, 1]
    cp[..., 2] = r * mer[None, :, 1]
    return NurbsSurface(cp, [0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1], 2, 2, wc[:, None] * wm)


HALF = np.array([[0, -1], [1, -1], [1, 0], [1, 1], [0, 1]], float)   # -90..90 deg
W_HALF = np.array([1, S2, 1, S2, 1])
K_HALF = [0, 0, 0, 0.5, 0.5, 1, 1, 1]


def cylinder_z(r: float = 1.0, h: float = 2.0) -> NurbsSurface:
    """x^2 + y^2 = r^2, x >= 0, |z| <= h."""
    cp = np.empty((5, 2, 3))
    cp[..., 0], cp[..., 1] = r * HALF[:, :1], r * HALF[:, 1:]
    cp[:, 0, 2], cp[:, 1, 2] = -h, h
    return NurbsSurface(cp, K_HALF, [0, 0, 1, 1], 2, 1, np.repeat(W_HALF[:, None], 2, 1))


def cylinder_x(r: float = 0.6, h: float = 2.0) -> NurbsSurface:
    """y^2 + z^2 = r^2, z >= 0, |x| <= h."""
    c = np.stack([-HALF[:, 1], HALF[:, 0]], 1)
    cp = np.empty((5, 2, 3))
    cp[..., 1], cp[..., 2] = r * c[:, :1], r * c[:, 1:]
    cp[:, 0, 0], cp[:, 1, 0] = -h, h
    return NurbsSurface(cp, K_HALF, [0, 0, 1, 1], 2, 1, np.repeat(W_HALF[:, None], 2, 1))


def invert_1d(f, target: np.ndarray, n: int = 20001) -> np.ndarray:
    """Parameter in [0, 1] with f(s) = target for a monotone f (table lookup)."""
    s = np.linspace(0, 1, n)
    values = f(s)
    if values[-1] < values[0]:
        s, values = s[::-1], values[::-1]
    return np.interp(target, values, s)


def sphere_uv(points: np.ndarray, r: float = R_SPHERE) -> np.ndarray:
    sph = sphere_patch(r)
    lon = np.arctan2(points[:, 1], points[:, 0])
    lat = np.arcsin(np.clip(points[:, 2] / r, -1, 1))
    u = invert_1d(lambda s: np.arctan2(*sph.evaluate(s, 0.5 + 0 * s)[:, [1, 0]].T), lon)
    v = invert_1d(lambda s: np.arcsin(sph.evaluate(0 * s, s)[:, 2] / r), lat)
    return np.stack([u, v], 1)


def sphere_plane_start(c: float, n: int, rng, perturb: float = 1e-2, lon=(0.0, np.pi / 2)):
    """Start parameters on the plane z = c and the sphere patch near the circle of latitude."""
    phi = np.linspace(*lon, n)
    rho = np.sqrt(R_SPHERE ** 2 - c ** 2)
    pts = np.stack([rho * np.cos(phi), rho * np.sin(phi), np.full(n, c)], 1)
    uv_a = plane_uv(pts) + rng.uniform(-perturb, perturb, (n, 2))
    uv_b = sphere_uv(pts) + rng.uniform(-perturb, perturb, (n, 2))
    return uv_a, uv_b


# ------------------------------------------------ height fields and planes (pipeline tests)
#: (centre x, centre y, sigma, height) of the bumps of :func:`bumpy`
BUMPS = [(0.25, 0.25, 0.08, 0.5), (0.72, 0.3, 0.06, 0.45), (0.4, 0.7, 0.12, 0.6),
         (0.8, 0.78, 0.05, 0.4)]


def bumpy(n: int = 20) -> NurbsSurface:
    """Bicubic height field over [0, 1]^2 with four Gaussian bumps of different sizes."""
    x = np.linspace(0, 1, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    Z = sum(h * np.exp(-((X - cx) ** 2 + (Y - cy) ** 2) / (2 * s * s)) for cx, cy, s, h in BUMPS)
    return NurbsSurface(np.stack([X, Y, Z], -1), clamped(n, 3), clamped(n, 3), 3, 3)


def flat(z: float) -> NurbsSurface:
    """The bilinear plane z = const over [-0.1, 1.1]^2."""
    cp = np.array([[[-0.1, -0.1, z], [-0.1, 1.1, z]], [[1.1, -0.1, z], [1.1, 1.1, z]]])
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def wall() -> NurbsSurface:
    """Quadratic in u (the parabola y = 1 - x^2, x in [-1, 1]), linear in v (z = 0..1)."""
    base = np.array([[-1, 0], [0, 2], [1, 0]], float)
    cp = np.empty((3, 2, 3))
    for j, z in enumerate((0.0, 1.0)):
        cp[:, j, :2] = base
        cp[:, j, 2] = z
    return NurbsSurface(cp, [0, 0, 0, 1, 1, 1], [0, 0, 1, 1], 2, 1)


def straight_loop(corners) -> TrimLoop:
    """A trimming loop of straight degree-1 pcurves through ``corners (k, 2)`` in
    ``(u, v)``, closed back to the first, without 3D curves."""
    c = np.asarray(corners, dtype=float)
    return TrimLoop(tuple(TrimEdge(None, NurbsCurve(np.array([a, b]), [0, 0, 1, 1], 1),
                                   0.0, 1.0) for a, b in zip(c, np.roll(c, -1, axis=0))))
