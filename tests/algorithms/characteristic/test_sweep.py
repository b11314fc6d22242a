"""The characteristic curves of the stage are complete to the sample grid (sweep.py):
components of phi_u = 0 that reach no side of r's domain (they start and end where
the projection onto q stops existing, §6.2 case 3) are traced from the cells where
phi_u changes sign and no curve passed."""

from __future__ import annotations

import numpy as np
from helpers.surfaces import plane_patch, several_bumps

from surfprep.algorithms.characteristic import (
    CurveKind,
    DistanceField,
    ProjectionStatus,
    Projector,
    critical_points,
)
from surfprep.algorithms.characteristic.grid import field_grid
from surfprep.algorithms.characteristic.points import edge_roots
from surfprep.algorithms.characteristic.sweep import sweep, unvisited_seeds


def small_plane_field():
    """The bumpy surface against a small plane over its first bump only: along
    every side of the bumpy domain the projection onto the plane does not exist."""
    plane = plane_patch([0.28, 0.3, 0.3], [0, 0, 1.0], half=0.15)
    return DistanceField(several_bumps(), Projector(plane, tol=1e-13))


def test_components_without_side_roots_are_traced_from_the_grid():
    field = small_plane_field()
    grid, shape = field_grid(field)
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


def test_a_curve_past_the_cut_locus_is_traced_again_on_the_nearest_branch():
    """Inside a sphere the centre is a focal point: a curve that carries its foot
    through it keeps the far foot (K negative definite, distance 1 + rho). other_branches
    projects the point afresh, finds the near foot (distance 1 - rho) and traces
    the curve on that branch (§6.2 case 2)."""
    from helpers.surfaces import sphere_band

    from surfprep.algorithms.characteristic import TracedCurve
    from surfprep.algorithms.characteristic.curves import EndReason
    from surfprep.algorithms.characteristic.sweep import other_branches

    field = DistanceField(plane_patch([0, 0, 0], [0, 0, 1.0], 0.6),
                          Projector(sphere_band(), tol=1e-13))
    uv = np.array([[0.5, 0.7], [0.5, 0.3]])            # on either side of the centre
    points = field.r.evaluate(uv[:, 0], uv[:, 1])
    near = field.jet(uv[:1])
    # the far foot of the second point: the near foot of its mirror image
    far_foot = field.projector.project(-points[1:]).st
    far = field.jet(uv[1:], far_foot)
    assert far.status[0] == ProjectionStatus.MULTIPLE      # K negative definite
    np.testing.assert_allclose(np.abs(far.phi), 1 + np.linalg.norm(points[1]), atol=1e-9)
    curve = TracedCurve(CurveKind.U_CHARACTERISTIC, uv, np.vstack([near.st, far.st]),
                        np.r_[near.phi, far.phi], np.vstack([near.grad, far.grad]),
                        np.r_[near.projection.det_k, far.projection.det_k],
                        EndReason.START, EndReason.DOMAIN)
    # the centre is an umbilic focal point: both eigenvalues of K flip there, det K
    # keeps its sign, and only the status (K not positive definite) tells the branch
    assert curve.cut_locus_crossings == 0
    flipped = TracedCurve(curve.kind, curve.uv, curve.st, curve.phi, curve.grad,
                          np.array([1.0, -0.5]), EndReason.START, EndReason.DOMAIN)
    assert flipped.cut_locus_crossings == 1             # one eigenvalue through zero
    again = other_branches(field, [curve], 0.15 * field.diagonal)
    assert len(again) == 2                                 # both ways from the fresh foot
    whole = 0
    for c in again:
        rho = np.linalg.norm(field.r.evaluate(c.uv[:, 0], c.uv[:, 1]), axis=1)
        regular = field.jet(c.uv, c.st).status == ProjectionStatus.UNIQUE
        assert regular[0]
        # on the near branch: phi = rho - 1 (the way back through the centre
        # crosses the focal point again: the next round takes it from there)
        np.testing.assert_allclose(c.phi[regular], rho[regular] - 1.0, atol=1e-6)
        whole += bool(regular.all())
    assert whole >= 1
