"""Overlaps beyond strips: two sheets of one surface overlapping at a corner (an
L-shaped union) and a trimmed face lying partly on another. The later face is trimmed
back to the earlier one's boundary: no doubled area, valid, free edges not increased.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.healing.connectivity import Side
from surfprep.algorithms.healing.partial_overlap import overlap_share
from surfprep.algorithms.projection import project_to_curve, project_to_surface
from surfprep.plugin.convert import to_nurbs
from surfprep.plugin.heal import heal
from surfprep.plugin.io import to_shape
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.shapes import face_area


def graph(x, y):
    return 0.2 * np.sin(1.1 * x) * np.cos(0.8 * y) + 0.05 * x * y


@pytest.fixture(scope="module")
def big():
    x = np.linspace(0, 2, 11)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, graph(gx, gy)], -1))


def compound(shapes):
    return to_shape(list(shapes))          # a compound of the faces


def piece(big, u0, u1, v0, v1):
    """The part of ``big`` over [u0, u1] x [v0, v1] (parameters = x, y / 2)."""
    return big.restrict(u0, u1, v0, v1)


def union_area(faces_uv, big) -> float:
    """Area of ``big`` over the union of parameter rectangles (dense quadrature)."""
    t = (np.arange(800) + 0.5) / 800
    gu, gv = np.meshgrid(t, t, indexing="ij")
    d = big.derivatives_grid(t, t, 1)
    cross = np.linalg.norm(np.cross(d[:, :, 1, 0], d[:, :, 0, 1]), axis=-1)
    inside = np.zeros_like(gu, bool)
    for u0, u1, v0, v1 in faces_uv:
        inside |= (gu >= u0) & (gu <= u1) & (gv >= v0) & (gv <= v1)
    return float(np.sum(cross * inside) / 800 ** 2)


def test_corner_overlap_trimmed_back(big):
    ra, rb = (0.0, 0.5, 0.0, 0.5), (0.3, 0.8, 0.3, 0.8)
    a, b = piece(big, *ra), piece(big, *rb)
    shape = compound([make_face(a), make_face(b)])
    union = union_area([ra, rb], big)
    doubled_before = face_area(shape) - union
    assert doubled_before > 0.03                       # the 0.2 x 0.2 (x4) corner twice
    assert overlap_share(to_nurbs(make_face(b)), to_nurbs(make_face(a)), 1e-4) > 0.1
    r = heal(shape)
    rep = json.loads(json.dumps(r.report()))
    (o,) = rep["partial_overlaps"]
    assert (o["kept"], o["trimmed"], o["pieces"]) == (0, 1, 1)
    assert o["area_cut"] == pytest.approx(doubled_before, rel=0.02)
    doubled_after = face_area(r.model.shape) - union
    assert abs(doubled_after) < 0.02 * doubled_before
    assert r.valid_after and r.free_edges_after <= r.free_edges_before
    # the L-shaped remainder meets PART of two sides of the first face's approximant:
    # those sides are fitted to its edges there (partial snap), closed in the geometry
    assert r.tight_free_edges_after <= r.tight_free_edges_before
    (quad,) = r.network.patches
    sides = [quad.isocurve(s.parameter(quad), s.fixed) for s in Side]
    ell = max(to_nurbs(r.model.shape), key=lambda f: f.surface.control_points[..., 0].max())
    met = 0
    for e in ell.loops[0].edges:
        pts = e.curve3d.evaluate(np.linspace(*e.curve3d.domain, 201))
        gap = np.min([project_to_curve(c, pts).distance for c in sides], axis=0)
        if gap.max() < 1e-3:
            met += 1
            assert gap.max() < 1e-6                    # 1.4e-5 without the partial snap
    assert met == 2
    # the output follows the surface densely
    for f in to_nurbs(r.model.shape):
        u0, u1, v0, v1 = f.surface.domain
        pts = f.surface.evaluate_grid(np.linspace(u0, u1, 31), np.linspace(v0, v1, 31))
        assert project_to_surface(big, pts.reshape(-1, 3)).distance.max() < 2e-3


def _with_hole(face, centre, radius):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(centre[0], centre[1], -1), gp_Dir(0, 0, 1)),
                                   radius, 2).Shape()
    cut = BRepAlgoAPI_Cut(face, cyl)
    assert cut.IsDone()
    from surfprep.plugin.occ.shapes import all_faces
    (out,) = all_faces(cut.Shape())
    return out


@pytest.mark.parametrize("trimmed_first", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_partial_overlap_of_a_trimmed_face(big, trimmed_first):
    # B has a round hole (trimmed, two loops) and lies on A over a corner; the
    # untrimmed A is kept whichever comes first, B trimmed back and keeps its hole
    ra, rb = (0.0, 0.5, 0.0, 0.5), (0.3, 0.8, 0.3, 0.8)
    a = make_face(piece(big, *ra))
    b = _with_hole(make_face(piece(big, *rb)), (1.25, 1.25), 0.15)
    faces = [b, a] if trimmed_first else [a, b]
    shape = compound(faces)
    hole = face_area(make_face(piece(big, *rb))) - face_area(b)
    union = union_area([ra, rb], big) - hole
    doubled_before = face_area(shape) - union
    assert doubled_before > 0.03
    r = heal(shape)
    (o,) = r.report()["partial_overlaps"]
    assert (o["kept"], o["trimmed"]) == ((1, 0) if trimmed_first else (0, 1))
    assert abs(face_area(r.model.shape) - union) < 0.02 * doubled_before
    assert r.valid_after and r.free_edges_after <= r.free_edges_before
