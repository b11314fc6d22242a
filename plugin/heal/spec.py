"""Directed patches for :func:`surfprep.heal`: the paper's interactive step, declared.

A spec is JSON (a file path, or the parsed dict / list)::

    {"patches": [
        {"name": "over the fillet", "corners": [[x, y, z], [x, y, z], [x, y, z], [x, y, z]]},
        {"curves": [{"edge": [3, 0]}, {"points": [[x, y, z], ...]},
                    {"edge": [4, 2]}, {"points": [[x, y, z], ...]}]}
    ]}

Each patch is given by four corner points (four straight lines between them,
003) or by four boundary curves in loop order, each an edge reference
``[face index, edge position in the face's outer loop]`` (face indices as in
the input model's face order) or a point list (a polyline, at least two
points). The curves may run either way; they must meet end to end.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...algorithms.healing import corners_boundary
from ...algorithms.trimmed import TrimmedFace
from ...errors import InputFileError, InvalidGeometryError

__all__ = ["DirectedPatch", "read_patch_spec"]


@dataclass(frozen=True, eq=False)
class DirectedPatch:
    """One declared patch: its boundary (four curves or a ``Boundary``) and name."""

    boundary: Any
    name: str | None = None


def _load(spec: Any) -> list:
    if isinstance(spec, (str, os.PathLike)):
        path = Path(spec)
        try:
            spec = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise InputFileError(f"cannot read patch spec {path}: {exc.strerror or exc}") from None
        except json.JSONDecodeError as exc:
            raise InputFileError(f"patch spec {path} is not valid JSON: {exc}") from None
    if isinstance(spec, dict):
        spec = spec.get("patches")
    if not isinstance(spec, list):
        raise InvalidGeometryError("a patch spec is a list of patches or {\"patches\": [...]}")
    return spec


def _points(value: Any, what: str, n_min: int) -> np.ndarray:
    try:
        pts = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidGeometryError(f"{what}: expected a list of [x, y, z] points") from None
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] < n_min or not np.all(np.isfinite(pts)):
        raise InvalidGeometryError(f"{what}: expected at least {n_min} finite [x, y, z] points, "
                                   f"got shape {pts.shape}")
    return pts


def _edge_curve(ref: Any, faces: list[TrimmedFace | None], what: str):
    try:
        f, k = (int(x) for x in ref)
    except (TypeError, ValueError):
        raise InvalidGeometryError(f"{what}: an edge reference is [face, edge]") from None
    if not 0 <= f < len(faces) or faces[f] is None or not faces[f].loops:
        raise InvalidGeometryError(f"{what}: no readable face {f}")
    face = faces[f]
    edges = face.loops[face.outer_loop_index].edges
    if not 0 <= k < len(edges) or edges[k].curve3d is None:
        raise InvalidGeometryError(f"{what}: face {f} has no edge {k} with a 3D curve "
                                   f"({len(edges)} edges in its outer loop)")
    return edges[k].curve3d


def _curve(entry: Any, faces, what: str):
    if isinstance(entry, dict) and "edge" in entry:
        return _edge_curve(entry["edge"], faces, what)
    if isinstance(entry, dict) and "points" in entry:
        return _points(entry["points"], what, 2)
    return _points(entry, what, 2)


def read_patch_spec(spec: Any, faces: list[TrimmedFace | None]) -> list[DirectedPatch]:
    """Directed patches of a spec (module docstring) for a model with ``faces``."""
    out = []
    for n, entry in enumerate(_load(spec)):
        what = f"patch {n}"
        if not isinstance(entry, dict):
            raise InvalidGeometryError(f"{what}: expected an object with 'corners' or 'curves'")
        name = entry.get("name")
        if "corners" in entry:
            pts = _points(entry["corners"], f"{what} corners", 4)
            if pts.shape[0] != 4:
                raise InvalidGeometryError(f"{what}: exactly four corners, got {pts.shape[0]}")
            out.append(DirectedPatch(corners_boundary(*pts), name))
        elif "curves" in entry:
            curves = entry["curves"]
            if not isinstance(curves, list) or len(curves) != 4:
                raise InvalidGeometryError(f"{what}: exactly four curves")
            out.append(DirectedPatch([_curve(c, faces, f"{what} curve {k}")
                                      for k, c in enumerate(curves)], name))
        else:
            raise InvalidGeometryError(f"{what}: needs 'corners' or 'curves'")
    return out
