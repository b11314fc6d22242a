"""Kernels compiled on first call (:mod:`surfprep.algorithms.jit`).

numba is imported when a kernel is first called, not when the geometry package
is imported, and a small call takes the numpy form rather than pay numba's loading
(``jit.compiled``); a kernel calling another inside compiled code sees it typed as
the dispatcher it stands for.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from surfprep.algorithms import basis_kernels, jit
from surfprep.algorithms.surface import NurbsSurface

_PROBE = """
import json, sys
import numpy as np
import surfprep.algorithms as alg
from surfprep.algorithms.parametrization import parametrization_quality
s = alg.NurbsSurface(control_points=np.random.default_rng(1).random((5, 6, 3)),
                     knots_u=[0, 0, 0, 0, .5, 1, 1, 1, 1], knots_v=[0, 0, 0, .25, .5, .75, 1, 1, 1],
                     degree_u=3, degree_v=2)
s.derivatives_grid(np.linspace(0, 1, 30), np.linspace(0, 1, 20), 2)
parametrization_quality(s)
before = [m for m in ("numba", "scipy") if m in sys.modules]
small = s.derivatives([0.2, 0.7], [0.1, 0.9], 1)   # a few scattered points: numpy, no numba
middle = [m for m in ("numba", "scipy") if m in sys.modules]
rng = np.random.default_rng(2)
u, v = rng.random(20000), rng.random(20000)
large = s.derivatives(u, v, 1)                      # many: the compiled kernel, numba loaded
after = [m for m in ("numba", "scipy") if m in sys.modules]
again = s.derivatives([0.2, 0.7], [0.1, 0.9], 1)    # small again: compiled, its price paid
print(json.dumps({"before": before, "middle": middle, "after": after,
                  "same": float(np.max(np.abs(small - again)))}))
"""


def test_numba_is_imported_by_the_first_large_kernel_call_not_before():
    done = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True,
                          timeout=300, check=True)
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["before"] == []                   # grids and the figure: numpy alone
    assert found["middle"] == []                   # a small scattered call: numpy too
    assert "numba" in found["after"]
    assert found["same"] < 1e-12                   # the two forms agree


def test_a_call_takes_the_compiled_form_when_large_or_when_numba_is_loaded(monkeypatch):
    monkeypatch.setattr(jit, "AVAILABLE", True)
    monkeypatch.delitem(sys.modules, "numba", raising=False)
    assert not jit.compiled(jit.COMPILE_FROM - 1) and jit.compiled(jit.COMPILE_FROM)
    monkeypatch.setitem(sys.modules, "numba", object())
    assert jit.compiled(1)
    monkeypatch.setattr(jit, "AVAILABLE", False)
    assert not jit.compiled(10 * jit.COMPILE_FROM)


def test_a_lazy_kernel_wraps_its_function_and_compiles_on_demand():
    kernel = basis_kernels.ders_one
    assert isinstance(kernel, jit.LazyKernel)
    assert kernel.py_func.__name__ == "ders_one" and kernel.__wrapped__ is kernel.py_func
    assert kernel.dispatcher is kernel.dispatcher           # compiled once, then reused
    assert "compiled" in repr(kernel) and "not yet" not in repr(kernel)


def test_numba_types_a_lazy_kernel_as_its_dispatcher():
    numba = pytest.importorskip("numba")
    kernel = basis_kernels.ders_one
    assert numba.typeof(kernel) == numba.typeof(kernel.dispatcher)


def test_a_kernel_calling_a_lazy_kernel_agrees_with_numpy():
    """``surface_derivatives_compiled`` calls ``ders_one`` inside compiled code."""
    rng = np.random.default_rng(4)
    s = NurbsSurface(control_points=rng.random((6, 5, 3)), weights=0.5 + rng.random((6, 5)),
                     knots_u=[0, 0, 0, 0, .4, .7, 1, 1, 1, 1], knots_v=[0, 0, 0, .3, .6, 1, 1, 1],
                     degree_u=3, degree_v=2)
    u, v = rng.random(50), rng.random(50)
    scattered = s.derivatives(u, v, 2)                                   # compiled
    on_grid = np.stack([s.derivatives_grid(u[i:i + 1], v[i:i + 1], 2)[0, 0]
                        for i in range(50)])                             # numpy basis
    np.testing.assert_allclose(scattered, on_grid, rtol=1e-12, atol=1e-12)
