"""The thin OpenCascade reference wrappers: layout, filled entries, projection."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.Geom import Geom_SphericalSurface
from OCP.gp import gp_Ax3

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.errors import ConversionError
from surfprep.plugin.occ.geom import surface_to_occ
from surfprep.plugin.occ_reference import (
    SURFACE_ENTRIES,
    evaluate_curve,
    evaluate_surface,
    project_point_on_surface,
)


def _surface() -> NurbsSurface:
    rng = np.random.default_rng(3)
    u, v = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 5), indexing="ij")
    cp = np.stack([u, v, 0.2 * rng.standard_normal(u.shape)], axis=-1)
    return NurbsSurface(cp, [0, 0, 0, 0.5, 1, 1, 1], [0, 0, 0, 0, 0.5, 1, 1, 1, 1], 2, 3,
                        rng.uniform(0.5, 2, u.shape))


@pytest.mark.parametrize("order", [0, 1, 2])
def test_surface_layout_and_filled_entries(order):
    surface = _surface()
    u = np.array([[0.1, 0.7], [0.3, 0.95]])
    v = 0.4
    ref = evaluate_surface(surface, u, v, order)
    ours = surface.derivatives(u, v, order)
    assert ref.shape == ours.shape == (2, 2, order + 1, order + 1, 3)
    for k in range(order + 1):
        for l in range(order + 1):
            block = ref[..., k, l, :]
            if (k, l) in SURFACE_ENTRIES[order]:
                np.testing.assert_allclose(block, ours[..., k, l, :], rtol=0, atol=1e-12)
            else:
                assert np.all(np.isnan(block))
    # same result from the OpenCascade object itself
    np.testing.assert_array_equal(evaluate_surface(surface_to_occ(surface), u, v, order), ref)


@pytest.mark.parametrize("dimension", [2, 3])
def test_curve_layout(dimension):
    rng = np.random.default_rng(dimension)
    curve = NurbsCurve(rng.standard_normal((5, dimension)), [0, 0, 0, 0.3, 0.6, 1, 1, 1], 2,
                       rng.uniform(0.5, 2, 5))
    t = np.linspace(0, 1, 6).reshape(2, 3)
    ref = evaluate_curve(curve, t, 2)
    assert ref.shape == (2, 3, 3, dimension)
    np.testing.assert_allclose(ref, curve.derivatives(t, 2), rtol=0, atol=1e-11)


def test_orders_out_of_range():
    with pytest.raises(ValueError):
        evaluate_surface(_surface(), 0.5, 0.5, 3)
    with pytest.raises(ValueError):
        evaluate_curve(NurbsCurve([[0.0, 0.0], [1.0, 1.0]], [0, 0, 1, 1], 1), 0.5, -1)
    with pytest.raises(ConversionError):
        evaluate_surface("nope", 0.5, 0.5)


def test_projection_on_a_sphere():
    sphere = Geom_SphericalSurface(gp_Ax3(), 2.0)
    rng = np.random.default_rng(0)
    directions = rng.standard_normal((3, 4, 3))
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    radii = rng.uniform(0.5, 5.0, (3, 4))
    points = directions * radii[..., None]
    uv, distance = project_point_on_surface(sphere, points)
    assert uv.shape == (3, 4, 2) and distance.shape == (3, 4)
    np.testing.assert_allclose(distance, np.abs(radii - 2.0), atol=1e-9)
    feet = np.array([sphere.Value(*p).Coord() for p in uv.reshape(-1, 2)]).reshape(points.shape)
    np.testing.assert_allclose(feet, 2.0 * directions, atol=1e-7)


def test_projection_on_a_nurbs_surface_recovers_parameters():
    surface = _surface()
    uv_true = np.array([[0.2, 0.3], [0.55, 0.8], [0.9, 0.1]])
    points = surface.evaluate(uv_true[:, 0], uv_true[:, 1])
    uv, distance = project_point_on_surface(surface, points)
    np.testing.assert_allclose(uv, uv_true, atol=1e-7)
    assert np.all(distance < 1e-9)
