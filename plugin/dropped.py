"""What a STEP/IGES translation left out, and what it changed, from OCCT's own checks.

OCCT's readers skip an entity they cannot translate (a surface with decreasing
knots, a ragged pole net, a negative weight, an IGES degree of -1) with at most a
line in a check list nobody reads: the model comes back with fewer faces and no
word. After a transfer every entity's checks sit in the work session's
transfer process; :func:`translation_checks` reads them once:

* **dropped**: an entity of a face-level type (surface, face, shell,
  representation...) with a *fail* or the warning that it was "not mapped" to a
  shape, while translating or (a damaged parameter list) while the file was
  loaded; an entity of an edge-level type (curve, edge, loop) the same way when
  faces are missing: named by its file label (``#55`` in STEP, the directory
  entry ``D17`` in IGES), its type, the names of the STEP faces that used it, and
  OCCT's reason. A STEP file's faces are also counted in its text
  (``ADVANCED_FACE``, ``FACE_SURFACE``), an IGES file's in its directory
  (:func:`iges_face_count`): fewer translated faces than that is a loss even when
  no check says so. In a STEP file whose faces are all there, load fails and
  edge-level fails are notes; in an IGES file they always count (a curve entity
  lost there is a trimming curve or a face's boundary);
  a face whose boundary was lost ("Face created with natural bounds": the whole
  untrimmed surface came back in its place) is dropped the same way;
* **repaired**: entities whose shape OCCT changed on the way in, said by a
  message with one of :data:`REPAIRED` ("Edges were intersecting, corrected",
  "Faces were incorrectly oriented in the shell, corrected", "Wire was split on
  several wires", "line shifted"...): named like the dropped ones, one record per
  entity and message;
* **notes**: every other message, counted by entity type and text ("Surface
  forced to be periodic" x 23, "With C0 continuity was split into C1 continuity
  Geom_BSplineCurve"): a representation OCCT chose, the geometry unchanged.

STEP labels come from the file itself: the transfer numbers entities in the order
of the DATA section, and the text gives each number's ``#id``.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

__all__ = ["DroppedEntity", "RepairedEntity", "TranslationChecks", "dropped_report",
           "iges_face_count", "repaired_report", "translation_checks"]

#: entity types whose loss loses a face (OCCT type names contain one of these)
FACE_LEVEL = ("Surface", "Face", "Shell", "Solid", "Plane", "Representation", "Brep", "Manifold",
              "Group")
#: entity types whose loss may lose a face (counted as dropped when faces are missing, or
#: in an IGES file, where faces cannot be counted in the text)
EDGE_LEVEL = ("Curve", "Edge", "Boundary", "Loop", "Wire")
#: warnings that mean the entity produced no shape (or, for a face, lost its boundary)
NOT_TRANSLATED = ("not mapped", "not translated", "no result", "failed", "natural bounds")
#: words of a message saying OCCT changed an entity's shape while translating it
REPAIRED = ("corrected", "fixed", "split on several", "split into parts", "shifted",
            "set confused")

#: IGES surface entity types that make a face of their own when nothing trims them
IGES_SURFACES = frozenset({108, 114, 118, 120, 122, 128, 140, 190, 192, 194, 196, 198})
#: IGES entities that are one face each, and the parameter (1-based after the type) that
#: points to the surface they trim or bound
IGES_FACES = {143: 2, 144: 1, 510: 1}

_STEP_STATEMENT = re.compile(rb"#(\d+)\s*=\s*([A-Za-z_0-9]*)")
_STEP_FACE_ENTITY = re.compile(rb"=\s*(?:ADVANCED_FACE|FACE_SURFACE)\s*\(")
_STEP_FACE = re.compile(rb"#(\d+)\s*=\s*(?:ADVANCED_FACE|FACE_SURFACE)\s*\(\s*'((?:[^']|'')*)'"
                        rb"\s*,\s*\((?:[^()]*)\)\s*,\s*#(\d+)")


@dataclass(frozen=True)
class DroppedEntity:
    """An entity of the file the translation produced no shape for.

    Attributes
    ----------
    label : str
        ``#55`` (STEP) or ``D17`` (IGES directory entry), as in the file.
    kind : str
        The entity's type (OCCT's class name, e.g. ``StepGeom_BSplineSurfaceWithKnots``).
    reason : str
        OCCT's check message(s).
    faces : tuple of str
        STEP: the labels and names of the faces that use it (``#17 'wing'``).
    """

    label: str
    kind: str
    reason: str
    faces: tuple[str, ...] = ()

    def as_dict(self) -> dict:
        return {"entity": self.label, "type": self.kind, "reason": self.reason,
                "faces": list(self.faces)}

    def __str__(self) -> str:
        used = f" (used by face {', '.join(self.faces)})" if self.faces else ""
        return f"{self.label} {self.kind}{used}: {self.reason}"


@dataclass(frozen=True)
class RepairedEntity:
    """An entity of the file whose shape the translation changed.

    Attributes
    ----------
    label : str
        ``#55`` (STEP) or ``D17`` (IGES directory entry), as in the file.
    kind : str
        The entity's type (OCCT's class name, e.g. ``StepShape_EdgeLoop``).
    repair : str
        OCCT's message saying what it changed.
    """

    label: str
    kind: str
    repair: str

    def as_dict(self) -> dict:
        return {"entity": self.label, "type": self.kind, "repair": self.repair}

    def __str__(self) -> str:
        return f"{self.label} {self.kind}: {self.repair}"


@dataclass(frozen=True)
class TranslationChecks:
    """:func:`translation_checks`' answer: the dropped entities, the repaired ones and the
    other notes (``(entity type, message, count)``, most frequent first)."""

    dropped: tuple[DroppedEntity, ...] = ()
    notes: tuple[tuple[str, str, int], ...] = ()
    repaired: tuple[RepairedEntity, ...] = ()


def _messages(check) -> tuple[list[str], list[str]]:
    fails = [" ".join(check.Fail(i).ToCString().split()) for i in range(1, check.NbFails() + 1)]
    warnings = [" ".join(check.Warning(i).ToCString().split())
                for i in range(1, check.NbWarnings() + 1)]
    return fails, warnings


def translation_checks(work_session, data: bytes, file_format: str,
                       translated_faces: int | None = None) -> TranslationChecks:
    """The dropped entities and the notes of the last transfer of ``work_session``
    (an ``XSControl_WorkSession``), labelled from the file's bytes ``data``;
    ``translated_faces`` is the number of distinct faces the transfer produced."""
    found, notes, changed = [], Counter(), []
    loaded = _entries(work_session.ModelCheckList(False), "load")
    process = work_session.TransferReader().TransientProcess()
    transferred = _entries(process.CheckList(False), "transfer") if process is not None else []
    if file_format == "STEP":
        start = data.find(b"DATA;")
        expected = len(_STEP_FACE_ENTITY.findall(data, start if start >= 0 else 0))
    else:
        expected = iges_face_count(data)
    lost_faces = (expected is not None and translated_faces is not None
                  and translated_faces < expected)
    load_drops = file_format != "STEP" or lost_faces
    for stage, number, kind, fails, warnings in loaded + transferred:
        lost = [w for w in warnings if any(k in w.lower() for k in NOT_TRANSLATED)]
        face_level = any(g in kind for g in FACE_LEVEL)
        edge_level = any(g in kind for g in EDGE_LEVEL)
        counts = (face_level and (stage == "transfer" or load_drops)) or (edge_level and load_drops)
        if (face_level or edge_level) and (lost or fails) and counts:
            reason = "; ".join(dict.fromkeys(fails + lost))
            if any("natural bounds" in w for w in lost):
                reason += (" (its boundary was not translated: the face came back as its whole "
                           "untrimmed surface)")
            found.append((number, kind, reason))
            fails, warnings = [], [w for w in warnings if w not in lost]
        for message in fails + warnings:
            if message in lost:
                continue
            if any(word in message.lower() for word in REPAIRED):
                changed.append((number, kind, message))
            else:
                notes[(kind, message)] += 1
    labels, faces = _labels(data, file_format, [n for n, _, _ in found + changed])
    dropped = [DroppedEntity(labels.get(n, f"entity {n}"), kind, reason,
                             tuple(faces.get(labels.get(n), ())))
               for n, kind, reason in found]
    if lost_faces:
        kinds = ("ADVANCED_FACE / FACE_SURFACE" if file_format == "STEP"
                 else "trimmed surface (143/144), face (510) or surface")
        dropped.append(DroppedEntity(
            "faces", kinds,
            f"{expected - translated_faces} of the file's {expected} faces were not translated"))
    repaired = tuple(RepairedEntity(labels.get(n, f"entity {n}"), kind, message)
                     for n, kind, message in dict.fromkeys(changed))
    return TranslationChecks(tuple(dropped),
                             tuple((k, m, c) for (k, m), c in notes.most_common()), repaired)


def iges_face_count(data: bytes) -> int:
    """The faces an IGES file holds, counted in its directory and parameter sections.

    Every trimmed surface (144), bounded surface (143) and face (510) is one face; a
    surface entity (:data:`IGES_SURFACES`; a plane 108 only when bounded, form 1 or -1)
    is one more when none of those points to it and its status does not make it
    physically dependent (subordinate switch 01 or 03: part of another entity).
    Unreadable directory entries are not counted (a file that lost its faces' entries
    shows that loss in OCCT's own checks).

    Parameters
    ----------
    data : bytes
        The whole file (80-column records: section letter in column 73).
    """
    sections: dict[str, list[str]] = {"G": [], "D": [], "P": []}
    for line in data.decode("latin-1").splitlines():
        if len(line) >= 73 and line[72] in sections:
            sections[line[72]].append(line)
    head = "".join(line[:72] for line in sections["G"]).lstrip()
    delimiter = head[2] if head.startswith("1H") and len(head) > 2 else ","
    directory, parameters = sections["D"], sections["P"]
    entries = []                             # (DE number, type, status, first P line, count, form)
    for k in range(0, len(directory) - 1, 2):
        first, second = directory[k], directory[k + 1]
        try:
            entries.append((k + 1, int(first[0:8]), first[64:72].replace(" ", "0"),
                            int(first[8:16].strip() or 0), int(second[24:32].strip() or 0),
                            int(second[32:40].strip() or 0)))
        except ValueError:
            continue
    faces, trimmed = 0, set()
    for _, kind, _, start, count, _ in entries:
        if kind in IGES_FACES:
            faces += 1
            fields = "".join(line[:64] for line in parameters[start - 1:start - 1 + count]
                             ).split(delimiter)
            try:
                trimmed.add(int(fields[IGES_FACES[kind]].strip()))
            except (ValueError, IndexError):
                pass
    for number, kind, status, _, _, form in entries:
        if (kind in IGES_SURFACES and number not in trimmed and status[2:4] not in ("01", "03")
                and not (kind == 108 and form == 0)):
            faces += 1
    return faces


def _entries(checks, stage: str) -> list[tuple[str, int, str, list[str], list[str]]]:
    """``(stage, entity number, type, fails, warnings)`` of every check of a check list."""
    out = []
    checks.Start()
    while checks.More():
        check = checks.Value()
        entity = check.Entity()
        kind = entity.DynamicType().Name() if entity is not None else "entity"
        fails, warnings = _messages(check)
        out.append((stage, checks.Number(), kind, fails, warnings))
        checks.Next()
    return out


def _labels(data: bytes, file_format: str, numbers: list[int]
            ) -> tuple[dict[int, str], dict[str, list[str]]]:
    """File labels of the transfer's entity ``numbers``, and (STEP) the faces using each."""
    if not numbers:
        return {}, {}
    if file_format != "STEP":
        return {n: f"D{2 * n - 1}" for n in numbers}, {}
    start = data.find(b"DATA;")
    body = data[start + 5:] if start >= 0 else data
    ids = [int(m.group(1)) for m in _STEP_STATEMENT.finditer(body)]
    labels = {n: f"#{ids[n - 1]}" for n in numbers if 0 < n <= len(ids)}
    wanted = set(labels.values())
    faces: dict[str, list[str]] = {}
    for m in _STEP_FACE.finditer(body):
        surface = f"#{int(m.group(3))}"
        if surface in wanted:
            name = m.group(2).decode(errors="replace").replace("''", "'")
            faces.setdefault(surface, []).append(f"#{int(m.group(1))} {name!r}" if name
                                                 else f"#{int(m.group(1))}")
    return labels, faces


def dropped_report(*models) -> list[dict]:
    """The dropped entities of ``models`` (:class:`~surfprep.plugin.io.CadModel` or None)
    for a JSON report, each with its file's name."""
    return [{"file": m.path.name if m.path is not None else None, **d.as_dict()}
            for m in models if m is not None for d in m.dropped]


def repaired_report(*models) -> list[dict]:
    """The repaired entities of ``models`` for a JSON report, each with its file's name."""
    return [{"file": m.path.name if m.path is not None else None, **r.as_dict()}
            for m in models if m is not None for r in m.repaired]
