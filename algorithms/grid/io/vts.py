"""VTK XML structured-grid files: one block per ``.vts``, several blocks under a ``.vtm``.

The layout is VTK's XML file format ("VTK File Formats", VTK User's Guide ch. 19, the
``StructuredGrid`` and ``vtkMultiBlockDataSet`` file types): a block of ``ni x nj`` nodes
is the extent ``0 ni-1 0 nj-1 0 0``, its points listed ``i`` fastest, then ``j``, as
Float64. Data arrays are inline, either ``binary`` (base64 of a UInt64 byte count then
the little-endian values, no compression) or ``ascii`` (``%.17g``, which reads back to the
same double). Point data are ``(ni, nj)`` or ``(ni, nj, ncomp)`` arrays, cell data
``(ni-1, nj-1)`` or ``(ni-1, nj-1, ncomp)``, listed in the same ``i``-fastest order.

:func:`write_vtm` writes ``<stem>.vtm`` and one ``.vts`` per block in the folder
``<stem>_blocks/`` beside it, which the ``.vtm`` names by relative path.
"""

from __future__ import annotations

import base64
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ....atomic_files import atomic_output
from .blocks import as_block, as_blocks

__all__ = ["write_vtm", "write_vts"]

_HEADER = '<?xml version="1.0"?>\n'
_FILE_TAG = '<VTKFile type="{}" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'


def write_vts(path: str | os.PathLike, block: ArrayLike, *,
              point_data: Mapping[str, ArrayLike] | None = None,
              cell_data: Mapping[str, ArrayLike] | None = None, binary: bool = True) -> Path:
    """Write one block as a VTK XML StructuredGrid file (``.vts``), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write; its folder must exist. An existing file is replaced; on any
        failure it is left as it was and no temporary file is left behind.
    block : (ni, nj, 3) array_like of float
        Node coordinates, ``ni, nj >= 2``, finite.
    point_data : mapping of str to (ni, nj) or (ni, nj, ncomp) array_like, optional
        Arrays at the nodes (e.g. a distance to the surface); real numbers, NaN allowed.
        Integer arrays are written as Int64, the others as Float64.
    cell_data : mapping of str to (ni-1, nj-1) or (ni-1, nj-1, ncomp) array_like, optional
        Arrays on the cells (e.g. skewness); cell ``(i, j)`` has the nodes ``(i..i+1, j..j+1)``.
    binary : bool
        True: base64 inline data; False: ASCII.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        A bad block, a data array of the wrong shape or type, or an empty array name.
    TypeError
        ``binary`` is not a bool, or ``point_data``/``cell_data`` not a mapping.
    FileNotFoundError
        The folder of ``path`` does not exist.
    """
    checked = as_block(block)
    text = _vts_text(checked, point_data, cell_data, binary)
    with atomic_output(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return Path(path)


def write_vtm(path: str | os.PathLike, blocks: Sequence[ArrayLike], *,
              point_data: Sequence[Mapping[str, ArrayLike] | None] | None = None,
              cell_data: Sequence[Mapping[str, ArrayLike] | None] | None = None,
              names: Sequence[str] | None = None, binary: bool = True) -> Path:
    """Write a multi-block grid as a VTK ``.vtm`` file plus one ``.vts`` per block.

    The blocks go to ``<folder of path>/<stem>_blocks/block<k>.vts`` (``k`` from 1,
    zero-padded to the width of the block count), the folder being created if needed;
    then ``path`` is written, naming them by relative path. Each file is written
    atomically; the ``.vtm`` last, so it never names a block file that is not complete.
    Other files already in the ``_blocks`` folder are left alone.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.vtm`` file to write; its folder must exist.
    blocks : sequence of (ni, nj, 3) array_like of float
        The blocks.
    point_data, cell_data : sequence of (mapping or None), optional
        Per block, the arrays of :func:`write_vts`; one entry per block.
    names : sequence of str, optional
        Block names shown by VTK readers (the ``name`` of each ``DataSet``); default
        ``Block1``, ``Block2``...
    binary : bool
        As for :func:`write_vts`.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        Bad blocks or data, or ``point_data``/``cell_data``/``names`` not one per block.
    TypeError
        As for :func:`write_vts`.
    FileNotFoundError
        The folder of ``path`` does not exist.
    IsADirectoryError
        ``path`` is a folder.
    """
    checked = as_blocks(blocks)
    count = len(checked)
    per_block_points = _per_block(point_data, count, "point_data")
    per_block_cells = _per_block(cell_data, count, "cell_data")
    names = [f"Block{k + 1}" for k in range(count)] if names is None else list(names)
    if len(names) != count or not all(isinstance(n, str) for n in names):
        raise ValueError(f"names must be {count} strings, one per block, got {names!r}")
    texts = [_vts_text(block, pd, cd, binary)
             for block, pd, cd in zip(checked, per_block_points, per_block_cells, strict=True)]
    target = Path(path)
    if target.is_dir():
        raise IsADirectoryError(f"cannot write {target}: it is a folder")
    if not target.absolute().parent.is_dir():
        raise FileNotFoundError(f"cannot write {target}: folder {target.absolute().parent} does not exist")
    folder_name = f"{target.stem}_blocks"
    folder = target.absolute().parent / folder_name
    folder.mkdir(exist_ok=True)
    width = len(str(count))
    files = [f"block{k + 1:0{width}d}.vts" for k in range(count)]
    for file, text in zip(files, texts, strict=True):
        with atomic_output(folder / file) as temporary:
            temporary.write_text(text, encoding="utf-8")
    lines = [_HEADER, _FILE_TAG.format("vtkMultiBlockDataSet"), "  <vtkMultiBlockDataSet>\n"]
    lines += [f'    <DataSet index="{k}" name={quoteattr(name)} file={quoteattr(folder_name + "/" + file)}/>\n'
              for k, (name, file) in enumerate(zip(names, files, strict=True))]
    lines += ["  </vtkMultiBlockDataSet>\n", "</VTKFile>\n"]
    with atomic_output(target) as temporary:
        temporary.write_text("".join(lines), encoding="utf-8")
    return target


def _per_block(data: Sequence | None, count: int, what: str) -> list:
    if data is None:
        return [None] * count
    if isinstance(data, Mapping) or len(data) != count:
        raise ValueError(f"{what} must be a sequence of {count} mappings (or None), one per block")
    return list(data)


def _vts_text(block: NDArray, point_data: Mapping[str, ArrayLike] | None,
              cell_data: Mapping[str, ArrayLike] | None, binary: bool) -> str:
    if not isinstance(binary, bool):
        raise TypeError(f"binary must be True or False, got {binary!r}")
    ni, nj = block.shape[:2]
    extent = f"0 {ni - 1} 0 {nj - 1} 0 0"
    points = _data_array(block, "Points", (ni, nj), binary)
    parts = [_HEADER, _FILE_TAG.format("StructuredGrid"), f'  <StructuredGrid WholeExtent="{extent}">\n',
             f'    <Piece Extent="{extent}">\n']
    for tag, data, shape in (("PointData", point_data, (ni, nj)), ("CellData", cell_data, (ni - 1, nj - 1))):
        if data is None:
            continue
        if not isinstance(data, Mapping):
            raise TypeError(f"{tag}: expected a mapping of array names to arrays, got {type(data).__name__}")
        parts.append(f"      <{tag}>\n")
        parts += [_data_array(values, name, shape, binary, what=tag) for name, values in data.items()]
        parts.append(f"      </{tag}>\n")
    parts += ["      <Points>\n", points, "      </Points>\n", "    </Piece>\n", "  </StructuredGrid>\n",
              "</VTKFile>\n"]
    return "".join(parts)


def _data_array(values: ArrayLike, name: str, shape: tuple[int, int], binary: bool,
                what: str = "") -> str:
    """One ``<DataArray>`` element of a ``(n0, n1)`` or ``(n0, n1, ncomp)`` array, ``i`` fastest."""
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"{what} array names must be non-empty strings, got {name!r}")
    array = np.asarray(values)
    if array.dtype.kind not in "biuf" or array.shape[:2] != shape or array.ndim not in (2, 3) \
            or (array.ndim == 3 and array.shape[2] < 1):
        raise ValueError(f"{what} array {name!r}: expected a real array of shape {shape} or "
                         f"{(*shape, 'ncomp')}, got shape {array.shape} of {array.dtype}")
    ncomp = 1 if array.ndim == 2 else array.shape[2]
    vtk_type, dtype = ("Int64", "<i8") if array.dtype.kind in "biu" else ("Float64", "<f8")
    flat = np.ascontiguousarray(array.swapaxes(0, 1).reshape(-1, ncomp), dtype=dtype)   # i fastest
    head = f'        <DataArray type="{vtk_type}" Name={quoteattr(name)} NumberOfComponents="{ncomp}"'
    if binary:
        raw = flat.tobytes()
        encoded = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode("ascii")
        return f'{head} format="binary">\n          {encoded}\n        </DataArray>\n'
    number = "%d" if vtk_type == "Int64" else "%.17g"
    rows = "".join("          " + " ".join(number % v for v in row) + "\n" for row in flat)
    return f'{head} format="ascii">\n{rows}        </DataArray>\n'
