"""The result of surface-surface intersection: sampled curves with their interpolants.

An :class:`IntersectionCurve` holds the refined samples (000 §29.4.6: "Common
representations are piecewise linear or cubic curve representations in physical
and/or parameter space") and three interpolants sharing one parametrization
(cumulative chord length of the 3D samples): ``curve3d`` through the points and
the pcurves ``pcurve_a``, ``pcurve_b`` through the (u, v) on each surface, all
from :func:`surfprep.algorithms.fitting.interpolate_curve` (cubic where there
are 4 samples or more; a closed curve gets a C1 closure).

:func:`intersection_curves` runs steps 5–6 on a segment topology: refine every
traced sample onto the exact surfaces (:func:`refine_chains`; or project onto
the exact side of a mesh x NURBS pair, or nothing for mesh x mesh), then keep
the samples the cubic interpolants need to stay within ``tol``
(:func:`sampled_curves`, :mod:`.sampling`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..curve import NurbsCurve
from ..measure import arc_length
from ..surface import NurbsSurface
from ..tolerance import check_tolerance
from .interpolants import (
    interpolate_samples,
    interpolate_stacked,
    sample_parameters,
    span_errors,
)
from .refine import RefinedCurve, project_points, refine_curves
from .sampling import cubic_samples
from .sampling_rounds import Refiner
from .topology import Chain, EndKind, SegmentTopology

__all__ = [
    "CurveDeviation",
    "IntersectionCurve",
    "checked_curves",
    "interpolate_samples",
    "intersection_curves",
    "refine_chains",
    "sampled_curves",
]

#: relative accuracy of :attr:`IntersectionCurve.length` (far below any tol / length)
LENGTH_REL_TOL = 1e-9


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
        t = sample_parameters(pts, bool(closed))
        if np.any(np.diff(t) <= 0):
            raise InvalidGeometryError("coincident consecutive samples")
        sing = np.zeros(n, dtype=bool) if singular is None else np.asarray(singular, dtype=bool)
        curves = [None, None, None]
        if interpolate:      # one collocation solve for all three (same parameters)
            curves = interpolate_stacked([pts, uvs[0], uvs[1]], t, bool(closed))
        return cls._frozen(pts, uvs[0], uvs[1], bool(closed), start_kind, end_kind, t, curves,
                           sing)

    @classmethod
    def _frozen(cls, pts, uv_a, uv_b, closed, start_kind, end_kind, t, curves, sing
                ) -> IntersectionCurve:
        for a in (pts, t, sing, *[u for u in (uv_a, uv_b) if u is not None]):
            a.setflags(write=False)
        return cls(pts, uv_a, uv_b, closed, start_kind, end_kind, t, *curves, sing)

    @property
    def length(self) -> float:
        """Length of the curve: of ``curve3d`` (:func:`measure.arc_length`), or of the
        polyline of the samples (closing chord included) without interpolants.
        The interpolant's length is integrated to ``LENGTH_REL_TOL`` relative to
        itself (bounded work and memory whatever the curve's size).

        The samples are only as dense as the cubic interpolants need, so their
        polyline is shorter than the curve by about ``kappa^2 h^2 / 24`` relative.
        """
        if self.curve3d is None:
            return float(self.parameters[-1])
        return arc_length(self.curve3d, tol=LENGTH_REL_TOL)

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
        return span_errors(self.span_parameters(samples_per_span), self.curve3d,
                           self.pcurve_a, self.pcurve_b, surface_a, surface_b)

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
def refine_chains(topology: SegmentTopology, surface_a: NurbsSurface, surface_b: NurbsSurface,
                  *, tol: float) -> tuple[list[Chain], list[RefinedCurve]]:
    """Step 5 on every traced chain: all its samples refined onto both surfaces.

    :func:`refine.refine_curves` without insertion or removal (``F_n`` anchored
    at each start point, to ``tol / 16``). Chains with fewer than 2 points (3
    when closed) are skipped; returns the chains kept and their dense curves.
    """
    if topology.uv_a is None or topology.uv_b is None:
        raise InvalidGeometryError("NURBS x NURBS refinement needs uv_a and uv_b")
    chains = [c for c in topology.chains if len(c) >= 2 + c.closed]
    refined = refine_curves(surface_a, surface_b, [topology.uv_a[c.point_ids] for c in chains],
                            [topology.uv_b[c.point_ids] for c in chains],
                            [c.closed for c in chains], tol=tol, max_passes=0, simplify=False)
    return chains, refined


def sampled_curves(refined: Sequence[RefinedCurve], kinds: Sequence[tuple[EndKind, EndKind]],
                   surface_a: NurbsSurface, surface_b: NurbsSurface, *, tol: float,
                   simplify: bool = True, max_rounds: int = 40) -> list[IntersectionCurve]:
    """Step 6: the samples the cubic interpolants need (:func:`.sampling.cubic_samples`)
    and the curves with their interpolants; ``kinds`` are the (start, end) kinds."""
    return checked_curves(refined, kinds, surface_a, surface_b, tol=tol, simplify=simplify,
                          max_rounds=max_rounds)[0]


def checked_curves(refined: Sequence[RefinedCurve], kinds: Sequence[tuple[EndKind, EndKind]],
                   surface_a: NurbsSurface, surface_b: NurbsSurface, *, tol: float,
                   simplify: bool = True, max_rounds: int = 40, aligned: bool = False,
                   refiner: Refiner | None = None) -> tuple[list[IntersectionCurve], NDArray]:
    """:func:`sampled_curves` and each curve's largest deviation ``(c,) float`` (as
    :meth:`IntersectionCurve.max_deviation` measures it: at a quarter, the midpoint
    and three quarters of every span), taken from the sampling's last check
    where it passed, measured otherwise. A curve collapsed onto a point is left
    out, or, with ``aligned``, given as None (deviation NaN), so that the output
    lines up with ``refined``. ``refiner``: as in :func:`.sampling.cubic_samples`."""
    out, worst = [], []
    extra = {} if refiner is None else {"refiner": refiner}
    for sampled, (start, end) in zip(cubic_samples(surface_a, surface_b, refined, tol=tol,
                                                   simplify=simplify, max_rounds=max_rounds,
                                                   **extra), kinds):
        if sampled is None:                    # collapsed onto a point
            if aligned:
                out.append(None)
                worst.append(float("nan"))
            continue
        r = sampled.curve
        if sampled.interpolants is None:
            curve = IntersectionCurve.from_samples(r.points, r.uv_a, r.uv_b, r.closed, start,
                                                   end, singular=r.singular)
            out.append(curve)
            worst.append(curve.max_deviation(surface_a, surface_b).max)
            continue
        out.append(IntersectionCurve._frozen(
            np.array(r.points, dtype=float), np.array(r.uv_a, dtype=float),
            np.array(r.uv_b, dtype=float), bool(r.closed), start, end,
            np.array(sampled.parameters, dtype=float), list(sampled.interpolants),
            np.array(r.singular, dtype=bool)))
        worst.append(sampled.error)
    return out, np.array(worst, dtype=float)


def intersection_curves(topology: SegmentTopology, surface_a: NurbsSurface | None,
                        surface_b: NurbsSurface | None, *, tol: float = 1e-7,
                        simplify: bool = True, max_splits: int = 40
                        ) -> list[IntersectionCurve]:
    """Steps 5–6 on traced chains: refine, sample for the cubic interpolants, interpolate.

    * NURBS x NURBS: every traced sample refined (:func:`refine_chains`), then
      :func:`.sampling.cubic_samples` keeps the samples the C2 cubic interpolants
      need to stay within ``tol / 2`` of both surfaces at three points per span
      (a curvature-spaced subset, then up to ``max_splits`` rounds inserting
      dense or newly refined samples where a span fails); ``simplify=False``
      keeps every traced sample and only inserts.
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
        chains, refined = refine_chains(topology, surface_a, surface_b, tol=tol)
        return sampled_curves(refined, [(c.start_kind, c.end_kind) for c in chains],
                              surface_a, surface_b, tol=tol, simplify=simplify,
                              max_rounds=max_splits)
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
