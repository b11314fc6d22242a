"""Pairs the certificate (002 §6.3) need not examine: cheap, exact reasons why two surfaces
can have no closed loop and no isolated contact point.

The certificate (:func:`.algorithm.certify`) looks for closed loops around
critical points of ``phi`` and for tangential contact points. Two cases rule
both out from the control nets alone (the net's convex hull holds the surface):

* **apart**: no Bézier-patch box of one surface comes within ``tol`` of a
  patch box of the other: the surfaces do not meet at all (no curve either);
* **plane x ruled**: one surface is planar (its control points within
  ``PLANAR_SHARE * tol`` of a plane) and the other is a plane too or has a
  straight parameter direction (degree 1 with two control points: every
  isoparametric line in that direction is a straight segment, rational or
  not). A segment meets a plane once or lies in it, so the intersection is a
  graph over the other parameter: it cannot close inside the domain; and at a
  tangential contact the segment through the point lies in the tangent plane,
  i.e. in the plane, so the contact is a segment, not an isolated point. The
  rule is not applied when the other surface lies within ``tol`` of the plane
  (coincidence is the full analysis's answer to give);
* **plane x monotone height**: one surface is planar (normal ``n``) and the
  other, non-rational or with separable weights ``w_ij = a_i b_j`` (surfaces of
  revolution and extrusions from OpenCascade are), has a height ``h = n . S - c`` over it that is strictly
  monotone in ``u`` across each row of Bézier patches between the first and the
  last patch that comes within ``tol`` of the plane (every u-difference of the
  patches' control heights of one sign, each larger than ``tol``), or the same
  in ``v`` across the columns. A closed loop ``h = 0`` inside the domain is cut
  twice by some line ``v = const`` inside one row, at two points of patches
  near the plane, and ``h`` would have to turn between them (Rolle; for the
  rational case: the variation-diminishing property of a rational curve with
  positive weights, whose control heights all rise, makes it strictly
  monotone); an isolated contact point needs a local extremum of ``h``, which a
  function strictly monotone along every line ``v = const`` has not. Where the net is too
  coarse for the test, every span is halved (knot insertion, same surface) a few
  times. The whole-model cut of a ship hull by a waterline plane is of this
  kind on every face.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence

import numpy as np

from ..bezier import bezier_patches
from ..intersection import IntersectionCurve
from ..intersection.culling import (
    exact_patch_boxes,
    patch_rectangles,
    span_hull_boxes,
    surface_patch_boxes,
    surface_tree,
    tree_pairs,
)
from ..surface import NurbsSurface
from .algorithm import CharacteristicRecord, FoundBy
from .poles import collapsed_sides

__all__ = ["PLANAR_SHARE", "NoLoopReason", "no_loop_reason", "uncertified_record"]

#: a control net within this share of ``tol`` of a plane is planar
PLANAR_SHARE = 1e-3
#: span halvings at most for the monotone-height rule, and the largest net it may reach
REFINEMENTS, MAX_REFINED_POLES = 3, 40_000


class NoLoopReason(str, enum.Enum):
    """Why a pair can have no closed loop nor isolated contact point."""

    APART = "apart"
    PLANE_AND_RULED = "plane and ruled"
    MONOTONE_HEIGHT = "monotone height over a plane"


#: below this many patch pairs the Bézier boxes are compared all at once (no trees)
_DIRECT_PAIRS = 4096


def _apart(a: NurbsSurface, b: NurbsSurface, tol: float) -> bool:
    """No Bézier-patch box of ``a`` within ``tol`` of one of ``b``'s. Few patches: all
    pairs at once. Otherwise the span hull boxes (sliding min/max over the nets, which
    hold the Bézier boxes) are descended as grid trees first and exact Bézier boxes
    extracted only for the candidate pairs, so a large surface far from most of the
    other costs little."""
    # small nets: all pairs at once
    if patch_rectangles(a).shape[0] * patch_rectangles(b).shape[0] <= _DIRECT_PAIRS:
        ba, bb = surface_patch_boxes(a)[0], surface_patch_boxes(b)[0]
        return not bool(np.all((ba[:, None, 0] <= bb[None, :, 1] + tol)
                               & (bb[None, :, 0] <= ba[:, None, 1] + tol), axis=-1).any())
    pairs = tree_pairs(surface_tree(a), surface_tree(b), pad=tol)
    if pairs.shape[0] == 0:
        return True
    patches_a, inv_a = np.unique(pairs[:, 0], return_inverse=True)
    patches_b, inv_b = np.unique(pairs[:, 1], return_inverse=True)
    ba = exact_patch_boxes(a, patches_a)[inv_a.ravel()]
    bb = exact_patch_boxes(b, patches_b)[inv_b.ravel()]
    touch = np.all((ba[:, 0] <= bb[:, 1] + tol) & (bb[:, 0] <= ba[:, 1] + tol), axis=-1)
    return not bool(touch.any())


def _plane(s: NurbsSurface, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """``(point, unit normal)`` when the control net is planar within ``PLANAR_SHARE tol``."""
    pts = s.control_points.reshape(-1, s.dimension)
    if s.dimension != 3 or pts.shape[0] < 3:
        return None
    centre = pts.mean(axis=0)
    _, sv, vt = np.linalg.svd(pts - centre, full_matrices=False)
    if sv.size < 3 or sv[1] <= 0:
        return None
    normal = vt[2]
    if np.abs((pts - centre) @ normal).max() > PLANAR_SHARE * tol:
        return None
    return centre, normal


def _straight_direction(s: NurbsSurface) -> bool:
    """True when u or v is degree 1 with two control points (straight isolines)."""
    nu, nv = s.n_control
    return (s.degree_u == 1 and nu == 2) or (s.degree_v == 1 and nv == 2)


def _monotone_rows(near: np.ndarray, step_sign: np.ndarray) -> bool:
    """Every row ``j`` of ``near (ku, kv)`` has, from its first to its last near
    patch, the same nonzero ``step_sign[i, j]``."""
    for j in range(near.shape[1]):
        idx = np.flatnonzero(near[:, j])
        if idx.size == 0:
            continue
        signs = step_sign[idx[0]:idx[-1] + 1, j]
        if not (np.all(signs == 1) or np.all(signs == -1)):
            return False
    return True


def _separable_weights(w: np.ndarray) -> bool:
    """True when ``w[i, j] = a[i] b[j]`` (to rounding): then along a line ``v = const`` the
    control heights of the u-curve are the same convex combination of the rows'
    heights for every ``i``, so their differences are combinations of the net's."""
    outer = np.outer(w[:, 0], w[0, :]) / w[0, 0]
    return bool(np.abs(outer - w).max() <= 1e-12 * np.abs(w).max())


def _halved(s: NurbsSurface) -> NurbsSurface:
    """``s`` with a knot inserted in the middle of every span, both directions."""
    for direction, knots, degree in (("u", s.knots_u, s.degree_u), ("v", s.knots_v, s.degree_v)):
        k = np.unique(knots[degree:knots.size - degree])
        s = s.refine(0.5 * (k[:-1] + k[1:]), direction)
    return s


def _monotone_height(s: NurbsSurface, centre: np.ndarray, normal: np.ndarray,
                     tol: float) -> bool:
    """The plane x monotone height rule of the module docstring, on ``s`` and, while
    it fails and the net stays under ``MAX_REFINED_POLES``, on ``s`` with every span
    halved (up to ``REFINEMENTS`` times: the control net closes in on the surface)."""
    if s.dimension != 3 or (s.is_rational and not _separable_weights(s.weights)):
        return False
    near = _near_spans(s, centre, normal, tol)
    if near is None:                                   # no span comes near the plane
        return True
    # every sign change of the sampled heights lies in the near spans' rectangle, so
    # the whole surface answers _crossed_twice as its restriction does: where the
    # rectangle is most of it, ask before restricting (a loop round a bump)
    share = _share(s, near)
    if 0.5 < share < 1 and all(_crossed_twice(s, centre, normal)):
        return False
    s = _restricted(s, near)
    crossed = _crossed_twice(s, centre, normal)
    if all(crossed):                                   # a loop, as around a bump
        return False
    if all(c or f for c, f in zip(crossed, _flat_directions(s, centre, normal, tol))):
        return False
    for level in range(REFINEMENTS + 1):
        if _monotone_patches(s, centre, normal, tol):
            return True
        if level == REFINEMENTS or 4 * np.prod(s.n_control) > MAX_REFINED_POLES:
            return False
        s = _halved(s)
    return False


#: samples per knot span of the necessary-condition check (:func:`_crossed_twice`)
_TURN_SAMPLES = 4


def _crossed_twice(s: NurbsSurface, centre: np.ndarray, normal: np.ndarray
                   ) -> tuple[bool, bool]:
    """Per direction (u, v): some sampled line along it crosses the plane twice (a
    height monotone along it crosses once at most), so the rule cannot hold in that
    direction whatever the refinement."""
    grids = []
    for knots, degree in ((s.knots_u, s.degree_u), (s.knots_v, s.degree_v)):
        breaks = np.unique(knots[degree:knots.size - degree])
        share = np.arange(_TURN_SAMPLES) / _TURN_SAMPLES
        grids.append(np.append((breaks[:-1, None] + share * np.diff(breaks)[:, None]).ravel(),
                               breaks[-1]))
    h = s.evaluate_grid(*grids) @ normal - float(centre @ normal)          # (nu, nv)
    sign = np.sign(h)
    return (bool(np.any(np.count_nonzero(sign[1:] * sign[:-1] < 0, axis=0) >= 2)),
            bool(np.any(np.count_nonzero(sign[:, 1:] * sign[:, :-1] < 0, axis=1) >= 2)))


def _flat_directions(s: NurbsSurface, centre: np.ndarray, normal: np.ndarray, tol: float
                     ) -> tuple[bool, bool]:
    """Per direction (u, v): some Bézier patch near the plane has every control-height
    difference along it within ``tol``. Halving a span halves such differences (the
    new ones are halved convex combinations of the old) and one half stays near the
    plane, so the rule, which needs every difference over ``tol``, cannot hold in
    that direction whatever the refinement (the circles of a torus cut normal to
    its axis: its heights do not change along them at all)."""
    patches, _, _ = bezier_patches(s)                      # (ku, kv, p+1, q+1, 4)
    h = (patches[..., :3] / patches[..., 3:]) @ normal - float(centre @ normal)
    near = (h.min(axis=(2, 3)) <= tol) & (h.max(axis=(2, 3)) >= -tol)
    out = []
    for axis in (2, 3):
        d = np.abs(np.diff(h, axis=axis))
        out.append(bool(d.shape[axis] > 0 and np.any(near & (d <= tol).all(axis=(2, 3)))))
    return out[0], out[1]


def _near_spans(s: NurbsSurface, centre: np.ndarray, normal: np.ndarray, tol: float
                ) -> tuple[int, int, int, int] | None:
    """``(i0, i1, j0, j1)``: the index rectangle (spans ``i0 <= i < i1`` along u, ``j0 <=
    j < j1`` along v) of the knot spans whose span hull comes within ``tol`` of the
    plane, or None when none does."""
    hull = span_hull_boxes(s)                                  # (ku, kv, 2, 3)
    offset = float(centre @ normal)
    low = np.where(normal >= 0, hull[:, :, 0], hull[:, :, 1]) @ normal - offset
    high = np.where(normal >= 0, hull[:, :, 1], hull[:, :, 0]) @ normal - offset
    near = (low <= tol) & (high >= -tol)
    if not near.any():
        return None
    rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def _breaks(s: NurbsSurface) -> tuple[np.ndarray, np.ndarray]:
    return (np.unique(s.knots_u[s.degree_u:s.knots_u.size - s.degree_u]),
            np.unique(s.knots_v[s.degree_v:s.knots_v.size - s.degree_v]))


def _share(s: NurbsSurface, near: tuple[int, int, int, int]) -> float:
    """Share of the spans of ``s`` inside the rectangle ``near``."""
    u, v = _breaks(s)
    i0, i1, j0, j1 = near
    return (i1 - i0) * (j1 - j0) / ((u.size - 1) * (v.size - 1))


def _restricted(s: NurbsSurface, near: tuple[int, int, int, int]) -> NurbsSurface:
    """``s`` restricted (exactly, at knots) to the span rectangle ``near``
    (:func:`_near_spans`).

    The Bézier patches near the plane lie in those spans (a Bézier box is inside
    its span's hull), and so does, in every row, the stretch from the first to the
    last near patch: the rule's answer on the restriction is its answer on ``s``,
    at the cost of the patches near the plane (a waterline across a hull face with
    100 x 100 poles touches a few rows)."""
    u, v = _breaks(s)
    i0, i1, j0, j1 = near
    if (i0, i1, j0, j1) == (0, u.size - 1, 0, v.size - 1):
        return s
    return s.restrict(u[i0], u[i1], v[j0], v[j1])


def _monotone_patches(s: NurbsSurface, centre: np.ndarray, normal: np.ndarray,
                      tol: float) -> bool:
    patches, _, _ = bezier_patches(s)                      # (ku, kv, p+1, q+1, 4)
    h = (patches[..., :3] / patches[..., 3:]) @ normal - float(centre @ normal)
    near = (h.min(axis=(2, 3)) <= tol) & (h.max(axis=(2, 3)) >= -tol)
    if not near.any():
        return True
    out = False
    for axis, rows in ((2, lambda x: x), (3, lambda x: x.T)):
        d = np.diff(h, axis=axis)
        if d.shape[axis] == 0:
            continue
        sign = np.where((d > tol).all(axis=(2, 3)), 1,
                        np.where((d < -tol).all(axis=(2, 3)), -1, 0))
        out = out or _monotone_rows(rows(near), rows(sign))
    return out


def _pole_near(s: NurbsSurface, other: NurbsSurface, tol: float) -> bool:
    """A collapsed side of ``s`` (a pole) within ``tol`` of ``other``'s control-net box:
    a tangential contact there is on the boundary of ``s``'s domain, which the
    height rules below do not see."""
    box = other.bounding_box()
    for uv in collapsed_sides(s):
        p = s.evaluate(*uv)
        if np.all(p >= box[0] - tol) and np.all(p <= box[1] + tol):
            return True
    return False


def no_loop_reason(a: NurbsSurface, b: NurbsSurface, *, tol: float) -> NoLoopReason | None:
    """Why ``a`` and ``b`` can have no closed loop nor isolated contact point (module
    docstring), or None when the certificate must look.

    Parameters
    ----------
    a, b : NurbsSurface
        In 3D.
    tol : float
        Model units.
    """
    if _apart(a, b, tol):
        return NoLoopReason.APART
    if _pole_near(a, b, tol) or _pole_near(b, a, tol):
        return None                                      # a contact may sit on the pole
    for flat, other in ((a, b), (b, a)):
        plane = _plane(flat, tol)
        if plane is None:
            continue
        centre, normal = plane
        if np.abs((other.control_points.reshape(-1, 3) - centre) @ normal).max() <= tol:
            continue                                     # may coincide: full analysis
        if _straight_direction(other) or _plane(other, tol) is not None:
            return NoLoopReason.PLANE_AND_RULED
        if _monotone_height(other, centre, normal, tol):
            return NoLoopReason.MONOTONE_HEIGHT
    return None


def uncertified_record(curves: Sequence[IntersectionCurve], reason: NoLoopReason
                       ) -> CharacteristicRecord:
    """The record of a pair the certificate skipped: ``curves`` as the triangle method
    found them, no characteristic points, ``extra["skipped"]`` the reason."""
    curves = tuple(curves)
    return CharacteristicRecord(curves, (FoundBy.MESH,) * len(curves), (), (), (), (), "a",
                                0.0, 0.0, extra={"skipped": reason.value})
