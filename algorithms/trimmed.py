"""Trimmed faces as plain data: a NURBS surface and loops of edges in its parameter domain.

:class:`TrimmedFace` is a face of a B-rep in NURBS terms: its
:class:`~surfprep.algorithms.NurbsSurface` and its trimming loops
(:class:`TrimLoop`), each a closed sequence of :class:`TrimEdge` occurrences
carrying the edge's 3D curve, its pcurve (the curve in the surface's ``(u, v)``)
over the same parameter range, the orientation of the occurrence in the loop and
the tolerances OpenCascade kept with it. The outer loop runs counter-clockwise in
``(u, v)``, holes clockwise, as in a ``TopoDS_Face`` seen FORWARD.

The types hold numpy arrays only: reading them from and building them into
OpenCascade faces is :mod:`surfprep.plugin.occ.faces`; which ``(u, v)`` lie
inside a trimmed face is :mod:`.face_region`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .surface import NurbsSurface

__all__ = [
    "DEFAULT_TOLERANCE",
    "LOOP_SAMPLES_PER_EDGE",
    "TrimEdge",
    "TrimLoop",
    "TrimmedFace",
    "curve3d_points",
    "edge_deviation",
    "is_natural",
    "loop_uv",
    "natural_loop",
]

#: Default tolerance of edges, vertices and faces (OpenCascade's Precision::Confusion).
DEFAULT_TOLERANCE = 1e-7
#: pcurve samples per edge of a trimming loop (:func:`loop_uv`)
LOOP_SAMPLES_PER_EDGE = 33


@dataclass(frozen=True, eq=False)
class TrimEdge:
    """One edge of a trimming loop, as it is used in the loop.

    Attributes
    ----------
    curve3d : NurbsCurve (d=3) or None
        The edge's 3D curve restricted to ``[t0, t1]``; ``None`` for a
        degenerated edge (a surface pole) or when only the pcurve is known.
    pcurve : NurbsCurve (d=2)
        The edge's curve in the surface's ``(u, v)`` parameters, over the same
        range ``[t0, t1]`` (same parameter as ``curve3d``): for this
        occurrence of the edge (on a seam, the pcurve of this side).
    t0, t1 : float
        Edge range, in the natural direction of the curves.
    reversed : bool
        True when the loop runs along the edge from ``t1`` to ``t0``.
    tolerance : float
        OpenCascade's edge tolerance (max. distance between the 3D curve and
        the pcurve mapped through the surface).
    vertex_tolerances : (float, float)
        Tolerances of the edge's vertices at ``t0`` and at ``t1`` (how far the
        curve ends may be from the loop's corners); kept so that a rebuilt face
        tolerates what the original did.
    seam_pcurve : NurbsCurve (d=2) or None
        For a seam edge (one edge used twice on a closed surface) the pcurve
        of the other side; ``None`` otherwise.
    degenerated : bool
        True for an edge collapsed to a point in 3D.
    """

    curve3d: NurbsCurve | None
    pcurve: NurbsCurve
    t0: float
    t1: float
    reversed: bool = False
    tolerance: float = DEFAULT_TOLERANCE
    seam_pcurve: NurbsCurve | None = None
    degenerated: bool = False
    vertex_tolerances: tuple[float, float] = (DEFAULT_TOLERANCE, DEFAULT_TOLERANCE)

    def __post_init__(self) -> None:
        if self.pcurve.dimension != 2:
            raise InvalidGeometryError(f"pcurve must be 2D, got dimension {self.pcurve.dimension}")
        if self.curve3d is not None and self.curve3d.dimension != 3:
            raise InvalidGeometryError(f"curve3d must be 3D, got dimension {self.curve3d.dimension}")
        if self.seam_pcurve is not None and self.seam_pcurve.dimension != 2:
            raise InvalidGeometryError("seam_pcurve must be 2D")
        object.__setattr__(self, "vertex_tolerances",
                           tuple(float(x) for x in self.vertex_tolerances))
        if len(self.vertex_tolerances) != 2:
            raise InvalidGeometryError("vertex_tolerances must be (at t0, at t1)")
        if not self.t0 < self.t1:
            raise InvalidGeometryError(f"empty edge range [{self.t0}, {self.t1}]")
        object.__setattr__(self, "t0", float(self.t0))
        object.__setattr__(self, "t1", float(self.t1))

    @property
    def is_seam(self) -> bool:
        return self.seam_pcurve is not None

    def __repr__(self) -> str:
        kind = "degenerated" if self.degenerated else ("seam" if self.is_seam else "edge")
        return (f"TrimEdge({kind}, range=({self.t0:g}, {self.t1:g}), reversed={self.reversed}, "
                f"tolerance={self.tolerance:g})")

    def corner_tolerances(self) -> tuple[float, float]:
        """Vertex tolerances at the start and end of this occurrence, in loop direction."""
        a, b = self.vertex_tolerances
        return (b, a) if self.reversed else (a, b)

    def uv_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """Start and end of this occurrence in ``(u, v)``, in loop direction."""
        a, b = self.pcurve.evaluate(np.array([self.t0, self.t1]))
        return (b, a) if self.reversed else (a, b)


@dataclass(frozen=True, eq=False)
class TrimLoop:
    """A closed loop of edges (an OpenCascade wire), in loop order."""

    edges: tuple[TrimEdge, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "edges", tuple(self.edges))
        if not self.edges:
            raise InvalidGeometryError("a trimming loop needs at least one edge")

    def __repr__(self) -> str:
        return f"TrimLoop({len(self.edges)} edges)"


@dataclass(frozen=True, eq=False)
class TrimmedFace:
    """A trimmed face in NURBS terms.

    Attributes
    ----------
    surface : NurbsSurface
        The face's surface, its location applied.
    loops : tuple of TrimLoop
        Every wire of the face, in the orientation it has in the face seen as
        FORWARD (outer loop counter-clockwise in ``(u, v)``, holes clockwise).
    outer_loop_index : int
        Index of the outer loop in ``loops`` (0 when there is no loop).
    reversed : bool
        The face's orientation: True when its normal is opposite to
        ``S_u x S_v``.
    name : str or None
    internal : tuple of TrimEdge
        Edges inside the face that bound nothing: an intersection curve that stops
        inside it (the edge where a fin stands on a sheet), OpenCascade's INTERNAL
        edges. Each runs ``t0 -> t1`` (``reversed`` False); the loops do not include
        them, so which points lie inside the face does not depend on them.
    """

    surface: NurbsSurface
    loops: tuple[TrimLoop, ...] = ()
    outer_loop_index: int = 0
    reversed: bool = False
    name: str | None = None
    internal: tuple[TrimEdge, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "loops", tuple(self.loops))
        object.__setattr__(self, "internal", tuple(self.internal))
        if self.loops and not 0 <= self.outer_loop_index < len(self.loops):
            raise InvalidGeometryError(
                f"outer_loop_index {self.outer_loop_index} out of range for {len(self.loops)} loops")

    def __repr__(self) -> str:
        inner = f", internal={len(self.internal)}" if self.internal else ""
        return (f"TrimmedFace({self.surface!r}, loops={[len(lp.edges) for lp in self.loops]}, "
                f"outer_loop_index={self.outer_loop_index}, reversed={self.reversed}, "
                f"name={self.name!r}{inner})")

    @property
    def edges(self) -> tuple[TrimEdge, ...]:
        """All edge occurrences of all loops."""
        return tuple(e for loop in self.loops for e in loop.edges)

    def parameter_box(self) -> tuple[float, float, float, float]:
        """``(u0, u1, v0, v1)`` holding the face: the box of its loops' pcurve control
        points (each pcurve, restricted to the part its edge uses, lies in their
        hull; all loops, so that a hole taken for the outer loop cannot shrink it),
        within the surface's domain; the whole domain without loops, or when a
        pcurve reaches outside the domain (a periodic surface's pcurve shifted by a
        period)."""
        domain = self.surface.domain
        if not self.loops:
            return domain
        u0, u1, v0, v1 = domain
        pad = 1e-9 * max(u1 - u0, v1 - v0)
        poles = np.concatenate([_used_poles(c, e.t0, e.t1) for e in self.edges
                                for c in (e.pcurve, e.seam_pcurve) if c is not None])
        low, high = poles.min(axis=0), poles.max(axis=0)
        if not (np.all(np.isfinite(poles)) and low[0] >= u0 - pad and high[0] <= u1 + pad
                and low[1] >= v0 - pad and high[1] <= v1 + pad):
            return domain
        return (max(float(low[0]), u0), min(float(high[0]), u1),
                max(float(low[1]), v0), min(float(high[1]), v1))

    def bounding_box(self) -> NDArray:
        """``(2, d)`` box holding the face: the control net's box of the surface
        restricted to :meth:`parameter_box` (exact restriction, so the face lies
        inside it; the whole surface's box when the face spans its domain or the
        restriction would be degenerate). Tighter than ``surface.bounding_box()``
        for a face trimmed from a larger surface."""
        box = self.parameter_box()
        u0, u1, v0, v1 = self.surface.domain
        if box == (u0, u1, v0, v1) or not (box[1] > box[0] and box[3] > box[2]):
            return self.surface.bounding_box()
        try:
            return self.surface.restrict(*box).bounding_box()
        except (InvalidGeometryError, ValueError):          # a box too thin to cut out
            return self.surface.bounding_box()


def _used_poles(pcurve: NurbsCurve, t0: float, t1: float) -> NDArray:
    """``(m, 2)`` control points of ``pcurve`` over ``[t0, t1]`` (the curve restricted
    when the edge uses only part of it; as it is when it cannot be)."""
    a, b = pcurve.domain
    lo, hi = min(t0, t1), max(t0, t1)
    if a <= lo < hi <= b and (lo > a or hi < b):
        try:
            pcurve = pcurve.restrict(lo, hi)
        except (InvalidGeometryError, ValueError):
            pass
    return np.asarray(pcurve.control_points, dtype=float)[:, :2]


def curve3d_points(edge: TrimEdge, surface: NurbsSurface, t: np.ndarray) -> np.ndarray:
    """Points ``(m, 3)`` of the edge at ``t (m,)``: its 3D curve, else its pcurve through the surface."""
    if edge.curve3d is not None:
        return edge.curve3d.evaluate(t)
    uv = edge.pcurve.evaluate(t)
    return surface.evaluate(uv[:, 0], uv[:, 1])


def edge_deviation(edge: TrimEdge, surface: NurbsSurface, samples: int = 33) -> float:
    """Max distance between the 3D curve and the pcurve(s) mapped through the surface."""
    if edge.curve3d is None:
        return 0.0
    t = np.linspace(edge.t0, edge.t1, samples)
    c = edge.curve3d.evaluate(t)
    dev = 0.0
    for pc in (edge.pcurve, edge.seam_pcurve):
        if pc is not None:
            uv = pc.evaluate(t)
            dev = max(dev, float(np.max(np.linalg.norm(surface.evaluate(uv[:, 0], uv[:, 1]) - c, axis=1))))
    return dev


def loop_uv(loop: TrimLoop) -> NDArray:
    """(n, 2) float: one trimming loop sampled along its pcurves, in loop order."""
    parts = []
    for e in loop.edges:
        t = np.linspace(e.t0, e.t1, LOOP_SAMPLES_PER_EDGE)
        uv = e.pcurve.evaluate(t[::-1] if e.reversed else t)
        parts.append(uv[:-1])
    return np.concatenate(parts)


def is_natural(face: TrimmedFace) -> bool:
    """No loop, or one loop running along the domain's rectangle: the face is its
    whole surface."""
    if not face.loops:
        return True
    if len(face.loops) != 1:
        return False
    u0, u1, v0, v1 = face.surface.domain
    eps = 1e-7 * max(u1 - u0, v1 - v0)
    uv = loop_uv(face.loops[0])
    on_side = ((np.abs(uv[:, 0] - u0) <= eps) | (np.abs(uv[:, 0] - u1) <= eps)
               | (np.abs(uv[:, 1] - v0) <= eps) | (np.abs(uv[:, 1] - v1) <= eps))
    return bool(np.all(on_side))


def natural_loop(surface: NurbsSurface) -> TrimLoop:
    """The surface's whole rectangle as a counter-clockwise loop of four edges: the loop
    of an untrimmed face (the pcurves on the surface's own parameters, the iso-lines as
    3D curves; a side of no length, a pole, is a degenerated edge)."""
    u0, u1, v0, v1 = surface.domain
    box = surface.bounding_box()
    tiny = 1e-12 * float(np.linalg.norm(box[1] - box[0]))
    sides = (((u0, v0), (u1, v0), "v", v0, u0, u1, False), ((u1, v0), (u1, v1), "u", u1, v0, v1, False),
             ((u0, v1), (u1, v1), "v", v1, u0, u1, True), ((u0, v0), (u0, v1), "u", u0, v0, v1, True))
    edges = []
    for a, b, held, value, t0, t1, backwards in sides:
        pcurve = NurbsCurve(np.array([a, b], float), np.array([t0, t0, t1, t1]), 1)
        curve3d = surface.isocurve(value, "u" if held == "u" else "v")
        ends = curve3d.evaluate(np.array([t0, 0.5 * (t0 + t1), t1]))
        degenerate = float(np.max(np.linalg.norm(ends - ends[0], axis=1))) <= tiny
        edges.append(TrimEdge(None if degenerate else curve3d, pcurve, t0, t1, backwards,
                              degenerated=degenerate))
    return TrimLoop(tuple(edges))
