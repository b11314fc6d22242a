"""Compilation of the hot loops: numba's ``njit`` with an on-disk cache, or nothing.

Every ``*_kernels.py`` module of :mod:`surfprep.algorithms` decorates its loops
with :func:`jit` and keeps a numpy form of each beside it (the reference the
tests compare against, and the fallback). ``AVAILABLE`` is False when numba
cannot be found; the callers use their numpy forms then.

numba is imported when a kernel is first *called*, not when a module defining
one is imported: importing numba and loading its compilation context costs
about half a second, which a command that never reaches a hot loop (``info``,
``--help``, an error) should not pay. :func:`jit` returns a
:class:`LazyKernel`; its first call compiles it (``njit(cache=True,
nogil=True)``: from the on-disk cache in a few milliseconds when present, about
a second per kernel without) and later calls go straight to numba's dispatcher.
A kernel calling another one inside compiled code works unchanged: numba types
a :class:`LazyKernel` as the dispatcher it stands for.
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["AVAILABLE", "COMPILE_FROM", "LazyKernel", "compiled", "jit"]

#: True when numba is installed and :func:`jit` compiles (found without importing it)
AVAILABLE = importlib.util.find_spec("numba") is not None

F = TypeVar("F", bound=Callable)

#: the size of a call (the elements its numpy form handles: points, control points,
#: boxes) from which a compiled kernel is used before numba is loaded: below it the
#: numpy form is quicker than importing numba and loading the kernel (~0.4 s once)
COMPILE_FROM = 200_000


def compiled(work: int) -> bool:
    """Whether a call of size ``work`` takes the compiled kernel or its numpy form: the
    kernel when numba is available and either already loaded in this process (its
    price paid) or the call is large (``work >= COMPILE_FROM``). A one-shot command on
    a small model then never imports numba; once one large call has loaded it, every
    call is compiled."""
    return AVAILABLE and (work >= COMPILE_FROM or "numba" in sys.modules)


class LazyKernel:
    """A numba kernel compiled on its first call; calls it afterwards.

    Parameters
    ----------
    py_func : callable
        The plain Python function (numba's ``nopython`` subset).
    """

    def __init__(self, py_func: Callable) -> None:
        self.py_func = py_func
        self.__wrapped__ = py_func
        self.__name__ = py_func.__name__
        self.__qualname__ = py_func.__qualname__
        self.__doc__ = py_func.__doc__
        self._dispatcher: Any = None

    @property
    def dispatcher(self) -> Any:
        """numba's dispatcher of :attr:`py_func` (numba imported on the first access)."""
        if self._dispatcher is None:
            self._dispatcher = _numba_njit()(self.py_func)
        return self._dispatcher

    def __call__(self, *args: Any) -> Any:
        return self.dispatcher(*args)

    def __repr__(self) -> str:
        state = "compiled" if self._dispatcher is not None else "not yet compiled"
        return f"<LazyKernel {self.__qualname__} ({state})>"


def _numba_njit() -> Callable:
    """``numba.njit(cache=True, nogil=True)``, numba imported and taught :class:`LazyKernel`."""
    import numba
    from numba.extending import typeof_impl

    if LazyKernel not in typeof_impl.registry:          # once per process: typed as its dispatcher
        typeof_impl.register(LazyKernel)(_typeof_lazy_kernel)
    return numba.njit(cache=True, nogil=True)


def _typeof_lazy_kernel(value: LazyKernel, context: Any) -> Any:
    from numba.extending import typeof_impl

    return typeof_impl(value.dispatcher, context)


def jit(fn: F) -> F:
    """``fn`` as a :class:`LazyKernel` (compiled on first call), or ``fn`` itself without numba."""
    return LazyKernel(fn) if AVAILABLE else fn   # type: ignore[return-value]
