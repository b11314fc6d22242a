"""Exception types of surfprep.

Every error surfprep raises on purpose derives from :class:`SurfprepError`, so a
caller can catch the package's failures without catching programming errors.
The more specific types also derive from the matching built-in (``ValueError``,
``OSError``) so that generic handlers keep working.
"""

from __future__ import annotations

__all__ = [
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


class SurfprepError(Exception):
    """Base class of every error surfprep raises on purpose."""


class InvalidGeometryError(SurfprepError, ValueError):
    """Geometry data that do not describe a valid NURBS object (shapes, knots, NaN...)."""


class DegenerateGeometryError(InvalidGeometryError):
    """A valid but degenerate object the requested operation cannot handle
    (collapsed edge, zero area, zero-length curve)."""


class InvalidToleranceError(SurfprepError, ValueError):
    """A tolerance that is not a finite positive number, or absurd for the model."""


class ConversionError(SurfprepError, TypeError):
    """An object that cannot be converted to or from the NURBS types."""


class InputFileError(SurfprepError, OSError):
    """A CAD file that cannot be read: missing, empty, corrupt or of the wrong type."""


class NoFacesError(InputFileError):
    """A CAD file that was read but holds no face."""


class OutputFileError(SurfprepError, OSError):
    """An output file that cannot be written (including a refusal to overwrite an input)."""


class OpenCascadeError(SurfprepError, RuntimeError):
    """An OpenCascade builder or reader reported failure (``IsDone()`` false, bad status)."""


class TimeLimitExceeded(SurfprepError):
    """A step stopped by the caller's time limit (``surfprep intersect --pair-time-limit``
    raises it into the face pair running too long): the verb records what it stopped,
    says so, and goes on with the rest."""


class InvalidShapeWarning(UserWarning):
    """The input shape already fails OpenCascade's check (``BRepCheck_Analyzer``): the
    result keeps those faults (it adds none) instead of being refused for them."""
