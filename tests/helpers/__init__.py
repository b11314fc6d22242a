"""One copy of each operand builder and measure the tests share (trimesh's ``tests/generic``).

* :mod:`.surfaces`: exact test surfaces (sphere band, plane patches, tori, height
  fields with bumps...) whose intersections are known;
* :mod:`.strategies`: hypothesis strategies of NURBS curves and surfaces and the
  comparisons of two of them;
* :mod:`.heal_cases`: the healing geometry (001's figure kinds, faces to decompose);
* :mod:`.measure`: intersection curves measured densely against exact answers;
* :mod:`.grid_cases`: surfaces whose structured grids are known (warped planes, a
  warped cylinder, a pole);
* :mod:`.cgns_library`: the CGNS library VTK ships, called through ctypes, to read
  back the CGNS files surfprep writes;
* :mod:`.paths`: the repository's folders (samples, stored reports);
* :mod:`.cli`: the command line run in-process.

Imported as ``from helpers.surfaces import ...`` (``tests`` is on the path, see
``[tool.pytest.ini_options]`` in ``pyproject.toml``).
"""
