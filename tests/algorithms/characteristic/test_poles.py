"""Tangential contacts at collapsed sides (poles): a sphere resting on a plane
touches it at the pole of its parametrization, where ``phi`` has no interior
critical point (algorithms/characteristic/poles.py)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import R2, plane_patch

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.characteristic import characteristic_intersection, no_loop_reason
from surfprep.algorithms.characteristic.poles import collapsed_sides, pole_contacts

TOL = 1e-7


def pole_sphere() -> NurbsSurface:
    """Unit sphere, rational biquadratic, with poles at v = 0 (south) and v = 1 (north)."""
    circ = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                     [1, 0]], float)
    wc = np.array([1, R2, 1, R2, 1, R2, 1, R2, 1])
    mer = np.array([[0, -1], [1, -1], [1, 0], [1, 1], [0, 1]], float)    # (rho, z)
    wm = np.array([1, R2, 1, R2, 1])
    cp = np.empty((9, 5, 3))
    cp[..., 0] = circ[:, None, 0] * mer[None, :, 0]
    cp[..., 1] = circ[:, None, 1] * mer[None, :, 0]
    cp[..., 2] = mer[None, :, 1]
    ku = [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1]
    return NurbsSurface(cp, ku, [0, 0, 0, .5, .5, 1, 1, 1], 2, 2, wc[:, None] * wm[None, :])


def test_pole_sphere_is_exact_and_has_two_collapsed_sides():
    s = pole_sphere()
    u, v = np.meshgrid(np.linspace(0, 1, 31), np.linspace(0, 1, 31), indexing="ij")
    np.testing.assert_allclose(np.linalg.norm(s.evaluate(u, v), axis=-1), 1.0, atol=1e-14)
    poles = [s.evaluate(*uv) for uv in collapsed_sides(s)]
    np.testing.assert_allclose(sorted(p[2] for p in poles), [-1.0, 1.0], atol=1e-15)


def test_sphere_resting_on_plane_touches_at_the_pole():
    contacts = pole_contacts(pole_sphere(), plane_patch((0, 0, 1), (0, 0, 1)), tol=TOL)
    assert len(contacts) == 1
    np.testing.assert_allclose(contacts[0].point, [0, 0, 1], atol=1e-12)
    assert contacts[0].distance <= TOL
    assert contacts[0].uv_a[1] == 1.0                      # on the north pole side of a


def test_roles_swapped_give_the_same_contact():
    (c,) = pole_contacts(plane_patch((0, 0, -1), (0, 0, 1)), pole_sphere(), tol=TOL)
    np.testing.assert_allclose(c.point, [0, 0, -1], atol=1e-12)
    assert c.uv_b[1] == 0.0                                # the south pole, on b


@pytest.mark.parametrize("offset", [1e-4, -10 * TOL])
def test_no_contact_when_the_plane_cuts_a_loop_or_misses(offset):
    """Plane 1e-4 below the pole: a small loop, not a point; 10 tol above: nothing."""
    assert pole_contacts(pole_sphere(), plane_patch((0, 0, 1 - offset), (0, 0, 1)), tol=TOL) == []


def test_no_contact_when_a_plane_crosses_the_pole():
    tilted = plane_patch((0, 0, 1), (0, np.sin(0.5), np.cos(0.5)))
    assert pole_contacts(pole_sphere(), tilted, tol=TOL) == []


def test_characteristic_method_reports_the_pole_contact_as_an_isolated_point():
    sphere, plane = pole_sphere(), plane_patch((0, 0, 1), (0, 0, 1))
    assert no_loop_reason(sphere, plane, tol=TOL) is None  # the prefilter must not skip it
    for phi_on in ("a", "b"):
        record = characteristic_intersection(sphere, plane, tol=TOL, phi_on=phi_on)
        assert record.curves == ()
        assert len(record.isolated_points) == 1
        np.testing.assert_allclose(record.isolated_points[0].point, [0, 0, 1], atol=1e-9)
