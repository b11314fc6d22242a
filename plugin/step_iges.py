"""Low-level STEP / IGES translation through OpenCascade (XDE first, plain readers as fallback).

This module talks to OCCT's data exchange classes and nothing else; the public
entry points with their input checks are :func:`surfprep.plugin.io.read` and
:func:`surfprep.plugin.io.write`.

Reading goes through XDE (``STEPCAFControl_Reader`` / ``IGESCAFControl_Reader``
into a ``TDocStd_Document``) so that face names and colours survive; when XDE
fails the plain ``STEPControl_Reader`` / ``IGESControl_Reader`` are tried. Every
status is checked (``IFSelect_RetDone``, ``NbRootsForTransfer``, the transfer's
boolean). OCCT's messenger is silenced during a translation (OCCT prints
progress lines such as "Total number of loaded entities" to stdout, which would
corrupt ``--json -`` output) and OCCT static parameters touched here are restored
afterwards.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.IGESCAFControl import IGESCAFControl_Reader, IGESCAFControl_Writer
from OCP.IGESControl import IGESControl_Reader, IGESControl_Writer
from OCP.Interface import Interface_Static
from OCP.Message import Message
from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
from OCP.STEPCAFControl import STEPCAFControl_Reader, STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_Reader, STEPControl_StepModelType, STEPControl_Writer
from OCP.TCollection import TCollection_ExtendedString
from OCP.TColStd import TColStd_SequenceOfAsciiString
from OCP.TDataStd import TDataStd_Name
from OCP.TDF import TDF_ChildIterator, TDF_Label, TDF_LabelSequence
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_FACE
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape
from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool, XCAFDoc_ShapeTool

from .dropped import TranslationChecks, translation_checks
from .file_format import FileFormat
from .occ.shapes import FaceNames, all_faces, compound, distinct_faces

__all__ = [
    "FileFormat",
    "Rgb",
    "TranslatedModel",
    "read_file",
    "write_file",
    "TranslationError",
]

Rgb = tuple[float, float, float]

_DONE = IFSelect_ReturnStatus.IFSelect_RetDone
_SUBSHAPE_NAMES_READ = "read.stepcaf.subshapes.name"
_SUBSHAPE_NAMES_WRITE = "write.stepcaf.subshapes.name"


class TranslationError(Exception):
    """An OCCT reader or writer reported failure; the message says which step."""


@dataclass(frozen=True)
class TranslatedModel:
    """What an OCCT reader produced: the shape, its unique faces and their XDE attributes."""

    shape: TopoDS_Shape
    faces: tuple[TopoDS_Face, ...]
    face_names: tuple[str | None, ...]
    face_colors: tuple[Rgb | None, ...]
    length_unit: str
    used_xde: bool
    checks: TranslationChecks = TranslationChecks()


# --------------------------------------------------------------- OCCT state
@contextmanager
def _quiet_occt() -> Iterator[None]:
    """Detach OCCT's default message printers for the duration, then reattach them.

    OCCT prints parser errors and progress lines ("Total number of loaded
    entities", "**** ERR StepFile ...") to stdout; surfprep reports failures as
    exceptions instead.
    """
    messenger = Message.DefaultMessenger_s()
    printers = messenger.Printers()
    detached = [printers.Value(i) for i in range(1, printers.Length() + 1)]
    for printer in detached:
        messenger.RemovePrinter(printer)
    try:
        yield
    finally:
        for printer in detached:
            messenger.AddPrinter(printer)


@contextmanager
def _static_int(name: str, value: int) -> Iterator[None]:
    """Set an OCCT ``Interface_Static`` integer parameter and restore it afterwards.

    The parameters exist only once the matching controller is initialised, i.e.
    after a reader/writer of that format has been constructed.
    """
    present = Interface_Static.IsPresent_s(name)
    old = Interface_Static.IVal_s(name) if present else None
    if present:
        Interface_Static.SetIVal_s(name, value)
    try:
        yield
    finally:
        if present:
            Interface_Static.SetIVal_s(name, old)


# ------------------------------------------------------------------- units
_UNIT_ALIASES = {
    "MM": "mm", "MILLIMETRE": "mm", "MILLIMETER": "mm", "MILLI METRE": "mm",
    "M": "m", "METRE": "m", "METER": "m",
    "CM": "cm", "CENTIMETRE": "cm", "CENTIMETER": "cm",
    "UM": "um", "MICRON": "um", "MICROMETRE": "um", "MICROMETER": "um",
    "KM": "km", "KILOMETRE": "km", "KILOMETER": "km",
    "IN": "in", "INCH": "in", "INCHES": "in",
    "FT": "ft", "FOOT": "ft", "FEET": "ft",
    "MI": "mi", "MILE": "mi", "MIL": "mil", "UIN": "uin", "MICROINCH": "uin",
}
# IGES global section, parameter 14 (unit flag)
_IGES_UNIT_FLAGS = {1: "in", 2: "mm", 4: "ft", 5: "mi", 6: "m", 7: "km", 8: "mil",
                    9: "um", 10: "cm", 11: "uin"}
UNSPECIFIED_UNIT = "unspecified"


def _unit_name(raw: str) -> str:
    key = raw.strip().strip(".").replace("_", " ").upper()
    return _UNIT_ALIASES.get(key, raw.strip().lower() or UNSPECIFIED_UNIT)


def _step_length_unit(reader: STEPControl_Reader) -> str:
    lengths, angles, solid_angles = (TColStd_SequenceOfAsciiString() for _ in range(3))
    reader.FileUnits(lengths, angles, solid_angles)
    names = [_unit_name(lengths.Value(i).ToCString()) for i in range(1, lengths.Length() + 1)]
    names = list(dict.fromkeys(names))  # unique, in order
    return ",".join(names) if names else UNSPECIFIED_UNIT


def _iges_length_unit(reader) -> str:
    section = reader.IGESModel().GlobalSection()
    flag = section.UnitFlag()
    if flag == 3:  # "name given in parameter 15"
        name = section.UnitName()
        return _unit_name(name.ToCString()) if name is not None else UNSPECIFIED_UNIT
    return _IGES_UNIT_FLAGS.get(flag, UNSPECIFIED_UNIT)


# ----------------------------------------------------------------- reading
def read_file(path: Path, fmt: FileFormat, *, xde: bool = True) -> TranslatedModel:
    """Translate a STEP/IGES file; XDE first, plain reader if XDE fails (only the plain
    reader with ``xde=False``: after XDE crashed on the file).

    Raises
    ------
    TranslationError
        When neither reader produced a shape; the message names the failing step.
    """
    with _quiet_occt():
        if not xde:
            return _read_plain(path, fmt)
        try:
            return _read_xde(path, fmt)
        except TranslationError as xde_error:
            try:
                return _read_plain(path, fmt)
            except TranslationError as plain_error:
                if str(plain_error) == str(xde_error):
                    raise plain_error from None
                raise TranslationError(f"{plain_error} (XDE reader: {xde_error})") from None


def _check_read_status(status, what: str) -> None:
    if status != _DONE:
        name = getattr(status, "name", str(status)).replace("IFSelect_Ret", "")
        raise TranslationError(f"the {what} reader cannot parse it (status {name})")


def _read_xde(path: Path, fmt: FileFormat) -> TranslatedModel:
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    if fmt is FileFormat.STEP:
        reader = STEPCAFControl_Reader()
        reader.SetNameMode(True)
        reader.SetColorMode(True)
        with _static_int(_SUBSHAPE_NAMES_READ, 1):
            _check_read_status(reader.ReadFile(str(path)), "STEP")
            if reader.NbRootsForTransfer() < 1:
                raise TranslationError("it has no root entity to transfer")
            if not reader.Transfer(doc):
                raise TranslationError("STEP (XDE) transfer failed")
        unit = _step_length_unit(reader.Reader())
        session = reader.Reader().WS()
    else:
        reader = IGESCAFControl_Reader()
        reader.SetNameMode(True)
        reader.SetColorMode(True)
        _check_read_status(reader.ReadFile(str(path)), "IGES")
        if reader.NbRootsForTransfer() < 1:
            raise TranslationError("it has no root entity to transfer")
        if not reader.Transfer(doc):
            raise TranslationError("IGES (XDE) transfer failed")
        unit = _iges_length_unit(reader)
        session = reader.WS()

    shape_tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    color_tool = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    free = TDF_LabelSequence()
    shape_tool.GetFreeShapes(free)
    shapes = [XCAFDoc_ShapeTool.GetShape_s(free.Value(i)) for i in range(1, free.Length() + 1)]
    shapes = [s for s in shapes if not s.IsNull()]
    if not shapes:
        raise TranslationError("XDE transfer produced no shape")
    shape = shapes[0] if len(shapes) == 1 else compound(shapes)
    faces = all_faces(shape)

    names = _names_by_face(shape_tool)
    face_names = tuple(names.get(f) for f in faces)
    face_colors = tuple(_face_color(color_tool, f) for f in faces)
    return TranslatedModel(shape, faces, face_names, face_colors, unit, used_xde=True,
                           checks=translation_checks(session, path.read_bytes(), fmt.value,
                                                    distinct_faces(faces)))


def _read_plain(path: Path, fmt: FileFormat) -> TranslatedModel:
    if fmt is FileFormat.STEP:
        reader = STEPControl_Reader()
        _check_read_status(reader.ReadFile(str(path)), "STEP")
        unit = _step_length_unit(reader)
    else:
        reader = IGESControl_Reader()
        _check_read_status(reader.ReadFile(str(path)), "IGES")
        unit = _iges_length_unit(reader)
    if reader.NbRootsForTransfer() < 1:
        raise TranslationError("it has no root entity to transfer")
    if reader.TransferRoots() < 1 or reader.NbShapes() < 1:
        raise TranslationError(f"{fmt.value} transfer produced no shape")
    shape = reader.OneShape()
    if shape.IsNull():
        raise TranslationError(f"{fmt.value} transfer produced a null shape")
    faces = all_faces(shape)
    return TranslatedModel(shape, faces, (None,) * len(faces), (None,) * len(faces), unit,
                           used_xde=False,
                           checks=translation_checks(reader.WS(), path.read_bytes(), fmt.value,
                                                    distinct_faces(faces)))


def _label_name(label: TDF_Label) -> str | None:
    # FindAttribute on a label without the attribute crashes in OCP: ask first
    if not label.IsAttribute(TDataStd_Name.GetID_s()):
        return None
    attr = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attr):
        text = attr.Get().ToExtString().strip()
        return text or None
    return None


def _names_by_face(shape_tool: XCAFDoc_ShapeTool) -> FaceNames:
    """Names of every named face label under the document's shape labels."""
    names = FaceNames()
    # every shape label (free shapes, parts, components) and their sub-shape labels
    top = TDF_LabelSequence()
    shape_tool.GetShapes(top)
    labels = [top.Value(i) for i in range(1, top.Length() + 1)]
    for label in labels:
        shape = XCAFDoc_ShapeTool.GetShape_s(label)
        if not shape.IsNull() and shape.ShapeType() == TopAbs_FACE:
            name = _label_name(label)
            if name is not None:
                names.add(shape, name)
        it = TDF_ChildIterator(label, True)
        while it.More():
            # it.Value() is a reference into the iterator: use it before Next()
            child = it.Value()
            shape = XCAFDoc_ShapeTool.GetShape_s(child)
            if not shape.IsNull() and shape.ShapeType() == TopAbs_FACE:
                name = _label_name(child)
                if name is not None:
                    names.add(shape, name)
            it.Next()
    return names


def _face_color(color_tool, face: TopoDS_Face) -> Rgb | None:
    color = Quantity_Color()
    for kind in (XCAFDoc_ColorType.XCAFDoc_ColorSurf, XCAFDoc_ColorType.XCAFDoc_ColorGen):
        if color_tool.GetColor(face, kind, color):
            return (round(color.Red(), 6), round(color.Green(), 6), round(color.Blue(), 6))
    return None


# ----------------------------------------------------------------- writing
def write_file(path: Path, fmt: FileFormat, shape: TopoDS_Shape,
               faces: Sequence[TopoDS_Face] = (),
               face_names: Sequence[str | None] = (),
               face_colors: Sequence[Rgb | None] = ()) -> None:
    """Write ``shape`` to ``path``; through XDE when faces carry names or colours.

    Raises
    ------
    TranslationError
        When the transfer or the write reports failure.
    """
    with _quiet_occt():
        if any(n is not None for n in face_names) or any(c is not None for c in face_colors):
            _write_xde(path, fmt, shape, faces, face_names, face_colors)
        else:
            _write_plain(path, fmt, shape)


def _write_xde(path, fmt, shape, faces, face_names, face_colors) -> None:
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    shape_tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    color_tool = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    lone_face = shape.ShapeType() == TopAbs_FACE
    if lone_face and fmt is FileFormat.STEP:
        # STEP names a lone face only as a sub-shape: wrap it in a compound
        shape = compound([shape])
        lone_face = False
    root = shape_tool.AddShape(shape, False)
    for face, name, color in zip(faces, face_names, face_colors):
        if name is None and color is None:
            continue
        # IGES names a lone face through its own (root) label
        sub = root if lone_face else shape_tool.AddSubShape(root, face)
        if sub.IsNull():
            continue
        if name is not None:
            TDataStd_Name.Set_s(sub, TCollection_ExtendedString(name))
        if color is not None:
            occ_color = Quantity_Color(*color, Quantity_TypeOfColor.Quantity_TOC_RGB)
            color_tool.SetColor(sub, occ_color, XCAFDoc_ColorType.XCAFDoc_ColorSurf)
    if fmt is FileFormat.STEP:
        writer = STEPCAFControl_Writer()
        writer.SetNameMode(True)
        writer.SetColorMode(True)
        with _static_int(_SUBSHAPE_NAMES_WRITE, 1):
            if not writer.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs):
                raise TranslationError("STEP (XDE) transfer of the shape failed")
            status = writer.Write(str(path))
        if status != _DONE:
            raise TranslationError(f"STEP (XDE) writer failed (status {status.name})")
    else:
        writer = IGESCAFControl_Writer()
        writer.SetNameMode(True)
        writer.SetColorMode(True)
        if not writer.Transfer(doc):
            raise TranslationError("IGES (XDE) transfer of the shape failed")
        if not writer.Write(str(path)):
            raise TranslationError("IGES (XDE) writer failed")


def _write_plain(path, fmt, shape) -> None:
    if fmt is FileFormat.STEP:
        writer = STEPControl_Writer()
        status = writer.Transfer(shape, STEPControl_StepModelType.STEPControl_AsIs)
        if status != _DONE:
            raise TranslationError(f"STEP transfer of the shape failed (status {status.name})")
        status = writer.Write(str(path))
        if status != _DONE:
            raise TranslationError(f"STEP writer failed (status {status.name})")
    else:
        writer = IGESControl_Writer("MM", 1)  # mode 1: B-rep (faces, shells), not surfaces only
        if not writer.AddShape(shape):
            raise TranslationError("IGES transfer of the shape failed")
        writer.ComputeModel()
        if not writer.Write(str(path)):
            raise TranslationError("IGES writer failed")
