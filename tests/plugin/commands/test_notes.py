"""Notes grouped by kind for the CLI (plugin/commands/notes.py)."""

from __future__ import annotations

from surfprep.plugin.commands.notes import grouped


def test_notes_differing_only_in_numbers_are_one_line_naming_the_others():
    notes = [f"patch {a} side v1 and patch {b} side v0 touch over part of their length only"
             for a, b in ((5, 6), (5, 7), (10, 14))]
    notes += ["face 3: not moved (its fit leaves 8.83e-05 > 5.46e-06); kept as it is",
              "7 edges between faces that cannot move left open",
              "face 12: not moved (its fit leaves 0.000184 > 5.46e-06); kept as it is"]
    out = grouped(notes)
    assert out == [
        notes[0] + " [and 2 more like it: patches 5-7, 10-14]",
        notes[3] + " [and 1 more like it: face 12]",
        notes[4]]


def test_distinct_notes_are_kept_in_order():
    notes = ["face 1: kept", "faces [2, 4] fail BRepCheck", "a sliver"]
    assert grouped(notes) == ["face 1: kept", "faces [2, 4] fail BRepCheck", "a sliver"]
    assert grouped(["faces [2, 4] fail", "faces [7] fail"]) == [
        "faces [2, 4] fail [and 1 more like it: face 7]"]
    assert grouped(["faces 15 and 35 overlap", "faces 16 and 20 overlap",
                    "faces 16 and 21 overlap"]) == [
        "faces 15 and 35 overlap [and 2 more like it: faces 16-20, 16-21]"]
