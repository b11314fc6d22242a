"""Holes of any number of sides: the surface their surroundings continue into, whether
they are holes at all, and their four-sided sub-patches (001 §3-5, handbook 000 §29.3).

A loop of free edges is capped by the smoothest surface that passes through its rim
and continues its surroundings (points of the faces that bound it, near the rim):
the thin-plate spline [D77]_ of their heights over the rim's best-fit plane,

.. math::

    h(x, y) = a_0 + a_1 x + a_2 y + \\sum_i c_i\\, r_i^2 \\log r_i,
    \\qquad r_i = \\lVert (x, y) - (x_i, y_i) \\rVert ,

interpolating the rim's samples and the surroundings' points (the same kernel that
fills an approximant's missing positions, :mod:`.fill`), tabulated and interpolated
as a bicubic graph surface :math:`S(s, t) = o + x(s)\\,e_1 + y(t)\\,e_2 + h\\,n`. The
rim's edges get exact pcurves on it (a NURBS curve projected onto a plane is the
NURBS curve of the projected control points), so the loop is split as a face's
outline is (:func:`.decompose.decompose_loop`): four corners give one patch, three
or five and more give as many quads around a centre on the cap, joined by spokes on
the cap; every sub-patch is then an approximant of its own (001 §3) whose rim
sides are edges of the model.

Whether a loop is a hole is decided by geometry, not by whether an approximant
converges: the *slope* of the surroundings is the angle, at each point near the
rim, between the cap's plane and the chord from the nearest rim sample to the
point (90° for a point over the hole's inside). Where the surroundings continue
the rim's plane (a patch missing from a skin: slopes of a few degrees) the loop is
a :attr:`LoopKind.HOLE`; where they turn away (the end of a pipe, the mouth of a
slot, the edge of a sheet folding down: slopes near 90°) it is an
:attr:`LoopKind.OPEN` boundary. The figure is the 90th percentile of the slopes,
so a few points of a neighbouring fillet do not decide it.

References
----------
.. [D77] J. Duchon, "Splines minimizing rotation-invariant semi-norms in Sobolev
   spaces", Lecture Notes in Mathematics 571, Springer, 1977, 85-100.
.. [001] B. Hamann, B. A. Jean, "Interactive surface correction based on a local
   approximation scheme", *Computer Aided Geometric Design* 13(4), 1996, §3-5.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import RBFInterpolator
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..curve import NurbsCurve
from ..face_region import FaceRegion, inside_loops
from ..fitting import interpolate_surface
from ..surface import NurbsSurface
from ..trimmed import TrimmedFace
from .clipping import SurfaceSource, trimmed_source
from .decompose import DEFAULT_SMOOTH_ANGLE, LoopEdge, decompose_loop, reverse_curve

__all__ = [
    "DEFAULT_OPEN_ANGLE",
    "HoleCap",
    "LoopKind",
    "NotCappableError",
    "cap_hole",
    "hole_quads",
    "loop_width",
    "orient_loop",
    "surroundings",
]

#: surroundings sloping more than this (degrees, 90th percentile) make an open boundary
DEFAULT_OPEN_ANGLE = 60.0
#: samples per rim edge for the plane and the spline
RIM_SAMPLES = 24
#: points of the surroundings kept for the spline: one per square of this fraction of
#: the rim's extent, every k-th beyond MAX_SURROUNDINGS
THIN_CELLS = 32
MAX_SURROUNDINGS = 800
#: the surroundings: points of the bounding faces within this times the rim's extent
REACH = 0.3
#: ... and at least this times the extent from the rim in the plane (the rim decides there)
NEAR_RIM = 0.02
#: the cap's table: this many nodes per direction over the rim's box
CAP_NODES = 25
#: ... grown by this fraction of its extent on every side
CAP_MARGIN = 0.05
#: grid per direction on which each bounding face is sampled for the surroundings
FACE_SAMPLES = 64
#: degree of the polynomial added to the thin-plate spline (1 in [D77]; 2 reproduces
#: quadrics, so a hole in a sphere or a cylinder is filled by the bulge of its rim)
POLYNOMIAL_DEGREE = 2
#: the slope figure: this percentile of the surroundings' slopes
SLOPE_PERCENTILE = 90.0


class LoopKind(enum.Enum):
    """What a loop of free edges is (module docstring; a sliver, :func:`loop_width`, is a
    gap between faces and is not capped)."""

    #: the surroundings continue across it: a missing piece of a skin, to be filled
    HOLE = "hole"
    #: the surroundings turn away from it: the edge of a sheet, the end of a pipe
    OPEN = "open boundary"


class NotCappableError(InvalidGeometryError):
    """No cap over the loop: its rim folds over itself seen along its plane's normal,
    or it encloses no area; ``str()`` says which."""


@dataclass(frozen=True, eq=False)
class HoleCap:
    """The smooth surface over a loop of free edges (module docstring).

    Attributes
    ----------
    surface : NurbsSurface
        Bicubic graph over the rim's plane, domain ``[0, 1]^2``.
    edges : tuple of LoopEdge
        The rim's edges oriented along the loop, with their pcurves on ``surface``.
    origin : (3,) float
    axes : (3, 3) float
        Rows ``e1, e2, n``: the plane's frame (``n`` its normal).
    slope : float
        Degrees: the surroundings' slope figure (NaN when there were none).
    kind : LoopKind
    continued : bool
        Whether the surroundings entered the spline (False for an open boundary:
        the cap is then the smoothest surface through the rim alone).
    covered : float
        Share of the surroundings' points lying over the loop's inside (seen along
        the plane's normal, beyond :data:`NEAR_RIM` of the rim): faces cover the
        inside of the outer boundary of a sheet, never that of a hole or a pipe's
        end.
    """

    surface: NurbsSurface
    edges: tuple
    origin: NDArray
    axes: NDArray
    slope: float
    kind: LoopKind
    continued: bool
    covered: float = 0.0

    def outline(self, samples: int = RIM_SAMPLES) -> NDArray:
        """``(m, 2)`` float: the rim in the cap's ``(s, t)``, ``samples`` per edge."""
        return np.concatenate([e.pcurve.evaluate(np.linspace(*e.pcurve.domain, samples + 1)[:-1])
                               for e in self.edges])

    def source(self, name: str = "") -> SurfaceSource:
        """The cap inside its rim (:func:`.clipping.trimmed_source`), the
        ``fill_source`` of :func:`.approximant.local_approximant`: the artificial
        projections of the patches over the hole lie on it."""
        return trimmed_source(self.surface, [self.outline()], name=name)


def orient_loop(curves: Sequence[NurbsCurve]) -> list[NurbsCurve]:
    """The curves of a loop (in loop order, each either way round) oriented head to tail.

    Parameters
    ----------
    curves : sequence of NurbsCurve (3D)
        Consecutive curves share an end (within a gap).

    Returns
    -------
    list of NurbsCurve
        The end of each is nearest the start of the next.
    """
    curves = list(curves)
    ends = [c.evaluate(np.array(c.domain)) for c in curves]
    if len(curves) == 1:
        return curves
    out = []
    for k, c in enumerate(curves):
        nxt = ends[(k + 1) % len(curves)]
        head, tail = ends[k][1], ends[k][0]
        if min(np.linalg.norm(nxt - tail, axis=1)) < min(np.linalg.norm(nxt - head, axis=1)):
            c = reverse_curve(c)
        out.append(c)
    return out


def loop_width(curves: Sequence[NurbsCurve], samples: int = RIM_SAMPLES) -> tuple[float, float]:
    """How wide a loop is: the largest distance from a point of one of its curves to the
    other curves (sampled), and its length.

    A sliver between two faces (a gap wider than ``gap_tol``, two curves side by side,
    or one long edge against the several edges of a T-junction) is a few thousandths
    of its length wide; a hole about a sixth (the middle of a square's side is half a
    side from its neighbours, an eighth of the perimeter).

    Returns
    -------
    (width, length) : (float, float)
        Model units.
    """
    pts = [c.evaluate(np.linspace(*c.domain, 4 * samples + 1)) for c in curves]
    length = float(sum(np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in pts))
    if len(pts) == 1:
        p = pts[0]
        half = p.shape[0] // 2
        return float(cKDTree(p[half:]).query(p[:half])[0].max()), length
    width = max(float(cKDTree(np.concatenate(pts[:k] + pts[k + 1:])).query(pts[k])[0].max())
                for k in range(len(pts)))
    return width, length


def _rim_samples(curves: Sequence[NurbsCurve]) -> NDArray:
    """(m, 3) float: each curve's samples but its last (the next curve's first)."""
    return np.concatenate([c.evaluate(np.linspace(*c.domain, RIM_SAMPLES + 1)[:-1])
                           for c in curves])


def _plane(points: NDArray) -> tuple[NDArray, NDArray]:
    """Centroid and frame (rows ``e1, e2, n``) of the best-fit plane."""
    origin = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - origin, full_matrices=False)
    axes = vt.copy()
    if np.linalg.det(axes) < 0:
        axes[1] = -axes[1]
    return origin, axes


def _segments_cross(poly: NDArray) -> bool:
    """Whether two non-adjacent edges of the closed polygon ``(m, 2)`` cross or touch.

    Edges cross when each straddles the other's line strictly; where an end lies on the
    other's line (within rounding) they touch only if it lies on the other edge itself:
    on a nearly straight curve an end two samples on lies on the line of an edge behind
    it, beyond that edge (the bearing's hole read as folding over itself)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    d = b - a

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    eps = 1e-12 * float(np.ptp(poly, axis=0).max()) ** 2     # rounding of the cross products
    r = cross(d[:, None], a[None] - a[:, None])          # side of a_j w.r.t. edge i
    s = cross(d[:, None], b[None] - a[:, None])          # side of b_j w.r.t. edge i
    r, s = np.where(np.abs(r) <= eps, 0.0, r), np.where(np.abs(s) <= eps, 0.0, s)
    p = r * s
    dd = np.maximum(np.einsum("ij,ij->i", d, d), np.finfo(float).tiny)

    def on_edge(point: NDArray, side: NDArray) -> NDArray:
        """(m, m): whether ``point[j]``, on edge i's line (``side`` 0), lies on edge i."""
        t = np.einsum("ijk,ik->ij", point[None] - a[:, None], d) / dd[:, None]
        return (side == 0) & (t >= 0.0) & (t <= 1.0)

    # pieces of one straight edge are collinear (r = s = 0) and never cross
    collinear = (r == 0) & (s == 0)
    proper = (p < 0) & (p.T < 0)
    touch = on_edge(a, r) | on_edge(b, s)                # an end of j on edge i
    touch = (touch | touch.T) & ~collinear & ~collinear.T
    m = poly.shape[0]
    i, j = np.indices((m, m))
    adjacent = (np.abs(i - j) <= 1) | (np.abs(i - j) == m - 1)
    return bool(np.any((proper | touch) & ~adjacent))


def _inside(points: NDArray, poly: NDArray) -> NDArray:
    """(k,) bool: even-odd test of planar points against the closed polygon."""
    return inside_loops(points, [poly])


def surroundings(faces: Sequence[TrimmedFace], rim: ArrayLike, *, reach: float,
                 samples: int = FACE_SAMPLES) -> NDArray:
    """Points of the faces that bound a hole, near its rim.

    Parameters
    ----------
    faces : sequence of TrimmedFace
        The faces whose edges make the rim.
    rim : (m, 3) float
        Samples of the rim.
    reach : float
        Model units: points farther than this from every rim sample are left out.
    samples : int
        Grid per direction over each face's parameter rectangle (points outside its
        trimming loops left out).

    Returns
    -------
    (k, 3) float
    """
    rim = np.asarray(rim, float)
    tree = cKDTree(rim)
    out = []
    for face in faces:
        s = face.surface
        u0, u1, v0, v1 = s.domain
        u, v = np.linspace(u0, u1, samples), np.linspace(v0, v1, samples)
        uu, vv = np.meshgrid(u, v, indexing="ij")
        uv = np.column_stack([uu.ravel(), vv.ravel()])
        if face.loops:
            uv = uv[FaceRegion(face).contains(uv)]
        pts = s.evaluate(uv[:, 0], uv[:, 1])
        near, _ = tree.query(pts, distance_upper_bound=reach)
        out.append(pts[np.isfinite(near)])
    return np.concatenate(out) if out else np.empty((0, 3))


def _thinned(xy: NDArray, h: NDArray, cell: float) -> tuple[NDArray, NDArray]:
    """One point per square ``cell`` of the plane (the first), then every k-th down to
    :data:`MAX_SURROUNDINGS`: points of two faces along their shared edge coincide, and
    coincident or crowded data make the spline's system singular."""
    _, first = np.unique(np.floor(xy / cell).astype(np.int64), axis=0, return_index=True)
    first = np.sort(first)
    step = max(1, -(-first.size // MAX_SURROUNDINGS))
    first = first[::step]
    return xy[first], h[first]


def _slopes(rim_xy: NDArray, rim_h: NDArray, xy: NDArray, h: NDArray, poly: NDArray
            ) -> NDArray:
    """Degrees: the slope of each surrounding point seen from its nearest rim sample in
    the plane; 90 for a point over the inside of the rim."""
    d, k = cKDTree(rim_xy).query(xy)
    slope = np.degrees(np.arctan2(np.abs(h - rim_h[k]), d))
    return np.where(_inside(xy, poly), 90.0, slope)


def cap_hole(curves: Sequence[NurbsCurve], around: ArrayLike | None = None, *,
             open_angle: float = DEFAULT_OPEN_ANGLE) -> HoleCap:
    """The cap over a loop of free edges and the loop's kind (module docstring).

    Parameters
    ----------
    curves : sequence of NurbsCurve (3D)
        The loop's edges in loop order, each either way round
        (:func:`orient_loop`).
    around : (k, 3) float, optional
        Points of the surroundings (:func:`surroundings`).
    open_angle : float
        Degrees in (0, 90): a slope figure above it makes an open boundary.

    Returns
    -------
    HoleCap

    Raises
    ------
    NotCappableError
        The rim folds over itself seen along its plane's normal, or encloses no
        area.

    Examples
    --------
    A square hole in the plane ``z = 0`` surrounded by the plane is a hole; the
    cap is that plane:

    >>> import numpy as np
    >>> from surfprep.algorithms.fitting import interpolate_curve
    >>> c = [(0, 0), (1, 0), (1, 1), (0, 1)]
    >>> edges = [interpolate_curve(np.array([[*c[k], 0], [*c[(k + 1) % 4], 0]]), degree=1)
    ...          for k in range(4)]
    >>> g = np.linspace(-0.3, 1.3, 17)
    >>> ring = np.array([[x, y, 0.0] for x in g for y in g
    ...                  if not (0 <= x <= 1 and 0 <= y <= 1)])
    >>> cap = cap_hole(edges, ring)
    >>> cap.kind.value, round(float(abs(cap.surface.evaluate(0.5, 0.5)[2])), 9)
    ('hole', 0.0)
    """
    if not 0.0 < open_angle < 90.0:
        raise InvalidGeometryError(f"open_angle must lie in (0, 90) degrees, got {open_angle!r}")
    curves = orient_loop(curves)
    rim = _rim_samples(curves)
    origin, axes = _plane(rim)
    rim_xy, rim_h = (rim - origin) @ axes[:2].T, (rim - origin) @ axes[2]
    extent = float(np.ptp(rim_xy, axis=0).max())
    area = 0.5 * abs(float(np.sum(rim_xy[:, 0] * np.roll(rim_xy[:, 1], -1)
                                  - np.roll(rim_xy[:, 0], -1) * rim_xy[:, 1])))
    if extent <= 0 or area <= 1e-6 * extent ** 2:
        raise NotCappableError("the loop encloses no area")
    if _segments_cross(rim_xy):
        raise NotCappableError("the loop folds over itself seen along its best-fit plane's "
                               "normal: no cap as a graph over it")
    slope, covered, data_xy, data_h = float("nan"), 0.0, rim_xy, rim_h
    around = np.empty((0, 3)) if around is None else np.asarray(around, float).reshape(-1, 3)
    if around.shape[0]:
        xy, h = (around - origin) @ axes[:2].T, (around - origin) @ axes[2]
        slope = float(np.percentile(_slopes(rim_xy, rim_h, xy, h, rim_xy), SLOPE_PERCENTILE))
        d, _ = cKDTree(rim_xy).query(xy)
        over = _inside(xy, rim_xy)
        covered = float(np.mean(over & (d > NEAR_RIM * extent)))
    kind = LoopKind.OPEN if slope > open_angle else LoopKind.HOLE
    continued = kind is LoopKind.HOLE and around.shape[0] > 0
    if continued:
        keep = (d > NEAR_RIM * extent) & ~over
        xy, h = _thinned(xy[keep], h[keep], extent / THIN_CELLS)
        data_xy, data_h = np.concatenate([rim_xy, xy]), np.r_[rim_h, h]
    spline = RBFInterpolator(data_xy / extent, data_h / extent, kernel="thin_plate_spline",
                             degree=POLYNOMIAL_DEGREE)
    low = rim_xy.min(axis=0) - CAP_MARGIN * extent
    span = np.ptp(rim_xy, axis=0) + 2 * CAP_MARGIN * extent
    s = np.linspace(0.0, 1.0, CAP_NODES)
    ss, tt = np.meshgrid(s, s, indexing="ij")
    plane_xy = low + np.stack([ss, tt], axis=-1) * span                  # (K, K, 2)
    heights = extent * spline(plane_xy.reshape(-1, 2) / extent).reshape(ss.shape)
    grid = origin + plane_xy @ axes[:2] + heights[..., None] * axes[2]
    surface = interpolate_surface(grid, params_u=s, params_v=s)
    edges = tuple(LoopEdge(c, _pcurve(c, origin, axes, low, span)) for c in curves)
    return HoleCap(surface, edges, origin, axes, slope, kind, continued, covered)


def _pcurve(curve: NurbsCurve, origin: NDArray, axes: NDArray, low: NDArray, span: NDArray
            ) -> NurbsCurve:
    """The curve's image on the cap: its control points projected onto the plane and
    mapped to ``(s, t)`` (affine maps commute with NURBS evaluation)."""
    st = ((curve.control_points - origin) @ axes[:2].T - low) / span
    return NurbsCurve(st, curve.knots, curve.degree, curve.weights)


def hole_quads(cap: HoleCap, *, smooth_angle: float = DEFAULT_SMOOTH_ANGLE
               ) -> list[tuple[list[NurbsCurve], tuple[int, ...]]]:
    """The four-sided sub-patches covering a capped loop.

    Parameters
    ----------
    cap : HoleCap
    smooth_angle : float
        Radians: rim vertices turning less join their edges into one side
        (:func:`.decompose.decompose_loop`).

    Returns
    -------
    list of (four NurbsCurve, tuple of int)
        Each sub-patch's boundary in loop order (bottom, right, top, left) and
        which of its sides lie on the rim (the others are spokes over the hole).

    Raises
    ------
    .decompose.NotDecomposableError
        With the reason (a cusp on the rim, a spoke leaving the outline, a
        sub-patch folding).
    """
    split = decompose_loop(cap.surface, cap.edges, smooth_angle=smooth_angle)
    rim = (0, 1, 2, 3) if split.centre_uv is None else (0, 3)
    return [(list(q), rim) for q in split.quads]
