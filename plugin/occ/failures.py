"""OpenCascade's exceptions, caught by what they are.

OCCT raises ``Standard_Failure`` and its many subclasses (``Standard_OutOfRange``,
``Standard_ConstructionError``, ``StdFail_NotDone``, ``Transfer_TransferFailure``,
...). OCP maps each to its own Python class deriving straight from
:class:`Exception`, *not* from ``OCP.Standard.Standard_Failure``: ``except
Standard_Failure`` lets the others through as "internal errors". Here an
OpenCascade exception is told by its class's module (``OCP...``), and
:func:`occ_failures` turns any of them into one of the package's exception types
with a message that says what failed.

>>> from surfprep.errors import OpenCascadeError
>>> with occ_failures(OpenCascadeError, "sewing failed"):   # doctest: +SKIP
...     sewing.Perform()
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from ...errors import SurfprepError

__all__ = ["describe", "is_occ_failure", "occ_failures"]


def is_occ_failure(exc: BaseException) -> bool:
    """True when ``exc`` is one of OpenCascade's exceptions (any OCP exception class)."""
    return type(exc).__module__.split(".", 1)[0] == "OCP"


def describe(exc: BaseException) -> str:
    """``exc``'s message, or its class name when OpenCascade gave none."""
    text = " ".join(str(exc).split())
    name = type(exc).__name__
    return f"{name}: {text}" if text and name not in text else (text or name)


@contextmanager
def occ_failures(error: type[SurfprepError], message: str) -> Iterator[None]:
    """Raise ``error(f"{message}: {what OpenCascade said}")`` for any OpenCascade exception
    raised inside the block; other exceptions pass unchanged."""
    try:
        yield
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise error(f"{message}: {describe(exc)}") from exc
