"""Directed patches that *replace* the region they cover (001 §1, "unwanted intersections").

A directed patch of :func:`surfprep.heal` is built from the original faces
(:func:`local_approximant`); the parts of the original faces under it are then
cut away, so that two faces cutting through each other and the patch over the
crossing become the patch and the faces' remainders, met G0 along the patch's
outline:

1. the patch's four boundary curves are first put onto the original faces
   (:func:`boundary_on_faces`: every sample moved to its closest point on the
   nearest face within ``reach``), so the patch's sides lie on the faces they
   cross and the cut edges below coincide with them;
2. the region under the patch is a slab (:func:`slab`): the patch's control net
   moved ``± h`` along the normals at the Greville points (top and bottom) and
   four ruled sides between them (their edges shared exactly: boundary rows of
   the two nets), sewn into a solid;
3. every face that passes through the slab is cut: ``BRepAlgoAPI_Cut(face, slab)``
   keeps the parts outside (exact intersection curves of the face with the
   slab's sides become the new edges); slivers (a slab side, tilted with the
   patch's normals, crossing a face next to the face's own edge where the
   patch's side runs along it) are dropped; the area cut away is the face's
   area less that of the pieces kept (:func:`cut_faces`).

The remainders are read again by :func:`surfprep.heal`; a four-sided remainder
gets its own approximant and joins the patch in the network, any other has the
patch's side snapped onto its new cut edge.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_IN, TopAbs_SOLID
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

from ...algorithms import NurbsSurface
from ...algorithms.healing import local_approximant
from ...algorithms.healing.adjacency import EDGE_SAMPLES, FaceEdge, polyline_distance
from ...algorithms.healing.boundary import Boundary, as_boundary
from ...algorithms.projection import project_to_surface
from ...algorithms.trimmed import TrimmedFace
from ...errors import OpenCascadeError, SurfprepError
from ..occ.faces import face_to_nurbs, make_face
from ..occ.shapes import all_faces, compound, face_area, is_valid, sew

__all__ = ["CutModel", "FaceCut", "boundary_on_faces", "cut_faces", "cut_under_patches",
           "inner_edges", "outline", "read_faces", "rebuilt_model", "replace_pieces", "slab"]

#: samples per boundary curve put onto the faces
BOUNDARY_SAMPLES = 65
#: the slab's half thickness is this times the approximant's offset ``d`` (eq. 8)
SLAB_FACTOR = 1.0
#: samples per direction of a face tested for lying wholly under a patch
COVER_SAMPLES = 21
#: the slab reaches this times ``gap_tol`` beyond the patch's sides
MARGIN_SHARE = 0.25
#: a face is cut only when the area cut away exceeds this share of its area
MIN_CUT_SHARE = 1e-6
#: a piece left by the cut whose mean width (2 area / perimeter) is below this share of
#: the outline's size is a sliver (the slab's side crossing a face near the face's own
#: edge where the patch's side runs along it, tilted by the normals) and goes too
SLIVER_SHARE = 0.02


@dataclass(frozen=True)
class FaceCut:
    """Face ``face`` (input index) cut by directed patch ``patch``.

    ``area_before`` and ``area_cut`` are in model units squared; ``pieces`` is the
    number of faces left (0: the face lay wholly under the patch)."""

    patch: int
    face: int
    area_before: float
    area_cut: float
    pieces: int

    def as_dict(self) -> dict:
        return {"patch": self.patch, "face": self.face, "area_before": self.area_before,
                "area_cut": self.area_cut, "pieces": self.pieces}


# ---------------------------------------------------------------- boundary
def _dense(curve) -> NDArray:
    if isinstance(curve, np.ndarray):
        seg = np.linalg.norm(np.diff(curve, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        t = np.linspace(0.0, s[-1], BOUNDARY_SAMPLES)
        return np.stack([np.interp(t, s, curve[:, k]) for k in range(3)], axis=1)
    t0, t1 = curve.domain
    return curve.evaluate(np.linspace(t0, t1, BOUNDARY_SAMPLES))


def boundary_on_faces(boundary, faces: list[TrimmedFace], reach: float) -> Boundary:
    """The four boundary curves as polylines ``(BOUNDARY_SAMPLES, 3) float`` whose
    samples are moved to their closest point on the nearest of ``faces`` (the face
    surfaces) when that is within ``reach``; samples farther from every face stay."""
    bnd = as_boundary(boundary)
    out = []
    for curve in bnd.curves:
        pts = _dense(curve)
        best = np.full(len(pts), np.inf)
        moved = pts.copy()
        for face in faces:
            proj = project_to_surface(face.surface, pts)
            closer = (proj.distance < best) & (proj.distance <= reach)
            moved[closer] = proj.points[closer]
            best = np.where(closer, proj.distance, best)
        out.append(moved)
    return as_boundary(out)


# -------------------------------------------------------------------- slab
def _greville(knots: NDArray, degree: int, n: int) -> NDArray:
    return np.array([knots[i + 1:i + degree + 1].mean() for i in range(n)])


def _offset_net(surface: NurbsSurface, h: float) -> NDArray:
    nu, nv = surface.n_control
    u = _greville(surface.knots_u, surface.degree_u, nu)
    v = _greville(surface.knots_v, surface.degree_v, nv)
    gu, gv = np.meshgrid(u, v, indexing="ij")
    n = surface.normals(gu.ravel(), gv.ravel()).reshape(nu, nv, 3)
    return surface.control_points + h * n


def _ruled(row_a: NDArray, row_b: NDArray, knots: NDArray, degree: int) -> NurbsSurface:
    net = np.stack([row_a, row_b], axis=1)                      # (n, 2, 3)
    return NurbsSurface(net, knots, np.array([0.0, 0.0, 1.0, 1.0]), degree, 1)


def _widened(surface: NurbsSurface, margin: float) -> NurbsSurface:
    """``surface`` with its boundary rows of control points moved ``margin`` outwards
    (along the control polygon), so its sides lie about ``margin`` beyond the old."""
    net = surface.control_points.copy()
    for axis in (0, 1):
        for first, second in ((0, 1), (-1, -2)):
            edge = np.take(net, first, axis=axis)
            out = edge - np.take(net, second, axis=axis)
            out /= np.maximum(np.linalg.norm(out, axis=-1, keepdims=True), 1e-300)
            index = [slice(None), slice(None)]
            index[axis] = first
            net[tuple(index)] = edge + margin * out
    return replace(surface, control_points=net)


def slab(surface: NurbsSurface, h: float, tol: float, margin: float = 0.0) -> TopoDS_Shape:
    """The solid between ``surface`` offset by ``-h`` and ``+h`` (control nets moved
    along the normals at the Greville points), closed by four ruled sides, widened
    by ``margin`` beyond the surface's sides (:func:`_widened`): a side of the patch
    that runs along a face's own edge then does not cut the face along that edge (a
    tangent boolean), and a cut edge lies ``margin`` from the patch's side, within
    the ``gap_tol`` that the network and the snapping close.

    Raises
    ------
    OpenCascadeError
        The six faces do not sew into a valid solid.
    """
    surface = _widened(surface, margin) if margin > 0 else surface
    lo, hi = _offset_net(surface, -h), _offset_net(surface, h)
    ku, kv, du, dv = surface.knots_u, surface.knots_v, surface.degree_u, surface.degree_v
    faces = [NurbsSurface(lo, ku, kv, du, dv), NurbsSurface(hi, ku, kv, du, dv),
             _ruled(lo[:, 0], hi[:, 0], ku, du), _ruled(lo[:, -1], hi[:, -1], ku, du),
             _ruled(lo[0, :], hi[0, :], kv, dv), _ruled(lo[-1, :], hi[-1, :], kv, dv)]
    shape, _ = sew([make_face(s) for s in faces], tol)
    if shape.ShapeType() != TopAbs_SOLID or not is_valid(shape):
        raise OpenCascadeError("heal: the slab around the surface is no valid solid")
    solid = TopoDS.Solid_s(shape)
    classifier = BRepClass3d_SolidClassifier(solid)
    classifier.PerformInfinitePoint(tol)
    if classifier.State() == TopAbs_IN:
        solid.Reverse()
    return solid


# --------------------------------------------------------------------- cut
def _boolean(op, face: TopoDS_Face, tool: TopoDS_Shape, fuzzy: float) -> TopoDS_Shape:
    builder = op()
    from OCP.TopTools import TopTools_ListOfShape
    args, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
    args.Append(face)
    tools.Append(tool)
    builder.SetArguments(args)
    builder.SetTools(tools)
    builder.SetFuzzyValue(fuzzy)
    builder.Build()
    if not builder.IsDone():
        raise OpenCascadeError(f"heal: {op.__name__} of a face by a slab failed")
    return builder.Shape()


def _boxes_meet(face: TopoDS_Face, tool: TopoDS_Shape) -> bool:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    a, b = Bnd_Box(), Bnd_Box()
    BRepBndLib.Add_s(face, a)
    BRepBndLib.Add_s(tool, b)
    return not a.IsOut(b)


def outline(surface: NurbsSurface, n: int = BOUNDARY_SAMPLES) -> NDArray:
    """(4 n - 3, 3) float: the patch's boundary as one closed polyline."""
    t = np.linspace(0.0, 1.0, n)
    zero, one = np.zeros(n), np.ones(n)
    sides = [surface.evaluate(t, zero), surface.evaluate(one, t),
             surface.evaluate(t[::-1], one), surface.evaluate(zero, t[::-1])]
    return np.concatenate([sides[0]] + [s[1:] for s in sides[1:]])


def _is_sliver(piece: TopoDS_Face, width: float) -> bool:
    props = GProp_GProps()
    BRepGProp.LinearProperties_s(piece, props)
    return 2.0 * face_area(piece) <= width * props.Mass()


def covered(face: TrimmedFace, surface: NurbsSurface, h: float, rim: float) -> bool:
    """Whether ``face`` lies wholly under the patch ``surface``: its surface's samples
    ``(COVER_SAMPLES ** 2)`` all within ``h`` of the patch, and those whose closest
    point is on the patch's border within ``rim`` of it (the face ends at the outline).
    Such a face goes whole; a boolean with a slab whose sides run along all its edges
    would be tangent there."""
    u0, u1, v0, v1 = face.surface.domain
    t = np.linspace(0.0, 1.0, COVER_SAMPLES)
    pts = face.surface.evaluate_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0)).reshape(-1, 3)
    foot = project_to_surface(surface, pts)
    if foot.distance.max() > h:
        return False
    eps = 1e-6
    border = np.any((foot.uv <= eps) | (foot.uv >= 1.0 - eps), axis=1)
    return bool(np.all(foot.distance[border] <= rim))


def cut_faces(faces: list[TopoDS_Face], tool: TopoDS_Shape, line: NDArray, patch: int,
              fuzzy: float, whole: set[int] = frozenset()
              ) -> tuple[dict[int, list[TopoDS_Face]], list[FaceCut]]:
    """Faces passing through ``tool`` (a slab) with the part inside it cut away;
    slivers along ``line`` (the patch's :func:`outline`) dropped; the faces ``whole``
    (:func:`covered`) removed whole.

    Returns
    -------
    pieces : dict
        Face index -> the faces left (only for faces that were cut).
    cuts : list of FaceCut
    """
    pieces, cuts = {}, []
    for i, face in enumerate(faces):
        if not _boxes_meet(face, tool):
            continue
        area = face_area(face)
        if i in whole:
            pieces[i] = []
            cuts.append(FaceCut(patch, i, area, area, 0))
            continue
        result = all_faces(_boolean(BRepAlgoAPI_Cut, face, tool, fuzzy))
        if area - sum(face_area(f) for f in result) <= MIN_CUT_SHARE * area:
            continue                                     # passes by, or only touches
        width = SLIVER_SHARE * float(np.linalg.norm(np.ptp(line, axis=0)))
        left = [f for f in result
                if face_area(f) > MIN_CUT_SHARE * area and not _is_sliver(f, width)]
        inside = area - sum(face_area(f) for f in left)
        pieces[i] = left
        cuts.append(FaceCut(patch, i, area, inside, len(left)))
    return pieces, cuts


# ------------------------------------------------------------ in the pipeline
#: boundary samples are put onto faces within this share of the boundary's size
REACH_SHARE = 0.25


@dataclass(frozen=True, eq=False)
class CutModel:
    """The input with the regions under directed patches cut away.

    Attributes
    ----------
    model : CadModel
        Faces in input order, a cut face replaced by its pieces (same name).
    faces : list of TrimmedFace or None
        The faces of :attr:`model` read again.
    origin : list of int
        Input face index of every face of :attr:`model`.
    approximants : list of (int, LocalApproximant)
        Directed patch index and its approximant, built from the uncut faces.
    cuts : list of FaceCut
    """

    model: Any
    faces: list
    origin: list[int]
    approximants: list
    cuts: list[FaceCut]


def rebuilt_model(model, faces: list[TopoDS_Face], names: list, colors: list):
    return replace(model, shape=compound(faces), faces=tuple(faces), face_names=tuple(names),
                   face_colors=tuple(colors))


def cut_under_patches(model, faces: list[TrimmedFace | None], directed: list, sources: list,
                      *, tol: float | None, gap_tol: float, tight: float, skipped: list[str]
                      ) -> CutModel:
    """Approximants of the directed patches over the original faces, then the faces
    under each patch cut away (module docstring). A patch that cannot be built is
    reported in ``skipped`` and cuts nothing."""
    readable = [f for f in faces if f is not None]
    occ = list(model.faces)
    names, colors = list(model.face_names), list(model.face_colors)
    origin = list(range(len(occ)))
    done, cuts = [], []
    for k, patch in enumerate(directed):
        try:
            reach = REACH_SHARE * as_boundary(patch.boundary).size
            bnd = boundary_on_faces(patch.boundary, readable, reach)
            la = local_approximant(bnd, sources, tol=tol, gap_tol=gap_tol)
        except (SurfprepError, np.linalg.LinAlgError) as exc:
            skipped.append(f"directed {k}: no approximant ({type(exc).__name__}: {exc}); "
                           "nothing cut")
            continue
        done.append((k, la))
        try:
            h = SLAB_FACTOR * la.offset
            tool = slab(la.surface, h, tight, MARGIN_SHARE * gap_tol)
            now = read_faces(occ, names)
            whole = {i for i, f in enumerate(now) if f is not None
                     and covered(f, la.surface, h, gap_tol)}
            pieces, made = cut_faces(occ, tool, outline(la.surface), k, tight, whole)
        except OpenCascadeError as exc:
            skipped.append(f"directed {k}: faces under it not cut ({exc}); added on top")
            continue
        cuts += [replace(c, face=origin[c.face]) for c in made]
        occ, names, colors, origin = replace_pieces(pieces, occ, names, colors, origin)
    if not cuts:
        return CutModel(model, faces, list(range(len(faces))), done, [])
    return CutModel(rebuilt_model(model, occ, names, colors), read_faces(occ, names), origin, done, cuts)


def read_faces(occ: list[TopoDS_Face], names: list) -> list[TrimmedFace | None]:
    out = []
    for f, name in zip(occ, names):
        try:
            out.append(face_to_nurbs(f, name))
        except SurfprepError:
            out.append(None)          # kept as it is; heal's own reading says why
    return out


def replace_pieces(pieces: dict, occ, names, colors, origin):
    out = ([], [], [], [])
    for i, f in enumerate(occ):
        for piece in pieces.get(i, [f]):
            for lst, value in zip(out, (piece, names[i], colors[i], origin[i])):
                lst.append(value)
    return out


def covered_holes_dropped(holes: list, cut: CutModel, gap_tol: float) -> list:
    """Hole loops (lists of FaceEdge) without those whose edges all lie on the outline
    of a directed patch: the patch fills them."""
    lines = [outline(la.surface) for _, la in cut.approximants]
    return [loop for loop in holes
            if not any(all(polyline_distance(e.samples, line).max() <= gap_tol for e in loop)
                       for line in lines)]


def inner_edges(faces: list[TrimmedFace | None], skip: set[int]) -> list[FaceEdge]:
    """Real edges of the inner loops (holes) of the faces not in ``skip``, sampled like
    :func:`.heal_topology.face_edges` (``k`` counts from -1 down): a directed patch in
    the middle of a face leaves a hole whose edges the patch's sides are snapped to."""
    out = []
    for i, face in enumerate(faces):
        if face is None or i in skip:
            continue
        inner = [lp for n, lp in enumerate(face.loops) if n != face.outer_loop_index]
        for k, e in enumerate(e for lp in inner for e in lp.edges):
            if e.degenerated or e.curve3d is None or e.is_seam:
                continue
            t0, t1 = e.curve3d.domain
            out.append(FaceEdge(i, -1 - k, e.curve3d,
                                e.curve3d.evaluate(np.linspace(t0, t1, EDGE_SAMPLES))))
    return out
