"""What a STEP/IGES translation left out, and what it changed, from OCCT's own checks.

OCCT's readers skip an entity they cannot translate (a surface with decreasing
knots, a ragged pole net, a negative weight, an IGES degree of -1) with at most a
line in a check list nobody reads: the model comes back with fewer faces and no
word. After a transfer every entity's checks sit in the work session's
transfer process; :func:`translation_checks` reads them once:

* **dropped**: an entity of a surface, face or curve type with a *fail*, or with
  the warning that it was "not mapped" to a shape: named by its file label
  (``#55`` in STEP, the directory entry ``D17`` in IGES), its type, the names of
  the STEP faces that used it, and OCCT's reason;
* **notes**: every other message, counted by entity type and text ("Surface
  forced to be periodic" x 23): what OCCT repaired on the way.

STEP labels come from the file itself: the transfer numbers entities in the order
of the DATA section, and the text gives each number's ``#id``.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

__all__ = ["DroppedEntity", "TranslationChecks", "translation_checks"]

#: entity types whose loss loses geometry (OCCT type names contain one of these)
GEOMETRIC = ("Surface", "Face", "Curve", "Shell", "Solid", "Plane")
#: warnings that mean the entity produced no shape
NOT_TRANSLATED = ("not mapped", "not translated", "no result", "failed")

_STEP_STATEMENT = re.compile(rb"#(\d+)\s*=\s*([A-Za-z_0-9]*)")
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
class TranslationChecks:
    """:func:`translation_checks`' answer: the dropped entities and the other notes
    (``(entity type, message, count)``, most frequent first)."""

    dropped: tuple[DroppedEntity, ...] = ()
    notes: tuple[tuple[str, str, int], ...] = ()


def _messages(check) -> tuple[list[str], list[str]]:
    fails = [" ".join(check.Fail(i).ToCString().split()) for i in range(1, check.NbFails() + 1)]
    warnings = [" ".join(check.Warning(i).ToCString().split())
                for i in range(1, check.NbWarnings() + 1)]
    return fails, warnings


def translation_checks(work_session, data: bytes, file_format: str) -> TranslationChecks:
    """The dropped entities and the notes of the last transfer of ``work_session``
    (an ``XSControl_WorkSession``), labelled from the file's bytes ``data``."""
    process = work_session.TransferReader().TransientProcess()
    if process is None:
        return TranslationChecks()
    checks = process.CheckList(False)
    found, notes = [], Counter()
    checks.Start()
    while checks.More():
        check, number = checks.Value(), checks.Number()
        entity = check.Entity()
        kind = entity.DynamicType().Name() if entity is not None else "entity"
        fails, warnings = _messages(check)
        lost = [w for w in warnings if any(k in w.lower() for k in NOT_TRANSLATED)]
        if any(g in kind for g in GEOMETRIC) and (fails or lost):
            found.append((number, kind, "; ".join(dict.fromkeys(fails + lost))))
        for message in fails + warnings:
            if message not in lost and message not in fails:
                notes[(kind, message)] += 1
        checks.Next()
    labels, faces = _labels(data, file_format, [n for n, _, _ in found])
    dropped = tuple(DroppedEntity(labels.get(n, f"entity {n}"), kind, reason,
                                  tuple(faces.get(labels.get(n), ())))
                    for n, kind, reason in found)
    return TranslationChecks(dropped, tuple((k, m, c) for (k, m), c in notes.most_common()))


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
