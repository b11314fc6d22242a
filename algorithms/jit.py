"""Compilation of the hot loops: numba's ``njit`` with an on-disk cache, or nothing.

Every ``*_kernels.py`` module of :mod:`surfprep.algorithms` decorates its loops
with :func:`jit` and keeps a numpy form of each beside it (the reference the
tests compare against, and the fallback). ``AVAILABLE`` is False when numba
cannot be imported; the callers use their numpy forms then.

The kernels are compiled on first use and cached on disk (``cache=True``): a
cold first call (no cache) costs about a second per kernel, a warm one (cache
present) a few milliseconds. They release the GIL (``nogil=True``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

try:                                    # numba is optional: the numpy forms remain
    import numba
except ImportError:                     # pragma: no cover - numba is installed in CI
    numba = None

__all__ = ["AVAILABLE", "jit"]

#: True when numba is importable and :func:`jit` compiles
AVAILABLE = numba is not None

F = TypeVar("F", bound=Callable)


def jit(fn: F) -> F:
    """``numba.njit(cache=True, nogil=True)(fn)``, or ``fn`` itself without numba."""
    return numba.njit(cache=True, nogil=True)(fn) if AVAILABLE else fn
