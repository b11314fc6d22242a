"""VTK XML structured grids (algorithms/grid/io/vts.py), read back with VTK's own readers
(``vtkXMLStructuredGridReader``, ``vtkXMLMultiBlockDataReader``): extents, exact points in
VTK's i-fastest order, point and cell data on the right nodes and cells, and the refusals
that leave no file behind."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.grid.io import write_vtm, write_vts

vtk_xml = pytest.importorskip("vtkmodules.vtkIOXML")
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersCore import vtkCellCenters


def surface_block(ni: int = 5, nj: int = 4, shift: float = 0.0) -> np.ndarray:
    u = np.linspace(0.0, 1.0, ni) + shift
    v = np.linspace(0.0, 2.0, nj) ** 2 / 3.0
    uu, vv = np.meshgrid(u, v, indexing="ij")
    return np.stack([uu, vv, np.sin(uu + 3 * vv) + 0.1], axis=-1)


def read_vts(path):
    reader = vtk_xml.vtkXMLStructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def vtk_points(grid) -> np.ndarray:
    """The points of a VTK structured grid as an (ni, nj, 3) array."""
    dims = [0, 0, 0]
    grid.GetDimensions(dims)
    assert dims[2] == 1
    points = vtk_to_numpy(grid.GetPoints().GetData())
    assert points.dtype == np.float64
    return points.reshape(dims[1], dims[0], 3).transpose(1, 0, 2)


@pytest.mark.parametrize("binary", [True, False], ids=["base64", "ascii"])
def test_vts_points_and_extent_read_back_exactly(tmp_path, binary):
    block = surface_block()
    path = write_vts(tmp_path / "b.vts", block, binary=binary)
    assert 'WholeExtent="0 4 0 3 0 0"' in path.read_text()
    grid = read_vts(path)
    assert grid.GetNumberOfPoints() == 20 and grid.GetNumberOfCells() == 12
    np.testing.assert_array_equal(vtk_points(grid), block)


@pytest.mark.parametrize("binary", [True, False], ids=["base64", "ascii"])
def test_point_and_cell_data_sit_on_their_nodes_and_cells(tmp_path, binary):
    block = surface_block()
    ni, nj = block.shape[:2]
    centroids = 0.25 * (block[:-1, :-1] + block[1:, :-1] + block[:-1, 1:] + block[1:, 1:])
    distance = np.linalg.norm(block, axis=-1)
    distance[1, 2] = np.nan                                      # data may hold NaN
    point_data = {"distance": distance, "normal": block * 2.0, "node id": np.arange(ni * nj).reshape(ni, nj)}
    cell_data = {"centroid x": centroids[..., 0], "centroid": centroids}
    grid = read_vts(write_vts(tmp_path / "b.vts", block, point_data=point_data, cell_data=cell_data,
                              binary=binary))
    for name, values in point_data.items():
        array = vtk_to_numpy(grid.GetPointData().GetArray(name))
        ncomp = 1 if values.ndim == 2 else values.shape[2]
        got = array.reshape(nj, ni, ncomp).transpose(1, 0, 2)
        np.testing.assert_array_equal(got, values.reshape(ni, nj, ncomp))
    assert vtk_to_numpy(grid.GetPointData().GetArray("node id")).dtype == np.int64
    # independent of the ordering convention: VTK's own cell centres (the mean of the four
    # corners, as here) carry the cell data written for them
    centres = vtkCellCenters()
    centres.SetInputData(grid)
    centres.Update()
    vtk_centres = vtk_to_numpy(centres.GetOutput().GetPoints().GetData())
    np.testing.assert_allclose(vtk_to_numpy(grid.GetCellData().GetArray("centroid")), vtk_centres, rtol=1e-15)
    np.testing.assert_allclose(vtk_to_numpy(grid.GetCellData().GetArray("centroid x")), vtk_centres[:, 0],
                               rtol=1e-15)


def test_vtm_writes_one_vts_per_block_in_the_blocks_folder(tmp_path):
    blocks = [surface_block(), surface_block(3, 4, shift=1.0), surface_block(2, 2, shift=2.0)]
    skew = [np.full((b.shape[0] - 1, b.shape[1] - 1), float(k)) for k, b in enumerate(blocks)]
    path = write_vtm(tmp_path / "wing.vtm", blocks, cell_data=[{"skewness": s} for s in skew],
                     names=["upper", "lower & tip", "cap"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["wing.vtm", "wing_blocks"]
    assert sorted(p.name for p in (tmp_path / "wing_blocks").iterdir()) == ["block1.vts", "block2.vts",
                                                                             "block3.vts"]
    reader = vtk_xml.vtkXMLMultiBlockDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    output = reader.GetOutput()
    assert output.GetNumberOfBlocks() == 3
    for k, block in enumerate(blocks):
        assert output.GetMetaData(k).Get(output.NAME()) == ["upper", "lower & tip", "cap"][k]
        grid = output.GetBlock(k)
        np.testing.assert_array_equal(vtk_points(grid), block)
        np.testing.assert_array_equal(vtk_to_numpy(grid.GetCellData().GetArray("skewness")), skew[k].ravel())


def test_vtm_default_names_and_zero_padded_files(tmp_path):
    blocks = [surface_block(2, 3, shift=k) for k in range(11)]
    path = write_vtm(tmp_path / "g.vtm", blocks, binary=False)
    files = sorted(p.name for p in (tmp_path / "g_blocks").iterdir())
    assert files[0] == "block01.vts" and files[-1] == "block11.vts"
    reader = vtk_xml.vtkXMLMultiBlockDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    output = reader.GetOutput()
    assert [output.GetMetaData(k).Get(output.NAME()) for k in range(11)] == [f"Block{k + 1}" for k in range(11)]
    np.testing.assert_array_equal(vtk_points(output.GetBlock(10)), blocks[10])


# ------------------------------------------------------------------ bad input, nothing written
@pytest.mark.parametrize(("kwargs", "error", "message"), [
    ({"point_data": {"d": np.zeros((4, 5))}}, ValueError, r"PointData array 'd': expected .* shape \(5, 4\)"),
    ({"cell_data": {"s": np.zeros((5, 4))}}, ValueError, r"CellData array 's': expected .* shape \(4, 3\)"),
    ({"cell_data": {"s": np.zeros((4, 3), dtype=complex)}}, ValueError, "complex128"),
    ({"point_data": {"": np.zeros((5, 4))}}, ValueError, "array names must be non-empty strings"),
    ({"point_data": [np.zeros((5, 4))]}, TypeError, "PointData: expected a mapping"),
    ({"binary": 1}, TypeError, "binary must be True or False"),
], ids=["point-shape", "cell-shape", "complex", "empty-name", "not-mapping", "binary"])
def test_bad_data_raise_before_any_file_appears(tmp_path, kwargs, error, message):
    with pytest.raises(error, match=message):
        write_vts(tmp_path / "b.vts", surface_block(), **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_nan_coordinate_or_bad_block_writes_nothing(tmp_path):
    block = surface_block()
    block[4, 0, 0] = np.nan
    with pytest.raises(ValueError, match=r"block has a non-finite coordinate: x = nan at node \(i, j\) = \(4, 0\)"):
        write_vts(tmp_path / "b.vts", block)
    with pytest.raises(ValueError, match="block 1 has a non-finite coordinate"):
        write_vtm(tmp_path / "g.vtm", [surface_block(), block])
    with pytest.raises(ValueError, match="block has 1 x 4 nodes"):
        write_vts(tmp_path / "b.vts", np.zeros((1, 4, 3)))
    assert list(tmp_path.iterdir()) == []                 # not even the _blocks folder


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"names": ["only one"]}, "names must be 2 strings, one per block"),
    ({"point_data": [None]}, "point_data must be a sequence of 2 mappings"),
    ({"cell_data": {"s": np.zeros((4, 3))}}, "cell_data must be a sequence of 2 mappings"),
    ({"cell_data": [None, {"s": np.zeros((4, 3))}]}, r"CellData array 's': expected a real array of shape \(2, 3\)"),
])
def test_vtm_refuses_per_block_input_that_does_not_fit_and_writes_nothing(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match=message):
        write_vtm(tmp_path / "g.vtm", [surface_block(), surface_block(3, 4)], **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_missing_folder_raises(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_vts(tmp_path / "no" / "b.vts", surface_block())
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_vtm(tmp_path / "no" / "g.vtm", [surface_block()])
    assert list(tmp_path.iterdir()) == []


def test_failed_rewrite_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    path = write_vts(tmp_path / "b.vts", surface_block())
    before = path.read_bytes()

    class Unprintable:                                   # fails while the text is being built
        def __array__(self, dtype=None, copy=None):
            raise RuntimeError("cannot convert")

    with pytest.raises(RuntimeError, match="cannot convert"):
        write_vts(path, surface_block(3, 3), point_data={"bad": Unprintable()})
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["b.vts"]


def test_vtm_target_that_is_a_folder_raises_before_any_block_file(tmp_path):
    (tmp_path / "g.vtm").mkdir()
    with pytest.raises(IsADirectoryError, match="it is a folder"):
        write_vtm(tmp_path / "g.vtm", [surface_block()])
    assert [p.name for p in tmp_path.iterdir()] == ["g.vtm"]
