"""Structured surface-grid blocks and the interfaces between them, as the grid writers take them.

A block is a float array of shape ``(ni, nj, 3)``: node ``(i, j)`` at ``block[i, j]``.
Its four sides are named ``"i0"`` (the nodes with ``i == 0``), ``"i1"`` (``i == ni - 1``),
``"j0"`` (``j == 0``) and ``"j1"`` (``j == nj - 1``); the nodes of a side run in the
order of the index that varies along it (``j`` on an i-side, ``i`` on a j-side).
An :class:`Interface` says that a whole side of one block is a whole side of another
(or of the same) block, node for node, the same way round or reversed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["SIDES", "Interface", "as_block", "as_blocks", "check_interfaces", "side_nodes"]

#: the side names, in the order i0, i1, j0, j1
SIDES = ("i0", "i1", "j0", "j1")


@dataclass(frozen=True)
class Interface:
    """A whole side of block ``block`` matching a whole side of block ``other``.

    Parameters
    ----------
    block, other : int
        Indices of the two blocks in the list of blocks (may be equal: a block meeting itself,
        e.g. the seam of an O-grid).
    side, other_side : str
        ``"i0"``, ``"i1"``, ``"j0"`` or ``"j1"``.
    reversed : bool
        False: node ``k`` of ``side`` is node ``k`` of ``other_side``; True: it is node
        ``n - 1 - k`` (``n`` nodes along the side).

    Raises
    ------
    ValueError
        A negative block index, an unknown side name, or a side matched with itself.
    TypeError
        A block index that is not an int, or ``reversed`` not a bool.
    """

    block: int
    side: str
    other: int
    other_side: str
    reversed: bool = False

    def __post_init__(self) -> None:
        for field, value in (("block", self.block), ("other", self.other)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                raise TypeError(f"Interface.{field} must be a block index (int), got {value!r}")
            if value < 0:
                raise ValueError(f"Interface.{field} must be a block index (>= 0), got {value}")
        for field, value in (("side", self.side), ("other_side", self.other_side)):
            if value not in SIDES:
                raise ValueError(f"Interface.{field} must be one of {', '.join(SIDES)}, got {value!r}")
        if not isinstance(self.reversed, (bool, np.bool_)):
            raise TypeError(f"Interface.reversed must be a bool, got {self.reversed!r}")
        if self.block == self.other and self.side == self.other_side:
            raise ValueError(f"Interface matches side {self.side} of block {self.block} with itself")


def as_block(block: ArrayLike, *, index: int | None = None) -> NDArray[np.float64]:
    """One block, checked, as a C-ordered ``(ni, nj, 3)`` float64 array (``block`` itself if it is one).

    Parameters
    ----------
    block : (ni, nj, 3) array_like of float
        Node coordinates, ``ni >= 2`` and ``nj >= 2``, all finite.
    index : int, optional
        The block's position in a multi-block grid, named in the error messages.

    Returns
    -------
    (ni, nj, 3) ndarray of float64

    Raises
    ------
    ValueError
        Not a real numeric array, wrong shape, fewer than 2 nodes in a direction, or a
        NaN/inf coordinate (the message names the first such node).
    """
    what = "block" if index is None else f"block {index}"
    array = np.asarray(block)
    if array.dtype.kind not in "iuf":
        raise ValueError(f"{what}: expected a real numeric array of shape (ni, nj, 3), "
                         f"got dtype {array.dtype}")
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{what}: expected an array of shape (ni, nj, 3), got shape {array.shape}")
    ni, nj = array.shape[:2]
    if ni < 2 or nj < 2:
        raise ValueError(f"{what} has {ni} x {nj} nodes; a block needs at least 2 nodes in i and in j")
    out = np.ascontiguousarray(array, dtype=np.float64)
    bad = ~np.isfinite(out)
    if bad.any():
        i, j, c = np.argwhere(bad)[0]
        raise ValueError(f"{what} has a non-finite coordinate: {'xyz'[c]} = {out[i, j, c]} at node "
                         f"(i, j) = ({i}, {j})")
    return out


def as_blocks(blocks: Sequence[ArrayLike]) -> list[NDArray[np.float64]]:
    """The blocks of a multi-block grid, each checked by :func:`as_block`.

    Parameters
    ----------
    blocks : sequence of (ni, nj, 3) array_like of float
        At least one block; the blocks may differ in size.

    Returns
    -------
    list of (ni, nj, 3) ndarray of float64

    Raises
    ------
    ValueError
        No block, a single ``(ni, nj, 3)`` array given instead of a sequence of blocks, or a
        bad block.
    TypeError
        ``blocks`` is not a sequence.
    """
    if isinstance(blocks, np.ndarray) and blocks.ndim == 3:
        raise ValueError(f"blocks is one array of shape {blocks.shape}; pass a sequence of blocks "
                         f"(e.g. [block]) of shape (ni, nj, 3) each")
    if isinstance(blocks, (str, bytes)) or not hasattr(blocks, "__len__"):
        raise TypeError(f"blocks must be a sequence of (ni, nj, 3) arrays, got {type(blocks).__name__}")
    if len(blocks) == 0:
        raise ValueError("no blocks to write: blocks is empty")
    return [as_block(block, index=k) for k, block in enumerate(blocks)]


def side_nodes(block: NDArray, side: str) -> NDArray:
    """The nodes of one side of a block, in the order of the index running along it.

    Parameters
    ----------
    block : (ni, nj, 3) ndarray of float
    side : str
        ``"i0"``, ``"i1"``, ``"j0"`` or ``"j1"``.

    Returns
    -------
    (nj, 3) or (ni, 3) ndarray of float
        A view: ``block[0]``, ``block[-1]``, ``block[:, 0]`` or ``block[:, -1]``.
    """
    if side not in SIDES:
        raise ValueError(f"side must be one of {', '.join(SIDES)}, got {side!r}")
    return {"i0": block[0], "i1": block[-1], "j0": block[:, 0], "j1": block[:, -1]}[side]


def check_interfaces(blocks: Sequence[NDArray], interfaces: Sequence[Interface], *,
                     rtol: float = 1e-9) -> tuple[Interface, ...]:
    """Check that every interface joins two existing sides node for node.

    Parameters
    ----------
    blocks : sequence of (ni, nj, 3) ndarray of float
        Checked blocks (:func:`as_blocks`).
    interfaces : sequence of Interface
        Each matched pair of sides once (not once per direction).
    rtol : float
        Matched nodes must coincide to ``rtol`` times the larger bounding-box diagonal of
        the two blocks.

    Returns
    -------
    tuple of Interface

    Raises
    ------
    ValueError
        A block index out of range, a side used by two interfaces, sides of different node
        counts, or matched nodes apart (the message names the interface and the node).
    TypeError
        An entry that is not an :class:`Interface`.
    """
    if isinstance(interfaces, Interface):
        raise TypeError("interfaces must be a sequence of Interface records; got a single Interface")
    checked = tuple(interfaces)
    used: dict[tuple[int, str], int] = {}
    for n, face in enumerate(checked):
        if not isinstance(face, Interface):
            raise TypeError(f"interface {n} is a {type(face).__name__}, not an Interface")
        for b in (face.block, face.other):
            if b >= len(blocks):
                raise ValueError(f"interface {n} refers to block {b}, but there are {len(blocks)} blocks")
        for key in ((face.block, face.side), (face.other, face.other_side)):
            if key in used:
                raise ValueError(f"side {key[1]} of block {key[0]} is in interfaces {used[key]} and {n}; "
                                 f"give each matched pair of sides once (both directions are implied)")
            used[key] = n
        here = side_nodes(blocks[face.block], face.side)
        there = side_nodes(blocks[face.other], face.other_side)
        if len(here) != len(there):
            raise ValueError(f"interface {n}: side {face.side} of block {face.block} has {len(here)} nodes "
                             f"but side {face.other_side} of block {face.other} has {len(there)}")
        if face.reversed:
            there = there[::-1]
        size = max(_diagonal(blocks[face.block]), _diagonal(blocks[face.other]))
        gap = np.linalg.norm(here - there, axis=1)
        k = int(np.argmax(gap))
        if gap[k] > rtol * size:
            raise ValueError(f"interface {n}: node {k} of side {face.side} of block {face.block} is "
                             f"{gap[k]:.3g} from its match on side {face.other_side} of block {face.other} "
                             f"(reversed={bool(face.reversed)}); allowed {rtol:g} x block size {size:.3g}")
    return checked


def _diagonal(block: NDArray) -> float:
    points = block.reshape(-1, 3)
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
