"""Quality of a structured surface grid, measured on the surface.

Every figure is taken from the 3D nodes and the surface's own normals, not from
planar-quad formulas in the parameters:

* **orthogonality**: the angle between the xi- and eta-lines at each node (the
  grid lines' tangents by central differences, one-sided on the boundary), with
  the boundary nodes reported apart;
* **equiangle skewness** of each cell, ``max((a_max - 90) / 90, (90 - a_min) / 90)``
  over the cell's four corner angles (0 a rectangle, 1 a degenerate cell);
* **aspect ratio** of each cell (its longer mean side over its shorter one);
* **growth ratio** along both families of lines (consecutive edge lengths, the
  larger over the smaller);
* **scaled Jacobian** at each cell corner, ``((e1 x e2) . n) / (|e1| |e2|)`` with
  ``n`` the surface normal at the corner node: ``<= 0`` is a fold (corners at a
  collapsed side, where an edge has zero length, are left out and counted);
* **area ratio** of neighbouring cells (the larger over the smaller).

Bands for the report: skewness <= 0.5 good, <= 0.8 acceptable, above poor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["SKEWNESS_BANDS", "GridQuality", "cell_skewness", "grid_quality"]

#: (upper bound, name) of the skewness bands
SKEWNESS_BANDS = ((0.5, "good"), (0.8, "acceptable"), (1.0, "poor"))
#: edges shorter than this fraction of the mean edge are collapsed (a pole's side)
COLLAPSED_EDGE = 1e-9
#: histogram edges of the orthogonality angle, degrees
ANGLE_BINS = (0.0, 30.0, 45.0, 60.0, 70.0, 80.0, 85.0, 95.0, 100.0, 110.0, 120.0, 135.0, 150.0, 180.0)


@dataclass(frozen=True)
class GridQuality:
    """Quality figures of one grid block (angles in degrees).

    Attributes
    ----------
    min_angle, max_angle : float
        Orthogonality: extreme angles between grid lines at the nodes.
    min_angle_boundary, max_angle_boundary : float
        The same at the boundary nodes only.
    angle_histogram : tuple of int
        Node counts in the bins of :data:`ANGLE_BINS`.
    max_skewness, mean_skewness : float
        Equiangle skewness of the cells.
    skewness_bands : dict
        Cell counts per band of :data:`SKEWNESS_BANDS`.
    max_aspect_ratio : float
    max_growth_ratio : float
        Largest ratio of consecutive edge lengths along either family of lines.
    min_scaled_jacobian : float
    folded_cells : int
        Cells with a corner of scaled Jacobian ``<= 0``.
    collapsed_corners : int
        Cell corners left out of the Jacobian because an edge there has zero length.
    max_area_ratio : float
        Largest area ratio of two neighbouring cells.
    """

    min_angle: float
    max_angle: float
    min_angle_boundary: float
    max_angle_boundary: float
    angle_histogram: tuple[int, ...]
    max_skewness: float
    mean_skewness: float
    skewness_bands: dict
    max_aspect_ratio: float
    max_growth_ratio: float
    min_scaled_jacobian: float
    folded_cells: int
    collapsed_corners: int
    max_area_ratio: float

    def report(self) -> dict:
        """Plain-JSON figures."""
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        out["angle_histogram"] = {f"{a:g}-{b:g}": int(n) for a, b, n in
                                  zip(ANGLE_BINS[:-1], ANGLE_BINS[1:], self.angle_histogram)}
        return out


def _unit(v: NDArray) -> tuple[NDArray, NDArray]:
    n = np.linalg.norm(v, axis=-1)
    return v / np.where(n > 0, n, 1.0)[..., None], n


def _line_tangents(x: NDArray, axis: int) -> NDArray:
    return np.gradient(x, axis=axis)


def _ratio(a: NDArray, b: NDArray) -> NDArray:
    big, small = np.maximum(a, b), np.minimum(a, b)
    return np.where(small > 0, big / np.where(small > 0, small, 1.0), np.where(big > 0, np.inf, 1.0))


def grid_quality(points: NDArray, normals: NDArray) -> GridQuality:
    """Quality of a grid block on a surface.

    Parameters
    ----------
    points : (ni, nj, 3) float
        The nodes.
    normals : (ni, nj, 3) float
        Unit surface normals at the nodes (the face's orientation).

    Returns
    -------
    GridQuality
    """
    x = np.asarray(points, dtype=float)
    n = np.asarray(normals, dtype=float)
    ni, nj = x.shape[:2]
    di = np.linalg.norm(np.diff(x, axis=0), axis=-1)           # (ni-1, nj) edges along xi
    dj = np.linalg.norm(np.diff(x, axis=1), axis=-1)           # (ni, nj-1) edges along eta
    # an edge shorter than this is a collapsed side's (rounding leaves it 1e-16, not 0)
    short = COLLAPSED_EDGE * float(np.mean(np.concatenate([di.ravel(), dj.ravel()])))
    di, dj = np.where(di <= short, 0.0, di), np.where(dj <= short, 0.0, dj)
    # orthogonality at the nodes (not at a pole, where one family has no direction)
    a, la = _unit(_line_tangents(x, 0))
    b, lb = _unit(_line_tangents(x, 1))
    ok = (la > short) & (lb > short)
    angle = np.degrees(np.arccos(np.clip(np.einsum("ijk,ijk->ij", a, b), -1.0, 1.0)))
    boundary = np.zeros((ni, nj), bool)
    boundary[0], boundary[-1], boundary[:, 0], boundary[:, -1] = True, True, True, True
    edge_ok = ok & boundary
    all_ok = angle[ok] if np.any(ok) else np.array([90.0])
    edge_angles = angle[edge_ok] if np.any(edge_ok) else all_ok
    histogram = np.histogram(all_ok, bins=ANGLE_BINS)[0]
    # cells: corners in order 00, 10, 11, 01 (counter-clockwise in (i, j))
    c = [x[:-1, :-1], x[1:, :-1], x[1:, 1:], x[:-1, 1:]]
    cn = [n[:-1, :-1], n[1:, :-1], n[1:, 1:], n[:-1, 1:]]
    corner_angles, jac, degenerate = [], [], []
    for k in range(4):
        e1, l1 = _unit(c[(k + 1) % 4] - c[k])
        e2, l2 = _unit(c[(k + 3) % 4] - c[k])
        l1, l2 = np.where(l1 <= short, 0.0, l1), np.where(l2 <= short, 0.0, l2)
        cos = np.clip(np.einsum("...k,...k->...", e1, e2), -1.0, 1.0)
        corner_angles.append(np.degrees(np.arccos(cos)))
        jac.append(np.einsum("...k,...k->...", np.cross(e1, e2), cn[k]))
        degenerate.append((l1 <= 0) | (l2 <= 0))
    corner_angles = np.stack(corner_angles)
    jac = np.stack(jac)
    degenerate = np.stack(degenerate)
    jac_valid = np.where(degenerate, np.inf, jac)
    # skewness from the corners that are real (a collapsed side's cells are triangles)
    amax = np.max(np.where(degenerate, -np.inf, corner_angles), axis=0)
    amin = np.min(np.where(degenerate, np.inf, corner_angles), axis=0)
    skew = np.maximum((amax - 90.0) / 90.0, (90.0 - amin) / 90.0)
    bands, lo = {}, -np.inf
    for hi, name in SKEWNESS_BANDS:
        bands[name] = int(np.sum((skew > lo) & (skew <= hi)))
        lo = hi
    # sides of the cells
    mean_i = 0.5 * (di[:, :-1] + di[:, 1:])
    mean_j = 0.5 * (dj[:-1] + dj[1:])
    aspect = _ratio(mean_i, mean_j)
    # growth along the lines, between edges that are not collapsed
    gi, gj = _ratio(di[1:], di[:-1]), _ratio(dj[:, 1:], dj[:, :-1])
    gi = gi[(di[1:] > 0) & (di[:-1] > 0)]
    gj = gj[(dj[:, 1:] > 0) & (dj[:, :-1] > 0)]
    growth = max(float(np.max(gi, initial=1.0)), float(np.max(gj, initial=1.0)))
    area = 0.5 * (np.linalg.norm(np.cross(c[1] - c[0], c[3] - c[0]), axis=-1)
                  + np.linalg.norm(np.cross(c[3] - c[2], c[1] - c[2]), axis=-1))
    area_ratio = max(float(np.max(_ratio(area[1:], area[:-1]), initial=1.0)),
                     float(np.max(_ratio(area[:, 1:], area[:, :-1]), initial=1.0)))
    return GridQuality(
        min_angle=float(all_ok.min()), max_angle=float(all_ok.max()),
        min_angle_boundary=float(edge_angles.min()), max_angle_boundary=float(edge_angles.max()),
        angle_histogram=tuple(int(h) for h in histogram),
        max_skewness=float(skew.max()), mean_skewness=float(skew.mean()), skewness_bands=bands,
        max_aspect_ratio=float(aspect.max()), max_growth_ratio=growth,
        min_scaled_jacobian=float(jac_valid.min()),
        folded_cells=int(np.sum(np.any(jac_valid <= 0.0, axis=0))),
        collapsed_corners=int(degenerate.sum()),
        max_area_ratio=area_ratio,
    )


def cell_skewness(points: NDArray) -> NDArray:
    """Equiangle skewness of every cell of a grid, ``(ni - 1, nj - 1)``.

    Corners where an edge has zero length (a collapsed side) are left out, as in
    :func:`grid_quality`; ``points`` is ``(ni, nj, d)``, ``d`` 2 or 3.
    """
    x = np.asarray(points, dtype=float)
    if x.shape[-1] == 2:
        x = np.concatenate([x, np.zeros(x.shape[:-1] + (1,))], axis=-1)
    c = [x[:-1, :-1], x[1:, :-1], x[1:, 1:], x[:-1, 1:]]
    legs = np.linalg.norm(np.diff(x, axis=0), axis=-1)
    short = COLLAPSED_EDGE * float(np.mean(legs)) if legs.size else 0.0
    amax = np.full(c[0].shape[:2], -np.inf)
    amin = np.full(c[0].shape[:2], np.inf)
    for k in range(4):
        e1, l1 = _unit(c[(k + 1) % 4] - c[k])
        e2, l2 = _unit(c[(k + 3) % 4] - c[k])
        angle = np.degrees(np.arccos(np.clip(np.einsum("...k,...k->...", e1, e2), -1.0, 1.0)))
        real = (l1 > short) & (l2 > short)
        amax = np.where(real, np.maximum(amax, angle), amax)
        amin = np.where(real, np.minimum(amin, angle), amin)
    return np.maximum((amax - 90.0) / 90.0, (90.0 - amin) / 90.0)
