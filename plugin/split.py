"""``surfprep.split``: faces cut along their intersection curves, the pieces sharing the cut edges.

:func:`split` intersects ``a`` with ``b`` (or ``a`` with itself) by
:func:`surfprep.intersect`, hands every face its curves as cuts in its own
parameters (each curve has a pcurve on both faces) to
:func:`~surfprep.algorithms.face_split.split_face`, records the pieces and the uncut
faces with the edges they share by use
(:class:`~surfprep.algorithms.nonmanifold.NonManifoldModel`) and builds the
OpenCascade faces from that structure (:func:`~.occ.structure.structure_to_occ`):
every edge one ``TopoDS_Edge`` shared by all its faces (where two surfaces cross,
four pieces share one intersection edge), nothing sewn. Every face comes out on its
B-spline form (an analytic face converted exactly). Should OpenCascade find a piece
built so invalid, each face is built on its own and the faces are sewn
(``SplitResult.assembled``). A curve that stops inside a face (where a fin
stands on a sheet, or over its border: a spur) divides nothing: it becomes an
INTERNAL edge of the face, shared with the faces that end on it (a T-junction: one
edge, three faces). A face the arrangement or the builder refuses is kept whole and
named with the reason; nothing is dropped.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from OCP.TopoDS import TopoDS

from ..algorithms.face_split import Cut, split_face
from ..algorithms.nonmanifold import NonManifoldModel
from ..errors import OpenCascadeError, SurfprepError
from .booleans import OPERATIONS, BooleanResult, select_pieces
from .convert import to_nurbs
from .intersect import IntersectionResult, intersect
from .io import as_model, named_model
from .occ.faces import trimmed_face_to_occ
from .occ.shapes import compound, count_free_edges, face_area, is_valid, sew
from .occ.structure import structure_to_occ

__all__ = ["SplitFace", "SplitResult", "boolean", "boolean_all", "split", "trim"]


@dataclass(frozen=True)
class SplitFace:
    """What became of one face: ``operand`` ``"a"`` or ``"b"``, its index there, the
    number of curves cutting it, the pieces (OpenCascade faces), or why it was kept whole."""

    operand: str
    index: int
    cuts: int
    pieces: tuple = ()
    kept: str | None = None


@dataclass(frozen=True)
class SplitResult:
    """The split model: every piece and every uncut face, one shell sharing their edges.

    Attributes
    ----------
    shape : TopoDS_Shape
        The faces in one shell built from the edges they share (non-manifold where
        surfaces cross), or sewn when built so a face was invalid (``assembled``).
    faces : tuple of SplitFace
        One per face that had a curve.
    curves : IntersectionResult
    free_edges : int
        Edges of ``shape`` used by one face only.
    shared_edges : dict
        Number of edges by the number of faces using them (``{2: 31, 4: 1}``).
    valid : bool
        BRepCheck on every piece.
    pieces_a, pieces_b : tuple of TopoDS_Face
        Every face of ``a`` (of ``b``) after the cut: the pieces and the uncut faces.
    """

    shape: Any
    faces: tuple[SplitFace, ...]
    curves: IntersectionResult
    free_edges: int
    shared_edges: dict
    valid: bool
    time_s: float = field(default=0.0, compare=False)
    pieces_a: tuple = field(default=(), repr=False, compare=False)
    pieces_b: tuple = field(default=(), repr=False, compare=False)
    #: the pieces and uncut faces as trimmed faces, with the edges they share by use
    #: (:class:`~surfprep.algorithms.nonmanifold.NonManifoldModel`, same order as
    #: ``pieces_a + pieces_b``)
    structure: NonManifoldModel | None = field(default=None, repr=False, compare=False)
    #: the models cut (``a``, ``b`` or None) and the sewing tolerance, for :meth:`select`
    operands: tuple = field(default=(), repr=False, compare=False)
    sew_tol: float = field(default=0.0, compare=False)
    #: each operand's faces as trimmed faces, when converted (None: not yet)
    operand_faces: tuple = field(default=(None, None), repr=False, compare=False)
    #: how ``shape`` was put together: ``"structure"`` (built from ``structure``, every
    #: edge one TopoDS_Edge shared by its faces) or ``"sewing"`` (a piece was invalid as
    #: built so: each face built alone and OpenCascade's sewing joined them)
    assembled: str = "structure"
    #: faces of a and b on each other, ``(f, g, along)`` indices into ``structure.faces``
    #: (normals agreeing or not): ``shape`` holds ``f`` once, ``g``'s piece is it
    coincident: tuple = field(default=(), compare=False)

    def faces_of(self, operand: int) -> list:
        """Operand ``operand``'s (0: a, 1: b) faces as trimmed faces: those the split
        converted, else converted now."""
        return (self.operand_faces[operand] if self.operand_faces[operand] is not None
                else to_nurbs(self.operands[operand]))

    def select(self, operation: str, *, keep: str = "front") -> BooleanResult:
        """A Boolean-like result as a selection of this split's pieces (002 §1), without
        cutting again: ``"fuse"``, ``"cut"`` (a minus b), ``"common"`` of two solids
        (:func:`~.booleans.boolean`), or ``"trim"``: a's pieces on the ``keep`` side
        (``"front"``: where b's normals point, or ``"back"``) of the sheet b
        (:func:`~.booleans.trim`)."""
        return select_pieces(self, operation, keep=keep)

    def fuse(self) -> BooleanResult:
        return self.select("fuse")

    def cut(self) -> BooleanResult:
        return self.select("cut")

    def common(self) -> BooleanResult:
        return self.select("common")

    @property
    def geometry(self) -> Any:
        return self.shape

    def report(self) -> dict:
        """Plain JSON: per cut face its curves and pieces (or why it was kept whole); per
        output face its origin, name and area; per intersection edge its faces, length
        and largest distance from each surface; the edges by the number of faces using
        them (OpenCascade's sewing, and ours by use), free edges, validity, time."""
        return {"faces": [{"operand": f.operand, "index": f.index, "cuts": f.cuts, "pieces": len(f.pieces),
                           "kept_whole": f.kept} for f in self.faces],
                "curves": len(self.curves), "pieces": sum(len(f.pieces) for f in self.faces),
                "free_edges": self.free_edges,
                "edges_by_faces": {str(k): v for k, v in sorted(self.shared_edges.items())},
                "valid": self.valid, "time_s": self.time_s, "assembled": self.assembled,
                "coincident_faces": len(self.coincident),
                "intersection_edges": [
                    {"faces": list(r.faces), "closed": r.closed, "length": r.length,
                     "max_distance_a": d.to_a, "max_distance_b": d.to_b}
                    for r, d in ((r, r.max_deviation()) for r in self.curves)],
                "output_faces": self.output_faces(),
                **({} if self.structure is None else {"structure": {
                    "edges_by_uses": {str(k): v for k, v in self.structure.edges_by_uses().items()},
                    "components": len(self.structure.components())}})}

    def names(self) -> list[str | None]:
        """Per output face (``pieces_a + pieces_b``) its name: an uncut face keeps its own,
        the pieces of a cut face get it (else ``a3``, ``b0``...) with a suffix ``.1``,
        ``.2``, ..."""
        if self.structure is None:
            return [None] * (len(self.pieces_a) + len(self.pieces_b))
        out, seen = [], {}
        cut = {(f.operand, f.index) for f in self.faces if f.kept is None}
        for trimmed, (operand, index) in zip(self.structure.faces, self.structure.origins):
            name = trimmed.name
            if (operand, index) in cut:
                seen[(operand, index)] = seen.get((operand, index), 0) + 1
                name = f"{name or f'{operand}{index}'}.{seen[(operand, index)]}"
            out.append(name)
        return out

    def output_faces(self) -> list[dict]:
        """Per output face (``pieces_a + pieces_b``): the operand and face it came from,
        its name (:meth:`names`), its area (GProp, 1e-9) and, for a piece of b lying on
        one of a (:attr:`coincident`), ``same_as``: the index of a's."""
        if self.structure is None:
            return []
        same = {g: f for f, g, _ in self.coincident}
        return [{"operand": operand, "face": index, "name": name, "area": face_area(face, 1e-9),
                 **({"same_as": same[k]} if k in same else {})}
                for k, (face, name, (operand, index)) in enumerate(zip(self.pieces_a + self.pieces_b, self.names(),
                                                                       self.structure.origins))]

    def as_model(self):
        """``shape`` as a :class:`~surfprep.plugin.io.CadModel` whose faces carry
        :meth:`names` (written to STEP through XDE)."""
        return named_model(self.shape, self.pieces_a + self.pieces_b, self.names())


def _share_internal_edges(shape, tol: float):
    """``shape`` with every INTERNAL edge of a face (a curve that stops inside it, where a
    fin stands on a sheet) replaced by the edge of the other faces lying on it -- a
    boundary edge, or another face's internal edge (a fin over the sheet's border) --
    when there is one over the same points and parameters: sewing joins boundary edges
    only, and the junction is then one edge used by all its faces. The face's pcurve is
    added to the shared edge. Unchanged when nothing matches."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepTools import BRepTools_ReShape
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_INTERNAL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    def probe(edge) -> tuple[np.ndarray, float, float]:
        c = BRepAdaptor_Curve(edge)
        a, b = c.FirstParameter(), c.LastParameter()
        return np.array([[c.Value(t).X(), c.Value(t).Y(), c.Value(t).Z()]
                         for t in (a, 0.5 * (a + b), b)]), a, b
    internal, others = [], []
    faces = TopExp_Explorer(shape, TopAbs_FACE)
    while faces.More():
        face = TopoDS.Face_s(faces.Current())
        faces.Next()
        edges = TopExp_Explorer(face, TopAbs_EDGE)
        while edges.More():
            edge = TopoDS.Edge_s(edges.Current())
            edges.Next()
            (internal if edge.Orientation() == TopAbs_INTERNAL else others).append((edge, face))
    if not internal:
        return shape
    reshape, builder = BRepTools_ReShape(), BRep_Builder()
    changed = False
    # an internal edge may be shared with a boundary edge of other faces, or with an
    # internal edge of another face (a fin over a sheet's border: a spur in both)
    targets = others + internal
    probes = [probe(e) for e, _ in targets]
    replaced: set[int] = set()
    for k, (edge, face) in enumerate(internal):
        if k + len(others) in replaced:
            continue                              # already the shared edge of another face
        p, a, b = probe(edge)
        span = max(abs(b - a), 1e-300)
        for j, ((other, other_face), (q, c, d)) in enumerate(zip(targets, probes)):
            if other.IsSame(edge) or other_face.IsSame(face) or j in replaced:
                continue
            if np.max(np.abs(p - q)) <= tol and abs(a - c) + abs(b - d) <= 1e-9 * span:
                pcurve = BRep_Tool.CurveOnSurface_s(edge, face, a, b)
                builder.UpdateEdge(other, pcurve, face, max(BRep_Tool.Tolerance_s(edge), tol))
                reshape.Replace(edge, other.Oriented(TopAbs_INTERNAL))
                replaced.add(k + len(others))
                changed = True
                break
    if not changed:
        return shape
    return _merge_internal_vertices(reshape.Apply(shape), tol)


def _merge_internal_vertices(shape, tol: float):
    """The vertices of INTERNAL edges made the same as the other vertices at their place
    (a spur's end on a face's border is the border's vertex there), so the faces meeting
    at the junction share it."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepLib import BRepLib
    from OCP.BRepTools import BRepTools_ReShape
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FORWARD, TopAbs_INTERNAL, TopAbs_VERTEX
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    def vertices_of(root):
        out, explorer = [], TopExp_Explorer(root, TopAbs_VERTEX)
        while explorer.More():
            v = TopoDS.Vertex_s(explorer.Current())
            p = BRep_Tool.Pnt_s(v)
            out.append((v, np.array([p.X(), p.Y(), p.Z()])))
            explorer.Next()
        return out
    inner, explorer = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        if explorer.Current().Orientation() == TopAbs_INTERNAL:
            inner.extend(vertices_of(explorer.Current()))
        explorer.Next()
    everything = vertices_of(shape)
    reshape, changed, builder = BRepTools_ReShape(), False, BRep_Builder()
    for v, p in inner:
        for w, q in everything:
            gap = float(np.linalg.norm(p - q))
            if not w.IsSame(v) and gap <= max(tol, BRep_Tool.Tolerance_s(w)) \
                    and not any(w.IsSame(x) for x, _ in inner):
                # the vertex must hold the internal edge's end as well as its own
                builder.UpdateVertex(w, max(BRep_Tool.Tolerance_s(w), gap + BRep_Tool.Tolerance_s(v)))
                # both FORWARD: the reshape then keeps each occurrence's own orientation
                # (a vertex explored through an INTERNAL edge comes INTERNAL)
                reshape.Replace(v.Oriented(TopAbs_FORWARD), w.Oriented(TopAbs_FORWARD))
                changed = True
                break
    if not changed:
        return shape
    merged = reshape.Apply(shape)
    # the vertex must hold the ends of the edge's 3D curve and of its pcurves on every face
    BRepLib.UpdateTolerances_s(merged, True)
    return merged


def _edge_uses(shape) -> dict:
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape
    edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
    out: dict = {}
    for k in range(1, edge_faces.Extent() + 1):
        n = edge_faces.FindFromIndex(k).Size()
        out[n] = out.get(n, 0) + 1
    return out


def split(a: Any, b: Any = None, *, tol: float | None = None, method: str = "auto",
          tool: bool = False) -> SplitResult:
    """The faces of ``a`` and ``b`` (or of ``a`` alone) cut along their intersection curves.

    Parameters
    ----------
    a, b
        What :func:`surfprep.intersect` takes (paths, models, shapes, cadquery and
        build123d objects). With ``b`` None, the faces of ``a`` are cut along the
        curves where they meet one another.
    tol : float, optional
        The intersection's tolerance (model units; its default).
    method : str
        The intersection method.
    tool : bool
        ``b`` only cuts: ``a``'s faces are split and returned, ``b``'s are not (a hull
        split at a waterline by a plane larger than it).

    Returns
    -------
    SplitResult

    Examples
    --------
    >>> import cadquery as cq                                          # doctest: +SKIP
    >>> out = split(cq.Workplane().sphere(10), cq.Workplane().box(30, 30, 1))  # doctest: +SKIP
    >>> out.report()["pieces"]                                         # doctest: +SKIP
    4
    """
    started = time.perf_counter()
    model_a = as_model(a)
    model_b = None if b is None else as_model(b)
    curves = intersect(model_a, model_b, tol=tol, method=method)
    cuts: dict[tuple[str, int], list[Cut]] = {}
    trimmed: dict[tuple[str, int], Any] = {}
    for r in curves:
        c = r.curve
        for operand, face, pcurve in (("a", r.face_a, c.pcurve_a), ("b" if b is not None else "a", r.face_b,
                                                                      c.pcurve_b)):
            if pcurve is None:
                continue
            key = (operand, face.index)
            cuts.setdefault(key, []).append(Cut(pcurve, c.curve3d))
            trimmed[key] = face.trimmed
    done: list[SplitFace] = []
    regions_of: dict[tuple[str, int], list] = {}
    refused: dict[tuple[str, int], str] = {}
    listed: list = []                                        # (trimmed face, (operand, index))
    converted: dict[str, list] = {}
    operands = [("a", model_a), ("b", None if tool else model_b)]
    for operand, model in operands:
        if model is None:
            continue
        whole = converted[operand] = to_nurbs(model)
        for k in range(len(model.faces)):
            key = (operand, k)
            if key in cuts:
                try:
                    regions_of[key] = split_face(trimmed[key], cuts[key], tol3d=10.0 * (curves.tol or 0.0))
                except SurfprepError as exc:
                    refused[key] = str(exc)
            listed.extend(((r, key) for r in regions_of[key]) if key in regions_of else [(whole[k], key)])
    size = model_a.size if model_b is None else max(model_a.size, model_b.size)
    sew_tol = max(1e-7 * size, 10.0 * (curves.tol or 0.0))
    structure = NonManifoldModel.build([t for t, _ in listed], [o for _, o in listed], tol=sew_tol)
    # faces of a and b lying on each other (coplanar faces of overlapping solids) are one
    # face of the result: a's, which b's pieces list as theirs too
    coincident = tuple(structure.coincident_faces()) if model_b is not None and not tool else ()
    twin = {g: (f, along) for f, g, along in coincident}
    unique = [k for k in range(len(structure.faces)) if k not in twin]
    try:
        built = structure_to_occ(structure, unique, tol=sew_tol)
    except OpenCascadeError:
        built = None
    if built is not None and built.valid:
        own = dict(zip(unique, built.faces))
        faces = [own[k] if k not in twin else
                 (own[twin[k][0]] if twin[k][1] else TopoDS.Face_s(own[twin[k][0]].Reversed()))
                 for k in range(len(structure.faces))]
        shape, assembled = built.shell, "structure"
    else:
        coincident = ()
        # a piece OpenCascade finds invalid as built from the structure: each face built
        # on its own (make_face checks and fixes it; a region it refuses keeps its face
        # whole) and the faces sewn
        faces, listed = _faces_one_by_one(operands, converted, listed, regions_of, refused)
        structure = NonManifoldModel.build([t for t, _ in listed], [o for _, o in listed], tol=sew_tol)
        shape = sew(faces, sew_tol, non_manifold=True)[0] if len(faces) > 1 else compound(faces)
        shape, assembled = _share_internal_edges(shape, sew_tol), "sewing"
    pieces: dict[tuple[str, int], list] = {}
    for face, (_, key) in zip(faces, listed):
        pieces.setdefault(key, []).append(face)
    for (operand, k), face_cuts in cuts.items():
        if operand == "b" and tool:
            continue
        done.append(SplitFace(operand, k, len(face_cuts), tuple(pieces[(operand, k)]), refused.get((operand, k))))
    done.sort(key=lambda f: (f.operand, f.index))
    # built from the structure, every face has passed BRepCheck already (built.valid)
    valid = assembled == "structure" or all(is_valid(p) for f in done for p in f.pieces)
    n_a = sum(1 for _, (operand, _) in listed if operand == "a")
    return SplitResult(shape, tuple(done), curves, count_free_edges(shape), _edge_uses(shape), valid,
                       time.perf_counter() - started, tuple(faces[:n_a]), tuple(faces[n_a:]),
                       structure, (model_a, model_b), sew_tol,
                       (converted.get("a"), converted.get("b")), assembled, coincident)


def _faces_one_by_one(operands, converted, listed, regions_of, refused) -> tuple[list, list]:
    """Every face of ``listed`` built on its own (:func:`trimmed_face_to_occ`); the regions
    of a cut face any of which it refuses are replaced by the face whole (its reason in
    ``refused``). Returns the faces and the (trimmed face, origin) list they match."""
    faces, kept = [], []
    shapes = {operand: model for operand, model in operands if model is not None}
    done_keys = set()
    for trimmed_face, key in listed:
        if key in done_keys:
            continue
        if key not in regions_of:
            faces.append(shapes[key[0]].faces[key[1]])
            kept.append((trimmed_face, key))
            continue
        done_keys.add(key)
        try:
            built = [trimmed_face_to_occ(region) for region in regions_of[key]]
        except SurfprepError as exc:
            refused[key] = str(exc)
            faces.append(shapes[key[0]].faces[key[1]])
            kept.append((converted[key[0]][key[1]], key))
            continue
        faces.extend(built)
        kept.extend((region, key) for region in regions_of[key])
    return faces, kept


def boolean(a: Any, b: Any, operation: str, *, tol: float | None = None, method: str = "auto") -> BooleanResult:
    """Fuse, cut (``a`` minus ``b``) or common of two solids, from their split pieces.

    Every face of ``a`` and of ``b`` is cut along the intersection curves
    (:func:`split`); each piece is classified by a point inside it against the
    other solid (ray parity on the exact trimmed surfaces, in the math layer:
    :func:`~surfprep.algorithms.containment.piece_states`), and the operation keeps
    (fuse) the pieces of each outside the other, (common) those inside, (cut) ``a``'s
    outside ``b`` and ``b``'s inside ``a`` turned over. Pieces on the other's boundary
    (coincident faces) count once: where the normals agree (coplanar faces of two
    overlapping boxes) ``a``'s piece is kept by fuse and common; where they are opposed
    (two solids touching) fuse and common drop both and cut keeps ``a``'s. The kept
    pieces are built into the result sharing the split's edges.

    Raises
    ------
    InvalidGeometryError
        An unknown operation.
    OpenCascadeError
        An operand that is not a closed solid.
    """
    from ..errors import InvalidGeometryError
    if operation not in OPERATIONS:
        raise InvalidGeometryError(f"unknown operation {operation!r}; expected one of {', '.join(OPERATIONS)}")
    return split(as_model(a), as_model(b), tol=tol, method=method).select(operation)


def boolean_all(operands: Sequence[Any], operation: str, *, tol: float | None = None,
                method: str = "auto") -> BooleanResult:
    """Fuse or common of N solids, or the first minus all the others (``"cut"``), pairwise:
    ``((a op b) op c) op ...``, each step a :func:`boolean` of the result so far (its
    faces on their B-spline form) with the next operand.

    Returns
    -------
    BooleanResult
        The last step's, with the ones before it in ``steps``.

    Raises
    ------
    InvalidGeometryError
        Fewer than two operands, an unknown operation.
    OpenCascadeError
        An operand, or a step's result, that is not a closed solid (a common that comes
        out empty ends the chain here too).
    """
    from ..errors import InvalidGeometryError
    operands = list(operands)
    if len(operands) < 2:
        raise InvalidGeometryError(f"boolean_all needs at least two operands, got {len(operands)}")
    if operation not in OPERATIONS:
        raise InvalidGeometryError(f"unknown operation {operation!r}; expected one of {', '.join(OPERATIONS)}")
    steps: list[BooleanResult] = []
    current: Any = operands[0]
    for operand in operands[1:]:
        if steps and not steps[-1].closed:
            raise OpenCascadeError(f"step {len(steps)} of the {operation} is not a closed solid: "
                                   "nothing to go on with")
        step = boolean(current, operand, operation, tol=tol, method=method)
        steps.append(step)
        current = step.shape
    last = steps[-1]
    return BooleanResult(last.shape, last.operation, last.split, last.kept, last.closed, last.valid,
                         last.named, tuple(steps[:-1]))


def trim(a: Any, b: Any, *, keep: str = "front", tol: float | None = None,
         method: str = "auto") -> BooleanResult:
    """The faces of ``a`` trimmed by a sheet ``b``: cut where they meet it and the pieces on
    one side of it kept (002 §1's "trim A by B" for an open sheet: the side by its
    normal).

    Parameters
    ----------
    a, b
        What :func:`split` takes; ``b`` an open sheet (or any faces) reaching over the
        pieces of ``a`` to be judged.
    keep : {"front", "back"}
        The side ``b``'s normals point to, or the other.
    tol, method
        As :func:`split`.

    Returns
    -------
    BooleanResult
        ``operation`` ``"trim-front"`` / ``"trim-back"``, ``kept`` (pieces of a, 0), the
        kept pieces in a shell (a solid only if they close).

    Raises
    ------
    InvalidGeometryError
        An unknown ``keep``, or a piece of ``a`` the sheet does not reach over (its side
        is not defined).
    """
    from ..errors import InvalidGeometryError
    if keep not in ("front", "back"):
        raise InvalidGeometryError(f"keep must be 'front' or 'back', got {keep!r}")
    return split(as_model(a), as_model(b), tol=tol, method=method, tool=True).select("trim", keep=keep)
