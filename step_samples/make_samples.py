"""Regenerate the synthetic sample ``synthetic_named_faces.step``.

Four faces with names and colours, written by surfprep itself (OCCT's
STEPCAFControl_Writer):

* ``uniform_patch``   bicubic B-spline patch, uniform knots, evenly spaced net
                      (parametrization figure close to 1);
* ``cubic_u_patch``   the unit square with x = u**3 (poles at x = 0, 0, 0, 1):
                      a badly parametrized flat patch, figure 7 in u;
* ``plane``           analytic plane face, 10 x 5;
* ``cylinder``        analytic half cylinder face, radius 2, height 3.

Run from the repository root: ``python step_samples/make_samples.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.gp import gp_Ax3, gp_Cylinder, gp_Dir, gp_Pln, gp_Pnt

from surfprep.algorithms import NurbsSurface
from surfprep.plugin.io import CadModel, write
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.step_iges import _compound

OUTPUT = Path(__file__).resolve().parent / "synthetic_named_faces.step"


def uniform_patch() -> NurbsSurface:
    n = 5
    x, y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 10, n), indexing="ij")
    z = np.sin(x / 4) * np.cos(y / 5)
    knots = [0, 0, 0, 0, 0.5, 1, 1, 1, 1]
    return NurbsSurface(np.stack([x, y, z], axis=-1), knots, knots, 3, 3)


def cubic_u_patch() -> NurbsSurface:
    cp = np.zeros((4, 2, 3))
    cp[:, :, 0] = np.array([0.0, 0.0, 0.0, 10.0])[:, None]
    cp[:, 1, 1] = 10.0
    cp[:, :, 0] += 12.0  # beside the first patch
    return NurbsSurface(cp, [0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 1, 1], 3, 1)


def _done(maker):
    if not maker.IsDone():
        raise RuntimeError("BRepBuilderAPI_MakeFace failed")
    return maker.Face()


def main() -> Path:
    plane = _done(BRepBuilderAPI_MakeFace(
        gp_Pln(gp_Pnt(0, 12, 0), gp_Dir(0, 0, 1)), 0.0, 10.0, 0.0, 5.0))
    cylinder = _done(BRepBuilderAPI_MakeFace(
        gp_Cylinder(gp_Ax3(gp_Pnt(20, 20, 0), gp_Dir(0, 0, 1)), 2.0),
        0.0, np.pi, 0.0, 3.0))
    faces = (make_face(uniform_patch()), make_face(cubic_u_patch()),
             plane, cylinder)
    names = ("uniform_patch", "cubic_u_patch", "plane", "cylinder")
    colors = ((0.8, 0.2, 0.2), (0.2, 0.8, 0.2), (0.2, 0.2, 0.8), (0.9, 0.9, 0.1))
    model = CadModel(_compound(faces), faces, names, colors)
    return write(model, OUTPUT, overwrite=True)


if __name__ == "__main__":
    print(main())
