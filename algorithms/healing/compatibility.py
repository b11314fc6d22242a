"""Making neighbouring patches compatible: same degree and knots along shared sides.

001 §8 asks for one global number of control points and one global knot
vector; 003 ("connecting B-spline surfaces") reaches the same by degree raising
and knot insertion, which keeps every surface exactly as it is. Here only what
continuity needs is made equal: the knots *along* each shared side.

Every patch has two running directions (u, v). A shared edge identifies the
running direction of ``side_a`` in patch ``a`` with that of ``side_b`` in ``b``,
flipped (``t -> 1 - t``) when the sides run opposite ways. The identified
directions form classes (union-find with the flip as parity); each class gets

* one degree: the largest of its members, at least 3 (bicubic, eq. 16);
* one knot vector on ``[0, 1]``: the union of its members' knots (flipped
  where their parity says so), each value with its largest multiplicity; a
  class whose cycles force both parities gets a knot vector symmetric under
  ``t -> 1 - t``.

Each patch is first reparametrized to ``[0, 1]^2`` (an affine map of its knots),
then degree-raised (:func:`..degree.elevate_degree_surface`) and refined
(:func:`..knots.refine_surface`) to its classes' knots. The geometry does not
change (to rounding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError
from ..knots import refine_surface
from ..surface import NurbsSurface
from ..tensor import Direction
from .connectivity import Connectivity

__all__ = ["MIN_DEGREE", "make_compatible", "normalize_domain"]

#: degree of the network in every direction at least (bicubic, 001 eq. 16)
MIN_DEGREE = 3
#: knot values closer than this (on [0, 1]) are one value
_KNOT_EPS = 1e-9


def normalize_domain(surface: NurbsSurface) -> NurbsSurface:
    """The same surface over ``[0, 1]^2`` (affine map of both knot vectors)."""
    u0, u1, v0, v1 = surface.domain
    ku = (surface.knots_u - u0) / (u1 - u0)
    kv = (surface.knots_v - v0) / (v1 - v0)
    return NurbsSurface(surface.control_points, ku, kv, surface.degree_u, surface.degree_v,
                        surface.weights)


class _ParityUnion:
    """Union-find over (patch, direction) nodes with a flip parity to the root."""

    def __init__(self, n: int):
        self.parent = list(range(n))
        self.parity = [0] * n
        self.symmetric = [False] * n

    def find(self, x: int) -> tuple[int, int]:
        parity = 0
        while self.parent[x] != x:
            parity ^= self.parity[x]
            x = self.parent[x]
        return x, parity

    def union(self, x: int, y: int, flip: int) -> None:
        rx, px = self.find(x)
        ry, py = self.find(y)
        if rx == ry:
            if px ^ py != flip:
                self.symmetric[rx] = True
            return
        self.parent[rx] = ry
        self.parity[rx] = px ^ py ^ flip
        self.symmetric[ry] = self.symmetric[ry] or self.symmetric[rx]


def _node(patch: int, direction: Direction) -> int:
    return 2 * patch + (0 if direction is Direction.U else 1)


def _knots_of(surface: NurbsSurface, direction: Direction) -> tuple[NDArray, int]:
    if direction is Direction.U:
        return surface.knots_u, surface.degree_u
    return surface.knots_v, surface.degree_v


@dataclass
class _Multiset:
    """Knot values in ``(0, 1)`` with multiplicities, merged within ``_KNOT_EPS``."""

    values: list[float]
    counts: list[int]

    @classmethod
    def of(cls, knots: NDArray, degree: int, flip: bool) -> _Multiset:
        inner = np.asarray(knots[degree + 1:-(degree + 1)], dtype=float)
        if flip:
            inner = 1.0 - inner[::-1]
        out = cls([], [])
        for x in inner:
            out.add(float(x), 1)
        return out

    def add(self, x: float, count: int) -> None:
        for k, y in enumerate(self.values):
            if abs(x - y) <= _KNOT_EPS:
                self.counts[k] += count
                return
        self.values.append(x)
        self.counts.append(count)

    def merge_max(self, other: _Multiset) -> None:
        for x, c in zip(other.values, other.counts):
            for k, y in enumerate(self.values):
                if abs(x - y) <= _KNOT_EPS:
                    self.counts[k] = max(self.counts[k], c)
                    break
            else:
                self.values.append(x)
                self.counts.append(c)

    def missing_from(self, present: _Multiset) -> list[float]:
        """Values to insert into ``present`` to reach this multiset (present's spelling)."""
        out = []
        for x, c in zip(self.values, self.counts):
            have = 0
            for y, d in zip(present.values, present.counts):
                if abs(x - y) <= _KNOT_EPS:
                    have, x = d, y
                    break
            out.extend([x] * max(0, c - have))
        return sorted(out)


def _classes(n: int, connectivity: Connectivity) -> _ParityUnion:
    union = _ParityUnion(2 * n)
    for e in connectivity.edges:
        union.union(_node(e.a, e.side_a.along), _node(e.b, e.side_b.along), int(e.reversed))
    return union


def make_compatible(patches: list[NurbsSurface], connectivity: Connectivity
                    ) -> list[NurbsSurface]:
    """Patches over ``[0, 1]^2``, degree >= 3, with equal knots along every shared side.

    Parameters
    ----------
    patches : list of NurbsSurface (non-rational)
    connectivity : Connectivity of these patches

    Returns
    -------
    list of NurbsSurface
        The same surfaces (to rounding). Along a shared edge both sides then
        have the same number of control points and the same knots (mirrored
        when ``reversed``), so their boundary rows correspond one to one.
    """
    for k, s in enumerate(patches):
        if s.is_rational:
            raise InvalidGeometryError(
                f"patch {k} is rational: the network joins non-rational B-spline "
                "patches (001 §10: all weights one)")
    work = [normalize_domain(s) for s in patches]
    union = _classes(len(work), connectivity)
    degrees: dict[int, int] = {}
    for p, s in enumerate(work):
        for d in (Direction.U, Direction.V):
            root, _ = union.find(_node(p, d))
            degrees[root] = max(degrees.get(root, MIN_DEGREE), _knots_of(s, d)[1])
    work = [_elevate(s, degrees[union.find(_node(p, Direction.U))[0]],
                     degrees[union.find(_node(p, Direction.V))[0]]) for p, s in enumerate(work)]
    targets: dict[int, _Multiset] = {}
    for p, s in enumerate(work):
        for d in (Direction.U, Direction.V):
            root, parity = union.find(_node(p, d))
            knots, degree = _knots_of(s, d)
            target = targets.setdefault(root, _Multiset([], []))
            target.merge_max(_Multiset.of(knots, degree, bool(parity)))
            if union.symmetric[root]:
                target.merge_max(_Multiset.of(knots, degree, not parity))
    return [_refined(s, p, union, targets) for p, s in enumerate(work)]


def _elevate(surface: NurbsSurface, degree_u: int, degree_v: int) -> NurbsSurface:
    tu, tv = degree_u - surface.degree_u, degree_v - surface.degree_v
    return surface if tu == tv == 0 else surface.elevate_degree(tu, tv)


def _refined(surface: NurbsSurface, patch: int, union: _ParityUnion,
             targets: dict[int, _Multiset]) -> NurbsSurface:
    for d in (Direction.U, Direction.V):
        root, parity = union.find(_node(patch, d))
        target = targets[root]
        if parity:
            target = _Multiset([1.0 - x for x in target.values], list(target.counts))
        knots, degree = _knots_of(surface, d)
        missing = target.missing_from(_Multiset.of(knots, degree, False))
        if missing:
            surface = refine_surface(surface, np.asarray(missing), d)
    return surface
