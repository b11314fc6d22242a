"""Atomic file output: write to a temporary file beside the target, then ``os.replace``.

A reader of the target sees the old file or the whole new one, never a half-written
file; on any failure the temporary is removed and the target is left as it was. Beside
:mod:`surfprep.errors` (standard library only): the geometry's writers, the CLI's
reports and the batch summaries all use it, and a batch parent or ``--help`` does not
load numpy for it.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["atomic_output", "new_file_mode", "write_text"]


@contextmanager
def atomic_output(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it onto ``path`` when the block succeeds.

    Parameters
    ----------
    path : str or os.PathLike
        The target file. Its folder must exist; an existing file is replaced.

    Yields
    ------
    Path
        An empty temporary file in the target's folder, for the caller to write (it may be
        reopened or truncated by name). On leaving the block normally it gets the mode a
        new file gets under the umask, is flushed to disk and replaces ``path``; on an
        exception it is deleted and ``path`` is untouched.

    Raises
    ------
    FileNotFoundError
        The target's folder does not exist.
    IsADirectoryError
        The target is a folder.
    """
    target = Path(path)
    if target.is_dir():
        raise IsADirectoryError(f"cannot write {target}: it is a folder")
    folder = target.absolute().parent
    if not folder.is_dir():
        raise FileNotFoundError(f"cannot write {target}: folder {folder} does not exist")
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    os.close(fd)
    temporary = Path(name)
    try:
        yield temporary
        os.chmod(temporary, new_file_mode())
        with open(temporary, "rb+") as stream:
            os.fsync(stream.fileno())
        os.replace(temporary, target)
    finally:
        temporary.unlink(missing_ok=True)


def new_file_mode() -> int:
    """Permission bits of a newly created file under the process umask (0o644 for umask 022).

    ``tempfile.mkstemp`` creates files readable by the owner only; the outputs get the
    mode ``open()`` would have given them. The umask is read from ``/proc`` (changing it
    to read it would race with other threads); 0o644 where that is not available.
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    return 0o644


def write_text(path: str | os.PathLike, text: str, *, newline: str | None = None) -> Path:
    """``text`` written to ``path`` atomically (:func:`atomic_output`), UTF-8.

    ``newline`` as :func:`open` (``""`` for CSV). Returns ``path``; raises ``OSError``
    (the callers say which output failed).
    """
    with atomic_output(path) as temporary, \
            open(temporary, "w", encoding="utf-8", newline=newline) as stream:
        stream.write(text)
    return Path(path)
