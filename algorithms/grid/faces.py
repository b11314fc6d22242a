"""Which trimmed faces a structured grid can cover: four-sided on their surface's rectangle.

A face is gridded as one block when its boundary is the whole parameter
rectangle of its surface: one loop, every edge's pcurve on a side of the
rectangle, and all four sides reached (a collapsed side, a pole, is a
degenerated edge or no edge at all). Anything else -- a face with holes, a face
trimmed inside its surface, an n-sided face -- is refused with the reason, so a
user knows to heal or split it first.
"""

from __future__ import annotations

import numpy as np

from ..trimmed import TrimmedFace

__all__ = ["four_sided_reason"]

#: pcurve samples per edge checked against the rectangle
SAMPLES = 9
#: how close to a side of the rectangle (fraction of the domain's span) a pcurve must run
SIDE_TOL = 1e-6


def four_sided_reason(face: TrimmedFace) -> str | None:
    """None when the face is its surface's whole parameter rectangle, else why not.

    Parameters
    ----------
    face : TrimmedFace

    Returns
    -------
    str or None
    """
    if not face.loops:
        return None                                          # the natural boundary
    if len(face.loops) > 1:
        return f"it has {len(face.loops) - 1} hole(s): not four-sided"
    u0, u1, v0, v1 = face.surface.domain
    span = max(u1 - u0, v1 - v0)
    tol = SIDE_TOL * span
    reached = set()
    for edge in face.loops[0].edges:
        uv = edge.pcurve.evaluate(np.linspace(edge.t0, edge.t1, SAMPLES))
        on = {"u0": np.abs(uv[:, 0] - u0) <= tol, "u1": np.abs(uv[:, 0] - u1) <= tol,
              "v0": np.abs(uv[:, 1] - v0) <= tol, "v1": np.abs(uv[:, 1] - v1) <= tol}
        sides = [name for name, mask in on.items() if np.all(mask)]
        if not sides:
            if edge.degenerated:
                continue
            return ("it is trimmed inside its surface (an edge runs off the parameter "
                    "rectangle's sides): heal or split it into four-sided faces first")
        reached.update(sides)
    missing = {"u0", "u1", "v0", "v1"} - reached
    if missing:
        return (f"its boundary leaves side(s) {', '.join(sorted(missing))} of the parameter "
                "rectangle uncovered: not four-sided")
    return None
