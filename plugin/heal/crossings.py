"""Faces that cut through each other, found and trimmed back without a directed patch
(issue 21 item 5; 001 §1 "intersecting surfaces", for :func:`surfprep.heal`).

A face that runs on past the curve where it meets another ends in free edges beyond
it. So the candidates are the pairs of faces (i, j), not neighbours along a paired edge,
where the box of i's free edges (grown by ``gap_tol``) meets j's box (its control
points'): a closed model without free edges costs nothing here, and the work follows
the free edges. Of those, the pairs where an edge of one passes through the other face
(:func:`~surfprep.algorithms.healing.overshoots.edges_pass_through`: from beyond
``gap_tol`` on one side to beyond it on the other, inside the face) are intersected by
:func:`surfprep.intersect` (the triangle method, to ``CURVE_SHARE`` x ``tight``, so that
the faces trimmed to the curve meet within ``tight`` in the geometry); every face a
curve crosses is split along its curves (:func:`~surfprep.algorithms.face_split.split_face`), and which pieces are
overshoots is decided by the model around them
(:func:`~surfprep.algorithms.healing.overshoots.overshoot_pieces`: a piece whose side
ends in free edges where the other is part of the model, or, of two sheets, the piece
much smaller than the other). The overshoots are dropped; each cut face is replaced by
its kept piece (its name kept; several pieces ``name.1``, ``name.2``), whose edge
along the curve is the curve itself, so the two faces meet along it and are sewn
like any neighbours. A crossing whose sides cannot be told apart is left as it is and
reported with the reason.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ...algorithms.face_region import FaceRegion
from ...algorithms.face_split import Cut, split_face
from ...algorithms.healing.adjacency import FaceEdge, polyline_distance
from ...algorithms.healing.overshoots import SurfaceSides, edges_pass_through, overshoot_pieces
from ...algorithms.trimmed import TrimmedFace
from ...errors import SurfprepError
from ..intersect import intersect
from ..occ.faces import trimmed_face_to_occ
from ..occ.shapes import face_area
from .cut import read_faces, rebuilt_model

__all__ = ["CURVE_SHARE", "Crossing", "crossing_candidates", "trim_crossings"]

#: the crossing curves are computed to this share of ``tight``
CURVE_SHARE = 0.1
#: a curve's end farther than this times ``tight`` from a face's boundary and its other
#: curves stops inside the face (split_face's own test is 10 x CURVE_SHARE x tight)
_ENDS_SHARE = 10.0
#: samples of each crossing curve compared with the pieces' edges
_CURVE_SAMPLES = 257


@dataclass(frozen=True)
class Crossing:
    """One crossing curve of two faces and what was done.

    Attributes
    ----------
    faces : (int, int)
        The two faces (indices of the model given to :func:`trim_crossings`).
    length : float
        The curve's length, model units.
    area_cut : (float, float)
        Area dropped from each face along this curve (0 when left; a piece along several
        curves, a lid's rim cut by four walls, counted at the first).
    left : str or None
        Why the crossing is left as it is; None when both faces were trimmed to it.
    """

    faces: tuple[int, int]
    length: float
    area_cut: tuple[float, float]
    left: str | None = None

    def as_dict(self) -> dict:
        return {"faces": list(self.faces), "length": self.length,
                "area_cut": list(self.area_cut),
                "action": "trimmed back" if self.left is None else "left",
                **({} if self.left is None else {"reason": self.left})}


def crossing_candidates(faces: list[TrimmedFace | None], edges: list[FaceEdge],
                        pairs: list[tuple[int, int]], gap_tol: float) -> list[tuple[int, int]]:
    """Face pairs ``(i, j)``, ``i < j``, that may cut through each other (module doc):
    not paired along an edge, and the box of the free edges of one meets the other's box."""
    paired = {k for pair in pairs for k in pair}
    neighbours = {tuple(sorted((edges[a].face, edges[b].face))) for a, b in pairs}
    free_lo: dict[int, np.ndarray] = {}
    free_hi: dict[int, np.ndarray] = {}
    for k, e in enumerate(edges):
        if k in paired:
            continue
        lo, hi = e.samples.min(axis=0) - gap_tol, e.samples.max(axis=0) + gap_tol
        free_lo[e.face] = np.minimum(free_lo.get(e.face, lo), lo)
        free_hi[e.face] = np.maximum(free_hi.get(e.face, hi), hi)
    if not free_lo:
        return []
    index = [i for i, f in enumerate(faces) if f is not None]
    points = [faces[i].surface.control_points[..., :3].reshape(-1, 3) for i in index]
    lo = np.array([p.min(axis=0) for p in points])
    hi = np.array([p.max(axis=0) for p in points])
    out = set()
    for i, flo in free_lo.items():
        fhi = free_hi[i]
        meets = np.all((lo <= fhi) & (flo <= hi), axis=1)
        for n in np.nonzero(meets)[0]:
            j = index[n]
            if j != i:
                pair = (min(i, j), max(i, j))
                if pair not in neighbours:
                    out.add(pair)
    return sorted(out)


def trim_crossings(model, faces: list[TrimmedFace | None], edges: list[FaceEdge],
                   pairs: list[tuple[int, int]], *, gap_tol: float, tight: float,
                   skipped: list[str]):
    """Faces cutting through each other trimmed back to their crossing curves (module
    doc).

    Returns
    -------
    model : CadModel
        As given when nothing was trimmed, else with each trimmed face replaced by its
        kept pieces (names and colours kept).
    faces : list of TrimmedFace or None
    crossings : list of Crossing
        Every crossing curve found, trimmed or left.
    """
    candidates = crossing_candidates(faces, edges, pairs, gap_tol)
    polylines: dict[int, list] = {}
    for e in edges:
        polylines.setdefault(e.face, []).append(e.samples)
    regions: dict[int, FaceRegion] = {}
    sides: dict[int, SurfaceSides] = {}

    def region(f: int) -> FaceRegion:
        if f not in regions:
            regions[f] = FaceRegion(faces[f])
        return regions[f]

    def through(i: int, j: int) -> bool:        # an edge of i passes through face j
        if j not in sides:
            sides[j] = SurfaceSides(region(j))
        return edges_pass_through(sides[j], np.stack(polylines[i]), gap_tol)

    candidates = [(i, j) for i, j in candidates if i in polylines and j in polylines
                  and (through(i, j) or through(j, i))]
    if not candidates:
        return model, faces, []
    curves = []                                      # (i, j, FaceIntersection)
    for i, j in candidates:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")          # a pair that fails is no crossing
            try:
                found = intersect(faces[i], faces[j], tol=CURVE_SHARE * tight, method="mesh")
            except SurfprepError:
                continue
        curves.extend((i, j, r) for r in found if not r.closed and r.curve.pcurve_a is not None
                      and r.curve.pcurve_b is not None)
    if not curves:
        return model, faces, []
    lines = {id(r): r.curve.curve3d.evaluate(np.linspace(*r.curve.curve3d.domain, _CURVE_SAMPLES))
             for _, _, r in curves}
    refused = _stopping_inside(curves, lines, region, _ENDS_SHARE * tight)
    done: dict = {}      # (face, its curves) -> pieces: a face keeps them while they stay
    while True:          # faces split along the curves whose two faces can both be cut
        usable = [(i, j, r) for i, j, r in curves if i not in refused and j not in refused]
        split = _split_faces(faces, usable, 10.0 * CURVE_SHARE * tight, refused, done)
        if split is not None:
            break
    pieces, origin, built = [], [], []
    for f, face in enumerate(faces):
        if face is None:
            continue
        for piece, occ in zip(*split.get(f, ([face], [None]))):
            pieces.append(piece)
            origin.append(f)
            built.append(occ)
    areas = np.array([face_area(b) if b is not None else 0.0 for b in built])
    dropped, decisions = overshoot_pieces(pieces, origin, areas, [lines[id(r)] for _, _, r in usable],
                                          [(i, j) for i, j, _ in usable], gap_tol)
    crossings, counted = [], set()
    for (i, j, r), d in zip(usable, decisions):
        mine = [p for p in d.dropped if p not in counted]      # a piece counted once
        counted.update(mine)
        cut_area = tuple(float(sum(areas[p] for p in mine if origin[p] == f)) for f in (i, j))
        crossings.append(Crossing((i, j), float(r.length), cut_area, d.reason))
    for i, j, r in curves:
        if i in refused or j in refused:
            f = i if i in refused else j
            crossings.append(Crossing((i, j), float(r.length), (0.0, 0.0),
                                      f"face {f}: {refused[f]}"))
    skipped.extend(_notes(crossings))
    if not dropped:
        return model, faces, crossings
    return _with_pieces(model, origin, built, dropped) + (crossings,)


def _stopping_inside(curves, lines: dict, region, near: float) -> dict[int, str]:
    """Faces where a curve ends inside, neither on the boundary nor on another of the
    face's curves (within ``near`` plus the sag of the face's sampled boundary): two
    faces poking through each other without one dividing the other, which no cut trims
    (:func:`split_face` would refuse it, at a cost growing with the face's curves). Per
    such face the reason. ``lines`` holds each curve's polyline by ``id``, ``region(f)``
    gives face ``f``'s :class:`FaceRegion`."""
    by_face: dict[int, list] = {}
    for i, j, r in curves:
        for f, g in ((i, j), (j, i)):
            by_face.setdefault(f, []).append((g, lines[id(r)]))
    out = {}
    for f, mine in by_face.items():
        face = region(f)
        reach = near + face.boundary_sag
        for n, (g, line) in enumerate(mine):
            ends = line[[0, -1]]
            inside = face.edge_distance(ends) > reach
            for m, (_, other) in enumerate(mine):
                if m != n and inside.any():
                    inside &= polyline_distance(ends, other) > reach
            if inside.any():
                out[f] = (f"a curve stops inside it (where it meets face {g}: the two poke "
                          "through each other, neither divided)")
                break
    return out


def _split_faces(faces, curves, tol3d: float, refused: dict[int, str], done: dict) -> dict | None:
    """Per face cut by ``curves`` its pieces and their OpenCascade faces; None when a face
    cannot be cut or a piece built (the face added to ``refused`` with the reason: the
    caller splits again without its curves). ``done`` keeps the faces split so far by
    their curves, so a face whose curves did not change is not split again."""
    cuts: dict[int, list] = {}
    for i, j, r in curves:
        cuts.setdefault(i, []).append((id(r), Cut(r.curve.pcurve_a, r.curve.curve3d)))
        cuts.setdefault(j, []).append((id(r), Cut(r.curve.pcurve_b, r.curve.curve3d)))
    out = {}
    for f, face_cuts in cuts.items():
        key = (f, tuple(k for k, _ in face_cuts))
        if key not in done:
            try:
                pieces = split_face(faces[f], [c for _, c in face_cuts], tol3d=tol3d)
                done[key] = (pieces, [trimmed_face_to_occ(p) for p in pieces])
            except SurfprepError as exc:
                refused[f] = f"it cannot be cut along the curves ({exc})"
                return None
        out[f] = done[key]
    return out


def _notes(crossings: list[Crossing]) -> list[str]:
    """The crossings in a few notes: those trimmed back, and those left by kind."""
    notes = []
    done = [c for c in crossings if c.left is None]
    if done:
        pairs = ", ".join(f"{i}-{j}" for i, j in dict.fromkeys(c.faces for c in done))
        notes.append(f"{len(done)} curve(s) where faces cut through each other: both faces "
                     f"trimmed back to each (faces {pairs}; area cut away "
                     f"{sum(sum(c.area_cut) for c in done):.4g})")
    kinds: dict[str, list] = {}
    for c in crossings:
        if c.left is not None:
            kind = c.left.split(": ", 1)[-1].split(" (")[0]     # "face N: why (figures)"
            kinds.setdefault(kind, []).append(c.faces)
    for kind, pairs in kinds.items():
        listed = ", ".join(f"{i}-{j}" for i, j in dict.fromkeys(pairs))
        notes.append(f"{len(pairs)} curve(s) where faces cut through each other left as they "
                     f"are: {kind} (faces {listed}; the report's crossings say why)")
    return notes


def _with_pieces(model, origin, built, dropped):
    """``model`` with every face that lost a piece replaced by the pieces it keeps."""
    losing = {origin[p] for p in dropped}
    kept: dict[int, list] = {}
    for p, f in enumerate(origin):
        if f in losing and p not in dropped:
            kept.setdefault(f, []).append(built[p])
    occ, names, colors = [], [], []
    for f, (face, name, color) in enumerate(zip(model.faces, model.face_names, model.face_colors)):
        mine = kept.get(f, []) if f in losing else [face]
        for n, piece in enumerate(mine, start=1):
            occ.append(piece)
            names.append(name if len(mine) == 1 or name is None else f"{name}.{n}")
            colors.append(color)
    return rebuilt_model(model, occ, names, colors), read_faces(occ, names)
