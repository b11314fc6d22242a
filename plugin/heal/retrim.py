"""Faces re-trimmed to their neighbours' edges, in the model (for :func:`surfprep.heal`).

:func:`surfprep.algorithms.healing.retrim.retrim_faces` decides which free edges of
which faces are replaced by their neighbours' edges lying on the face's surface;
here the re-trimmed faces are built (``make_face``: edge tolerances the measured
distance of the new edges from the surface, ``BRepCheck`` valid) and put in the
model in place of the old ones, names and colours kept. A face OpenCascade refuses
is kept as it was, with a note.
"""

from __future__ import annotations

from ...algorithms.healing.adjacency import FaceEdge, pair_gaps
from ...algorithms.healing.retrim import retrim_faces
from ...algorithms.trimmed import TrimmedFace
from ...errors import SurfprepError
from ..occ.faces import face_to_nurbs, trimmed_face_to_occ
from .cut import rebuilt_model

__all__ = ["retrim_to_neighbours"]


def retrim_to_neighbours(model, faces: list[TrimmedFace | None], edges: list[FaceEdge],
                         pairs: list[tuple[int, int]], *, tol: float | None, tight: float,
                         kept: set[int], skipped: list[str], wide: bool = True):
    """The faces of ``model`` whose free edges run beside neighbours' edges lying on
    their surfaces, re-trimmed to those edges; so are the faces in ``kept`` (no
    approximant will replace them: not four-sided and not split) whose edges are
    paired with an edge of another face in ``kept`` but farther than ``tight`` from
    it (where a neighbour is re-approximated, its approximant's side is fitted to
    the kept face's edge and closes the gap entirely). ``wide`` False: the paired
    edges only (after the approximants, for the faces whose approximant failed).

    Returns
    -------
    model : CadModel
        ``model`` itself when nothing was re-trimmed.
    faces : list of TrimmedFace or None
        Same indices; the re-trimmed faces as read back from their new OpenCascade
        faces.
    retrims : list of Retrim
    """
    paired = {k for pair in pairs for k in pair}
    free = [k for k in range(len(edges)) if k not in paired] if wide else []
    loose = [(own, other, float(gap))
             for (a, b), gap in zip(pairs, pair_gaps(edges, pairs)) if gap > tight
             if edges[a].face in kept and edges[b].face in kept for own, other in ((a, b), (b, a))]
    if not free and not loose:
        return model, faces, []
    new, found, refused = retrim_faces(faces, edges, free, pairs=pairs, loose=loose, tol=tol)
    by_why: dict[str, list[tuple[int, float]]] = {}
    for face, why, figure in refused:
        by_why.setdefault(why, []).append((face, figure))
    for why, group in by_why.items():
        worst = max(figure for _, figure in group)
        which = (f"face {group[0][0]}: not re-trimmed to its" if len(group) == 1 else
                 f"faces {', '.join(str(f) for f, _ in group)}: not re-trimmed to their")
        skipped.append(f"{which} neighbours' edges ({why}"
                       + (f", up to {worst:.3g} off)" if worst else ")"))
    occ, out, done = list(model.faces), list(faces), []
    for r in found:
        name = model.face_names[r.face]
        try:
            face = trimmed_face_to_occ(new[r.face])
            read_back = face_to_nurbs(face, name)
        except SurfprepError as exc:
            skipped.append(f"face {r.face}: not re-trimmed to its neighbours' edges ({exc})")
            continue
        occ[r.face], out[r.face] = face, read_back
        done.append(r)
        edges_word = "edge" if len(r.partners) == 1 else "edges"
        skipped.append(f"face {r.face}: re-trimmed to {len(r.partners)} {edges_word} of its "
                       f"neighbours lying on its surface (its loop moved up to {r.width:.3g}; "
                       f"the new edges within {r.deviation:.3g} of the surface)")
    if not done:
        return model, faces, []
    return rebuilt_model(model, occ, list(model.face_names), list(model.face_colors)), out, done

