"""Composing two trivariate NURBS solids (004 §3, §5 and the classification): the curves
where their boundaries meet, which solid(s) a point is in, and the volumes of the
composed domain -- without building a B-rep.

:func:`compose` takes the exterior boundary surfaces of both solids (004 §3: the six
boundary surfaces less the collapsed ones and the seams of closed directions,
:meth:`~surfprep.algorithms.volume.NurbsVolume.exterior_faces`) and intersects every
pair whose control-net boxes overlap with the library's surface--surface
intersection (:func:`~surfprep.algorithms.intersection.intersect_surfaces`: every
sample within ``tol`` of both surfaces, the curves with their images in both
parameter domains). A point is classified by inverting it into each solid (Newton
on ``x(u, v, w) = p``): 0 outside both, 1 in A only, 2 in B only, 3 in both.

004's hybrid hierarchy (Bézier patches and their boxes, overlap boxes, local
triangulations, kd-trees, merged loops: :mod:`.hierarchy`) is built on first use of
:attr:`Composition.hierarchy` and kept; a solid's level 1 (its Bézier patches) is
reused when it is composed again with another partner (``compose(a, c,
reuse=composition)``). The curves come from the surface--surface intersection, not
from the hierarchy's loops: on the same pairs it is 1.5-2.5x faster and certifies that
no loop is missed (``benchmarks/compose.py`` measures both). The volumes and the
boundaries of the composed regions: :meth:`Composition.volume`,
:meth:`Composition.boundary` (:mod:`.regions`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..intersection import intersect_surfaces
from ..volume import NurbsVolume
from .hierarchy import BoundaryPatches, Hierarchy, build_hierarchy

if TYPE_CHECKING:                                        # pragma: no cover
    from .regions import RegionVolumes

__all__ = ["Composition", "compose"]

#: default chord tolerance of the hierarchy's triangulations, times the solids' diagonal
MESH_SHARE = 2e-3

@dataclass(frozen=True)
class Composition:
    """Two solids composed (see the module doc).

    Attributes
    ----------
    a, b : NurbsVolume
    curves : tuple of (str, str, IntersectionCurve)
        The curves where the boundaries meet: the faces of A and of B (``"u0"``...)
        and the curve (samples, and ``uv_a`` / ``uv_b`` on those faces' parameters).
    tol : float
    """

    a: NurbsVolume
    b: NurbsVolume
    curves: tuple
    tol: float
    time_s: float = field(default=0.0, compare=False)
    #: level 1 of the hierarchy of each solid when already known (``compose(reuse=)``)
    level1: tuple = field(default=(None, None), compare=False, repr=False)

    @property
    def size(self) -> float:
        """Diagonal of both solids' box."""
        box = np.vstack([self.a.bounding_box(), self.b.bounding_box()])
        return float(np.linalg.norm(box.max(axis=0) - box.min(axis=0)))

    def build_hierarchy(self, *, mesh_tol: float | None = None, candidates: str = "descent"
                        ) -> Hierarchy:
        """004's hybrid hierarchy of the two solids (:func:`.hierarchy.build_hierarchy`).

        Parameters
        ----------
        mesh_tol : float, optional
            Chord tolerance of the local triangulations; default ``MESH_SHARE`` of the
            solids' diagonal (and at least ``tol``).
        candidates : {"descent", "sweep"}
            Triangle pairs by the box-tree descent (the default: as fast or faster on
            every pair measured) or by 004's kd-tree sweep; the same pairs either way.
        """
        mesh_tol = max(MESH_SHARE * self.size, self.tol) if mesh_tol is None else float(mesh_tol)
        if not (np.isfinite(mesh_tol) and mesh_tol >= self.tol):
            raise InvalidGeometryError(f"mesh_tol must be >= tol = {self.tol!r}, got {mesh_tol!r}")
        started = time.perf_counter()
        la, lb = self.level1
        la = la if la is not None else BoundaryPatches.of(self.a)
        lb = lb if lb is not None else BoundaryPatches.of(self.b)
        level1 = time.perf_counter() - started
        built = build_hierarchy(la, lb, tol=self.tol, mesh_tol=mesh_tol, candidates=candidates)
        return replace(built, times={"level1": level1, **built.times})

    @cached_property
    def hierarchy(self) -> Hierarchy:
        """:meth:`build_hierarchy` with its defaults, built on first use and kept."""
        return self.build_hierarchy()

    def classify(self, points: ArrayLike, *, method: str = "ray") -> NDArray:
        """``(n,)`` labels of points ``(n, 3)``: 0 outside both, 1 A only, 2 B only, 3 both
        (a point on a boundary, within ``tol``, is in that solid).

        Parameters
        ----------
        points : (n, 3) float
        method : {"ray", "inversion"}
            ``"ray"``: ray parity on each solid's exact exterior boundary, decided for all
            points at once (:func:`~surfprep.algorithms.containment.classify_points`);
            ``"inversion"``: Newton inversion into each solid (``x(u, v, w) = p``,
            :meth:`NurbsVolume.invert`), which :meth:`locate` uses for the parameters.
            The same labels; the ray test is 2-4x faster.
        """
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        if method == "inversion":
            in_a = self.a.invert(p, tol=self.tol).inside
            in_b = self.b.invert(p, tol=self.tol).inside
        elif method == "ray":
            from ..containment import OUTSIDE, classify_points
            in_a = classify_points(self.boundary_faces("A"), p, tol=self.tol) != OUTSIDE
            in_b = classify_points(self.boundary_faces("B"), p, tol=self.tol) != OUTSIDE
        else:
            raise InvalidGeometryError(f"method must be 'ray' or 'inversion', got {method!r}")
        return in_a.astype(int) + 2 * in_b.astype(int)

    def boundary_faces(self, which: str) -> list:
        """The exterior boundary of solid ``"A"`` or ``"B"`` as trimmed faces (whole
        surfaces) oriented out of it (``u1``, ``v0``, ``w1`` out of a right-handed solid,
        :data:`~surfprep.algorithms.volume_measure.OUTWARD`)."""
        from ..trimmed import TrimmedFace
        from ..volume_measure import OUTWARD, handedness
        if which not in ("A", "B"):
            raise InvalidGeometryError(f"which must be 'A' or 'B', got {which!r}")
        solid = self.a if which == "A" else self.b
        right = handedness(solid) > 0
        return [TrimmedFace(s, reversed=(name in OUTWARD) != right, name=name)
                for name, s in solid.exterior_faces().items()]

    def locate(self, points: ArrayLike) -> dict:
        """Per point, whether it is in A and in B and its ``(u, v, w)`` in each."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        ia, ib = self.a.invert(p, tol=self.tol), self.b.invert(p, tol=self.tol)
        return {"in_a": ia.inside, "uvw_a": ia.uvw, "in_b": ib.inside, "uvw_b": ib.uvw}

    def volume(self, which: str) -> float:
        """Volume of ``"A"``, ``"B"``, ``"A only"``, ``"B only"``, ``"common"``, ``"union"``
        or ``"A-B"`` (= ``"A only"``): the solids' own volumes, the others by the
        divergence theorem over the faces' parts inside the other solid
        (:func:`.regions.region_volumes`)."""
        kinds = ("A", "B", "A only", "B only", "common", "union", "A-B")
        if which not in kinds:
            raise InvalidGeometryError(f"which must be one of {', '.join(map(repr, kinds))}, "
                                       f"got {which!r}")
        if which in ("A", "B"):
            return float((self.a if which == "A" else self.b).volume())
        v = self.volumes
        return {"A only": v.a_only, "A-B": v.a_only, "B only": v.b_only, "common": v.both,
                "union": v.union}[which]

    @cached_property
    def volumes(self) -> RegionVolumes:
        """The volumes of A only, B only, both and the union
        (:func:`.regions.region_volumes`), computed on first use and kept."""
        from .regions import region_volumes
        return region_volumes(self)

    def boundary(self, which: str) -> list:
        """The pieces of the exterior faces bounding ``"A"``, ``"B"``, ``"union"``,
        ``"common"`` or ``"A-B"`` (:func:`.regions.boundary_pieces`: a list of
        :class:`~.regions.BoundaryPiece`)."""
        from .regions import BOUNDARIES, boundary_pieces
        if which not in BOUNDARIES:
            raise InvalidGeometryError(f"which must be one of {', '.join(map(repr, BOUNDARIES))}, "
                                       f"got {which!r}")
        return boundary_pieces(self, which)


def _boxes_overlap(a: NDArray, b: NDArray, pad: float) -> bool:
    return bool(np.all(a[0] - pad <= b[1]) and np.all(b[0] - pad <= a[1]))


def _level1(volume: NurbsVolume, reuse) -> BoundaryPatches | None:
    """The level 1 of ``volume`` that ``reuse`` (a Composition) has built, if any."""
    built = None if reuse is None else reuse.__dict__.get("hierarchy")
    if built is None:
        return None
    for patches in (built.a, built.b):
        if patches.volume is volume:
            return patches
    return None


def compose(a: NurbsVolume, b: NurbsVolume, *, tol: float | None = None,
            reuse: Composition | None = None) -> Composition:
    """Compose two solids: the curves where their boundaries meet, for classification
    and volumes (see the module doc).

    Parameters
    ----------
    a, b : NurbsVolume (3D)
    tol : float, optional
        Model units; default 1e-6 of the diagonal of both solids' box.
    reuse : Composition, optional
        An earlier composition of one of the same solids: its level 1 of the hierarchy
        (the Bézier patches of that solid's boundary) is reused, not rebuilt.

    Returns
    -------
    Composition
    """
    started = time.perf_counter()
    for name, v in (("a", a), ("b", b)):
        if not isinstance(v, NurbsVolume) or v.dimension != 3:
            raise InvalidGeometryError(f"{name} must be a 3D NurbsVolume")
    if reuse is not None and not isinstance(reuse, Composition):
        raise InvalidGeometryError(f"reuse must be a Composition, got {type(reuse).__name__}")
    box = np.vstack([a.bounding_box(), b.bounding_box()])
    size = float(np.linalg.norm(box.max(axis=0) - box.min(axis=0)))
    tol = 1e-6 * size if tol is None else float(tol)
    if not np.isfinite(tol) or tol <= 0:
        raise InvalidGeometryError(f"tol must be a positive length, got {tol!r}")
    curves = []
    faces_a, faces_b = a.exterior_faces(), b.exterior_faces()
    for name_a, sa in faces_a.items():
        box_a = sa.bounding_box()
        for name_b, sb in faces_b.items():
            if not _boxes_overlap(box_a, sb.bounding_box(), tol):
                continue
            for curve in intersect_surfaces(sa, sb, tol=tol):
                curves.append((name_a, name_b, curve))
    return Composition(a, b, tuple(curves), tol, time.perf_counter() - started,
                       (_level1(a, reuse), _level1(b, reuse)))
