"""The compiled tracer (curves_kernels.py) takes the same steps as the numpy reference
(curves.trace_curves(compiled=False)): the same samples, feet and end reasons for
the three kinds of curve, on a polynomial and a rational pair, with sides reached
(pinned steps), closed loops and projection losses among them."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import degree_six_pair, several_bumps, sphere_and_plane, torus_and_plane

from surfprep.algorithms.characteristic import CurveKind, EndReason, curves_kernels, trace_curves
from surfprep.algorithms.characteristic.algorithm import choose_field


def test_compiled_kernels_are_available():
    # numba is a declared dependency: without it the numpy fallbacks would run
    # silently and the comparisons below would compare a form with itself
    assert curves_kernels.AVAILABLE


def _pairs():
    a, b = degree_six_pair()
    yield "degree six", a, b
    a, b, _, _ = sphere_and_plane(2e-2)
    yield "sphere", a, b
    a, b = torus_and_plane(1e-3)
    yield "torus", a, b
    from helpers.surfaces import horizontal_plane
    yield "bumps", several_bumps(), horizontal_plane(0.05)


@pytest.mark.parametrize("kind", list(CurveKind))
@pytest.mark.parametrize("name, a, b", list(_pairs()), ids=lambda x: x if isinstance(x, str) else "")
def test_compiled_tracer_matches_the_numpy_reference(name, a, b, kind):
    field = choose_field(a, b, tol=1e-9)
    rng = np.random.default_rng(7)
    span = field.upper - field.lower
    uv0 = field.lower + span * rng.uniform(0.05, 0.95, (12, 2))
    st0 = field.jet(uv0).st
    direction = rng.normal(size=(12, 2))
    h_max = 0.15 * field.diagonal
    kw = {"h0": h_max, "h_max": h_max, "max_steps": 150, "max_turn": 0.6, "ctol": 1e-3 * field.diagonal,
              "relative_ctol": 5e-2}
    if kind is CurveKind.INTERSECTION:
        kw = {"h0": 0.02 * field.diagonal, "h_max": h_max, "max_steps": 150}
    ref = trace_curves(field, kind, uv0, st0, direction, compiled=False, **kw)
    new = trace_curves(field, kind, uv0, st0, direction, compiled=True, **kw)
    assert len(ref) == len(new) == 12
    reasons = set()
    for r, n in zip(ref, new):
        assert n.kind is r.kind and n.end_reason is r.end_reason
        assert n.uv.shape == r.uv.shape
        scale = field.diagonal
        assert np.abs(n.uv - r.uv).max() <= 1e-9 * scale
        assert np.abs(n.st - r.st).max() <= 1e-8 * scale
        assert np.allclose(n.phi, r.phi, rtol=1e-8, atol=1e-12)
        assert np.allclose(n.grad, r.grad, rtol=1e-8, atol=1e-12)
        reasons.add(r.end_reason)
    assert EndReason.DOMAIN in reasons or EndReason.PROJECTION in reasons or \
        EndReason.CLOSED in reasons
