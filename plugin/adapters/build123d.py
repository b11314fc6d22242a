"""surfprep's verbs for build123d: build123d shapes in, build123d shapes out.

The functions take what the verbs take (build123d shapes and parts, OpenCascade
shapes, paths, :class:`~surfprep.CadModel`...) and wrap the geometry the verb
makes in build123d's classes: ``Shape.cast`` (a ``Solid``, ``Shell``, ``Face`` or
``Compound`` as the geometry is), ``Compound`` for split pieces, ``Edge`` for
intersection curves. They work in algebra mode (``part = split(a, b)``) and in
builder mode (``with BuildPart(): insert(heal(part))``). Where the result is one
object made from one build123d object (:func:`heal`, :func:`reparametrize`,
:func:`prepare`, :func:`split` of one operand), it keeps that object's ``label``
and ``color``. ``report=True`` returns ``(object, result)`` with the verb's full
result. See :mod:`surfprep.plugin.adapters`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, TypeVar, overload

import build123d as bd

from ...inputs import ShapeLike
from ..heal import heal as _heal_verb
from ..intersect import intersect as _intersect_verb
from ..prepare import prepare as _prepare_verb
from ..split import boolean as _boolean_verb
from ..split import split as _split_verb
from . import as_compound, reparametrize_any, reparametrized_shape

if TYPE_CHECKING:
    from ..booleans import BooleanResult
    from ..heal import HealResult
    from ..intersect import IntersectionResult
    from ..prepare import PrepareResult
    from ..reparam import ReparametrizeResult
    from ..split import SplitResult
    from . import ModelReparametrizeResult

__all__ = ["boolean", "heal", "intersect", "prepare", "reparametrize", "split"]

_S = TypeVar("_S", bound=bd.Shape)


def _keep_label_and_color(out: _S, source: Any) -> _S:
    """``out`` with the ``label`` and ``color`` of ``source`` when that is one build123d
    shape (a list, a path, a cadquery object carry none)."""
    if isinstance(source, bd.Shape):
        out.label = source.label
        out.color = source.color
    return out


# ------------------------------------------------------------------ the verbs
@overload
def heal(shape: ShapeLike, *, report: Literal[False] = ..., **options: Any) -> bd.Shape: ...
@overload
def heal(shape: ShapeLike, *, report: Literal[True], **options: Any) -> tuple[bd.Shape, HealResult]: ...

def heal(shape: ShapeLike, *, report: bool = False, **options: Any
         ) -> bd.Shape | tuple[bd.Shape, HealResult]:
    """Heal a shape (:func:`surfprep.heal`) and return it as a build123d shape.

    Parameters
    ----------
    shape : build123d Shape (Part, Solid, Shell, Face...), TopoDS_Shape, path or CadModel
    report : bool
        Return ``(shape, HealResult)`` instead of the shape alone.
    **options
        :func:`surfprep.heal`'s keyword arguments (``continuity``, ``tol``,
        ``gap_tol``, ``replace``...).

    Returns
    -------
    build123d.Shape
        ``Shape.cast`` of the healed shape (a ``Solid`` when it is closed, a
        ``Shell`` or ``Compound`` otherwise), with the input's label and colour.

    Examples
    --------
    >>> import build123d as bd
    >>> import surfprep.build123d
    >>> plate = bd.Box(10, 20, 3)
    >>> plate.label = "plate"
    >>> with bd.BuildPart() as healed:                      # every face an approximant
    ...     _ = bd.insert(surfprep.build123d.heal(plate, replace="all"))
    >>> round(healed.part.volume, 3)
    600.0
    >>> surfprep.build123d.heal(plate).label
    'plate'
    """
    result = _heal_verb(shape, **options)
    out = _keep_label_and_color(bd.Shape.cast(result.shape), shape)
    return (out, result) if report else out


@overload
def reparametrize(face_or_shape: ShapeLike, *, report: Literal[False] = ...,
                  **options: Any) -> bd.Shape: ...
@overload
def reparametrize(face_or_shape: ShapeLike, *, report: Literal[True], **options: Any
                  ) -> tuple[bd.Shape, ReparametrizeResult | ModelReparametrizeResult]: ...

def reparametrize(face_or_shape: ShapeLike, *, report: bool = False, **options: Any
                  ) -> bd.Shape | tuple[bd.Shape, ReparametrizeResult | ModelReparametrizeResult]:
    """Chord-length reparametrization of a face, or of every B-spline face of a shape.

    Parameters
    ----------
    face_or_shape : build123d Face, Shape or Part, TopoDS_Shape, NurbsSurface...
        One face (or a surface) is rebuilt on its new surface with the same
        boundary (:func:`surfprep.reparametrize`); a shape with several faces has
        each of its B-spline faces rebuilt, the others kept and all still sewn
        (:func:`surfprep.plugin.reparam.reparametrize_model`).
    report : bool
        Return ``(shape, result)``: a :class:`~surfprep.ReparametrizeResult` for one
        face, a :class:`~surfprep.plugin.adapters.ModelReparametrizeResult` for a shape.
    **options
        ``tol`` and the other keyword arguments of those functions.

    Returns
    -------
    build123d.Face or build123d.Shape
        A ``Face`` on the new surface for one face; ``Shape.cast`` of the new shape
        otherwise; with the input's label and colour.

    Raises
    ------
    ConversionError
        A single face that is not on a B-spline surface (a plane, a cylinder...).
    InvalidGeometryError
        A shape without any B-spline face (a ``Box``).

    Examples
    --------
    >>> import build123d as bd
    >>> import surfprep.build123d
    >>> import numpy as np
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> t = np.linspace(0, 1, 9)
    >>> u, v = np.meshgrid(t, t, indexing="ij")                  # x = 10 u^3: badly parametrized
    >>> sheet = bd.Face(surfprep.make_face(interpolate_surface(
    ...     np.stack([10 * u**3, 10 * v, np.sin(3 * u**3)], axis=-1), params_u=t, params_v=t)))
    >>> sheet.label = "sheet"
    >>> even, result = surfprep.build123d.reparametrize(sheet, report=True)
    >>> type(even).__name__, even.label, result.report()["mismatch_after"] < 1.1
    ('Face', 'sheet', True)
    """
    result = reparametrize_any(face_or_shape, **options)
    out = _keep_label_and_color(bd.Shape.cast(reparametrized_shape(result)), face_or_shape)
    return (out, result) if report else out


@overload
def intersect(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[False] = ...,
              **options: Any) -> list[bd.Edge]: ...
@overload
def intersect(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[True],
              **options: Any) -> tuple[list[bd.Edge], IntersectionResult]: ...

def intersect(a: ShapeLike, b: ShapeLike | None = None, *, report: bool = False,
              **options: Any
              ) -> list[bd.Edge] | tuple[list[bd.Edge], IntersectionResult]:
    """The intersection curves of ``a`` with ``b`` (or among ``a``'s faces) as build123d edges.

    Parameters
    ----------
    a, b : build123d Shape, TopoDS_Shape, path, NurbsSurface...
        With ``b`` None, the faces of ``a`` are intersected with one another
        (their shared edges left out).
    report : bool
        Return ``(edges, IntersectionResult)``.
    **options
        :func:`surfprep.intersect`'s keyword arguments (``tol``, ``method``...).

    Returns
    -------
    list of build123d.Edge
        One edge per curve, with the 3D curve and a pcurve on each face
        (:meth:`surfprep.IntersectionResult.edges`).

    Examples
    --------
    >>> import build123d as bd
    >>> import surfprep.build123d
    >>> slab = bd.Pos(0, 0, 5) * bd.Box(30, 30, 1)
    >>> edges = surfprep.build123d.intersect(bd.Sphere(10), slab)
    >>> type(edges[0]).__name__, sorted(round(e.position_at(0).Z, 6) for e in edges)
    ('Edge', [4.5, 5.5])
    """
    result = _intersect_verb(a, b, **options)
    out = [bd.Edge(e) for e in result.edges()]
    return (out, result) if report else out


@overload
def split(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[False] = ...,
          **options: Any) -> bd.Compound: ...
@overload
def split(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[True],
          **options: Any) -> tuple[bd.Compound, SplitResult]: ...

def split(a: ShapeLike, b: ShapeLike | None = None, *, report: bool = False,
          **options: Any
          ) -> bd.Compound | tuple[bd.Compound, SplitResult]:
    """The faces of ``a`` and ``b`` cut along their intersection curves, sharing the cut edges.

    Parameters
    ----------
    a, b : build123d Shape, TopoDS_Shape, path...
        With ``b`` None, the faces of ``a`` are cut where they meet one another
        (and the compound keeps ``a``'s label and colour).
    report : bool
        Return ``(compound, SplitResult)``.
    **options
        :func:`surfprep.split`'s keyword arguments (``tol``, ``method``, ``tool``).

    Returns
    -------
    build123d.Compound
        The pieces and the uncut faces in one shell built from their shared edges
        (non-manifold where surfaces cross:
        four pieces share each intersection edge).

    Examples
    --------
    >>> import build123d as bd
    >>> import surfprep.build123d
    >>> pieces = surfprep.build123d.split(bd.Sphere(10), bd.Pos(0, 0, 5) * bd.Box(30, 30, 1))
    >>> type(pieces).__name__, len(pieces.faces())   # 3 zones of the sphere, 6 + 2 faces of the slab
    ('Compound', 11)
    """
    result = _split_verb(a, b, **options)
    out = bd.Compound(as_compound(result.shape))
    if b is None:
        out = _keep_label_and_color(out, a)
    return (out, result) if report else out


@overload
def boolean(a: ShapeLike, b: ShapeLike, operation: str, *, report: Literal[False] = ...,
            **options: Any) -> bd.Shape: ...
@overload
def boolean(a: ShapeLike, b: ShapeLike, operation: str, *, report: Literal[True],
            **options: Any) -> tuple[bd.Shape, BooleanResult]: ...

def boolean(a: ShapeLike, b: ShapeLike, operation: str, *, report: bool = False,
            **options: Any
            ) -> bd.Shape | tuple[bd.Shape, BooleanResult]:
    """Fuse, cut (``a`` minus ``b``) or common of two solids from their split pieces.

    Parameters
    ----------
    a, b : build123d Solid or Part, TopoDS_Shape, path...
        Closed solids.
    operation : {"fuse", "cut", "common"}
    report : bool
        Return ``(shape, BooleanResult)``.
    **options
        :func:`surfprep.boolean`'s keyword arguments (``tol``, ``method``).

    Returns
    -------
    build123d.Shape
        A ``Solid`` when the kept pieces close (a ``Compound`` of solids, or of open
        shells when they do not).

    Examples
    --------
    >>> import build123d as bd
    >>> import surfprep.build123d
    >>> lens, result = surfprep.build123d.boolean(bd.Sphere(5), bd.Pos(6, 0, 0) * bd.Sphere(5),
    ...                                           "common", report=True)
    >>> type(lens).__name__, round(result.volume, 3)   # two caps: 2 pi 2^2 (15 - 2) / 3
    ('Solid', 108.909)
    """
    result = _boolean_verb(a, b, operation, **options)
    out = bd.Shape.cast(result.shape)
    return (out, result) if report else out


@overload
def prepare(shape: ShapeLike, *, report: Literal[False] = ..., **options: Any) -> bd.Shape: ...
@overload
def prepare(shape: ShapeLike, *, report: Literal[True], **options: Any
            ) -> tuple[bd.Shape, PrepareResult]: ...

def prepare(shape: ShapeLike, *, report: bool = False, **options: Any
            ) -> bd.Shape | tuple[bd.Shape, PrepareResult]:
    """Heal, intersect, reparametrize (and grid) a shape: :func:`surfprep.prepare`.

    Parameters
    ----------
    shape : build123d Shape or Part, TopoDS_Shape, path or CadModel
    report : bool
        Return ``(shape, PrepareResult)``: the stages' reports, the curves, the grid.
    **options
        :func:`surfprep.prepare`'s keyword arguments (``heal``, ``reparam``,
        ``intersect``, ``grid``, ``tol``...).

    Returns
    -------
    build123d.Shape
        ``Shape.cast`` of the prepared shape, with the input's label and colour.

    Examples
    --------
    >>> import build123d as bd
    >>> import surfprep.build123d
    >>> ready, result = surfprep.build123d.prepare(bd.Box(10, 20, 3), report=True)
    >>> type(ready).__name__, [s.status for s in result.stages]
    ('Solid', ['done', 'done', 'skipped', 'skipped'])
    """
    result = _prepare_verb(shape, **options)
    out = _keep_label_and_color(bd.Shape.cast(result.geometry), shape)
    return (out, result) if report else out
