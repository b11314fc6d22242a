"""Curves of critical points: the degenerate case of 002 §4.2 (``det H = 0``).

A surface of revolution cut by a plane normal to its axis (a torus, a sphere,
a turned part against a face) gives a ``phi`` that is constant along the
circles of latitude: ``phi_u = 0`` identically, the u-characteristic curves
fill the domain, and the critical points are not isolated but form a curve
(a *ridge*, ``grad phi = 0`` and ``det H = 0`` all along it) on which ``phi``
is constant. The paper leaves this case out (its guarantee assumes isolated,
nondegenerate critical points). Here:

1. Newton with a pseudo-inverse (:func:`.points.critical_points`) lands on the
   ridge from the seeds :func:`.points.grid_seeds` puts on it;
2. from every degenerate critical point the ridge is traced both ways as the
   characteristic curve across it (``phi_v = 0`` when the Hessian's live
   eigenvector is mostly along ``v``, else ``phi_u = 0``), and kept as a ridge
   when the whole gradient stays within the noise along it;
3. a ridge with ``|phi| <= tol`` is a *tangential curve* (the plane touches the
   surface along a circle): reported as one intersection curve, not as the
   fragments a triangle method leaves along it;
4. a ridge that is a maximum with ``phi > tol`` or a minimum with
   ``phi < -tol`` is flanked by intersection curves on both sides (two circles
   close together when the plane is just below the top of a torus): rays across
   it from three of its samples give starts on them (:func:`.starts.ray_starts`),
   checked against the known curves like any other start.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..intersection.refine import RefinedPoints
from .curves import CurveKind, EndReason, TracedCurve, correct, trace_curves
from .distance import DistanceField, DistanceJet
from .points import PointKind
from .projector import ProjectionStatus
from .starts import Start, ray_starts

__all__ = ["RIDGE_NOISE", "Ridge", "ridge_refiner", "ridge_starts", "trace_ridges"]

#: a characteristic curve is a ridge when |grad phi| stays below this share of the
#: largest gradient on the grid all along it
RIDGE_NOISE = 1e-6


@dataclass(frozen=True)
class Ridge:
    """One curve of critical points.

    Attributes
    ----------
    curve : TracedCurve
        Its samples (kind: the characteristic family traced along it).
    phi : float
        The (constant) value of ``phi`` on it: mean of the samples.
    curvature : float
        The Hessian's live eigenvalue there (mean): negative on a maximum ridge.
    """

    curve: TracedCurve
    phi: float
    curvature: float

    def is_tangential(self, tol: float) -> bool:
        return bool(np.abs(self.curve.phi).max() <= tol)


def _on_curve(uv: NDArray, curve: TracedCurve, reach: float) -> NDArray:
    """``(m,) bool``: ``uv (m, 2)`` within ``reach`` of the curve's polyline."""
    p = curve.uv
    if p.shape[0] < 2:
        return np.linalg.norm(uv - p[0], axis=1) <= reach
    a, d = p[:-1], np.diff(p, axis=0)
    dd = np.maximum(np.einsum("sc,sc->s", d, d), 1e-300)
    t = np.clip(np.einsum("msc,sc->ms", uv[:, None] - a[None], d) / dd, 0, 1)
    gap = np.linalg.norm(a[None] + t[..., None] * d[None] - uv[:, None], axis=-1)
    return gap.min(axis=1) <= reach


def trace_ridges(field: DistanceField, crit: DistanceJet, kinds: list[PointKind],
                 grad_scale: float, h_max: float) -> list[Ridge]:
    """The ridges through the degenerate critical points of ``crit`` (module docstring).

    Parameters
    ----------
    crit : DistanceJet
        Critical points; ``kinds`` their classes (:func:`.points.classify_critical`).
    grad_scale : float
        Largest ``|grad phi|`` on the grid (the noise is ``RIDGE_NOISE`` of it).
    h_max : float
        Largest step of the tracer (parameter units).
    """
    rows = [i for i, k in enumerate(kinds) if k in (PointKind.DEGENERATE, PointKind.CUSP)]
    ridges: list[Ridge] = []
    noise = RIDGE_NOISE * grad_scale
    for i in rows:
        uv = crit.uv[i]
        if any(_on_curve(uv[None], r.curve, 1e-3 * field.diagonal)[0] for r in ridges):
            continue
        lam, vec = np.linalg.eigh(crit.hess[i])
        live = int(np.argmax(np.abs(lam)))
        across, along = vec[:, live], vec[:, 1 - live]
        kind = CurveKind.V_CHARACTERISTIC if abs(across[1]) >= abs(across[0]) \
            else CurveKind.U_CHARACTERISTIC
        both = trace_curves(field, [kind, kind], np.stack([uv, uv]), np.stack([crit.st[i]] * 2),
                            np.stack([along, -along]), h0=0.05 * h_max, h_max=h_max,
                            max_steps=400, ctol=1e-9 * field.diagonal, max_turn=0.3)
        curve = both[0] if both[0].end_reason is EndReason.CLOSED else both[0].after(both[1])
        if np.abs(curve.grad).max() > noise or curve.uv.shape[0] < 3:
            continue                          # an isolated degenerate point, not a ridge
        ridges.append(Ridge(curve, float(curve.phi.mean()), float(lam[live])))
    return ridges


def ridge_starts(field: DistanceField, ridges: list[Ridge], tol: float) -> Start:
    """Starts on the intersection curves flanking the maximum ridges with ``phi > tol``
    and minimum ridges with ``phi < -tol``: rays across each from three samples."""
    uv, st, kinds = [], [], []
    for r in ridges:
        if not ((r.curvature < 0 and r.phi > tol) or (r.curvature > 0 and r.phi < -tol)):
            continue
        pick = np.unique(np.linspace(0, r.curve.uv.shape[0] - 1, 3).astype(int))
        uv.append(r.curve.uv[pick])
        st.append(r.curve.st[pick])
        kinds += [PointKind.MAXIMUM if r.curvature < 0 else PointKind.MINIMUM] * pick.size
    if not uv:
        return Start.empty()
    jet = field.jet(np.concatenate(uv), np.concatenate(st))
    return ray_starts(field, jet, kinds, tol)


def ridge_refiner(field: DistanceField, kind: CurveKind):
    """New samples of a tangential curve put on its ridge (a refiner for
    :func:`..intersection.sampling.cubic_samples`).

    Where the surfaces touch along a curve, the points within ``tol`` of both form a
    band about ``sqrt(tol / curvature)`` wide, and the triangle method's refinement
    lands anywhere in it: neighbouring samples scatter across it, the interpolants
    wobble, and verification keeps splitting (12 465 samples on a torus's top
    circle at tol 1e-9). Here a sample is moved across the band onto the ridge by
    the corrector of the characteristic curve ``kind`` traced along it
    (``phi_u = 0`` or ``phi_v = 0``, :func:`.curves.correct`); its foot on ``q``
    comes with the jet, its gap is ``|phi|``.
    """
    def refine(surface_a, surface_b, uv_a, uv_b, *, tol, anchors=None, tangent_sin=None
               ) -> RefinedPoints:
        uv, st = (uv_b, uv_a) if field.swapped else (uv_a, uv_b)
        x, jet, ok = correct(field, kind, np.asarray(uv, dtype=float),
                              np.asarray(st, dtype=float), np.full(uv.shape[0], -1),
                              1e-12 * field.diagonal)
        foot = jet.projection.foot
        gap = np.linalg.norm(jet.point - foot, axis=1)
        ok &= (jet.status == ProjectionStatus.UNIQUE) & (gap <= tol)
        ua, ub = (jet.st, x) if field.swapped else (x, jet.st)
        n = x.shape[0]
        return RefinedPoints(0.5 * (jet.point + foot), ua.copy(), ub.copy(), gap,
                             np.zeros(n, dtype=np.int64), ok, np.zeros(n, dtype=bool))
    return refine
