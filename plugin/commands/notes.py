"""Notes printed by the CLI, grouped by kind: one line per kind with the faces or patches
it names, instead of one line per face (the JSON report keeps every note)."""

from __future__ import annotations

import re

__all__ = ["grouped"]

_LIST = re.compile(r"\[[\d,\s]+\]")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?")
_SINGULAR = {"faces": "face", "patches": "patch"}
_PLURAL = {"face": "faces", "patch": "patches"}
_SUBJECT = re.compile(r"\b(face|faces|patch|patches)\s+\[?(\d+(?:(?:,\s*| and )\d+)*)\]?")


def grouped(notes: list[str]) -> list[str]:
    """``notes`` with those that differ only in their numbers merged into one line: the
    first of them, then how many more there are and what they name (``faces 12, 17``, or
    ``patches 5-7`` for a note naming two patches).

    Examples
    --------
    >>> grouped(["face 3: not moved (its fit leaves 8.8e-05 > 5.5e-06); kept as it is",
    ...          "face 12: not moved (its fit leaves 0.00018 > 5.5e-06); kept as it is",
    ...          "7 edges left open"])
    ['face 3: not moved (its fit leaves 8.8e-05 > 5.5e-06); kept as it is [and 1 more like it: face 12]', '7 edges left open']
    """
    kinds: dict[str, list[str]] = {}
    for note in notes:
        kinds.setdefault(_NUMBER.sub("#", _LIST.sub("[#]", note)), []).append(note)
    out = []
    for same in kinds.values():
        if len(same) == 1:
            out.append(same[0])
            continue
        names = [_subject(note) for note in same[1:]]
        word = _SUBJECT.search(same[0])
        noun = "note" if word is None else _SINGULAR.get(word.group(1), word.group(1))
        noun = _PLURAL.get(noun, noun) if len(names) > 1 else noun
        listed = ", ".join(n for n in names if n) or "..."
        out.append(f"{same[0]} [and {len(same) - 1} more like it: {noun} {listed}]")
    return out


def _subject(note: str) -> str:
    """What a note names: its face or patch numbers, joined by '-' (``5-6`` for "patch 5
    side v1 and patch 6 side v0")."""
    return "-".join(m.group(2).replace(" and ", "-").replace(" ", "") for m in _SUBJECT.finditer(note))
