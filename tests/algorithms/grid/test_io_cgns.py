"""Structured CGNS/HDF5 files (algorithms/grid/io/cgns.py), read back by two real readers:

* VTK's ``vtkCGNSReader`` (zones, their dimensions, their points);
* the CGNS mid-level library itself (``cg_open``, ``cg_base_read``, ``cg_zone_read``,
  ``cg_coord_read``, ``cg_1to1_read``), the copy VTK ships as ``libvtkcgns.so``, called
  through ctypes: base dimensions, zone sizes and type, coordinates, and every 1-to-1
  connection checked by what it means (the Transform carries each node of the range onto
  the coincident donor node, and a step out of the zone onto the donor's first inner line).

Plus the HDF5 layout of the CGNS file mapping, read with h5py, and the refusals.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from helpers.cgns_library import Connection, Zone, read_with_cgns_library

from surfprep.algorithms.grid.io import SIDES, Interface, side_nodes, write_cgns
from surfprep.algorithms.grid.io import cgns as cgns_module

pytest.importorskip("vtkmodules")


def read_with_vtk(path) -> list[tuple[str, list[int], np.ndarray]]:
    """(zone name, dimensions, (ni, nj, 3) points) of every zone, from ``vtkCGNSReader``."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOCGNSReader import vtkCGNSReader

    reader = vtkCGNSReader()
    reader.SetFileName(str(path))
    reader.UpdateInformation()
    reader.EnableAllBases()
    reader.Update()
    output = reader.GetOutput()
    assert output.GetNumberOfBlocks() == 1 and output.GetMetaData(0).Get(output.NAME()) == "Base"
    base = output.GetBlock(0)
    zones = []
    for k in range(base.GetNumberOfBlocks()):
        grid = base.GetBlock(k)
        dims = [0, 0, 0]
        grid.GetDimensions(dims)
        points = vtk_to_numpy(grid.GetPoints().GetData())
        zones.append((base.GetMetaData(k).Get(base.NAME()), dims,
                      points.reshape(dims[1], dims[0], 3).transpose(1, 0, 2)))
    return zones


# ------------------------------------------------------------------ grids
def lattice(x0: int, x1: int, y1: int) -> np.ndarray:
    """Nodes of the unit lattice [x0, x1] x [0, y1] with z = (x + 2y) / 4: exact doubles, and
    any node one step past a side is the linear extrapolation of the side."""
    x, y = np.meshgrid(np.arange(x0, x1 + 1.0), np.arange(0.0, y1 + 1.0), indexing="ij")
    return np.stack([x, y, (x + 2 * y) / 4], axis=-1)


def orient(block: np.ndarray, k: int) -> np.ndarray:
    """One of the 8 ways to lay indices on the same nodes (transpose, flip i, flip j)."""
    out = block.transpose(1, 0, 2) if k & 4 else block
    out = out[::-1] if k & 1 else out
    return np.ascontiguousarray(out[:, ::-1] if k & 2 else out)


def matching_interface(a: np.ndarray, b: np.ndarray) -> Interface:
    """The one side of ``a`` that is a side of ``b``, found node by node."""
    found = [Interface(0, s, 1, t, rev) for s in SIDES for t in SIDES for rev in (False, True)
             if len(side_nodes(a, s)) == len(side_nodes(b, t))
             and np.array_equal(side_nodes(a, s), side_nodes(b, t)[::-1] if rev else side_nodes(b, t))]
    assert len(found) == 1
    return found[0]


def two_block_grid() -> tuple[list[np.ndarray], list[Interface]]:
    a, b = lattice(0, 4, 3), orient(lattice(4, 6, 3), 6)      # b: transposed, j flipped
    return [a, b], [matching_interface(a, b)]


def check_connection(zones: dict[str, Zone], zone: Zone, c: Connection, *, exact_ghost: bool = True) -> None:
    """What a GridConnectivity1to1 means: Transform(index - begin) + donor_begin is the donor
    node at the same place, for every node of the range, and for a node one step out of
    the zone (its ghost) a node on the donor's first inner line (there, exactly where the
    ghost would be on a uniform lattice)."""
    donor = zones[c.donor]
    matrix = np.zeros((2, 2), dtype=int)
    for k, t in enumerate(c.transform):
        matrix[abs(t) - 1, k] = np.sign(t)
    assert abs(round(np.linalg.det(matrix))) == 1

    def to_donor(index):
        return matrix @ (index - c.begin) + c.donor_begin

    np.testing.assert_array_equal(to_donor(c.end), c.donor_end)
    shape = np.array(zone.coordinates.shape[:2])
    across = 0 if c.begin[0] == c.end[0] else 1
    assert c.begin[across] in (1, shape[across])
    outward = np.zeros(2, dtype=int)
    outward[across] = -1 if c.begin[across] == 1 else 1
    step = np.sign(c.end - c.begin)
    count = int(abs(c.end - c.begin).max()) + 1
    assert count == shape[1 - across]
    donor_shape = np.array(donor.coordinates.shape[:2])
    for k in range(count):
        index = c.begin + k * step
        there = to_donor(index)
        assert np.all(there >= 1) and np.all(there <= donor_shape)
        np.testing.assert_allclose(donor.coordinates[tuple(there - 1)], zone.coordinates[tuple(index - 1)],
                                   rtol=0, atol=1e-12)
        ghost = to_donor(index + outward)
        assert np.all(ghost >= 1) and np.all(ghost <= donor_shape), "the ghost falls outside the donor"
        assert np.abs(ghost - there).sum() == 1
        if exact_ghost:
            expected = 2 * zone.coordinates[tuple(index - 1)] - zone.coordinates[tuple(index - outward - 1)]
            np.testing.assert_array_equal(donor.coordinates[tuple(ghost - 1)], expected)


# ------------------------------------------------------------------ readers
def test_vtk_cgns_reader_reads_every_zone_and_its_points(tmp_path):
    blocks, interfaces = two_block_grid()
    path = write_cgns(tmp_path / "grid.cgns", blocks, interfaces=interfaces)
    zones = read_with_vtk(path)
    assert [name for name, _, _ in zones] == ["Zone1", "Zone2"]
    for (_, dims, points), block in zip(zones, blocks, strict=True):
        assert dims == [block.shape[0], block.shape[1], 1]
        np.testing.assert_array_equal(points, block)


def test_cgns_library_reads_base_zones_coordinates_and_connectivity(tmp_path):
    blocks, interfaces = two_block_grid()
    path = write_cgns(tmp_path / "grid.cgns", blocks, interfaces=interfaces, names=["wing", "flap"])
    base, cell_dim, phys_dim, zones = read_with_cgns_library(path)
    assert (base, cell_dim, phys_dim) == ("Base", 2, 3)
    assert [z.name for z in zones] == ["flap", "wing"]              # the library sorts zones by name
    by_name = {z.name: z for z in zones}
    for name, block in zip(["wing", "flap"], blocks, strict=True):
        zone = by_name[name]
        ni, nj = block.shape[:2]
        assert zone.sizes == [ni, nj, ni - 1, nj - 1, 0, 0] and zone.zone_type == 2      # Structured
        np.testing.assert_array_equal(zone.coordinates, block)
        assert len(zone.connections) == 1
        (c,) = zone.connections
        assert c.donor == ("flap" if name == "wing" else "wing")
        check_connection(by_name, zone, c)
    face = interfaces[0]
    assert by_name["wing"].connections[0].name == f"Interface1_{face.side}"
    assert by_name["flap"].connections[0].name == f"Interface1_{face.other_side}"


@pytest.mark.parametrize("b_orientation", range(8))
@pytest.mark.parametrize("a_orientation", range(8))
def test_every_pair_of_sides_and_direction_gives_a_transform_that_maps_node_to_node(
        tmp_path, a_orientation, b_orientation):
    a, b = orient(lattice(0, 4, 3), a_orientation), orient(lattice(4, 6, 3), b_orientation)
    face = matching_interface(a, b)
    path = write_cgns(tmp_path / "pair.cgns", [a, b], interfaces=[face])
    _, _, _, zones = read_with_cgns_library(path)
    by_name = {z.name: z for z in zones}
    for zone in zones:
        (c,) = zone.connections
        check_connection(by_name, zone, c)


def test_a_block_meeting_itself_has_both_directions_in_its_zone(tmp_path):
    angle = np.linspace(0.0, 2 * np.pi, 9)
    height = np.linspace(0.0, 1.0, 3)
    t, h = np.meshgrid(angle, height, indexing="ij")
    cylinder = np.stack([np.cos(t), np.sin(t), h], axis=-1)              # i0 and i1 coincide (O-grid seam)
    path = write_cgns(tmp_path / "o.cgns", [cylinder], interfaces=[Interface(0, "i1", 0, "i0", False)])
    _, _, _, zones = read_with_cgns_library(path)
    (zone,) = zones
    assert sorted(c.name for c in zone.connections) == ["Interface1_i0", "Interface1_i1"]
    for c in zone.connections:
        assert c.donor == "Zone1"
        check_connection({"Zone1": zone}, zone, c, exact_ghost=False)
    assert [name for name, _, _ in read_with_vtk(path)] == ["Zone1"]


def test_default_zone_names_keep_the_block_order_in_both_readers(tmp_path):
    blocks = [lattice(2 * k, 2 * k + 2, 1 + k % 3) for k in range(12)]
    interfaces = [Interface(k, "i1", k + 1, "i0", False) for k in range(11) if blocks[k].shape[1]
                  == blocks[k + 1].shape[1]]
    path = write_cgns(tmp_path / "row.cgns", blocks, interfaces=interfaces)
    _, _, _, zones = read_with_cgns_library(path)
    assert [z.name for z in zones] == [f"Zone{k + 1:02d}" for k in range(12)]
    for zone, block in zip(zones, blocks, strict=True):
        np.testing.assert_array_equal(zone.coordinates, block)
    vtk_zones = read_with_vtk(path)
    assert [name for name, _, _ in vtk_zones] == [z.name for z in zones]
    for (_, _, points), block in zip(vtk_zones, blocks, strict=True):
        np.testing.assert_array_equal(points, block)


# ------------------------------------------------------------------ the HDF5 file mapping
def string_attribute(obj, name: str, size: int) -> str:
    attribute = h5py.h5a.open(obj.id, name.encode())
    string_type = attribute.get_type()
    assert attribute.shape == () and isinstance(string_type, h5py.h5t.TypeStringID)
    assert string_type.get_size() == size and string_type.get_strpad() == h5py.h5t.STR_NULLTERM
    return obj.attrs[name].decode()


def test_hdf5_layout_follows_the_cgns_file_mapping(tmp_path):
    blocks, interfaces = two_block_grid()
    path = write_cgns(tmp_path / "grid.cgns", blocks, interfaces=interfaces)
    with h5py.File(path, "r") as root:
        assert string_attribute(root, "name", 33) == "HDF5 MotherNode"
        assert string_attribute(root, "label", 33) == "Root Node of HDF5 File"
        assert string_attribute(root, "type", 3) == "MT"
        assert root[" format"].dtype == np.int8 and bytes(root[" format"][()]) == b"IEEE_LITTLE_32\0"
        version = root[" hdf5version"]
        assert version.dtype == np.int8 and version.shape == (33,)
        assert bytes(version[()]).rstrip(b"\0") == f"HDF5 Version {h5py.version.hdf5_version}".encode()
        assert root["/"].id.get_create_plist().get_link_creation_order() & h5py.h5p.CRT_ORDER_TRACKED
        nodes = []
        root.visititems(lambda name, obj: nodes.append((name, obj)) if isinstance(obj, h5py.Group) else None)
        for name, group in nodes:
            assert string_attribute(group, "name", 33) == name.rsplit("/", 1)[-1]
            assert string_attribute(group, "type", 3) in ("MT", "I4", "R4", "R8", "C1")
            assert group.attrs["flags"].dtype == np.int32 and list(group.attrs["flags"]) == [1]
            assert (" data" in group) == (group.attrs["type"] != b"MT")
            assert group.id.get_create_plist().get_link_creation_order() & h5py.h5p.CRT_ORDER_TRACKED
        assert list(root) == [" format", " hdf5version", "CGNSLibraryVersion", "Base"]
        assert root["CGNSLibraryVersion/ data"].dtype == np.float32
        assert list(root["Base/ data"][()]) == [2, 3]
        for k, block in enumerate(blocks):
            zone = root[f"Base/Zone{k + 1}"]
            ni, nj = block.shape[:2]
            assert string_attribute(zone, "label", 33) == "Zone_t"
            assert zone[" data"].dtype == np.int32
            np.testing.assert_array_equal(zone[" data"][()], [[ni, nj], [ni - 1, nj - 1], [0, 0]])
            assert bytes(zone["ZoneType/ data"][()]) == b"Structured"
            for c, axis in enumerate("XYZ"):
                data = zone[f"GridCoordinates/Coordinate{axis}/ data"]
                assert data.dtype == np.float64 and data.shape == (nj, ni)     # Fortran (ni, nj) reversed
                np.testing.assert_array_equal(data[()], block[..., c].T)
            (link,) = zone["ZoneGridConnectivity"].values()
            assert string_attribute(link, "label", 33) == "GridConnectivity1to1_t"
            assert list(link) == [" data", "Transform", "PointRange", "PointRangeDonor"]
            assert string_attribute(link["Transform"], "label", 33) == '"int[IndexDimension]"'
            assert link["PointRange/ data"].shape == (2, 2)                   # [[i, j] begin, [i, j] end]


# ------------------------------------------------------------------ refusals, nothing written
@pytest.mark.parametrize(("interfaces", "error", "message"), [
    ([Interface(0, "i1", 1, "i0")], ValueError, "side i1 of block 0 has 4 nodes but side i0 of block 1 has 3"),
    ([Interface(0, "i1", 1, "j1", True)], ValueError,
     r"interface 0: node 0 of side i1 of block 0 is 3.35 from its match on side j1 of block 1 \(reversed=True\)"),
    ([Interface(0, "i1", 2, "j1")], ValueError, "interface 0 refers to block 2, but there are 2 blocks"),
    ([Interface(0, "i1", 1, "j1"), Interface(1, "j1", 0, "i1")], ValueError,
     "side j1 of block 1 is in interfaces 0 and 1; give each matched pair of sides once"),
    ([("0", "i1", 1, "j1")], TypeError, "interface 0 is a tuple, not an Interface"),
    (Interface(0, "i1", 1, "j1"), TypeError, "got a single Interface"),
], ids=["counts", "apart", "range", "twice", "tuple", "single"])
def test_bad_interfaces_raise_before_any_file_appears(tmp_path, interfaces, error, message):
    blocks, _ = two_block_grid()            # block 1's j1 side is block 0's i1 side
    with pytest.raises(error, match=message):
        write_cgns(tmp_path / "grid.cgns", blocks, interfaces=interfaces)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("kwargs", "error", "message"), [
    ({"block": -1}, ValueError, r"Interface.block must be a block index \(>= 0\), got -1"),
    ({"other": 1.0}, TypeError, r"Interface.other must be a block index \(int\), got 1.0"),
    ({"side": "k0"}, ValueError, "Interface.side must be one of i0, i1, j0, j1, got 'k0'"),
    ({"reversed": "no"}, TypeError, "Interface.reversed must be a bool"),
    ({"other": 0, "other_side": "i1"}, ValueError, "matches side i1 of block 0 with itself"),
])
def test_interface_record_checks_its_fields(kwargs, error, message):
    fields = {"block": 0, "side": "i1", "other": 1, "other_side": "i0", "reversed": False} | kwargs
    with pytest.raises(error, match=message):
        Interface(**fields)


@pytest.mark.parametrize(("names", "message"), [
    (["a"], "names must be a sequence of 2 zone names"),
    (["a", "a"], "zone name 'a' is given to blocks 0 and 1"),
    (["a", "x" * 33], "zone name 1 'x{33}' is not a CGNS node name"),
    (["a/b", "c"], "is not a CGNS node name: 1 to 32 printable ASCII characters, no '/'"),
    ([" a", "c"], "no leading or trailing space"),
    (["a", ""], "zone name 1 '' is not a CGNS node name"),
    (["a", "é"], "is not a CGNS node name"),
])
def test_bad_zone_names_raise_before_any_file_appears(tmp_path, names, message):
    blocks, interfaces = two_block_grid()
    with pytest.raises(ValueError, match=message):
        write_cgns(tmp_path / "grid.cgns", blocks, interfaces=interfaces, names=names)
    assert list(tmp_path.iterdir()) == []


def test_nan_block_or_missing_folder_writes_nothing(tmp_path):
    blocks, _ = two_block_grid()
    blocks[1][0, 1, 2] = np.inf
    with pytest.raises(ValueError, match=r"block 1 has a non-finite coordinate: z = inf at node \(i, j\) = \(0, 1\)"):
        write_cgns(tmp_path / "grid.cgns", blocks)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_cgns(tmp_path / "no" / "grid.cgns", two_block_grid()[0])
    with pytest.raises(ValueError, match="no blocks to write"):
        write_cgns(tmp_path / "grid.cgns", [])
    assert list(tmp_path.iterdir()) == []


def test_failure_inside_hdf5_writing_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    blocks, interfaces = two_block_grid()
    path = write_cgns(tmp_path / "grid.cgns", blocks, interfaces=interfaces)
    before = path.read_bytes()
    original = cgns_module._write_zone

    def fail_on_second_zone(base, name, block, links):
        if name == "Zone2":
            raise RuntimeError("interrupted")
        original(base, name, block, links)

    monkeypatch.setattr(cgns_module, "_write_zone", fail_on_second_zone)
    with pytest.raises(RuntimeError, match="interrupted"):
        write_cgns(path, [blocks[0] * 2, blocks[1] * 2])
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["grid.cgns"]
