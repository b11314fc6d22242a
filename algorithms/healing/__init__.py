"""Healing of gaps, holes, overlaps and intersections with four-sided bicubic
B-spline approximants joined G0/G1 (Hamann & Jean 1996, paper 001; handbook
§29.3; Soni & Hamann 1993, paper 003)."""

from .approximant import LocalApproximant, ResolutionStep, local_approximant
from .boundary import Boundary, as_boundary, corners_boundary
from .clipping import SurfaceSource, trimmed_source
from .connectivity import (
    Connectivity,
    NetworkTopologyError,
    SharedEdge,
    Side,
    find_connectivity,
)
from .fill import FillMethod
from .interpolant import Interpolant
from .measure_joins import JoinReport, measure_join
from .network import Continuity, Network, connect

# one local approximant (approximant.py and the modules of its steps) and their
# network (network.py, connectivity.py, compatibility.py, continuity.py, measure_joins.py)
__all__ = [
    "Boundary",
    "Connectivity",
    "Continuity",
    "FillMethod",
    "Interpolant",
    "JoinReport",
    "LocalApproximant",
    "Network",
    "NetworkTopologyError",
    "ResolutionStep",
    "SharedEdge",
    "Side",
    "SurfaceSource",
    "as_boundary",
    "connect",
    "corners_boundary",
    "find_connectivity",
    "local_approximant",
    "measure_join",
    "trimmed_source",
]
