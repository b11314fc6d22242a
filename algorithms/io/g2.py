"""GoTools ``.g2`` text files of spline curves, surfaces and volumes.

The layout, from GoTools' documentation of the format ("The g2-format, GoTools file
format for geometry entities": ``SplineCurve``, ``SplineSurface``, ``SplineVolume``)
and as Splipy's ``splipy/io/g2.py`` reads and writes it::

    700 1 0 0          header: class type (100 curve, 200 surface, 700 volume),
                       major version 1, minor version 0, auxiliary data 0
                       (4: four colour integers 0-255 follow, which are skipped)
    3 1                dimension of the space, rational (1) or not (0)
    3 3                per parameter direction: number of coefficients n, order
    0 0 0 1 1 1          (degree + 1), and the n + order knots (full vector)
    ...                  (repeated for v, then w)
    x y z [w]          the coefficients, one per line: the first direction runs
    ...                  fastest, then the second, then the third

For a rational object the coefficients are ``(x w, y w, z w, w)``: GoTools stores the
Cartesian coordinates **pre-multiplied by the weight** (the homogeneous control points;
Splipy's rational ``controlpoints`` are the same). Objects follow one another; blank
lines between them and any line breaks inside a knot vector or coefficient list are
accepted (the reader splits on whitespace).

Every float is written with Python's ``repr`` (the shortest string that reads back to
the same double), so knots, weights and non-rational control points round-trip
exactly. A rational object's Cartesian control points are stored multiplied by their
weights, so they come back as ``(x w) / w``, within an ulp of ``x``; its homogeneous
net round-trips exactly. Files are written atomically (a temporary file beside the
target, then ``os.replace``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...atomic_files import atomic_output
from ...errors import ConversionError, InputFileError, InvalidGeometryError
from ..curve import NurbsCurve
from ..surface import NurbsSurface
from ..volume import NurbsVolume

__all__ = ["CLASS_IDS", "format_g2", "read_g2", "write_g2"]

#: GoTools class type of each NURBS type
CLASS_IDS = {NurbsCurve: 100, NurbsSurface: 200, NurbsVolume: 700}
_PARAMETRIC_DIMENSION = {100: 1, 200: 2, 700: 3}
#: other GoTools class types, named in the message refusing them
_OTHER_CLASSES = {
    110: "CurveOnSurface", 120: "Line", 130: "Circle", 140: "Ellipse", 150: "BoundedCurve",
    160: "Hyperbola", 170: "Parabola", 210: "BoundedSurface", 211: "SurfaceOnVolume",
    220: "GoBaryPolSurface", 230: "GoHBSplineParamSurface", 240: "CompositeSurface",
    250: "Plane", 260: "Cylinder", 261: "SurfaceOfLinearExtrusion", 270: "Sphere",
    280: "Cone", 290: "Torus", 291: "SurfaceOfRevolution", 292: "Disc",
    293: "LRSplineSurface", 294: "TSplineSurface", 400: "PointCloud", 410: "LineCloud",
    720: "Parallelepiped", 721: "SphereVolume", 722: "CylinderVolume", 723: "ConeVolume",
    724: "TorusVolume", 793: "LRSplineVolume",
}


# ------------------------------------------------------------------- reading
class _Tokens:
    """The whitespace-separated words of a file with their line numbers."""

    def __init__(self, text: str, name: str) -> None:
        self.name = name
        self.words: list[str] = []
        self.lines: list[int] = []
        for number, line in enumerate(text.splitlines(), start=1):
            parts = line.split()
            self.words.extend(parts)
            self.lines.extend([number] * len(parts))
        self.position = 0

    def more(self) -> bool:
        return self.position < len(self.words)

    def line(self) -> int:
        return self.lines[min(self.position, len(self.lines) - 1)] if self.lines else 0

    def fail(self, message: str) -> InputFileError:
        return InputFileError(f"{self.name}, line {self.line()}: {message}")

    def take(self, count: int, what: str) -> list[str]:
        if self.position + count > len(self.words):
            raise InputFileError(f"{self.name}: the file ends before {what} "
                                 f"(needs {count} values, {len(self.words) - self.position} left)")
        out = self.words[self.position:self.position + count]
        self.position += count
        return out

    def integers(self, count: int, what: str) -> list[int]:
        start = self.position
        words = self.take(count, what)
        try:
            return [int(word) for word in words]
        except ValueError:
            self.position = start
            raise self.fail(f"expected {count} integer(s) for {what}, got {' '.join(words)!r}") from None

    def floats(self, count: int, what: str) -> NDArray:
        start = self.position
        words = self.take(count, what)
        try:
            values = np.array(words, dtype=float)
        except ValueError:
            self.position = start
            raise self.fail(f"expected {count} numbers for {what}") from None
        if not np.all(np.isfinite(values)):
            self.position = start
            raise self.fail(f"{what} contain NaN or infinite values")
        return values


def _source_text(source: str | os.PathLike) -> tuple[str, str]:
    """``(text, name for messages)``: a path is read, a string holding a line break is
    the text itself."""
    if isinstance(source, str) and ("\n" in source or "\r" in source):
        return source, "<g2 text>"
    if not isinstance(source, (str, os.PathLike)):
        raise ConversionError(f"read_g2 takes a path or the file's text, got {type(source).__name__}")
    path = Path(source)
    try:
        return path.read_text(encoding="utf-8"), str(path)
    except FileNotFoundError:
        raise InputFileError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputFileError(f"{path} is a folder, not a .g2 file") from None
    except UnicodeDecodeError:
        raise InputFileError(f"{path} is not a text file (a .g2 file is text)") from None


def _read_object(tokens: _Tokens, index: int):
    header_line = tokens.line()
    class_id, major, minor, aux = tokens.integers(4, f"the header of object {index}")
    where = f"object {index} (line {header_line})"
    if class_id not in _PARAMETRIC_DIMENSION:
        other = _OTHER_CLASSES.get(class_id)
        kind = f"class {class_id}" + (f" ({other})" if other else "")
        raise InputFileError(f"{tokens.name}: {where}: {kind} is not supported; only 100 "
                             "(SplineCurve), 200 (SplineSurface) and 700 (SplineVolume) are read")
    if (major, minor) != (1, 0):
        raise InputFileError(f"{tokens.name}: {where}: unknown g2 version {major}.{minor} (expected 1.0)")
    if aux == 4:
        tokens.integers(4, f"the colour of {where}")
    elif aux != 0:
        raise InputFileError(f"{tokens.name}: {where}: auxiliary header value must be 0 or 4, got {aux}")
    dim, rational = tokens.integers(2, f"the dimension and rational flag of {where}")
    if dim < 1 or rational not in (0, 1):
        raise InputFileError(f"{tokens.name}: {where}: expected a dimension >= 1 and a rational "
                             f"flag 0 or 1, got {dim} {rational}")
    counts, degrees, knots = [], [], []
    for direction in "uvw"[:_PARAMETRIC_DIMENSION[class_id]]:
        n, order = tokens.integers(2, f"the coefficient count and order in {direction} of {where}")
        if order < 2 or n < order:
            raise InputFileError(f"{tokens.name}: {where}: direction {direction} needs order >= 2 and "
                                 f"n >= order coefficients, got n = {n}, order = {order}")
        knots.append(tokens.floats(n + order, f"the {direction} knots of {where}"))
        counts.append(n)
        degrees.append(order - 1)
    width = dim + rational
    coefficients = tokens.floats(int(np.prod(counts)) * width, f"the coefficients of {where}")
    # the first direction runs fastest: C order over the reversed counts, then transposed
    net = coefficients.reshape(tuple(reversed(counts)) + (width,))
    net = np.transpose(net, tuple(reversed(range(len(counts)))) + (len(counts),))
    weights = None
    if rational:
        weights = net[..., -1]
        if np.any(weights <= 0):
            raise InputFileError(f"{tokens.name}: {where}: weights must be > 0")
        net = net[..., :-1] / weights[..., None]
    cls = {100: NurbsCurve, 200: NurbsSurface, 700: NurbsVolume}[class_id]
    try:
        return cls(net, *knots, *degrees, weights)
    except InvalidGeometryError as exc:
        raise InputFileError(f"{tokens.name}: {where}: {exc}") from None


def read_g2(source: str | os.PathLike) -> list[NurbsCurve | NurbsSurface | NurbsVolume]:
    """The spline curves, surfaces and volumes of a GoTools ``.g2`` file.

    Parameters
    ----------
    source : str or os.PathLike
        A path, or the text of a file (a string with a line break in it).

    Returns
    -------
    list
        :class:`NurbsCurve` (class 100), :class:`NurbsSurface` (200) and
        :class:`NurbsVolume` (700) in file order; control points Cartesian (a rational
        file's coefficients divided by their weights), weights kept when the file says
        rational (even if all are 1); an empty file gives ``[]``.

    Raises
    ------
    InputFileError
        Missing or unreadable file, another class type (lines, elementary or trimmed
        surfaces...), a version other than 1.0, a malformed number, a file ending in
        the middle of an object, or data that are no valid NURBS (the message names the
        object and its line).

    Examples
    --------
    >>> text = "100 1 0 0\\n3 0\\n2 2\\n0 0 1 1\\n0 0 0\\n1 0 0\\n"
    >>> (line,) = read_g2(text)
    >>> line.degree, line.evaluate(0.25)
    (1, array([0.25, 0.  , 0.  ]))
    """
    text, name = _source_text(source)
    tokens = _Tokens(text, name)
    objects = []
    while tokens.more():
        objects.append(_read_object(tokens, len(objects) + 1))
    return objects


# ------------------------------------------------------------------- writing
def _numbers(values: Iterable[float]) -> str:
    return " ".join(map(repr, values))


def _object_lines(obj: NurbsCurve | NurbsSurface | NurbsVolume) -> Iterator[str]:
    class_id = CLASS_IDS[type(obj)]
    rational = obj.weights is not None
    if class_id == 100:
        knots, degrees = [obj.knots], [obj.degree]
    elif class_id == 200:
        knots, degrees = [obj.knots_u, obj.knots_v], [obj.degree_u, obj.degree_v]
    else:
        knots, degrees = list(obj.knots), list(obj.degrees)
    yield f"{class_id} 1 0 0"
    yield f"{obj.dimension} {int(rational)}"
    for k, p in zip(knots, degrees):
        yield f"{k.size - p - 1} {p + 1}"
        yield _numbers(k.tolist())
    net = obj.homogeneous_points() if rational else obj.control_points
    k = net.ndim - 1
    flat = np.transpose(net, tuple(reversed(range(k))) + (k,)).reshape(-1, net.shape[-1])
    yield from (_numbers(row) for row in flat.tolist())


def _as_objects(objects) -> list:
    items = [objects] if type(objects) in CLASS_IDS else list(objects)
    for k, obj in enumerate(items):
        if type(obj) not in CLASS_IDS:
            raise ConversionError(f"object {k} is a {type(obj).__name__}; .g2 files hold "
                                  "NurbsCurve, NurbsSurface and NurbsVolume objects")
    return items


def format_g2(objects) -> str:
    """The text of a ``.g2`` file holding ``objects`` (one object or a sequence of them),
    as :func:`write_g2` writes it."""
    return "".join(line + "\n" for obj in _as_objects(objects) for line in _object_lines(obj))


def write_g2(path: str | os.PathLike, objects) -> Path:
    """Write curves, surfaces and volumes to a GoTools ``.g2`` file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write; its folder must exist. An existing file is replaced; on
        any failure it is left as it was and no temporary file is left behind.
    objects : NurbsCurve, NurbsSurface, NurbsVolume or a sequence of them
        Written in order: class 100, 200 or 700, version ``1 0 0``; rational (flag 1,
        coefficients ``(x w, y w, z w, w)``) when the object has weights.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ConversionError
        An object of another type.
    FileNotFoundError
        The folder of ``path`` does not exist.

    Examples
    --------
    >>> import os, tempfile
    >>> from surfprep.algorithms.volume_builders import solid_sphere
    >>> folder = tempfile.mkdtemp()
    >>> target = write_g2(os.path.join(folder, "ball.g2"), [solid_sphere(2.0)])
    >>> (ball,) = read_g2(target)
    >>> ball.degrees, ball.n_control
    ((2, 2, 2), (3, 5, 9))
    """
    text = format_g2(objects)
    with atomic_output(path) as temporary:
        temporary.write_text(text, encoding="ascii", newline="\n")
    return Path(path)
