"""A face's surface moved onto its neighbours' edges: gaps closed in the geometry where
the face is not replaced by an approximant (001 §8's joins for faces that keep their
surface).

Two trimmed faces of a real model often meet along edges that lie a little apart
(1e-4 to 1e-1 mm): each face's trimming curve lies on its own surface, the surfaces miss
each other along it. Sewing hides such a gap behind a raised edge tolerance. Closing it
in the geometry means changing a surface so that its trimming curve, mapped through it,
runs along the common edge. :func:`fit_to_edges` does that with the least change: the
displacement is a B-spline on the surface's own knots (refined where the edges need
it), with control-point displacements ``d_ij``

.. math::

    S'(u, v) = S(u, v) + \\sum_{ij} R_{ij}(u, v)\\, d_{ij},

``R_ij`` the surface's (rational) basis functions, so the weights and the
parametrization stay and every pcurve of the face stays valid. The ``d_ij`` are the
minimum-norm least-squares solution of ``S'(uv_k) = target_k`` at the samples of the
edges, so only control points whose support meets an edge move, and since the
``R_ij`` are non-negative and sum to one, ``max |d_ij|`` bounds how far any point of
the surface moved (:attr:`EdgeFit.moved`). Knots are inserted (exactly, [PT] A5.4)
in the spans where a sample misses its target (in both directions: across an edge the
band the displacement decays over narrows; more the more it misses) until every sample
is within ``tol``.

References
----------
001 §8, [PT] A5.4 (see ``surfprep.algorithms`` References).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.sparse import linalg as splinalg

from ...errors import InvalidGeometryError
from ..basis import basis_functions, find_span, greville_abscissae
from ..surface import NurbsSurface

__all__ = ["MAX_FIT_CONTROL", "MAX_FIT_ROUNDS", "MIN_SPAN_SAMPLES", "EdgeFit", "EdgeTarget", "fit_to_edges"]

#: rounds of knot insertion at most
MAX_FIT_ROUNDS = 24
#: control points of the refined surface at most
MAX_FIT_CONTROL = 40_000
#: weight of the displacement's membrane energy against the samples' (relative to the
#: largest diagonal entry of ``A^T A``) ...
_SMOOTH = 1e-6
#: ... and the length, as a share of the parameter domain, over which it decays
_DECAY = 1.0 / 3.0
#: corrections of the regularized solution by what the samples still miss
_SWEEPS = 3
#: a span is split only when it holds at least this many samples
MIN_SPAN_SAMPLES = 12
#: the displacement's degree at least (the surface's degree raised to it when lower)
_MIN_DEGREE = 3
#: a span is split into this many parts at most in one round
_MAX_SPLIT = 8
#: refinement stops when the largest miss has fallen by less than this share ...
_PROGRESS = 0.1
#: ... over this many rounds
_STALLED = 8
#: a sample lies on a side of the domain within this share of its width
_ON_SIDE = 1e-9
#: samples on either side of a miss among which a kink inside a target is looked for
_KINK_WINDOW = 8
#: samples at an end of a target its slope there is measured on
_SLOPE_SAMPLES = 5
#: entries of the per-cell blocks of ``A^T A`` scattered at once (~50 MB with indices)
_GRAM_ENTRIES = 2_000_000


@dataclass(frozen=True)
class EdgeTarget:
    """Where one edge of a face must lie: samples of its pcurve and the points they go to.

    Attributes
    ----------
    uv : (m, 2) float
        Parameters on the surface, in order along the edge (m >= 2).
    points : (m, 3) float
        The targets; the surface's own points along an edge the face holds.
    """

    uv: NDArray
    points: NDArray

    def __post_init__(self) -> None:
        uv = np.asarray(self.uv, dtype=float)
        points = np.asarray(self.points, dtype=float)
        if uv.ndim != 2 or uv.shape[1] != 2 or uv.shape[0] < 2:
            raise InvalidGeometryError(f"uv must have shape (m, 2) with m >= 2, got {uv.shape}")
        if points.shape != (uv.shape[0], 3):
            raise InvalidGeometryError(
                f"points must have shape ({uv.shape[0]}, 3) like uv, got {points.shape}")
        if not (np.all(np.isfinite(uv)) and np.all(np.isfinite(points))):
            raise InvalidGeometryError("edge targets contain NaN or infinite values")
        object.__setattr__(self, "uv", uv)
        object.__setattr__(self, "points", points)


@dataclass(frozen=True)
class EdgeFit:
    """Result of :func:`fit_to_edges`.

    Attributes
    ----------
    surface : NurbsSurface
        The moved surface (the input's degree raised to at least 3, its knots plus those
        inserted; the same weights where none is raised).
    residual : float
        Largest distance between the moved surface and a target, over all samples.
    moved : float
        Largest control-point displacement: no point of the surface moved farther.
    inserted : int
        Knots inserted.
    converged : bool
        ``residual <= tol``.
    """

    surface: NurbsSurface
    residual: float
    moved: float
    inserted: int
    converged: bool


def fit_to_edges(surface: NurbsSurface, targets: Sequence[EdgeTarget], *, tol: float,
                 max_rounds: int = MAX_FIT_ROUNDS, max_control: int = MAX_FIT_CONTROL
                 ) -> EdgeFit:
    """Move ``surface`` the least so that its points at the targets' ``uv`` are the
    targets' points (the module doc).

    Parameters
    ----------
    surface : NurbsSurface (d = 3)
    targets : sequence of EdgeTarget
        One per edge of the face: where it must go, or (points on the surface) where it
        must stay.
    tol : float
        Largest distance left at a sample, model units.
    max_rounds : int
        Rounds of knot insertion at most.
    max_control : int
        Control points of the refined surface at most; refinement stops before it
        would exceed them.

    Returns
    -------
    EdgeFit

    Raises
    ------
    InvalidGeometryError
        No target, a surface that is not 3D, or ``tol`` not a positive number.

    Examples
    --------
    A flat bicubic patch whose edge ``v = 0`` must rise by 1e-3:

    >>> import numpy as np
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    >>> flat = interpolate_surface(np.stack([x, y, 0 * x], axis=-1))
    >>> u = np.linspace(0, 1, 50)
    >>> edge = EdgeTarget(np.stack([u, 0 * u], axis=1), np.stack([u, 0 * u, 0 * u + 1e-3], axis=1))
    >>> fit = fit_to_edges(flat, [edge], tol=1e-9)
    >>> fit.converged, round(fit.moved, 6)
    (True, 0.001)
    >>> 0 < float(fit.surface.evaluate(0.5, 1.0)[2]) < 1e-3   # the far edge moved less
    True
    """
    if surface.dimension != 3:
        raise InvalidGeometryError(f"fit_to_edges needs a 3D surface, got d={surface.dimension}")
    if not targets:
        raise InvalidGeometryError("fit_to_edges needs at least one edge target")
    if not (np.isfinite(tol) and tol > 0):
        raise InvalidGeometryError(f"tol must be a positive length, got {tol!r}")
    uv = np.concatenate([t.uv for t in targets])
    points = np.concatenate([t.points for t in targets])
    u0, u1, v0, v1 = surface.domain
    uv = np.stack([np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)], axis=1)
    inserted = 0
    # a direction of degree below 3 raised to 3 first (exactly): a displacement in a
    # bilinear net only refines towards the targets' kinks at the vertices linearly
    s = surface.elevate_degree(max(0, _MIN_DEGREE - surface.degree_u),
                               max(0, _MIN_DEGREE - surface.degree_v))
    s, inserted = _with_kinks(s, targets, tol)
    # a target along a side of the domain is the side's row of control points: knots
    # along it meet it, splitting the spans across it only adds knot lines (degree 7
    # nets of ICEM files were split down to spans of 1e-8 at their sides)
    splits = np.concatenate([np.repeat([[_on_side(t.uv, k, s.domain) is None for k in (0, 1)]],
                                       t.uv.shape[0], axis=0) for t in targets])
    worst: list[float] = []
    for round_ in range(max_rounds + 1):
        collocation = _collocation(s, uv)
        # S(uv_k) = sum R_ij(uv_k) P_ij: the rows are the (rational) basis at the samples
        offset = points - collocation.matrix @ s.control_points.reshape(-1, 3)
        d = _smooth_solve(collocation, offset, s)
        left = np.linalg.norm(collocation.matrix @ d - offset, axis=1)
        worst.append(float(left.max()))
        if worst[-1] <= tol or round_ == max_rounds:
            break
        if len(worst) > _STALLED and worst[-1] > (1.0 - _PROGRESS) * worst[-1 - _STALLED]:
            break                       # knots no longer help (the misses lie where none can go)
        s, count = _with_inner_kinks(s, targets, uv, left, tol)
        refined = _refined(s, uv, splits, left, tol, max_control)
        if refined is None and not count:
            break
        if refined is not None:
            s, more = refined
            count += more
        inserted += count
    net = s.control_points + d.reshape(s.control_points.shape)
    moved = s.construct_fast(net, s.knots_u, s.knots_v, s.degree_u, s.degree_v, s.weights)
    residual = float(np.max(np.linalg.norm(moved.evaluate(uv[:, 0], uv[:, 1]) - points, axis=1)))
    return EdgeFit(moved, residual, float(np.max(np.linalg.norm(d, axis=1), initial=0.0)),
                   inserted, residual <= tol)


def _with_kinks(s: NurbsSurface, targets: Sequence[EdgeTarget], tol: float
                ) -> tuple[NurbsSurface, int]:
    """``s`` with a knot of full multiplicity (the degree) where two targets along the
    same side of the domain meet and the displacement they ask for turns there, and
    the count inserted.

    Two edges of a face along one side of its domain (a side split by a vertex) lie
    next to two different neighbours, whose edges meet at the vertex at a slight angle:
    the displacement ``target - S`` along that side is continuous there but its slope
    jumps. A smooth spline only follows a kink by knots graded towards it, and being a
    tensor product it pays for each of those knots with a whole knot line (the Mars
    capsule's faces grew from 7 x 4 to 105 x 139 control points); a knot of multiplicity
    ``degree`` at the vertex lets the displacement turn there exactly (the surface is
    then C0 along that iso-line, its tangent planes turning by the neighbours' angle,
    ``|jump| / |S_t|``, a few 1e-4 rad). Inserted only where the jump times the knot
    span holding the vertex exceeds ``tol`` (a smooth spline meets smaller kinks); a
    vertex the displacement only fades to (its slopes level there) gets a simple knot,
    a break point for the fades on either side."""
    ends: dict[tuple[int, int, float], list[tuple[NDArray, float]]] = {}
    domain = s.domain
    for t in targets:
        if t.uv.shape[0] < _SLOPE_SAMPLES:
            continue
        offset = t.points - s.evaluate(t.uv[:, 0], t.uv[:, 1])
        for k in (0, 1):                         # the target runs along parameter k ...
            side = _on_side(t.uv, 1 - k, domain)
            if side is None:                     # ... on a side of the domain
                continue
            for end in (slice(0, _SLOPE_SAMPLES), slice(-1, -_SLOPE_SAMPLES - 1, -1)):
                at = float(t.uv[end, k][0])
                step = t.uv[end, k] - at
                if not abs(step[-1]) > 0.0:
                    continue
                # d offset / d param at the end: a parabola through the end's samples
                slope = np.polyfit(step / step[-1], offset[end], 2)[1] / step[-1]
                moves = float(np.max(np.linalg.norm(offset, axis=1)))
                ends.setdefault((k, side, round(at, 12)), []).append((slope, moves))
    new: tuple[dict[float, int], dict[float, int]] = ({}, {})
    for (k, _, at), meeting in ends.items():
        knots, degree = (s.knots_u, s.degree_u) if k == 0 else (s.knots_v, s.degree_v)
        if len(meeting) < 2 or not knots[degree] < at < knots[-degree - 1]:
            continue
        if max(moves for _, moves in meeting) <= tol:
            continue
        span = int(find_span(knots, degree, np.array([at]))[0])
        jump = max(float(np.linalg.norm(a - b)) for a, _ in meeting for b, _ in meeting)
        # a kink: multiplicity degree; a vertex the targets fade to: a break point
        wanted = degree if jump * (knots[span + 1] - knots[span]) > tol else 1
        new[k][at] = max(new[k].get(at, 0), wanted)
    return _with_knots(s, new)


def _with_inner_kinks(s: NurbsSurface, targets: Sequence[EdgeTarget], uv: NDArray,
                      miss: NDArray, tol: float) -> tuple[NurbsSurface, int]:
    """``s`` with a knot of full multiplicity where a target along a side of the domain
    turns between two of its samples, and the count inserted.

    The common curve of an edge is often a neighbour's boundary, which turns where the
    neighbour's pcurve or surface has a knot of full multiplicity: the displacement has
    a kink inside the edge. Refinement splits the spans around it until they hold too
    few samples (``MIN_SPAN_SAMPLES``), and stalls; so where the samples missing by more
    than ``tol`` lie in such a span along their side, the kink is located between them
    (the crossing of the lines fitted to the offsets on either side, the split of the
    window that fits them best) and a knot put there."""
    domain = s.domain
    start = 0
    new: tuple[dict[float, int], dict[float, int]] = ({}, {})
    held: dict[int, NDArray] = {}       # per direction, distinct parameters per span
    for t in targets:
        m = t.uv.shape[0]
        here = slice(start, start + m)
        start += m
        along = next((k for k in (0, 1) if _on_side(t.uv, 1 - k, domain) is not None), None)
        missed = np.flatnonzero(miss[here] > tol)
        if along is None or missed.size == 0:
            continue
        knots, degree = (s.knots_u, s.degree_u) if along == 0 else (s.knots_v, s.degree_v)
        if along not in held:
            held[along] = _held(knots, degree, uv[:, along])
        span = find_span(knots, degree, uv[here, along])
        for c in np.unique(span[missed]):
            if held[along][c] >= MIN_SPAN_SAMPLES:
                continue                        # refinement can still split it
            in_span = missed[span[missed] == c]
            j = int(in_span[np.argmax(miss[here][in_span])])
            at = _kink(t, s, along, j, tol)
            if at is not None and knots[degree] < at < knots[-degree - 1]:
                new[along][at] = degree
    return _with_knots(s, new)


def _kink(t: EdgeTarget, s: NurbsSurface, k: int, j: int, tol: float) -> float | None:
    """Where the offset ``target - S`` of ``t`` (m samples along parameter ``k``) turns
    near its sample ``j``: of the splits of the ``2 _KINK_WINDOW + 1`` distinct
    parameters around ``j`` into two runs of at least 3, the one whose two fitted lines leave the least,
    and the parameter where those lines come closest; None when the window is too
    short, the lines' slopes differ by less than ``tol`` over it, or they come
    closest outside the gap between the runs' facing samples."""
    # the distinct parameters (samples piled at one resolve nothing), in order
    param, first = np.unique(t.uv[:, k], return_index=True)
    at = int(np.searchsorted(param, t.uv[j, k]))
    lo, hi = max(0, at - _KINK_WINDOW), min(param.size, at + _KINK_WINDOW + 1)
    if hi - lo < 6:
        return None
    chosen = first[lo:hi]
    x0 = param[lo]
    y = t.points[chosen] - s.evaluate(t.uv[chosen, 0], t.uv[chosen, 1])
    scale = float(param[hi - 1] - x0) or 1.0
    x = (param[lo:hi] - x0) / scale
    best = None
    for c in range(3, x.size - 2):
        lines, left = [], 0.0
        for part in (slice(0, c), slice(c, x.size)):
            line = _line(x[part], y[part])
            if line is None:
                break
            lines.append(line[:2])
            left += line[2]
        else:
            if best is None or left < best[0]:
                best = (left, c, lines)
    if best is None:
        return None
    _, c, ((b1, a1), (b2, a2)) = best
    db, da = b1 - b2, a1 - a2
    # a turn the samples resolve: the two lines part by more than tol across the window
    if float(np.linalg.norm(db)) * float(np.ptp(x)) <= tol:
        return None
    cross = -float(da @ db) / float(db @ db)
    lo_x, hi_x = sorted((x[c - 1], x[c]))
    if not lo_x <= cross <= hi_x:       # the lines meet beyond the runs: the turn lies
        return None                     # outside the window
    return float(x0 + scale * cross)


def _with_knots(s: NurbsSurface, new: tuple[dict[float, int], dict[float, int]]
                ) -> tuple[NurbsSurface, int]:
    """``s`` with each knot ``new[k]`` (k = 0 for u) raised to its multiplicity there
    (knots within ``_ON_SIDE`` of the domain width counted as one), and the count
    inserted."""
    inserted = 0
    for k, direction in ((0, "u"), (1, "v")):
        for at, wanted in sorted(new[k].items()):
            knots = s.knots_u if k == 0 else s.knots_v
            have = int(np.count_nonzero(np.abs(knots - at) <= _ON_SIDE * (knots[-1] - knots[0])))
            if have < wanted:
                s = s.insert_knot(at, direction, wanted - have)
                inserted += wanted - have
    return s, inserted


def _held(knots: NDArray, degree: int, t: NDArray) -> NDArray:
    """Per knot span, how many distinct parameters of ``t`` (m,) it holds (samples
    piled at one parameter resolve nothing between them)."""
    return np.bincount(find_span(knots, degree, np.unique(t)), minlength=knots.size)


def _line(x: NDArray, y: NDArray) -> tuple[NDArray, NDArray, float] | None:
    """The least-squares line ``y = a + b x`` through (n,) ``x`` and (n, 3) ``y``:
    ``(b, a, squared residual)``, or None when ``x`` holds one value (samples piled
    at one parameter)."""
    dx = x - x.mean()
    sxx = float(dx @ dx)
    if not sxx > 0.0:
        return None
    b = dx @ (y - y.mean(axis=0)) / sxx
    a = y.mean(axis=0) - b * x.mean()
    return b, a, float(np.sum((a + np.outer(x, b) - y) ** 2))


def _on_side(uv: NDArray, k: int, domain: tuple[float, float, float, float]) -> int | None:
    """0 or 1 when all of ``uv`` (m, 2) lie on the side ``k = lo`` or ``k = hi`` of
    ``domain`` (k = 0 for u), else None."""
    lo, hi = domain[2 * k], domain[2 * k + 1]
    return next((j for j, value in enumerate((lo, hi))
                 if np.all(np.abs(uv[:, k] - value) <= _ON_SIDE * (hi - lo))), None)


@dataclass(frozen=True)
class _Collocation:
    """``A = R_ij(uv_k)``, the (m, n_u n_v) collocation matrix, and what forms ``A^T A``
    fast: each row's (p+1)(q+1) values and the flat net index of its block's first
    control point (a row's nonzeros are the block of control points whose support holds
    its sample)."""

    matrix: sparse.csr_matrix
    values: NDArray          # (m, K) the row's nonzeros, K = (p + 1)(q + 1)
    first: NDArray           # (m,) flat net index of the block's first control point
    block: NDArray           # (K,) flat offsets of the block's control points from it

    def gram(self) -> sparse.csc_matrix:
        """``A^T A``, summed per block of control points: the rows sharing a block
        (samples in one knot cell) give ``V^T V`` in one dense product, scattered once.

        Forming it as a sparse product costs ``m K^2`` scalar steps (15 of 43 s of
        closing gaps on ``overture_asmo_icem.igs``, faces sampled at up to 590 000
        points); samples along edges fall in few cells, so the dense products do the
        same sums at matrix-product speed and the scatter is per cell."""
        m, k = self.values.shape
        n = self.matrix.shape[1]
        order = np.argsort(self.first, kind="stable")
        first = self.first[order]
        values = self.values[order]
        starts = np.flatnonzero(np.r_[True, first[1:] != first[:-1]])
        ends = np.r_[starts[1:], m]
        gram = sparse.csc_matrix((n, n))
        step = max(1, _GRAM_ENTRIES // (k * k))          # cells per batch: bounded memory
        for lo in range(0, starts.size, step):
            cells = slice(lo, lo + step)
            blocks = np.empty((len(starts[cells]), k, k))
            for c, (a, b) in enumerate(zip(starts[cells].tolist(), ends[cells].tolist())):
                part = values[a:b]
                np.matmul(part.T, part, out=blocks[c])
            index = first[starts[cells], None] + self.block              # (cells, K)
            rows = np.broadcast_to(index[:, :, None], blocks.shape).reshape(-1)
            cols = np.broadcast_to(index[:, None, :], blocks.shape).reshape(-1)
            gram = gram + sparse.coo_matrix((blocks.reshape(-1), (rows, cols)),
                                            shape=(n, n)).tocsc()
        return gram


def _collocation(s: NurbsSurface, uv: NDArray) -> _Collocation:
    """``R_ij(uv_k)``: the (m, n_u n_v) sparse matrix, columns the flat net indices."""
    p, q = s.degree_u, s.degree_v
    nu, nv = s.n_control
    span_u, bu = basis_functions(s.knots_u, p, uv[:, 0])
    span_v, bv = basis_functions(s.knots_v, q, uv[:, 1])
    m, k = uv.shape[0], (p + 1) * (q + 1)
    first = (span_u - p) * nv + (span_v - q)                             # (m,)
    block = (np.arange(p + 1)[:, None] * nv + np.arange(q + 1)).reshape(-1)   # ascending
    values = (bu[:, :, None] * bv[:, None, :]).reshape(m, k)
    if s.weights is not None:           # R = N w / sum(N w), the weights gathered flat
        values *= s.weights.reshape(-1)[first[:, None] + block]
        values /= values.sum(axis=1, keepdims=True)
    # a row's columns ascend and are distinct: the CSR arrays directly, no COO pass
    matrix = sparse.csr_matrix((values.reshape(-1), (first[:, None] + block).reshape(-1),
                                np.arange(0, m * k + 1, k)), shape=(m, nu * nv))
    return _Collocation(matrix, values, first, block)


def _membrane(s: NurbsSurface) -> tuple[sparse.csc_matrix, sparse.csc_matrix]:
    """``(E, M)`` for a displacement ``d`` of ``s``'s control points: ``d^T E d`` its
    Dirichlet energy and ``d^T M d`` its squared norm, the control points taken as
    nodal values at their Greville abscissae on the parameter domain scaled to the
    unit square (bilinear elements, masses lumped):

    ``E = M_u (x) K_v + K_u (x) M_v``, ``M = M_u (x) M_v``,

    ``K = D^T diag(1 / h) D`` the 1D stiffness (``D`` first differences, ``h`` the
    abscissae's steps) and ``M`` the diagonal of each abscissa's share of them. On a
    uniform square net ``E`` is the first differences of the net; where knots were
    inserted close together (spans graded towards a kink at a vertex, or towards a
    target crossing the side) a difference across a short step weighs more, so the
    displacement does not turn the surface over within it (KCS hull face 5: rows
    graded to 1e-4 of the domain next to a side moved by 0.03 folded over it). Steps
    are floored at ``1e-9``: coincident abscissae (a knot of multiplicity above the
    degree) move together."""
    stiffness, masses = [], []
    for knots, degree in ((s.knots_u, s.degree_u), (s.knots_v, s.degree_v)):
        g = greville_abscissae(knots, degree)
        g = (g - g[0]) / max(float(g[-1] - g[0]), 1e-300)
        n = g.size
        h = np.maximum(np.diff(g), 1e-9)
        if n < 2:
            stiffness.append(sparse.csr_matrix((n, n)))
            masses.append(sparse.identity(n, format="csr"))
            continue
        diff = sparse.diags([-np.ones(n - 1), np.ones(n - 1)], [0, 1], shape=(n - 1, n), format="csr")
        stiffness.append((diff.T @ sparse.diags(1.0 / h) @ diff).tocsr())
        share = np.zeros(n)
        share[:-1] += 0.5 * h
        share[1:] += 0.5 * h
        masses.append(sparse.diags(share, format="csr"))
    (ku, kv), (mu, mv) = stiffness, masses
    energy = (sparse.kron(mu, kv) + sparse.kron(ku, mv)).tocsc()
    return energy, sparse.kron(mu, mv, format="csc")


def _smooth_solve(collocation: _Collocation, offset: NDArray, s: NurbsSurface) -> NDArray:
    """Control-point displacements ``d`` (n_u n_v, 3) minimizing

    ``|A d - offset|^2 + mu (d^T E d + d^T M d / L^2)``:

    the samples met, the displacement a discrete screened membrane on the parameter
    domain (:func:`_membrane`: ``E`` its Dirichlet energy, ``M`` its masses), which
    decays away from the edges over ``L`` = ``_DECAY`` of the domain and, by the
    maximum principle, nowhere exceeds what the samples ask; ``mu`` is small against
    ``A``'s scale, so the samples dominate, and ``_SWEEPS`` steps of iterated Tikhonov
    regularization (the same factorization applied to what the samples still miss)
    take out the pull the membrane keeps on them."""
    energy, mass = _membrane(s)
    matrix = collocation.matrix
    gram = collocation.gram()
    scale = float(gram.diagonal().max())
    system = _SMOOTH * scale * (energy + mass / _DECAY ** 2) + gram
    solve = splinalg.splu(system.tocsc()).solve
    rhs = np.asarray(matrix.T @ offset)
    d = solve(rhs)
    for _ in range(_SWEEPS):            # iterated Tikhonov: the membrane's pull on the samples undone
        # A^T (offset - A d), on the normal matrix (n x n) rather than the samples' (m x n)
        d += solve(rhs - gram @ d)
    return d


def _refined(s: NurbsSurface, uv: NDArray, splits: NDArray, miss: NDArray, tol: float,
             max_control: int) -> tuple[NurbsSurface, int] | None:
    """``s`` with each span (in u and in v) holding a sample that misses its target by
    more than ``tol`` split into ``k`` equal parts, ``k = (miss / tol)^(1/4)`` (the
    error of a cubic falls as the fourth power of the span) between 2 and
    ``_MAX_SPLIT``, where the span holds at least ``MIN_SPAN_SAMPLES`` distinct samples (finer
    spans than the samples resolve would wave between them); ``splits`` (m, 2) bool
    says in which directions a sample's miss splits its spans. None when nothing can be
    inserted or the net would exceed ``max_control`` control points."""
    new = []
    for knots, degree, k in ((s.knots_u, s.degree_u, 0), (s.knots_v, s.degree_v, 1)):
        missed = (miss > tol) & splits[:, k]
        span = find_span(knots, degree, uv[:, k])
        held = _held(knots, degree, uv[:, k])
        worst = np.zeros(knots.size)
        np.maximum.at(worst, span[missed], miss[missed])
        chosen = np.flatnonzero((worst > tol) & (held >= MIN_SPAN_SAMPLES)
                                & (np.append(np.diff(knots), 0.0) > 0))
        parts = np.clip(np.ceil((worst[chosen] / tol) ** 0.25), 2, _MAX_SPLIT).astype(int)
        values = np.concatenate([knots[c] + (knots[c + 1] - knots[c]) * np.arange(1, n) / n
                                 for c, n in zip(chosen, parts)] or [np.zeros(0)])
        # strictly inside their spans (a span too short to split in floating point is not)
        inside = np.concatenate([np.full(n - 1, c) for c, n in zip(chosen, parts)] or [np.zeros(0, int)])
        keep = (values > knots[inside]) & (values < knots[inside + 1])
        new.append(np.unique(values[keep]))
    nu, nv = s.n_control
    if not (new[0].size or new[1].size) or (nu + new[0].size) * (nv + new[1].size) > max_control:
        return None
    out = s
    if new[0].size:
        out = out.refine(np.sort(new[0]), "u")
    if new[1].size:
        out = out.refine(np.sort(new[1]), "v")
    return out, int(new[0].size + new[1].size)
