"""Pure numpy/scipy geometry of surfprep: no OCP, cadquery or build123d here."""

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
from .measure import arc_length, bounding_box, cumulative_arc_length, normals
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

__all__ = [
    "NurbsCurve",
    "NurbsSurface",
    "Direction",
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
    "bounding_box", "normals", "arc_length", "cumulative_arc_length",
    # isocurve
    "isocurve",
    # fitting
    "chord_length_parameters", "averaged_knots", "knots_from_breakpoints",
    "approximation_knots", "interpolate_curve", "interpolate_surface", "approximate_curve",
    # projection
    "ProjectionResult", "CurveProjectionResult", "project_to_surface", "project_to_curve",
    "distance_to_surface", "distance_to_curve",
]
