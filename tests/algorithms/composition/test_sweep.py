"""The kd-tree sweep over triangle boxes and the bidirectional lists of segments (004 §5)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.composition.sweep import link_segments, sweep_pairs, triangle_boxes
from surfprep.algorithms.intersection.culling import candidate_pairs


def soup(rng, n, scale, offset=0.0):
    vertices = rng.uniform(0, 10, (3 * n, 3)) + offset
    triangles = np.arange(3 * n).reshape(n, 3)
    centre = vertices[triangles].mean(axis=1, keepdims=True)
    vertices = (centre + scale * (vertices[triangles] - centre)).reshape(-1, 3)
    return vertices, triangles


@pytest.mark.parametrize("pad", [0.0, 0.05])
def test_the_sweep_finds_exactly_the_overlapping_boxes(pad):
    rng = np.random.default_rng(11)
    v1, t1 = soup(rng, 400, 0.08)
    v2, t2 = soup(rng, 300, 0.12, offset=0.5)
    # vertices shared by several triangles, some of them large (the sweep's reach)
    extra = np.stack([rng.permutation(v1.shape[0])[:3] for _ in range(30)])
    t1 = np.vstack([t1, extra])
    b1, b2 = triangle_boxes(v1, t1), triangle_boxes(v2, t2)
    ours = sweep_pairs(v1, t1, b2, pad=pad)
    reference = candidate_pairs(b1, b2, pad=pad)
    assert ours.shape[0] > 50
    assert {tuple(p) for p in ours.tolist()} == {tuple(p) for p in reference.tolist()}
    # brute force on a subset
    lo1, hi1, lo2, hi2 = b1[:, 0], b1[:, 1], b2[:, 0], b2[:, 1]
    brute = np.all((lo1[:, None] - pad <= hi2[None]) & (lo2[None] - pad <= hi1[:, None]), axis=2)
    assert {tuple(p) for p in np.argwhere(brute).tolist()} == {tuple(p) for p in ours.tolist()}


def test_the_sweep_of_nothing_is_empty():
    v, t = soup(np.random.default_rng(0), 5, 0.1)
    assert sweep_pairs(v, t, np.zeros((0, 2, 3))).shape == (0, 2)
    far = triangle_boxes(v + 100.0, t)
    assert sweep_pairs(v, t, far).shape == (0, 2)


def polygon_segments(n, closed=True):
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    p = np.stack([np.cos(angle), np.sin(angle), np.zeros(n)], axis=1)
    ends = np.roll(p, -1, axis=0) if closed else p[1:]
    return np.stack([p[: ends.shape[0]], ends], axis=1)


def test_shuffled_segments_of_a_loop_merge_into_one_closed_list():
    segments = polygon_segments(40)
    order = np.random.default_rng(5).permutation(40)
    chains = link_segments(segments[order])
    assert len(chains.chains) == 1 and chains.closed.tolist() == [True]
    chain = chains.chains[0]
    assert sorted(chain.tolist()) == list(range(40))
    # the list follows the loop: each segment's end is the next one's start
    linked = segments[order][chain]
    np.testing.assert_array_equal(linked[:-1, 1], linked[1:, 0])
    np.testing.assert_array_equal(chains.next[chain[:-1]], chain[1:])
    np.testing.assert_array_equal(chains.prev[chain[1:]], chain[:-1])


def test_open_chains_and_a_branch_break_where_they_should():
    arc = polygon_segments(20, closed=False)                # open: 19 segments
    other = arc[:5] + np.array([0.0, 0.0, 3.0])             # a second, separate chain
    spur = np.array([[arc[9, 1], arc[9, 1] + [0.0, 0.0, 1.0]]])   # a second segment from one point
    chains = link_segments(np.concatenate([arc, other, spur])[::-1])
    assert not chains.closed.any()
    sizes = sorted(len(c) for c in chains.chains)
    # the arc breaks at the branch point: 10 + 9 segments, the spur alone, the other chain
    assert sizes == [1, 5, 9, 10]
    assert (chains.next == -1).sum() == 4
