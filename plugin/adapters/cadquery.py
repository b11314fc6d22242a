"""surfprep's verbs for CadQuery: ``cq.Workplane`` / ``cq.Shape`` in, CadQuery objects out.

The functions take what the verbs take (CadQuery objects, OpenCascade shapes, paths,
:class:`~surfprep.CadModel`...; a ``Workplane`` stands for all the objects on its
stack, combined) and wrap the geometry the verb makes in CadQuery's classes:
``cq.Shape.cast`` (a ``Solid``, ``Shell``, ``Face`` or ``Compound`` as the geometry
is), ``cq.Edge`` for intersection curves. ``report=True`` returns ``(object,
result)`` with the verb's full result. See :mod:`surfprep.plugin.adapters`.

:func:`register` adds four methods to ``cq.Workplane`` (:data:`WORKPLANE_METHODS`),
each returning a new Workplane on its result, as CadQuery's own methods do;
:func:`unregister` removes them. Importing this module changes nothing.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Literal, overload

import cadquery as cq

from ...errors import ConversionError
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

__all__ = ["WORKPLANE_METHODS", "boolean", "heal", "intersect", "prepare", "register",
           "reparametrize", "split", "unregister"]

#: the methods :func:`register` adds to ``cq.Workplane``, none of which CadQuery has
#: (its ``intersect`` and ``split`` are Booleans: these names leave them alone)
WORKPLANE_METHODS = ("heal", "reparametrize", "surface_intersections", "split_faces")


def _checked(*operands: Any) -> None:
    """Refuse a Workplane whose stack holds no shape (surfprep's own message would speak of
    an empty list), naming what it holds instead."""
    for operand in operands:
        if isinstance(operand, cq.Workplane) and not any(isinstance(v, cq.Shape)
                                                         for v in operand.vals()):
            held = ", ".join(type(v).__name__ for v in operand.vals()) or "nothing"
            raise ConversionError(f"the cq.Workplane holds no shape (its stack: {held})")


# ------------------------------------------------------------------ the verbs
@overload
def heal(shape: ShapeLike, *, report: Literal[False] = ..., **options: Any) -> cq.Shape: ...
@overload
def heal(shape: ShapeLike, *, report: Literal[True], **options: Any) -> tuple[cq.Shape, HealResult]: ...

def heal(shape: ShapeLike, *, report: bool = False, **options: Any
         ) -> cq.Shape | tuple[cq.Shape, HealResult]:
    """Heal a shape (:func:`surfprep.heal`) and return it as a CadQuery shape.

    Parameters
    ----------
    shape : cq.Workplane, cq.Shape, TopoDS_Shape, path or CadModel
    report : bool
        Return ``(shape, HealResult)`` instead of the shape alone.
    **options
        :func:`surfprep.heal`'s keyword arguments (``continuity``, ``tol``,
        ``gap_tol``, ``replace``...).

    Returns
    -------
    cq.Shape
        ``cq.Shape.cast`` of the healed shape: a ``cq.Solid`` when it is closed, a
        ``cq.Shell`` or ``cq.Compound`` otherwise.

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> plate, result = surfprep.cadquery.heal(cq.Workplane().box(10, 20, 3), replace="all",
    ...                                        report=True)   # every face an approximant
    >>> type(plate).__name__, round(plate.Volume(), 3), result.report()["valid"]["after"]
    ('Solid', 600.0, True)
    """
    _checked(shape)
    result = _heal_verb(shape, **options)
    out = cq.Shape.cast(result.shape)
    return (out, result) if report else out


@overload
def reparametrize(face_or_shape: ShapeLike, *, report: Literal[False] = ...,
                  **options: Any) -> cq.Shape: ...
@overload
def reparametrize(face_or_shape: ShapeLike, *, report: Literal[True], **options: Any
                  ) -> tuple[cq.Shape, ReparametrizeResult | ModelReparametrizeResult]: ...

def reparametrize(face_or_shape: ShapeLike, *, report: bool = False, **options: Any
                  ) -> cq.Shape | tuple[cq.Shape, ReparametrizeResult | ModelReparametrizeResult]:
    """Chord-length reparametrization of a face, or of every B-spline face of a shape.

    Parameters
    ----------
    face_or_shape : cq.Face, cq.Shape, cq.Workplane, TopoDS_Shape, NurbsSurface...
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
    cq.Face or cq.Shape
        A ``cq.Face`` on the new surface for one face; ``cq.Shape.cast`` of the new
        shape otherwise.

    Raises
    ------
    ConversionError
        A single face that is not on a B-spline surface (a plane, a cylinder...).
    InvalidGeometryError
        A shape without any B-spline face.

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> import numpy as np
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> t = np.linspace(0, 1, 9)
    >>> u, v = np.meshgrid(t, t, indexing="ij")                  # x = 10 u^3: badly parametrized
    >>> sheet = cq.Face(surfprep.make_face(interpolate_surface(
    ...     np.stack([10 * u**3, 10 * v, np.sin(3 * u**3)], axis=-1), params_u=t, params_v=t)))
    >>> even, result = surfprep.cadquery.reparametrize(sheet, report=True)
    >>> type(even).__name__, result.report()["mismatch_after"] < 1.1
    ('Face', True)
    """
    _checked(face_or_shape)
    result = reparametrize_any(face_or_shape, **options)
    out = cq.Shape.cast(reparametrized_shape(result))
    return (out, result) if report else out


@overload
def intersect(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[False] = ...,
              **options: Any) -> list[cq.Edge]: ...
@overload
def intersect(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[True],
              **options: Any) -> tuple[list[cq.Edge], IntersectionResult]: ...

def intersect(a: ShapeLike, b: ShapeLike | None = None, *, report: bool = False,
              **options: Any
              ) -> list[cq.Edge] | tuple[list[cq.Edge], IntersectionResult]:
    """The intersection curves of ``a`` with ``b`` (or among ``a``'s faces) as CadQuery edges.

    Parameters
    ----------
    a, b : cq.Workplane, cq.Shape, TopoDS_Shape, path, NurbsSurface...
        With ``b`` None, the faces of ``a`` are intersected with one another
        (their shared edges left out).
    report : bool
        Return ``(edges, IntersectionResult)``.
    **options
        :func:`surfprep.intersect`'s keyword arguments (``tol``, ``method``...).

    Returns
    -------
    list of cq.Edge
        One edge per curve, with the 3D curve and a pcurve on each face
        (:meth:`surfprep.IntersectionResult.edges`).

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> edges = surfprep.cadquery.intersect(cq.Workplane().sphere(10),
    ...                                     cq.Workplane().box(30, 30, 1).translate((0, 0, 5)))
    >>> type(edges[0]).__name__, sorted(round(e.startPoint().z, 6) for e in edges)   # the slab's faces
    ('Edge', [4.5, 5.5])
    """
    _checked(a, b)
    result = _intersect_verb(a, b, **options)
    out = [cq.Edge(e) for e in result.edges()]
    return (out, result) if report else out


@overload
def split(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[False] = ...,
          **options: Any) -> cq.Compound: ...
@overload
def split(a: ShapeLike, b: ShapeLike | None = None, *, report: Literal[True],
          **options: Any) -> tuple[cq.Compound, SplitResult]: ...

def split(a: ShapeLike, b: ShapeLike | None = None, *, report: bool = False,
          **options: Any
          ) -> cq.Compound | tuple[cq.Compound, SplitResult]:
    """The faces of ``a`` and ``b`` cut along their intersection curves, sharing the cut edges.

    Parameters
    ----------
    a, b : cq.Workplane, cq.Shape, TopoDS_Shape, path...
        With ``b`` None, the faces of ``a`` are cut where they meet one another.
    report : bool
        Return ``(compound, SplitResult)``.
    **options
        :func:`surfprep.split`'s keyword arguments (``tol``, ``method``, ``tool``).

    Returns
    -------
    cq.Compound
        The pieces and the uncut faces in one shell built from their shared edges
        (non-manifold where surfaces cross:
        four pieces share each intersection edge).

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> pieces = surfprep.cadquery.split(cq.Workplane().sphere(10),
    ...                                  cq.Workplane().box(30, 30, 1).translate((0, 0, 5)))
    >>> type(pieces).__name__, len(pieces.Faces())   # 3 zones of the sphere, 6 + 2 faces of the slab
    ('Compound', 11)
    """
    _checked(a, b)
    result = _split_verb(a, b, **options)
    out = cq.Compound(as_compound(result.shape))
    return (out, result) if report else out


@overload
def boolean(a: ShapeLike, b: ShapeLike, operation: str, *, report: Literal[False] = ...,
            **options: Any) -> cq.Shape: ...
@overload
def boolean(a: ShapeLike, b: ShapeLike, operation: str, *, report: Literal[True],
            **options: Any) -> tuple[cq.Shape, BooleanResult]: ...

def boolean(a: ShapeLike, b: ShapeLike, operation: str, *, report: bool = False,
            **options: Any
            ) -> cq.Shape | tuple[cq.Shape, BooleanResult]:
    """Fuse, cut (``a`` minus ``b``) or common of two solids from their split pieces.

    Parameters
    ----------
    a, b : cq.Workplane, cq.Solid, TopoDS_Shape, path...
        Closed solids.
    operation : {"fuse", "cut", "common"}
    report : bool
        Return ``(shape, BooleanResult)``.
    **options
        :func:`surfprep.boolean`'s keyword arguments (``tol``, ``method``).

    Returns
    -------
    cq.Shape
        A ``cq.Solid`` when the kept pieces close (a ``cq.Compound`` of solids, or
        of open shells when they do not).

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> lens = surfprep.cadquery.boolean(cq.Workplane().sphere(5),
    ...                                  cq.Workplane().sphere(5).translate((6, 0, 0)), "common")
    >>> type(lens).__name__, round(lens.Volume(tol=1e-9), 3)   # two caps: 2 pi 2^2 (15 - 2) / 3
    ('Solid', 108.909)
    """
    _checked(a, b)
    result = _boolean_verb(a, b, operation, **options)
    out = cq.Shape.cast(result.shape)
    return (out, result) if report else out


@overload
def prepare(shape: ShapeLike, *, report: Literal[False] = ..., **options: Any) -> cq.Shape: ...
@overload
def prepare(shape: ShapeLike, *, report: Literal[True], **options: Any
            ) -> tuple[cq.Shape, PrepareResult]: ...

def prepare(shape: ShapeLike, *, report: bool = False, **options: Any
            ) -> cq.Shape | tuple[cq.Shape, PrepareResult]:
    """Heal, intersect, reparametrize (and grid) a shape: :func:`surfprep.prepare`.

    Parameters
    ----------
    shape : cq.Workplane, cq.Shape, TopoDS_Shape, path or CadModel
    report : bool
        Return ``(shape, PrepareResult)``: the stages' reports, the curves, the grid.
    **options
        :func:`surfprep.prepare`'s keyword arguments (``heal``, ``reparam``,
        ``intersect``, ``grid``, ``tol``...).

    Returns
    -------
    cq.Shape
        ``cq.Shape.cast`` of the prepared shape.

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> ready, result = surfprep.cadquery.prepare(cq.Workplane().box(10, 20, 3), report=True)
    >>> type(ready).__name__, [s.status for s in result.stages]
    ('Solid', ['done', 'done', 'skipped', 'skipped'])
    """
    _checked(shape)
    result = _prepare_verb(shape, **options)
    out = cq.Shape.cast(result.geometry)
    return (out, result) if report else out


# -------------------------------------------------------- Workplane methods
def _workplane_method(name: str) -> Callable[[Callable[..., cq.Workplane]], Callable[..., cq.Workplane]]:
    """Name the function as the method ``name`` and mark it as surfprep's (what
    :func:`unregister` removes)."""
    def mark(function: Callable[..., cq.Workplane]) -> Callable[..., cq.Workplane]:
        function.__name__ = name
        function.__qualname__ = f"Workplane.{name}"
        function.surfprep_adapter = True  # type: ignore[attr-defined]
        return function
    return mark


@_workplane_method("heal")
def _workplane_heal(self: cq.Workplane, **options: Any) -> cq.Workplane:
    """The objects on the stack healed, combined (:func:`surfprep.cadquery.heal`).

    Parameters
    ----------
    **options
        :func:`surfprep.heal`'s keyword arguments.

    Returns
    -------
    cq.Workplane
        A new Workplane on the healed shape.
    """
    return self.newObject([heal(self, report=False, **options)])


@_workplane_method("reparametrize")
def _workplane_reparametrize(self: cq.Workplane, **options: Any) -> cq.Workplane:
    """The objects on the stack reparametrized (:func:`surfprep.cadquery.reparametrize`):
    one face on its new surface, or a shape's B-spline faces.

    Parameters
    ----------
    **options
        ``tol`` and the other keyword arguments of :func:`surfprep.cadquery.reparametrize`.

    Returns
    -------
    cq.Workplane
        A new Workplane on the new face or shape.
    """
    return self.newObject([reparametrize(self, report=False, **options)])


@_workplane_method("surface_intersections")
def _workplane_surface_intersections(self: cq.Workplane, other: ShapeLike | None = None,
                                     **options: Any) -> cq.Workplane:
    """Intersection curves of the stack's faces with ``other``'s (:func:`surfprep.cadquery.intersect`).

    Not CadQuery's ``Workplane.intersect``, the Boolean common of solids: this one
    returns the curves where the surfaces cross.

    Parameters
    ----------
    other : cq.Workplane, cq.Shape, TopoDS_Shape..., optional
        None: the stack's faces with one another.
    **options
        :func:`surfprep.intersect`'s keyword arguments.

    Returns
    -------
    cq.Workplane
        A new Workplane with one ``cq.Edge`` per curve on its stack.
    """
    return self.newObject(intersect(self, other, report=False, **options))


@_workplane_method("split_faces")
def _workplane_split_faces(self: cq.Workplane, other: ShapeLike | None = None,
                           **options: Any) -> cq.Workplane:
    """The stack's faces (and ``other``'s) cut along their intersection curves
    (:func:`surfprep.cadquery.split`).

    Not CadQuery's ``Workplane.split``, which cuts solids by a plane or a tool.

    Parameters
    ----------
    other : cq.Workplane, cq.Shape, TopoDS_Shape..., optional
        None: the stack's faces cut where they meet one another.
    **options
        :func:`surfprep.split`'s keyword arguments.

    Returns
    -------
    cq.Workplane
        A new Workplane on the ``cq.Compound`` of the pieces (their shared edges one edge each).
    """
    return self.newObject([split(self, other, report=False, **options)])


def _methods() -> tuple[tuple[str, Callable[..., cq.Workplane]], ...]:
    """``(name, function)`` of each Workplane method, in :data:`WORKPLANE_METHODS` order."""
    functions = (_workplane_heal, _workplane_reparametrize, _workplane_surface_intersections,
                 _workplane_split_faces)
    return tuple(zip(WORKPLANE_METHODS, functions))


def _is_ours(value: Any) -> bool:
    return getattr(value, "surfprep_adapter", False) is True


def register() -> tuple[str, ...]:
    """Add :data:`WORKPLANE_METHODS` to ``cq.Workplane`` (an explicit opt-in).

    ``Workplane.heal(**options)``, ``.reparametrize(**options)``,
    ``.surface_intersections(other=None, **options)`` and
    ``.split_faces(other=None, **options)`` run this module's functions on the
    objects of the stack and return a new Workplane on the result
    (``self.newObject``), so they chain like CadQuery's own methods. Calling
    ``register`` again changes nothing.

    Returns
    -------
    tuple of str
        The names of the methods, now on ``cq.Workplane``.

    Raises
    ------
    RuntimeError
        ``cq.Workplane`` already has an attribute of one of those names that is not
        this module's (a newer CadQuery, another plugin): nothing is added.

    Examples
    --------
    >>> import cadquery as cq
    >>> import surfprep.cadquery
    >>> surfprep.cadquery.register()
    ('heal', 'reparametrize', 'surface_intersections', 'split_faces')
    >>> slab = cq.Workplane().box(30, 30, 1).translate((0, 0, 5))
    >>> len(cq.Workplane().sphere(10).surface_intersections(slab).edges().vals())
    2
    >>> surfprep.cadquery.unregister()
    ('heal', 'reparametrize', 'surface_intersections', 'split_faces')
    """
    taken = [name for name in WORKPLANE_METHODS
             if hasattr(cq.Workplane, name)
             and not _is_ours(inspect.getattr_static(cq.Workplane, name))]
    if taken:
        raise RuntimeError(f"cq.Workplane already has {', '.join(taken)} (cadquery "
                           f"{cq.__version__}): surfprep's methods were not added")
    for name, function in _methods():
        if name not in vars(cq.Workplane):
            setattr(cq.Workplane, name, function)
    return WORKPLANE_METHODS


def unregister() -> tuple[str, ...]:
    """Remove the methods :func:`register` added to ``cq.Workplane`` (only those).

    Returns
    -------
    tuple of str
        The names removed (empty when none was there).
    """
    removed = tuple(name for name in WORKPLANE_METHODS if _is_ours(vars(cq.Workplane).get(name)))
    for name in removed:
        delattr(cq.Workplane, name)
    return removed
