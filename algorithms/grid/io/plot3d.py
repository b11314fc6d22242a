"""Plot3D grid files: multi-block, 3-D, whole (no iblank), double precision, with ``k = 1``.

This is the layout pyHyp, Pointwise and most structured CFD codes read as a
"multi-block 3-D whole double" Plot3D grid (NASA Plot3D manual, ch. 8 "Data File
Formats"; the Fortran reads are ``read nblocks``, ``read (ni(n), nj(n), nk(n), n=1,nblocks)``,
then per block ``read (((x(i,j,k), i), j), k), (((y...))), (((z...)))``):

* formatted (text): the block count, one ``ni nj 1`` line per block, then per block all
  ``x`` (``i`` fastest, then ``j``), all ``y``, all ``z``, each value as ``%.17g`` (which
  reads back to the same double), four to a line;
* unformatted (binary): Fortran sequential records, little-endian, each framed by a
  4-byte int32 byte count before and after: record 1 the block count (int32), record 2
  all the ``(ni, nj, 1)`` triples (int32), then one record per block with its ``x``,
  ``y``, ``z`` (float64).

:func:`read_plot3d` reads both forms back (and also big-endian or single-precision
unformatted files and Fortran ``1.0D+00`` exponents), for surface grids (``nk = 1``).
"""

from __future__ import annotations

import os
import struct
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ....atomic_files import atomic_output
from .blocks import as_blocks

__all__ = ["MAX_RECORD_BYTES", "read_plot3d", "write_plot3d"]

#: the largest record a 4-byte signed record marker can frame
MAX_RECORD_BYTES = 2**31 - 1
#: numbers per line of a formatted file
_PER_LINE = 4


def write_plot3d(path: str | os.PathLike, blocks: Sequence[ArrayLike], *, binary: bool = False) -> Path:
    """Write a multi-block Plot3D grid file (3-D whole form with ``k = 1``), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (usually ``.xyz``, ``.x``, ``.p3d`` or ``.fmt``); its folder
        must exist. An existing file is replaced; on any failure it is left as it was and
        no temporary file is left behind.
    blocks : sequence of (ni, nj, 3) array_like of float
        The blocks, ``ni, nj >= 2``, finite coordinates.
    binary : bool
        False: formatted (text, ``%.17g``). True: Fortran unformatted sequential records,
        little-endian, int32 record markers and counts, float64 coordinates.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        Bad blocks (shape, size, non-finite coordinates), or (binary) a block too large for
        one record (more than ``MAX_RECORD_BYTES // 24`` nodes).
    TypeError
        ``binary`` is not a bool, or ``blocks`` not a sequence.
    FileNotFoundError
        The folder of ``path`` does not exist.
    """
    if not isinstance(binary, bool):
        raise TypeError(f"binary must be True or False, got {binary!r}")
    checked = as_blocks(blocks)
    if binary:
        for k, block in enumerate(checked):
            if block.nbytes > MAX_RECORD_BYTES:
                raise ValueError(f"block {k} has {block.shape[0] * block.shape[1]} nodes, too many for one "
                                 f"Plot3D record (at most {MAX_RECORD_BYTES // 24} nodes)")
    with atomic_output(path) as temporary:
        if binary:
            _write_unformatted(temporary, checked)
        else:
            _write_formatted(temporary, checked)
    return Path(path)


def _coordinates(block: NDArray) -> NDArray:
    """All x, then all y, then all z of a block, ``i`` fastest."""
    return np.concatenate([block[:, :, c].ravel(order="F") for c in range(3)])


def _write_unformatted(path: Path, blocks: list[NDArray]) -> None:
    def record(stream, payload: bytes) -> None:
        marker = struct.pack("<i", len(payload))
        stream.write(marker)
        stream.write(payload)
        stream.write(marker)

    dims = np.array([(b.shape[0], b.shape[1], 1) for b in blocks], dtype="<i4")
    with open(path, "wb") as stream:
        record(stream, struct.pack("<i", len(blocks)))
        record(stream, dims.tobytes())
        for block in blocks:
            record(stream, _coordinates(block).astype("<f8").tobytes())


def _write_formatted(path: Path, blocks: list[NDArray]) -> None:
    row = " ".join(["%.17g"] * _PER_LINE) + "\n"
    with open(path, "w", encoding="ascii", newline="\n") as stream:
        stream.write(f"{len(blocks)}\n")
        stream.writelines(f"{block.shape[0]} {block.shape[1]} 1\n" for block in blocks)
        for block in blocks:
            for c in range(3):
                values = block[:, :, c].ravel(order="F")
                full = len(values) - len(values) % _PER_LINE
                stream.writelines(row % tuple(line) for line in values[:full].reshape(-1, _PER_LINE))
                if full < len(values):
                    stream.write(" ".join(format(v, ".17g") for v in values[full:]) + "\n")


def read_plot3d(path: str | os.PathLike) -> list[NDArray[np.float64]]:
    """Read a multi-block 3-D whole Plot3D grid file of surface blocks (``nk = 1``).

    The form is detected from the first bytes: a 4-byte record marker holding 4 (either
    byte order) means unformatted, anything else formatted.

    Parameters
    ----------
    path : str or os.PathLike
        A file written by :func:`write_plot3d` or in the same layout (unformatted: 4-byte
        markers, little- or big-endian, int32 counts, float64 or float32 coordinates).

    Returns
    -------
    list of (ni, nj, 3) ndarray of float64
        The blocks, in file order.

    Raises
    ------
    ValueError
        Not such a Plot3D file: bad or truncated records, a count that does not match the
        data, iblank data, or a block with ``nk != 1``.
    FileNotFoundError
        No such file.
    """
    data = Path(path).read_bytes()
    for order in "<>":
        if len(data) >= 12 and struct.unpack(f"{order}i", data[:4])[0] == 4 \
                and struct.unpack(f"{order}i", data[8:12])[0] == 4:
            return _read_unformatted(data, order, path)
    return _read_formatted(data, path)


def _check_dims(dims: NDArray, path: str | os.PathLike) -> None:
    for k, (ni, nj, nk) in enumerate(dims):
        if ni < 1 or nj < 1 or nk < 1:
            raise ValueError(f"{path}: block {k} has dimensions {ni} x {nj} x {nk}")
        if nk != 1:
            raise ValueError(f"{path}: block {k} has nk = {nk}; read_plot3d reads surface grids (nk = 1)")


def _block(values: NDArray, ni: int, nj: int) -> NDArray[np.float64]:
    xyz = values.astype(np.float64).reshape(3, nj, ni)        # (c, j, i): i fastest in the file
    return np.ascontiguousarray(xyz.transpose(2, 1, 0))


def _read_unformatted(data: bytes, order: str, path: str | os.PathLike) -> list[NDArray[np.float64]]:
    records = []
    pos = 0
    while pos < len(data):
        if pos + 4 > len(data):
            raise ValueError(f"{path}: truncated Plot3D record marker at byte {pos}")
        (size,) = struct.unpack_from(f"{order}i", data, pos)
        end = pos + 4 + size
        if size < 0 or end + 4 > len(data) or struct.unpack_from(f"{order}i", data, end)[0] != size:
            raise ValueError(f"{path}: record {len(records) + 1} at byte {pos} is truncated or its "
                             f"markers differ; not a Plot3D unformatted file with 4-byte markers")
        records.append(data[pos + 4:end])
        pos = end + 4
    (nblocks,) = struct.unpack(f"{order}i", records[0])
    if nblocks < 1 or len(records) < 2 or len(records[1]) != 12 * nblocks:
        raise ValueError(f"{path}: record 2 should hold {nblocks} (ni, nj, nk) triples "
                         f"(3-D whole multi-block form)")
    dims = np.frombuffer(records[1], dtype=f"{order}i4").reshape(nblocks, 3)
    _check_dims(dims, path)
    if len(records) != 2 + nblocks:
        raise ValueError(f"{path}: {nblocks} blocks announced but {len(records) - 2} coordinate records found")
    blocks = []
    for k, ((ni, nj, _), payload) in enumerate(zip(dims, records[2:], strict=True)):
        n = 3 * int(ni) * int(nj)
        if len(payload) == 8 * n:
            values = np.frombuffer(payload, dtype=f"{order}f8")
        elif len(payload) == 4 * n:
            values = np.frombuffer(payload, dtype=f"{order}f4")
        elif len(payload) in (8 * n + 4 * n // 3, 4 * n + 4 * n // 3):
            raise ValueError(f"{path}: block {k} has iblank data; read_plot3d reads whole grids (no iblank)")
        else:
            raise ValueError(f"{path}: block {k} record has {len(payload)} bytes; {ni} x {nj} nodes need "
                             f"{8 * n} (double) or {4 * n} (single)")
        blocks.append(_block(values, int(ni), int(nj)))
    return blocks


def _read_formatted(data: bytes, path: str | os.PathLike) -> list[NDArray[np.float64]]:
    try:
        tokens = data.decode("ascii").replace("D", "E").replace("d", "e").split()
        nblocks = int(tokens[0])
        dims = np.array([int(t) for t in tokens[1:1 + 3 * nblocks]], dtype=np.int64)
        values = np.array(tokens[1 + 3 * nblocks:], dtype=np.float64)
    except (UnicodeDecodeError, IndexError, ValueError):
        raise ValueError(f"{path}: not a Plot3D grid file (neither unformatted with 4-byte record "
                         f"markers nor formatted text: block count, dimensions, coordinates)") from None
    if nblocks < 1 or len(dims) != 3 * nblocks:
        raise ValueError(f"{path}: bad block count {nblocks} or missing dimensions")
    dims = dims.reshape(nblocks, 3)
    _check_dims(dims, path)
    sizes = [3 * int(ni) * int(nj) for ni, nj, _ in dims]
    if sum(sizes) != len(values):
        raise ValueError(f"{path}: {nblocks} blocks of {', '.join(f'{a} x {b}' for a, b, _ in dims)} nodes "
                         f"need {sum(sizes)} coordinates, found {len(values)}")
    starts = np.cumsum([0, *sizes])
    return [_block(values[starts[k]:starts[k + 1]], int(ni), int(nj)) for k, (ni, nj, _) in enumerate(dims)]
