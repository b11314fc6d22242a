r"""Boundary orthogonality control of the elliptic system: sources iterated with the grid (Steger--Sorenson).

The elliptic system of :mod:`.elliptic`,

.. math::

    g_{22} (r_{\xi\xi} + P r_\xi) - 2 g_{12} r_{\xi\eta} + g_{11} (r_{\eta\eta} + Q r_\eta)
        = 2 H g \, n,

is given sources near every side of the grid that make its lines leave the
side at a wanted angle -- 90 degrees, blended to the face's own angle next to
its corners ([SS]_, [S]_) -- and, where asked, with a given first-cell height.
As in Sorenson's GRAPE the sources of a side are ``p(xi) exp(-a eta)`` (``eta``
the index distance from the side, ``a`` = :data:`DECAY`) and their side values
``p`` are iterated with the grid; what moves them here is the miss measured on
the grid itself, not a one-sided estimate of ``r_etaeta`` (which on a curved
side confuses a chord with a derivative and asks for sources an exact
orthogonal grid does not need). At a node of the side ``eta = 0``, with
``r_xi`` along the side and ``r_1 - r_0`` the first line across it:

* the angle: a source ``P`` moves the first row along ``r_xi``; for a miss that
  is smooth along the side the 1-D problem across it,
  ``g11 d_etaeta = -g22 c exp(-a eta) |r_xi|``, ``d(0) = 0``, gives the first
  row's move ``d_1 = (g22 / g11) |r_xi| c (1 - e^{-a}) / a^2``, so the step of
  ``c`` that turns the line by ``d cos`` is
  ``d cos |r_xi| / (h (1 - e^{-a}) / a^2)`` (:func:`source_steps`);
* the height: likewise a source ``Q`` moves the first row across the side by
  ``h c (1 - e^{-a}) / a^2``.

The steps are under-relaxed (:data:`RELAXATION`), bounded (:data:`BOUND`), and
each node's step gain grows while its steps keep their sign and is cut when it
flips (:func:`_adapted`): a miss local to a few nodes moves the row less per
unit of source than a smooth one. Nodes at a sharp bend of a side or next to a
pole are left free. The grid has converged when every side is within
:data:`ANGLE_TOL` of its wanted angle outside the corners' blend.

References
----------
.. [SS] J. L. Steger, R. L. Sorenson, "Automatic mesh-point clustering near a
   boundary in grid generation with elliptic partial differential equations",
   J. Comput. Phys. 33 (1979) 405-410.
.. [S] R. L. Sorenson, "A computer program to generate two-dimensional grids about
   airfoils and other shapes by the use of Poisson's equation", NASA TM-81198 (1980).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError

__all__ = ["SIDE_NAMES", "BoundaryControl", "side_targets", "source_steps", "spread"]

#: decay of a side's sources into the grid, per node of index distance
DECAY = 0.35
#: fraction of the way a side's correction moves toward what it lacks, per update
RELAXATION = 0.5
#: largest correction of a source (dimensionless, per index unit; P's times the first
#: cells' aspect ratio, :func:`source_steps`)
BOUND = 2.0
#: per-node gain changes (:func:`_adapted`)
GAIN_UP, GAIN_DOWN, GAIN_MIN, GAIN_MAX = 1.25, 0.5, 0.25, 16.0
#: a side is as wanted when its lines leave it within this many degrees of the wanted angle
ANGLE_TOL = 0.5
#: ... and, where held, its first cells are within this fraction of their height
HEIGHT_TOL = 0.01
#: a side bending by more than this many degrees at a node is left free there (:func:`side_targets`)
BEND = 8.0
#: the wanted angle blends from the face's corner angle to 90 degrees over this
#: fraction of a side's length, or BLEND_NODES nodes, whichever reaches farther
CORNER_BLEND = 0.1
BLEND_NODES = 3.0
#: ... that fraction times ``1 + CORNER_STRETCH |cos(corner angle)|``
CORNER_STRETCH = 3.0
#: a corner with ``|cos(angle)|`` above this (sharper than 45 or flatter than 135
#: degrees) leaves the lines near it free over the same stretch
SHARP_CORNER = math.cos(math.radians(45.0)) + 1e-9


def _unit(v: NDArray) -> NDArray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0.0, n, 1.0)


def side_targets(points: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """First-cell heights, wanted angles and freedom along the side ``j = 0`` of a grid.

    Parameters
    ----------
    points : (ni, nj, 3) float
        The start grid (its first-cell heights are the ones held).

    Returns
    -------
    heights : (ni,) float
        ``|r_1 - r_0|`` of the start grid at every node of the side.
    cosines : (ni,) float
        Cosine of the wanted angle between the side and the lines leaving it: 0
        (90 degrees), blended linearly to the grid's own angle at the two corners
        over ``CORNER_BLEND (1 + CORNER_STRETCH |cos(corner angle)|)`` of the side's
        length or :data:`BLEND_NODES` nodes, whichever reaches farther (a corner's
        angle is the face's; no source can change it, and the farther it is from
        square the longer the lines take to turn; on a side whose nodes crowd into
        a corner the blend still spans a length).
    free : (ni,) float in [0, 1]
        How far each node is left to the system: 1 at a bend of the side sharper
        than :data:`BEND` (orthogonal lines would fan out of a convex bend and cross
        in a concave one) and next to a pole (a collapsed neighbouring side, where
        the lines fan out), fading to 0 over the same length as the corners' blend;
        and over the blend of a corner sharper than 45 or flatter than 135 degrees
        (:data:`SHARP_CORNER`: turning the lines there folds the cells beside it
        toward the corner's own angle).
    counted : (ni,) bool
        The nodes that must meet their wanted angle for the grid to have converged:
        those outside the corners' blend and the free nodes' reach (there the
        sides' wishes meet and may not all be met).
    """
    ni = points.shape[0]
    heights = np.linalg.norm(points[:, 1] - points[:, 0], axis=-1)
    side = points[:, 0]
    legs = np.diff(side, axis=0)
    lengths = np.linalg.norm(legs, axis=-1)
    k = np.arange(ni, dtype=float)
    along_side = np.concatenate([[0.0], np.cumsum(lengths)])
    along_side /= along_side[-1]

    def near(c: int, reach: float = CORNER_BLEND) -> NDArray:
        """1 at node c, fading to 0 over ``reach`` of the side's length or BLEND_NODES nodes."""
        by_nodes = 1.0 - np.abs(k - c) / BLEND_NODES
        by_length = 1.0 - np.abs(along_side - along_side[c]) / reach
        return np.clip(np.maximum(by_nodes, by_length), 0.0, 1.0)

    centres = []                                   # nodes the system is left to
    corner = []
    for i, along in ((0, legs[0]), (ni - 1, legs[-1])):
        across = points[i, 1] - points[i, 0]
        a, c = np.linalg.norm(along), np.linalg.norm(across)
        if a > 0.0 and c > 0.0:
            corner.append(float(np.dot(along, across) / (a * c)))
        else:
            corner.append(0.0)
            centres.append(i)
    ok = (lengths[1:] > 0.0) & (lengths[:-1] > 0.0)
    turn = np.einsum("ij,ij->i", legs[1:], legs[:-1]) / np.where(ok, lengths[1:] * lengths[:-1], 1.0)
    bends = 1 + np.flatnonzero(ok & (turn < math.cos(math.radians(BEND))))
    centres.extend(bends.tolist())
    # a corner far from square turns the lines over a longer stretch of the side
    wa, wb = (near(i, CORNER_BLEND * (1.0 + CORNER_STRETCH * abs(c))) for i, c in ((0, corner[0]),
                                                                                   (ni - 1, corner[1])))
    free = np.zeros(ni)
    for c in centres:
        free = np.maximum(free, near(c))
    for w, c in ((wa, corner[0]), (wb, corner[1])):
        if abs(c) > SHARP_CORNER:             # a sharp or flat corner: the lines near it are left free
            free = np.maximum(free, w)
    counted = (wa == 0.0) & (wb == 0.0) & (free == 0.0)
    return heights, corner[0] * wa + corner[1] * wb, free, counted


def source_steps(points: NDArray, heights: NDArray | None, cosines: NDArray, free: NDArray,
                 counted: NDArray) -> tuple[NDArray, NDArray, float, NDArray]:
    """Changes of ``P``, ``Q`` at the first interior row that would put it where the side wants it.

    Parameters
    ----------
    points : (ni, nj, 3) float, nj >= 2
        The current grid.
    heights, cosines, free, counted : (ni,)
        From :func:`side_targets`; ``heights`` None where they are not held. A
        node's step is ``(1 - free)`` of the step to its wanted angle (a free node
        asks nothing).

    Returns
    -------
    dP, dQ : (ni - 2,) float
        At the side's inner nodes (0 where the side or the line has no length: a pole).
    misfit : float
        The side's worst miss at its ``counted`` nodes: angle off in units of
        :data:`ANGLE_TOL`, or height off in units of :data:`HEIGHT_TOL` (relative),
        whichever is larger; at most 1 when the side is as wanted.
    aspect : (ni - 2,) float
        ``max(1, |r_xi| / h)`` of the first cells: a ``P`` moves a first row that is
        ``aspect`` times flatter than wide that much less, so its bound is that much
        larger.
    """
    r0, r1 = points[:, 0], points[:, 1]
    along = 0.5 * (r0[2:] - r0[:-2])
    across = r1[1:-1] - r0[1:-1]
    a = np.linalg.norm(along, axis=-1)
    h = np.linalg.norm(across, axis=-1)
    ok = (a > 0.0) & (h > 0.0)
    a, h = np.where(ok, a, 1.0), np.where(ok, h, 1.0)
    cos = np.einsum("ij,ij->i", along, across) / (a * h)
    held = 1.0 - free[1:-1]
    wanted = held * cosines[1:-1] + free[1:-1] * cos
    # a correction c spread as c exp(-DECAY k) moves the first row, for errors smooth along
    # the side, by c (1 - exp(-DECAY)) / DECAY^2 times (g22 / g11) |r_xi| along it and h across
    response = (1.0 - np.exp(-DECAY)) / DECAY ** 2
    dP = (wanted - cos) * a / (h * response)
    off = np.degrees(np.abs(np.arccos(np.clip(cos, -1.0, 1.0))
                            - np.arccos(np.clip(wanted, -1.0, 1.0)))) / ANGLE_TOL
    if heights is None:
        dQ = np.zeros_like(h)
    else:
        dQ = held * (heights[1:-1] - h) / (h * response)
        off = np.maximum(off, held * np.abs(heights[1:-1] - h)
                         / (np.maximum(heights[1:-1], 1e-300) * HEIGHT_TOL))
    misfit = float(np.max(np.where(ok & counted[1:-1], off, 0.0), initial=0.0))
    aspect = np.where(ok, np.maximum(a / h, 1.0), 1.0)
    return np.where(ok, dP, 0.0), np.where(ok, dQ, 0.0), misfit, aspect


def spread(corrections: NDArray, length: int, decay: float = DECAY) -> NDArray:
    """A side's corrections (n,) carried ``length`` nodes into the grid: (n, length), weight ``exp(-decay k)``."""
    return corrections[:, None] * np.exp(-decay * np.arange(length, dtype=float))[None, :]


def _adapted(gain: NDArray, step: NDArray, last: NDArray) -> NDArray:
    """Per-node step gains, Rprop-like: grown where a node's steps keep their sign, cut where it flips.

    The steps of :func:`source_steps` assume an error smooth along the side; an
    error local to a few nodes moves the first row less per unit of source (down
    to about a tenth), so its steps keep their sign and its gain grows until it is
    corrected at the pace of the smooth errors.
    """
    same = step * last
    return np.clip(np.where(same > 0.0, gain * GAIN_UP, np.where(same < 0.0, gain * GAIN_DOWN, gain)),
                   GAIN_MIN, GAIN_MAX)


#: the four sides as views of the grid with the side at j = 0: (transpose, flip j), and whether
#: the side's "P" is the grid's P (True) or its Q
_SIDES = {"j0": (False, False), "j1": (False, True), "i0": (True, False), "i1": (True, True)}
#: the four sides' names
SIDE_NAMES = tuple(_SIDES)


def _view(a: NDArray, side: str) -> NDArray:
    transpose, flip = _SIDES[side]
    if transpose:
        a = np.swapaxes(a, 0, 1)
    return a[:, ::-1] if flip else a


@dataclass(frozen=True)
class BoundaryControl:
    """The corrections of ``P``, ``Q`` held for the four sides of a grid as it is refined.

    Built on the start grid, whose first-cell heights it holds (:meth:`start`);
    :meth:`update` moves each side's corrections by a relaxed step toward what the
    current grid lacks and returns the corrections spread over the grid, to add to
    the base control functions.

    Attributes
    ----------
    sides : tuple of str
        The controlled sides (``"i0"``, ``"i1"``, ``"j0"``, ``"j1"``).
    targets : dict
        Side to its ``(heights or None, cosines, free, counted)`` (:func:`side_targets`).
    corrections : dict
        Side to its state ``(along, across, gain_along, gain_across, last_along,
        last_across)``, each ``(n - 2,)`` at the side's inner nodes, in the side's
        own orientation: the corrections, their step gains (:func:`_adapted`) and
        the last steps.
    """

    sides: tuple[str, ...]
    targets: dict
    corrections: dict

    @classmethod
    def start(cls, points: NDArray, *, sides: Collection[str] = ("j0", "j1", "i0", "i1"),
              heights: Mapping[str, float] | None = None, short: float = 0.0) -> BoundaryControl:
        """Targets of the ``sides`` named from the start grid ``points`` (ni, nj, 3), at least 3 x 3.

        ``heights`` maps sides to the height of their first cells, held across the
        whole side (model units); the other sides only get the angle (their first
        cells take the height the system gives them). Sides shorter than ``short`` in total (collapsed: a
        pole) are not controlled.
        """
        targets, corrections, kept = {}, {}, []
        heights = dict(heights or {})
        unknown = set(sides) - set(_SIDES)
        if unknown:
            raise InvalidGeometryError(f"unknown side(s) {sorted(unknown)}; expected {', '.join(_SIDES)}")
        for side in _SIDES:
            if side not in sides:
                continue
            p = _view(points, side)
            if float(np.linalg.norm(np.diff(p[:, 0], axis=0), axis=-1).sum()) <= short:
                continue
            held, cosines, free, counted = side_targets(p)
            if side in heights:
                held = np.full_like(held, float(heights[side]))
            targets[side] = (held if side in heights else None, cosines, free, counted)
            zero, one = np.zeros(p.shape[0] - 2), np.ones(p.shape[0] - 2)
            corrections[side] = (zero, zero, one, one, zero, zero)
            kept.append(side)
        return cls(tuple(kept), targets, corrections)

    def update(self, points: NDArray) -> tuple[BoundaryControl, NDArray, NDArray, float]:
        """One relaxed step of every side's corrections on the current grid ``points`` (ni, nj, 3).

        Returns
        -------
        control : BoundaryControl
            With the new corrections.
        dP, dQ : (ni, nj) float
            The corrections spread over the grid (to add to the base ``P``, ``Q``).
        misfit : float
            The worst side's miss before this step (:func:`source_steps`; at most 1
            when every side is as wanted).
        """
        misfit = 0.0
        corrections = {}
        for side in self.sides:
            p = _view(points, side)
            step_a, step_b, miss, aspect = source_steps(p, *self.targets[side])
            misfit = max(misfit, miss)
            ca, cb, ga, gb, pa, pb = self.corrections[side]
            ga, gb = _adapted(ga, step_a, pa), _adapted(gb, step_b, pb)
            na = np.clip(ca + RELAXATION * ga * step_a, -BOUND * aspect, BOUND * aspect)
            nb = np.clip(cb + RELAXATION * gb * step_b, -BOUND, BOUND)
            corrections[side] = (na, nb, ga, gb, step_a, step_b)
        moved = BoundaryControl(self.sides, self.targets, corrections)
        return (moved, *moved.fields(points.shape[:2]), misfit)

    def fields(self, shape: tuple[int, int]) -> tuple[NDArray, NDArray]:
        """The corrections spread over a grid of ``shape`` (ni, nj): ``dP, dQ``, each (ni, nj),
        zero on the boundary."""
        dP, dQ = np.zeros(shape), np.zeros(shape)
        for side in self.sides:
            na, nb = self.corrections[side][:2]
            transpose, flip = _SIDES[side]
            sign_b = -1.0 if flip else 1.0         # Q r_eta is even in eta: Q flips with it
            va, vb = _view(dQ if transpose else dP, side), _view(dP if transpose else dQ, side)
            va[1:-1] += spread(na, va.shape[1])
            vb[1:-1] += sign_b * spread(nb, vb.shape[1])
        for a in (dP, dQ):
            a[[0, -1], :] = 0.0
            a[:, [0, -1]] = 0.0
        return dP, dQ

    def resumed(self, previous: BoundaryControl, scale: float = 1.0) -> BoundaryControl:
        """These targets with the corrections ``previous`` had reached on the same sides.

        For a grid refined again after its side nodes slid a little (same node counts:
        the corrections and their step gains are taken as they are), or for the fine grid
        started from a coarse one's solution: then a side's corrections are interpolated
        along it and multiplied by ``scale``, the ratio of the index spacings (a source's
        ``P r_xi`` keeps its effect when ``P`` scales with the spacing), gains restarted.
        """
        corrections = dict(self.corrections)
        for side in self.sides:
            if side not in previous.corrections:
                continue
            mine, theirs = corrections[side], previous.corrections[side]
            if theirs[0].shape == mine[0].shape:
                corrections[side] = theirs
                continue
            n, m = mine[0].size, theirs[0].size
            if m == 0:
                continue
            at, known = np.arange(1, n + 1) / (n + 1), np.arange(1, m + 1) / (m + 1)
            along = scale * np.interp(at, known, theirs[0])
            across = scale * np.interp(at, known, theirs[1])
            corrections[side] = (along, across, *mine[2:])
        return BoundaryControl(self.sides, self.targets, corrections)
