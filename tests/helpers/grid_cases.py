"""Surfaces whose structured grids are known: the grid tests' operands.

* :func:`warped_plane`: the unit square z = 0 with a badly warped parametrization
  (interior control points moved within the plane): Winslow's grid of its
  uniform sides is the uniform Cartesian grid, whatever the parametrization;
* :func:`warped_cylinder`: a half cylinder, rational in u and quadratic in v
  with its middle control point moved: developable, so its harmonic grid is the
  unrolled uniform grid (an orthogonal grid exists, and the solver must find it);
* :func:`pole_patch`: a planar patch with the side ``u = 0`` collapsed to a point;
* :func:`crowded_plane`: a plane whose parameters crowd into one corner (a
  chord-length mismatch in the hundreds): the parameter grid there is useless;
* :func:`side_angles`: the angles at which a grid's lines leave its four sides,
  measured on the nodes, away from the corners.
"""

from __future__ import annotations

import numpy as np

from surfprep import NurbsSurface

from .surfaces import HALF, K_HALF, W_HALF

__all__ = ["crowded_plane", "pole_patch", "side_angles", "unrolled_cylinder_grid", "warped_cylinder",
           "warped_plane"]


def side_angles(points: np.ndarray, blend: float = 0.1, stretch: float = 3.0, nodes: int = 3) -> list[np.ndarray]:
    """Angles (degrees) between each side of a grid (i0, i1, j0, j1) and the lines leaving it.

    Measured on the nodes: the side's direction by central differences, the line's by
    the first cell across (one-sided), at the side's inner nodes away from its corners,
    whose angles are the face's: farther than ``nodes`` nodes and than
    ``blend (1 + stretch |cos(corner angle)|)`` of the side's length from each corner
    (the reach :mod:`surfprep.algorithms.grid.orthogonal` documents for its blend).
    A collapsed side (a pole) gives an empty array.
    """
    out = []
    longest = max(float(np.linalg.norm(np.diff(side, axis=0), axis=1).sum())
                  for side in (points[:, 0], points[:, -1], points[0], points[-1]))
    for view in (np.swapaxes(points, 0, 1), np.swapaxes(points, 0, 1)[:, ::-1], points, points[:, ::-1]):
        side = view[:, 0]
        run = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(side, axis=0), axis=1))])
        if run[-1] <= 1e-9 * longest:
            out.append(np.zeros(0))
            continue
        along, across = side[2:] - side[:-2], view[1:-1, 1] - side[1:-1]
        with np.errstate(invalid="ignore", divide="ignore"):
            cos = np.einsum("ij,ij->i", along, across) / np.linalg.norm(along, axis=1) \
                / np.linalg.norm(across, axis=1)
            corners = []
            for i, leg in ((0, side[1] - side[0]), (-1, side[-1] - side[-2])):
                line = view[i, 1] - view[i, 0]
                corners.append(abs(float(np.dot(leg, line) / np.linalg.norm(leg) / np.linalg.norm(line))))
        s = run[1:-1] / run[-1]
        k = np.arange(1, view.shape[0] - 1)
        corners = np.nan_to_num(corners)
        keep = (s > blend * (1 + stretch * corners[0])) & (1 - s > blend * (1 + stretch * corners[1])) \
            & (k >= nodes) & (k <= view.shape[0] - 1 - nodes) & np.isfinite(cos)
        out.append(np.degrees(np.arccos(np.clip(cos[keep], -1, 1))))
    return out


def warped_plane(n: int = 6) -> NurbsSurface:
    """Bicubic unit square in z = 0, interior poles moved along x and y."""
    knots = np.r_[0, 0, 0, 0, np.linspace(0, 1, n - 2)[1:-1], 1, 1, 1, 1]
    g = np.linspace(0, 1, n)
    cp = np.zeros((n, n, 3))
    cp[..., 0], cp[..., 1] = np.meshgrid(g, g, indexing="ij")
    inner = (slice(1, -1), slice(1, -1))
    x, y = cp[inner][..., 0].copy(), cp[inner][..., 1].copy()
    cp[inner + (0,)] = x + 0.12 * np.sin(3 * y)
    cp[inner + (1,)] = y + 0.1 * np.cos(2 * x)
    return NurbsSurface(cp, knots, knots, 3, 3)


RADIUS, HEIGHT = 1.0, 2.0


def warped_cylinder(middle=(0.6, -0.4, 0.5, -0.3, 0.6)) -> NurbsSurface:
    """x^2 + y^2 = 1, x >= 0, |z| <= 2, with z(u, v) quadratic in v whose middle poles
    sit at ``middle[i] * 2`` (any z keeps the points on the cylinder; differing
    ones make the parametrization warp across, not only along, the lines)."""
    cp = np.empty((5, 3, 3))
    cp[..., 0] = RADIUS * HALF[:, :1]
    cp[..., 1] = RADIUS * HALF[:, 1:]
    cp[:, :, 2] = np.array([-HEIGHT, 0.0, HEIGHT])[None, :]
    cp[:, 1, 2] = np.asarray(middle, dtype=float) * HEIGHT
    weights = np.repeat(W_HALF[:, None], 3, 1)
    return NurbsSurface(cp, K_HALF, [0, 0, 0, 1, 1, 1], 2, 2, weights)


def unrolled_cylinder_grid(ni: int, nj: int) -> np.ndarray:
    """The uniform grid of :func:`warped_cylinder` in arc length, ``(ni, nj, 3)``."""
    theta = np.linspace(-np.pi / 2, np.pi / 2, ni)
    z = np.linspace(-HEIGHT, HEIGHT, nj)
    T, Z = np.meshgrid(theta, z, indexing="ij")
    return np.stack([RADIUS * np.cos(T), RADIUS * np.sin(T), Z], -1)


def pole_patch() -> NurbsSurface:
    """Biquadratic patch in z = 0 whose side u = 0 is the single point (0, 0, 0)."""
    cp = np.zeros((3, 3, 3))
    for i, r in enumerate((0.0, 0.5, 1.0)):
        for j, y in enumerate((-1.0, 0.0, 1.0)):
            cp[i, j] = [r * 2.0, r * y, 0.0]
    k = [0, 0, 0, 1, 1, 1]
    return NurbsSurface(cp, k, k, 2, 2)


def crowded_plane() -> NurbsSurface:
    """The square [0, 1]^2 in z = 0 with its parameters crowded toward (1, 1) and sheared."""
    xs = np.array([0.0, 0.96, 0.99, 1.0])
    cp = np.zeros((4, 4, 3))
    cp[..., 0], cp[..., 1] = np.meshgrid(xs, xs, indexing="ij")
    cp[1:3, 1:3, 0] -= np.array([[0.5, 0.3], [0.2, 0.0]])
    cp[1:3, 1:3, 1] -= np.array([[0.1, 0.6], [0.3, 0.0]])
    k = [0, 0, 0, 0, 1, 1, 1, 1]
    return NurbsSurface(cp, k, k, 3, 3)
