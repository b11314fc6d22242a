"""Analytic operands built in OpenCascade and converted exactly (``surface_from_occ``).

Spheres, cylinders, tori and planes as ``Geom_*Surface`` on an axis system, over
the parameter rectangle given, as :class:`~surfprep.algorithms.NurbsSurface`.
"""

from __future__ import annotations

import numpy as np
from OCP.Geom import Geom_CylindricalSurface, Geom_Plane, Geom_SphericalSurface, Geom_ToroidalSurface
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt

from surfprep.algorithms import NurbsSurface
from surfprep.plugin.occ.geom import surface_from_occ

TAU = 2 * np.pi


def axes(origin=(0, 0, 0), normal=(0, 0, 1), xdir=None) -> gp_Ax3:
    if xdir is None:
        return gp_Ax3(gp_Pnt(*origin), gp_Dir(*normal))
    return gp_Ax3(gp_Pnt(*origin), gp_Dir(*normal), gp_Dir(*xdir))


def sphere(r, **kw) -> NurbsSurface:
    return surface_from_occ(Geom_SphericalSurface(axes(**kw), r), (0, TAU, -np.pi / 2, np.pi / 2))


def cylinder(r, half_height, **kw) -> NurbsSurface:
    return surface_from_occ(Geom_CylindricalSurface(axes(**kw), r), (0, TAU, -half_height,
                                                                     half_height))


def torus(big, small, **kw) -> NurbsSurface:
    return surface_from_occ(Geom_ToroidalSurface(axes(**kw), big, small), (0, TAU, 0, TAU))


def plane(half_size, **kw) -> NurbsSurface:
    s = half_size
    return surface_from_occ(Geom_Plane(axes(**kw)), (-s, s, -s, s))
