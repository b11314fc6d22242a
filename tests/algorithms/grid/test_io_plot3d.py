"""Plot3D grid files (algorithms/grid/io/plot3d.py): the byte layout, exact round trips through
``read_plot3d`` and through VTK's independent ``vtkMultiBlockPLOT3DReader``, and the refusals
that leave no file behind."""

from __future__ import annotations

import os
import struct

import numpy as np
import pytest

from surfprep.algorithms.grid.io import plot3d as plot3d_module
from surfprep.algorithms.grid.io import read_plot3d, write_plot3d


def two_blocks() -> list[np.ndarray]:
    """Two blocks of different sizes sharing a side, with awkward doubles (1/3, 0.1, -0.0,
    1e-300, 1e300) so that a lossy print or a transposed order shows."""
    u = np.linspace(0.0, 1.0, 5)
    v = np.linspace(0.0, 1.0, 4) ** 2 / 3.0
    a = np.stack([*np.meshgrid(u, v, indexing="ij"), np.full((5, 4), 0.1)], axis=-1)
    b = np.stack([*np.meshgrid(1.0 + u[:3] * 0.7, v, indexing="ij"), np.sin(np.arange(12.0)).reshape(3, 4)],
                 axis=-1)
    a[0, 0, 2], a[1, 0, 2], a[2, 0, 2] = -0.0, 1e-300, 1e300
    return [a, b]


def read_with_vtk(path, *, binary: bool) -> list[np.ndarray]:
    """The blocks as VTK's Plot3D reader sees them (multi-grid, 3-D, whole, double, little-endian)."""
    vtk_parallel = pytest.importorskip("vtkmodules.vtkIOParallel")
    from vtkmodules.util.numpy_support import vtk_to_numpy

    reader = vtk_parallel.vtkMultiBlockPLOT3DReader()
    reader.SetXYZFileName(str(path))
    reader.AutoDetectFormatOff()
    reader.SetMultiGrid(1)
    reader.SetBinaryFile(int(binary))
    reader.SetHasByteCount(int(binary))
    reader.SetByteOrderToLittleEndian()
    reader.SetDoublePrecision(1)
    reader.SetIBlanking(0)
    reader.SetTwoDimensionalGeometry(0)
    reader.SetForceRead(0)
    reader.Update()
    output = reader.GetOutput()
    blocks = []
    for k in range(output.GetNumberOfBlocks()):
        grid = output.GetBlock(k)
        dims = [0, 0, 0]
        grid.GetDimensions(dims)
        points = vtk_to_numpy(grid.GetPoints().GetData())
        assert dims[2] == 1 and points.dtype == np.float64
        blocks.append(points.reshape(dims[1], dims[0], 3).transpose(1, 0, 2))   # VTK: i fastest
    return blocks


def assert_same_blocks(got, expected):
    assert len(got) == len(expected)
    for g, e in zip(got, expected, strict=True):
        assert g.shape == e.shape and g.dtype == np.float64
        np.testing.assert_array_equal(g, e)


def assert_nothing_written(folder):
    assert list(folder.iterdir()) == []


# ------------------------------------------------------------------ layout
def test_unformatted_layout_is_fortran_records_int32_then_float64(tmp_path):
    blocks = two_blocks()
    path = write_plot3d(tmp_path / "grid.xyz", blocks, binary=True)
    data = path.read_bytes()
    assert struct.unpack_from("<3i", data, 0) == (4, 2, 4)
    assert struct.unpack_from("<8i", data, 12) == (24, 5, 4, 1, 3, 4, 1, 24)
    pos = 12 + 32
    for block in blocks:
        ni, nj = block.shape[:2]
        size = 3 * ni * nj * 8
        assert struct.unpack_from("<i", data, pos)[0] == size
        values = np.frombuffer(data, dtype="<f8", count=3 * ni * nj, offset=pos + 4)
        assert values[1] == block[1, 0, 0] and values[ni] == block[0, 1, 0]          # i fastest, then j
        assert values[ni * nj] == block[0, 0, 1] and values[2 * ni * nj] == block[0, 0, 2]   # x, y, z
        np.testing.assert_array_equal(values, np.concatenate([block[..., c].ravel("F") for c in range(3)]))
        assert struct.unpack_from("<i", data, pos + 4 + size)[0] == size
        pos += size + 8
    assert pos == len(data)


def test_formatted_layout_counts_dimensions_then_x_y_z_per_block(tmp_path):
    blocks = two_blocks()
    text = write_plot3d(tmp_path / "grid.fmt", blocks).read_text()
    lines = text.splitlines()
    assert lines[:3] == ["2", "5 4 1", "3 4 1"]
    assert all(1 <= len(line.split()) <= 4 for line in lines[3:])
    values = np.array(" ".join(lines[3:]).split(), dtype=np.float64)
    expected = np.concatenate([np.concatenate([b[..., c].ravel("F") for c in range(3)]) for b in blocks])
    np.testing.assert_array_equal(values, expected)
    assert "0.10000000000000001" in text                     # %.17g, not a shortened 0.1


# ------------------------------------------------------------------ round trips
@pytest.mark.parametrize("binary", [False, True], ids=["formatted", "unformatted"])
def test_round_trip_through_read_plot3d_is_exact(tmp_path, binary):
    blocks = two_blocks()
    path = write_plot3d(tmp_path / "grid.xyz", blocks, binary=binary)
    got = read_plot3d(path)
    assert_same_blocks(got, blocks)
    assert np.signbit(got[0][0, 0, 2])                      # -0.0 kept


@pytest.mark.parametrize("binary", [False, True], ids=["formatted", "unformatted"])
def test_vtk_plot3d_reader_reads_the_same_coordinates(tmp_path, binary):
    blocks = two_blocks()
    path = write_plot3d(tmp_path / "grid.xyz", blocks, binary=binary)
    assert_same_blocks(read_with_vtk(path, binary=binary), blocks)


def test_single_block_and_integer_input(tmp_path):
    block = np.arange(2 * 3 * 3).reshape(2, 3, 3)
    path = write_plot3d(tmp_path / "one.xyz", [block], binary=True)
    assert_same_blocks(read_plot3d(path), [block.astype(float)])


def test_reader_accepts_big_endian_single_precision_and_fortran_exponents(tmp_path):
    block = two_blocks()[1].astype(np.float32).astype(np.float64)
    values = np.concatenate([block[..., c].ravel("F") for c in range(3)])

    def record(payload: bytes) -> bytes:
        return struct.pack(">i", len(payload)) + payload + struct.pack(">i", len(payload))

    big = record(struct.pack(">i", 1)) + record(struct.pack(">3i", 3, 4, 1)) + record(values.astype(">f4").tobytes())
    (tmp_path / "big.x").write_bytes(big)
    assert_same_blocks(read_plot3d(tmp_path / "big.x"), [block])
    text = "1\n3 4 1\n" + "\n".join(f"{v:.17E}".replace("E", "D") for v in values) + "\n"
    (tmp_path / "fortran.fmt").write_text(text)
    assert_same_blocks(read_plot3d(tmp_path / "fortran.fmt"), [block])


# ------------------------------------------------------------------ bad files
@pytest.mark.parametrize(("content", "message"), [
    (b"not a grid at all", "not a Plot3D grid file"),
    (b"1\n2 2 1\n0 1 0 1 0 0 1 1 0 0 0\n", "need 12 coordinates, found 11"),
    (b"1\n2 2 3\n" + b"0 " * 36, "nk = 3"),
    (struct.pack("<3i", 4, 1, 4) + struct.pack("<i", 12) + struct.pack("<3i", 2, 2, 1), "truncated"),
    (struct.pack("<3i", 4, 1, 4) + struct.pack("<5i", 12, 2, 2, 1, 12) + struct.pack("<i", 16) + bytes(16)
     + struct.pack("<i", 16), "block 0 record has 16 bytes"),
    (struct.pack("<3i", 4, 2, 4) + struct.pack("<5i", 12, 2, 2, 1, 12), "record 2 should hold 2"),
], ids=["text", "short", "nk", "truncated", "size", "dims"])
def test_read_refuses_what_is_not_such_a_plot3d_file(tmp_path, content, message):
    (tmp_path / "bad.xyz").write_bytes(content)
    with pytest.raises(ValueError, match=message):
        read_plot3d(tmp_path / "bad.xyz")


# ------------------------------------------------------------------ bad input, nothing written
@pytest.mark.parametrize(("blocks", "error", "message"), [
    ([np.zeros((3, 4))], ValueError, r"block 0: expected an array of shape \(ni, nj, 3\), got shape \(3, 4\)"),
    ([np.zeros((3, 4, 2))], ValueError, r"got shape \(3, 4, 2\)"),
    ([np.zeros((2, 2, 3)), np.zeros((1, 4, 3))], ValueError, "block 1 has 1 x 4 nodes; a block needs at least 2"),
    ([np.zeros((3, 4, 3), dtype=complex)], ValueError, "got dtype complex128"),
    ([], ValueError, "no blocks to write"),
    (np.zeros((3, 4, 3)), ValueError, r"blocks is one array of shape \(3, 4, 3\); pass a sequence"),
    (7, TypeError, "blocks must be a sequence"),
], ids=["2d", "2comp", "one-node", "complex", "empty", "bare-array", "int"])
@pytest.mark.parametrize("binary", [False, True], ids=["formatted", "unformatted"])
def test_bad_blocks_raise_before_any_file_appears(tmp_path, blocks, error, message, binary):
    with pytest.raises(error, match=message):
        write_plot3d(tmp_path / "grid.xyz", blocks, binary=binary)
    assert_nothing_written(tmp_path)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_coordinate_is_named_and_nothing_is_written(tmp_path, value):
    blocks = two_blocks()
    blocks[1][2, 3, 1] = value
    with pytest.raises(ValueError, match=rf"block 1 has a non-finite coordinate: y = {value} at node "
                                         r"\(i, j\) = \(2, 3\)"):
        write_plot3d(tmp_path / "grid.xyz", blocks)
    assert_nothing_written(tmp_path)


def test_binary_must_be_a_bool(tmp_path):
    with pytest.raises(TypeError, match="binary must be True or False, got 'yes'"):
        write_plot3d(tmp_path / "grid.xyz", two_blocks(), binary="yes")
    assert_nothing_written(tmp_path)


def test_missing_folder_raises_and_writes_nothing(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_plot3d(tmp_path / "no" / "grid.xyz", two_blocks())
    assert_nothing_written(tmp_path)


def test_target_that_is_a_folder_raises(tmp_path):
    (tmp_path / "grid.xyz").mkdir()
    with pytest.raises(IsADirectoryError):
        write_plot3d(tmp_path / "grid.xyz", two_blocks())
    assert [p.name for p in tmp_path.iterdir()] == ["grid.xyz"]


@pytest.mark.parametrize("binary", [False, True], ids=["formatted", "unformatted"])
def test_failure_while_writing_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch, binary):
    path = write_plot3d(tmp_path / "grid.xyz", two_blocks(), binary=binary)
    before = path.read_bytes()

    def half_then_fail(target, blocks):
        target.write_bytes(b"half a file")
        raise OSError("disk full")

    monkeypatch.setattr(plot3d_module, "_write_unformatted" if binary else "_write_formatted", half_then_fail)
    with pytest.raises(OSError, match="disk full"):
        write_plot3d(path, [np.ones((2, 2, 3))], binary=binary)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["grid.xyz"]


def test_rewrite_replaces_the_file_with_the_umask_mode(tmp_path):
    path = write_plot3d(tmp_path / "grid.xyz", two_blocks())
    write_plot3d(path, [np.ones((2, 2, 3))])
    assert_same_blocks(read_plot3d(path), [np.ones((2, 2, 3))])
    umask = os.umask(0o022)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask
