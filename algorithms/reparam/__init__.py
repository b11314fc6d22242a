"""Chord-length (RCA) reparametrization of B-spline surfaces within a
guaranteed tolerance (000 §29.2: Hamann, Jean, Razdan, Handbook of Grid Generation ch. 29).

:func:`reparametrize_surface` is the entry point; the steps live in
:mod:`.boundary_points` (arc length + curvature, §29.2.4), :mod:`.reconcile`
(§29.2.5), :mod:`.interior` (penalty relocation, §29.2.6) and
:mod:`.deviation` (dense error, eq. 29.3).
"""

from .boundary_points import ArcLengthTable, arc_length_table, boundary_fractions
from .deviation import DeviationMap, deviation_map, original_on_new
from .interior import RelocationResult, initial_guess, penalties, relocate
from .rca import (
                  DEFAULT_RELATIVE_TOL,
                  ReparametrizationResult,
                  default_tolerance,
                  reparametrize_surface,
)
from .reconcile import insert_midpoints, reconcile_fractions

__all__ = [
                  "DEFAULT_RELATIVE_TOL",
                  "ArcLengthTable",
                  "DeviationMap",
                  "RelocationResult",
                  "ReparametrizationResult",
                  "arc_length_table",
                  "boundary_fractions",
                  "default_tolerance",
                  "deviation_map",
                  "initial_guess",
                  "insert_midpoints",
                  "original_on_new",
                  "penalties",
                  "reconcile_fractions",
                  "relocate",
                  "reparametrize_surface",
]
