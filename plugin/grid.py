"""``surfprep.grid``: structured surface grids on faces, surfaces, models and patch networks.

:func:`grid` takes what the other verbs take -- a STEP/IGES path, a
:class:`~surfprep.plugin.io.CadModel`, a ``TopoDS_Shape``, a cadquery or
build123d object -- or surfprep's own :class:`NurbsSurface` / :class:`TrimmedFace`
(one, or a list making a network), grids every four-sided face as one block
(:func:`~surfprep.algorithms.grid.network.grid_network`: point-matched across
shared edges, elliptic refinement on each surface's metric) and says which faces
it cannot grid and why. The geometry work is in :mod:`surfprep.algorithms.grid`;
this module reads the faces, orients the blocks and writes the files.

Orientation: i runs along the face's u and j along its v; for a face used
reversed in its shell (its normal opposite to ``S_u x S_v``) j is reversed, so
``x_i x x_j`` points along the face's outward normal in every block.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..algorithms import NurbsSurface
from ..algorithms.grid.faces import POLE_CAPS, face_regions, rectangle_regions
from ..algorithms.grid.io import write_cgns, write_plot3d, write_vtm, write_vts
from ..algorithms.grid.network import NetworkGrid, grid_network
from ..algorithms.grid.quality import cell_skewness
from ..algorithms.grid.structured import Spacing
from ..algorithms.trimmed import TrimmedFace
from ..errors import InvalidGeometryError, OutputFileError, SurfprepError

__all__ = ["FORMATS", "GridResult", "grid", "grid_format"]

#: output formats by file extension
FORMATS = {".xyz": "plot3d", ".p3d": "plot3d", ".x": "plot3d", ".g": "plot3d", ".grd": "plot3d",
           ".cgns": "cgns", ".vts": "vts", ".vtm": "vtm"}
#: default largest gap between two sides called one edge, relative to the model's size
DEFAULT_RELATIVE_GAP = 1e-4


@dataclass(frozen=True)
class GridResult:
    """Structured grids of the four-sided faces of a model, one block per face.

    Attributes
    ----------
    network : NetworkGrid
        The blocks (:class:`~surfprep.algorithms.grid.SurfaceGrid`), their
        interfaces, the snap and kink figures.
    faces : tuple of int
        The face index (file order) of each block; for surfaces given directly,
        their position in the list.
    names : tuple of (str or None)
    reversed_j : tuple of bool
        Blocks whose j runs against their surface's v (faces used reversed).
    skipped : tuple of (int, str)
        Faces not gridded, with the reason.
    time_s : float
    """

    network: NetworkGrid
    faces: tuple[int, ...]
    names: tuple[str | None, ...]
    reversed_j: tuple[bool, ...]
    skipped: tuple[tuple[int, str], ...] = ()
    time_s: float = field(default=0.0, compare=False)

    @property
    def blocks(self) -> list[np.ndarray]:
        """The nodes of every block, ``(ni, nj, 3)`` each, in face order."""
        return [b.points for b in self.network.blocks]

    def report(self) -> dict:
        """Plain-JSON report: per block the face, dims, quality, residual history, time."""
        net = self.network.report()
        for entry, face, name, rev in zip(net["blocks"], self.faces, self.names, self.reversed_j,
                                          strict=True):
            entry.update({"face": face, "name": name, "j_reversed": rev})
        worst = {}
        if self.network.blocks:
            q = [b.quality for b in self.network.blocks]
            worst = {"min_angle": min(x.min_angle for x in q), "max_angle": max(x.max_angle for x in q),
                     "max_skewness": max(x.max_skewness for x in q),
                     "min_scaled_jacobian": min(x.min_scaled_jacobian for x in q),
                     "folded_cells": sum(x.folded_cells for x in q),
                     "max_growth_ratio": max(x.max_growth_ratio for x in q)}
        return {"blocks": net["blocks"], "interfaces": net["interfaces"], "worst": worst,
                "snap": net["snap"], "kink_deg": net["kink_deg"],
                "interface_rounds": net["interface_rounds"], "cuts": net["cuts"],
                "t_junctions_left": net["t_junctions_left"],
                "dims_changed": [{**d, "face": self.faces[d["block"]]} for d in net["dims_changed"]],
                "skipped": [{"face": k, "reason": r} for k, r in self.skipped],
                "time_s": self.time_s}

    def write(self, path: str | os.PathLike, *, format: str | None = None, binary: bool = False) -> Path:
        """Write the blocks: Plot3D, CGNS (with the interfaces), VTK ``.vts``/``.vtm``.

        ``format`` defaults to the extension's (:data:`FORMATS`); ``binary`` writes
        Fortran unformatted Plot3D. Skewness goes into the VTK files as cell data.
        """
        target = Path(path)
        fmt = grid_format(target, format)
        blocks = self.blocks
        if not blocks:
            raise OutputFileError("no block to write: no face was gridded")
        if fmt == "plot3d":
            return write_plot3d(target, blocks, binary=binary)
        if fmt == "cgns":
            width = len(str(max(self.faces)))
            # a face split into several blocks (round a hole, at its corners) names each of them
            split = {k for k in self.faces if self.faces.count(k) > 1}
            seen: dict[int, int] = {}
            names = []
            for k in self.faces:
                names.append(f"Face{k:0{width}d}" + (f"_{seen.get(k, 0)}" if k in split else ""))
                seen[k] = seen.get(k, 0) + 1
            return write_cgns(target, blocks, interfaces=self.network.interfaces, names=names)
        cells = [{"skewness": cell_skewness(b)} for b in blocks]
        if fmt == "vts":
            if len(blocks) != 1:
                raise OutputFileError(f"{target}: a .vts file holds one block, the grid has "
                                      f"{len(blocks)}; write a .vtm (multiblock) instead")
            return write_vts(target, blocks[0], cell_data=cells[0])
        return write_vtm(target, blocks, cell_data=cells)


def grid_format(path: Path, format: str | None = None) -> str:
    """The format for ``path``: ``format`` if given, else by extension; OutputFileError if unknown."""
    if format is not None:
        if format not in set(FORMATS.values()):
            raise OutputFileError(f"unknown grid format {format!r}; expected one of "
                                  f"{', '.join(sorted(set(FORMATS.values())))}")
        return format
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise OutputFileError(f"grid file {path} has unknown extension {path.suffix or '(none)'!r}; "
                              f"expected one of {', '.join(FORMATS)}")
    return fmt


def reversed_v(surface: NurbsSurface) -> NurbsSurface:
    """The same surface with its v direction reversed (``v -> v0 + v1 - v``)."""
    kv = surface.knots_v
    knots = (kv[0] + kv[-1]) - kv[::-1]
    weights = None if surface.weights is None else surface.weights[:, ::-1]
    return NurbsSurface(surface.control_points[:, ::-1], surface.knots_u, knots,
                        surface.degree_u, surface.degree_v, weights)


def _faces_of(obj: Any) -> tuple[list[TrimmedFace | NurbsSurface | None], list[str | None],
                                    list[tuple[int, str]], float]:
    """Faces (or surfaces), their names, the unreadable ones, and the model's size."""
    items = obj if isinstance(obj, (list, tuple)) else [obj]
    if items and all(isinstance(x, (NurbsSurface, TrimmedFace)) for x in items):
        boxes = np.vstack([(x if isinstance(x, NurbsSurface) else x.surface).bounding_box()
                           for x in items])
        size = float(np.linalg.norm(boxes.max(axis=0) - boxes.min(axis=0)))
        names = [getattr(x, "name", None) for x in items]
        return list(items), names, [], size
    from .io import as_model
    from .occ.faces import face_to_nurbs
    model = as_model(obj)
    faces: list[TrimmedFace | NurbsSurface | None] = []
    unreadable = []
    for k, (face, name) in enumerate(zip(model.faces, model.face_names, strict=True)):
        try:
            faces.append(face_to_nurbs(face, name))
        except SurfprepError as exc:
            faces.append(None)
            unreadable.append((k, f"not readable as NURBS ({exc})"))
    return faces, list(model.face_names), unreadable, model.size


def _assign_held(surfaces: list, curves: list, gap: float) -> dict[int, list]:
    """The surface each held curve lies on and crosses (the first that takes it; whole
    rectangles only)."""
    from ..algorithms.grid.held import held_line
    out: dict[int, list] = {}
    for k, curve in enumerate(curves):
        reasons = []
        for b, surface in enumerate(surfaces):
            if not isinstance(surface, NurbsSurface):
                continue
            try:
                held_line(surface, curve, tol=gap)
            except InvalidGeometryError as exc:
                reasons.append(str(exc))
                continue
            out.setdefault(b, []).append(curve)
            break
        else:
            raise InvalidGeometryError(
                f"held curve {k} runs across no gridded face from side to side within {gap:.3g} "
                f"({reasons[0] if reasons else 'no face'})")
    return out


def grid(obj: Any, *, faces: list[int] | None = None, dims: tuple[int, int] | None = None,
         size: float | None = None, spacing: Spacing | tuple[Spacing, Spacing] | None = None,
         smooth: str = "elliptic", orthogonal: bool = True, tol: float = 1e-4,
         gap: float | None = None,
         whole_surfaces: bool = False, hold=(), max_sweeps: int = 2000, pole_caps: str = "o",
         progress=None) -> GridResult:
    """Structured grids on the four-sided faces of a model (or on surfaces), one block each.

    Parameters
    ----------
    obj : path, CadModel, TopoDS_Shape, cadquery/build123d object, NurbsSurface,
        TrimmedFace, or a list of NurbsSurface/TrimmedFace (a network)
    faces : list of int, optional
        Face indices to grid (file order); default every four-sided face.
    dims : (int, int), optional
        Exactly ``ni x nj`` nodes per block (i along the face's u).
    size : float, optional
        Target cell size in model units (default: the median face's longest side over 40).
    spacing : Spacing or (Spacing, Spacing), optional
        Node distribution along i and j (default uniform in arc length).
    smooth : {"elliptic", "none"}
    orthogonal : bool
        With elliptic smoothing, grid lines leave every face side at 90 degrees
        (blended to the face's own corner angles).
    tol : float
        Elliptic residual to stop at (fraction of a cell).
    gap : float, optional
        Largest distance between two sides called one shared edge (model units);
        default 1e-4 x the model's size.
    whole_surfaces : bool
        Grid the whole parameter rectangle of a trimmed face's surface instead of
        refusing the face (the trims are ignored; said in the report).
    hold : sequence of NurbsCurve (3D) or (m, 3) points
        Curves to keep as grid lines (an intersection curve, a crease): each must lie
        on one gridded face within ``gap`` and run from a side of it to the opposite
        side; it becomes a line of that face's block.
    max_sweeps : int
    pole_caps : {"o", "h"}
        A cap round a pole (a hemisphere, a nose of revolution: one side of its
        rectangle collapsed, closed round it): ``"o"`` one block round the pole, its
        cells there triangles; ``"h"`` five blocks, a square over the pole and four
        round it (003 Fig. 5's O-to-H remapping: no cell touches the pole; three
        blocks meet at each of four points; a face sharing the rim is cut where the
        blocks meet it). A sphere is two caps.
    progress : callable(done, total), optional

    Returns
    -------
    GridResult

    Raises
    ------
    InvalidGeometryError
        Bad arguments, face indices out of range, or no face that can be gridded.
    """
    started = time.perf_counter()
    items, names, skipped, model_size = _faces_of(obj)
    if faces is not None:
        bad = [k for k in faces if not 0 <= k < len(items)]
        if bad:
            raise InvalidGeometryError(f"face indices {bad} out of range 0..{len(items) - 1}")
        chosen = list(dict.fromkeys(faces))
    else:
        chosen = list(range(len(items)))
    unreadable = {k for k, _ in skipped}
    gap = DEFAULT_RELATIVE_GAP * model_size if gap is None else float(gap)
    if not np.isfinite(gap) or gap <= 0:
        raise InvalidGeometryError(f"gap must be a positive length, got {gap!r}")
    if pole_caps not in POLE_CAPS:
        raise InvalidGeometryError(f"pole_caps must be one of {', '.join(POLE_CAPS)}, got {pole_caps!r}")
    surfaces, kept, kept_names, flips = [], [], [], []
    skipped = [s for s in skipped if s[0] in chosen]
    for k in chosen:
        item = items[k]
        if k in unreadable or item is None:
            continue
        surface = item if isinstance(item, NurbsSurface) else item.surface
        if surface.dimension != 3:
            skipped.append((k, "not a 3D surface"))
            continue
        flip = not isinstance(item, NurbsSurface) and bool(item.reversed)
        # a surface's rectangle (a sphere's: a block round each pole), or the face's regions
        regions = face_regions(item, gap_tol=gap, pole_caps=pole_caps) \
            if not isinstance(item, NurbsSurface) else None
        if isinstance(regions, str):
            if not whole_surfaces:
                skipped.append((k, regions))
                continue
            regions = None
        if regions is None:
            regions = rectangle_regions(surface, pole_caps=pole_caps, clockwise=flip)
        name = names[k] if k < len(names) else None
        for n, region in enumerate(regions):
            if region.is_rectangle:             # the surface's rectangle, or half of it
                region = reversed_v(region.surface) if flip else region.surface
            surfaces.append(region)
            kept.append(k)
            kept_names.append(name if len(regions) == 1 or name is None else f"{name}_{n}")
            # a loop's region is oriented by the loop's direction
            flips.append(flip and isinstance(region, NurbsSurface))
    if not surfaces:
        why = "; ".join(f"face {k}: {r}" for k, r in skipped[:3])
        raise InvalidGeometryError(f"nothing to grid: no four-sided face ({why})" if why
                                   else "nothing to grid")
    held = _assign_held(surfaces, list(hold), gap)
    network = grid_network(surfaces, gap=gap, dims=dims, size=size, spacing=spacing,
                           smooth=smooth, orthogonal=orthogonal, tol=tol, max_sweeps=max_sweeps,
                           hold=held,
                           progress=progress)
    skipped += [(kept[b], why) for b, why in network.failed]
    # a block cut to conform with its neighbours: its pieces named in order
    pieces = {b: network.indices.count(b) for b in set(network.indices)}
    seen: dict[int, int] = {}
    names_out = []
    for b in network.indices:
        name = kept_names[b]
        if pieces[b] > 1 and name is not None:
            name = f"{name}_{seen.get(b, 0)}"
        seen[b] = seen.get(b, 0) + 1
        names_out.append(name)
    return GridResult(network, tuple(kept[b] for b in network.indices), tuple(names_out),
                      tuple(flips[b] for b in network.indices), tuple(sorted(skipped)),
                      time.perf_counter() - started)
