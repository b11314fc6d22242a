"""Reading a CGNS file with the CGNS mid-level library itself, through ctypes.

The library is the copy VTK's wheel ships (``vtkmodules/libvtkcgns.so``, functions
prefixed ``vtkcgns_``); the tests that use it are skipped where it is not there.
:func:`read_with_cgns_library` returns what ``cg_base_read``, ``cg_zone_read``,
``cg_zone_type``, ``cg_coord_read`` and ``cg_1to1_read`` report for its one base.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest


@dataclass
class Connection:
    """One ``GridConnectivity1to1_t`` of a zone."""

    name: str
    donor: str
    begin: np.ndarray           # 1-based (i, j)
    end: np.ndarray
    donor_begin: np.ndarray
    donor_end: np.ndarray
    transform: np.ndarray


@dataclass
class Zone:
    """One zone of the base."""

    name: str
    sizes: list[int]            # ni, nj, ni-1, nj-1, 0, 0
    zone_type: int
    coordinates: np.ndarray     # (ni, nj, 3)
    connections: list[Connection]


def cgns_library() -> ctypes.CDLL:
    """VTK's copy of the CGNS library; skips the calling test where it is missing."""
    vtkmodules = pytest.importorskip("vtkmodules")
    path = Path(vtkmodules.__file__).parent / "libvtkcgns.so"
    if not path.is_file():
        pytest.skip("VTK's copy of the CGNS library (libvtkcgns.so) is not there")
    library = ctypes.CDLL(str(path))
    if not hasattr(library, "vtkcgns_cg_open"):
        pytest.skip("libvtkcgns.so does not export the CGNS mid-level API")
    library.vtkcgns_cg_get_error.restype = ctypes.c_char_p
    return library


def read_with_cgns_library(path) -> tuple[str, int, int, list[Zone]]:
    """Base name, cell and physical dimensions, and the zones, as ``cg_*`` calls return them."""
    lib = cgns_library()

    def call(function, *args):
        if getattr(lib, f"vtkcgns_{function}")(*args) != 0:
            raise AssertionError(f"{function}: {lib.vtkcgns_cg_get_error().decode()}")

    fn = ctypes.c_int()
    call("cg_open", str(path).encode(), 0, ctypes.byref(fn))          # CG_MODE_READ
    try:
        nbases = ctypes.c_int()
        call("cg_nbases", fn, ctypes.byref(nbases))
        assert nbases.value == 1
        name, cell_dim, phys_dim = ctypes.create_string_buffer(33), ctypes.c_int(), ctypes.c_int()
        call("cg_base_read", fn, 1, name, ctypes.byref(cell_dim), ctypes.byref(phys_dim))
        base_name = name.value.decode()
        probe = (ctypes.c_int32 * 18)()
        call("cg_zone_read", fn, 1, 1, name, probe)
        size_t = ctypes.c_int64 if probe[1] == 0 else ctypes.c_int32       # cgsize_t: 64 or 32 bits
        nzones = ctypes.c_int()
        call("cg_nzones", fn, 1, ctypes.byref(nzones))
        zones = []
        for z in range(1, nzones.value + 1):
            sizes, zone_type = (size_t * 9)(), ctypes.c_int()
            call("cg_zone_read", fn, 1, z, name, sizes)
            call("cg_zone_type", fn, 1, z, ctypes.byref(zone_type))
            ni, nj = sizes[0], sizes[1]
            coordinates = []
            for axis in "XYZ":
                buffer = (ctypes.c_double * (ni * nj))()
                call("cg_coord_read", fn, 1, z, f"Coordinate{axis}".encode(), 4,     # RealDouble
                     (size_t * 2)(1, 1), (size_t * 2)(ni, nj), buffer)
                coordinates.append(np.frombuffer(buffer).reshape(nj, ni).T)
            n1to1 = ctypes.c_int()
            call("cg_n1to1", fn, 1, z, ctypes.byref(n1to1))
            connections = []
            for c in range(1, n1to1.value + 1):
                link, donor = ctypes.create_string_buffer(33), ctypes.create_string_buffer(33)
                here, there, transform = (size_t * 4)(), (size_t * 4)(), (ctypes.c_int * 3)()
                call("cg_1to1_read", fn, 1, z, c, link, donor, here, there, transform)
                connections.append(Connection(link.value.decode(), donor.value.decode(), np.array(here[:2]),
                                              np.array(here[2:]), np.array(there[:2]), np.array(there[2:]),
                                              np.array(transform[:2])))
            zones.append(Zone(name.value.decode(), list(sizes[:6]), zone_type.value,
                              np.stack(coordinates, axis=-1), connections))
    finally:
        lib.vtkcgns_cg_close(fn)
    return base_name, cell_dim.value, phys_dim.value, zones
