"""Connecting local approximants into one G0 or G1 network (001 §8, 003, 000 §29.3.7).

:func:`connect` runs the steps of 001 §8 on a list of four-sided B-spline
patches:

1. connectivity table from boundary-curve distances, topology rules checked
   (:mod:`.connectivity`);
2. compatibility: degree >= 3 and the same knots along every shared side, by
   degree raising and knot insertion (:mod:`.compatibility`, as in 003);
3. G0 by averaging shared control rows and corners, optionally G1 by the
   tangent-plane conditions at shared corners and collinear control triples
   along shared edges (:mod:`.continuity`);
4. every shared edge measured on the resulting surfaces (:mod:`.measure_joins`).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from ...errors import InvalidGeometryError
from ..surface import NurbsSurface
from .compatibility import make_compatible
from .connectivity import Connectivity, SharedEdge, Side, find_connectivity
from .continuity import enforce_g0, enforce_g1
from .measure_joins import JoinReport, measure_join

__all__ = ["Continuity", "Network", "connect"]


class Continuity(enum.Enum):
    """How patches meet along shared edges: ``G0`` (common boundary curve) or ``G1``
    (common boundary curve and tangent plane)."""

    G0 = "G0"
    G1 = "G1"

    @classmethod
    def parse(cls, value: Continuity | str) -> Continuity:
        if isinstance(value, cls):
            return value
        try:
            return cls(str(value).upper())
        except ValueError:
            raise InvalidGeometryError(
                f"continuity must be 'G0' or 'G1', got {value!r}") from None


@dataclass(frozen=True)
class Network:
    """Connected patches and their measured joins.

    Attributes
    ----------
    patches : tuple of NurbsSurface
        The joined patches, in input order (over ``[0, 1]^2``, degree >= 3).
    connectivity : Connectivity
        Shared edges, corner clusters, ``gap_tol`` and (non-strict) violations.
    joins : tuple of JoinReport
        One per shared edge, measured on :attr:`patches`.
    joins_before : tuple of JoinReport
        The same edges measured on the input patches.
    continuity : Continuity
    """

    patches: tuple[NurbsSurface, ...]
    connectivity: Connectivity
    joins: tuple[JoinReport, ...]
    joins_before: tuple[JoinReport, ...]
    continuity: Continuity

    @property
    def edges(self) -> tuple[SharedEdge, ...]:
        return self.connectivity.edges

    @property
    def max_gap(self) -> float:
        return max((j.max_gap for j in self.joins), default=0.0)

    @property
    def max_angle(self) -> float:
        return max((j.max_angle for j in self.joins), default=0.0)

    def free_sides(self) -> list[tuple[int, Side]]:
        return self.connectivity.free_sides(len(self.patches))


def connect(patches, *, continuity: Continuity | str = Continuity.G0,
            gap_tol: float | None = None, strict: bool = True,
            connectivity: Connectivity | None = None, measure: bool = True) -> Network:
    """Join four-sided B-spline patches along shared boundary curves (001 §8).

    Parameters
    ----------
    patches : sequence of NurbsSurface (non-rational, 3D)
        E.g. the ``surface`` of each :class:`LocalApproximant`.
    continuity : Continuity or "G0" / "G1"
    gap_tol : float, optional
        Model units: boundary curves closer than this are one shared curve.
        Default :func:`.connectivity.default_gap_tol`.
    strict : bool
        Raise :class:`.connectivity.NetworkTopologyError` on a bifurcation or a
        partial (not full-face) contact; with False such pairs stay unconnected
        and are listed in ``network.connectivity.violations``.
    connectivity : Connectivity, optional
        A table computed before (skips step 1).
    measure : bool
        Measure the joins (before and after); False leaves both empty.

    Returns
    -------
    Network
    """
    continuity = Continuity.parse(continuity)
    patches = [getattr(p, "surface", p) for p in patches]
    for k, s in enumerate(patches):
        if not isinstance(s, NurbsSurface) or s.dimension != 3:
            raise InvalidGeometryError(f"patch {k} is not a 3D NurbsSurface")
    table = connectivity or find_connectivity(patches, gap_tol=gap_tol, strict=strict)
    before = tuple(measure_join(patches, e) for e in table.edges) if measure else ()
    work = make_compatible(patches, table)
    if continuity is Continuity.G1:
        work = enforce_g1(work, table)
    else:
        work, _ = enforce_g0(work, table)
    after = tuple(measure_join(work, e) for e in table.edges) if measure else ()
    return Network(tuple(work), table, after, before, continuity)
