"""What the verbs accept: :data:`ShapeLike`, anything that holds faces.

``surfprep.read``-able paths, :class:`~surfprep.CadModel`, OpenCascade shapes and
surfaces, surfprep's own NURBS types, cadquery and build123d objects, and lists of
these. Type checkers see the union; at run time the alias is :data:`typing.Any`,
so that importing surfprep loads neither OpenCascade nor cadquery nor build123d.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, TypeAlias, Union

__all__ = ["ShapeLike"]

if TYPE_CHECKING:
    import build123d
    import cadquery
    from OCP.Geom import Geom_Surface
    from OCP.TopoDS import TopoDS_Shape

    from .algorithms import NurbsSurface
    from .algorithms.trimmed import TrimmedFace
    from .plugin.io import CadModel

    ShapeLike: TypeAlias = Union[
        str, os.PathLike, CadModel, TopoDS_Shape, Geom_Surface, NurbsSurface, TrimmedFace,
        cadquery.Shape, cadquery.Workplane, build123d.Shape, Sequence["ShapeLike"],
    ]
else:
    #: anything that holds faces (the module docstring); ``Any`` at run time
    ShapeLike = Any
