"""Compiled inner loops of the adaptive tessellation (000 §29.4.2, 004 §4; numba): per
rectangle, a few hundred multiply-adds that numpy spends in temporaries and per-call overhead.

* :func:`grid_points`: the surface on the test grid of every rectangle, the basis
  functions once per grid line instead of once per point (the sums of
  :func:`..basis_kernels.surface_derivatives_compiled` in the same order, so the
  points are bitwise those of :meth:`NurbsSurface.evaluate`);
* :func:`chord_errors_from_grid`: the chord errors of :func:`.tessellation._chord_errors`
  from the evaluated test grid (both two-triangle interpolants, the u- and v-line
  chords), the same formulas in the same order;
* :func:`restricted_boxes`: the control-net boxes of Bézier patches restricted to
  sub-rectangles (what the blossoms of :func:`.culling._blossom_restrict` give, in u,
  then v, by two de Casteljau splits per line: O(p^2) instead of O(p^3));
* :func:`blossom_spans`: the Bernstein coefficients of single knot spans (the de Boor
  triangles of :func:`.culling._blossom_spans`, the same steps in the same order);
* :func:`any_overlap`: which boxes come near any leaf of a box tree (the pruning test
  of :func:`.tessellation._near`, without listing the pairs);
* :func:`query_pairs`: the overlapping pairs of :func:`.culling.candidate_pairs` with a
  tree on one side only.

``AVAILABLE`` is False without numba; the callers keep their numpy forms then.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..basis_kernels import ders_one
from ..jit import AVAILABLE, jit

__all__ = ["AVAILABLE", "any_overlap", "any_overlap_in_range", "blossom_spans",
           "chord_errors_from_grid", "grid_points", "query_pairs", "restricted_boxes"]


@jit
def _line_basis(knots, p, t, span, out):
    """Basis functions ``out (n, p + 1)`` at ``t (n,)`` with spans ``span (n,)`` (A2.2)."""
    ndu = np.empty((p + 1, p + 1))
    a = np.zeros((2, p + 1))
    left, right = np.empty(p + 1), np.empty(p + 1)
    one = np.zeros((1, p + 1))
    for i in range(t.size):
        one[0, :] = 0.0
        ders_one(knots, p, t[i], span[i], 0, ndu, a, left, right, one)
        for j in range(p + 1):
            out[i, j] = one[0, j]


@jit
def _grid_points(knots_u, knots_v, p, q, net, u, v, su, sv, rational, out):
    k, n = u.shape
    c = net.shape[2]
    bu, bv = np.empty((n, p + 1)), np.empty((n, q + 1))
    tmp = np.empty((q + 1, c))
    hom = np.empty(c)
    for r in range(k):
        _line_basis(knots_u, p, u[r], su[r], bu)
        _line_basis(knots_v, q, v[r], sv[r], bv)
        for i in range(n):
            iu0 = su[r, i] - p
            done = -1                              # the u sums of column block `done`
            for j in range(n):
                iv0 = sv[r, j] - q
                if iv0 != done:
                    done = iv0
                    for jj in range(q + 1):        # the u sums, then the v sums
                        for cc in range(c):
                            s = 0.0
                            for ii in range(p + 1):
                                s += bu[i, ii] * net[iu0 + ii, iv0 + jj, cc]
                            tmp[jj, cc] = s
                for cc in range(c):
                    s = 0.0
                    for jj in range(q + 1):
                        s += bv[j, jj] * tmp[jj, cc]
                    hom[cc] = s
                inv_w = 1.0 / hom[c - 1] if rational else 1.0
                for cc in range(c - 1):
                    out[r, i, j, cc] = hom[cc] * inv_w if rational else hom[cc]


def grid_points(knots_u: NDArray, knots_v: NDArray, p: int, q: int, net: NDArray, u: NDArray,
                v: NDArray, su: NDArray, sv: NDArray, rational: bool) -> NDArray:
    """Surface points ``(k, n, n, d)`` on the tensor grids ``u (k, n) x v (k, n)``.

    ``net (n_u, n_v, d + 1)`` the homogeneous control net, ``su, sv (k, n)`` the knot
    spans of ``u, v``; bitwise equal to the scattered evaluation at every grid point.
    """
    k, n = u.shape
    out = np.empty((k, n, n, net.shape[2] - 1))
    _grid_points(np.ascontiguousarray(knots_u, dtype=np.float64),
                 np.ascontiguousarray(knots_v, dtype=np.float64), int(p), int(q),
                 np.ascontiguousarray(net, dtype=np.float64),
                 np.ascontiguousarray(u, dtype=np.float64),
                 np.ascontiguousarray(v, dtype=np.float64),
                 np.ascontiguousarray(su, dtype=np.int64),
                 np.ascontiguousarray(sv, dtype=np.int64), bool(rational), out)
    return out


@jit
def _dist(g, a, b, c, d, wa, wb, wc, wd):
    s = 0.0
    for e in range(3):
        x = g[e] - (wa * a[e] + wb * b[e] + wc * c[e] + wd * d[e])
        s += x * x
    return np.sqrt(s)


@jit
def _chord_errors(grid, s, err, diag, error_u, error_v):
    k, n = grid.shape[0], grid.shape[1]
    for r in range(k):
        g = grid[r]
        c00, c10, c11, c01 = g[0, 0], g[n - 1, 0], g[n - 1, n - 1], g[0, n - 1]
        e0 = 0.0
        e1 = 0.0
        eu = 0.0
        ev = 0.0
        for i in range(n):
            si = s[i]
            for j in range(n):
                tj = s[j]
                if si >= tj:        # diagonal 0 (c00-c11), weights of [c00, c10, c11, c01]
                    d0 = _dist(g[i, j], c00, c10, c11, c01, 1 - si, si - tj, tj, 0.0)
                else:
                    d0 = _dist(g[i, j], c00, c10, c11, c01, 1 - tj, 0.0, si, tj - si)
                if si + tj <= 1:    # diagonal 1 (c10-c01)
                    d1 = _dist(g[i, j], c00, c10, c11, c01, 1 - si - tj, si, 0.0, tj)
                else:
                    d1 = _dist(g[i, j], c00, c10, c11, c01, 0.0, 1 - tj, si + tj - 1, 1 - si)
                e0 = max(e0, d0)
                e1 = max(e1, d1)
                du = 0.0
                dv = 0.0
                for e in range(3):
                    x = g[i, j, e] - ((1 - si) * g[0, j, e] + si * g[n - 1, j, e])
                    y = g[i, j, e] - ((1 - tj) * g[i, 0, e] + tj * g[i, n - 1, e])
                    du += x * x
                    dv += y * y
                eu = max(eu, np.sqrt(du))
                ev = max(ev, np.sqrt(dv))
        err[r] = min(e0, e1)
        diag[r] = 1 if e1 < e0 else 0
        error_u[r] = eu
        error_v[r] = ev


def chord_errors_from_grid(grid: NDArray, s: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """``(error, diagonal, error_u, error_v)``, four ``(k,)`` arrays, from the test grid
    ``grid (k, n, n, 3)`` at the fractions ``s (n,)`` (see :func:`.tessellation._chord_errors`)."""
    k = grid.shape[0]
    err, eu, ev = np.empty(k), np.empty(k), np.empty(k)
    diag = np.empty(k, dtype=np.int64)
    _chord_errors(np.ascontiguousarray(grid, dtype=float), np.asarray(s, dtype=float), err, diag,
                  eu, ev)
    return err, diag, eu, ev


@jit
def _restrict(line, s0, s1, out, work):
    """Bernstein coefficients ``out (p + 1, c)`` of ``line (p + 1, c)`` on ``[s0, s1]``:
    the left part of the de Casteljau split at ``s1``, then the right part of that
    split at ``s0 / s1`` (two triangles, O(p^2), where the blossoms
    ``f(s0^(p-i), s1^i)`` of :func:`.culling._blossom_restrict` take one per
    coefficient; equal up to rounding)."""
    p, c = line.shape[0] - 1, line.shape[1]
    for a in range(p + 1):
        for e in range(c):
            work[a, e] = line[a, e]
    for e in range(c):
        out[0, e] = work[0, e]
    for r in range(1, p + 1):                     # [0, s1]: the triangle's left edge
        for a in range(p + 1 - r):
            for e in range(c):
                work[a, e] = (1.0 - s1) * work[a, e] + s1 * work[a + 1, e]
        for e in range(c):
            out[r, e] = work[0, e]
    x = s0 / s1 if s1 > 0.0 else 0.0
    for a in range(p + 1):
        for e in range(c):
            work[a, e] = out[a, e]
    for r in range(1, p + 1):                     # [s0 / s1, 1] of it: the right edge
        for a in range(p + 1 - r):
            for e in range(c):
                work[a, e] = (1.0 - x) * work[a, e] + x * work[a + 1, e]
        for e in range(c):
            out[p - r, e] = work[p - r, e]


@jit
def _boxes(coeffs, which, s0, s1, t0, t1, out):
    k = which.size
    p1, q1, c = coeffs.shape[1], coeffs.shape[2], coeffs.shape[3]
    first = np.empty((p1, q1, c))
    line_u, res_u, work_u = np.empty((p1, c)), np.empty((p1, c)), np.empty((p1, c))
    line_v, res_v, work_v = np.empty((q1, c)), np.empty((q1, c)), np.empty((q1, c))
    for r in range(k):
        w_ = which[r]
        for j in range(q1):                    # u first (axis 1 of the patch)
            for i in range(p1):
                for e in range(c):
                    line_u[i, e] = coeffs[w_, i, j, e]
            _restrict(line_u, s0[r], s1[r], res_u, work_u)
            for i in range(p1):
                for e in range(c):
                    first[i, j, e] = res_u[i, e]
        for e in range(3):
            out[r, 0, e] = np.inf
            out[r, 1, e] = -np.inf
        for i in range(p1):                    # then v
            for j in range(q1):
                for e in range(c):
                    line_v[j, e] = first[i, j, e]
            _restrict(line_v, t0[r], t1[r], res_v, work_v)
            for j in range(q1):
                w = res_v[j, c - 1]
                for e in range(3):
                    x = res_v[j, e] / w
                    out[r, 0, e] = min(out[r, 0, e], x)
                    out[r, 1, e] = max(out[r, 1, e], x)


def restricted_boxes(coeffs: NDArray, which: NDArray, s0: NDArray, s1: NDArray, t0: NDArray,
                     t1: NDArray) -> NDArray:
    """Boxes ``(k, 2, 3)`` of the homogeneous Bézier patches ``coeffs[which] (k, p + 1,
    q + 1, 4)`` restricted to local ``[s0, s1] x [t0, t1]`` (all ``(k,)``)."""
    out = np.empty((which.size, 2, 3))
    _boxes(np.ascontiguousarray(coeffs, dtype=float), np.asarray(which, dtype=np.int64),
           *(np.ascontiguousarray(a, dtype=float) for a in (s0, s1, t0, t1)), out)
    return out


@jit
def _any_overlap(lo, hi, left, right, boxes, pad, depth, out):
    stack = np.empty(depth, dtype=np.int64)
    for r in range(boxes.shape[0]):
        top = 0
        stack[0] = 0
        hit = False
        while top >= 0 and not hit:
            node = stack[top]
            top -= 1
            inside = True
            for e in range(3):
                if lo[node, e] > boxes[r, 1, e] + pad or boxes[r, 0, e] > hi[node, e] + pad:
                    inside = False
                    break
            if not inside:
                continue
            if left[node] < 0:
                hit = True
            else:
                stack[top + 1] = right[node]
                stack[top + 2] = left[node]
                top += 2
        out[r] = hit


def any_overlap(tree, boxes: NDArray, pad: float) -> NDArray:
    """Mask ``(k,)``: box ``boxes[i] (2, 3)`` is within ``pad`` of some leaf box of
    ``tree`` (a :class:`.culling.BoxTree`) on every axis; a depth-first search per box
    that stops at the first hit (the pairs of :func:`.culling.tree_pairs` are not needed)."""
    out = np.zeros(boxes.shape[0], dtype=bool)
    if tree.n_nodes and boxes.shape[0]:
        _any_overlap(tree.lo, tree.hi, tree.left, tree.right,
                     np.ascontiguousarray(boxes, dtype=float), float(pad), 2 * tree.depth + 4, out)
    return out


@jit
def _region_any(boxes, first, last, keep, pad, out):
    for r in range(boxes.shape[0]):
        for b in range(first[r], last[r]):
            inside = True
            for e in range(3):
                if boxes[r, 0, e] > keep[b, 1, e] + pad or keep[b, 0, e] > boxes[r, 1, e] + pad:
                    inside = False
                    break
            if inside:
                out[r] = True
                break


def any_overlap_in_range(boxes: NDArray, first: NDArray, last: NDArray, keep: NDArray,
                         pad: float) -> NDArray:
    """Mask ``(k,)``: box ``boxes[i]`` is within ``pad`` of some of ``keep[first[i]:last[i]]``
    on every axis (stops at the first hit)."""
    out = np.zeros(boxes.shape[0], dtype=bool)
    _region_any(np.ascontiguousarray(boxes, dtype=float), np.asarray(first, dtype=np.int64),
                np.asarray(last, dtype=np.int64), np.ascontiguousarray(keep, dtype=float),
                float(pad), out)
    return out


@jit
def _query_pairs(lo, hi, left, right, item, boxes, pad, depth):
    out = np.empty((max(16, 4 * boxes.shape[0]), 2), dtype=np.int64)
    k = 0
    stack = np.empty(depth, dtype=np.int64)
    for r in range(boxes.shape[0]):
        top = 0
        stack[0] = 0
        while top >= 0:
            node = stack[top]
            top -= 1
            inside = True
            for e in range(3):
                if lo[node, e] > boxes[r, 1, e] + pad or boxes[r, 0, e] > hi[node, e] + pad:
                    inside = False
                    break
            if not inside:
                continue
            if left[node] < 0:
                if k == out.shape[0]:
                    grown = np.empty((2 * k, 2), dtype=np.int64)
                    for x in range(k):
                        grown[x, 0] = out[x, 0]
                        grown[x, 1] = out[x, 1]
                    out = grown
                out[k, 0] = r
                out[k, 1] = item[node]
                k += 1
            else:
                stack[top + 1] = right[node]
                stack[top + 2] = left[node]
                top += 2
    return out, k


def query_pairs(tree, boxes: NDArray, pad: float) -> NDArray:
    """All pairs ``(i, item)`` with ``boxes[i]`` within ``pad`` of the leaf box of ``item``
    in ``tree`` on every axis, sorted lexicographically: :func:`.culling.tree_pairs`
    with a tree on one side only (a depth-first search per box)."""
    if tree.n_nodes == 0 or boxes.shape[0] == 0:
        return np.zeros((0, 2), np.int64)
    pairs, k = _query_pairs(tree.lo, tree.hi, tree.left, tree.right, tree.item,
                            np.ascontiguousarray(boxes, dtype=float), float(pad), 2 * tree.depth + 4)
    pairs = pairs[:k]
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


@jit
def blossom_spans(net, knots, p):
    """``(k, p + 1, m, c)``: the Bernstein coefficients along axis 1 of the knot spans
    ``[knots[s, p], knots[s, p + 1]]`` from their poles ``net (k, p + 1, m, c)``;
    coefficient ``i`` is the blossom ``f(a^{p-i}, b^i)`` (:func:`.culling._blossom_spans`).

    The blossom is symmetric, so the ``i`` arguments ``b`` go first: one chain of de
    Boor levels at ``b`` is shared by all coefficients, each finishing with its
    ``p - i`` levels at ``a`` (about p^3 / 6 combinations instead of p^3 / 2; equal
    to the numpy form up to rounding)."""
    k, _, m, c = net.shape
    out = np.empty((k, p + 1, m, c))
    base = np.empty(p + 1)
    work = np.empty(p + 1)
    for s in range(k):
        a, b = knots[s, p], knots[s, p + 1]
        for j in range(m):
            for ch in range(c):
                for t in range(p + 1):
                    base[t] = net[s, t, j, ch]
                for i in range(p + 1):
                    if i > 0:                          # level i of the chain at b
                        for t in range(p + 1 - i):
                            lo, hi = knots[s, i + t], knots[s, p + 1 + t]
                            alpha = (b - lo) / (hi - lo)
                            base[t] = (1.0 - alpha) * base[t] + alpha * base[t + 1]
                    for t in range(p + 1 - i):
                        work[t] = base[t]
                    for r in range(i + 1, p + 1):      # then levels i + 1 .. p at a
                        for t in range(p + 1 - r):
                            lo, hi = knots[s, r + t], knots[s, p + 1 + t]
                            alpha = (a - lo) / (hi - lo)
                            work[t] = (1.0 - alpha) * work[t] + alpha * work[t + 1]
                    out[s, i, j, ch] = work[0]
    return out
