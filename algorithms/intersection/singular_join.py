"""Curves meeting at singular points of an intersection, made to end exactly there.

Where two surfaces cross with parallel normals (a double point: two branches
crossing, as two cylinders of equal radius with perpendicular axes; 000
§29.5.1, 002 §4) the tessellations' segments cross over between the branches
and the refinement's auxiliary plane degenerates, so traced curves end short
of the point, switch branches or cut the corner. :func:`join_at_singular_points`
locates the points (:func:`.branches.locate_singular_points`), reads the branch
directions off the second-order form (:func:`.branches.singular_branches`),
cuts the curves out of a ball around each double point and joins each cut end
to the half-branch it points along by points solved on planes across that
branch (:func:`points_on_branch`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from .angles import normal_sines
from .branches import SingularKind, locate_singular_points, singular_branches
from .refine import RefinedCurve
from .topology import EndKind

__all__ = ["join_at_singular_points", "points_on_branch"]


#: a sample whose normals are within this sine of parallel may be near a singular point
_SIN_CANDIDATE = 0.1
#: at most this many such samples per call are tried as starts
_MAX_SAMPLE_STARTS = 16
#: a local minimum of the normals' sine is a start only when it dips by this share (:func:`_dips`)
_DIP_SHARE = 0.25
#: the ball cut around a singular point: this times the farthest end that led to it
_BALL_MARGIN = 1.25
#: a piece end is joined to the half-branch it points along within this angle
_JOIN_COS = np.cos(np.radians(35.0))
#: a cut end whose (u, v) differ from the singular point's by more than this share of
#: the domain's extent (either surface) lies across a seam from it
_SAME_SIDE = 0.25


def _dips(sines: NDArray, minima: NDArray) -> NDArray:
    """Mask of the local minima ``minima`` of a curve's ``sines`` that dip: across the
    five samples around one the sine varies by at least ``_DIP_SHARE`` of its value.

    Near a double point ``|N_a x N_b|`` falls linearly to zero along the curve, as
    ``c |x - x0|``: with samples ``h`` apart the nearest has ``c d`` (``d <= h / 2``)
    and the one two samples beyond ``c (2h - d)``, a variation of at least ``c h >= 2
    c d``. Where the surfaces meet at a small but steady angle (near-tangential
    pairs: a plane just below a torus's top circle, near-coincident sheets) every
    sample is a flat minimum, and none of them is near a singular point."""
    n = sines.size
    window = np.clip(minima[:, None] + np.arange(-2, 3)[None, :], 0, n - 1)
    values = sines[window]
    return np.ptp(values, axis=1) >= _DIP_SHARE * sines[minima]


def _singular_starts(curves: list[RefinedCurve], kinds: list, surface_a: NurbsSurface,
                     surface_b: NurbsSurface) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Starts for :func:`.branches.locate_singular_points`: every BIFURCATION or OPEN
    end, and the samples where the normals come closest to parallel (local
    minima of ``|N_a x N_b|`` below ``_SIN_CANDIDATE``, the lowest few).
    Returns ``points (k, 3)``, ``uv_a, uv_b (k, 2)`` and ``is_end (k,) bool``."""
    pts, ua, ub, is_end = [], [], [], []
    for c, kind in zip(curves, kinds):
        if c.closed or c.points.shape[0] < 2:
            continue
        for e, k in ((0, kind[0]), (-1, kind[1])):
            if k in (EndKind.BIFURCATION, EndKind.OPEN):
                pts.append(c.points[e])
                ua.append(c.uv_a[e])
                ub.append(c.uv_b[e])
                is_end.append(True)
    sizes = [c.points.shape[0] for c in curves]
    if sum(sizes):
        all_a = np.concatenate([c.uv_a for c in curves])
        all_b = np.concatenate([c.uv_b for c in curves])
        sines = normal_sines(surface_a, surface_b, all_a, all_b)
        minima = []
        start = 0
        for n in sizes:
            s = sines[start:start + n]
            if n >= 3:
                inner = np.flatnonzero((s[1:-1] <= s[:-2]) & (s[1:-1] <= s[2:])
                                       & (s[1:-1] < _SIN_CANDIDATE)) + 1
                minima.extend(start + inner[_dips(s, inner)])
            start += n
        minima = np.array(minima, dtype=int)
        minima = minima[np.argsort(sines[minima])[:_MAX_SAMPLE_STARTS]]
        all_p = np.concatenate([c.points for c in curves])
        pts.extend(all_p[minima])
        ua.extend(all_a[minima])
        ub.extend(all_b[minima])
        is_end.extend([False] * minima.size)
    if not pts:
        z = np.zeros((0, 2))
        return np.zeros((0, 3)), z, z, np.zeros(0, dtype=bool)
    return np.array(pts), np.array(ua), np.array(ub), np.array(is_end)


def _unique_points(points: NDArray, merge: float) -> tuple[NDArray, NDArray]:
    """Indices of the first of each group of ``points`` within ``merge``, and the
    group of each point."""
    first, group = [], np.full(points.shape[0], -1)
    for i, p in enumerate(points):
        for g, j in enumerate(first):
            if np.linalg.norm(points[j] - p) <= merge:
                group[i] = g
                break
        else:
            group[i] = len(first)
            first.append(i)
    return np.array(first, dtype=int), group


def _pieces(curve: RefinedCurve, kind: tuple, centre: NDArray, radius: float) -> list:
    """The runs of ``curve`` outside the ball ``|x - centre| < radius``:
    ``[(RefinedCurve, (start_kind, end_kind), (start_cut, end_cut))]``. An end
    made by the cut has kind OPEN and ``*_cut`` True; where the cut removed an
    original BOUNDARY end (a singular point on a seam or side), that end keeps
    kind BOUNDARY (the join brings it back to the point). A curve not entering
    the ball comes back whole."""
    inside = np.linalg.norm(curve.points - centre, axis=1) < radius
    if not inside.any():
        return [(curve, kind, (False, False))]
    fields = [curve.points, curve.uv_a, curve.uv_b, curve.converged, curve.singular]
    if curve.closed:                      # start the open curve inside the ball
        shift = int(np.argmax(inside))
        fields = [np.roll(f, -shift, axis=0) for f in fields]
        inside = np.roll(inside, -shift)
        kind = (EndKind.OPEN, EndKind.OPEN)
    out = []
    edges = np.flatnonzero(np.diff(np.concatenate([[1], inside.astype(int), [1]])))
    n = inside.size
    for lo, hi in zip(edges[0::2], edges[1::2]):      # runs of outside samples [lo, hi)
        if hi - lo < 2:
            continue
        cut = (lo > 0, hi < n)
        k = [kind[0] if lo == 0 else EndKind.OPEN, kind[1] if hi == n else EndKind.OPEN]
        if lo == int(np.argmax(~inside)) and lo > 0 and kind[0] is EndKind.BOUNDARY:
            k[0] = EndKind.BOUNDARY
        if hi == n - int(np.argmax(~inside[::-1])) and hi < n and kind[1] is EndKind.BOUNDARY:
            k[1] = EndKind.BOUNDARY
        part = [f[lo:hi] for f in fields]
        out.append((RefinedCurve(part[0], part[1], part[2], False, part[3], part[4]),
                    tuple(k), cut))
    return out


def points_on_branch(surface_a: NurbsSurface, surface_b: NurbsSurface, centre: NDArray,
                     uv_a: NDArray, uv_b: NDArray, direction: NDArray, heights: NDArray,
                     tol: float, iterations: int = 30, guess: tuple | None = None
                     ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Points of branches leaving singular points along unit directions, all at once.

    Row ``i`` is the intersection of the branch leaving ``centre[i] (3,)`` (at
    ``uv_a[i], uv_b[i]``) along ``direction[i] (3,)`` with the plane
    ``direction[i] . (x - centre[i]) = heights[i]``: Newton on
    ``[a(u, v) - b(s, t), direction . (a - centre) - h]`` (four equations, four
    unknowns), started from the tangent-plane prediction ``centre + h direction``
    mapped by each surface's Jacobian pseudo-inverse there. Its Jacobian is
    regular on the branch away from the centre (the normals differ by about
    ``h |II_a - II_b|``).

    ``guess = (uv_a, uv_b)``, ``(m, 2)`` each, replaces that prediction.

    Returns ``points (m, 3)``, ``uv_a, uv_b (m, 2)`` and ``converged (m,) bool``
    (``|a - b| <= tol / 16`` and within ``tol / 16`` of its plane).
    """
    m = heights.size
    da = surface_a.derivatives(uv_a[:, 0], uv_a[:, 1], 1)
    db = surface_b.derivatives(uv_b[:, 0], uv_b[:, 1], 1)
    step = heights[:, None] * direction
    pa = np.linalg.pinv(np.stack([da[:, 1, 0], da[:, 0, 1]], axis=2))        # (m, 2, 3)
    pb = np.linalg.pinv(np.stack([db[:, 1, 0], db[:, 0, 1]], axis=2))
    z = np.concatenate([uv_a + np.einsum("mij,mj->mi", pa, step),
                        uv_b + np.einsum("mij,mj->mi", pb, step)], axis=1)
    if guess is not None:
        z = np.concatenate([guess[0], guess[1]], axis=1).astype(float)
    lo = np.concatenate([surface_a.domain[0::2], surface_b.domain[0::2]])
    hi = np.concatenate([surface_a.domain[1::2], surface_b.domain[1::2]])
    ok = np.zeros(m, dtype=bool)
    todo = np.arange(m)
    for _ in range(iterations):
        zt = z[todo]
        da = surface_a.derivatives(zt[:, 0], zt[:, 1], 1)
        db = surface_b.derivatives(zt[:, 2], zt[:, 3], 1)
        d = direction[todo]
        gap = da[:, 0, 0] - db[:, 0, 0]
        off = np.einsum("mi,mi->m", da[:, 0, 0] - centre[todo], d) - heights[todo]
        met = (np.linalg.norm(gap, axis=1) <= tol / 16) & (np.abs(off) <= tol / 16)
        done = met & ok[todo]          # one more step once met: rounding level, since
        ok[todo[met]] = True           # near the point tol / 16 would slide tol / (16 sin)
        keep = ~done
        todo, zt, da, db, d = todo[keep], zt[keep], da[keep], db[keep], d[keep]
        gap, off = gap[keep], off[keep]
        if todo.size == 0:
            break
        jac = np.zeros((todo.size, 4, 4))
        jac[:, :3, 0], jac[:, :3, 1] = da[:, 1, 0], da[:, 0, 1]
        jac[:, :3, 2], jac[:, :3, 3] = -db[:, 1, 0], -db[:, 0, 1]
        jac[:, 3, 0] = np.einsum("mi,mi->m", da[:, 1, 0], d)
        jac[:, 3, 1] = np.einsum("mi,mi->m", da[:, 0, 1], d)
        rhs = -np.concatenate([gap, off[:, None]], axis=1)
        good = np.abs(np.linalg.det(jac)) > 1e-300
        dz = np.zeros((todo.size, 4))
        dz[good] = np.linalg.solve(jac[good], rhs[good][..., None])[..., 0]
        z[todo] = np.clip(zt + dz, lo, hi)
    pts = 0.5 * (surface_a.evaluate(z[:, 0], z[:, 1]) + surface_b.evaluate(z[:, 2], z[:, 3]))
    return pts, z[:, :2], z[:, 2:], ok & np.isfinite(z).all(axis=1)


def _reversed(c: RefinedCurve) -> RefinedCurve:
    return RefinedCurve(c.points[::-1], c.uv_a[::-1], c.uv_b[::-1], False, c.converged[::-1],
                        c.singular[::-1])


def _arc_heights(centre: NDArray, direction: NDArray, piece: RefinedCurve) -> NDArray:
    """Plane heights of the new samples between the point and the piece's first
    sample, at about the piece's own first spacing."""
    reach = float((piece.points[0] - centre) @ direction)
    spacing = float(np.linalg.norm(piece.points[1] - piece.points[0]))
    n = min(max(2, int(np.ceil(reach / max(spacing, 1e-300)))), 4096)
    return reach * np.arange(1, n) / n


def _joined(centre: tuple, arc: tuple, piece: RefinedCurve) -> RefinedCurve:
    """``piece`` preceded by the singular point ``centre = (p, uv_a (1, 2), uv_b (1, 2))``
    and the converged ``arc = (points, uv_a, uv_b, converged)`` samples between."""
    p, uv_a, uv_b = centre
    ok = arc[3]
    pts, ua, ub = arc[0][ok], arc[1][ok], arc[2][ok]
    k = pts.shape[0]
    return RefinedCurve(np.concatenate([p[None], pts, piece.points]),
                        np.concatenate([uv_a, ua, piece.uv_a]),
                        np.concatenate([uv_b, ub, piece.uv_b]), False,
                        np.concatenate([np.ones(k + 1, bool), piece.converged]),
                        np.concatenate([[True], np.zeros(k, bool), piece.singular]))


def _centres_per_end(surface_a: NurbsSurface, surface_b: NurbsSurface, centre: tuple,
                     ends: list, tol: float, radius: float) -> list[tuple]:
    """The singular point located again from each cut end ``(piece, end)`` at once,
    so that its (u, v) lie on that end's side of a seam; the shared ``centre``
    where that fails, and for an end whose (u, v) lie within ``_SAME_SIDE`` of the
    domain's extent of the centre's on both surfaces (no seam between them: the
    only other representation of the point is a whole period away)."""
    if not ends:
        return []
    ua = np.array([piece.uv_a[-end] for piece, end in ends])
    ub = np.array([piece.uv_b[-end] for piece, end in ends])
    out = [centre] * len(ends)
    far = np.zeros(len(ends), dtype=bool)
    shifted, extents = [], []   # the centre's (u, v) moved by whole extents towards the end's
    for uv, at, surface in ((ua, centre[1], surface_a), (ub, centre[2], surface_b)):
        extent = np.array([surface.domain[1] - surface.domain[0],
                           surface.domain[3] - surface.domain[2]])
        extents.append(extent)
        far |= np.any(np.abs(uv - at) > _SAME_SIDE * extent, axis=1)
        shifted.append(np.clip(at + extent * np.round((uv - at) / extent), surface.domain[0::2],
                               surface.domain[1::2]))
    if not far.any():
        return out
    idx = np.flatnonzero(far)
    # first from the shifted centre (a seam: a few steps), then from the ends themselves
    for start_a, start_b in ((shifted[0], shifted[1]), (ua, ub)):
        ra, rb, ok = locate_singular_points(surface_a, surface_b, start_a[idx], start_b[idx],
                                            tol=tol, scale=max(radius, tol))
        where = surface_a.evaluate(ra[:, 0], ra[:, 1])
        ok &= np.linalg.norm(where - centre[0], axis=1) <= 16 * tol
        for got, end_uv, extent in ((ra, ua[idx], extents[0]), (rb, ub[idx], extents[1])):
            ok &= np.all(np.abs(got - end_uv) <= _SAME_SIDE * extent, axis=1)   # its side
        for n, i in enumerate(idx):
            if ok[n]:
                out[i] = (centre[0], ra[n:n + 1], rb[n:n + 1])
        idx = idx[~ok]
        if idx.size == 0:
            break
    return out


def _resolve_one(curves: list, kinds: list, centre: tuple, directions: NDArray,
                 radius: float, surface_a: NurbsSurface, surface_b: NurbsSurface,
                 tol: float) -> tuple[list, list]:
    """Cut the ball of ``radius`` around one double point out of every curve and
    join the cut ends to the half-branches ``+-directions (2, 3)`` through it
    (each half-branch to the cut end pointing most nearly along it)."""
    p = centre[0]
    pieces = []
    for c, k in zip(curves, kinds):
        pieces.extend(_pieces(c, k, p, radius))
    halves = np.concatenate([directions, -directions])              # (4, 3)
    ends = []                     # (cos, piece, end 0 / 1, half)
    for i, (piece, _, cut) in enumerate(pieces):
        for end in (0, 1):
            if cut[end]:
                x = piece.points[-end] - p
                cos = halves @ x / max(np.linalg.norm(x), 1e-300)
                ends.append((float(np.max(cos)), i, end, int(np.argmax(cos))))
    taken, joins = set(), {}
    for cos, i, end, j in sorted(ends, reverse=True):
        if cos >= _JOIN_COS and j not in taken:
            taken.add(j)
            joins[(i, end)] = j
    keys = sorted(joins)
    local = dict(zip(keys, _centres_per_end(surface_a, surface_b, centre,
                                            [(pieces[i][0], e) for i, e in keys], tol, radius)))
    # every join's arc in one batched solve, each piece seen from its joined end
    starts = {key: pieces[key[0]][0] if key[1] == 0 else _reversed(pieces[key[0]][0])
              for key in keys}
    heights = [_arc_heights(p, halves[joins[key]], starts[key]) for key in keys]
    rows = np.repeat(np.arange(len(keys)), [h.size for h in heights])
    arcs = {}
    if keys:
        cu = np.concatenate([local[key][1] for key in keys])
        cv = np.concatenate([local[key][2] for key in keys])
        dirs = np.stack([halves[joins[key]] for key in keys])
        solved = points_on_branch(surface_a, surface_b, np.broadcast_to(p, (rows.size, 3)),
                             cu[rows], cv[rows], dirs[rows], np.concatenate(heights), tol)
        for n, key in enumerate(keys):
            arcs[key] = tuple(x[rows == n] for x in solved)
    new_curves, new_kinds = [], []
    for i, (piece, kind, _) in enumerate(pieces):
        kind = list(kind)
        if (i, 0) in joins:
            piece = _joined(local[(i, 0)], arcs[(i, 0)], piece)
            kind[0] = kind[0] if kind[0] is EndKind.BOUNDARY else EndKind.BIFURCATION
        if (i, 1) in joins:
            piece = _reversed(_joined(local[(i, 1)], arcs[(i, 1)], _reversed(piece)))
            kind[1] = kind[1] if kind[1] is EndKind.BOUNDARY else EndKind.BIFURCATION
        new_curves.append(piece)
        new_kinds.append(tuple(kind))
    return new_curves, new_kinds


def join_at_singular_points(curves: list[RefinedCurve], kinds: list[tuple[EndKind, EndKind]],
                            surface_a: NurbsSurface, surface_b: NurbsSurface, *, tol: float,
                            reach: float) -> tuple[list[RefinedCurve], list[tuple]]:
    """Curves meeting at singular points of the intersection made to end exactly there.

    Near a point where the surfaces cross with parallel normals (a double point:
    two branches crossing, as two cylinders of equal radius with perpendicular
    axes) the tessellations' segments cross over between the branches and the
    refinement's auxiliary plane degenerates (its normal ``N_a x N_b`` vanishes),
    so the traced curves end short of the point, switch branches, or cut the
    corner. Here (000 §29.5.1; 002 §4):

    1. the singular points are located (:func:`.branches.locate_singular_points`)
       from every BIFURCATION / OPEN end and from the samples where the normals
       come nearest to parallel, keeping those within ``reach`` of their start;
    2. the branch directions come from the second-order form ``II_a - II_b``
       (:func:`.branches.singular_branches`); only double points are resolved;
    3. every curve is cut out of a ball around the point (``_BALL_MARGIN`` times
       the farthest end that led to it), and each cut end is joined to the
       half-branch it points along by points solved on planes across that
       branch (:func:`points_on_branch`), so four curves end at the point, with end
       kind BIFURCATION and the point itself as their first sample.

    Parameters
    ----------
    curves : list of RefinedCurve
        Dense refined curves.
    kinds : list of (EndKind, EndKind)
        Their end kinds.
    tol : float
        Model units; new samples lie within ``tol / 16`` of both surfaces.
    reach : float
        Model units: how far from a curve end or sample a singular point is looked for.

    Returns
    -------
    (curves, kinds)
        With every double point found resolved; unchanged when there is none.
    """
    pts, ua, ub, is_end = _singular_starts(curves, kinds, surface_a, surface_b)
    if pts.shape[0] == 0:
        return curves, kinds
    sa, sb, ok = locate_singular_points(surface_a, surface_b, ua, ub, tol=tol, scale=reach)
    where = 0.5 * (surface_a.evaluate(sa[:, 0], sa[:, 1]) + surface_b.evaluate(sb[:, 0], sb[:, 1]))
    dist = np.linalg.norm(where - pts, axis=1)
    ok &= dist <= reach
    if not ok.any():
        return curves, kinds
    idx = np.flatnonzero(ok)
    first, group = _unique_points(where[idx], max(64 * tol, 1e-3 * reach))
    centres, kinds_s, dirs = singular_branches(surface_a, surface_b, sa[idx[first]],
                                               sb[idx[first]])
    curves, kinds = list(curves), list(kinds)
    for g, f in enumerate(first):
        if kinds_s[g] is not SingularKind.DOUBLE_POINT:
            continue
        mine = group == g
        far = dist[idx[mine]][is_end[idx[mine]]]
        spacing = _local_spacing(curves, centres[g], reach)
        radius = min(max(_BALL_MARGIN * (far.max() if far.size else 0.0), 4 * spacing), reach)
        radius = _clear_of_sides(curves, kinds, centres[g], radius)
        centre = (centres[g], sa[idx[f]][None], sb[idx[f]][None])
        curves, kinds = _resolve_one(curves, kinds, centre, dirs[g], radius, surface_a,
                                     surface_b, tol)
    return curves, kinds


def _clear_of_sides(curves: list[RefinedCurve], kinds: list, centre: NDArray,
                    radius: float) -> float:
    """``radius`` shrunk so that no BOUNDARY end lies in the ball unless it lies at
    ``centre`` (within a quarter of the radius: a singular point on a side or
    seam, whose end kind the join keeps)."""
    for c, kind in zip(curves, kinds):
        if c.closed:
            continue
        for e, k in ((0, kind[0]), (-1, kind[1])):
            d = float(np.linalg.norm(c.points[e] - centre))
            if k is EndKind.BOUNDARY and 0.25 * radius < d < radius:
                radius = 0.9 * d
    return radius


def _local_spacing(curves: list[RefinedCurve], centre: NDArray, reach: float) -> float:
    """Largest spacing of the samples within ``reach`` of ``centre`` (0 if none)."""
    best = 0.0
    for c in curves:
        near = np.linalg.norm(c.points - centre, axis=1) <= reach
        if near.sum() >= 2:
            d = np.linalg.norm(np.diff(c.points, axis=0), axis=1)
            best = max(best, float(d[near[:-1] & near[1:]].max(initial=0.0)))
    return best
