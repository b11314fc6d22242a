"""Surface-surface intersection (000 §29.4, 004 §4-6): triangulation, culling,
triangle intersection, curve topology and refinement onto the exact surfaces.

The entry point is :func:`intersect_surfaces` (:mod:`.pipeline`); the stages are
public too, module by module:

* :mod:`.mesh`: :class:`TriangleMesh`;
* :mod:`.tessellation`: adaptive tessellation of a surface's parameter regions;
* :mod:`.culling`: Bézier patch boxes, overlap boxes, box trees;
* :mod:`.triangles`: vectorized triangle-triangle intersection;
* :mod:`.segments`: :func:`mesh_segments`, steps 1-4 to a :class:`SegmentSoup`;
* :mod:`.topology`: Point / PointUse / Segment topology, traced chains;
* :mod:`.refine`: auxiliary-plane refinement (eqs. 29.18-29.26);
* :mod:`.interpolants`: the cubic interpolants of samples and their deviation;
* :mod:`.sampling`: the samples the cubic interpolants need (:func:`cubic_samples`);
* :mod:`.result`: :class:`IntersectionCurve` and its interpolants;
* :mod:`.sides`, :mod:`.seams`, :mod:`.extend`, :mod:`.singular_join`: curves along
  domain sides, cuts at seams, hanging ends marched, curves joined at double points;
* :mod:`.boundary_ends`: curve ends solved on the domain side they lie on;
* :mod:`.trimming`: curves clipped to trimmed faces (:func:`clip_curve`), shared
  edges of one shape told apart;
* :mod:`.angles`: how flat a crossing the triangles can follow;
* :mod:`.compare`: distances between two answers (Hausdorff, per-branch).
"""

from .compare import CurveSetDistance, connected_branches, curve_set_distance, hausdorff, polyline_distance
from .culling import (
                      BoxTree,
                      PatchOverlap,
                      build_tree,
                      candidate_pairs,
                      overlap_boxes,
                      overlap_patches,
                      patch_rectangles,
                      subpatch_boxes,
                      surface_patch_boxes,
                      tree_pairs,
)
from .mesh import TriangleMesh, collinear_mask
from .pipeline import (
                      SmallAngleWarning,
                      StrayCurves,
                      StrayCurveWarning,
                      closed_in_space,
                      default_mesh_tolerance,
                      intersect_surfaces,
                      operand_size,
)
from .refine import (
                      RefinedCurve,
                      RefinedPoints,
                      project_points,
                      refine_curves,
                      refine_points,
                      segment_distance,
)
from .result import CurveDeviation, IntersectionCurve, interpolate_samples, intersection_curves
from .sampling import SampledCurve, cubic_samples
from .segments import SegmentSoup, SoupStats, mesh_segments
from .tessellation import Tessellation, tessellate
from .topology import Chain, EndKind, SegmentTopology, build_topology, topology_from_soup
from .triangles import TriangleHits, intersect_triangles
from .trimming import along_a_boundary, clip_curve

__all__ = [
    "intersect_surfaces", "SmallAngleWarning", "StrayCurves", "StrayCurveWarning",
    "closed_in_space", "default_mesh_tolerance", "operand_size",
    "IntersectionCurve", "CurveDeviation", "intersection_curves", "interpolate_samples",
    "cubic_samples", "SampledCurve",
    "EndKind", "Chain", "SegmentTopology", "build_topology", "topology_from_soup",
    "RefinedPoints", "RefinedCurve", "refine_points", "refine_curves", "project_points",
    "segment_distance",
    "SegmentSoup", "SoupStats", "mesh_segments",
    "TriangleHits", "intersect_triangles",
    "TriangleMesh", "collinear_mask",
    "Tessellation", "tessellate",
    "BoxTree", "PatchOverlap", "build_tree", "tree_pairs", "candidate_pairs", "overlap_boxes",
    "overlap_patches", "surface_patch_boxes", "patch_rectangles", "subpatch_boxes",
    "hausdorff", "polyline_distance", "curve_set_distance", "CurveSetDistance",
    "connected_branches",
    "clip_curve", "along_a_boundary",
]
