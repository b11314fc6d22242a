"""Measures of trivariate NURBS solids (004 §3): volume, collapsed and exterior faces,
point inversion.

* **Volume** ``integral |det J| du dv dw`` by Gauss–Legendre quadrature, a tensor rule
  on every knot span (:func:`solid_volume`). For a polynomial solid of degrees
  ``(p, q, r)`` in space, ``det J`` is a polynomial of degrees ``(3p - 1, 3q - 1,
  3r - 1)`` on each span, which ``ceil(3p / 2)`` Gauss points in u (and likewise in v,
  w) integrate exactly; a rational solid gets :data:`RATIONAL_EXTRA` more points per
  direction (the integrand is a smooth rational function there; the solid sphere and
  torus of :mod:`.volume_builders` come out within about 1e-14 relative).
* **Collapsed faces** (004 §3: "the degenerate cases are those for which any of the
  six surfaces in eq. 3.3 collapse"): a face whose area is ~ 0, a curve or a point
  (:func:`collapsed_faces`). **Exterior faces**: the non-degenerate exterior boundary,
  the faces neither collapsed nor glued to the opposite face (:func:`exterior_faces`).
* **Inversion** of points ``x(u, v, w) = p`` by Newton's method with the Jacobian
  (:func:`invert_points`), and the nearest point of the solid for points outside it.

The functions take the solid as their first argument and use only its methods, so this
module does not import :mod:`.volume` (whose methods call it).

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997 (section 6.1).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from ..errors import InvalidGeometryError
from .basis import distinct_knots
from .projection import project_to_surface
from .projection.newton import check_count, check_points, projection_tolerance, span_samples
from .surface import NurbsSurface
from .tolerance import check_tolerance

if TYPE_CHECKING:                                        # pragma: no cover
    from .volume import NurbsVolume

__all__ = [
    "OUTWARD",
    "RATIONAL_EXTRA",
    "VolumeInversion",
    "collapsed_faces",
    "exterior_faces",
    "gauss_rule",
    "handedness",
    "invert_points",
    "solid_volume",
    "surface_area",
]

#: faces whose normal ``S_a x S_b`` points out of a right-handed solid (``det J > 0``)
OUTWARD = frozenset({"u1", "v0", "w1"})
#: Gauss points per span and direction added for rational solids
RATIONAL_EXTRA = 10
#: default relative tolerance of the collapsed-face and seam tests (times the box diagonal)
_FACE_RELATIVE_TOL = 1e-10
#: quadrature points per batch of the volume integral
_CHUNK = 1 << 16
_MAX_HALVINGS = 30
#: samples per direction of the inversion's seed grid, at most
_MAX_SEED_SAMPLES = 40


def gauss_rule(knots: NDArray, degree: int, n: int) -> tuple[NDArray, NDArray]:
    """Gauss–Legendre nodes and weights, ``n`` on every non-empty knot span of the domain.

    Returns
    -------
    nodes : (S n,) float
    weights : (S n,) float
        Summing to the length of the domain.
    """
    x, w = np.polynomial.legendre.leggauss(int(n))
    breaks, _ = distinct_knots(knots, degree)
    a, b = breaks[:-1, None], breaks[1:, None]
    nodes = 0.5 * (a + b) + 0.5 * (b - a) * x[None, :]
    return nodes.reshape(-1), (0.5 * (b - a) * w[None, :]).reshape(-1)


def _gauss_counts(volume: NurbsVolume, n_points: int | None) -> list[int]:
    if n_points is not None:
        return [check_count(n_points, "n_points", 1)] * 3
    extra = RATIONAL_EXTRA if volume.weights is not None else 0
    return [max(1, -(-3 * p // 2)) + extra for p in volume.degrees]


def _require_space(volume: NurbsVolume, what: str) -> None:
    if volume.dimension != 3:
        raise InvalidGeometryError(f"{what} needs a solid in 3D, got dimension {volume.dimension}")


def solid_volume(volume: NurbsVolume, n_points: int | None = None) -> float:
    """Volume of the solid, ``integral |det J(u, v, w)| du dv dw`` over its domain.

    Gauss–Legendre quadrature, a tensor rule on every knot span. The default counts
    per span and direction are ``ceil(3 p / 2)`` for degree ``p`` (``det J`` has degree
    ``3 p - 1`` in that direction, so a polynomial solid's volume is exact to rounding),
    plus :data:`RATIONAL_EXTRA` for a rational solid.

    Parameters
    ----------
    volume : NurbsVolume, dimension 3
    n_points : int, optional
        Points per span in every direction instead of the default.

    Returns
    -------
    float
        A folded solid (``det J`` changing sign) counts the overlap twice.
    """
    _require_space(volume, "volume()")
    rules = [gauss_rule(k, p, n) for k, p, n in
             zip(volume.knots, volume.degrees, _gauss_counts(volume, n_points))]
    (nu, wu), (nv, wv), (nw, ww) = rules
    step = max(1, _CHUNK // (nv.size * nw.size))
    total = 0.0
    for start in range(0, nu.size, step):
        part = slice(start, start + step)
        d = volume.derivatives_grid(nu[part], nv, nw, 1)
        jac = np.stack([d[..., 1, 0, 0, :], d[..., 0, 1, 0, :], d[..., 0, 0, 1, :]], axis=-1)
        det = np.abs(np.linalg.det(jac))                               # (a, b, c)
        total += float(np.einsum("abc,a,b,c->", det, wu[part], wv, ww))
    return total


def surface_area(surface: NurbsSurface, n_points: int | None = None) -> float:
    """Area of a surface by Gauss–Legendre quadrature per knot span (``degree + 2`` points
    per span and direction by default): ``integral sqrt(|S_a|^2 |S_b|^2 - (S_a . S_b)^2)``.
    Approximate for curved surfaces; 0 to rounding for a face collapsed to a curve or a
    point."""
    counts = [surface.degree_u + 2, surface.degree_v + 2] if n_points is None else [n_points] * 2
    (na, wa), (nb, wb) = (gauss_rule(k, p, n) for k, p, n in
                          zip((surface.knots_u, surface.knots_v),
                              (surface.degree_u, surface.degree_v), counts))
    d = surface.derivatives_grid(na, nb, 1)
    su, sv = d[:, :, 1, 0], d[:, :, 0, 1]
    gram = np.einsum("abi,abi->ab", su, su) * np.einsum("abi,abi->ab", sv, sv) \
        - np.einsum("abi,abi->ab", su, sv) ** 2
    return float(np.einsum("ab,a,b->", np.sqrt(np.maximum(gram, 0.0)), wa, wb))


def _face_tolerance(volume: NurbsVolume, tol: float | None) -> tuple[float, float]:
    box = volume.bounding_box()
    diagonal = max(float(np.linalg.norm(box[1] - box[0])), np.finfo(float).tiny)
    if tol is None:
        return _FACE_RELATIVE_TOL * diagonal, diagonal
    return check_tolerance(tol), diagonal


def collapsed_faces(volume: NurbsVolume, tol: float | None = None) -> dict[str, bool]:
    """Which of the six faces of 004 eq. 3.3 collapse to a curve or a point.

    Parameters
    ----------
    volume : NurbsVolume
    tol : float, optional
        Model units. A face is collapsed when its area (:func:`surface_area`) is at
        most ``tol * L``, ``L`` the diagonal of the control-net box (a face thinner
        than ``tol`` on average). Default ``1e-10 L``.

    Returns
    -------
    dict
        ``{"u0": bool, ..., "w1": bool}``, True for a collapsed face. For
        :func:`.volume_builders.solid_sphere`: ``u0`` (the centre, a point), ``v0`` and
        ``v1`` (the axis segments to the poles).
    """
    tol, diagonal = _face_tolerance(volume, tol)
    return {name: surface_area(face) <= tol * diagonal for name, face in volume.boundary().items()}


def _same_surface(a: NurbsSurface, b: NurbsSurface, tol: float) -> bool:
    """``a(s, t)`` and ``b(s, t)`` within ``tol`` on a grid over the same domain."""
    if a.domain != b.domain:
        return False
    grids = []
    for knots, degree in ((a.knots_u, a.degree_u), (a.knots_v, a.degree_v)):
        nodes, _ = gauss_rule(knots, degree, degree + 2)
        grids.append(np.concatenate([nodes, distinct_knots(knots, degree)[0]]))
    gap = a.evaluate_grid(*grids) - b.evaluate_grid(*grids)
    return float(np.linalg.norm(gap, axis=-1).max()) <= tol


def exterior_faces(volume: NurbsVolume, tol: float | None = None, *,
                   collapsed: dict[str, bool] | None = None) -> dict[str, NurbsSurface]:
    """The non-degenerate exterior boundary of 004 §3.

    The faces of :meth:`~.NurbsVolume.boundary` that are neither collapsed
    (:func:`collapsed_faces`) nor glued to the opposite face of the same direction
    (``P(u_min, v, w) = P(u_max, v, w)`` within ``tol`` on a grid: the seam of a
    direction closed by a full revolution). ``tol`` as in :func:`collapsed_faces`;
    ``collapsed`` its result when already known.

    Returns
    -------
    dict
        Name to surface, in the order of :data:`.volume.FACES`; ``{"u1": sphere}`` for
        the solid sphere and the solid torus of :mod:`.volume_builders`.
    """
    tol_value, _ = _face_tolerance(volume, tol)
    faces = volume.boundary()
    collapsed = collapsed_faces(volume, tol) if collapsed is None else collapsed
    keep = {name: not flag for name, flag in collapsed.items()}
    for axis in "uvw":
        lo, hi = f"{axis}0", f"{axis}1"
        if keep[lo] and keep[hi] and _same_surface(faces[lo], faces[hi], tol_value):
            keep[lo] = keep[hi] = False
    return {name: face for name, face in faces.items() if keep[name]}


# ---------------------------------------------------------------- inversion
@dataclass(frozen=True)
class VolumeInversion:
    """Parameters of points in a solid (:func:`invert_points`).

    Attributes
    ----------
    uvw : (..., 3) float
        Parameters inside the domain: of the point itself when it is inside, else of
        the nearest point of the solid found.
    points : (..., 3) float
        ``x(uvw)``.
    inside : (...) bool
        ``|x(uvw) - p| <= tol`` was reached (the point lies in the solid, its
        boundary within ``tol`` included).
    distance : (...) float
        ``|x(uvw) - p|``: at most ``tol`` for a point inside, the distance to the solid
        for a point outside.
    """

    uvw: NDArray
    points: NDArray
    inside: NDArray
    distance: NDArray


def _seed_grid(volume: NurbsVolume, soft: NDArray) -> tuple[NDArray, NDArray]:
    """Sample points ``(N, 3)`` and their parameters ``(N, 3)`` on a grid that has at
    least ``degree + 1`` steps per span and direction; a sample on a collapsed face
    (``soft[axis, end]``) is moved a quarter step into the domain (there the parameters
    along the face are not determined by the point, and Newton could not leave it)."""
    params = []
    for axis, (knots, degree) in enumerate(zip(volume.knots, volume.degrees)):
        spans = distinct_knots(knots, degree)[0].size - 1
        per_span = max(degree + 1, min(2 * (degree + 1), _MAX_SEED_SAMPLES // spans))
        t = span_samples(knots, degree, np.full(spans, per_span))
        if soft[axis, 0]:
            t[0] += 0.25 * (t[1] - t[0])
        if soft[axis, 1]:
            t[-1] -= 0.25 * (t[-1] - t[-2])
        params.append(t)
    grid = volume.evaluate_grid(*params).reshape(-1, volume.dimension)
    mesh = np.stack(np.meshgrid(*params, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid, mesh


def _newton_steps(jac: NDArray, f: NDArray) -> NDArray:
    """``delta`` with ``J delta = -f`` for ``jac (m, 3, 3)``: Cramer's rule where ``J`` is
    well conditioned, the pseudo-inverse (least-norm step) where it is nearly singular."""
    cof = np.cross(jac[:, :, [1, 2, 0]], jac[:, :, [2, 0, 1]], axis=1)  # columns c1 x c2, ...
    det = np.einsum("mi,mi->m", jac[:, :, 0], cof[:, :, 0])
    scale = np.prod(np.linalg.norm(jac, axis=1), axis=1)
    regular = np.abs(det) > 1e-8 * scale
    step = np.empty_like(f)
    with np.errstate(divide="ignore", invalid="ignore"):
        step[regular] = -np.einsum("mik,mi->mk", cof[regular], f[regular]) / det[regular, None]
    singular = ~regular
    if singular.any():
        step[singular] = -np.einsum("mij,mj->mi", np.linalg.pinv(jac[singular], rcond=1e-13),
                                    f[singular])
    return step


def _limit(x: NDArray, cand: NDArray, lo: NDArray, hi: NDArray, soft: NDArray) -> NDArray:
    """``cand`` clipped to the box; toward a collapsed face (``soft``) a parameter goes at
    most 90 % of the way to the bound instead (never onto it: there the Jacobian is
    singular and a polar-like parameter could not turn round)."""
    out = np.clip(cand, lo, hi)
    below = soft[:, 0] & (cand < lo + 0.1 * (x - lo))
    above = soft[:, 1] & (cand > hi - 0.1 * (hi - x))
    out = np.where(below, lo + 0.1 * (x - lo), out)
    return np.where(above, hi - 0.1 * (hi - x), out)


def _newton(volume: NurbsVolume, targets: NDArray, x: NDArray, lo: NDArray, hi: NDArray,
            soft: NDArray, tol: float, max_iter: int) -> tuple[NDArray, NDArray]:
    """Newton on ``F(x) = P(x) - target`` for all problems at once, steps limited to the
    box ``[lo, hi]`` (:func:`_limit`) and halved until ``|F|`` decreases; the problems
    that reach ``|F| <= tol`` take one more step (which squares the error). A problem
    stops when no halving decreases ``|F|``, or when it sits on a (non-collapsed) face
    of the box and decreased ``|F|`` by less than half (it is heading for the nearest
    boundary point of a point outside, which the faces' projection finds faster).

    Returns
    -------
    x : (m, 3) float
    residual : (m,) float
        ``|F(x)|``.
    """
    x = np.clip(x, lo, hi)
    f = volume.evaluate(x[:, 0], x[:, 1], x[:, 2]) - targets
    fn = np.linalg.norm(f, axis=1)
    done = np.zeros(x.shape[0], dtype=bool)
    reached = fn <= tol
    for _ in range(max_iter):
        idx = np.flatnonzero(~done)
        if idx.size == 0:
            break
        before = fn[idx].copy()
        step = _newton_steps(volume.jacobian(x[idx, 0], x[idx, 1], x[idx, 2]), f[idx])
        scale = np.ones(idx.size)
        accepted = np.zeros(idx.size, dtype=bool)
        pending = np.arange(idx.size)
        for _ in range(_MAX_HALVINGS):
            rows = idx[pending]
            cand = _limit(x[rows], x[rows] + scale[pending, None] * step[pending], lo, hi, soft)
            fc = volume.evaluate(cand[:, 0], cand[:, 1], cand[:, 2]) - targets[rows]
            fcn = np.linalg.norm(fc, axis=1)
            ok = fcn < fn[rows]
            x[rows[ok]], f[rows[ok]], fn[rows[ok]] = cand[ok], fc[ok], fcn[ok]
            accepted[pending[ok]] = True
            pending = pending[~ok]
            if pending.size == 0:
                break
            scale[pending] *= 0.5
        at_face = np.any(((x[idx] == lo) & ~soft[:, 0]) | ((x[idx] == hi) & ~soft[:, 1]), axis=1)
        slow = at_face & (fn[idx] > 0.5 * before) & (fn[idx] > tol)
        # stalled, polished (a step after reaching tol) or sliding along a face: stop
        done[idx[~accepted | reached[idx] | slow]] = True
        reached |= fn <= tol
    return x, fn


def _best(rows: NDArray, residual: NDArray, n: int) -> NDArray:
    """Index of the smallest residual per query."""
    order = np.lexsort((residual, rows))
    first = np.ones(order.size, dtype=bool)
    first[1:] = rows[order[1:]] != rows[order[:-1]]
    best = np.empty(n, dtype=int)
    best[rows[order[first]]] = order[first]
    return best


@dataclass(frozen=True)
class _Setup:
    """What the Newton runs of one :func:`invert_points` call share."""

    volume: NurbsVolume
    tree: cKDTree
    mesh: NDArray
    soft: NDArray
    tol: float
    max_iter: int

    def solve(self, targets: NDArray, n_seeds: int, extra: NDArray | None = None
              ) -> tuple[NDArray, NDArray]:
        """Newton from the ``n_seeds`` nearest samples (and ``extra`` starts), the best
        result per target: parameters ``(n, 3)`` and residuals ``(n,)``."""
        lo, hi = np.array(self.volume.domain[0::2]), np.array(self.volume.domain[1::2])
        k = min(n_seeds, self.mesh.shape[0])
        _, near = self.tree.query(targets, k)
        rows = np.repeat(np.arange(targets.shape[0]), k)
        x0 = self.mesh[np.reshape(near, -1)]
        if extra is not None:
            # starts on a collapsed face moved off it by 1e-3 of the range
            inward = np.where(self.soft[:, 0] & (extra <= lo), lo + 1e-3 * (hi - lo), extra)
            inward = np.where(self.soft[:, 1] & (extra >= hi), hi - 1e-3 * (hi - lo), inward)
            rows = np.concatenate([rows, np.arange(targets.shape[0])])
            x0 = np.concatenate([x0, inward])
        x, residual = _newton(self.volume, targets[rows], x0, lo, hi, self.soft, self.tol,
                              self.max_iter)
        best = _best(rows, residual, targets.shape[0])
        return x[best], residual[best]


def _outward(volume: NurbsVolume, uvw: NDArray, targets: NDArray, axis: NDArray,
             end: NDArray) -> NDArray:
    """True where ``p - x(uvw)`` points out of the solid through the face ``(axis, end)``:
    its component along ``+dP/d(axis)`` (face ``end = 1``) or ``-dP/d(axis)``
    (``end = 0``) is positive (the foot being the nearest point of the face, ``p - x`` is
    normal to it)."""
    jac = volume.jacobian(uvw[:, 0], uvw[:, 1], uvw[:, 2])
    column = jac[np.arange(axis.size), :, axis]
    sign = np.where(end == 1, 1.0, -1.0)
    return sign * np.einsum("mi,mi->m", targets - volume.evaluate(*uvw.T), column) > 0


def invert_points(volume: NurbsVolume, points: ArrayLike, *, tol: float | None = None,
                  max_iter: int = 40, n_seeds: int = 8) -> VolumeInversion:
    """Parameters ``(u, v, w)`` with ``x(u, v, w) = p`` for many points ``p``.

    1. **Seeds**: the solid is sampled on a parameter grid (at least ``degree + 1``
       steps per knot span and direction; samples on collapsed faces moved a quarter
       step inside); each point starts from its ``n_seeds`` nearest samples (a k-d tree).
    2. **Newton** on ``F = x(u, v, w) - p``: the step solves ``J delta = -F`` (Cramer's
       rule; the pseudo-inverse where ``J`` is nearly singular, on the axis or near the
       centre of a revolved solid, which gives the least-norm step), is clipped to the
       domain box (toward a collapsed face it stops 90 % of the way, so polar-like
       parameters can still turn round) and halved until ``|F|`` decreases; a problem
       that reaches ``|F| <= tol`` takes one more step; one that slides along a face of
       the box stops early (step 3 finds its foot). The best seed per point is kept.
    3. A point is **inside** when ``|F| <= tol`` was reached. Otherwise it is
       projected onto every exterior face (:func:`exterior_faces`,
       :func:`.projection.project_to_surface`) and the nearest foot is taken. The
       point is **outside** when ``p - foot`` leaves the solid through that face
       (its component along the face's outward parameter derivative is positive);
       if it points inwards, Newton failed on a point of the solid, which is solved
       again from ``4 n_seeds`` samples and the foot.

    "Outside" means: no parameter of the closed domain maps within ``tol`` of ``p``,
    i.e. the distance from ``p`` to the solid ``x(D)`` exceeds ``tol``; ``uvw`` is then
    the nearest point of the solid (on its exterior boundary) and ``distance`` the
    distance to it. A point of the solid on which every Newton start fails (not seen
    on the solids of the tests) would be reported outside with its nearest boundary
    point. The solid is assumed not to overlap itself (``x`` one-to-one inside the
    domain), so that its boundary is the image of its exterior faces.

    Parameters
    ----------
    volume : NurbsVolume, dimension 3
    points : (..., 3) float
    tol : float, optional
        Model units; default :data:`.projection.DEFAULT_RELATIVE_TOL` times the
        control-net box diagonal.
    max_iter : int
        Newton iterations per seed.
    n_seeds : int
        Nearest samples each point starts from.

    Returns
    -------
    VolumeInversion
        ``uvw (..., 3)``, ``points (..., 3)``, ``inside (...)``, ``distance (...)``.
    """
    _require_space(volume, "invert()")
    p = check_points(points, 3)
    shape = p.shape[:-1]
    targets = p.reshape(-1, 3)
    tol = projection_tolerance(tol, volume)
    max_iter = check_count(max_iter, "max_iter", 1)
    n_seeds = check_count(n_seeds, "n_seeds", 1)
    collapsed = collapsed_faces(volume)
    soft = np.array([[collapsed[f"{a}0"], collapsed[f"{a}1"]] for a in "uvw"])
    grid, mesh = _seed_grid(volume, soft)
    setup = _Setup(volume, cKDTree(grid), mesh, soft, tol, max_iter)
    uvw, distance = setup.solve(targets, n_seeds)
    inside = distance <= tol
    out = np.flatnonzero(~inside)
    if out.size:
        faces = exterior_faces(volume, collapsed=collapsed)
        uvw_out, dist_out, inside_out = _outside(setup, faces, targets[out], uvw[out],
                                                 distance[out], n_seeds)
        uvw[out], distance[out], inside[out] = uvw_out, dist_out, inside_out
    feet = volume.evaluate(uvw[:, 0], uvw[:, 1], uvw[:, 2])
    return VolumeInversion(uvw=uvw.reshape(shape + (3,)), points=feet.reshape(shape + (3,)),
                           inside=inside.reshape(shape), distance=distance.reshape(shape))


def _outside(setup: _Setup, faces: dict[str, NurbsSurface], targets: NDArray, uvw: NDArray,
             distance: NDArray, n_seeds: int) -> tuple[NDArray, NDArray, NDArray]:
    """Step 3 of :func:`invert_points` for the points Newton did not reach."""
    volume, tol = setup.volume, setup.tol
    n = targets.shape[0]
    foot_uvw, foot_distance = np.zeros((n, 3)), np.full(n, np.inf)
    axis, end = np.full(n, -1), np.zeros(n, dtype=int)
    for name, face in faces.items():
        k, e = "uvw".index(name[0]), int(name[1])
        result = project_to_surface(face, targets, tol=tol)
        closer = result.distance < foot_distance
        free = [a for a in range(3) if a != k]
        foot_uvw[np.ix_(closer, free)] = result.uv[closer]
        foot_uvw[closer, k] = volume.domain[2 * k + e]
        foot_distance[closer] = result.distance[closer]
        axis[closer], end[closer] = k, e
    # the nearest point of the solid to a point outside is on its boundary: the foot is
    # at least as near as Newton's last iterate (up to the tolerances)
    use_foot = foot_distance <= distance + tol
    uvw = np.where(use_foot[:, None], foot_uvw, uvw)
    distance = np.where(use_foot, foot_distance, distance)
    inside = distance <= tol
    on_face = np.flatnonzero(use_foot & ~inside)
    suspicious = np.flatnonzero(~use_foot & ~inside)
    if on_face.size:
        leaves = _outward(volume, uvw[on_face], targets[on_face], axis[on_face], end[on_face])
        suspicious = np.concatenate([suspicious, on_face[~leaves]])
    if suspicious.size:
        again, residual = setup.solve(targets[suspicious], 4 * n_seeds, extra=uvw[suspicious])
        found = suspicious[residual <= tol]
        uvw[found] = again[residual <= tol]
        distance[found] = residual[residual <= tol]
        inside[found] = True
    return uvw, distance, inside


def handedness(volume) -> float:
    """Sign of ``det J`` at the centre of the solid's parameter box: +1 for a right-handed
    solid (its :data:`OUTWARD` faces' normals ``S_a x S_b`` point out of it), -1 for a
    left-handed one (they point in).

    Raises
    ------
    InvalidGeometryError
        ``det J`` vanishes or is not finite there: no orientation for the boundary.
    """
    u0, u1, v0, v1, w0, w1 = volume.domain
    jac = volume.jacobian(0.5 * (u0 + u1), 0.5 * (v0 + v1), 0.5 * (w0 + w1))
    det = float(np.linalg.det(np.asarray(jac).reshape(3, 3)))
    if not np.isfinite(det) or det == 0:
        raise InvalidGeometryError("the solid's Jacobian vanishes at the centre of its "
                                   "parameter box: no orientation for its boundary")
    return float(np.sign(det))
