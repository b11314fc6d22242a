"""G0 and G1 joins of compatible patches by moving control points (001 §8).

The control points of all patches are put in classes: the boundary rows of
the two sides of a shared edge correspond one to one (after
:func:`.compatibility.make_compatible`), and the corners of a
:class:`.connectivity.CornerCluster` are one point. A class is one point of the
network.

* **G0** (001 §8): every class is moved to the mean of its members ("averaging
  corresponding pairs of control points", corners of several patches
  included).
* **G1** (001 §8, Faux & Pratt's gradient continuity): after G0, with the
  corners held,

  - at a shared corner ``c`` the tangent plane's normal is the mean of the
    patches' unit normals there (signs aligned), and every second control
    point ``d_i`` of a boundary row leaving ``c`` must lie in that plane:
    ``n . (d_i - c) = 0``;
  - along a shared edge with boundary row ``s_k`` and next rows ``a_k``, ``b_k``
    in the two patches, the triples are collinear with one ratio per edge:
    ``(b_k - s_k) + lambda (a_k - s_k) = 0``, ``lambda`` the ratio of the mean
    lengths ``|b_k - s_k|`` and ``|a_k - s_k|`` before the adjustment (the
    patches keep their proportions). One ratio along the whole edge makes the
    cross-boundary derivatives parallel, hence one tangent plane, everywhere
    along the edge. The end triples (at the corners) are left to the
    corner's plane condition: at a vertex of valence three collinear end
    triples would put all three tangents on one line, and at valence four
    they conflict with the planes when the edges' ratios differ (measured: 3
    degrees left at the corners of a 3x3 grid with them, 0.03 without).

  These are linear in the class points. The classes next to shared edges
  (boundary rows without corners and the rows beside them) move by the
  smallest total displacement that satisfies all conditions (least squares
  where they conflict, e.g. twist points of a vertex of even valence),
  solved with LSQR's minimum-norm solution. Shared points stay one class, so
  G0 is kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.linalg import lsqr

from ..basis import collocation_matrix
from ..curve import NurbsCurve
from ..measure import normals
from ..projection import project_to_curve
from ..surface import NurbsSurface
from .connectivity import (
    Connectivity,
    CornerCluster,
    SharedEdge,
    corner_index,
    side_indices,
)

__all__ = ["PointClasses", "covered_samples", "enforce_g0", "enforce_g1", "fit_side_to_curve",
           "point_classes"]


@dataclass(frozen=True)
class PointClasses:
    """Control points of all patches in shared classes.

    Attributes
    ----------
    offsets : (P + 1,) int
        Flat index of patch ``p``'s point ``(i, j)``: ``offsets[p] + i n_v + j``.
    label : (F,) int
        Class of every flat point, ``0..n_classes-1``.
    n_classes : int
    """

    offsets: NDArray
    label: NDArray
    n_classes: int

    def flat(self, patch: int, shape: tuple[int, int], i, j) -> NDArray:
        return self.offsets[patch] + np.asarray(i) * shape[1] + np.asarray(j)


def _find(parent: NDArray, x: int) -> int:
    root = x
    while parent[root] != root:
        root = parent[root]
    while parent[x] != root:
        parent[x], x = root, parent[x]
    return root


def point_classes(patches: list[NurbsSurface], connectivity: Connectivity) -> PointClasses:
    """Classes of control points that must coincide (shared rows and corners)."""
    sizes = [s.n_control[0] * s.n_control[1] for s in patches]
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    parent = np.arange(offsets[-1])

    def union(x: int, y: int) -> None:
        rx, ry = _find(parent, int(x)), _find(parent, int(y))
        if rx != ry:
            parent[rx] = ry

    for e in connectivity.edges:
        fa, fb = _row_flats(patches, offsets, e, 0)
        for x, y in zip(fa, fb):
            union(x, y)
    for cluster in connectivity.corners:
        flats = [_corner_flat(patches, offsets, m) for m in cluster.members]
        for x in flats[1:]:
            union(flats[0], x)
    roots = np.array([_find(parent, x) for x in range(offsets[-1])])
    _, label = np.unique(roots, return_inverse=True)
    return PointClasses(offsets, label, int(label.max()) + 1)


def _row_flats(patches, offsets, e: SharedEdge, depth: int) -> tuple[NDArray, NDArray]:
    """Flat indices of row ``depth`` along both sides of ``e``, in a's running order."""
    sa, sb = patches[e.a].n_control, patches[e.b].n_control
    ia, ja = side_indices(sa, e.side_a, depth)
    ib, jb = side_indices(sb, e.side_b, depth)
    fa = offsets[e.a] + ia * sa[1] + ja
    fb = offsets[e.b] + ib * sb[1] + jb
    if fa.size != fb.size:
        raise ValueError(f"shared edge {e} joins rows of {fa.size} and {fb.size} control "
                         "points: make the patches compatible first")
    return fa, (fb[::-1] if e.reversed else fb)


def _corner_flat(patches, offsets, member) -> int:
    p, side, end = member
    i, j = corner_index(patches[p].n_control, side, end)
    return int(offsets[p] + i * patches[p].n_control[1] + j)


def _flat_points(patches: list[NurbsSurface]) -> NDArray:
    return np.concatenate([s.control_points.reshape(-1, 3) for s in patches])


def _write_back(patches: list[NurbsSurface], classes: PointClasses, points: NDArray
                ) -> list[NurbsSurface]:
    flat = points[classes.label]
    out = []
    for p, s in enumerate(patches):
        net = flat[classes.offsets[p]:classes.offsets[p + 1]].reshape(s.control_points.shape)
        out.append(NurbsSurface(net, s.knots_u, s.knots_v, s.degree_u, s.degree_v, s.weights))
    return out


def _class_means(patches: list[NurbsSurface], classes: PointClasses) -> NDArray:
    flat = _flat_points(patches)
    sums = np.zeros((classes.n_classes, 3))
    np.add.at(sums, classes.label, flat)
    counts = np.bincount(classes.label, minlength=classes.n_classes)
    return sums / counts[:, None]


def enforce_g0(patches: list[NurbsSurface], connectivity: Connectivity
               ) -> tuple[list[NurbsSurface], PointClasses]:
    """Shared control rows and corners averaged (001 §8). Patches must be compatible."""
    classes = point_classes(patches, connectivity)
    return _write_back(patches, classes, _class_means(patches, classes)), classes


# ----------------------------------------------------------------------- G1
@dataclass
class _Constraints:
    """Sparse rows over the 3 coordinates of the class points (``3 c + coord``)."""

    rows: list[int]
    cols: list[int]
    vals: list[float]
    rhs: list[float]

    def add(self, terms: list[tuple[int, NDArray]]) -> None:
        """One row: ``sum coef . X[class] = 0`` with coef a (3,) vector."""
        r = len(self.rhs)
        for cls, coef in terms:
            for c in range(3):
                if coef[c] != 0.0:
                    self.rows.append(r)
                    self.cols.append(3 * cls + c)
                    self.vals.append(float(coef[c]))
        self.rhs.append(0.0)

    def add_vector(self, terms: list[tuple[int, float]]) -> None:
        """Three rows: ``sum coef X[class] = 0`` per coordinate."""
        for c in range(3):
            e = np.zeros(3)
            e[c] = 1.0
            self.add([(cls, coef * e) for cls, coef in terms])


def _corner_patch_normal(surface: NurbsSurface, member) -> NDArray:
    _, side, end = member
    a, b = side.running_domain(surface)
    uv = side.uv(surface, np.array([b if end else a]))[0]
    return normals(surface, uv[0], uv[1])


def _corner_plane(patches, cluster: CornerCluster) -> NDArray:
    ns = [_corner_patch_normal(patches[m[0]], m) for m in cluster.members]
    ref = ns[0]
    total = sum(n if np.dot(n, ref) >= 0 else -n for n in ns)
    return total / max(np.linalg.norm(total), np.finfo(float).tiny)


def _corner_neighbours(patches, classes: PointClasses, member) -> tuple[int, list[int]]:
    """Class of a corner and of the two control points next to it on its two sides."""
    p, side, end = member
    shape = patches[p].n_control
    i, j = corner_index(shape, side, end)
    di = 1 if i == 0 else -1
    dj = 1 if j == 0 else -1
    flat = classes.flat(p, shape, [i, i + di, i], [j, j, j + dj])
    labels = classes.label[flat]
    return int(labels[0]), [int(labels[1]), int(labels[2])]


def _edge_ratio(points: NDArray, s: NDArray, a: NDArray, b: NDArray) -> float:
    la = np.linalg.norm(points[a] - points[s], axis=1).mean()
    lb = np.linalg.norm(points[b] - points[s], axis=1).mean()
    return float(lb / la) if la > 0 else 1.0


def _edge_constraints(patches, classes, points, e: SharedEdge, out: _Constraints) -> None:
    fs, _ = _row_flats(patches, classes.offsets, e, 0)
    fa, fb = _row_flats(patches, classes.offsets, e, 1)
    s, a, b = classes.label[fs], classes.label[fa], classes.label[fb]
    lam = _edge_ratio(points, s, a, b)
    for k in range(1, s.size - 1):
        out.add_vector([(int(b[k]), 1.0), (int(a[k]), lam), (int(s[k]), -(1.0 + lam))])


def _plane_constraints(patches, classes, connectivity: Connectivity, out: _Constraints
                       ) -> None:
    touched = {(e.a, e.side_a) for e in connectivity.edges} | \
              {(e.b, e.side_b) for e in connectivity.edges}
    shared_patches = {p for p, _ in touched}
    for cluster in connectivity.corners:
        if not any(m[0] in shared_patches for m in cluster.members):
            continue
        normal = _corner_plane(patches, cluster)
        done = set()
        for m in cluster.members:
            c, neighbours = _corner_neighbours(patches, classes, m)
            for d in neighbours:
                if d not in done:
                    done.add(d)
                    out.add([(d, normal), (c, -normal)])


def enforce_g1(patches: list[NurbsSurface], connectivity: Connectivity
               ) -> list[NurbsSurface]:
    """G0, then the tangent-plane conditions at shared corners and along shared edges.

    Returns
    -------
    list of NurbsSurface
        Patches meeting G1 where the conditions are consistent; the
        measured angles (:mod:`.measure_joins`) say how well.
    """
    patches, classes = enforce_g0(patches, connectivity)
    points = _class_means(patches, classes)
    cons = _Constraints([], [], [], [])
    _plane_constraints(patches, classes, connectivity, cons)
    for e in connectivity.edges:
        _edge_constraints(patches, classes, points, e, cons)
    if not cons.rhs:
        return patches
    fixed = _fixed_classes(patches, classes, connectivity)
    free = np.setdiff1d(np.arange(classes.n_classes), fixed)
    new = _solve(cons, points, free)
    return _write_back(patches, classes, new)


def _fixed_classes(patches, classes: PointClasses, connectivity: Connectivity) -> NDArray:
    """Every patch corner (001 §8: the shared corner point is preserved)."""
    out = []
    for p, s in enumerate(patches):
        nu, nv = s.n_control
        out.extend(classes.label[classes.flat(p, s.n_control, [0, nu - 1, 0, nu - 1],
                                              [0, 0, nv - 1, nv - 1])].tolist())
    return np.unique(out)


def _solve(cons: _Constraints, points: NDArray, free: NDArray) -> NDArray:
    """Smallest displacement of the free classes satisfying the rows (LSQR)."""
    n_rows = len(cons.rhs)
    full = sp.csr_matrix((cons.vals, (cons.rows, cons.cols)), shape=(n_rows, points.size))
    x0 = points.reshape(-1)
    residual = np.asarray(cons.rhs) - full @ x0
    cols = (3 * free[:, None] + np.arange(3)).reshape(-1)
    matrix = full[:, cols]
    used = np.diff(matrix.tocsc().indptr) > 0
    step = np.zeros(cols.size)
    if np.any(used):
        sol = lsqr(matrix[:, used], residual, atol=1e-15, btol=1e-15, iter_lim=20000)[0]
        step[used] = sol
    out = x0.copy()
    out[cols] += step
    return out.reshape(points.shape)


# ------------------------------------------------ joining a fixed neighbour
#: samples per knot span of the side for :func:`fit_side_to_curve`
FIT_SAMPLES_PER_SPAN = 8
#: least-squares weight of the samples along a partial target (against 1 for the rest)
_COVERED_WEIGHT = 1e3


def _refined_along(surface: NurbsSurface, side, min_spans: int) -> NurbsSurface:
    """Knots inserted at the midpoint of the longest span along ``side`` until it has
    ``min_spans`` spans: the same surface with more freedom in the boundary row."""
    from ..knots import refine_surface
    knots = surface.knots_v if side.along.name == "V" else surface.knots_u
    breaks = list(np.unique(knots))
    new = []
    while len(breaks) - 1 < min_spans:
        k = int(np.argmax(np.diff(breaks)))
        mid = 0.5 * (breaks[k] + breaks[k + 1])
        breaks.insert(k + 1, mid)
        new.append(mid)
    return refine_surface(surface, np.sort(new), side.along) if new else surface


def fit_side_to_curve(surface: NurbsSurface, side, target, *,
                      min_spans: int = 0, free_corners: tuple[bool, bool] = (False, False),
                      cover_tol: float | None = None) -> NurbsSurface:
    """``surface`` with the boundary row of ``side`` fitted to ``target`` (corners kept).

    For a side that meets a face which is not re-approximated (its edge is
    ``target``): the side's samples (``FIT_SAMPLES_PER_SPAN`` per knot span) are
    projected onto ``target`` and the inner control points of the boundary row
    are the least-squares fit of those foot points with the side's own knots;
    the two corners stay (they may be shared with other patches). Only the
    boundary row moves, so the gap to ``target`` closes up to the fit error.

    Parameters
    ----------
    surface : NurbsSurface (non-rational)
    side : connectivity.Side
    target : NurbsCurve, 3D, or a sequence of them
        The edge, or edges end to end along the side (a side meeting several
        edges of one kept face: each sample goes to the nearest of them).
    min_spans : int
        Knots are first inserted along the side (geometry unchanged) until it has
        this many spans, so the row can follow a target with more detail.
    free_corners : (bool, bool)
        Move the corner at the start / end of the side onto the nearer end of
        ``target`` (for corners no other patch shares).
    cover_tol : float, optional
        Model units. A side only partly along ``target`` (the kept edge meets part
        of it, the rest is free): only samples within ``cover_tol`` of ``target``
        whose foot is not at an outer end of it (one no other target curve
        continues) go to their foot; the others keep their place.

    Returns
    -------
    NurbsSurface
    """
    from .connectivity import side_indices
    surface = _refined_along(surface, side, min_spans)
    knots = surface.knots_v if side.along.name == "V" else surface.knots_u
    degree = surface.degree_v if side.along.name == "V" else surface.degree_u
    lo, hi = side.running_domain(surface)
    spans = max(1, np.unique(knots).size - 1)
    t = np.linspace(lo, hi, FIT_SAMPLES_PER_SPAN * spans + 1)
    uv = side.uv(surface, t)
    curves = [target] if isinstance(target, NurbsCurve) else list(target)
    samples = surface.evaluate(uv[:, 0], uv[:, 1])
    found = [project_to_curve(c, samples) for c in curves]
    nearest = np.argmin(np.stack([f.distance for f in found]), axis=0)
    feet = np.stack([f.points for f in found])[nearest, np.arange(samples.shape[0])]
    weight = np.ones(samples.shape[0])
    if cover_tol is not None:
        covered = covered_samples(curves, found, nearest, cover_tol)
        feet = np.where(covered[:, None], feet, samples)
        # the step between foot and own place at the stretch's end goes to the free part
        weight[covered] = _COVERED_WEIGHT
    basis = collocation_matrix(knots, degree, t)                  # (m, n)
    i, j = side_indices(surface.n_control, side)
    row = surface.control_points[i, j].copy()                     # (n, 3)
    ends = np.concatenate([c.evaluate(np.array(c.domain)) for c in curves])
    for k, free in zip((0, -1), free_corners):
        if free:
            row[k] = ends[int(np.argmin(np.linalg.norm(ends - row[k], axis=1)))]
    rhs = feet - basis[:, [0]] * row[0] - basis[:, [-1]] * row[-1]
    inner, *_ = np.linalg.lstsq(weight[:, None] * basis[:, 1:-1], weight[:, None] * rhs,
                                rcond=None)
    net = surface.control_points.copy()
    net[i[1:-1], j[1:-1]] = inner
    net[i[[0, -1]], j[[0, -1]]] = row[[0, -1]]
    return NurbsSurface(net, surface.knots_u, surface.knots_v, surface.degree_u,
                        surface.degree_v, surface.weights)


def covered_samples(curves: list[NurbsCurve], found: list, nearest: NDArray,
                    cover_tol: float) -> NDArray:
    """(m,) bool: samples within ``cover_tol`` of the nearest target curve whose foot is
    not at an outer end of the targets (an end no other curve continues within
    ``cover_tol``). ``found`` holds each curve's :func:`project_to_curve` result."""
    m = nearest.size
    distance = np.stack([f.distance for f in found])[nearest, np.arange(m)]
    t = np.stack([f.t for f in found])[nearest, np.arange(m)]
    ends = [c.evaluate(np.array(c.domain)) for c in curves]
    at_outer = np.zeros(m, bool)
    for k, (c, e) in enumerate(zip(curves, ends)):
        others = [x for n, x in enumerate(ends) if n != k]
        span = c.domain[1] - c.domain[0]
        for end, value in zip(e, c.domain):
            continued = any(np.linalg.norm(o - end, axis=1).min() <= cover_tol for o in others)
            if not continued:
                at_outer |= (nearest == k) & (np.abs(t - value) <= 1e-9 * span)
    return (distance <= cover_tol) & ~at_outer
