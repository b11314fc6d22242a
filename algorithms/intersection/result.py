"""The result of surface-surface intersection: sampled curves with their interpolants.

An :class:`IntersectionCurve` holds the refined samples (000 §29.4.6: "Common
representations are piecewise linear or cubic curve representations in physical
and/or parameter space") and three interpolants sharing one parametrization
(cumulative chord length of the 3D samples): ``curve3d`` through the points and
the pcurves ``pcurve_a``, ``pcurve_b`` through the (u, v) on each surface, all
from :func:`surfprep.algorithms.fitting.interpolate_curve` (cubic where there
are 4 samples or more; a closed curve gets a C1 closure).

:func:`intersection_curves` runs steps 4–6 on a segment topology: trace,
refine onto the exact surfaces (or project onto the exact side of a
mesh x NURBS pair, or nothing for mesh x mesh), interpolate, and split the
spans whose interpolants stray from the surfaces by more than ``tol``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..curve import NurbsCurve
from ..fitting import interpolate_curve
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from .refine import project_points, refine_curves, refine_points
from .topology import EndKind, SegmentTopology

__all__ = ["IntersectionCurve", "CurveDeviation", "intersection_curves", "interpolate_samples"]


@dataclass(frozen=True)
class CurveDeviation:
    """Largest distances measured by :meth:`IntersectionCurve.max_deviation` (NaN: no such side).

    Attributes
    ----------
    to_a : float
        ``max |S_a(pcurve_a(t)) - curve3d(t)|``.
    to_b : float
        ``max |S_b(pcurve_b(t)) - curve3d(t)|``.
    gap : float
        ``max |S_a(pcurve_a(t)) - S_b(pcurve_b(t))|``.
    """

    to_a: float
    to_b: float
    gap: float

    @property
    def max(self) -> float:
        return float(np.nanmax([self.to_a, self.to_b, self.gap, 0.0]))


def _sample_parameters(points: NDArray, closed: bool) -> NDArray:
    """Cumulative chord length ``(n,)`` (``(n + 1,)`` when closed: the closing chord too)."""
    pts = np.vstack([points, points[:1]]) if closed else points
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])


def interpolate_samples(values: ArrayLike, parameters: ArrayLike, closed: bool) -> NurbsCurve:
    """The interpolant of samples: one call of :func:`fitting.interpolate_curve`.

    Parameters
    ----------
    values : (n, d) float
        A closed sequence does not repeat its first sample.
    parameters : (n,) float, or (n + 1,) float when closed
    closed : bool
        Closed: the first sample is appended, with a C1 (Bessel) closure when
        there are at least 4 samples.

    Returns
    -------
    NurbsCurve of degree ``min(3, samples - 1)``
    """
    q = np.asarray(values, dtype=float)
    if closed:
        q = np.vstack([q, q[:1]])
    degree = min(3, q.shape[0] - 1)
    return interpolate_curve(q, degree=degree, parameters=parameters,
                             smooth_closure=closed and q.shape[0] >= 4)


@dataclass(frozen=True)
class IntersectionCurve:
    """One intersection curve: samples on the true intersection and their interpolants.

    Attributes
    ----------
    points : (n, 3) float
    uv_a, uv_b : (n, 2) float or None
        Parameters on surface A / B (``None`` for a mesh operand).
    closed : bool
        A closed curve does not repeat its first sample.
    start_kind, end_kind : EndKind
    parameters : (n,) float, or (n + 1,) when closed
        Parameter of each sample on the interpolants (cumulative chord length).
    curve3d : NurbsCurve or None
    pcurve_a, pcurve_b : NurbsCurve (2D) or None
    singular : (n,) bool
        Samples where the surfaces are near-tangential.
    """

    points: NDArray
    uv_a: NDArray | None
    uv_b: NDArray | None
    closed: bool
    start_kind: EndKind
    end_kind: EndKind
    parameters: NDArray
    curve3d: NurbsCurve | None
    pcurve_a: NurbsCurve | None
    pcurve_b: NurbsCurve | None
    singular: NDArray

    @classmethod
    def from_samples(cls, points: ArrayLike, uv_a: ArrayLike | None, uv_b: ArrayLike | None,
                     closed: bool, start_kind: EndKind, end_kind: EndKind, *,
                     singular: ArrayLike | None = None, interpolate: bool = True
                     ) -> IntersectionCurve:
        """Build the curve and, with ``interpolate``, its three interpolants.

        Raises
        ------
        InvalidGeometryError
            Shapes that do not match, fewer than 2 samples (3 when closed),
            coincident consecutive samples.
        """
        pts = np.array(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise InvalidGeometryError(f"points must have shape (n, 3), got {pts.shape}")
        n = pts.shape[0]
        if n < 2 + bool(closed):
            raise InvalidGeometryError(
                f"an {'closed' if closed else 'open'} curve needs >= {2 + bool(closed)} "
                f"samples, got {n}")
        uvs = []
        for name, uv in (("uv_a", uv_a), ("uv_b", uv_b)):
            uv = None if uv is None else np.array(uv, dtype=float)
            if uv is not None and uv.shape != (n, 2):
                raise InvalidGeometryError(f"{name} must have shape ({n}, 2), got {uv.shape}")
            uvs.append(uv)
        t = _sample_parameters(pts, bool(closed))
        if np.any(np.diff(t) <= 0):
            raise InvalidGeometryError("coincident consecutive samples")
        sing = np.zeros(n, dtype=bool) if singular is None else np.asarray(singular, dtype=bool)
        curves = [None, None, None]
        if interpolate:
            curves = [None if v is None else interpolate_samples(v, t, bool(closed))
                      for v in (pts, uvs[0], uvs[1])]
        for a in (pts, t, sing, *[u for u in uvs if u is not None]):
            a.setflags(write=False)
        return cls(pts, uvs[0], uvs[1], bool(closed), start_kind, end_kind, t, *curves, sing)

    @property
    def length(self) -> float:
        """Length of the polyline of the samples (closing chord included when closed)."""
        return float(self.parameters[-1])

    def span_parameters(self, samples_per_span: int = 3) -> NDArray:
        """``(spans, samples_per_span) float``: interior parameters of every span,
        equally spaced (odd counts include each span's midpoint)."""
        if int(samples_per_span) != samples_per_span or samples_per_span < 1:
            raise InvalidGeometryError(f"samples_per_span must be >= 1, got {samples_per_span!r}")
        s = np.arange(1, samples_per_span + 1) / (samples_per_span + 1)
        t = self.parameters
        return t[:-1, None] + s[None, :] * np.diff(t)[:, None]

    def span_deviation(self, surface_a: NurbsSurface | None, surface_b: NurbsSurface | None,
                       samples_per_span: int = 3) -> tuple[NDArray, NDArray, NDArray]:
        """Per span: ``(to_a, to_b, gap)``, three (spans,) float (NaN where a side is missing)."""
        if self.curve3d is None:
            raise InvalidGeometryError("the curve was built without interpolants")
        t = self.span_parameters(samples_per_span)
        c = self.curve3d.evaluate(t)
        on = []
        for surface, pcurve in ((surface_a, self.pcurve_a), (surface_b, self.pcurve_b)):
            if surface is None or pcurve is None:
                on.append(None)
                continue
            uv = pcurve.evaluate(t)
            on.append(surface.evaluate(uv[..., 0], uv[..., 1]))
        nan = np.full(t.shape[0], np.nan)
        dist = [nan if s is None else np.linalg.norm(s - c, axis=-1).max(axis=1) for s in on]
        gap = nan if any(s is None for s in on) else np.linalg.norm(on[0] - on[1], axis=-1).max(axis=1)
        return dist[0], dist[1], gap

    def max_deviation(self, surface_a: NurbsSurface | None, surface_b: NurbsSurface | None,
                      samples_per_span: int = 3) -> CurveDeviation:
        """Distances of the interpolants from the surfaces between the samples.

        At ``samples_per_span`` interior parameters of every span (with the default
        3: a quarter, the midpoint and three quarters) it measures
        ``|S_a(pcurve_a(t)) - curve3d(t)|``, ``|S_b(pcurve_b(t)) - curve3d(t)|``
        and the gap ``|S_a(pcurve_a(t)) - S_b(pcurve_b(t))|``: all within ``tol``
        means the interpolants lie within ``tol`` of the true intersection.
        """
        a, b, g = self.span_deviation(surface_a, surface_b, samples_per_span)

        def top(x: NDArray) -> float:
            return float(np.max(x)) if x.size and not np.all(np.isnan(x)) else float("nan")

        return CurveDeviation(top(a), top(b), top(g))


# ------------------------------------------------------------------ pipeline
def _split_failing(curve: IntersectionCurve, surface_a, surface_b, tol: float
                   ) -> IntersectionCurve | None:
    """Insert refined midpoints in the spans whose interpolants stray by more than tol;
    ``None`` when every span passes (or none can be split)."""
    to_a, to_b, gap = curve.span_deviation(surface_a, surface_b)
    bad = np.flatnonzero(np.nan_to_num(np.maximum(np.maximum(to_a, to_b), gap)) > tol)
    n = curve.points.shape[0]
    nxt = (bad + 1) % n
    mid = refine_points(surface_a, surface_b, 0.5 * (curve.uv_a[bad] + curve.uv_a[nxt]),
                        0.5 * (curve.uv_b[bad] + curve.uv_b[nxt]), tol=tol / 16,
                        anchors=0.5 * (curve.points[bad] + curve.points[nxt]))
    bad = bad[mid.converged]
    if bad.size == 0:
        return None
    order = np.argsort(np.concatenate([2 * np.arange(n), 2 * bad + 1]), kind="stable")

    def merged(a, b):
        return np.concatenate([a, b])[order]

    ok = mid.converged
    return IntersectionCurve.from_samples(
        merged(curve.points, mid.points[ok]), merged(curve.uv_a, mid.uv_a[ok]),
        merged(curve.uv_b, mid.uv_b[ok]), curve.closed, curve.start_kind, curve.end_kind,
        singular=merged(curve.singular, mid.singular[ok]))


def intersection_curves(topology: SegmentTopology, surface_a: NurbsSurface | None,
                        surface_b: NurbsSurface | None, *, tol: float = 1e-7,
                        simplify: bool = True, max_splits: int = 8
                        ) -> list[IntersectionCurve]:
    """Steps 5–6 on traced chains: refine, interpolate, check the interpolants.

    * NURBS x NURBS: :func:`refine.refine_curves` (auxiliary-plane method, chord
      midpoint insertion, redundant-point removal), then interpolants; spans whose
      interpolants stray by more than ``tol`` (:meth:`IntersectionCurve.span_deviation`)
      get a refined midpoint, up to ``max_splits`` rounds.
    * mesh x NURBS (one surface ``None``): the samples are projected onto the exact
      surface (:func:`refine.project_points`); no insertion.
    * mesh x mesh: the traced polyline is the result, without interpolants.

    Chains with fewer than 2 points (3 when closed) are skipped.

    Returns
    -------
    list of IntersectionCurve, in the order of ``topology.chains``
    """
    tol = check_tolerance(tol)
    chains = [c for c in topology.chains if len(c) >= 2 + c.closed]
    if surface_a is not None and surface_b is not None:
        if topology.uv_a is None or topology.uv_b is None:
            raise InvalidGeometryError("NURBS x NURBS refinement needs uv_a and uv_b")
        refined = refine_curves(surface_a, surface_b, [topology.uv_a[c.point_ids] for c in chains],
                                [topology.uv_b[c.point_ids] for c in chains],
                                [c.closed for c in chains], tol=tol, simplify=simplify)
        out = []
        for chain, r in zip(chains, refined):
            curve = IntersectionCurve.from_samples(r.points, r.uv_a, r.uv_b, r.closed,
                                                   chain.start_kind, chain.end_kind,
                                                   singular=r.singular)
            for _ in range(max_splits):
                split = _split_failing(curve, surface_a, surface_b, tol)
                if split is None:
                    break
                curve = split
            out.append(curve)
        return out
    exact = surface_a if surface_a is not None else surface_b
    side_uv = topology.uv_a if surface_a is not None else topology.uv_b
    if exact is not None and side_uv is None:
        raise InvalidGeometryError("projection onto the exact side needs its uv")
    out = []
    for chain in chains:
        pts = topology.points[chain.point_ids]
        uv_a = uv_b = None
        if exact is not None:
            uv, pts, _ = project_points(exact, pts, side_uv[chain.point_ids], tol=0.1 * tol)
            uv_a, uv_b = (uv, None) if surface_a is not None else (None, uv)
        out.append(IntersectionCurve.from_samples(pts, uv_a, uv_b, chain.closed,
                                                  chain.start_kind, chain.end_kind,
                                                  interpolate=exact is not None))
    return out
