"""surfprep for build123d: build123d shapes in, build123d shapes out.

The verbs of :mod:`surfprep` as free functions on build123d objects (and
OpenCascade shapes, paths and everything else the verbs take), returning
build123d objects: :func:`heal`, :func:`reparametrize`, :func:`prepare` and
:func:`boolean` a ``Shape`` (``Solid``, ``Shell``, ``Face``, ``Compound`` as the
result is), :func:`intersect` a list of ``Edge``, :func:`split` a ``Compound``.
They work in algebra mode and in builder mode (``insert(...)``); a result made from
one build123d object keeps its ``label`` and ``color``. The keyword arguments
after the shapes are the verb's own; ``report=True`` returns ``(object,
result)`` with the verb's full result (``.report()``, the figures). Importing
this module patches nothing.

Example
-------
>>> import build123d as bd
>>> import surfprep.build123d
>>> ball, slab = bd.Sphere(10), bd.Pos(0, 0, 5) * bd.Box(30, 30, 1)
>>> pieces = surfprep.build123d.split(ball, slab)           # algebra mode: a bd.Compound
>>> len(pieces.faces())
11
>>> plate = bd.Box(10, 20, 3)
>>> plate.label = "plate"
>>> with bd.BuildPart() as healed:                          # builder mode
...     _ = bd.insert(surfprep.build123d.heal(plate))
>>> round(healed.part.volume, 6), surfprep.build123d.heal(plate).label
(600.0, 'plate')
"""

from __future__ import annotations

from .plugin.adapters.build123d import boolean, heal, intersect, prepare, reparametrize, split

__all__ = ["boolean", "heal", "intersect", "prepare", "reparametrize", "split"]
