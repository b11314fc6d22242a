"""Gap and normal angle along a shared edge, measured on the surfaces (the G0/G1 joins of
001 §8 checked).

Not taken from the construction: each side is sampled densely, every sample is
projected onto the other patch's boundary curve (closest point, Newton
on the exact curve), the distance is the gap there and the angle between the
unit normals of the two surfaces at the sample and at its foot point is the
normal angle (orientation ignored: ``atan2(|n_a x n_b|, |n_a . n_b|)``). Both directions
are measured and the worse one is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import DegenerateGeometryError
from ..measure import normals
from ..projection import project_to_curve
from ..surface import NurbsSurface
from .connectivity import SharedEdge, Side

__all__ = ["JOIN_SAMPLES", "JoinReport", "measure_join"]

#: samples per side for the measured join
JOIN_SAMPLES = 201


@dataclass(frozen=True)
class JoinReport:
    """Measured join of one shared edge.

    Attributes
    ----------
    a, side_a, b, side_b, reversed : as in :class:`.connectivity.SharedEdge`
    max_gap, rms_gap : float
        Distances (model units) from the samples of each side to the other
        side's boundary curve.
    max_angle, rms_angle : float
        Angle (degrees) between the surface normals at the samples and at their
        closest points.
    samples : int
        Samples per side.
    """

    a: int
    side_a: Side
    b: int
    side_b: Side
    reversed: bool
    max_gap: float
    rms_gap: float
    max_angle: float
    rms_angle: float
    samples: int

    def as_dict(self) -> dict:
        return {"patch_a": self.a, "side_a": self.side_a.value, "patch_b": self.b,
                "side_b": self.side_b.value, "reversed": self.reversed,
                "max_gap": self.max_gap, "rms_gap": self.rms_gap,
                "max_angle_deg": self.max_angle, "rms_angle_deg": self.rms_angle,
                "samples": self.samples}


def _normals(surface: NurbsSurface, uv: NDArray) -> NDArray:
    """(n, 3) float unit normals, NaN rows where the surface has none (a corner
    collapsed to a point, a patch degenerated along a side)."""
    try:
        return normals(surface, uv[:, 0], uv[:, 1])
    except DegenerateGeometryError:
        out = np.full((uv.shape[0], 3), np.nan)
        for k in range(uv.shape[0]):          # rare: only when some point has no normal
            try:
                out[k] = normals(surface, uv[k:k + 1, 0], uv[k:k + 1, 1])[0]
            except DegenerateGeometryError:
                pass
        return out


def _one_way(sa: NurbsSurface, side_a: Side, sb: NurbsSurface, side_b: Side, n: int,
             reversed_: bool = False) -> tuple[NDArray, NDArray]:
    """Gaps ``(n,)`` and angles ``(n,)`` (degrees) from side a's samples to side b.

    The closest points on side b start from the samples' positions carried over
    linearly (reversed when the sides run opposite ways): the shared sides
    correspond, so no global search is needed; a start in a wrong valley could
    only overstate a gap, never hide one."""
    lo, hi = side_a.running_domain(sa)
    s = np.linspace(0.0, 1.0, n)
    uv_a = side_a.uv(sa, lo + s * (hi - lo))
    points = sa.evaluate(uv_a[:, 0], uv_a[:, 1])
    curve_b = sb.isocurve(side_b.parameter(sb), side_b.fixed)
    lo_b, hi_b = side_b.running_domain(sb)
    guess = lo_b + (1.0 - s if reversed_ else s) * (hi_b - lo_b)
    foot = project_to_curve(curve_b, points, guess=guess)
    uv_b = side_b.uv(sb, foot.t)
    na = _normals(sa, uv_a)
    nb = _normals(sb, uv_b)
    cos = np.abs(np.einsum("nc,nc->n", na, nb))
    sin = np.linalg.norm(np.cross(na, nb), axis=1)
    return foot.distance, np.degrees(np.arctan2(sin, cos))


def measure_join(patches: list[NurbsSurface], edge: SharedEdge, *,
                 samples: int = JOIN_SAMPLES) -> JoinReport:
    """Gap and normal angle of ``edge`` measured on ``patches`` (both directions)."""
    ga, aa = _one_way(patches[edge.a], edge.side_a, patches[edge.b], edge.side_b, samples,
                      edge.reversed)
    gb, ab = _one_way(patches[edge.b], edge.side_b, patches[edge.a], edge.side_a, samples,
                      edge.reversed)
    gaps, angles = np.concatenate([ga, gb]), np.concatenate([aa, ab])
    return JoinReport(edge.a, edge.side_a, edge.b, edge.side_b, edge.reversed,
                      float(gaps.max()), float(np.sqrt(np.mean(gaps ** 2))),
                      _nan_max(angles), _nan_rms(angles), samples)


def _nan_max(values: NDArray) -> float:
    """Largest value where defined (angles where both normals exist); NaN if none."""
    finite = values[np.isfinite(values)]
    return float(finite.max()) if finite.size else float("nan")


def _nan_rms(values: NDArray) -> float:
    finite = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(finite ** 2))) if finite.size else float("nan")
