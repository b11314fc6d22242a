"""The geometry of surfprep: numpy/scipy (numba for the hot loops), no OCP, cadquery or
build123d here.

By concept:

* the types: :class:`NurbsCurve`, :class:`NurbsSurface` (:mod:`.curve`,
  :mod:`.surface`; their methods call the operation modules below),
  :class:`~.trimmed.TrimmedFace` / :class:`~.trimmed.TrimLoop` /
  :class:`~.trimmed.TrimEdge` (:mod:`.trimmed`), which ``(u, v)`` lie inside a
  trimmed face (:mod:`.face_region`);
* operations on them: :mod:`.basis`, :mod:`.knots` (insertion, refinement,
  splitting), :mod:`.tensor` (a surface seen along one direction), :mod:`.bezier`,
  :mod:`.degree`, :mod:`.isocurve`, :mod:`.measure`, :mod:`.rational`,
  :mod:`.fitting` (interpolation and approximation), :mod:`.creases`;
* closest points: :mod:`.projection`;
* the methods of the papers: :mod:`.intersection` (surface-surface intersection,
  000 §29.4, 004), :mod:`.characteristic` (no missed loop, 002), :mod:`.healing`
  (gaps, holes, overlaps, 001, 000 §29.3, 003), :mod:`.reparam` (chord-length
  reparametrization, 000 §29.2), :mod:`.parametrization` (the figure of
  000 eqs. 29.1/29.2);
* compiled kernels: ``*_kernels.py`` beside the module whose numpy reference they
  compile (:mod:`.jit`).

References
----------
The code cites the papers by key and section or equation ("001 §5", "000 eq. 29.3"):

====  ===================================================================================
key   paper
====  ===================================================================================
000   B. Hamann, B. A. Jean, A. Razdan, "Computer-Aided Geometric Design Techniques for
      Surface Grid Generation", chapter 29 of J. F. Thompson, B. K. Soni,
      N. P. Weatherill (eds.), *Handbook of Grid Generation*, CRC Press, 1999
      (§29.2 reparametrization, §29.3 healing, §29.4 surface-surface intersection).
001   B. Hamann, B. A. Jean, "Interactive surface correction based on a local
      approximation scheme", *Computer Aided Geometric Design* 13(4), 351-368, 1996.
002   Y. Wang, L. Gursoz, J. Chen, F. Prinz, N. M. Patrikalakis, "Non-manifold boundary
      representation with parametric geometric elements", Engineering Design Research
      Center, Carnegie Mellon University, report EDRC 24-37-90, 1990.
003   B. K. Soni, B. Hamann, "Computational geometry tools in grid generation", First
      International Conference on Hydro-Science and Engineering, Washington, D.C., 1993.
004   O. T. Morgan, G. Subbarayan, D. C. Anderson, "A hybrid hierarchical procedure for
      composing trivariate NURBS solids", *Computer-Aided Design and Applications* 9,
      2012.
[PT]  L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer, 1997 (cited as [PT]
      with its algorithm numbers, e.g. A2.3).
====  ===================================================================================
"""

from .bezier import (
    bezier_curves,
    bezier_decompose_array,
    bezier_patches,
    bezier_segments,
    bezier_surfaces,
    patch_bounding_boxes,
)
from .curve import NurbsCurve
from .degree import bezier_elevation_matrix, elevate_degree, elevate_degree_array, elevate_degree_surface
from .fitting import (
    approximate_curve,
    approximation_knots,
    averaged_knots,
    chord_length_parameters,
    interpolate_curve,
    interpolate_surface,
    knots_from_breakpoints,
)
from .isocurve import isocurve
from .knots import (
    clamp,
    clamp_surface,
    insert_knot,
    insert_knot_array,
    insert_knot_surface,
    periodic_to_clamped,
    refine,
    refine_knots_array,
    refine_surface,
    restrict,
    restrict_array,
    restrict_surface,
    split,
    split_surface,
)
from .measure import arc_length, bounding_box, cumulative_arc_length, normal_turn, normals
from .projection import (
    CurveProjectionResult,
    ProjectionResult,
    distance_to_curve,
    distance_to_surface,
    project_to_curve,
    project_to_surface,
)
from .surface import NurbsSurface
from .tensor import Direction
from .trimmed import TrimEdge, TrimLoop, TrimmedFace

__all__ = [
    "NurbsCurve",
    "NurbsSurface",
    "Direction",
    "TrimmedFace",
    "TrimLoop",
    "TrimEdge",
    # knots
    "insert_knot", "refine", "split", "restrict", "clamp", "periodic_to_clamped",
    "insert_knot_surface", "refine_surface", "split_surface", "restrict_surface",
    "clamp_surface", "insert_knot_array", "refine_knots_array", "restrict_array",
    # bezier
    "bezier_segments", "bezier_patches", "bezier_curves", "bezier_surfaces",
    "patch_bounding_boxes", "bezier_decompose_array",
    # degree
    "elevate_degree", "elevate_degree_surface", "elevate_degree_array",
    "bezier_elevation_matrix",
    # measure
    "bounding_box", "normals", "normal_turn", "arc_length", "cumulative_arc_length",
    # isocurve
    "isocurve",
    # fitting
    "chord_length_parameters", "averaged_knots", "knots_from_breakpoints",
    "approximation_knots", "interpolate_curve", "interpolate_surface", "approximate_curve",
    # projection
    "ProjectionResult", "CurveProjectionResult", "project_to_surface", "project_to_curve",
    "distance_to_surface", "distance_to_curve",
]
