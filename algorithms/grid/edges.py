"""The edges two blocks of a network share: their nodes in each block, moved from one to
the other, and how the blocks lie on either side.

Used by the network's gridding and snapping (:mod:`.network`) and by the sliding of the
shared nodes (:mod:`.sliding`). A side is named as in :mod:`.structured` (``"i0"``:
``i = 0``, ``"j1"``: ``j = nj - 1``); a side's nodes are given by their normalized
parameters along it (:class:`.region.Side`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError
from .io.blocks import Interface, side_nodes
from .region import Region
from .structured import SurfaceGrid

__all__ = ["LOOP_DIRECTION", "SIDE_INDEX", "SMOOTH_INTERFACE", "crease", "inner_line", "on_seam",
           "same_orientation", "set_side_parameters", "side_parameters", "transfer"]

#: an interface whose surfaces' normals differ by more than this (degrees) is a crease:
#: its nodes do not slide and its kink is not counted in the summary
SMOOTH_INTERFACE = 15.0
#: a side as ``(axis, index)`` of a block's node array: ``block[index]`` (axis 0) or
#: ``block[:, index]`` (axis 1)
SIDE_INDEX = {"i0": (0, 0), "i1": (0, -1), "j0": (1, 0), "j1": (1, -1)}
#: direction of each side in its block's boundary loop (counter-clockwise in (i, j))
LOOP_DIRECTION = {"j0": 1, "i1": 1, "j1": -1, "i0": -1}


def transfer(region_a: Region, side_a: str, fractions_a: NDArray, region_b: Region, side_b: str,
             reverse: bool) -> NDArray:
    """Normalized parameters on side ``b`` of the nodes of side ``a`` (their nearest points).

    Raises InvalidGeometryError when the feet are not in order.
    """
    points = region_a.sides[side_a].points(fractions_a)
    if reverse:
        points = points[::-1]
    t = region_b.sides[side_b].locate(points)
    t[0], t[-1] = 0.0, 1.0
    t = np.clip(t, 0.0, 1.0)
    if np.any(np.diff(t) <= 0.0):
        raise InvalidGeometryError(f"the nodes of a shared edge do not project in order onto side {side_b}")
    return t


def side_parameters(grid: SurfaceGrid, side: str) -> NDArray:
    """Normalized parameters of a gridded block's side nodes along that side."""
    return np.asarray(grid.side_params[side], dtype=float)


def on_seam(blocks: list[SurfaceGrid], f: Interface) -> bool:
    """The interface is a block's own seam, solved across by its elliptic step (:mod:`.periodic`)."""
    seam = blocks[f.block].seam
    return f.block == f.other and seam is not None and {f.side, f.other_side} == (
        {"i0", "i1"} if seam.axis == 0 else {"j0", "j1"})


def set_side_parameters(params: NDArray, region: Region, side: str, values: NDArray) -> None:
    """Put a side's nodes, given by normalized side parameters, into a block's ``(u, v)``
    (inside the domain: a trimmed face's pcurves may run off it by a rounding)."""
    u0, u1, v0, v1 = region.surface.domain
    uv = np.clip(region.sides[side].uv(values), [u0, v0], [u1, v1])
    axis, index = SIDE_INDEX[side]
    if axis == 0:
        params[index] = uv
    else:
        params[:, index] = uv


def inner_line(block: NDArray, side: str, depth: int = 1) -> NDArray:
    """The line of nodes ``depth`` steps inside a side."""
    axis, index = SIDE_INDEX[side]
    inner = depth if index == 0 else -1 - depth
    return block[inner] if axis == 0 else block[:, inner]


def same_orientation(f: Interface) -> bool:
    """True when the two blocks of an interface are oriented alike (their boundary
    loops run along the shared edge in opposite directions)."""
    along = LOOP_DIRECTION[f.side] * LOOP_DIRECTION[f.other_side] * (-1 if f.reversed else 1)
    return along == -1


def crease(surfaces, blocks: list[SurfaceGrid], f: Interface) -> float:
    """Largest angle (degrees) between the two surfaces' normals along an interface,
    the second block's taken with the first's orientation."""
    from .polar import surface_normals as normals
    ends = []
    for block, side in ((f.block, f.side), (f.other, f.other_side)):
        uv = side_nodes(blocks[block].parameters, side)
        ends.append(blocks[block].orientation * normals(surfaces[block].surface, uv[:, 0], uv[:, 1]))
    na, nb = ends
    if f.reversed:
        nb = nb[::-1]
    if not same_orientation(f):
        nb = -nb
    cos = np.clip(np.einsum("ij,ij->i", na, nb), -1.0, 1.0)
    return float(np.degrees(np.arccos(cos)).max())
