"""Characteristic points of the oriented distance function (002 §3.3, §4.2, §6.3).

* **Border points** (eq. 6): a boundary curve of one surface meets the other
  surface. Found by sampling ``phi`` along every side of each domain (the
  boundary curve projected onto the other surface), then Newton on
  ``r(u, v) = q(s, t)`` with the side's parameter held (three equations, three
  unknowns), batched over all sign changes.
* **Initial points of characteristic curves** (§6.3 step 2): roots of
  ``phi_u`` and ``phi_v`` along the sides of ``r``'s domain, by sampling and
  batched regula falsi.
* **Critical points** (eq. 9): ``grad phi = 0`` by Newton's method
  (``H d = -grad phi``) from seeds; classified by ``det H`` (§4.2): maximum /
  minimum (``det H > 0``) or saddle (``det H < 0``).
* **Singular points** (eq. 8): critical points on the intersection
  (``|phi| <= tol``), classified by the Gaussian curvature of the graph of
  ``phi`` (the sign of ``det H``): isolated point (tangential contact,
  ``det H > 0``), double point (``det H < 0``), cusp (``det H = 0``).
* **Turning points** (eq. 7) are the zeros of ``phi`` on the characteristic
  curves (§5: "a u- (v-) characteristic curve will reveal the v- (u-) turning
  points"); :mod:`.curves` finds them.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from . import points_kernels
from .distance import DistanceField, DistanceJet
from .projector import ProjectionStatus

__all__ = [
    "CharacteristicPoint",
    "PointKind",
    "border_points",
    "classify_critical",
    "critical_points",
    "edge_roots",
    "edge_samples",
    "grid_seeds",
    "make_points",
    "solve_held",
]

#: samples per side of a domain for the 1-D root searches (at least)
EDGE_SAMPLES = 65
#: a critical point is degenerate when |det H| is below this times |H|^2
DEGENERATE_SHARE = 1e-6


class PointKind(enum.Enum):
    """What a characteristic point is."""

    BORDER = "border"
    EDGE_ROOT_U = "edge_root_u"          # phi_u = 0 on a side: starts a u-characteristic curve
    EDGE_ROOT_V = "edge_root_v"
    TURNING_U = "turning_u"              # phi = phi_u = 0 (eq. 7)
    TURNING_V = "turning_v"
    MAXIMUM = "maximum"
    MINIMUM = "minimum"
    SADDLE = "saddle"
    DEGENERATE = "degenerate"            # critical, det H = 0, off the intersection
    ISOLATED = "isolated"                # singular, det H > 0: tangential contact point
    DOUBLE_POINT = "double_point"        # singular, det H < 0: two branches cross
    CUSP = "cusp"                        # singular, det H = 0

    @property
    def is_critical(self) -> bool:
        return self in _CRITICAL

    @property
    def is_singular(self) -> bool:
        return self in (PointKind.ISOLATED, PointKind.DOUBLE_POINT, PointKind.CUSP)


_CRITICAL = frozenset({PointKind.MAXIMUM, PointKind.MINIMUM, PointKind.SADDLE,
                       PointKind.DEGENERATE, PointKind.ISOLATED, PointKind.DOUBLE_POINT,
                       PointKind.CUSP})


@dataclass(frozen=True)
class CharacteristicPoint:
    """One characteristic point, in the pair's order (``a``, ``b``).

    Attributes
    ----------
    kind : PointKind
    uv_a, uv_b : (2,) float
        Parameters on ``a`` and on ``b`` (the foot of the projection).
    point : (3,) float
        The point on the surface ``phi`` lives on.
    phi : float
        Oriented distance there.
    """

    kind: PointKind
    uv_a: NDArray
    uv_b: NDArray
    point: NDArray
    phi: float


def make_points(field: DistanceField, kind: PointKind | list, uv: NDArray, st: NDArray,
                point: NDArray, phi: NDArray) -> list[CharacteristicPoint]:
    """CharacteristicPoints ``(m,)`` from arrays on ``r`` / ``q`` (roles put in a, b order)."""
    ua, ub = field.ab(uv, st)
    kinds = [kind] * len(phi) if isinstance(kind, PointKind) else list(kind)
    return [CharacteristicPoint(k, ua[i].copy(), ub[i].copy(), point[i].copy(), float(phi[i]))
            for i, k in enumerate(kinds)]


# ------------------------------------------------------------------ classification
def classify_critical(phi: NDArray, hess: NDArray, tol: float) -> list[PointKind]:
    """Kinds of critical points ``(m,)`` from ``phi (m,)`` and ``hess (m, 2, 2)`` (§4.2, eq. 8)."""
    det = hess[:, 0, 0] * hess[:, 1, 1] - hess[:, 0, 1] * hess[:, 1, 0]
    size = np.einsum("mij,mij->m", hess, hess)
    flat = np.abs(det) <= DEGENERATE_SHARE * size + 1e-300
    out = []
    for f, d, fl, trace in zip(phi, det, flat, hess[:, 0, 0] + hess[:, 1, 1]):
        if abs(f) <= tol:
            out.append(PointKind.CUSP if fl else
                       PointKind.ISOLATED if d > 0 else PointKind.DOUBLE_POINT)
        elif fl:
            out.append(PointKind.DEGENERATE)
        elif d > 0:
            out.append(PointKind.MAXIMUM if trace < 0 else PointKind.MINIMUM)
        else:
            out.append(PointKind.SADDLE)
    return out


# ------------------------------------------------------------------ critical points
def _newton_steps(h: NDArray, g: NDArray, flat: float) -> tuple[NDArray, NDArray]:
    """Newton steps ``-H^{-1} g`` (m, 2) and ``ok (m,)``. Where ``H`` is degenerate
    (``|det H| <= DEGENERATE_SHARE |H|^2``) the pseudo-inverse instead: the inverse
    on the eigenvalues above ``DEGENERATE_SHARE`` of the largest (a rank-1 Hessian
    on a ridge of critical points still gives the step across the ridge); ``ok``
    False where ``H`` is below ``flat`` altogether."""
    lam, vec = np.linalg.eigh(h)                                  # (m, 2), (m, 2, 2)
    top = np.abs(lam).max(axis=1)
    rank1 = np.abs(lam[:, 0] * lam[:, 1]) <= DEGENERATE_SHARE * top ** 2
    big = ~rank1[:, None] | (np.abs(lam) > DEGENERATE_SHARE * top[:, None])
    coef = np.where(big, np.einsum("mki,mk->mi", vec, g) / np.where(big, lam, 1.0), 0.0)
    return -np.einsum("mki,mi->mk", vec, coef), top > flat


def critical_points(field: DistanceField, seeds: NDArray, st0: NDArray | None = None, *,
                    max_iter: int = 16, dedupe: float = 1e-7,
                    hess_scale: float = 0.0, compiled: bool | None = None
                    ) -> DistanceJet | None:
    """Newton on ``grad phi = 0`` (eq. 9) from ``seeds (k, 2)``, batched.

    Steps are limited to a tenth of the domain diagonal; a seed whose iterate
    leaves ``r``'s domain, loses its regular projection or does not converge in
    ``max_iter`` steps is dropped. Converged points closer than ``dedupe`` times
    the diagonal are merged. With ``hess_scale`` (the largest ``|H|`` of ``phi``
    over the domain) a degenerate ``H`` takes the pseudo-inverse step
    (:func:`_newton_steps`): Newton then converges onto a curve of critical
    points (a surface of revolution cut normal to its axis: ``det H = 0`` all
    along it) instead of giving up; ``H`` below ``1e-9 hess_scale`` (``phi``
    flat) still stops the seed. ``compiled`` (default: when numba is there) runs
    the same iterations by :mod:`.points_kernels`; False: the batched numpy form.

    Returns
    -------
    DistanceJet at the distinct critical points, or None when there are none.
    """
    if len(seeds) == 0:
        return None
    diag = field.diagonal
    uv = np.array(seeds, dtype=float).reshape(-1, 2)
    st = None if st0 is None else np.array(st0, dtype=float).reshape(-1, 2)
    if compiled is None:
        compiled = points_kernels.AVAILABLE
    if compiled:
        if st is None:
            st = (np.zeros_like(uv) if field.projector.is_affine
                  else field.projector.seeds(field.evaluator.evaluate(uv[:, 0], uv[:, 1])))
        uv, st, done = points_kernels.newton_compiled(
            field, uv, st, max_iter=max_iter, flat=1e-9 * hess_scale,
            degenerate=DEGENERATE_SHARE, pseudo=hess_scale > 0)
        return _distinct(field, uv, st, done, dedupe)
    alive = np.ones(uv.shape[0], dtype=bool)
    done = np.zeros(uv.shape[0], dtype=bool)
    for _ in range(max_iter):
        todo = np.flatnonzero(alive & ~done)
        if todo.size == 0:
            break
        jet = field.jet(uv[todo], None if st is None else st[todo])
        if st is None:
            st = np.zeros_like(uv)
        st[todo] = jet.st
        h, g = jet.hess, jet.grad
        if hess_scale > 0:
            step, ok = _newton_steps(h, g, 1e-9 * hess_scale)
        else:
            det = h[:, 0, 0] * h[:, 1, 1] - h[:, 0, 1] ** 2
            ok = np.abs(det) > 1e-300
            det = np.where(ok, det, 1.0)
            step = -np.stack([h[:, 1, 1] * g[:, 0] - h[:, 0, 1] * g[:, 1],
                              h[:, 0, 0] * g[:, 1] - h[:, 0, 1] * g[:, 0]], -1) / det[:, None]
        length = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, 0.1 * diag / np.maximum(length, 1e-300))[:, None]
        uv[todo] += step
        bad = ~ok | (jet.status != ProjectionStatus.UNIQUE) | ~field.inside(uv[todo], 1e-9)
        alive[todo[bad]] = False
        done[todo[~bad & (length <= 1e-13 * diag)]] = True
    return _distinct(field, uv, st, done & alive, dedupe)


def _distinct(field: DistanceField, uv: NDArray, st: NDArray, done: NDArray, dedupe: float
              ) -> DistanceJet | None:
    """The jet at the converged ``uv[done]`` with a unique foot, merged within ``dedupe``."""
    diag = field.diagonal
    keep = np.flatnonzero(done)
    if keep.size == 0:
        return None
    jet = field.jet(uv[keep], st[keep])
    keep = np.flatnonzero(jet.status == ProjectionStatus.UNIQUE)
    if keep.size == 0:
        return None
    pts = jet.uv[keep]
    order = _first_apart(pts, dedupe * diag)
    return field.jet(pts[order], jet.st[keep][order])


def _first_apart(pts: NDArray, radius: float) -> list[int]:
    """Indices of ``pts (k, d)``, in order, each farther than ``radius`` from every one
    kept before it (one matrix of distances, then a greedy pass over its rows; ``k``
    is bounded by the side samples and the grid seeds, some hundreds at most)."""
    if pts.shape[0] == 0:
        return []
    far = (np.linalg.norm(pts[:, None] - pts[None], axis=-1) > radius).tolist()
    keep: list[int] = []
    for i, row in enumerate(far):
        if all(row[j] for j in keep):
            keep.append(i)
    return keep


def grid_seeds(jet: DistanceJet, shape: tuple[int, int], max_seeds: int = 400,
               noise: float = 0.0) -> NDArray:
    """Seeds ``(k, 2)`` for critical points from a jet on a tensor grid ``shape``.

    A cell whose corners see both ``phi_u`` and ``phi_v`` change sign, or a grid
    sample that is a local extremum of ``phi`` among its 8 neighbours, seeds
    Newton (the cell centre / the sample). Samples without a regular projection
    take no part; gradient components within ``noise`` of zero count as zero of
    either sign only when the cell also holds a value beyond it. A cell where one
    component is within ``noise`` at all four corners (it vanishes identically:
    ``phi`` constant along lines) and the other changes sign beyond it holds a
    ridge of critical points; one seed per run of such cells along the null
    direction (a ridge needs one point: :mod:`.ridges` traces the rest).
    """
    nu, nv = shape
    uv = jet.uv.reshape(nu, nv, 2)
    ok = (jet.status == ProjectionStatus.UNIQUE).reshape(nu, nv)
    g = jet.grad.reshape(nu, nv, 2)
    corners = [(slice(0, -1), slice(0, -1)), (slice(1, None), slice(0, -1)),
               (slice(0, -1), slice(1, None)), (slice(1, None), slice(1, None))]
    cell_ok = np.logical_and.reduce([ok[c] for c in corners])
    change = np.ones((nu - 1, nv - 1), dtype=bool)
    for k in range(2):
        vals = np.stack([g[c][..., k] for c in corners])
        change &= ((vals.min(axis=0) <= 0) & (vals.max(axis=0) >= 0)
                   & (np.abs(vals).max(axis=0) > noise))
    centre = 0.25 * sum(uv[c] for c in corners)
    seeds = [centre[change & cell_ok]]
    phi = np.where(ok, jet.phi.reshape(nu, nv), np.nan)
    pad = np.pad(phi, 1, constant_values=np.nan)
    neigh = np.stack([pad[1 + di:nu + 1 + di, 1 + dj:nv + 1 + dj]
                      for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj])
    with np.errstate(invalid="ignore"):
        top = np.all((phi >= neigh) | np.isnan(neigh), axis=0) & ok
        bottom = np.all((phi <= neigh) | np.isnan(neigh), axis=0) & ok
    seeds.append(uv[top | bottom])
    out = np.concatenate(seeds)
    if noise > 0:          # a flat grid (phi constant along lines) is no seed
        flat = np.all(np.abs(jet.grad) <= noise, axis=1).reshape(nu, nv)
        extreme = (top | bottom) & ~flat
        out = np.concatenate([seeds[0], uv[extreme], _ridge_seeds(g, centre, cell_ok, corners,
                                                                  noise)])
    if out.shape[0] > max_seeds:
        out = out[np.linspace(0, out.shape[0] - 1, max_seeds).astype(int)]
    return out


def _ridge_seeds(g: NDArray, centre: NDArray, cell_ok: NDArray, corners: list, noise: float
                 ) -> NDArray:
    """Cell centres ``(k, 2)`` on ridges of critical points (:func:`grid_seeds`): the
    first cell of every run along the direction in which ``phi`` is constant."""
    out = [np.zeros((0, 2))]
    for null in (0, 1):
        vals = np.stack([g[c][..., null] for c in corners])
        other = np.stack([g[c][..., 1 - null] for c in corners])
        ridge = (cell_ok & np.all(np.abs(vals) <= noise, axis=0)
                 & (other.min(axis=0) <= 0) & (other.max(axis=0) >= 0)
                 & (np.abs(other).max(axis=0) > noise))
        # phi_u = 0 identically: phi constant along u, runs go along axis 0
        ridge = ridge if null == 0 else ridge.T
        first = ridge & ~np.vstack([np.zeros((1, ridge.shape[1]), dtype=bool), ridge[:-1]])
        first = first if null == 0 else first.T
        out.append(centre[first])
    return np.concatenate(out)


# ------------------------------------------------------------------ sides
def edge_samples(lower: NDArray, upper: NDArray, count: int) -> list[tuple[int, float, NDArray]]:
    """The four sides of a domain: ``(held coordinate, held value, uv (count, 2))`` each."""
    out = []
    for coord in (0, 1):
        free = 1 - coord
        t = np.linspace(lower[free], upper[free], count)
        for value in (lower[coord], upper[coord]):
            uv = np.empty((count, 2))
            uv[:, coord], uv[:, free] = value, t
            out.append((coord, float(value), uv))
    return out


def _edge_count(surface: NurbsSurface) -> int:
    spans = max(np.unique(surface.knots_u).size, np.unique(surface.knots_v).size) - 1
    return max(EDGE_SAMPLES, 4 * spans + 1)


def side_jets(field: DistanceField) -> tuple[list[tuple[int, float, NDArray]], DistanceJet]:
    """The four sides of ``r``'s domain (:func:`edge_samples`, :func:`_edge_count` samples
    each) and ``phi``'s jet at all of them, side after side: one batch, computed once
    per field (the border points and the side roots of ``phi_u``, ``phi_v`` read the
    same samples)."""
    if "sides" not in field._cache:
        sides = edge_samples(field.lower, field.upper, _edge_count(field.r))
        field._cache["sides"] = (sides, field.jet(np.concatenate([uv for _, _, uv in sides])))
    return field._cache["sides"]


def edge_roots(field: DistanceField, component: int, iterations: int = 6, noise: float = 0.0
               ) -> tuple[NDArray, NDArray, NDArray]:
    """Roots of ``phi_u`` (``component`` 0) or ``phi_v`` (1) on the sides of ``r``'s domain.

    Sampling, then batched regula falsi (Illinois) on each bracket with a regular
    projection at both ends (§6.3 step 2). A sign change between values both
    within ``noise`` of zero is rounding, not a root (a side along which
    ``phi_u`` vanishes identically, e.g. a surface of revolution against a
    plane normal to its axis).

    Returns
    -------
    uv : (k, 2) float
    st : (k, 2) float
    side : (k,) int
        The held coordinate of each root's side (0: a side ``u = const``).
    """
    brackets = []
    sides, every = side_jets(field)
    count = sides[0][2].shape[0]
    for n, (coord, _, uv) in enumerate(sides):
        rows = slice(n * count, (n + 1) * count)
        g = every.grad[rows, component]
        ok = every.status[rows] == ProjectionStatus.UNIQUE
        st_side = every.st[rows]
        k = np.flatnonzero(ok[:-1] & ok[1:] & (np.sign(g[:-1]) != np.sign(g[1:]))
                           & (np.maximum(np.abs(g[:-1]), np.abs(g[1:])) > noise))
        for i in k:
            brackets.append((uv[i], uv[i + 1], g[i], g[i + 1], st_side[i], coord))
    if not brackets:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, dtype=int)
    a = np.array([b[0] for b in brackets])
    b = np.array([b[1] for b in brackets])
    fa = np.array([b[2] for b in brackets])
    fb = np.array([b[3] for b in brackets])
    st = np.array([b[4] for b in brackets])
    side = np.array([b[5] for b in brackets])
    side_a = np.zeros(a.shape[0], dtype=bool)
    for _ in range(iterations):
        w = fa / np.where(fa != fb, fa - fb, 1.0)
        x = a + w[:, None] * (b - a)
        jet = field.jet(x, st)
        fx = jet.grad[:, component]
        st = jet.st
        left = np.sign(fx) == np.sign(fa)
        # Illinois: halve the stale end's value when the same side moves twice
        fb = np.where(left & side_a, 0.5 * fb, fb)
        fa = np.where(~left & ~side_a, 0.5 * fa, fa)
        a = np.where(left[:, None], x, a)
        fa = np.where(left, fx, fa)
        b = np.where(left[:, None], b, x)
        fb = np.where(left, fb, fx)
        side_a = left
    uv = np.where((np.abs(fa) <= np.abs(fb))[:, None], a, b)
    return uv, st, side


def solve_held(a: NurbsSurface, b: NurbsSurface, uv_a: NDArray, uv_b: NDArray,
               on_b: NDArray, coord: NDArray, value: NDArray, tol: float,
               iterations: int = 30) -> tuple[NDArray, NDArray, NDArray]:
    """Newton on ``a(uv_a) = b(uv_b)`` with one parameter held on a domain side.

    Batched over ``k`` points: ``on_b (k,) bool`` says whether the held
    parameter is ``b``'s, ``coord (k,)`` which one, ``value (k,)`` its value.
    Three equations in the three free parameters.

    Returns
    -------
    uv_a, uv_b : (k, 2) float
    converged : (k,) bool
        ``|a - b| <= tol`` and inside both domains.
    """
    ua, ub = uv_a.astype(float).copy(), uv_b.astype(float).copy()
    k = ua.shape[0]
    rows = np.arange(k)
    held = np.zeros((k, 4), dtype=bool)
    held[rows, 2 * on_b + coord] = True
    x = np.concatenate([ua, ub], axis=1)
    x[rows, 2 * on_b + coord] = value
    da_, db_ = a.domain, b.domain
    lo = np.array([da_[0], da_[2], db_[0], db_[2]])
    hi = np.array([da_[1], da_[3], db_[1], db_[3]])
    span = hi - lo
    free_order = np.argsort(held, axis=1, kind="stable")[:, :3]
    gap = np.full((k, 3), np.inf)
    for _ in range(iterations):
        pa = a.derivatives(x[:, 0], x[:, 1], 1)
        pb = b.derivatives(x[:, 2], x[:, 3], 1)
        gap = pa[:, 0, 0] - pb[:, 0, 0]
        if np.all(np.linalg.norm(gap, axis=1) <= 0.01 * tol):
            break
        cols = np.stack([pa[:, 1, 0], pa[:, 0, 1], -pb[:, 1, 0], -pb[:, 0, 1]], axis=2)
        jac = np.take_along_axis(cols, free_order[:, None, :], axis=2)
        ok = np.abs(np.linalg.det(jac)) > 1e-300
        step = np.zeros((k, 3))
        if ok.any():
            step[ok] = np.linalg.solve(jac[ok], -gap[ok][..., None])[..., 0]
        full = np.zeros((k, 4))
        np.put_along_axis(full, free_order, step, axis=1)
        scale = np.max(np.abs(full) / (0.1 * span), axis=1)
        full /= np.maximum(scale, 1.0)[:, None]
        x = np.clip(x + full, lo, hi)
    pa = a.evaluate(x[:, 0], x[:, 1])
    pb = b.evaluate(x[:, 2], x[:, 3])
    converged = np.linalg.norm(pa - pb, axis=1) <= tol
    return x[:, :2], x[:, 2:], converged


def border_points(fields: tuple[DistanceField, DistanceField], tol: float
                  ) -> tuple[NDArray, NDArray, NDArray]:
    """Border points (eq. 6) of a pair: every side of each domain against the other surface.

    ``fields`` are the two roles of the pair (``r = a`` and ``r = b``). Along each
    side of ``r``'s domain ``phi`` is sampled, sign changes with regular
    projections at both ends give starts, and :func:`solve_held` puts them on the
    side. Duplicates (a corner, or the same point found from both surfaces)
    merged within ``tol``.

    Returns
    -------
    points : (k, 3) float
    uv_a, uv_b : (k, 2) float
    """
    a = fields[0].r
    b = fields[0].q
    starts_a, starts_b, on_b, coords, values = [], [], [], [], []
    for field in fields:
        sides, every = side_jets(field)
        count = sides[0][2].shape[0]
        for n, (coord, value, uv) in enumerate(sides):
            rows = slice(n * count, (n + 1) * count)
            st_side = every.st[rows]
            ok = every.status[rows] != ProjectionStatus.NONE
            f = every.phi[rows]
            k = np.flatnonzero(ok[:-1] & ok[1:] & ((np.sign(f[:-1]) != np.sign(f[1:]))
                                                   | (np.abs(f[:-1]) <= tol)))
            if k.size == 0:
                continue
            w = f[k] / np.where(f[k] != f[k + 1], f[k] - f[k + 1], 1.0)
            uv0 = uv[k] + np.clip(w, 0, 1)[:, None] * (uv[k + 1] - uv[k])
            ua, ub = field.ab(uv0, st_side[k])
            starts_a.append(ua)
            starts_b.append(ub)
            on_b.append(np.full(k.size, field.swapped))
            coords.append(np.full(k.size, coord))
            values.append(np.full(k.size, value))
    if not starts_a:
        return np.zeros((0, 3)), np.zeros((0, 2)), np.zeros((0, 2))
    ua, ub, ok = solve_held(a, b, np.concatenate(starts_a), np.concatenate(starts_b),
                            np.concatenate(on_b).astype(int), np.concatenate(coords),
                            np.concatenate(values), tol / 16)
    ua, ub = ua[ok], ub[ok]
    pts = 0.5 * (a.evaluate(ua[:, 0], ua[:, 1]) + b.evaluate(ub[:, 0], ub[:, 1]))
    keep = _first_apart(pts, tol)
    return pts[keep], ua[keep], ub[keep]
