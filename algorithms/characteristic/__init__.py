"""Surface-surface intersection with a no-missed-loop guarantee: the oriented
distance function, characteristic points and characteristic curves
(Wang, Gursoz, Chen, Prinz, Patrikalakis 1990; paper 002).

* :mod:`.projector`: orthogonal projection onto a surface (eqs. 3-4, §6.2 cases);
* :mod:`.distance`: the oriented distance ``phi`` and its derivatives (A.1, eqs. 24-31);
* :mod:`.points`: border, turning, singular and critical points (§3.3, §4.2);
* :mod:`.curves`: u-/v-characteristic curves and intersection curves traced as
  ODEs with a corrector (eqs. 15-21, 33);
* :mod:`.trace`: intersection curves from start points, refined to ``tol``;
* :mod:`.starts`: starts on loops (rays from extrema) and their check against known curves;
* :mod:`.algorithm`: the algorithm of §6.3 (:func:`characteristic_intersection`)
  and the certificate for the triangle method (:func:`certify`);
* :mod:`.sweep`: the characteristic curves of the stage, complete to the sample
  grid (components reaching no side, projection branches past the cut locus);
* :mod:`.ridges`: curves of critical points (surfaces of revolution cut normal
  to their axis): tangential curves, and starts beside maximum/minimum ridges;
* :mod:`.evaluator`: fast power-basis evaluation for the tracers;
* :mod:`.distance_kernels`: the distance jet and the projection as numba kernels;
* :mod:`.prefilter`: pairs with no possible loop nor contact point (the certificate skips them);
* :mod:`.grid`: the roles of the two surfaces and the stage's sample grid;
* :mod:`.crossing`: the flattest crossing angle on that grid;
* :mod:`.auto`: the default ``auto`` method per pair (:func:`auto_intersection`);
* :mod:`.coincidence`: where two trimmed faces coincide (:func:`face_coincidence`).
"""

from .algorithm import (
                        CharacteristicAnalysis,
                        CharacteristicRecord,
                        CoincidentRegion,
                        FoundBy,
                        certify,
                        characteristic_analysis,
                        characteristic_intersection,
                        choose_field,
                        tangential_curves,
)
from .auto import FULL_COINCIDENCE, Route, auto_intersection, small_angle
from .coincidence import face_coincidence
from .crossing import grid_crossing_sine
from .curves import CurveKind, EndReason, TracedCurve, trace_curves
from .distance import DistanceField, DistanceJet, distance_jet
from .evaluator import PatchEvaluator
from .grid import StageGrid, stage_grid
from .points import CharacteristicPoint, PointKind, classify_critical, critical_points
from .prefilter import NoLoopReason, no_loop_reason, uncertified_record
from .projector import Projection, ProjectionStatus, Projector
from .ridges import Ridge
from .trace import to_intersection_curve, trace_intersections

__all__ = [
    "FULL_COINCIDENCE",
    "CharacteristicAnalysis",
    "CharacteristicPoint",
    "CharacteristicRecord",
    "CoincidentRegion",
    "CurveKind",
    "DistanceField",
    "DistanceJet",
    "EndReason",
    "FoundBy",
    "NoLoopReason",
    "PatchEvaluator",
    "PointKind",
    "Projection",
    "ProjectionStatus",
    "Projector",
    "Ridge",
    "Route",
    "StageGrid",
    "TracedCurve",
    "auto_intersection",
    "certify",
    "characteristic_analysis",
    "characteristic_intersection",
    "choose_field",
    "classify_critical",
    "critical_points",
    "distance_jet",
    "face_coincidence",
    "grid_crossing_sine",
    "no_loop_reason",
    "small_angle",
    "stage_grid",
    "tangential_curves",
    "to_intersection_curve",
    "trace_curves",
    "trace_intersections",
    "uncertified_record",
]
