"""surfprep's verbs in CadQuery's and build123d's idiom: their objects in, their objects out.

:mod:`.cadquery` (public as :mod:`surfprep.cadquery`) and :mod:`.build123d` (public
as :mod:`surfprep.build123d`) hold the same six free functions, each taking that
library's objects (and anything the verb itself takes: paths, OpenCascade shapes,
:class:`~surfprep.CadModel`, NURBS surfaces...) and returning that library's objects:

=====================================  ==============================  ===============================
function                               CadQuery returns                build123d returns
=====================================  ==============================  ===============================
``heal(shape, **options)``             ``cq.Shape`` (Solid, Shell...)  ``bd.Shape`` (Solid, Shell...)
``reparametrize(face_or_shape, ...)``  ``cq.Face`` / ``cq.Shape``      ``bd.Face`` / ``bd.Shape``
``intersect(a, b=None, **options)``    ``list[cq.Edge]``               ``list[bd.Edge]``
``split(a, b=None, **options)``        ``cq.Compound``                 ``bd.Compound``
``boolean(a, b, operation, ...)``      ``cq.Shape``                    ``bd.Shape``
``prepare(shape, **options)``          ``cq.Shape``                    ``bd.Shape``
=====================================  ==============================  ===============================

The keyword arguments after the shapes are the verb's own (``tol=``,
``continuity=``...), and one more, the same everywhere: ``report=True`` returns
``(object, result)``, the library object and the verb's full result
(:class:`~surfprep.HealResult`, :class:`~surfprep.IntersectionResult`...,
each with ``.geometry`` and the plain-JSON ``.report()``).

``reparametrize`` of a single face (or a surface) rebuilds that face on its new
surface (:func:`surfprep.reparametrize`); of a shape with several faces it
reparametrizes every B-spline face of it and keeps the others
(:func:`surfprep.plugin.reparam.reparametrize_model`: the faces stay sewn), and
``report=True`` gives a :class:`ModelReparametrizeResult`.

build123d shapes carry a ``label`` and a ``color``: where the result is one
object made from one input object (``heal``, ``reparametrize``, ``prepare``,
``split`` of one operand) it gets the input's.

Nothing is patched on import. :func:`surfprep.cadquery.register` is the explicit
opt-in that adds ``Workplane.heal``, ``.reparametrize``, ``.surface_intersections``
and ``.split_faces`` (names CadQuery does not use: its ``intersect`` and ``split``
are Booleans); :func:`surfprep.cadquery.unregister` takes them away.

This package imports neither cadquery nor build123d; each adapter module
imports its own library.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from OCP.Geom import Geom_Surface
from OCP.TopAbs import TopAbs_COMPOUND, TopAbs_FACE
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Shape

from ...algorithms import NurbsSurface
from ...algorithms.trimmed import TrimmedFace
from ...inputs import ShapeLike
from ..io import as_model
from ..occ.faces import make_face
from ..occ.shapes import compound
from ..reparam import ModelFace, ReparametrizeResult, reparametrize, reparametrize_model

__all__ = ["ModelReparametrizeResult", "as_compound", "reparametrize_any", "reparametrized_shape"]


@dataclass(frozen=True, eq=False)
class ModelReparametrizeResult:
    """What ``reparametrize`` of a shape with several faces made.

    Attributes
    ----------
    shape : TopoDS_Shape
        The shape with its B-spline faces on their new surfaces (also ``.geometry``).
    faces : tuple of ModelFace
        One entry per B-spline face (or per face asked for with ``faces=``): the
        rebuilt face and its figures, or why it kept its surface.
    time_s : float
    """

    shape: TopoDS_Shape
    faces: tuple[ModelFace, ...]
    time_s: float

    @property
    def geometry(self) -> TopoDS_Shape:
        """The new shape, as every verb's result has its geometry."""
        return self.shape

    def report(self) -> dict:
        """Plain-JSON report: per face :meth:`ModelFace.report`, the counts and the time."""
        entries = [f.report() for f in self.faces]
        done = sum(e["status"] == "ok" for e in entries)
        return {"faces": entries, "reparametrized": done, "skipped": len(entries) - done,
                "time_s": self.time_s}


def reparametrize_any(obj: ShapeLike, **options: Any
                      ) -> ReparametrizeResult | ModelReparametrizeResult:
    """Reparametrize a surface, a face, or every B-spline face of a shape.

    Parameters
    ----------
    obj
        A :class:`NurbsSurface`, ``Geom_Surface`` or :class:`TrimmedFace`
        (:func:`surfprep.reparametrize`), or anything :func:`surfprep.plugin.io.as_model`
        takes: one face goes to :func:`surfprep.reparametrize`, a shape with
        several faces to :func:`surfprep.plugin.reparam.reparametrize_model`.
    **options
        Their keyword arguments (``tol``, and for a shape ``faces``, ``progress``).

    Returns
    -------
    ReparametrizeResult or ModelReparametrizeResult

    Examples
    --------
    >>> import numpy as np
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> from surfprep.plugin.adapters import reparametrize_any
    >>> t = np.linspace(0, 1, 9)
    >>> u, v = np.meshgrid(t, t, indexing="ij")
    >>> sheet = interpolate_surface(np.stack([10 * u**3, 10 * v, np.sin(3 * u**3)], axis=-1),
    ...                             params_u=t, params_v=t)
    >>> type(reparametrize_any(sheet)).__name__               # a surface, a face: surfprep.reparametrize
    'ReparametrizeResult'
    """
    if isinstance(obj, (NurbsSurface, TrimmedFace, Geom_Surface)):
        return reparametrize(obj, **options)
    model = as_model(obj)
    if model.shape.ShapeType() == TopAbs_FACE:
        return reparametrize(model.shape, **options)
    start = time.perf_counter()
    shape, entries = reparametrize_model(model, **options)
    return ModelReparametrizeResult(shape, tuple(entries), time.perf_counter() - start)


def reparametrized_shape(result: ReparametrizeResult | ModelReparametrizeResult) -> TopoDS_Shape:
    """The OpenCascade shape of :func:`reparametrize_any`'s result: the new face (a
    surface's result made a face over its whole domain) or the new shape."""
    if isinstance(result, ModelReparametrizeResult):
        return result.shape
    if result.face is not None:
        return result.face.face
    return make_face(result.geometry)


def as_compound(shape: TopoDS_Shape) -> TopoDS_Compound:
    """``shape`` itself when it is a compound, else a compound holding it (a sewn shell
    stays one shell inside)."""
    if shape.ShapeType() == TopAbs_COMPOUND:
        return TopoDS.Compound_s(shape)
    return compound([shape])
