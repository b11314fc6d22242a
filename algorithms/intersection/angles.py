"""How flat a crossing the triangle method of 000 §29.4 can follow at a given mesh tolerance.

The tessellations stray up to ``mesh_tol`` from their surfaces, so where two
surfaces cross at the angle ``theta`` the triangles cross up to about ``2
mesh_tol / theta`` beside the true curve. Once that exceeds a triangle's
width (about ``sqrt(8 mesh_tol / kappa)``), i.e. for ``theta`` below about
``sqrt(mesh_tol kappa)``, consecutive segments stop meeting: the traced chains
come out as fragments or zigzags, and a zigzag that the refinement cannot pull
within tol is dropped as stray. Measured on sheets crossing along a wavy line
at ``mesh_tol = 1e-3`` of the size: fragments or nothing at slopes 1e-3 and
5e-3, one correct curve from 1e-2 on.

* :func:`small_crossing_sine`: the limit, ``SMALL_ANGLE_SHARE sqrt(mesh_tol /
  size)`` (0.019 at the default mesh tolerance);
* :func:`normal_sines`: the sine of the angle between the exact normals at
  parameters of both surfaces (the segment ends of a triangle soup; the samples
  of :mod:`.singular_join`), and :func:`flat_share`, the share of them below the
  limit (``FLAT_SHARE`` or more: a flat crossing, not the short
  stretch round a double point).
"""

from __future__ import annotations

import numpy as np

from ..surface import NurbsSurface
from . import vectors

__all__ = ["FLAT_SHARE", "SMALL_ANGLE_SHARE", "flat_share", "normal_sines",
           "small_crossing_sine"]

#: the limit of the module docstring, times ``sqrt(mesh_tol / size)``
SMALL_ANGLE_SHARE = 0.6
#: a soup with this share of its segment ends below the limit crosses flat
FLAT_SHARE = 0.1


def small_crossing_sine(size: float, mesh_tol: float) -> float:
    """Sine below which a crossing is too flat for triangles at ``mesh_tol`` (model units)
    on operands of diagonal ``size``."""
    return SMALL_ANGLE_SHARE * float(np.sqrt(mesh_tol / max(size, np.finfo(float).tiny)))


def normal_sines(surface_a: NurbsSurface, surface_b: NurbsSurface, uv_a: np.ndarray,
                 uv_b: np.ndarray) -> np.ndarray:
    """``|N_a x N_b|`` ``(k,)`` at the parameters ``uv_a, uv_b (k, 2)`` (0 where a normal
    vanishes, as at a pole)."""
    if uv_a.shape[0] == 0:
        return np.zeros(0)
    da = surface_a.derivatives(uv_a[:, 0], uv_a[:, 1], 1)
    db = surface_b.derivatives(uv_b[:, 0], uv_b[:, 1], 1)
    na = vectors.cross(da[:, 1, 0], da[:, 0, 1])
    nb = vectors.cross(db[:, 1, 0], db[:, 0, 1])
    den = np.maximum(np.linalg.norm(na, axis=1) * np.linalg.norm(nb, axis=1),
                     np.finfo(float).tiny)
    return np.linalg.norm(vectors.cross(na, nb), axis=1) / den


def flat_share(sines: np.ndarray, limit: float) -> float:
    """Share of the segment ends whose sine is below ``limit`` (0 without any). Near a
    singular point (a double point, where the normals are parallel) the sine falls
    to zero only over a short stretch; a flat crossing keeps it small all along."""
    return float(np.mean(sines < limit)) if sines.size else 0.0
