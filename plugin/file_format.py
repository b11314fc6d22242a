"""Which CAD exchange format a file is, and whether it looks whole, without OpenCascade.

:class:`FileFormat` names the formats surfprep reads and writes and their
extensions; :func:`sniff_format` tells them apart by their first bytes;
:func:`check_input_file` is every check of an input file that needs no
OpenCascade (so a missing, empty, truncated or wrong-type file is refused in a
fraction of a second, before OCP is even imported).
"""

from __future__ import annotations

import enum
from pathlib import Path

from ..errors import InputFileError
from .content_checks import content_problems

__all__ = ["MESH_SUFFIXES", "FileFormat", "check_input_file", "is_mesh_file", "known_suffixes",
           "sniff_format"]

#: extensions of discrete geometry read as a mesh operand: STL, Wavefront OBJ, and Plot3D
#: surface grids
MESH_SUFFIXES = (".stl", ".obj", ".xyz", ".p3d", ".x", ".g", ".grd")

_HEAD_BYTES = 4096
_TAIL_BYTES = 2048
_STEP_MAGIC = b"ISO-10303-21"
_STEP_TRAILER = b"END-ISO-10303-21"


class FileFormat(enum.Enum):
    """A CAD exchange format surfprep reads and writes."""

    STEP = "STEP"
    IGES = "IGES"

    @property
    def suffixes(self) -> tuple[str, ...]:
        """File name extensions of the format (lower case, with the dot)."""
        return _SUFFIXES[self]

    @classmethod
    def from_suffix(cls, path: str | Path) -> FileFormat | None:
        """The format a file name's extension stands for (case-insensitive), or None."""
        suffix = Path(path).suffix.lower()
        for fmt, suffixes in _SUFFIXES.items():
            if suffix in suffixes:
                return fmt
        return None


_SUFFIXES = {FileFormat.STEP: (".step", ".stp"), FileFormat.IGES: (".igs", ".iges")}


def check_input_file(file: Path, *, content: bool = True) -> FileFormat:
    """The format of the STEP/IGES file ``file`` after the checks that need no OpenCascade:
    it exists, is a regular non-empty file with a known extension, its content is of that
    format (signature at the start, trailer at the end: not truncated) and holds nothing
    that crashes or hangs OpenCascade's readers (:func:`.content_checks.content_problems`;
    left out with ``content=False``: it reads the whole file, about 0.1 s per MB).

    Raises
    ------
    InputFileError
        Saying which check failed.
    """
    if not file.exists():
        raise InputFileError(f"input file {file} does not exist")
    if file.is_dir():
        raise InputFileError(f"input {file} is a directory, not a STEP/IGES file")
    if not file.is_file():
        raise InputFileError(f"input {file} is not a regular file")
    fmt = FileFormat.from_suffix(file)
    if fmt is None:
        raise InputFileError(
            f"input file {file} has unknown extension {file.suffix!r}; "
            f"expected one of {known_suffixes()}")
    try:
        size = file.stat().st_size
        with file.open("rb") as stream:
            head = stream.read(_HEAD_BYTES)
            stream.seek(max(0, size - _TAIL_BYTES))
            tail = stream.read()
    except OSError as exc:
        raise InputFileError(f"cannot open input file {file}: {exc.strerror or exc}") from None
    if size == 0:
        raise InputFileError(f"input file {file} is empty (0 bytes)")
    content = sniff_format(head)
    if content is None:
        raise InputFileError(
            f"input file {file} is not a {fmt.value} file (no {_format_signature(fmt)} "
            "at its start): corrupt or of another type")
    if content is not fmt:
        raise InputFileError(
            f"input file {file} holds {content.value} data but is named {file.suffix}; "
            f"rename it to {content.suffixes[0]}")
    if not _has_trailer(content, tail):
        raise InputFileError(
            f"{fmt.value} file {file} is truncated (no {_format_trailer(fmt)} at its end)")
    if not content:
        return fmt
    try:
        problems = content_problems(file.read_bytes(), fmt.value)
    except OSError as exc:
        raise InputFileError(f"cannot read input file {file}: {exc.strerror or exc}") from None
    if problems:
        raise InputFileError(f"{fmt.value} file {file} is corrupt: " + "; ".join(problems))
    return fmt


def known_suffixes() -> str:
    return ", ".join(s for fmt in FileFormat for s in fmt.suffixes)


def _format_signature(fmt: FileFormat) -> str:
    return ("'ISO-10303-21;' header" if fmt is FileFormat.STEP
            else "80-column start/global section record")


def _format_trailer(fmt: FileFormat) -> str:
    return "'END-ISO-10303-21;' line" if fmt is FileFormat.STEP else "terminate (T) record"


def sniff_format(head: bytes) -> FileFormat | None:
    """The format the first bytes of a file are written in, or None if neither.

    STEP (ISO 10303-21) files start with ``ISO-10303-21``; IGES files are
    80-column records whose column 73 holds the section letter (``S`` start,
    ``G`` global) and columns 74-80 a sequence number.
    """
    text = head.removeprefix(b"\xef\xbb\xbf")
    if text.lstrip(b" \t\r\n").startswith(_STEP_MAGIC):
        return FileFormat.STEP
    if b"\x00" in head:
        return None
    first = text.lstrip(b"\r\n").split(b"\n", 1)[0].rstrip(b"\r")
    if len(first) >= 73 and first[72:73] in (b"S", b"G") and first[73:80].strip().isdigit():
        return FileFormat.IGES
    return None


def _has_trailer(fmt: FileFormat, tail: bytes) -> bool:
    if fmt is FileFormat.STEP:
        return _STEP_TRAILER in tail
    lines = [ln.rstrip(b"\r") for ln in tail.split(b"\n") if ln.strip()]
    return bool(lines) and len(lines[-1]) >= 73 and lines[-1][72:73] == b"T"


def is_mesh_file(path: str | Path) -> bool:
    """True for a path whose extension is one of :data:`MESH_SUFFIXES`."""
    return Path(path).suffix.lower() in MESH_SUFFIXES
