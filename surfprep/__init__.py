"""surfprep: prepare B-spline CAD geometry for grid generation and downstream CAD.

The NURBS types and the exceptions load at once; the OpenCascade side
(``read``, ``write``, ``to_nurbs``, ``to_occ``, ``make_face``, ...) loads on
first use, so numpy-only code does not pay for importing OCP.

>>> import surfprep
>>> model = surfprep.read("step_samples/occt_fuselage.stp")     # doctest: +SKIP
>>> face = surfprep.to_nurbs(model.faces[0])                     # doctest: +SKIP
>>> face.surface.evaluate_grid([0.0, 0.5], [0.0, 1.0]).shape     # doctest: +SKIP
(2, 2, 3)
"""

from __future__ import annotations

from importlib import import_module

from .algorithms import Direction, NurbsCurve, NurbsSurface
from .algorithms.trimmed import TrimEdge, TrimLoop, TrimmedFace
from .algorithms.parametrization import ParametrizationQuality, parametrization_quality
from .errors import (ConversionError, DegenerateGeometryError, InputFileError,
                     InvalidGeometryError, InvalidToleranceError, NoFacesError,
                     OpenCascadeError, OutputFileError, SurfprepError)

__version__ = "0.1.0"

#: Public names served by the OpenCascade side, and the module each comes from.
_PLUGIN_EXPORTS = {
    "read": "surfprep.plugin.io",
    "write": "surfprep.plugin.io",
    "CadModel": "surfprep.plugin.io",
    "FileFormat": "surfprep.plugin.io",
    "to_nurbs": "surfprep.plugin.convert",
    "to_occ": "surfprep.plugin.convert",
    "make_face": "surfprep.plugin.occ.faces",
    "make_edge": "surfprep.plugin.occ.edges",
    "intersect": "surfprep.plugin.intersect",
    "reparametrize": "surfprep.plugin.reparam",
    "heal": "surfprep.plugin.heal",
}

__all__ = [
    "NurbsCurve", "NurbsSurface", "Direction", "TrimmedFace", "TrimLoop", "TrimEdge",
    "parametrization_quality", "ParametrizationQuality",
    *_PLUGIN_EXPORTS,
    "SurfprepError", "InvalidGeometryError", "DegenerateGeometryError",
    "InvalidToleranceError", "ConversionError", "InputFileError", "NoFacesError",
    "OutputFileError", "OpenCascadeError",
]


def __getattr__(name: str):
    """Load the OpenCascade-backed names on first access (PEP 562)."""
    module = _PLUGIN_EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'surfprep' has no attribute {name!r}")
    return getattr(import_module(module), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_PLUGIN_EXPORTS))
