"""surfprep.heal projects onto the part of a trimmed face that exists (item: trimmed
sources): eight faces cut from one surface that carries a bump over the middle square;
the middle is a hole (no face), so the fill must follow the surroundings, not the bump
of the surface the faces were trimmed from."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.TopoDS import TopoDS_Compound

import surfprep
from surfprep.algorithms.healing import SurfaceSource
from surfprep.algorithms.healing.clipping import face_source
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.surface import NurbsSurface
from surfprep.plugin.occ.faces import face_to_nurbs, make_face
from surfprep.plugin.occ.geom import surface_to_occ

BUMP = 0.05
KNOTS = np.r_[0, 0, 0, np.linspace(0, 1, 13), 1, 1, 1]       # interior knots at k / 12


def _surface(bump: float) -> NurbsSurface:
    """x = u, y = v exactly (control x, y at the Greville abscissae); z a smooth graph,
    plus ``bump`` on the one basis function supported on [1/3, 2/3]^2."""
    greville = np.convolve(KNOTS[1:-1], np.ones(3) / 3, mode="valid")
    gx, gy = np.meshgrid(greville, greville, indexing="ij")
    z = 0.3 * np.sin(1.3 * gx) * np.cos(0.9 * gy) + 0.1 * gx * gy
    z[7, 7] += bump                          # basis 7 spans knots 4/12 .. 8/12
    return NurbsSurface(np.stack([gx, gy, z], axis=-1), KNOTS, KNOTS, 3, 3)


def _grid_faces(surface: NurbsSurface) -> list:
    occ = surface_to_occ(surface)
    faces = []
    for i in range(3):
        for j in range(3):
            if (i, j) != (1, 1):
                mk = BRepBuilderAPI_MakeFace(occ, i / 3, (i + 1) / 3, j / 3, (j + 1) / 3, 1e-7)
                assert mk.IsDone()
                faces.append(mk.Face())
    return faces


def test_face_source_trimmed_or_whole():
    bumped = _surface(BUMP)
    whole = face_source(face_to_nurbs(make_face(bumped)))
    assert isinstance(whole, NurbsSurface)
    part = face_source(face_to_nurbs(_grid_faces(bumped)[0]))        # x, y in [0, 1/3]
    assert isinstance(part, SurfaceSource) and part.mesh is not None
    centroids = part.mesh.triangle_uv().mean(axis=1)
    assert centroids.max(axis=0) == pytest.approx([1 / 3, 1 / 3], abs=0.06)
    assert np.all(centroids <= 1 / 3 + 1e-9)


@pytest.mark.slow
def test_hole_fill_ignores_the_trimmed_away_bump():
    faces = _grid_faces(_surface(BUMP))
    out = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(out)
    for f in faces:
        builder.Add(out, f)
    r = surfprep.heal(out, continuity="G1")
    (k,) = [n for n, p in enumerate(r.patches) if p.origin.kind == "hole"]
    assert r.patches[k].artificial_share > 0.5           # nothing under the hole
    fill = r.network.patches[k]
    s = np.linspace(0.38, 0.62, 25)
    gx, gy = np.meshgrid(s, s, indexing="ij")
    flat = _surface(0.0)                                  # the surface without the bump
    truth = flat.evaluate_grid(s, s).reshape(-1, 3)
    assert np.allclose(truth[:, :2], np.stack([gx, gy], -1).reshape(-1, 2))
    deviation = project_to_surface(fill, truth).distance.max()
    assert deviation < 0.05 * BUMP
    assert r.valid_after
