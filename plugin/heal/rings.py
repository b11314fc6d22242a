"""Rings of free edges :func:`surfprep.heal` bridges: two closed loops (of one face or
several) that run beside each other all round, wider apart than ``gap_tol`` (the
missing end face of a tube with two skins), planned as four-sided strips
(:mod:`surfprep.algorithms.healing.ring_strip`).

A ring is a gap between faces, not a hole nor an open boundary: it is bridged unless
``fill="none"``. Its strips are approximants like a hole's sub-patches (kind
``"ring"`` in the report's patches, named ``heal_ring_<index>_<n>``): their sides on
the loops are edges of the model, and a ring is bridged by all its strips or by none.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

from ...algorithms.healing.adjacency import FaceEdge
from ...algorithms.healing.ring_strip import NotARingError, ring_pairs, ring_strips
from .loops import FreeLoop

__all__ = ["Ring", "mark_ring_loops", "plan_rings"]


@dataclass(frozen=True)
class Ring:
    """Two loops of free edges bridged (or not) by strips.

    Attributes
    ----------
    index : int
        The ring's number (its strips are ``heal_ring_<index>_<n>``).
    faces : (tuple of int, tuple of int)
        The faces whose edges make each loop.
    edges : (int, int)
        Each loop's number of edges.
    width : float
        The largest distance from a point of one loop to the other.
    fill : bool
        Whether strips are built (they may still not fit: the report's patches and
        notes say).
    why : str
    strips : tuple of (list of four curves, RuledStrip)
        Per strip its boundary (sides 0 and 2 on the loops) and its ruled surface.
    """

    index: int
    faces: tuple[tuple[int, ...], tuple[int, ...]]
    edges: tuple[int, int]
    width: float
    fill: bool
    why: str
    strips: tuple = ()
    members: frozenset = field(default=frozenset(), repr=False)   # id() of its FaceEdges

    def as_dict(self, *, bridged: bool | None = None) -> dict:
        out = {"index": self.index, "faces": [list(f) for f in self.faces],
               "edges": list(self.edges), "width": self.width, "fill": self.fill,
               "strips": len(self.strips), "why": self.why}
        if bridged is not None:
            out["bridged"] = bridged
        return out


def plan_rings(loops: Sequence[Sequence[FaceEdge]], *, gap_tol: float,
               fill: str = "holes") -> list[Ring]:
    """The rings among the loops of free edges and their strips (module docstring).

    Parameters
    ----------
    loops : sequence of sequence of FaceEdge
        Every closed loop of free edges, of one face or several, in loop order
        (:func:`~surfprep.algorithms.healing.adjacency.hole_loops` with ``min_faces=1``).
    gap_tol : float
        Loops nearer each other than this somewhere are no ring (sewing joins them
        there); every side of a strip is longer.
    fill : "holes", "all" or "none"
        Rings are bridged unless "none".
    """
    rings = []
    for index, pair in enumerate(ring_pairs([[e.curve for e in loop] for loop in loops],
                                            gap_tol=gap_tol,
                                            owners=[set(_faces(loop)) for loop in loops])):
        a, b = loops[pair.first], loops[pair.second]
        head = {"index": index, "faces": (_faces(a), _faces(b)), "edges": (len(a), len(b)),
                "width": pair.width, "members": frozenset(id(e) for e in a + b)}
        if fill == "none":
            rings.append(Ring(**head, fill=False, why="left open: fill='none'"))
            continue
        try:
            strips = ring_strips([e.curve for e in a], [e.curve for e in b], min_side=gap_tol)
        except NotARingError as exc:
            rings.append(Ring(**head, fill=False, why=f"left open: {exc}"))
            continue
        rings.append(Ring(**head, fill=True, strips=tuple(strips),
                          why=f"{len(strips)} strips across it, {pair.narrowest:.3g} to "
                              f"{pair.width:.3g} wide"))
    return rings


def mark_ring_loops(loops: Sequence[FreeLoop], rims: Sequence[Sequence[FaceEdge]],
                    rings: Sequence[Ring]) -> list[FreeLoop]:
    """``loops`` (of ``rims``) with those that are one side of a ring saying so."""
    out = []
    for loop in loops:
        ids = {id(e) for e in rims[loop.index]}
        ring = next((r for r in rings if ids <= r.members), None)
        if ring is None:
            out.append(loop)
            continue
        other = ring.faces[1] if set(loop.faces) == set(ring.faces[0]) else ring.faces[0]
        out.append(replace(loop, kind="gap", fill=False, boundaries=(), cap=None,
                           why=f"one side of ring {ring.index}, with the loop of faces "
                               f"{list(other)} beside it: {ring.why}"))
    return out


def _faces(loop: Sequence[FaceEdge]) -> tuple[int, ...]:
    return tuple(sorted({e.face for e in loop}))
