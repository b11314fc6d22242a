"""Original geometry taking part in a local approximant: selection, triangulation, clipping
(001 §4, 000 §29.3.3, 003 "block").

A source is a :class:`NurbsSurface`, a :class:`TriangleMesh` (a discretized
geometry with no parametric form, e.g. STL data), or a :class:`SurfaceSource`
pairing both: a surface and a triangulation of the part of it that exists
(a trimmed face), whose vertices carry their ``(u, v)``.

Clipping, against the box of the upper and lower offsets:

1. a surface whose control-net box misses the box is dropped (a B-spline
   surface lies in the convex hull of its control points); a mesh whose
   vertex box misses it likewise;
2. the other surfaces are triangulated near the box only
   (:func:`..intersection.tessellation.tessellate` with the box as keep box, so
   Bézier patches whose control nets miss it are never refined);
3. triangles whose box misses the box are dropped ("all vertices left of ...
   the bounding box").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from weakref import WeakKeyDictionary

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError, SurfprepError
from ..face_region import inside_loops
from ..intersection.culling import patch_rectangles
from ..intersection.mesh import TriangleMesh
from ..intersection.tessellation import tessellate
from ..surface import NurbsSurface
from ..trimmed import TrimmedFace, is_natural, loop_uv

__all__ = [
    "ClippedTriangles",
    "Source",
    "SurfaceSource",
    "as_sources",
    "clip_sources",
    "face_source",
    "trim_regions",
    "trimmed_source",
]

#: default chord tolerance of :func:`trimmed_source`, fraction of the surface's box diagonal
TRIM_MESH_FRACTION = 1e-3
#: rectangles across the trimming loops' (u, v) box, per direction, that a trimmed
#: face's triangulation has at least (a narrow face on a flat surface is resolved)
TRIM_CELLS = 8
#: a surface at most this many times the clipping box's size is triangulated whole and kept
CACHE_SIZE_RATIO = 4.0
#: a kept triangulation serves chord tolerances up to this factor coarser than its own
CACHE_TOL_RANGE = 4.0
_SURFACE_MESHES: WeakKeyDictionary = WeakKeyDictionary()
_MESH_TRIANGLES: WeakKeyDictionary = WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class SurfaceSource:
    """An original surface, its triangulation, or both.

    Attributes
    ----------
    surface : NurbsSurface or None
        Exact geometry: hits are mapped onto it (eqs. 9-10) and distances are
        measured to it.
    mesh : TriangleMesh or None
        The triangulation to project onto. With a surface it must carry
        ``uv`` (the parameters of its vertices on ``surface``) and stands for
        the part of the surface that exists (trimmed faces, holes); without
        a mesh the whole surface is triangulated.
    name : str
        Free label, reported back (e.g. the face's name).
    """

    surface: NurbsSurface | None = None
    mesh: TriangleMesh | None = None
    name: str = ""

    def __post_init__(self) -> None:
        if self.surface is None and self.mesh is None:
            raise InvalidGeometryError("a SurfaceSource needs a surface, a mesh or both")
        if self.surface is not None and (not isinstance(self.surface, NurbsSurface)
                                         or self.surface.dimension != 3):
            raise InvalidGeometryError("SurfaceSource.surface must be a 3D NurbsSurface")
        if self.mesh is not None and not isinstance(self.mesh, TriangleMesh):
            raise InvalidGeometryError("SurfaceSource.mesh must be a TriangleMesh")
        if self.surface is not None and self.mesh is not None and self.mesh.uv is None:
            raise InvalidGeometryError(
                "a SurfaceSource with both surface and mesh needs the mesh's (u, v)")

    def box(self) -> NDArray:
        """(2, 3) float: control-net box of the surface, else the mesh's box."""
        if self.mesh is not None:
            return self.mesh.bounding_box()
        return self.surface.bounding_box()


Source = NurbsSurface | TriangleMesh | SurfaceSource


def trimmed_source(surface: NurbsSurface, loops: Sequence[NDArray], *,
                   mesh_tol: float | None = None, name: str = "",
                   straddle: bool = True) -> SurfaceSource:
    """A trimmed face as a source: its surface and a triangulation of the part that exists.

    The surface is triangulated (:func:`..intersection.tessellation.tessellate`)
    over the Bézier patches that meet the loops' ``(u, v)`` box, split so that
    each is at most :data:`TRIM_CELLS`-th of that box per direction (the chord
    tolerance alone leaves a flat surface a few triangles, and a face trimmed
    narrow on it — a lens 4 mm wide on a 25 mm patch — would keep none inside
    its loops), and the triangles that lie outside the trimming loops (even-odd,
    :func:`inside_loops`) are dropped, so projections onto the face miss its holes
    and the parts trimmed away. The rim is as fine as the triangulation: with
    ``straddle`` a triangle with a corner inside is kept (the face reaches a
    triangle beyond its loops, where a trim gap to its neighbours lies), without
    it only those whose centroid is inside.

    Parameters
    ----------
    surface : NurbsSurface
    loops : sequence of (n_k, 2) float
        The trimming loops sampled in ``(u, v)`` (e.g. the pcurves' points).
    mesh_tol : float, optional
        Chord tolerance, model units; default :data:`TRIM_MESH_FRACTION` times
        the control-net box diagonal.
    name : str
    straddle : bool
        Keep the triangles across the loops too (a corner inside).
    """
    if mesh_tol is None:
        mesh_tol = TRIM_MESH_FRACTION * float(np.linalg.norm(np.ptp(surface.bounding_box(),
                                                                      axis=0)))
    mesh = tessellate(surface, mesh_tol, trim_regions(surface, loops)).mesh
    corners = mesh.triangle_uv()                                         # (t, 3, 2)
    keep = inside_loops(corners.mean(axis=1), loops)
    if straddle:
        keep |= inside_loops(corners.reshape(-1, 2), loops).reshape(-1, 3).any(axis=1)
    if not np.any(keep):
        raise InvalidGeometryError(
            f"no part of the surface lies inside the trimming loops{f' of {name}' if name else ''}")
    trimmed = TriangleMesh.from_arrays(mesh.vertices, mesh.triangles[keep], mesh.uv)
    return SurfaceSource(surface, trimmed, name)


def trim_regions(surface: NurbsSurface, loops: Sequence[NDArray], cells: int = TRIM_CELLS
                 ) -> NDArray:
    """Parameter rectangles to triangulate a trimmed face over: ``(r, 4) float``.

    The Bézier patches of ``surface`` that meet the bounding box of ``loops``
    (``(n_k, 2) float`` each), halved (at the floating-point midpoint, as the
    tessellation splits, so shared edges keep bitwise equal parameters) in u
    while wider than ``1 / cells`` of the box's u extent, likewise in v.
    """
    uv = np.concatenate([np.asarray(lp, dtype=float).reshape(-1, 2) for lp in loops])
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    rects = patch_rectangles(surface)
    meets = ((rects[:, 0] <= hi[0]) & (rects[:, 1] >= lo[0])
             & (rects[:, 2] <= hi[1]) & (rects[:, 3] >= lo[1]))
    rects = rects[meets] if np.any(meets) else rects
    width = np.maximum(hi - lo, 1e-12 * (np.ptp(rects[:, :2]) + np.ptp(rects[:, 2:])))
    for axis in (0, 1):
        a, b = 2 * axis, 2 * axis + 1
        for _ in range(16):                    # 2^16 halvings at most
            wide = rects[:, b] - rects[:, a] > width[axis] / cells
            if not np.any(wide):
                break
            mid = 0.5 * (rects[wide, a] + rects[wide, b])
            first, second = rects[wide].copy(), rects[wide].copy()
            first[:, b], second[:, a] = mid, mid
            rects = np.concatenate([rects[~wide], first, second])
            keep = ((rects[:, a] <= hi[axis]) & (rects[:, b] >= lo[axis]))
            rects = rects[keep]
    return rects


def as_sources(sources: Sequence[Source] | Source) -> tuple[SurfaceSource, ...]:
    """Normalize a source or a sequence of sources to :class:`SurfaceSource`.

    Raises
    ------
    InvalidGeometryError
        No source, or an object of another type.
    """
    if isinstance(sources, (NurbsSurface, TriangleMesh, SurfaceSource)):
        sources = [sources]
    out = []
    for k, s in enumerate(sources):
        if isinstance(s, SurfaceSource):
            out.append(s)
        elif isinstance(s, NurbsSurface):
            out.append(SurfaceSource(surface=s))
        elif isinstance(s, TriangleMesh):
            out.append(SurfaceSource(mesh=s))
        else:
            raise InvalidGeometryError(
                f"source {k} must be a NurbsSurface, TriangleMesh or SurfaceSource, "
                f"got {type(s).__name__}")
    if not out:
        raise InvalidGeometryError("no original surfaces given: nothing to approximate")
    return tuple(out)


@dataclass(frozen=True, eq=False)
class ClippedTriangles:
    """Triangles of all sources that may lie in the offsets' box.

    Attributes
    ----------
    points : (t, 3, 3) float
        Corners ``[triangle, corner, xyz]``.
    uv : (t, 3, 2) float
        Corner parameters on the triangle's source surface (NaN without one).
    source : (t,) int
        Index of the triangle's source in :attr:`sources`.
    sources : tuple of SurfaceSource
        All sources given (indices refer to them).
    kept : (s,) bool
        Sources whose box meets the offsets' box.
    box : (2, 3) float
        The box clipped to.
    """

    points: NDArray
    uv: NDArray
    source: NDArray
    sources: tuple
    kept: NDArray
    box: NDArray

    @property
    def n_triangles(self) -> int:
        return self.points.shape[0]

    def restrict(self, box: NDArray) -> ClippedTriangles:
        """The triangles (and sources) that may lie in a smaller ``box`` (2, 3)."""
        tri_boxes = np.stack([self.points.min(axis=1), self.points.max(axis=1)], axis=1)
        keep = _overlaps(box, tri_boxes) if self.n_triangles else np.zeros(0, bool)
        kept = self.kept & np.array([bool(_overlaps(box, s.box())) for s in self.sources])
        keep &= kept[self.source] if self.n_triangles else keep
        return ClippedTriangles(self.points[keep], self.uv[keep], self.source[keep],
                                self.sources, kept, np.array(box, dtype=float))

    def covers(self, box: NDArray) -> bool:
        """True when ``box`` lies inside the box these triangles were clipped to."""
        return bool(np.all(box[0] >= self.box[0]) and np.all(box[1] <= self.box[1]))


def _overlaps(box_a: NDArray, box_b: NDArray) -> NDArray:
    """Closed overlap of box ``(2, 3)`` with boxes ``(..., 2, 3)``."""
    return np.all((box_b[..., 0, :] <= box_a[1]) & (box_b[..., 1, :] >= box_a[0]), axis=-1)


def _surface_triangles(surface: NurbsSurface, box: NDArray, mesh_tol: float
                       ) -> tuple[NDArray, NDArray]:
    """Triangles ``(t, 3, 3)`` and parameters ``(t, 3, 2)`` of a surface near ``box``.

    A surface not much larger than the box is triangulated whole, once, and
    kept (per surface, weakly) for every later box whose chord tolerance lies in
    ``[tol, CACHE_TOL_RANGE * tol]``: heal projects many approximants onto the same
    neighbours. A large surface is triangulated near the box only, every time.
    """
    surface_size = float(np.linalg.norm(np.ptp(surface.bounding_box(), axis=0)))
    box_size = float(np.linalg.norm(np.ptp(box, axis=0)))
    if surface_size > CACHE_SIZE_RATIO * box_size:
        mesh = tessellate(surface, mesh_tol, keep_boxes=box[None]).mesh
        return mesh.triangle_points(), mesh.triangle_uv()
    entries = _SURFACE_MESHES.setdefault(surface, [])
    for tol, points, uv in entries:
        if mesh_tol / CACHE_TOL_RANGE <= tol <= mesh_tol:
            return points, uv
    tol = mesh_tol / np.sqrt(CACHE_TOL_RANGE)
    mesh = tessellate(surface, tol).mesh
    entries.append((tol, mesh.triangle_points(), mesh.triangle_uv()))
    return entries[-1][1], entries[-1][2]


def _mesh_triangles(mesh: TriangleMesh, with_uv: bool) -> tuple[NDArray, NDArray]:
    """Triangle corners and parameters of a source's own mesh (computed once per mesh)."""
    cached = _MESH_TRIANGLES.get(mesh)
    if cached is None:
        pts = mesh.triangle_points()
        uv = (mesh.triangle_uv() if with_uv and mesh.uv is not None
              else np.full(pts.shape[:2] + (2,), np.nan))
        cached = (pts, uv)
        _MESH_TRIANGLES[mesh] = cached
    return cached


def _source_mesh(source: SurfaceSource, box: NDArray, mesh_tol: float
                 ) -> tuple[NDArray, NDArray]:
    """Triangle corners (t, 3, 3) and parameters (t, 3, 2) of one source near ``box``."""
    if source.mesh is not None:
        pts, uv = _mesh_triangles(source.mesh, source.surface is not None)
    else:
        pts, uv = _surface_triangles(source.surface, box, mesh_tol)
    keep = _overlaps(box, np.stack([pts.min(axis=1), pts.max(axis=1)], axis=1))
    return pts[keep], uv[keep]


def clip_sources(sources: tuple[SurfaceSource, ...], box: NDArray, *, mesh_tol: float
                 ) -> ClippedTriangles:
    """Select, triangulate and clip the sources against ``box`` (module docstring).

    Parameters
    ----------
    sources : tuple of SurfaceSource
    box : (2, 3) float
    mesh_tol : float > 0
        Chord tolerance of the triangulation of surfaces without a mesh.
    """
    kept = np.array([bool(_overlaps(box, s.box())) for s in sources])
    pts, uv, src = [np.zeros((0, 3, 3))], [np.zeros((0, 3, 2))], [np.zeros(0, np.int64)]
    for k in np.flatnonzero(kept):
        p, q = _source_mesh(sources[k], box, mesh_tol)
        pts.append(p)
        uv.append(q)
        src.append(np.full(p.shape[0], k, np.int64))
    return ClippedTriangles(np.concatenate(pts), np.concatenate(uv), np.concatenate(src),
                            sources, kept, np.array(box, dtype=float))


def face_source(face: TrimmedFace) -> NurbsSurface | SurfaceSource:
    """A face as a source of :func:`local_approximant`: its surface where the face is
    the whole surface, else :func:`trimmed_source` (only the part inside its loops is
    projected onto, so a hole in the face or a part trimmed away gets the fill)."""
    if is_natural(face):
        return face.surface
    loops = [loop_uv(lp) for lp in face.loops]
    try:
        return trimmed_source(face.surface, loops, name=face.name or "")
    except SurfprepError:
        return face.surface
