"""Geometry of the healing tests and of benchmarks/heal_table1.py.

* the kinds of 001's Figs. 5-8 (part of a single patch, a hole, intersecting
  surfaces, a highly oscillating surface), all in the unit cube as in Table 1;
* faces for the decomposition tests: loops of straight (u, v) lines or arcs on a
  wavy bicubic surface, with 3D edges interpolated through the mapped pcurves.
"""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.curve import NurbsCurve
from surfprep.algorithms.fitting import interpolate_curve, interpolate_surface
from surfprep.algorithms.healing.adjacency import polyline_distance
from surfprep.algorithms.healing.decompose import LoopEdge
from surfprep.algorithms.intersection.mesh import TriangleMesh
from surfprep.algorithms.intersection.tessellation import tessellate
from surfprep.algorithms.projection import project_to_surface
from surfprep.algorithms.surface import NurbsSurface
from surfprep.algorithms.tensor import Direction
from surfprep.algorithms.trimmed import TrimEdge, TrimLoop, TrimmedFace


def graph_surface(height, samples: int = 13) -> NurbsSurface:
    """Bicubic interpolant of ``z = height(x, y)`` over the unit square, ``(u, v) = (x, y)``
    at the samples."""
    s = np.linspace(0.0, 1.0, samples)
    x, y = np.meshgrid(s, s, indexing="ij")
    return interpolate_surface(np.stack([x, y, height(x, y)], axis=-1), params_u=s, params_v=s)


def smooth_surface() -> NurbsSurface:
    """A gently curved patch (001 Fig. 5 kind)."""
    return graph_surface(lambda x, y: 0.3 + 0.15 * np.sin(2.5 * x + 0.5) * np.cos(2.0 * y - 0.3),
                         samples=9)


def oscillating_surface() -> NurbsSurface:
    """Several waves in each direction (001 Fig. 8 kind)."""
    return graph_surface(lambda x, y: 0.5 + 0.04 * np.sin(5 * np.pi * x) * np.sin(4 * np.pi * y),
                         samples=41)


def iso_boundary(surface: NurbsSurface, u0: float, u1: float, v0: float, v1: float) -> list:
    """Four isocurves of ``surface`` bounding ``[u0, u1] x [v0, v1]``, bottom, right, top, left
    (top and left in the surface's directions: the boundary orients them)."""
    sub = surface.restrict(u0, u1, v0, v1)
    return [sub.isocurve(v0, Direction.V), sub.isocurve(u1, Direction.U),
            sub.isocurve(v1, Direction.V), sub.isocurve(u0, Direction.U)]


def surrounding_patches(surface: NurbsSurface, hole: tuple) -> list[NurbsSurface]:
    """Four patches of ``surface`` around the parameter rectangle ``hole`` (a hole in it)."""
    u0, u1, v0, v1 = hole
    return [surface.restrict(None, u0, None, None), surface.restrict(u1, None, None, None),
            surface.restrict(u0, u1, None, v0), surface.restrict(u0, u1, v1, None)]


def holed_mesh(surface: NurbsSurface, hole: tuple, tol: float = 2e-4) -> TriangleMesh:
    """Triangulation of ``surface`` with the triangles over ``hole`` cut out (with uv)."""
    mesh = tessellate(surface, tol).mesh
    c = mesh.triangle_uv().mean(axis=1)
    u0, u1, v0, v1 = hole
    inside = (c[:, 0] > u0) & (c[:, 0] < u1) & (c[:, 1] > v0) & (c[:, 1] < v1)
    return TriangleMesh.from_arrays(mesh.vertices, mesh.triangles[~inside], mesh.uv)


def _rising(x, y):
    return 0.45 + 0.35 * (x - 0.5) + 0.24 * y * (1.0 - y)


def _falling(x, y):
    return 0.45 - 0.35 * (x - 0.5) + 0.08 * (y - 0.5) ** 2


def crossing_surfaces() -> tuple[NurbsSurface, NurbsSurface]:
    """Two surfaces cutting through each other along a curve near ``x = 0.5`` (001 Fig. 7):
    one rising, one falling in x; their upper envelope has a crease there. Both heights
    are polynomials the bicubic interpolants reproduce exactly."""
    return graph_surface(_rising, samples=7), graph_surface(_falling, samples=7)


def upper_envelope(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Height of the upper envelope of :func:`crossing_surfaces` (exact)."""
    return np.maximum(_rising(x, y), _falling(x, y))


def envelope_boundary(x0: float, x1: float, y0: float, y1: float, samples: int = 81) -> list:
    """Four polylines on the upper envelope of :func:`crossing_surfaces` around a rectangle."""
    s = np.linspace(0.0, 1.0, samples)

    def line(p, q):
        x = p[0] + s * (q[0] - p[0])
        y = p[1] + s * (q[1] - p[1])
        return np.stack([x, y, upper_envelope(x, y)], axis=1)

    c = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return [line(c[k], c[(k + 1) % 4]) for k in range(4)]


def stepped_gap(step: float = 0.01, gap: tuple = (0.45, 0.55), samples: int = 81
                ) -> tuple[list, list[NurbsSurface]]:
    """Two surfaces with a gap between them and a step across it (001 Fig. 6 kind).

    The smooth surface is cut at ``x = gap[0]`` and ``x = gap[1]``; the right part is
    raised by ``step``. The boundary runs around ``[0.2, 0.8]^2``: on the surfaces
    where they exist, a straight bridge across the gap on the bottom and top sides.

    Returns
    -------
    boundary : four (n, 3) polylines
    sources : [left, right] NurbsSurface
    """
    smooth = smooth_surface()
    left = smooth.restrict(None, gap[0], None, None)
    right_part = smooth.restrict(gap[1], None, None, None)
    right = NurbsSurface(right_part.control_points + np.array([0.0, 0.0, step]),
                         right_part.knots_u, right_part.knots_v, 3, 3)

    def height(x, y):
        z = smooth.evaluate(x, y)[..., 2]
        z = np.where(x >= gap[1], z + step, z)
        z_left = smooth.evaluate(np.full_like(x, gap[0]), y)[..., 2]
        z_right = smooth.evaluate(np.full_like(x, gap[1]), y)[..., 2] + step
        bridge = (x - gap[0]) / (gap[1] - gap[0])
        inside = (x > gap[0]) & (x < gap[1])
        return np.where(inside, (1 - bridge) * z_left + bridge * z_right, z)

    s = np.linspace(0.0, 1.0, samples)

    def line(p, q):
        x = p[0] + s * (q[0] - p[0])
        y = p[1] + s * (q[1] - p[1])
        return np.stack([x, y, height(x, y)], axis=1)

    c = [(0.2, 0.2), (0.8, 0.2), (0.8, 0.8), (0.2, 0.8)]
    return [line(c[k], c[(k + 1) % 4]) for k in range(4)], [left, right]


# ------------------------------------------------------------ decomposition
def wavy_surface():
    """Bicubic graph over [0, 1]^2 (domain [0, 1]^2), a unit-size free-form patch."""
    x = np.linspace(0, 1, 9)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    z = 0.15 * np.sin(2.5 * gx) * np.cos(2.0 * gy) + 0.1 * gx * gy
    return interpolate_surface(np.stack([gx, gy, z], axis=-1))


def edge_from_uv(surface, uv_of_t, n=65) -> LoopEdge:
    """Edge with pcurve through ``uv_of_t(t)``, ``t`` in [0, 1], and its 3D curve."""
    t = np.linspace(0, 1, n)
    uv = uv_of_t(t)
    pcurve = interpolate_curve(uv, parameters=t)
    xyz = surface.evaluate(pcurve.evaluate(t)[:, 0], pcurve.evaluate(t)[:, 1])
    return LoopEdge(interpolate_curve(xyz, parameters=t), pcurve)


def line(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return lambda t: (1 - t)[:, None] * a + t[:, None] * b


def arc(centre, radius, a0, a1):
    c = np.asarray(centre, float)
    return lambda t: c + radius * np.column_stack([np.cos(a0 + t * (a1 - a0)),
                                                   np.sin(a0 + t * (a1 - a0))])


def polygon_loop(surface, corners):
    """Straight uv edges between consecutive corners (counter-clockwise)."""
    c = np.asarray(corners, float)
    return [edge_from_uv(surface, line(c[k], c[(k + 1) % len(c)])) for k in range(len(c))]


def triangle(surface):
    return polygon_loop(surface, [(0.1, 0.1), (0.9, 0.2), (0.4, 0.85)])


def pentagon(surface):
    a = np.pi / 2 + 2 * np.pi * np.arange(5) / 5
    return polygon_loop(surface, np.column_stack([0.5 + 0.4 * np.cos(a), 0.5 + 0.4 * np.sin(a)]))


def six_edges_two_smooth(surface):
    """A rounded rectangle in uv: four corners, two sides each made of two edges that
    continue each other smoothly (a straight side split in two, an arc split in two)."""
    return [edge_from_uv(surface, line((0.1, 0.1), (0.5, 0.1))),
            edge_from_uv(surface, line((0.5, 0.1), (0.9, 0.1))),
            edge_from_uv(surface, line((0.9, 0.1), (0.9, 0.8))),
            edge_from_uv(surface, arc((0.5, 0.45), np.hypot(0.4, 0.35),
                                      np.arctan2(0.35, 0.4), np.pi / 2)),
            edge_from_uv(surface, arc((0.5, 0.45), np.hypot(0.4, 0.35), np.pi / 2,
                                      np.pi - np.arctan2(0.35, 0.4))),
            edge_from_uv(surface, line((0.1, 0.8), (0.1, 0.1)))]


def disc(surface, pieces=1):
    """A circle in uv as ``pieces`` smooth arcs."""
    step = 2 * np.pi / pieces
    return [edge_from_uv(surface, arc((0.5, 0.5), 0.35, k * step, (k + 1) * step), n=129)
            for k in range(pieces)]


def notched(surface):
    """A deep U-shaped outline (very non-convex, eight corners)."""
    return polygon_loop(surface, [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.7, 0.9), (0.7, 0.3),
                                  (0.3, 0.3), (0.3, 0.9), (0.1, 0.9)])


def outline_uv(edges):
    return np.concatenate([e.pcurve.evaluate(np.linspace(0, 1, 200))[:-1] for e in edges])


# ------------------------------------------------------------ a face with a hole
HOLE_CENTRE, HOLE_RADIUS = np.array([0.5, 0.5]), 0.3


def _loop(edges) -> TrimLoop:
    return TrimLoop([TrimEdge(e.curve, e.pcurve, 0.0, 1.0) for e in edges])


def plane_with_hole(outline=((0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9))) -> TrimmedFace:
    """z = 0 trimmed to the polygon ``outline`` (counter-clockwise; default the square
    [0.1, 0.9]^2) with a disc hole (radius 0.3) inside."""
    plane = graph_surface(lambda x, y: 0.0 * x, samples=9)
    outer = polygon_loop(plane, list(outline))
    # the hole clockwise, in four arcs
    hole = [edge_from_uv(plane, lambda t, k=k: HOLE_CENTRE + HOLE_RADIUS * np.column_stack(
        [np.cos(-(k + t) * np.pi / 2), np.sin(-(k + t) * np.pi / 2)]), n=129) for k in range(4)]
    return TrimmedFace(plane, (_loop(outer), _loop(hole)))


__all__ = ["HOLE_CENTRE", "HOLE_RADIUS", "NurbsCurve", "disc", "edge_from_uv", "graph_surface",
           "notched", "outline_uv", "pentagon", "plane_with_hole", "polygon_loop",
           "six_edges_two_smooth", "triangle", "wavy_surface"]


def occ_triangle_face():
    """A ``TopoDS_Face`` on :func:`wavy_surface` trimmed to :func:`triangle` (three edges)."""
    from surfprep.plugin.occ.faces import make_face

    surface = wavy_surface()
    trim = [TrimLoop([TrimEdge(e.curve, e.pcurve, 0.0, 1.0) for e in triangle(surface)])]
    return make_face(surface, trim)


# ------------------------------------------------------------ crossing sheets
# Two bent sheets cutting through each other, each overshooting the crossing (001 Fig. 7,
# "intersecting surfaces"), and the corners of a directed patch over the crossing: the
# geometry of tests/plugin/heal/test_cut.py and of benchmarks/heal.py.
X_CROSS = 1.0          # the sheets cross along x = 1
SLOPE = 0.4            # B rises with this slope beyond the crossing
X0, X1 = 0.7, 1.3      # the patch spans these x


def bend(x, y):
    return 0.05 * np.sin(2 * y) + 0.03 * x ** 2


def truth(x, y):
    """The intended surface: A before the crossing, B after."""
    return bend(x, y) + SLOPE * np.maximum(x - X_CROSS, 0.0)


def truth_area() -> float:
    """Area of the intended surface :func:`truth` over [0, 2] x [0, 1]."""
    x, y = np.linspace(0, 2, 1601), np.linspace(0, 1, 801)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    h = 1e-6
    zx = (truth(gx + h, gy) - truth(gx - h, gy)) / (2 * h)
    zy = (truth(gx, gy + h) - truth(gx, gy - h)) / (2 * h)
    return float(np.trapezoid(np.trapezoid(np.sqrt(1 + zx ** 2 + zy ** 2), y, axis=1), x))


def sheet(x0, x1, slope):
    x, y = np.linspace(x0, x1, 9), np.linspace(0, 1, 6)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, bend(gx, gy) + slope * (gx - X_CROSS)], -1))


def bilinear_quad(p00, p10, p01, p11) -> NurbsSurface:
    """The bilinear patch through four corners (``p10`` at u = 1, ``p01`` at v = 1), as a
    bicubic interpolant of 4 x 4 of its points (exactly bilinear)."""
    s = np.linspace(0.0, 1.0, 4)
    u, v = np.meshgrid(s, s, indexing="ij")
    p = [np.asarray(x, float) for x in (p00, p10, p01, p11)]
    return interpolate_surface(((1 - u) * (1 - v))[..., None] * p[0] + (u * (1 - v))[..., None] * p[1]
                               + ((1 - u) * v)[..., None] * p[2] + (u * v)[..., None] * p[3])


def overshooting_box(over: float = 0.1, height: float = 1.1) -> list[NurbsSurface]:
    """A unit cube's bottom, its four walls running up to ``height`` and a lid at z = 1
    reaching ``over`` beyond the walls: the lid and the walls cut through each other
    (their overshoots a collar above the lid and a rim around it)."""
    o, h = over, height
    return [bilinear_quad((0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)),
            bilinear_quad((0, 0, 0), (1, 0, 0), (0, 0, h), (1, 0, h)),
            bilinear_quad((1, 0, 0), (1, 1, 0), (1, 0, h), (1, 1, h)),
            bilinear_quad((1, 1, 0), (0, 1, 0), (1, 1, h), (0, 1, h)),
            bilinear_quad((0, 1, 0), (0, 0, 0), (0, 1, h), (0, 0, h)),
            bilinear_quad((-o, -o, 1), (1 + o, -o, 1), (-o, 1 + o, 1), (1 + o, 1 + o, 1))]


def compound(shapes):
    """A compound of the faces."""
    from surfprep.plugin.io import to_shape
    return to_shape(list(shapes))


def corners():
    pts = [(X0, 0), (X1, 0), (X1, 1), (X0, 1)]
    return [[x, y, float(truth(x, y))] for x, y in pts]


def _outline(surface):
    from surfprep.plugin.heal.cut import outline
    return outline(surface)


def crossings(surfaces, n=41, near=0.02) -> int:
    """Sample points of one surface closer than ``near`` to another one away from that
    one's outline (farther than ``2 near``): a face crossing or lying on another."""
    count = 0
    for i, s in enumerate(surfaces):
        u0, u1, v0, v1 = s.domain
        pts = s.evaluate_grid(np.linspace(u0, u1, n), np.linspace(v0, v1, n)).reshape(-1, 3)
        for j, other in enumerate(surfaces):
            if i == j:
                continue
            foot = project_to_surface(other, pts)
            close = foot.distance < near
            if np.any(close):
                rim = polyline_distance(foot.points[close], _outline(other))
                count += int(np.sum(rim > 2 * near))
    return count


# ------------------------------------------------------------ closed solids heal must not open
def slotted_plate():
    """A 2 x 2 x 0.5 plate with a 0.6 x 0.6 square slot through it, as one solid: the top
    and bottom faces have an inner loop, met along it by the slot's four walls (the
    geometry of occt_cornetta.stp's and occt_k1_alias.stp's slots). Closed: no free edge."""
    import cadquery as cq

    return cq.Workplane().box(2.0, 2.0, 0.5).faces(">Z").workplane().rect(0.6, 0.6) \
        .cutThruAll().val().wrapped


def boxes_sharing_a_wall():
    """Two unit cubes side by side as two solids of one compound: the wall between them is
    there twice, one face of each solid (as in occt_s1_ideas.stp's 11 solids). Sewn, no
    edge is free."""
    import cadquery as cq

    a = cq.Workplane().box(1.0, 1.0, 1.0).val()
    b = cq.Workplane().box(1.0, 1.0, 1.0).translate((1.0, 0.0, 0.0)).val()
    return cq.Compound.makeCompound([a, b]).wrapped


# ------------------------------------------------------ n-sided holes (hole_cap.py)
def gentle_height(x, y):
    """The graph of the n-sided hole cases (benchmarks/heal.py's too)."""
    return 0.3 * np.sin(1.3 * x) * np.cos(0.9 * y) + 0.1 * x * y


def fan_around_hole(n: int, *, r: float = 0.15, outer: float = 0.5, centre=(0.5, 0.5),
                    height=gentle_height, samples: int = 7) -> list[NurbsSurface]:
    """``n`` four-sided patches of ``z = height(x, y)`` around a regular ``n``-gon hole of
    circumradius ``r`` (patch ``k`` spans the hole's edge ``k`` at ``v = 0`` and the outer
    ``n``-gon's at ``v = 1``); neighbours share their ``u = 1`` / ``u = 0`` sides exactly
    (interpolants of the same points with the same parameters)."""
    angle = np.linspace(0.0, 2 * np.pi, n + 1)[:-1] + 0.3
    inner = np.column_stack([centre[0] + r * np.cos(angle), centre[1] + r * np.sin(angle)])
    rim = np.column_stack([centre[0] + outer * np.cos(angle), centre[1] + outer * np.sin(angle)])
    s = np.linspace(0.0, 1.0, samples)
    ss, tt = np.meshgrid(s, s, indexing="ij")
    out = []
    for k in range(n):
        j = (k + 1) % n
        a = (1 - ss)[..., None] * inner[k] + ss[..., None] * inner[j]
        b = (1 - ss)[..., None] * rim[k] + ss[..., None] * rim[j]
        xy = (1 - tt)[..., None] * a + tt[..., None] * b
        z = height(xy[..., 0], xy[..., 1])[..., None]
        out.append(interpolate_surface(np.concatenate([xy, z], axis=-1), params_u=s, params_v=s))
    return out


def inside_regular_polygon(n: int, *, r: float = 0.15, centre=(0.5, 0.5), rings: int = 15,
                           spokes: int = 60) -> np.ndarray:
    """(k, 2) points of the disc inscribed in the hole of :func:`fan_around_hole` (98 %)."""
    radius = np.linspace(0.0, 0.98 * r * np.cos(np.pi / n), rings)
    angle = np.linspace(0.0, 2 * np.pi, spokes, endpoint=False)
    rr, aa = np.meshgrid(radius, angle)
    return np.column_stack([centre[0] + (rr * np.cos(aa)).ravel(),
                            centre[1] + (rr * np.sin(aa)).ravel()])


# ------------------------------------------- an open box whose lid is trimmed short
LID_SHORT = 0.05      # the lid's loop stops this far short of its east wall


def _face_on(surface: NurbsSurface, corners) -> TrimmedFace:
    return TrimmedFace(surface, (_loop(polygon_loop(surface, corners)),))


def _wall(top, depth: float = 0.5) -> NurbsSurface:
    """A wall hanging ``depth`` below the curve ``top(t)``, t in [0, 1]; its side v = 0
    runs along ``top``."""
    t = np.linspace(0.0, 1.0, 9)
    d = np.linspace(0.0, depth, 4)
    pts = top(t)[:, None, :] - d[None, :, None] * np.array([0.0, 0.0, 1.0])
    return interpolate_surface(pts, params_u=t, params_v=d / depth)


def short_lid_box(short: float = LID_SHORT, lid_surface: NurbsSurface | None = None,
                  split_east: bool = False) -> list[TrimmedFace]:
    """A curved lid over ``[0.1, 0.9]^2`` (``(u, v) = (x, y)``) whose loop stops
    ``short`` before its east side, and four walls hanging from the lid surface's
    isocurves at ``x, y = 0.1, 0.9``: the lid's surface holds the walls' top edges,
    its loop does not (faces: lid, west, east, south, north; with ``split_east`` the
    east wall is two faces, y below and above 0.5, appended last: a T-junction)."""
    lid = lid_surface if lid_surface is not None else graph_surface(
        lambda x, y: 0.2 * np.sin(2 * x) * np.cos(1.5 * y), samples=9)

    def along(u=None, v=None, s0=0.1, s1=0.9):
        def top(t):
            s = s0 + (s1 - s0) * t
            uu = np.full_like(s, u) if u is not None else s
            vv = np.full_like(s, v) if v is not None else s
            return lid.evaluate(uu, vv)
        return top

    square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    walls = [_face_on(_wall(along(u=0.1)), square), _face_on(_wall(along(u=0.9)), square),
             _face_on(_wall(along(v=0.1)), square), _face_on(_wall(along(v=0.9)), square)]
    top = _face_on(lid, [(0.1, 0.1), (0.9 - short, 0.1), (0.9 - short, 0.9), (0.1, 0.9)])
    if split_east:
        walls[1:2] = []
        walls += [_face_on(_wall(along(u=0.9, s1=0.5)), square),
                  _face_on(_wall(along(u=0.9, s0=0.5)), square)]
    return [top, *walls]


__all__ += ["LID_SHORT", "short_lid_box"]
