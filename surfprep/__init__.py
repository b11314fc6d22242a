"""surfprep: prepare B-spline CAD geometry for grid generation and downstream CAD.

The exceptions load at once; everything else on first use (PEP 562): the NURBS
and trimmed-face types with numpy and the compiled kernels, the OpenCascade side
(``read``, ``write``, ``to_nurbs``, ``to_occ``, ``make_face``, the verbs
``intersect``, ``reparametrize``, ``heal``... and their result types) with OCP.
So numpy-only code does not pay for importing OCP, and ``surfprep --help`` or a
one-line usage error pays for neither.

Every verb returns a result object with the geometry (``.geometry``) and its
plain-JSON report (``.report()``): :class:`IntersectionResult` (also the list
of curves), :class:`ReparametrizeResult`, :class:`HealResult`; :func:`grid`
returns a :class:`GridResult` (the blocks, ``.write(path)`` for Plot3D, CGNS, VTK).

>>> import surfprep
>>> model = surfprep.read("step_samples/occt_fuselage.stp")     # doctest: +SKIP
>>> face = surfprep.to_nurbs(model.faces[0])                     # doctest: +SKIP
>>> face.surface.evaluate_grid([0.0, 0.5], [0.0, 1.0]).shape     # doctest: +SKIP
(2, 2, 3)

The method of each part comes from one of five papers, cited in the code by
their key (``001 §5``...); :mod:`surfprep.algorithms` decodes the keys.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

from .errors import (
    ConversionError,
    DegenerateGeometryError,
    InputFileError,
    InvalidGeometryError,
    InvalidShapeWarning,
    InvalidToleranceError,
    NoFacesError,
    OpenCascadeError,
    OutputFileError,
    SurfprepError,
    TimeLimitExceeded,
)
from .inputs import ShapeLike

if TYPE_CHECKING:
    from .algorithms import Direction, NurbsCurve, NurbsSurface
    from .algorithms.composition import Composition, compose
    from .algorithms.grid import Spacing, SurfaceGrid, grid_surface
    from .algorithms.parametrization import ParametrizationQuality, parametrization_quality
    from .algorithms.reparam import ReparametrizationResult
    from .algorithms.trimmed import TrimEdge, TrimLoop, TrimmedFace
    from .algorithms.volume import NurbsVolume
    from .plugin.booleans import BooleanResult
    from .plugin.convert import to_nurbs, to_occ
    from .plugin.grid import GridResult, grid
    from .plugin.heal import HealResult, heal
    from .plugin.intersect import FaceIntersection, IntersectionResult, intersect
    from .plugin.io import CadModel, FileFormat, read, write
    from .plugin.occ.edges import make_edge
    from .plugin.occ.faces import make_face
    from .plugin.prepare import PrepareResult, prepare
    from .plugin.reparam import ReparametrizeResult, reparametrize
    from .plugin.split import SplitResult, boolean, boolean_all, split, trim
    from .plugin.volume_boundary import (
        BoundarySolid,
        ComposedVolumes,
        boundary_solid,
        composed_volumes,
    )

__version__ = "0.1.0"

__all__ = [
    # NURBS and trimmed-face types (numpy only)
    "NurbsCurve",
    "NurbsSurface",
    "Direction",
    "TrimmedFace",
    "TrimLoop",
    "TrimEdge",
    "parametrization_quality",
    "ParametrizationQuality",
    "ShapeLike",
    # files and conversion (OpenCascade)
    "read",
    "write",
    "CadModel",
    "FileFormat",
    "to_nurbs",
    "to_occ",
    "make_face",
    "make_edge",
    # the verbs and their results
    "prepare",
    "PrepareResult",
    "intersect",
    "IntersectionResult",
    "FaceIntersection",
    "reparametrize",
    "ReparametrizeResult",
    "ReparametrizationResult",
    "heal",
    "HealResult",
    "grid",
    "GridResult",
    "split",
    "SplitResult",
    "boolean",
    "boolean_all",
    "trim",
    "BooleanResult",
    # trivariate solids (numpy only)
    "NurbsVolume",
    "compose",
    "Composition",
    "boundary_solid",
    "BoundarySolid",
    "composed_volumes",
    "ComposedVolumes",
    # structured grids (numpy only)
    "grid_surface",
    "SurfaceGrid",
    "Spacing",
    # errors
    "SurfprepError",
    "InvalidGeometryError",
    "DegenerateGeometryError",
    "InvalidToleranceError",
    "ConversionError",
    "InputFileError",
    "NoFacesError",
    "OutputFileError",
    "OpenCascadeError",
    "TimeLimitExceeded",
    "InvalidShapeWarning",
]

#: Public names loaded on first use, and the module each comes from.
_LAZY_EXPORTS = {
    "NurbsCurve": "surfprep.algorithms",
    "NurbsSurface": "surfprep.algorithms",
    "Direction": "surfprep.algorithms",
    "TrimmedFace": "surfprep.algorithms.trimmed",
    "TrimLoop": "surfprep.algorithms.trimmed",
    "TrimEdge": "surfprep.algorithms.trimmed",
    "parametrization_quality": "surfprep.algorithms.parametrization",
    "ParametrizationQuality": "surfprep.algorithms.parametrization",
    "ReparametrizationResult": "surfprep.algorithms.reparam",
    "read": "surfprep.plugin.io",
    "write": "surfprep.plugin.io",
    "CadModel": "surfprep.plugin.io",
    "FileFormat": "surfprep.plugin.io",
    "to_nurbs": "surfprep.plugin.convert",
    "to_occ": "surfprep.plugin.convert",
    "make_face": "surfprep.plugin.occ.faces",
    "make_edge": "surfprep.plugin.occ.edges",
    "prepare": "surfprep.plugin.prepare",
    "PrepareResult": "surfprep.plugin.prepare",
    "intersect": "surfprep.plugin.intersect",
    "IntersectionResult": "surfprep.plugin.intersect",
    "FaceIntersection": "surfprep.plugin.intersect",
    "reparametrize": "surfprep.plugin.reparam",
    "ReparametrizeResult": "surfprep.plugin.reparam",
    "heal": "surfprep.plugin.heal",
    "HealResult": "surfprep.plugin.heal",
    "grid": "surfprep.plugin.grid",
    "GridResult": "surfprep.plugin.grid",
    "split": "surfprep.plugin.split",
    "SplitResult": "surfprep.plugin.split",
    "boolean": "surfprep.plugin.split",
    "boolean_all": "surfprep.plugin.split",
    "trim": "surfprep.plugin.split",
    "BooleanResult": "surfprep.plugin.booleans",
    "NurbsVolume": "surfprep.algorithms.volume",
    "compose": "surfprep.algorithms.composition",
    "Composition": "surfprep.algorithms.composition",
    "boundary_solid": "surfprep.plugin.volume_boundary",
    "BoundarySolid": "surfprep.plugin.volume_boundary",
    "composed_volumes": "surfprep.plugin.volume_boundary",
    "ComposedVolumes": "surfprep.plugin.volume_boundary",
    "grid_surface": "surfprep.algorithms.grid",
    "SurfaceGrid": "surfprep.algorithms.grid",
    "Spacing": "surfprep.algorithms.grid",
}


def __getattr__(name: str):
    """Load the lazily served names on first access (PEP 562)."""
    module = _LAZY_EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'surfprep' has no attribute {name!r}")
    return getattr(import_module(module), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY_EXPORTS))
