"""Where two trimmed *faces* coincide, given that their surfaces do (002's coincident case
taken to the faces).

The characteristic stage (:mod:`.algorithm`) finds where two *surfaces* coincide
within ``tol`` (:class:`~.algorithm.CoincidentRegion`). Two faces on one surface
(the mirrored halves of a shell of revolution, two faces cut from one sheet) meet
at most along a line although their surfaces coincide everywhere:
:func:`face_coincidence` measures the faces themselves, densely both ways, with
the point-in-face test of :mod:`surfprep.algorithms.face_region`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..face_region import FaceRegion
from ..projection import project_to_surface
from .algorithm import CoincidentRegion

__all__ = ["COINCIDENCE_SAMPLES", "face_coincidence"]

#: samples per direction of each face's domain
COINCIDENCE_SAMPLES = 41


def _on_other(ra: FaceRegion, rb: FaceRegion, tol: float, samples: int
              ) -> tuple[NDArray, NDArray, NDArray, int]:
    """Samples of face ``ra`` (inside it) lying within ``tol`` of face ``rb`` (their foot
    inside it): their ``uv`` on a, their feet's ``uv`` on b, their distances, and how
    many samples of a were inside a."""
    u0, u1, v0, v1 = ra.surface.domain
    t = (np.arange(samples) + 0.5) / samples          # cell centres: a shared edge is no overlap
    uu, vv = np.meshgrid(u0 + t * (u1 - u0), v0 + t * (v1 - v0), indexing="ij")
    uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
    uv = uv[ra.contains(uv)]
    inside = uv.shape[0]
    if inside == 0:
        return uv, uv, np.zeros(0), 0
    # a point within tol of a foot inside face b lies within tol of b's box: only
    # those are projected (faces that share an edge: a strip along it)
    points = ra.surface.evaluate(uv[:, 0], uv[:, 1])
    box = rb.face.bounding_box()
    near = np.all((points >= box[0] - tol) & (points <= box[1] + tol), axis=1)
    uv, points = uv[near], points[near]
    if uv.shape[0] == 0:
        return uv, uv, np.zeros(0), inside
    foot = project_to_surface(rb.surface, points)
    on = (foot.distance <= tol) & rb.contains(foot.uv)
    return uv[on], foot.uv[on], foot.distance[on], inside


def face_coincidence(ra: FaceRegion, rb: FaceRegion, tol: float,
                     samples: int = COINCIDENCE_SAMPLES) -> CoincidentRegion | None:
    """Where two *faces* coincide within ``tol``, measured densely both ways, or None.

    The characteristic stage finds where two *surfaces* coincide; two faces on one
    surface (the mirrored halves of a shell of revolution, a face and its neighbour
    cut from one sheet) meet at most along a line although their surfaces coincide
    everywhere. Here the centres of ``samples x samples`` cells of each face's domain
    that lie inside the face are projected onto the other surface (centres: faces
    that only share an edge have none on each other); a point coincides when it lies
    within ``tol`` of it and its foot inside the other face. ``share`` is the
    larger of the two faces' coinciding shares; ``box_a``, ``box_b`` bound the
    coinciding points in each domain (both ways); ``max_distance`` is the largest
    distance among them. None when no point of either face coincides.
    """
    a_uv, a_feet, a_dist, a_in = _on_other(ra, rb, tol, samples)
    b_uv, b_feet, b_dist, b_in = _on_other(rb, ra, tol, samples)
    if a_uv.shape[0] == 0 and b_uv.shape[0] == 0:
        return None
    on_a = np.concatenate([a_uv, b_feet])
    on_b = np.concatenate([a_feet, b_uv])
    share = max(a_uv.shape[0] / max(a_in, 1), b_uv.shape[0] / max(b_in, 1))
    return CoincidentRegion(np.stack([on_a.min(axis=0), on_a.max(axis=0)]),
                            np.stack([on_b.min(axis=0), on_b.max(axis=0)]), float(share),
                            float(np.concatenate([a_dist, b_dist]).max()))
