"""Reading and writing STEP and IGES files: :func:`read`, :func:`write`, :class:`CadModel`.

``read`` checks the file before OpenCascade sees it (exists, is a regular file,
not empty, extension known, content matches the extension, not truncated, no
dangling reference or non-finite number: :mod:`.content_checks`), then
translates it through XDE to keep face names and colours (plain readers as a
fallback), in a child process so that a reader crashing or hanging on a corrupt
file cannot take the caller down (:mod:`.isolation`), and refuses a file without
faces. Every failure is one of the package
exceptions (:mod:`surfprep.errors`) with a one-line message naming the file.

``write`` converts what it is given (a :class:`CadModel`, OCC shapes,
cadquery/build123d objects, :class:`~surfprep.algorithms.NurbsSurface` /
:class:`~surfprep.algorithms.NurbsCurve`, or a list of them) to one shape,
writes it to a temporary file in the target directory and moves that into
place with ``os.replace``, so a failed write never leaves a partial file or a
temporary behind. It never overwrites the file a :class:`CadModel` was read
from, and refuses any other existing file unless ``overwrite=True``.

Coordinates: OpenCascade converts the file's length unit to millimetres while
reading (and writes millimetres), so ``CadModel.shape`` is always in mm;
``CadModel.length_unit`` is the unit the file *declares*, kept for reports and
for spotting unit slips. Use :attr:`CadModel.size` (the bounding-box diagonal)
to derive tolerances.
"""

from __future__ import annotations

import dataclasses
import io
import os
import tempfile
import warnings
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

from OCP.BinTools import BinTools, BinTools_FormatVersion
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.ShapeFix import ShapeFix_Shape
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

from ..algorithms import NurbsCurve, NurbsSurface
from ..algorithms.trimmed import TrimmedFace
from ..atomic_files import new_file_mode
from ..errors import ConversionError, InputFileError, NoFacesError, OpenCascadeError, OutputFileError
from ..inputs import ShapeLike
from . import isolation
from .dropped import DroppedEntity, RepairedEntity
from .file_format import FileFormat, check_input_file, known_suffixes, sniff_format
from .occ.edges import make_edge
from .occ.faces import make_face, trimmed_face_to_occ
from .occ.failures import describe, is_occ_failure
from .occ.shapes import FaceNames, all_faces, compound
from .step_iges import Rgb, TranslatedModel, TranslationError, read_file, write_file

__all__ = [
    "CadModel",
    "FileFormat",
    "StagedFile",
    "TranslationWarning",
    "as_model",
    "bounding_box",
    "named_model",
    "read",
    "sniff_format",
    "staged_write",
    "to_shape",
    "write",
]

#: Unit of ``CadModel.shape`` coordinates (OCCT's default working unit).
MODEL_UNIT = "mm"

#: seconds an isolated translation may take (the largest file of the test data, 4 MB,
#: reads in about 1 s)
DEFAULT_READ_TIMEOUT = 120.0


class TranslationWarning(UserWarning):
    """The file was read, but not the way asked (e.g. without face names: see the message)."""


@dataclass(frozen=True, eq=False)
class CadModel:
    """A CAD model read from (or destined for) a STEP/IGES file.

    Attributes
    ----------
    shape : TopoDS_Shape
        Everything the file holds, in millimetres (see module docstring).
    faces : tuple of TopoDS_Face
        Every face occurrence in file (exploration) order.
    face_names : tuple of (str or None)
        Name of each face from the file's XDE labels, None where it has none.
    face_colors : tuple of ((r, g, b) or None)
        Surface colour of each face (components in [0, 1]), None where unset.
    length_unit : str
        Length unit the file declares ("mm", "m", "in", "ft", ...; "unspecified"
        when it declares none; comma-joined when a STEP file declares several).
    path : Path or None
        The file read, resolved; None for a model built in memory.
    file_format : FileFormat or None
    dropped : tuple of DroppedEntity
        Entities of the file the translation produced no shape for (a face lost,
        :mod:`.dropped`); empty for a model built in memory.
    translation_notes : tuple of (str, str, int)
        OCCT's other messages while reading, ``(entity type, message, count)``.
    repaired : tuple of RepairedEntity
        Entities whose shape OCCT changed while reading (:mod:`.dropped`).
    """

    shape: TopoDS_Shape
    faces: tuple[TopoDS_Face, ...]
    face_names: tuple[str | None, ...]
    face_colors: tuple[Rgb | None, ...]
    length_unit: str = MODEL_UNIT
    path: Path | None = None
    file_format: FileFormat | None = None
    model_unit: str = field(default=MODEL_UNIT)
    dropped: tuple[DroppedEntity, ...] = ()
    translation_notes: tuple[tuple[str, str, int], ...] = ()
    repaired: tuple[RepairedEntity, ...] = ()

    def __post_init__(self) -> None:
        n = len(self.faces)
        if len(self.face_names) != n or len(self.face_colors) != n:
            raise ValueError(
                f"CadModel needs one name and one colour per face: {n} faces, "
                f"{len(self.face_names)} names, {len(self.face_colors)} colours")

    @classmethod
    def from_shape(cls, shape: TopoDS_Shape) -> CadModel:
        """A model of an in-memory shape, without names or colours."""
        faces = all_faces(shape)
        return cls(shape, faces, (None,) * len(faces), (None,) * len(faces))

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    def copy(self) -> CadModel:
        """The same model on a deep copy of its shape (``BRepBuilderAPI_Copy``, geometry
        included): each face the copy of the one at its index, names, colours and the
        rest kept. What a verb changes in place on the copy (a pcurve added to an edge,
        a face moved) leaves this model as it was."""
        copier = BRepBuilderAPI_Copy(self.shape, True, False)
        if not copier.IsDone():
            raise OpenCascadeError("BRepBuilderAPI_Copy failed")
        faces = tuple(TopoDS.Face_s(copier.ModifiedShape(f).Oriented(f.Orientation()))
                      for f in self.faces)
        return dataclasses.replace(self, shape=copier.Shape(), faces=faces)

    @cached_property
    def bounding_box(self) -> tuple[float, float, float, float, float, float]:
        """Tight box ``(xmin, ymin, zmin, xmax, ymax, zmax)`` of the shape, in mm."""
        return bounding_box(self.shape)

    @property
    def size(self) -> float:
        """Diagonal of :attr:`bounding_box`: the model's length scale for tolerances."""
        x0, y0, z0, x1, y1, z1 = self.bounding_box
        return float(((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2) ** 0.5)

    def __repr__(self) -> str:
        where = self.path.name if self.path is not None else "in memory"
        return (f"CadModel({where}, {self.n_faces} faces, declared unit "
                f"{self.length_unit!r}, size {self.size:.6g} {self.model_unit})")


def bounding_box(shape: TopoDS_Shape) -> tuple[float, float, float, float, float, float]:
    """Tight axis-aligned box of a shape (exact geometry, no triangulation, no tolerances)."""
    box = Bnd_Box()
    try:
        BRepBndLib.AddOptimal_s(shape, box, False, False)
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"bounding box computation failed: {describe(exc)}") from exc
    if box.IsVoid():
        raise OpenCascadeError("the shape has an empty bounding box")
    return tuple(float(x) for x in box.Get())


# ===================================================================== read
def read(path: str | os.PathLike, *, heal: bool = False, isolate: bool = True,
         timeout: float = DEFAULT_READ_TIMEOUT, require_faces: bool = True) -> CadModel:
    """Read a STEP (.step/.stp) or IGES (.igs/.iges) file.

    Parameters
    ----------
    path : path-like
    heal : bool
        Run OpenCascade's generic ``ShapeFix_Shape`` on the result (face names
        and colours follow the faces it keeps).
    isolate : bool
        Translate in a child process (:mod:`.isolation`, the default): OCCT's
        readers can crash (SIGSEGV) or hang on corrupt files, and a caller's
        process must survive them. The child is forked (a few milliseconds, no
        second import) and sends the shape back in OCCT's binary format, exactly.
        False translates in this process (where ``fork`` is unavailable it always
        does).
    timeout : float
        Seconds the isolated translation may take before it is killed.
    require_faces : bool
        Refuse a file without faces (the default); False returns it (a file of
        curves only, as ``surfprep intersect`` writes, for ``surfprep info``).

    Raises
    ------
    InputFileError
        Missing file, a directory, empty file, unknown extension, content of the
        other format (a STEP file named .igs), truncated or unreadable file, a
        reader that crashed or did not finish within ``timeout``.
    NoFacesError
        The file was read but holds no face (with ``require_faces``).
    """
    file = Path(path)
    fmt = check_input_file(file)
    if isolate and isolation.AVAILABLE:
        translated = _translate_isolated(file, fmt, timeout)
    else:
        translated = _translate(file, fmt)
    if not translated.faces and require_faces:
        kind = translated.shape.ShapeType().name.removeprefix("TopAbs_").lower()
        raise NoFacesError(f"{fmt.value} file {file} holds no faces (OpenCascade read it "
                           f"as a {kind} without faces)")
    model = CadModel(translated.shape, translated.faces, translated.face_names,
                     translated.face_colors, translated.length_unit, file.resolve(), fmt,
                     dropped=translated.checks.dropped,
                     translation_notes=translated.checks.notes,
                     repaired=translated.checks.repaired)
    return _healed(model) if heal else model


def _translate(file: Path, fmt: FileFormat, xde: bool = True) -> TranslatedModel:
    """OCCT's translation of the file, its failures as :class:`InputFileError`."""
    try:
        return read_file(file, fmt, xde=xde)
    except TranslationError as exc:
        raise InputFileError(f"cannot read {fmt.value} file {file}: {exc}") from None
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise InputFileError(
            f"cannot read {fmt.value} file {file}: OpenCascade failed: {describe(exc)}") from None


def _portable(file: Path, fmt: FileFormat, xde: bool) -> dict:
    """In the child: the translation as plain data (the shape in OCCT's binary format)."""
    translated = _translate(file, fmt, xde)
    stream = io.BytesIO()
    BinTools.Write_s(translated.shape, stream, False, False,
                     BinTools_FormatVersion.BinTools_FormatVersion_CURRENT)
    return {"shape": stream.getvalue(), "n_faces": len(translated.faces),
            "face_names": translated.face_names, "face_colors": translated.face_colors,
            "length_unit": translated.length_unit, "used_xde": translated.used_xde,
            "checks": translated.checks}


def _translate_isolated(file: Path, fmt: FileFormat, timeout: float) -> TranslatedModel:
    """:func:`_translate` in a child process (:func:`.isolation.call_isolated`); when the
    XDE reader crashes, the plain reader in another child (no names or colours, said)."""
    what = f"{fmt.value} file {file}"
    try:
        data = isolation.call_isolated(_portable, file, fmt, True, timeout=timeout)
    except isolation.ChildCrashed as exc:
        try:
            data = isolation.call_isolated(_portable, file, fmt, False, timeout=timeout)
        except (isolation.ChildCrashed, isolation.ChildTimedOut, InputFileError):
            how = f"crashed ({exc.signal_name})" if exc.signal_name else f"died ({exc})"
            raise InputFileError(f"cannot read {what}: OpenCascade's reader {how}; the file "
                                 "is corrupt or holds what the reader cannot handle") from None
        how = exc.signal_name or str(exc)
        warnings.warn(f"{file.name}: OpenCascade's XDE reader crashed ({how}); read with the "
                      "plain reader, without face names or colours", TranslationWarning,
                      stacklevel=3)
    except isolation.ChildTimedOut:
        raise InputFileError(f"cannot read {what}: OpenCascade's reader did not finish within "
                             f"{timeout:g} s (stopped); the file is corrupt or far larger "
                             "than it looks") from None
    shape = TopoDS_Shape()
    BinTools.Read_s(shape, io.BytesIO(data["shape"]))
    faces = all_faces(shape)
    if len(faces) != data["n_faces"]:
        raise OpenCascadeError(f"reading {what}: {data['n_faces']} faces translated, "
                               f"{len(faces)} came back from the reading process")
    return TranslatedModel(shape, faces, tuple(data["face_names"]), tuple(data["face_colors"]),
                           data["length_unit"], data["used_xde"], data["checks"])


def _healed(model: CadModel) -> CadModel:
    try:
        fixer = ShapeFix_Shape(model.shape)
        fixer.Perform()
        shape = fixer.Shape()
    except Exception as exc:
        if not is_occ_failure(exc):
            raise
        raise OpenCascadeError(f"ShapeFix_Shape failed on {model.path}: {describe(exc)}") from exc
    if shape.IsNull():
        raise OpenCascadeError(f"ShapeFix_Shape returned a null shape for {model.path}")
    context = fixer.Context()
    names, colors = FaceNames(), FaceNames()
    for face, name, color in zip(model.faces, model.face_names, model.face_colors):
        new = context.Apply(face)
        if name is not None:
            names.add(new, name)
        if color is not None:
            colors.add(new, color)
    faces = all_faces(shape)
    if not faces:
        raise NoFacesError(f"no faces left after healing {model.path}")
    return CadModel(shape, faces, tuple(names.get(f) for f in faces),
                    tuple(colors.get(f) for f in faces), model.length_unit, model.path,
                    model.file_format, dropped=model.dropped,
                    translation_notes=model.translation_notes, repaired=model.repaired)


# ==================================================================== write
def write(obj: ShapeLike, path: str | os.PathLike, *, overwrite: bool = False) -> Path:
    """Write geometry to a STEP or IGES file, atomically.

    Parameters
    ----------
    obj
        A :class:`CadModel` (its face names/colours are written through XDE), a
        ``TopoDS_Shape``, an object with a ``.wrapped`` shape (cadquery Shape,
        build123d objects), a cadquery ``Workplane``, a
        :class:`~surfprep.algorithms.NurbsSurface` (becomes a face) or 3D
        :class:`~surfprep.algorithms.NurbsCurve` (an edge), or a list/tuple of these.
    path : path-like
        Target; the extension (.step/.stp/.igs/.iges, any case) picks the format.
    overwrite : bool
        Replace an existing file. The file a CadModel was read from is never
        overwritten.

    Returns
    -------
    Path
        The resolved path written.

    Raises
    ------
    OutputFileError
        Unknown extension, missing target directory, existing target without
        ``overwrite``, target is the model's input file, or the writer failed.
    ConversionError
        An object that cannot be turned into a shape.
    OpenCascadeError
        A face/edge builder failed.

    See Also
    --------
    staged_write : the same, with the move into place left to the caller.
    """
    with staged_write(obj, path, overwrite=overwrite) as staged:
        return staged.commit()


@dataclass
class StagedFile:
    """A file written next to its target and not yet moved into place.

    :meth:`commit` moves it there (``os.replace``, atomic on one file system);
    leaving the :func:`staged_write` block without committing deletes it, so a
    failure between writing and committing (a report that cannot be written, a
    plot that fails) leaves neither a half result nor a temporary behind.
    """

    temporary: Path
    target: Path
    committed: bool = False

    def commit(self) -> Path:
        """Move the staged file onto its target; returns the target."""
        if self.committed:
            return self.target
        try:
            os.replace(self.temporary, self.target)
        except OSError as exc:
            raise OutputFileError(f"cannot write {self.target}: {exc.strerror or exc}") from None
        self.committed = True
        return self.target


@contextmanager
def staged_write(obj: ShapeLike, path: str | os.PathLike, *,
                 overwrite: bool = False) -> Iterator[StagedFile]:
    """Write ``obj`` to a temporary file beside ``path``; yields a :class:`StagedFile`.

    The checks and the conversion are those of :func:`write`; the file appears
    at ``path`` only when the caller calls :meth:`StagedFile.commit` inside the
    block. The commands write their JSON report first and commit the model
    after, so a report that cannot be written leaves no model without one.
    """
    target = Path(path)
    fmt = FileFormat.from_suffix(target)
    if fmt is None:
        raise OutputFileError(
            f"output file {target} has unknown extension {target.suffix!r}; "
            f"expected one of {known_suffixes()}")
    _check_output_file(target, obj, overwrite)
    model = obj if isinstance(obj, CadModel) else CadModel.from_shape(to_shape(obj))
    if model.shape.IsNull():
        raise OutputFileError(f"nothing to write to {target}: the shape is empty")

    directory = target.resolve().parent
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise OutputFileError(
            f"cannot write {target}: cannot create a file in {directory}: "
            f"{exc.strerror or exc}") from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        try:
            write_file(tmp, fmt, model.shape, model.faces, model.face_names, model.face_colors)
            if not tmp.is_file() or tmp.stat().st_size == 0:
                raise TranslationError("the writer reported success but wrote nothing")
            os.chmod(tmp, new_file_mode())
        except TranslationError as exc:
            raise OutputFileError(f"cannot write {fmt.value} file {target}: {exc}") from None
        except OSError as exc:
            raise OutputFileError(f"cannot write {target}: {exc.strerror or exc}") from None
        except Exception as exc:
            if not is_occ_failure(exc):
                raise
            raise OutputFileError(f"cannot write {fmt.value} file {target}: "
                                  f"OpenCascade failed: {describe(exc)}") from None
        yield StagedFile(tmp, target.resolve())
    finally:
        tmp.unlink(missing_ok=True)


def _check_output_file(target: Path, obj: Any, overwrite: bool) -> None:
    if target.is_dir():
        raise OutputFileError(f"output {target} is a directory")
    parent = target.resolve().parent
    if not parent.is_dir():
        raise OutputFileError(f"output directory {parent} does not exist")
    if not target.exists():
        return
    source = obj.path if isinstance(obj, CadModel) else None
    if source is not None and Path(source).exists() and os.path.samefile(source, target):
        raise OutputFileError(
            f"refusing to overwrite the input file {target}; choose another output path")
    if not overwrite:
        raise OutputFileError(
            f"output file {target} already exists (pass overwrite=True to replace it)")


# ========================================================== object -> shape
def as_model(obj: ShapeLike | str | os.PathLike) -> CadModel:
    """A :class:`CadModel` for a path (read), a model (itself) or anything :func:`to_shape` takes."""
    if isinstance(obj, CadModel):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        return read(obj)
    return CadModel.from_shape(to_shape(obj))


def to_shape(obj: ShapeLike) -> TopoDS_Shape:
    """One ``TopoDS_Shape`` for anything :func:`write` accepts (lists become a compound)."""
    if isinstance(obj, CadModel):
        return obj.shape
    if isinstance(obj, TopoDS_Shape):
        if obj.IsNull():
            raise ConversionError("cannot write a null TopoDS_Shape")
        return obj
    if isinstance(obj, NurbsSurface):
        return make_face(obj)
    if isinstance(obj, NurbsCurve):
        return make_edge(obj)
    if isinstance(obj, TrimmedFace):
        return trimmed_face_to_occ(obj)
    wrapped = getattr(obj, "wrapped", None)
    if isinstance(wrapped, TopoDS_Shape):
        return to_shape(wrapped)
    vals = getattr(obj, "vals", None)  # cadquery Workplane
    if callable(vals) and not isinstance(obj, (str, bytes)):
        return to_shape(list(vals()))
    if isinstance(obj, Iterable) and not isinstance(obj, (str, bytes, os.PathLike)):
        shapes = [to_shape(item) for item in obj]
        if not shapes:
            raise ConversionError("cannot write an empty list of objects")
        return shapes[0] if len(shapes) == 1 else compound(shapes)
    raise ConversionError(
        f"cannot write a {type(obj).__name__}: expected a CadModel, TopoDS_Shape, "
        "cadquery/build123d object, NurbsSurface, NurbsCurve or a list of them")


def named_model(shape, faces, names) -> CadModel:
    """A CadModel of ``shape`` whose faces are named as ``faces`` (the same faces, in
    any orientation or location) are by ``names``."""
    table = FaceNames()
    for face, name in zip(faces, names):
        if name is not None:
            table.add(face, name)
    out = all_faces(shape)
    return CadModel(shape, out, tuple(table.get(f) for f in out), (None,) * len(out))
