"""How far healed geometry lies from the faces it was healed from, measured densely.

An approximant measures its own error (001 §7, eq. 19; :mod:`.error`) at the
midpoints of its grid and only where the grid points around them landed on the
sources: a bulge over a hole of the face it replaces, where no grid point landed,
is never seen (overture_heartvalve_rhino.igs: "largest error 0.157" for a patch
lying 4.33 off the plane it replaces). Here a surface is sampled on a uniform
grid of its parameter rectangle (or along its four sides only, for a patch over
a hole, whose inside has nothing to be near) and each sample's distance to the
union of the trimmed input faces is found by closest-point projection
(:meth:`InputFaces.distance`).

The distance to a trimmed face is the distance to its surface when the foot lies
inside the face (:meth:`~surfprep.algorithms.face_region.FaceRegion.contains`),
else the distance to its trimming edges in space (an upper bound, exact when the
nearest point of the face is on its boundary). Faces are taken nearest
control-net box first; a face's box distance bounds its distance from below,
and only for the samples that bound lies below the best distance found so far
is its grid (its surface sampled, in a k-d tree) queried: the nearest grid
point seeds Newton's point inversion and, less the largest cell diagonal, gives
a closer bound, and only below that bound is the face projected onto. The cost
follows the few faces near each sample, not the model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ..face_region import FaceRegion
from ..projection import project_to_surface
from ..surface import NurbsSurface
from ..trimmed import TrimmedFace

__all__ = ["DEFAULT_SAMPLES", "FACE_GRID", "InputFaces", "SurfaceDeviation", "surface_deviation"]

#: samples per direction of :func:`surface_deviation` (per side with ``rim_only``)
DEFAULT_SAMPLES = 25


@dataclass(frozen=True)
class SurfaceDeviation:
    """Distances of a surface's samples from the input faces.

    Attributes
    ----------
    max_distance, rms_distance : float
        Model units.
    worst_point : (3,) float
        The sample farthest from every face.
    samples : int
        How many samples were measured.
    """

    max_distance: float
    rms_distance: float
    worst_point: NDArray
    samples: int


#: samples per direction of the grid each face keeps for seeds and culling
FACE_GRID = 48


@dataclass(frozen=True)
class _FaceGrid:
    """A face's surface sampled on a grid: ``uv (m, 2)``, their points in a tree, and
    ``reach``: no point of the surface is farther than this from a grid point."""

    uv: NDArray
    tree: cKDTree
    reach: float
    box: NDArray


def _face_grid(region: FaceRegion) -> _FaceGrid:
    surface = region.surface
    u0, u1, v0, v1 = surface.domain
    u, v = np.linspace(u0, u1, FACE_GRID), np.linspace(v0, v1, FACE_GRID)
    grid = surface.evaluate_grid(u, v)
    # a cell's points lie within its longer diagonal of its corners (curvature aside:
    # hence the whole diagonal, twice the flat-cell bound)
    diagonal = np.maximum(np.linalg.norm(grid[1:, 1:] - grid[:-1, :-1], axis=-1),
                          np.linalg.norm(grid[1:, :-1] - grid[:-1, 1:], axis=-1))
    uu, vv = np.meshgrid(u, v, indexing="ij")
    return _FaceGrid(np.stack([uu.ravel(), vv.ravel()], axis=1), cKDTree(grid.reshape(-1, 3)),
                     float(diagonal.max()), surface.bounding_box())


@dataclass(frozen=True, eq=False)
class InputFaces:
    """The trimmed faces a result is measured against, prepared once for many queries.

    Attributes
    ----------
    regions : tuple of FaceRegion
    """

    regions: tuple[FaceRegion, ...]

    @classmethod
    def of(cls, faces: Sequence[TrimmedFace]) -> InputFaces:
        """From the faces (None entries, faces that could not be read, are left out)."""
        return cls(tuple(FaceRegion(f) for f in faces if f is not None))

    @cached_property
    def _grids(self) -> tuple[_FaceGrid, ...]:
        return tuple(_face_grid(r) for r in self.regions)

    def distance(self, points: NDArray, *, tol: float) -> NDArray:
        """Distance of each point to the nearest face (module docstring).

        Parameters
        ----------
        points : (n, 3) float
        tol : float
            Model units: convergence of the point inversion, and how close (in space)
            to a trimming edge a foot outside the loops may lie and still count as
            inside.

        Returns
        -------
        (n,) float
            ``inf`` where there is no face.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        best = np.full(points.shape[0], np.inf)
        if points.shape[0] == 0 or not self.regions:
            return best
        grids = self._grids
        boxes = np.stack([g.box for g in grids])                            # (F, 2, 3)
        outside = np.maximum(np.maximum(boxes[:, None, 0] - points, 0.0),
                             points - boxes[:, None, 1])
        box_lower = np.linalg.norm(outside, axis=-1)                        # (F, n)
        # nearest boxes first; a face's grid is queried only for the points its box
        # could still beat the best distance for, and projected onto only where its
        # grid's bound (nearest grid point less the reach) could too
        for k in np.argsort(box_lower.min(axis=1), kind="stable"):
            near = np.flatnonzero(box_lower[k] < best)
            if near.size == 0:
                continue
            g = grids[k]
            dg, idx = g.tree.query(points[near])
            keep = np.maximum(dg - g.reach, box_lower[k, near]) < best[near]
            todo, seeds = near[keep], g.uv[idx[keep]]
            if todo.size == 0:
                continue
            region = self.regions[k]
            foot = project_to_surface(region.surface, points[todo], tol=tol, guess=seeds)
            inside = region.contains(foot.uv, tol)
            distance = foot.distance.copy()
            if not inside.all():
                distance[~inside] = np.maximum(foot.distance[~inside],
                                               region.edge_distance(points[todo[~inside]]))
            best[todo] = np.minimum(best[todo], distance)
        return best


def _samples(surface: NurbsSurface, n: int, rim_only: bool | Sequence[int]) -> NDArray:
    u0, u1, v0, v1 = surface.domain
    u, v = np.linspace(u0, u1, n), np.linspace(v0, v1, n)
    if rim_only is False:
        return surface.evaluate_grid(u, v).reshape(-1, 3)
    sides = (0, 1, 2, 3) if rim_only is True else tuple(rim_only)
    # bottom (v0), right (u1), top (v1), left (u0): the boundary's loop order
    uv = [np.stack([u, np.full(n, v0)], 1), np.stack([np.full(n, u1), v], 1),
          np.stack([u, np.full(n, v1)], 1), np.stack([np.full(n, u0), v], 1)]
    uv = np.concatenate([uv[k] for k in sides])
    return surface.evaluate(uv[:, 0], uv[:, 1])


def surface_deviation(surface: NurbsSurface, faces: InputFaces, *, tol: float,
                      samples: int = DEFAULT_SAMPLES, rim_only: bool | Sequence[int] = False
                      ) -> SurfaceDeviation:
    """How far ``surface`` lies from the faces: ``samples x samples`` points uniform in
    its parameter rectangle, or ``samples`` along each of its four sides with
    ``rim_only`` (a patch over a hole), or along the sides listed (0 bottom ``v0``,
    1 right ``u1``, 2 top ``v1``, 3 left ``u0``: a sub-patch of a hole, whose other
    sides cross the hole), measured by :meth:`InputFaces.distance`.

    Examples
    --------
    A plane lifted by 0.01 above a unit square face on ``z = 0``:

    >>> import numpy as np
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> from surfprep.algorithms.trimmed import TrimmedFace
    >>> def square(z):
    ...     x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
    ...     return interpolate_surface(np.stack([x, y, np.full_like(x, z)], axis=-1))
    >>> faces = InputFaces.of([TrimmedFace(square(0.0))])
    >>> round(surface_deviation(square(0.01), faces, tol=1e-9).max_distance, 12)
    0.01
    """
    points = _samples(surface, samples, rim_only)
    distance = faces.distance(points, tol=tol)
    k = int(np.argmax(distance))
    return SurfaceDeviation(max_distance=float(distance[k]),
                            rms_distance=float(np.sqrt(np.mean(distance ** 2))),
                            worst_point=points[k], samples=int(points.shape[0]))
