"""What :func:`surfprep.heal` returns: :class:`HealResult` and its :class:`PatchReport` s."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from OCP.TopoDS import TopoDS_Shape

from ...algorithms.healing import Continuity, JoinReport, LocalApproximant, Network
from ..io import CadModel
from .jobs import PatchOrigin

__all__ = ["HealResult", "PatchReport"]


class StageClock:
    """Seconds spent in each stage of :func:`surfprep.heal`: calling it with a stage's
    name ends the stage before and tells ``stage`` (the caller's callback, if any);
    :meth:`times` ends the last and returns ``{stage: seconds}``."""

    def __init__(self, stage=None) -> None:
        self._tell = stage
        self._times: dict[str, float] = {}
        self._current: str | None = None
        self._since = time.perf_counter()

    def _end(self) -> float:
        now = time.perf_counter()
        if self._current is not None:
            self._times[self._current] = self._times.get(self._current, 0.0) + now - self._since
        return now

    def __call__(self, name: str) -> None:
        self._current, self._since = name, self._end()
        if self._tell is not None:
            self._tell(name)

    def times(self) -> dict[str, float]:
        self._end()
        self._current = None
        return dict(self._times)


@dataclass(frozen=True)
class PatchReport:
    """One approximant: origin, name, resolution ``(M, N)``, errors of §7 (model
    units), artificial share, whether ``tol`` was met, and ``deviation``: the largest
    distance of the joined patch from the input faces on a dense sample (its
    four sides only for a hole; :mod:`surfprep.algorithms.healing.fidelity`)."""

    origin: PatchOrigin
    name: str | None
    resolution: tuple[int, int]
    max_error: float
    rms_error: float
    artificial_share: float
    converged: bool
    tol: float = float("nan")
    deviation: float = float("nan")

    def as_dict(self) -> dict:
        return {"kind": self.origin.kind, "faces": list(self.origin.faces),
                "index": self.origin.index, "name": self.name,
                "resolution": list(self.resolution), "max_error": self.max_error,
                "rms_error": self.rms_error, "artificial_share": self.artificial_share,
                "converged": self.converged, "tol": self.tol,
                "deviation_from_input": self.deviation}


@dataclass(frozen=True, eq=False)
class HealResult:
    """What :func:`heal` built and measured.

    Attributes
    ----------
    model : CadModel
        The healed shape with face names.
    patches : tuple of PatchReport
    approximants : tuple of LocalApproximant
        Same order as :attr:`patches` (deviation maps in ``.error``).
    network : Network or None
        The joined patches, their connectivity and measured joins.
    dropped : tuple of (int, int)
        ``(kept, dropped)`` overlapping face pairs.
    skipped : tuple of str
        Faces or holes left as they were, and why.
    free_edges_before, free_edges_after : int
        Free edges after sewing at ``gap_tol`` (input) and in the result.
    tight_free_edges_before, tight_free_edges_after : int
        Free edges in the geometry at ``TIGHT_FACTOR`` x size, of the input and of the
        result sewn at ``gap_tol``: free edges plus, per shared edge whose faces lie
        farther apart than that (measured on the faces, :mod:`surfprep.plugin.occ.gaps`),
        one per face.
    valid_before, valid_after : bool
        ``BRepCheck_Analyzer`` on the input shape and on the result.
    max_edge_tolerance : float
        Largest edge tolerance of the result (sewing raises it where it closes
        a gap by tolerance instead of geometry).
    tol, gap_tol : float
    continuity : Continuity
    time_s : float
    """

    model: CadModel
    patches: tuple[PatchReport, ...]
    approximants: tuple[LocalApproximant, ...]
    network: Network | None
    dropped: tuple[tuple[int, int], ...]
    skipped: tuple[str, ...]
    free_edges_before: int
    free_edges_after: int
    tight_free_edges_before: int
    tight_free_edges_after: int
    valid_before: bool
    valid_after: bool
    max_edge_tolerance: float
    tol: float | None
    gap_tol: float
    continuity: Continuity
    time_s: float
    extra: dict = field(default_factory=dict)

    @property
    def shape(self) -> TopoDS_Shape:
        return self.model.shape

    @property
    def geometry(self) -> CadModel:
        """The healed model, as every verb's result has its geometry."""
        return self.model

    @property
    def joins(self) -> tuple[JoinReport, ...]:
        return () if self.network is None else self.network.joins

    def report(self) -> dict:
        """Plain-JSON report (per patch, per shared edge, free edges, validity)."""
        net = self.network
        return {
            "continuity": self.continuity.value, "tol": self.tol, "gap_tol": self.gap_tol,
            "time_s": self.time_s, "stage_times_s": self.extra.get("stage_times_s", {}),
            "faces_in": self.extra.get("faces_in"),
            "faces_out": self.model.n_faces,
            "patches": [p.as_dict() for p in self.patches],
            "shared_edges": [j.as_dict() for j in self.joins],
            "shared_edges_before": [] if net is None else [j.as_dict() for j in
                                                           net.joins_before],
            "topology_violations": [] if net is None else list(net.connectivity.violations),
            "dropped_overlaps": [{"kept": a, "dropped": b} for a, b in self.dropped],
            "trimmed_overlaps": self.extra.get("trimmed_overlaps", []),
            "cuts": self.extra.get("cuts", []),
            "partial_overlaps": self.extra.get("partial_overlaps", []),
            "crossings": self.extra.get("crossings", []),
            "retrimmed": self.extra.get("retrimmed", []),
            "snapped_sides": self.extra.get("snapped_sides", 0),
            "skipped": list(self.skipped),
            "free_edges": {"before": self.free_edges_before, "after": self.free_edges_after,
                           "tight_before": self.tight_free_edges_before,
                           "tight_after": self.tight_free_edges_after},
            "valid": {"before": self.valid_before, "after": self.valid_after},
            "max_edge_tolerance": self.max_edge_tolerance,
            "replace": self.extra.get("replace"),
            "free_loops": self.extra.get("free_loops", []),
            "rings": self.extra.get("rings", []),
            "free_boundary": self.extra.get("free_boundary", {}),
            "closed_gaps": self.extra.get("closed_gaps", {}),
        }
