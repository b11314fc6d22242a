"""The loops of free edges :func:`surfprep.heal` finds, what each is, and the four-sided
boundaries that fill the holes among them.

Every loop of free edges from two or more faces that is not a sliver (a gap between
faces wider than ``gap_tol``: :func:`~surfprep.algorithms.healing.hole_cap.loop_width`,
or a loop whose edges all run beside other faces' free edges, a gap between two loops)
is capped
(:func:`surfprep.algorithms.healing.hole_cap.cap_hole`, its surroundings sampled on
the faces that bound it) and classified by the slope of those surroundings: a
*hole* (they continue across it) or an *open boundary* (they turn away: a sheet's
edge, a pipe's end). The ``fill`` rule decides what is filled:

``"holes"`` (default)
    holes only; open boundaries stay open and are named.
``"all"``
    open boundaries too, each by the smoothest cap through its rim alone, except
    where faces lie over the loop's inside (the outer edge of a sheet: filling it
    would lay a second skin on the first).
``"none"``
    nothing.

A loop of four edges is filled by one approximant over its four edges, as ever; a
loop of any other number of edges by the cap's four-sided sub-patches
(:func:`~surfprep.algorithms.healing.hole_cap.hole_quads`): one patch when its
vertices make four corners, else quads around a centre on the cap.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...algorithms.healing.adjacency import FaceEdge
from ...algorithms.healing.decompose import NotDecomposableError
from ...algorithms.healing.free_boundary import classify_free_edges
from ...algorithms.healing.hole_cap import (
    REACH,
    HoleCap,
    LoopKind,
    NotCappableError,
    cap_hole,
    hole_quads,
    loop_width,
    surroundings,
)
from ...algorithms.trimmed import TrimmedFace
from ...errors import InvalidGeometryError

__all__ = ["FILL_RULES", "FreeLoop", "plan_loops"]

#: the values of ``heal(fill=...)``
FILL_RULES = ("holes", "all", "none")
ALL_SIDES = (0, 1, 2, 3)
#: a loop at most this times its length wide is a gap between faces (a sliver), not a hole
GAP_WIDTH = 0.02
#: an open boundary whose inside faces cover more than this share of the points
#: near it is never filled, not even with ``fill="all"``
MAX_COVERED = 0.05


@dataclass(frozen=True)
class FreeLoop:
    """One loop of free edges.

    Attributes
    ----------
    index : int
        The hole's number (patches over it are ``heal_hole_<index>``).
    edges : int
    faces : tuple of int
        The faces whose edges make it.
    kind : str
        "hole", "open boundary", "gap" (a sliver between faces, at most
        :data:`GAP_WIDTH` x its length wide, or between it and other faces' free edges
        its edges all run beside) or "not capped" (no cap as a graph over its plane:
        ``why`` says why).
    slope : float
        Degrees: the surroundings' slope figure (NaN without one).
    fill : bool
        Whether approximants are built over it (they may still not fit: the
        report's patches and notes say).
    why : str
        How it is filled, or why it is left open.
    boundaries : tuple of (list of four curves, tuple of int)
        The sub-patches' boundaries and their sides on the rim.
    cap : HoleCap or None
        The surface over it: the artificial projections of its patches lie on it
        (where no face or mesh is hit).
    """

    index: int
    edges: int
    faces: tuple[int, ...]
    kind: str
    slope: float
    fill: bool
    why: str
    boundaries: tuple = ()
    cap: HoleCap | None = None

    def as_dict(self) -> dict:
        return {"index": self.index, "edges": self.edges, "faces": list(self.faces),
                "kind": self.kind, "slope_deg": None if np.isnan(self.slope) else self.slope,
                "fill": self.fill, "sub_patches": len(self.boundaries), "why": self.why}


def _loop(index: int, loop: Sequence[FaceEdge], faces: list[TrimmedFace | None], fill: str,
          gap_tol: float, beside: dict[int, float]) -> FreeLoop:
    curves = [e.curve for e in loop]
    owners = tuple(sorted({e.face for e in loop}))
    head = {"index": index, "edges": len(loop), "faces": owners}
    width, length = loop_width(curves)
    if width <= GAP_WIDTH * length:
        # edges paired one to one are not free: a loop within gap_tol is a T-junction,
        # which sewing joins (and closing gaps closes in the geometry where faces move)
        return FreeLoop(**head, kind="gap", slope=float("nan"), fill=False,
                        why=f"a gap between faces up to {width:.3g} wide along {length:.4g} "
                            f"(a sliver, not a hole): {_gap_how(width, gap_tol)}")
    if all(id(e) in beside for e in loop):
        # its other side is another loop: a pipe's mouth a little off the hole it
        # should meet (the spaceship's nozzles, 0.9 to 1.2 mm from the body)
        wide = max(beside[id(e)] for e in loop)
        return FreeLoop(**head, kind="gap", slope=float("nan"), fill=False,
                        why=f"a gap between faces up to {wide:.3g} wide: its edges run beside "
                            "other faces' free edges (a sliver between two loops, not a hole "
                            f"nor a boundary): {_gap_how(wide, gap_tol)}")
    rim = np.concatenate([e.samples for e in loop])
    reach = REACH * float(np.ptp(rim, axis=0).max())
    bounding = [faces[i] for i in owners if faces[i] is not None]
    around = surroundings(bounding, rim, reach=reach)
    four = [(curves, ALL_SIDES)] if len(loop) == 4 else []
    try:
        cap = cap_hole(curves, around)
    except NotCappableError as exc:
        # four edges are tried as ever (whether the approximant fits decides)
        return FreeLoop(**head, kind="not capped", slope=float("nan"),
                        fill=bool(four) and fill != "none",
                        why=f"{exc}" + ("; one patch over its four edges tried" if four
                                        and fill != "none" else "; left open"),
                        boundaries=tuple(four) if fill != "none" else ())
    head.update(kind=cap.kind.value, slope=cap.slope)
    if fill == "none":
        return FreeLoop(**head, fill=False, why="left open: fill='none'")
    if cap.kind is LoopKind.OPEN and cap.covered > MAX_COVERED:
        return FreeLoop(**head, fill=False, why=f"left open: faces lie over its inside "
                                                f"({100 * cap.covered:.0f}% of the points "
                                                "near it): the outer edge of a sheet")
    if cap.kind is LoopKind.OPEN and fill == "holes":
        return FreeLoop(**head, fill=False, why=f"left open: its surroundings turn away "
                                                f"from it by {cap.slope:.0f} degrees")
    if four:
        return FreeLoop(**head, fill=True, why="one patch over its four edges",
                        boundaries=tuple(four), cap=cap)
    try:
        quads = hole_quads(cap)
    except NotDecomposableError as exc:
        return FreeLoop(**head, fill=False, why=f"left open: not split into four-sided "
                                                f"patches ({exc})")
    how = "one patch" if len(quads) == 1 else f"{len(quads)} patches around a centre"
    return FreeLoop(**head, fill=True, why=f"{how} over its {len(loop)} edges",
                    boundaries=tuple(quads), cap=cap)


def _gap_how(width: float, gap_tol: float) -> str:
    return (f"sewn: its sides lie within gap_tol ({gap_tol:.3g}) of each other, one "
            "against several edges" if width <= gap_tol else
            "left open: wider than gap_tol, and not a ring (two loops beside each other "
            "all round, bridged by strips: the report's rings)")


def _beside(free: Sequence[FaceEdge], gap_tol: float) -> dict[int, float]:
    """``id(edge) -> width`` of the free edges that run beside another face's free edge
    (a gap's side: :func:`~surfprep.algorithms.healing.free_boundary.classify_free_edges`),
    the gap's width along them."""
    if not free:
        return {}
    sides = classify_free_edges([e.samples for e in free], [e.face for e in free],
                                join=gap_tol)
    return {id(e): float(w) for e, kind, w in zip(free, sides.kinds, sides.widths)
            if kind == "gap"}


def plan_loops(loops: Sequence[Sequence[FaceEdge]], faces: list[TrimmedFace | None], *,
               fill: str = "holes", gap_tol: float = 0.0,
               free: Sequence[FaceEdge] = ()) -> list[FreeLoop]:
    """Each loop of free edges classified and, where ``fill`` says, its fill planned
    (module docstring).

    Parameters
    ----------
    loops : sequence of sequence of FaceEdge
        In loop order (:func:`surfprep.algorithms.healing.adjacency.hole_loops`).
    faces : list of TrimmedFace or None
        The model's faces (those of the loops' edges sampled for the surroundings).
    fill : "holes", "all" or "none"
    gap_tol : float
        A gap loop no wider than this is sewn (said so in its ``why``), not left open.
    free : sequence of FaceEdge, optional
        Every free edge of the model (the loops' and the others, a loop of one face's
        edges too): a loop whose every edge runs beside another face's free edge is a
        gap between it and them, neither a hole nor a boundary.

    Returns
    -------
    list of FreeLoop
    """
    if fill not in FILL_RULES:
        raise InvalidGeometryError(f"fill must be one of {', '.join(map(repr, FILL_RULES))}, "
                                   f"got {fill!r}")
    beside = _beside(free, gap_tol)
    return [_loop(k, loop, faces, fill, gap_tol, beside) for k, loop in enumerate(loops)]
