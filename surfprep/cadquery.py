"""surfprep for CadQuery: ``cq.Workplane`` and ``cq.Shape`` in, CadQuery objects out.

The verbs of :mod:`surfprep` as free functions on CadQuery objects (a Workplane
stands for the objects on its stack, combined; OpenCascade shapes, paths and
everything else the verbs take work too), returning CadQuery objects:
:func:`heal`, :func:`reparametrize`, :func:`prepare` and :func:`boolean` a
``cq.Shape`` (``Solid``, ``Shell``, ``Face``, ``Compound`` as the result is),
:func:`intersect` a list of ``cq.Edge``, :func:`split` a ``cq.Compound``. The
keyword arguments after the shapes are the verb's own; ``report=True`` returns
``(object, result)`` with the verb's full result (``.report()``, the figures).

Importing this module patches nothing. :func:`register` adds the methods
``Workplane.heal``, ``.reparametrize``, ``.surface_intersections`` and
``.split_faces`` (:data:`WORKPLANE_METHODS`: CadQuery's own ``intersect`` and
``split`` are Booleans and stay as they are); :func:`unregister` removes them.

Example
-------
>>> import cadquery as cq
>>> import surfprep.cadquery
>>> ball, slab = cq.Workplane().sphere(10), cq.Workplane().box(30, 30, 1).translate((0, 0, 5))
>>> edges = surfprep.cadquery.intersect(ball, slab)             # [cq.Edge]: two circles
>>> sorted(round(e.startPoint().z, 6) for e in edges)
[4.5, 5.5]
>>> pieces, result = surfprep.cadquery.split(ball, slab, report=True)   # cq.Compound, SplitResult
>>> len(pieces.Faces()), result.report()["pieces"]
(11, 7)
"""

from __future__ import annotations

from .plugin.adapters.cadquery import (
    WORKPLANE_METHODS,
    boolean,
    heal,
    intersect,
    prepare,
    register,
    reparametrize,
    split,
    unregister,
)

__all__ = ["WORKPLANE_METHODS", "boolean", "heal", "intersect", "prepare", "register",
           "reparametrize", "split", "unregister"]
