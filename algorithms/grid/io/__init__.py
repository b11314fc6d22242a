"""Writers of structured surface grids: Plot3D, VTK XML (``.vts``/``.vtm``) and CGNS/HDF5.

A block is a ``(ni, nj, 3)`` float array (node ``(i, j)`` at ``block[i, j]``); a
multi-block grid is a sequence of blocks; :class:`Interface` records say which whole
sides of blocks coincide node for node. Every file is written atomically (a temporary
file beside the target, then ``os.replace``): a failure leaves the target as it was and
no temporary behind.

* :func:`write_plot3d` / :func:`read_plot3d`: multi-block 3-D whole Plot3D, ``k = 1``,
  formatted or Fortran unformatted (:mod:`.plot3d`);
* :func:`write_vts` / :func:`write_vtm`: VTK XML StructuredGrid per block, with point
  and cell data, and a multiblock index (:mod:`.vts`);
* :func:`write_cgns`: CGNS SIDS structured zones with 1-to-1 connectivity, HDF5 file
  mapping, via h5py (:mod:`.cgns`).
"""

from .blocks import SIDES, Interface, as_block, as_blocks, check_interfaces, side_nodes
from .cgns import write_cgns
from .plot3d import read_plot3d, write_plot3d
from .vts import write_vtm, write_vts

__all__ = [
    "SIDES",
    "Interface",
    "as_block",
    "as_blocks",
    "check_interfaces",
    "read_plot3d",
    "side_nodes",
    "write_cgns",
    "write_plot3d",
    "write_vtm",
    "write_vts",
]
