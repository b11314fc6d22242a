"""The boundary of a trivariate NURBS solid as an OpenCascade solid (issue 24): what a
CAD tool sees of a :class:`~surfprep.algorithms.volume.NurbsVolume`.

The non-degenerate exterior faces (004 §3: collapsed faces such as a ball's centre
and poles left out, the two faces of a closed direction glued, :meth:`exterior_faces`)
become faces, oriented out of the solid (the ``u1``, ``v0`` and ``w1`` faces of a
right-handed solid point out, :meth:`NurbsVolume.boundary`), and are sewn into a shell;
a closed shell becomes a solid (``BRepBuilderAPI_MakeSolid``, ``ShapeFix_Solid``). A
single closed face (the ball's sphere, the torus) is put in a shell of its own:
sewing one face returns the face. Every result is checked by ``BRepCheck_Analyzer``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
from OCP.TopoDS import TopoDS_Shape, TopoDS_Shell

from ..algorithms.volume import NurbsVolume
from ..errors import InvalidGeometryError, OpenCascadeError
from .occ.faces import make_face
from .occ.shapes import count_free_edges, is_valid, sew, shell_or_solid

__all__ = ["BoundarySolid", "boundary_solid"]

#: faces pointing out of a right-handed solid (``det J > 0``)
OUTWARD = {"u1", "v0", "w1"}
#: relative accuracy of OpenCascade's volume integration of the result
VOLUME_EPS = 1e-9


@dataclass(frozen=True, eq=False)
class BoundarySolid:
    """A solid's boundary in OpenCascade.

    Attributes
    ----------
    shape : TopoDS_Shape
        A solid when the faces close, else the shell.
    faces : tuple of str
        The exterior faces used (``"u1"``, ...).
    closed : bool
        Whether ``shape`` is a solid.
    free_edges : int
    volume : float
        OpenCascade's volume of ``shape`` (NaN for a shell).
    """

    shape: TopoDS_Shape
    faces: tuple[str, ...]
    closed: bool
    free_edges: int
    volume: float


def _handedness(volume: NurbsVolume) -> float:
    """Sign of ``det J`` at the centre of the parameter box."""
    u0, u1, v0, v1, w0, w1 = volume.domain
    jac = volume.jacobian(0.5 * (u0 + u1), 0.5 * (v0 + v1), 0.5 * (w0 + w1))
    det = float(np.linalg.det(np.asarray(jac).reshape(3, 3)))
    if not np.isfinite(det) or det == 0:
        raise InvalidGeometryError("the solid's Jacobian vanishes at the centre of its "
                                   "parameter box: no orientation for its boundary")
    return np.sign(det)


def boundary_solid(volume: NurbsVolume, *, tol: float | None = None) -> BoundarySolid:
    """The solid's exterior boundary faces sewn into an OpenCascade solid (module docstring).

    Parameters
    ----------
    volume : NurbsVolume
        In 3D.
    tol : float, optional
        Sewing tolerance, model units; default 1e-7 x the control-net box diagonal
        (faces of one solid share their edges exactly).

    Returns
    -------
    BoundarySolid

    Raises
    ------
    InvalidGeometryError
        Not a 3D solid, or no exterior face.
    OpenCascadeError
        A builder failed or the result is not valid for ``BRepCheck_Analyzer``.
    """
    if not isinstance(volume, NurbsVolume) or volume.dimension != 3:
        raise InvalidGeometryError("boundary_solid needs a NurbsVolume in 3D")
    if tol is None:
        tol = 1e-7 * float(np.linalg.norm(np.ptp(volume.bounding_box(), axis=0)))
    right = _handedness(volume) > 0
    faces = volume.exterior_faces()
    if not faces:
        raise InvalidGeometryError("the solid has no exterior face (every face collapsed)")
    occ_faces = [make_face(s, reversed=(name in OUTWARD) != right) for name, s in faces.items()]
    if len(occ_faces) > 1:
        shape, _ = sew(occ_faces, tol)
    else:
        builder, shell = BRep_Builder(), TopoDS_Shell()
        builder.MakeShell(shell)
        builder.Add(shell, occ_faces[0])
        shape = shell_or_solid(shell)
    if shape.ShapeType() == TopAbs_FACE:
        shape = shell_or_solid(_shell_of(shape))
    if not is_valid(shape):
        raise OpenCascadeError("the boundary of the solid is not valid for BRepCheck_Analyzer")
    closed = shape.ShapeType() == TopAbs_SOLID
    measured = float("nan")
    if closed:
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(shape, props, VOLUME_EPS)
        measured = float(props.Mass())
    return BoundarySolid(shape, tuple(faces), closed, count_free_edges(shape), measured)


def _shell_of(face: TopoDS_Shape) -> TopoDS_Shell:
    builder, shell = BRep_Builder(), TopoDS_Shell()
    builder.MakeShell(shell)
    builder.Add(shell, face)
    return shell
