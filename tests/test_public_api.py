"""The public facade: every advertised name resolves, and numpy-only use does not load OCP."""

from __future__ import annotations

import subprocess
import sys

import surfprep


def test_every_public_name_resolves():
    for name in surfprep.__all__:
        assert getattr(surfprep, name) is not None, name
    assert set(surfprep.__all__) <= set(dir(surfprep))


def test_unknown_name_raises_attribute_error():
    try:
        surfprep.no_such_thing  # noqa: B018
    except AttributeError as exc:
        assert "no_such_thing" in str(exc)
    else:
        raise AssertionError("unknown attribute did not raise")


def test_numpy_only_import_does_not_load_opencascade():
    code = ("import sys, surfprep; s = surfprep.NurbsCurve([[0, 0], [1, 1]], [0, 0, 1, 1], 1);"
            "s.evaluate(0.5); print('OCP' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_errors_derive_from_builtin_types():
    assert issubclass(surfprep.InputFileError, OSError)
    assert issubclass(surfprep.InvalidGeometryError, ValueError)
    assert issubclass(surfprep.ConversionError, TypeError)
    assert issubclass(surfprep.NoFacesError, surfprep.InputFileError)
    for name in ("InvalidGeometryError", "InputFileError", "OpenCascadeError", "OutputFileError"):
        assert issubclass(getattr(surfprep, name), surfprep.SurfprepError)


def test_all_is_a_literal_list_and_the_lazy_names_are_typed():
    """IDEs and type checkers read ``__all__`` without running the module, and see the
    lazily loaded names through the ``if TYPE_CHECKING:`` imports."""
    import ast
    from pathlib import Path

    source = Path(surfprep.__file__).read_text()
    tree = ast.parse(source)
    (assign,) = [n for n in tree.body if isinstance(n, ast.Assign)
                 and any(getattr(t, "id", None) == "__all__" for t in n.targets)]
    assert isinstance(assign.value, ast.List)
    assert all(isinstance(e, ast.Constant) and isinstance(e.value, str) for e in assign.value.elts)
    typed = {alias.asname or alias.name
             for node in tree.body if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
             for imp in node.body if isinstance(imp, ast.ImportFrom) for alias in imp.names}
    assert set(surfprep._LAZY_EXPORTS) <= typed
    assert (Path(surfprep.__file__).parent / "py.typed").is_file()


def test_every_verb_returns_geometry_and_a_report():
    import numpy as np

    from surfprep.algorithms.fitting import interpolate_surface

    t = np.linspace(0, 1, 6)
    u, v = np.meshgrid(t, t, indexing="ij")
    sheet = interpolate_surface(np.stack([u, v, 0.1 * u * v], axis=-1))
    plane = interpolate_surface(np.stack([u, 0.5 + 0 * v, v - 0.5], axis=-1))
    cut = surfprep.intersect(sheet, plane, tol=1e-7)
    assert isinstance(cut, surfprep.IntersectionResult) and cut.geometry == list(cut)
    assert cut.report()["n_curves"] == len(cut) == 1 and cut.time_s > 0 and cut.tol == 1e-7
    even = surfprep.reparametrize(sheet, tol=1e-4)
    assert isinstance(even, surfprep.ReparametrizeResult)
    assert isinstance(even.geometry, surfprep.NurbsSurface)
    assert even.report()["max_deviation"] <= 1e-4
    assert isinstance(surfprep.HealResult.geometry, property)
