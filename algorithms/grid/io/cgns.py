"""Structured CGNS grid files in the HDF5 form, written with h5py.

The tree follows the CGNS SIDS (Standard Interface Data Structures: ch. 6 CGNSBase_t and
Zone_t, ch. 7 GridCoordinates_t, ch. 8 GridConnectivity1to1_t) for a structured surface
grid, mapped onto HDF5 as the CGNS/HDF5 file mapping (cgns.github.io, "CGNS/HDF5") and the
reference library's ``src/adfh/ADFH.c`` lay it out:

* every CGNS node is an HDF5 group with the attributes ``name`` and ``label`` (scalar
  null-terminated strings of 33 bytes), ``type`` (3 bytes: ``MT``, ``I4``, ``I8``, ``R4``,
  ``R8``, ``C1``) and ``flags`` (int32, one value); its data, if any, is the child dataset
  ``" data"``; strings (``C1``) are int8 arrays without a terminator;
* arrays are stored with their dimensions reversed: a SIDS (Fortran-ordered) array of
  dimensions ``(n1, n2)`` is an HDF5 (C-ordered) dataset of shape ``(n2, n1)``, which the
  root dataset ``" hdf5version"`` announces;
* the root group has ``name``/``label``/``type`` and the datasets ``" format"`` and
  ``" hdf5version"``; links are tracked in creation order (the reference library lists
  children in that order).

The tree::

    CGNSLibraryVersion   CGNSLibraryVersion_t  R4 [4.0]
    Base                 CGNSBase_t            I4 [CellDimension 2, PhysicalDimension 3]
      Zone1              Zone_t                I4 (2, 3): vertices, cells, boundary vertices
                                                  (HDF5: [[ni, nj], [ni-1, nj-1], [0, 0]])
        ZoneType         ZoneType_t            C1 "Structured"
        GridCoordinates  GridCoordinates_t     MT
          CoordinateX/Y/Z  DataArray_t         R8 (ni, nj), i fastest
        ZoneGridConnectivity  ZoneGridConnectivity_t  MT   (if the zone has interfaces)
          Interface<n>_<side>  GridConnectivity1to1_t  C1 donor zone name
            Transform        "int[IndexDimension]"  I4 (2)
            PointRange       IndexRange_t     I4 (2, 2): begin and end (i, j), 1-based
            PointRangeDonor  IndexRange_t     I4 (2, 2)

Every matched pair of sides (``interfaces[n - 1]``) gives one ``GridConnectivity1to1_t``
named ``Interface<n>_<side>`` in each of its two zones (both in one zone for a block
meeting itself); its Transform is :func:`transform`, its ranges :func:`point_range`.
Periodic interfaces (``GridConnectivityProperty_t``) are not written: matched nodes must
coincide.

Note that the CGNS mid-level library lists the zones of a base sorted by name, hence the
zero-padded default names (``Zone01`` ... ``Zone12``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ....atomic_files import atomic_output
from .blocks import Interface, as_blocks, check_interfaces

if TYPE_CHECKING:                   # h5py loads when a CGNS file is written
    import h5py

__all__ = ["CGNS_VERSION", "NAME_LENGTH", "point_range", "transform", "write_cgns"]

#: the CGNS library version the file declares (CGNSLibraryVersion_t): the SIDS it follows
CGNS_VERSION = 4.0
#: the longest CGNS node name
NAME_LENGTH = 32


def write_cgns(path: str | os.PathLike, blocks: Sequence[ArrayLike], *,
               interfaces: Sequence[Interface] = (), names: Sequence[str] | None = None) -> Path:
    """Write a structured surface grid as a CGNS/HDF5 file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (usually ``.cgns``); its folder must exist. An existing file is
        replaced; on any failure it is left as it was and no temporary file is left behind.
    blocks : sequence of (ni, nj, 3) array_like of float
        The blocks, ``ni, nj >= 2``, finite coordinates; block ``k`` is zone ``names[k]``
        of the base ``Base`` (CellDimension 2, PhysicalDimension 3).
    interfaces : sequence of Interface
        Matched sides, each pair once; each becomes a ``GridConnectivity1to1_t`` in both
        zones. The two sides must have the same node count and the matched nodes must
        coincide to 1e-9 times the block size.
    names : sequence of str, optional
        Zone names: ASCII, 1 to 32 characters, no ``/``, no leading or trailing space,
        distinct. Default ``Zone1``, ``Zone2``... zero-padded to the width of the count, so
        that the CGNS library, which lists zones sorted by name, lists them in block order.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        Bad blocks, bad names, or an interface that does not match (see
        :func:`~surfprep.algorithms.grid.io.blocks.check_interfaces`).
    TypeError
        ``blocks`` not a sequence, or an entry of ``interfaces`` not an :class:`Interface`.
    FileNotFoundError
        The folder of ``path`` does not exist.
    """
    import h5py
    checked = as_blocks(blocks)
    faces = check_interfaces(checked, interfaces)
    zone_names = _zone_names(names, len(checked))
    connections: list[list[tuple[str, str, NDArray, NDArray, NDArray]]] = [[] for _ in checked]
    for n, face in enumerate(faces):
        for a, side, b, other_side in ((face.block, face.side, face.other, face.other_side),
                                       (face.other, face.other_side, face.block, face.side)):
            shape_a, shape_b = checked[a].shape[:2], checked[b].shape[:2]
            donor = point_range(shape_b, other_side)
            if face.reversed:
                donor = donor[:, ::-1]
            connections[a].append((f"Interface{n + 1}_{side}", zone_names[b], transform(side, other_side,
                                   bool(face.reversed)), point_range(shape_a, side), donor))
    with atomic_output(path) as temporary, \
            h5py.File(temporary, "w", libver=("earliest", "v108"), track_order=True) as root:
        _write_root(root)
        _node(root, "CGNSLibraryVersion", "CGNSLibraryVersion_t", "R4", np.array([CGNS_VERSION], dtype="<f4"))
        base = _node(root, "Base", "CGNSBase_t", "I4", np.array([2, 3], dtype="<i4"))
        for block, name, links in zip(checked, zone_names, connections, strict=True):
            _write_zone(base, name, block, links)
    return Path(path)


def point_range(shape: tuple[int, int], side: str) -> NDArray[np.int64]:
    """The SIDS ``IndexRange_t`` of a whole side: 1-based ``[[i_begin, i_end], [j_begin, j_end]]``.

    Parameters
    ----------
    shape : (int, int)
        ``(ni, nj)`` of the block.
    side : str
        ``"i0"``, ``"i1"``, ``"j0"`` or ``"j1"``.

    Returns
    -------
    (2, 2) ndarray of int64
        Row ``d`` holds the begin and end index in direction ``d`` (Fortran order: the
        HDF5 dataset is its transpose, ``[[i_begin, j_begin], [i_end, j_end]]``).
    """
    ni, nj = shape
    begin, end = {"i0": ((1, 1), (1, nj)), "i1": ((ni, 1), (ni, nj)),
                  "j0": ((1, 1), (ni, 1)), "j1": ((1, nj), (ni, nj))}[side]
    return np.array([begin, end], dtype=np.int64).T


def transform(side: str, other_side: str, reversed_: bool) -> NDArray[np.int32]:
    """The SIDS ``Transform`` of a 1-to-1 interface from ``side`` to the donor's ``other_side``.

    ``Transform[d] = ±e`` says that index direction ``d + 1`` of this zone runs along
    index direction ``e`` of the donor, the same way (+) or the opposite way (-).
    Along the interface the directions match unless ``reversed_``; across it, going into
    this zone is going out of the donor, so the directions agree when one side is at the
    start of its index range and the other at the end.

    Parameters
    ----------
    side, other_side : str
        ``"i0"``, ``"i1"``, ``"j0"`` or ``"j1"``.
    reversed_ : bool
        Whether the donor's side runs the other way.

    Returns
    -------
    (2,) ndarray of int32
    """
    along = {"i": 2, "j": 1}          # the index running along an i-side is j (2), along a j-side i (1)
    across = {"i": 1, "j": 2}
    out = np.zeros(2, dtype=np.int32)
    out[along[side[0]] - 1] = (-1 if reversed_ else 1) * along[other_side[0]]
    out[across[side[0]] - 1] = (1 if side[1] != other_side[1] else -1) * across[other_side[0]]
    return out


def _zone_names(names: Sequence[str] | None, count: int) -> list[str]:
    if names is None:
        width = len(str(count))
        return [f"Zone{k + 1:0{width}d}" for k in range(count)]
    if isinstance(names, str) or len(names) != count:
        raise ValueError(f"names must be a sequence of {count} zone names, one per block")
    out = list(names)
    for k, name in enumerate(out):
        if not isinstance(name, str) or not 1 <= len(name) <= NAME_LENGTH or not name.isascii() \
                or not name.isprintable() or "/" in name or name != name.strip() or name == ".":
            raise ValueError(f"zone name {k} {name!r} is not a CGNS node name: 1 to {NAME_LENGTH} printable "
                             f"ASCII characters, no '/', no leading or trailing space")
        if name in out[:k]:
            raise ValueError(f"zone name {name!r} is given to blocks {out.index(name)} and {k}")
    return out


def _write_zone(base: h5py.Group, name: str, block: NDArray,
                links: list[tuple[str, str, NDArray, NDArray, NDArray]]) -> None:
    ni, nj = block.shape[:2]
    sizes = np.array([[ni, nj], [ni - 1, nj - 1], [0, 0]]).T      # SIDS (IndexDimension, 3)
    zone = _node(base, name, "Zone_t", *_integers(sizes))
    _node(zone, "ZoneType", "ZoneType_t", "C1", _chars("Structured"))
    coordinates = _node(zone, "GridCoordinates", "GridCoordinates_t", "MT")
    for c, axis in enumerate("XYZ"):
        _node(coordinates, f"Coordinate{axis}", "DataArray_t", "R8", block[:, :, c])
    if not links:
        return
    connectivity = _node(zone, "ZoneGridConnectivity", "ZoneGridConnectivity_t", "MT")
    for link_name, donor, transform_, receiver, donor_range in links:
        link = _node(connectivity, link_name, "GridConnectivity1to1_t", "C1", _chars(donor))
        _node(link, "Transform", '"int[IndexDimension]"', "I4", transform_.astype("<i4"))
        _node(link, "PointRange", "IndexRange_t", *_integers(receiver))
        _node(link, "PointRangeDonor", "IndexRange_t", *_integers(donor_range))


def _write_root(root: h5py.File) -> None:
    import h5py
    _string_attribute(root, "name", "HDF5 MotherNode", NAME_LENGTH + 1)
    _string_attribute(root, "label", "Root Node of HDF5 File", NAME_LENGTH + 1)
    _string_attribute(root, "type", "MT", 3)
    root.create_dataset(" format", data=_chars("IEEE_LITTLE_32\0"))
    version = f"HDF5 Version {h5py.version.hdf5_version}".encode("ascii").ljust(NAME_LENGTH + 1, b"\0")
    root.create_dataset(" hdf5version", data=np.frombuffer(version, dtype=np.int8))


def _node(parent: h5py.Group, name: str, label: str, data_type: str,
          data: NDArray | None = None) -> h5py.Group:
    """A CGNS node: a group with its attributes and, for a SIDS array ``data``, the dataset
    ``" data"`` holding it with the dimensions reversed (the C view of a Fortran array)."""
    group = parent.create_group(name, track_order=True)
    _string_attribute(group, "name", name, NAME_LENGTH + 1)
    _string_attribute(group, "label", label, NAME_LENGTH + 1)
    _string_attribute(group, "type", data_type, 3)
    group.attrs.create("flags", np.array([1], dtype="<i4"))
    if data is not None:
        dtype = {"I4": "<i4", "I8": "<i8", "R4": "<f4", "R8": "<f8", "C1": "i1"}[data_type]
        group.create_dataset(" data", data=np.ascontiguousarray(np.asarray(data).T, dtype=dtype))
    return group


def _string_attribute(group: h5py.Group, name: str, value: str, size: int) -> None:
    """A scalar fixed-size null-terminated ASCII string attribute (HDF5 ``H5T_C_S1``)."""
    import h5py
    string_type = h5py.h5t.C_S1.copy()
    string_type.set_size(size)
    string_type.set_strpad(h5py.h5t.STR_NULLTERM)
    attribute = h5py.h5a.create(group.id, name.encode("ascii"), string_type,
                                h5py.h5s.create(h5py.h5s.SCALAR))
    attribute.write(np.array(value.encode("ascii").ljust(size, b"\0")[:size], dtype=f"S{size}"),
                    mtype=string_type)


def _chars(text: str) -> NDArray[np.int8]:
    return np.frombuffer(text.encode("ascii"), dtype=np.int8)


def _integers(array: NDArray) -> tuple[str, NDArray]:
    """``("I4", array)`` if every value fits in int32, else ``("I8", array)``."""
    fits = np.abs(np.asarray(array)).max() < 2**31
    return ("I4", np.asarray(array, dtype="<i4")) if fits else ("I8", np.asarray(array, dtype="<i8"))
