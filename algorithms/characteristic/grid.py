"""The characteristic stage's field and sample grid (002 §6.3, step 0).

* :func:`choose_field`: which surface carries ``phi`` (``r``) and which is
  projected onto (``q``);
* :func:`stage_grid`: ``phi`` and its derivatives on a grid of ``r``'s domain
  (four samples per knot span, between ``GRID_MIN`` and ``GRID_MAX`` per
  direction), with the flattest crossing angle on it
  (:func:`.crossing.grid_crossing_sine`). The ``auto`` method reads the angle
  before it decides how to go on, and hands the grid to the stage so it is
  computed once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from .crossing import grid_crossing_sine
from .distance import DistanceField, DistanceJet
from .evaluator import PatchEvaluator
from .projector import ProjectionStatus, Projector

__all__ = ["GRID_MAX", "GRID_MIN", "StageGrid", "choose_field", "field_grid", "stage_grid"]

#: grid samples per direction of r's domain for the critical-point seeds
GRID_MIN, GRID_MAX = 33, 129


@dataclass(frozen=True, eq=False)
class StageGrid:
    """``phi`` on the stage's grid.

    Attributes
    ----------
    field : DistanceField
    jet : DistanceJet
        At the ``nu * nv`` nodes, row by row.
    shape : (nu, nv)
    crossing_sine : float
        :func:`.crossing.grid_crossing_sine` (inf: ``phi`` changes sign nowhere).
    """

    field: DistanceField
    jet: DistanceJet
    shape: tuple[int, int]
    crossing_sine: float


@dataclass(frozen=True, eq=False)
class _Coarse:
    """An ``n x n`` grid over a surface's domain: ``params (n*n, 2)``, ``points (n*n, 3)``
    and unit ``normals (n*n, 3)`` (one evaluation, by the projector's compiled patches,
    for the field choice's two tests)."""

    params: NDArray
    points: NDArray
    normals: NDArray

    @classmethod
    def of(cls, evaluator: PatchEvaluator, n: int = 9) -> _Coarse:
        d = evaluator.domain
        u, v = np.linspace(d[0], d[1], n), np.linspace(d[2], d[3], n)
        params = np.stack(np.meshgrid(u, v, indexing="ij"), -1).reshape(-1, 2)
        g = evaluator.derivatives(params[:, 0], params[:, 1], 1)
        normal = np.cross(g[:, 1, 0], g[:, 0, 1])
        normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
        return cls(params, g[:, 0, 0], normal)

    def spread(self) -> float:
        """Largest angle (radians) between the normals and their mean."""
        mean = self.normals.mean(axis=0)
        mean /= max(np.linalg.norm(mean), 1e-300)
        return float(np.arccos(np.clip(self.normals @ mean, -1, 1)).max())


def _nearest(x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    """Index of the nearest row of ``y (k, 3)`` to every row of ``x (m, 3)``, and of ``x``
    to every row of ``y``: one matrix of squared distances, both ways (centred first:
    the expanded form loses no digits to coordinates far from the origin)."""
    centre = x.mean(axis=0)
    x, y = x - centre, y - centre
    d2 = (x * x).sum(1)[:, None] + (y * y).sum(1)[None, :] - 2.0 * (x @ y.T)
    return np.argmin(d2, axis=1), np.argmin(d2, axis=0)


def _coverage(points: NDArray, seeds: NDArray, projector: Projector) -> float:
    """Share of ``points (m, 3)`` whose feet on ``q``, by Newton from ``seeds (m, 2)``,
    lie in ``q``'s domain.

    The seeds are the nearest nodes of a coarse grid of ``q`` (:class:`_Coarse`),
    not the projector's seed tree: in the certificate's route the projector that
    is not chosen is never used again, and building its tree of ``(4 spans + 1)^2``
    nodes cost more than the whole estimate.
    """
    return float(np.mean(projector.project(points, seeds).status != ProjectionStatus.NONE))


def choose_field(a: NurbsSurface, b: NurbsSurface, *, tol: float, phi_on: str | None = None
                 ) -> DistanceField:
    """The role of each surface: ``phi`` on the domain of ``r``, projection onto ``q``.

    ``q`` should be the surface onto which more of the other projects (coverage
    of a coarse grid: the share of its feet, by Newton from the nearest node of
    the other coarse grid, inside ``q``'s domain) and, between near ties, the
    flatter one (smaller spread of normals: projections onto it are unique
    farther out). ``phi_on`` forces the choice (``"a"`` or ``"b"``).
    """
    if phi_on not in (None, "a", "b"):
        raise ValueError(f"phi_on must be 'a', 'b' or None, got {phi_on!r}")
    proj_b, proj_a = Projector(b, tol=tol * 1e-3), Projector(a, tol=tol * 1e-3)
    if phi_on is None:
        grid_a, grid_b = _Coarse.of(proj_a.evaluator), _Coarse.of(proj_b.evaluator)
        near_ab, near_ba = _nearest(grid_a.points, grid_b.points)
        cover_ab = _coverage(grid_a.points, grid_b.params[near_ab], proj_b)
        cover_ba = _coverage(grid_b.points, grid_a.params[near_ba], proj_a)
        if abs(cover_ab - cover_ba) > 0.1:
            phi_on = "a" if cover_ab > cover_ba else "b"
        else:
            phi_on = "a" if grid_b.spread() <= grid_a.spread() else "b"
    field = DistanceField(a, proj_b, False) if phi_on == "a" else DistanceField(b, proj_a, True)
    # the other role (border points) reuses the other projector instead of building it again
    field._cache["other_projector"] = proj_a if phi_on == "a" else proj_b
    field._cache["evaluator"] = field._cache["other_projector"].evaluator   # r's, built once
    return field


def field_grid(field: DistanceField) -> tuple[DistanceJet, tuple[int, int]]:
    """``phi`` on the grid of ``r``'s domain: the jet at ``nu * nv`` nodes, row by row
    (four per knot span, ``GRID_MIN`` to ``GRID_MAX`` per direction), and ``(nu, nv)``."""
    counts = []
    for knots, degree in ((field.r.knots_u, field.r.degree_u), (field.r.knots_v, field.r.degree_v)):
        spans = np.unique(knots[degree:knots.size - degree]).size - 1
        counts.append(int(np.clip(4 * spans + 1, GRID_MIN, GRID_MAX)))
    u = np.linspace(field.lower[0], field.upper[0], counts[0])
    v = np.linspace(field.lower[1], field.upper[1], counts[1])
    uv = np.stack(np.meshgrid(u, v, indexing="ij"), -1).reshape(-1, 2)
    return field.jet(uv), (counts[0], counts[1])


def stage_grid(a: NurbsSurface, b: NurbsSurface, *, tol: float, phi_on: str | None = None
               ) -> StageGrid:
    """The field (:func:`choose_field`) and ``phi`` on its grid (:func:`field_grid`)."""
    field = choose_field(a, b, tol=tol, phi_on=phi_on)
    jet, shape = field_grid(field)
    return StageGrid(field, jet, shape, grid_crossing_sine(field, jet, shape))
