"""Which pieces of faces cut through each other are overshoots
(algorithms/healing/overshoots.py), on pieces built directly as flat quads: two sheets
crossing, a fin standing through a sheet, two sheets crossing half way, a closed box
whose walls and lid overshoot each other."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.heal_cases import bilinear_quad

from surfprep.algorithms.healing.overshoots import OVERSHOOT_SHARE, overshoot_pieces
from surfprep.algorithms.trimmed import TrimmedFace, natural_loop

GAP = 1e-4


def quad(p00, p10, p01, p11) -> TrimmedFace:
    surface = bilinear_quad(p00, p10, p01, p11)
    return TrimmedFace(surface, (natural_loop(surface),))


def area(face: TrimmedFace) -> float:
    c = face.surface.control_points
    return float(np.linalg.norm(np.cross(c[-1, 0] - c[0, 0], c[0, -1] - c[0, 0])))


def line(a, b, n=33):
    t = np.linspace(0.0, 1.0, n)[:, None]
    return (1 - t) * np.asarray(a, float) + t * np.asarray(b, float)


def decide(pieces, origin, curves, faces):
    return overshoot_pieces(pieces, origin, np.array([area(p) for p in pieces]), curves,
                            faces, GAP)


def crossing_sheets(beyond_a: float, beyond_b: float):
    """Sheet A in z = 0 over x in [0, 1 + beyond_a], sheet B in x = 1 over z in
    [-beyond_b, 1]: cut at x = 1, z = 0 into A1 (x < 1), A2, B1 (z < 0), B2."""
    a1 = quad((0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0))
    a2 = quad((1, 0, 0), (1 + beyond_a, 0, 0), (1, 1, 0), (1 + beyond_a, 1, 0))
    b1 = quad((1, 0, -beyond_b), (1, 0, 0), (1, 1, -beyond_b), (1, 1, 0))
    b2 = quad((1, 0, 0), (1, 0, 1), (1, 1, 0), (1, 1, 1))
    return [a1, a2, b1, b2], [0, 0, 1, 1], [line((1, 0, 0), (1, 1, 0))], [(0, 1)]


def test_two_sheets_each_overshooting_lose_their_small_pieces():
    pieces, origin, curves, faces = crossing_sheets(0.2, 0.3)
    dropped, (decision,) = decide(pieces, origin, curves, faces)
    assert dropped == {1, 2} and decision.reason is None and decision.dropped == (1, 2)


def test_pieces_of_about_the_same_area_are_left_with_the_reason():
    # B crosses A half way: neither side of B is an overshoot
    pieces, origin, curves, faces = crossing_sheets(0.2, 1.0)
    dropped, (decision,) = decide(pieces, origin, curves, faces)
    assert dropped == set() and decision.dropped == ()
    assert "about the same area" in decision.reason
    # just inside the share, B's lower piece is an overshoot again
    pieces, origin, curves, faces = crossing_sheets(0.2, 0.99 * OVERSHOOT_SHARE)
    assert decide(pieces, origin, curves, faces)[0] == {1, 2}


def test_an_overshoot_joined_to_a_face_no_curve_cuts_is_left():
    # A's piece beyond the crossing continues into a face C of its own: dropping the
    # piece would orphan C (a crossing removes pieces of the faces it cuts, never whole
    # faces), so the crossing is left and says why
    pieces, origin, curves, faces = crossing_sheets(0.2, 0.3)
    c = quad((1.2, 0, 0), (1.3, 0, 0), (1.2, 1, 0), (1.3, 1, 0))
    dropped, (decision,) = decide(pieces + [c], origin + [2], curves, faces)
    assert dropped == set() and "no curve cuts" in decision.reason


def test_a_fin_through_a_sheet_is_not_a_crossing_of_two_overshoots():
    # fin B stands on sheet A at x = 1 and runs through it below; A continues on both
    # sides of x = 1 with pieces of the same area: A has no overshoot, nothing is dropped
    pieces, origin, curves, faces = crossing_sheets(1.0, 0.3)
    dropped, (decision,) = decide(pieces, origin, curves, faces)
    assert dropped == set() and decision.reason.startswith("face 0")


def closed_box_overshooting(over: float = 0.1, height: float = 1.1):
    """A unit cube's bottom, its four walls running up to ``height`` and its lid at z = 1
    reaching ``over`` beyond the walls (the lid as a centre square and four strips)."""
    h, o = height, over
    bottom = quad((0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0))
    corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
    mains, flaps = [], []
    for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1]):
        mains.append(quad((x0, y0, 0), (x1, y1, 0), (x0, y0, 1), (x1, y1, 1)))
        flaps.append(quad((x0, y0, 1), (x1, y1, 1), (x0, y0, h), (x1, y1, h)))
    centre = quad((0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1))
    rim = [quad((-o, -o, 1), (1 + o, -o, 1), (0, 0, 1), (1, 0, 1)),
           quad((1, 0, 1), (1 + o, -o, 1), (1, 1, 1), (1 + o, 1 + o, 1)),
           quad((0, 1, 1), (1, 1, 1), (-o, 1 + o, 1), (1 + o, 1 + o, 1)),
           quad((-o, -o, 1), (0, 0, 1), (-o, 1 + o, 1), (0, 1, 1))]
    pieces = [bottom] + mains + flaps + [centre] + rim
    origin = [0, 1, 2, 3, 4, 1, 2, 3, 4, 5, 5, 5, 5, 5]
    curves = [line((x0, y0, 1), (x1, y1, 1))
              for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1])]
    return pieces, origin, curves, [(1, 5), (2, 5), (3, 5), (4, 5)]


def test_a_closed_box_loses_the_walls_collar_and_the_lids_rim():
    pieces, origin, curves, faces = closed_box_overshooting()
    dropped, decisions = decide(pieces, origin, curves, faces)
    # the flaps (5-8) join round the box into one dangling collar; the rim strips
    # (10-13) into one dangling ring; the walls' lower parts, the bottom and the lid's
    # centre are the closed part
    assert dropped == {5, 6, 7, 8, 10, 11, 12, 13}
    assert all(d.reason is None for d in decisions)


@pytest.mark.parametrize("over", [0.1, 3.0])
def test_the_side_joined_to_the_closed_part_wins_whatever_the_areas(over):
    # a lid reaching 3 beyond the walls: its rim is 48 times its centre, still dropped
    pieces, origin, curves, faces = closed_box_overshooting(over=over, height=5.0)
    dropped, _ = decide(pieces, origin, curves, faces)
    assert dropped == {5, 6, 7, 8, 10, 11, 12, 13}
