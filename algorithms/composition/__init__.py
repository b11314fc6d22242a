"""Composition of two trivariate NURBS solids (004): the curves where their boundaries
meet, the hierarchy of Bézier patches, overlap boxes, local triangulations and kd-trees
that finds them, which solid(s) a point is in, and the volumes and boundaries of the
composed regions -- without building a B-rep."""

from .compose import Composition, compose

__all__ = ["Composition", "compose"]
