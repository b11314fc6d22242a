"""The characteristic curves of the stage are complete to the sample grid (sweep.py):
components of phi_u = 0 that reach no side of r's domain (they start and end where
the projection onto q stops existing, §6.2 case 3) are traced from the cells where
phi_u changes sign and no curve passed."""

from __future__ import annotations

import numpy as np
from char_surfaces import plane_patch, several_bumps

from surfprep.algorithms.characteristic import (
    CurveKind,
    DistanceField,
    Projector,
    critical_points,
)
from surfprep.algorithms.characteristic.algorithm import _grid
from surfprep.algorithms.characteristic.points import edge_roots
from surfprep.algorithms.characteristic.sweep import sweep, unvisited_seeds


def small_plane_field():
    """The bumpy surface against a small plane over its first bump only: along
    every side of the bumpy domain the projection onto the plane does not exist."""
    plane = plane_patch([0.28, 0.3, 0.3], [0, 0, 1.0], half=0.15)
    return DistanceField(several_bumps(), Projector(plane, tol=1e-13))


def test_components_without_side_roots_are_traced_from_the_grid():
    field = small_plane_field()
    grid, shape = _grid(field)
    noise = 1e-9 * np.abs(grid.grad).max()
    uv, _, _ = edge_roots(field, 0, noise=noise)
    assert uv.shape[0] == 0                       # the paper's side roots see nothing
    seeds = unvisited_seeds(field, grid, shape, 0, [], noise)
    assert seeds.shape[0] >= 1
    _, curves = sweep(field, grid, shape, noise, 0.15 * field.diagonal, both=False)
    assert curves and all(c.kind is CurveKind.U_CHARACTERISTIC for c in curves)
    # every sign-change cell of phi_u is now passed by a traced curve
    assert unvisited_seeds(field, grid, shape, 0, curves, noise).shape[0] == 0
    # the traced samples lie on phi_u = 0 (loose corrector: a small share of phi_uu)
    for c in curves:
        jet = field.jet(c.uv, c.st)
        ok = jet.status == 0
        assert np.abs(jet.grad[ok, 0]).max() <= 0.05 * np.abs(jet.hess[ok, 0, 0]).max()
    # a sign change of phi_v along them gives the bump's top (maximum of phi) exactly
    seeds = []
    for c in curves:
        g = c.grad[:, 1]
        for i in np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0):
            w = g[i] / (g[i] - g[i + 1])
            seeds.append(c.uv[i] + w * (c.uv[i + 1] - c.uv[i]))
    crit = critical_points(field, np.array(seeds))
    assert crit is not None
    top = crit.uv[np.argmax(crit.phi)]
    # the bump (0.28, 0.3) sits on Greville points: the top is near, phi_u = phi_v = 0 there
    assert np.linalg.norm(top - [0.28, 0.3]) < 0.02
    assert np.abs(crit.grad).max() <= 1e-10
