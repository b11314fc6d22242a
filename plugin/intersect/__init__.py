"""Intersection curves of faces: :func:`intersect` on anything that holds faces.

For every pair of faces (across ``a`` and ``b``, or within ``a`` when ``b`` is
None) whose boxes overlap (each face's box: its surface restricted to the box of
its loops in ``(u, v)``, :meth:`TrimmedFace.bounding_box`), the two *surfaces* are
intersected by
:func:`surfprep.algorithms.intersection.intersect_surfaces`. Every curve is
then clipped to both faces' trimmed domains
(:func:`surfprep.algorithms.intersection.clip_curve`: the point-in-face test of
:class:`surfprep.algorithms.face_region.FaceRegion` on each face, crossings
located on the interpolants and moved onto the exact trimming pcurves).

**Shared edges** (faces of one shape): adjacent faces meet along their common
edge, which is an intersection of their surfaces but not one of the faces. With
``b`` None a piece is dropped when all its samples lie within ``max(10 tol, 2 x
edge tolerance)`` of the trimming loops of *either* face, or the two faces lie on
each other from the piece to their loops (a tangent join;
:func:`surfprep.algorithms.intersection.along_a_boundary`): faces of one valid
shape meet only along edges. Across ``a`` and ``b`` nothing is dropped (a face of
``b`` touching an edge of ``a`` is an answer there).

Each result is a :class:`FaceIntersection` (the piece, the two faces' indices
and names, and how it was found); :meth:`FaceIntersection.to_edges` builds a
``TopoDS_Edge`` with the 3D curve and a pcurve on each face
(:func:`surfprep.plugin.occ.edges.make_edge`, checked by BRepCheck).

**Methods** (``method=``, :class:`Method`):

* ``"mesh"``: the triangle method alone
  (:func:`surfprep.algorithms.intersection.intersect_surfaces`);
* ``"characteristic"``: the characteristic-curve method of paper 002 alone
  (:func:`surfprep.algorithms.characteristic.characteristic_intersection`);
* ``"auto"`` (default): the triangle method, then the characteristic points as
  a certificate (:func:`surfprep.algorithms.characteristic.certify`): every
  closed loop they imply must be among the curves; a loop the triangles missed
  is traced, refined to ``tol`` and added (``found_by`` ``"characteristic"``).
  When the characteristic stage finds the surfaces coincident over their whole
  grid, the triangle method is not run at all (it would only produce debris).

**The result** is an :class:`IntersectionResult`: a ``list`` of
FaceIntersection (so every existing use of the returned list works as
before) with three more attributes: ``isolated_points`` (tangential contact
points, :class:`ContactPoint`: a contact is a point, not a curve, and is not
dropped), ``coincident`` (:class:`CoincidentFaces`: face pairs whose surfaces
coincide within ``tol`` over a region, with that region) and ``records`` (the
characteristic record of every face pair, :class:`PairRecord`, for reports and
plots).
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...algorithms.characteristic import CharacteristicRecord, face_coincidence
from ...algorithms.intersection import IntersectionCurve, along_a_boundary, clip_curve, closed_in_space
from ...algorithms.tolerance import check_tolerance
from ...errors import InvalidGeometryError, TimeLimitExceeded
from ...inputs import ShapeLike
from ..occ.edges import make_edge
from .methods import (
    CoincidentFaces,
    ContactPoint,
    FoundBy,
    IntersectionResult,
    Method,
    PairRecord,
    StoppedPair,
    pair_curves,
)
from .operands import DEFAULT_TOL_FACTOR, MIN_TOL_FACTOR, FaceOperand, face_operands

__all__ = [
    "DEFAULT_TOL_FACTOR",
    "MIN_TOL_FACTOR",
    "CoincidentFaces",
    "ContactPoint",
    "FaceIntersection",
    "FaceOperand",
    "FoundBy",
    "IntersectionResult",
    "Method",
    "PairRecord",
    "StoppedPair",
    "face_operands",
    "intersect",
]

# ------------------------------------------------------------------ result
@dataclass(frozen=True, eq=False)
class FaceIntersection:
    """One intersection curve of two faces, clipped to both.

    Attributes
    ----------
    curve : IntersectionCurve
        Samples, (u, v) on each face's surface, interpolants.
    face_a, face_b : FaceOperand
        The faces (``face_b`` from ``b``, or from ``a`` when ``b`` was None).
    tol : float
        The tolerance the curve was computed to (model units).
    found_by : FoundBy
        ``MESH`` (the triangle method) or ``CHARACTERISTIC`` (traced from a
        characteristic point: with ``method="auto"``, a loop the triangles missed).
    """

    curve: IntersectionCurve
    face_a: FaceOperand
    face_b: FaceOperand
    tol: float
    found_by: FoundBy = FoundBy.MESH

    @property
    def points(self) -> NDArray:
        return self.curve.points

    @property
    def closed(self) -> bool:
        """Closed in space (a loop cut at a seam included)."""
        return closed_in_space(self.curve, self.tol)

    @property
    def length(self) -> float:
        return self.curve.length

    @property
    def faces(self) -> tuple[int, int]:
        """Indices of the two faces in their operands."""
        return self.face_a.index, self.face_b.index

    def max_deviation(self):
        """:meth:`IntersectionCurve.max_deviation` from both faces' surfaces."""
        return self.curve.max_deviation(self.face_a.surface, self.face_b.surface)

    def to_edges(self, tol: float | None = None) -> list:
        """``[TopoDS_Edge]``: the 3D curve with a pcurve on each face, checked by BRepCheck.

        ``tol`` (edge tolerance) defaults to the larger of the curve's tolerance
        and its measured deviation from the surfaces.
        """
        c = self.curve
        if c.curve3d is None or c.pcurve_a is None or c.pcurve_b is None:
            raise InvalidGeometryError("the curve has no interpolants to build an edge from")
        if tol is None:
            tol = max(self.tol, 1.01 * self.max_deviation().max)
        fa, fb = self.face_a.face_for_edges(), self.face_b.face_for_edges()
        pcurves = [(c.pcurve_a, fa)]
        if not fb.IsSame(fa):
            pcurves.append((c.pcurve_b, fb))
        return [make_edge(c.curve3d, pcurves, tol)]


# ------------------------------------------------------------------ driver
def _boxes(faces: Sequence[FaceOperand], *, trimmed: bool = False) -> NDArray:
    """``(n, 2, 3)`` control-net boxes of the faces' surfaces; with ``trimmed`` of the
    faces themselves (a face cut from a larger surface gets the box of the surface
    restricted to its loops' parameter box, :meth:`TrimmedFace.bounding_box`)."""
    if not faces:
        return np.zeros((0, 2, 3))
    return np.stack([np.asarray(f.trimmed.bounding_box() if trimmed else
                                f.surface.bounding_box(), dtype=float) for f in faces])


def _size(boxes: NDArray) -> float:
    return float(np.linalg.norm(boxes[:, 1].max(axis=0) - boxes[:, 0].min(axis=0)))


def _contacts(record: CharacteristicRecord | None, fa: FaceOperand, fb: FaceOperand,
              tol: float, within: bool) -> list[ContactPoint]:
    """The record's isolated points inside both faces (not on a shared edge within a shape)."""
    if record is None:
        return []
    out = []
    for p in record.isolated_points:
        ra, rb = fa.region, fb.region
        if not (ra.contains(p.uv_a[None], tol)[0] and rb.contains(p.uv_b[None], tol)[0]):
            continue
        if within:
            near = max(10 * tol, 2 * max(ra.edge_tolerance(), rb.edge_tolerance()))
            if min(ra.edge_distance(p.point[None])[0], rb.edge_distance(p.point[None])[0]) \
                    <= near:
                continue
        out.append(ContactPoint(p.point, p.uv_a, p.uv_b, fa, fb))
    return out


def _one_pair(fa: FaceOperand, fb: FaceOperand, tol: float, mesh_tol: float | None,
              method: Method, within: bool):
    """The curves of one face pair clipped to both faces (not those along a shared edge
    ``within`` one operand), its contact points, coincident regions and its record."""
    curves, found_by, record = pair_curves(fa, fb, tol, mesh_tol, method, within=within)
    pieces = [FaceIntersection(piece, fa, fb, tol, how)
              for curve, how in zip(curves, found_by)
              for piece in clip_curve(curve, fa.region, fb.region, tol)
              if not (within and along_a_boundary(piece, fa.region, fb.region, tol))]
    coincident = []
    if record is not None and record.coincident:
        region = face_coincidence(fa.region, fb.region, tol)    # the faces, not the surfaces
        if region is not None:
            coincident.append(CoincidentFaces(fa, fb, region))
    return pieces, _contacts(record, fa, fb, tol, within), coincident, (record, tuple(curves))


def _mesh_operand(a, b):
    """``(mesh, other)`` when one operand is a triangle mesh (a ``TriangleMesh``, or the path
    of an STL file or a Plot3D surface grid), ``(None, None)`` when neither is."""
    from ...algorithms.intersection import TriangleMesh
    from ..file_format import is_mesh_file
    from .mesh_operand import read_mesh

    def as_mesh(x):
        if isinstance(x, TriangleMesh):
            return x
        if isinstance(x, (str, os.PathLike)) and is_mesh_file(x):
            return read_mesh(x)
        return None
    ma, mb = as_mesh(a), None if b is None else as_mesh(b)
    if ma is None and mb is None:
        return None, None
    if b is None or (ma is not None and mb is not None):
        raise InvalidGeometryError("a triangle mesh is intersected with exact faces: give one "
                                   "mesh and one model, face or surface")
    return (ma, b) if ma is not None else (mb, a)


def intersect(a: ShapeLike, b: ShapeLike | None = None, *, tol: float | None = None,
              mesh_tol: float | None = None, method: Method | str = Method.AUTO,
              progress: Callable[[int, int], None] | None = None) -> IntersectionResult:
    """Intersection curves of the faces of ``a`` with those of ``b`` (or among ``a``'s).

    Parameters
    ----------
    a, b
        Faces, shapes, :class:`CadModel`, ``Geom_Surface`` (finite),
        :class:`NurbsSurface`, :class:`TrimmedFace`, cadquery / build123d
        objects, or lists of these. With ``b`` None, every pair of distinct
        faces of ``a`` is intersected and common edges of adjacent faces are
        not reported (module docstring).
    tol : float, optional
        Model units; default ``DEFAULT_TOL_FACTOR`` (1e-6) times the diagonal
        of the box of all faces. Must not be below ``MIN_TOL_FACTOR`` (1e-9)
        times that diagonal.
    mesh_tol : float, optional
        Tessellation tolerance per pair (default: 1e-3 times the pair's size).
    method : Method or str
        ``"auto"`` (default), ``"mesh"`` or ``"characteristic"`` (module docstring).
    progress : callable(done, total), optional
        Called with ``done = 0`` once the face pairs whose boxes overlap are
        known, then after each of them. A pair interrupted by
        :class:`~surfprep.errors.TimeLimitExceeded` (raised into it by the caller,
        as ``surfprep intersect --pair-time-limit`` does from a timer) is recorded
        in ``stopped`` with a warning, and the run goes on.

    Returns
    -------
    IntersectionResult
        (A :class:`~surfprep.plugin.intersect.mesh_operand.MeshIntersectionResult`
        when one operand is a triangle mesh: a ``TriangleMesh``, an ``.stl`` path or a
        Plot3D surface grid's;
        its curves lie on the exact faces within ``tol`` and as near the surface the
        mesh stands for as the mesh itself.)
        A list of FaceIntersection: pieces clipped to both faces, in face-pair
        order, each with ``found_by``. Curves that break ``tol`` (near-tangential
        or overlapping surfaces, where the refinement does not converge) are left
        out (``StrayCurves.DROP``); a pair whose intersection fails raises no
        error: it is skipped with a warning. Also ``isolated_points``
        (tangential contacts), ``coincident`` (face pairs coinciding over a
        region) and ``records`` (the characteristic record per pair).

    Raises
    ------
    InvalidToleranceError
        ``tol`` not finite and positive, below ``MIN_TOL_FACTOR`` times the size
        (beyond what the refinement reaches reliably) or larger than the size.
    ConversionError
        An operand without faces or of an unsupported type.
    ValueError
        An unknown ``method``.

    Examples
    --------
    The sheet ``z = 0.1 x y`` over the unit square cut by the plane ``y = 0.5``:

    >>> import numpy as np, surfprep
    >>> from surfprep.algorithms.fitting import interpolate_surface
    >>> u, v = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    >>> sheet = interpolate_surface(np.stack([u, v, 0.1 * u * v], axis=-1))
    >>> plane = interpolate_surface(np.stack([u, 0.5 + 0 * v, v - 0.5], axis=-1))
    >>> cut = surfprep.intersect(sheet, plane, tol=1e-7)
    >>> len(cut), round(cut[0].length, 6)               # the segment z = 0.05 x: sqrt(1.0025)
    (1, 1.001249)
    >>> dev = cut[0].max_deviation()                    # from both surfaces, between samples too
    >>> bool(dev.to_a <= 1e-7 and dev.to_b <= 1e-7)
    True
    >>> cut.report()["curves"][0]["found_by"]
    <FoundBy.MESH: 'mesh'>
    """
    mesh, other = _mesh_operand(a, b)
    if mesh is not None:                      # a triangle mesh against exact faces
        from .mesh_operand import intersect_mesh
        return intersect_mesh(mesh, other, tol=tol, mesh_tol=mesh_tol, progress=progress)
    start_time = time.perf_counter()
    method = Method(method)
    faces_a = face_operands(a)
    faces_b = faces_a if b is None else face_operands(b)
    size = _size(_boxes(faces_a if b is None else faces_a + faces_b))
    if not size > 0:
        raise InvalidGeometryError("the faces to intersect have no extent (a zero-size model)")
    if tol is None:
        tol = DEFAULT_TOL_FACTOR * size
    tol = check_tolerance(tol, "tol", low=MIN_TOL_FACTOR * size, high=size)
    pad = tol
    boxes_a = _boxes(faces_a, trimmed=True)
    boxes_b = boxes_a if b is None else _boxes(faces_b, trimmed=True)
    overlap = np.all((boxes_a[:, None, 0] <= boxes_b[None, :, 1] + pad)
                     & (boxes_b[None, :, 0] <= boxes_a[:, None, 1] + pad), axis=-1)
    if b is None:
        overlap &= np.triu(np.ones_like(overlap), k=1).astype(bool)
    pairs = np.argwhere(overlap)
    out = IntersectionResult(method=method, tol=tol)
    if progress is not None:
        progress(0, len(pairs))
    for done, (i, j) in enumerate(pairs, start=1):
        fa, fb = faces_a[i], faces_b[j]
        start = time.perf_counter()
        try:
            pieces, contacts, coincident, record = _one_pair(fa, fb, tol, mesh_tol, method,
                                                             within=b is None)
        except TimeLimitExceeded:
            stopped = StoppedPair(fa, fb, time.perf_counter() - start)
            out.stopped.append(stopped)
            warnings.warn(f"faces {fa.index} and {fb.index}: stopped by the time limit after "
                          f"{stopped.time_s:.0f} s; the curves of this pair are missing",
                          stacklevel=2)
        else:                  # a pair counts whole or not at all
            out.extend(pieces)
            out.isolated_points += contacts
            out.coincident += coincident
            out.records.append(PairRecord(fa, fb, record[0], record[1],
                                          time.perf_counter() - start))
        if progress is not None:
            progress(done, len(pairs))
    out.time_s = time.perf_counter() - start_time
    return out
