"""Regenerate the synthetic samples ``synthetic_named_faces.step`` and ``synthetic_wing.step``.

Four faces with names and colours, written by surfprep itself (OCCT's
STEPCAFControl_Writer):

* ``uniform_patch``   bicubic B-spline patch, uniform knots, evenly spaced net
                      (parametrization figure close to 1);
* ``cubic_u_patch``   the unit square with x = u**3 (poles at x = 0, 0, 0, 1):
                      a badly parametrized flat patch, figure 7 in u;
* ``plane``           analytic plane face, 10 x 5;
* ``cylinder``        analytic half cylinder face, radius 2, height 3.

``synthetic_wing.step`` is a wing-like B-spline solid through the fuselage of
``occt_fuselage.stp`` (a closed cambered spline section lofted from y = -16 m to
16 m; its seam runs along the trailing edge): the pair ``surfprep split`` cuts in the
README and ``benchmarks/split.py`` compares with OpenCascade's General Fuse.

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
from surfprep.plugin.occ.shapes import compound

OUTPUT = Path(__file__).resolve().parent / "synthetic_named_faces.step"
WING = Path(__file__).resolve().parent / "synthetic_wing.step"


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


def wing():
    """The wing of the module doc, as a cadquery Solid (mm; the fuselage declares feet,
    which OpenCascade reads in mm)."""
    import cadquery as cq

    def section(y, chord, x0, z0, n=24):
        th = np.linspace(0, 2 * np.pi, n, endpoint=False)
        x = x0 + chord * 0.5 * (1 + np.cos(th))
        z = z0 + chord * 0.12 * np.sin(th) * (0.6 + 0.4 * np.cos(th))
        return [cq.Vector(a, y, b) for a, b in zip(x, z)]
    wires = [cq.Wire.assembleEdges([cq.Edge.makeSpline(section(y, c, x0, z0), periodic=True)])
             for y, c, x0, z0 in ((-16000, 9000, 24000, -1200), (16000, 7000, 26000, -800))]
    return cq.Solid.makeLoft(wires, True)


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
    model = CadModel(compound(faces), faces, names, colors)
    write(wing().wrapped, WING, overwrite=True)
    return write(model, OUTPUT, overwrite=True)


if __name__ == "__main__":
    print(main(), WING)
