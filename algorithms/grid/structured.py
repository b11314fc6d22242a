"""A structured grid on one four-sided surface: redistribution, TFI, elliptic refinement.

:func:`grid_surface` is the whole grid step of 003 on a :class:`NurbsSurface`:

1. **edge distributions**: the nodes of each side placed by the :class:`Spacing`
   law in exact arc length (:mod:`.distribution`), so a first spacing asked for
   in model units is the distance between the first two nodes in space;
2. **redistribution**: the side nodes' parameters, normalized, span the
   arc-length *distribution mesh* (:func:`.tfi.distribution_mesh`, 003), the
   start grid ``(s, t)``; on a chord-length parametrized face it is close to the
   final grid, on a badly parametrized one it is only a start;
3. **elliptic refinement** on the surface's metric (:func:`.elliptic.refine`,
   003 eqs. 5-9), boundary nodes held, folds refused;
4. **quality** of the start grid and of the result, on the surface (:mod:`.quality`).

The i direction runs along the surface's u, the j direction along v.
"""

from __future__ import annotations

import math
import time
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..curve import NurbsCurve
from ..surface import NurbsSurface
from ..tensor import Direction
from . import distribution
from .elliptic import EllipticResult, corner_jacobians, refine
from .held import HeldLine, held_line, split_along
from .periodic import Seam
from .polar import PoleChart, surface_normals
from .quality import GridQuality, grid_quality
from .region import SIDE_NAMES, Region
from .respacing import Respacing, respaced
from .tfi import distribution_mesh, transfinite

__all__ = ["DEFAULT_CELLS", "SKEW_SLACK", "Spacing", "SurfaceGrid", "corner_angles", "corner_skewness",
           "grid_region", "grid_surface", "plain_kept", "side_curves", "squeezes_corners"]

#: cells along the longest side when neither ``dims`` nor ``size`` is given
DEFAULT_CELLS = 40
#: a side shorter than this fraction of the surface's box diagonal is collapsed (a pole)
COLLAPSED = 1e-9
LAWS = ("uniform", "geometric", "tanh", "curvature")
SIDES = ("j0", "j1", "i0", "i1")
#: the sides' orthogonality may leave the worst cell this much more skewed than the face's
#: corners before the grid without it is tried
SKEW_SLACK = 0.02


@dataclass(frozen=True)
class Spacing:
    """How the nodes are spread along the lines of one grid direction.

    Attributes
    ----------
    law : {"uniform", "geometric", "tanh", "curvature"}
        Default ``"uniform"``, or ``"tanh"`` when a first/last spacing is given,
        ``"geometric"`` when a growth ratio is.
    first, last : float, optional
        Length of the first / last interval of each side, in model units.
    growth : float, optional
        Ratio of consecutive intervals (geometric law).
    strength : float
        Weight of the curvature in the ``"curvature"`` law.
    """

    law: str | None = None
    first: float | None = None
    last: float | None = None
    growth: float | None = None
    strength: float = 1.0

    def __post_init__(self) -> None:
        law = self.law
        if law is None:
            law = "geometric" if self.growth is not None else (
                "tanh" if self.first is not None or self.last is not None else "uniform")
        if law not in LAWS:
            raise InvalidGeometryError(f"unknown spacing law {law!r}; expected one of {', '.join(LAWS)}")
        object.__setattr__(self, "law", law)
        for name in ("first", "last", "growth"):
            value = getattr(self, name)
            if value is not None and (not math.isfinite(float(value)) or float(value) <= 0.0):
                raise InvalidGeometryError(f"spacing {name} must be a positive number, got {value!r}")
        if law == "tanh" and self.first is None and self.last is None:
            raise InvalidGeometryError("the tanh law needs a first or a last spacing")
        if law == "geometric" and (self.growth is None) == (self.first is None):
            raise InvalidGeometryError("the geometric law needs a growth ratio or a first spacing")

    def fractions(self, n: int, curve: NurbsCurve | None, length: float,
                  points: NDArray | None = None) -> NDArray:
        """``(n,)`` fractions of the arc length of a side (of ``length``) for this law;
        the curvature law reads the side's 3D ``curve``, or its dense ``points``."""
        if self.law == "uniform":
            return distribution.uniform(n)
        if self.law == "curvature":
            if curve is not None:
                return distribution.by_curvature(curve, n, strength=self.strength)
            return distribution.by_curvature_points(points, n, strength=self.strength)
        if self.law == "geometric":
            if self.growth is not None:
                return distribution.geometric(n, growth=self.growth)
            return distribution.geometric(n, first=self.first / length)
        return distribution.stretched(
            n, first=None if self.first is None else self.first / length,
            last=None if self.last is None else self.last / length)


@dataclass(frozen=True)
class SurfaceGrid:
    """A structured grid block on a surface.

    Attributes
    ----------
    points : (ni, nj, 3) float
        The nodes, on the surface (i along u, j along v).
    parameters : (ni, nj, 2) float
        The ``(u, v)`` of each node.
    quality : GridQuality
        Of the result.
    start_quality : GridQuality
        Of the algebraic start grid (the distribution mesh), before smoothing.
    elliptic : EllipticResult or None
        The refinement's residual history; None when not smoothed.
    kept_start : str or None
        Why the algebraic grid was kept although smoothing was asked: the refined
        grid folded a cell or, not converged, was more skewed (never returned worse).
    held : tuple of (str, int)
        The grid lines that are held curves: ``("i", 14)`` is the i-line 14.
    orientation : int
        +1 when ``x_i x x_j`` follows the surface's normal ``S_u x S_v``, -1 when it
        runs against it (the block's normal is then the surface's reversed).
    collapsed_sides : tuple of str
        Sides of zero length (``"i0"``, ``"i1"``, ``"j0"``, ``"j1"``).
    spacing_error : float
        Largest relative deviation of the first/last side intervals from the
        spacing asked for (0 when none was asked).
    time_s : float
    start_points, start_parameters : (ni, nj, 3), (ni, nj, 2) float or None
        The algebraic start grid (to show what the refinement changed).
    side_params : dict of str to (n,) float
        The normalized side parameters (:class:`Side`) of each side's nodes.
    orthogonal_dropped : str or None
        With ``orthogonal=True``: None when the lines leave the sides at right angles
        (:func:`.elliptic.refine`), else why the grid without that control is kept (the
        controlled iteration did not settle, or it skewed the cells by a sharp corner
        beyond the corner's own skewness).
    seam : Seam or None
        Where the grid closes on itself (:mod:`.periodic`): the two copies of that side
        were solved as one line, not held.
    """

    points: NDArray
    parameters: NDArray
    quality: GridQuality
    start_quality: GridQuality
    elliptic: EllipticResult | None
    kept_start: str | None = None
    held: tuple[tuple[str, int], ...] = ()
    orientation: int = 1
    collapsed_sides: tuple[str, ...] = ()
    spacing_error: float = 0.0
    time_s: float = field(default=0.0, compare=False)
    start_points: NDArray | None = field(default=None, repr=False, compare=False)
    start_parameters: NDArray | None = field(default=None, repr=False, compare=False)
    side_params: dict = field(default_factory=dict, repr=False, compare=False)
    orthogonal_dropped: str | None = None
    seam: Seam | None = field(default=None, repr=False, compare=False)

    @property
    def dims(self) -> tuple[int, int]:
        return tuple(self.points.shape[:2])

    def report(self) -> dict:
        """Plain-JSON figures of the block."""
        out = {"dims": list(self.dims), "corner_angles": corner_angles(self.points),
               "collapsed_sides": list(self.collapsed_sides),
               "held_lines": [f"{family}={index}" for family, index in self.held],
               "quality": self.quality.report(), "start_quality": self.start_quality.report(),
               "spacing_error": self.spacing_error, "time_s": self.time_s}
        if self.elliptic is not None:
            out["elliptic"] = {"converged": self.elliptic.converged, "sweeps": self.elliptic.sweeps,
                               "refused_steps": self.elliptic.refused,
                               "residuals": list(self.elliptic.residuals),
                               "sides_misfit": self.elliptic.sides_misfit,
                               "kept_start": self.kept_start, "orthogonal_dropped": self.orthogonal_dropped}
        return out


def corner_angles(points: NDArray) -> list[float | None]:
    """The angles (degrees) of a block's four corners, at (0, 0), (ni-1, 0), (ni-1, nj-1),
    (0, nj-1): the face's own corners, which bound the orthogonality any grid can reach
    (None at a collapsed corner)."""
    out = []
    for i, j, di, dj in ((0, 0, 1, 1), (-1, 0, -1, 1), (-1, -1, -1, -1), (0, -1, 1, -1)):
        a = points[i + di, j] - points[i, j]
        b = points[i, j + dj] - points[i, j]
        n = float(np.linalg.norm(a) * np.linalg.norm(b))
        out.append(float(np.degrees(np.arccos(np.clip(np.dot(a, b) / n, -1.0, 1.0)))) if n > 0 else None)
    return out


def side_curves(surface: NurbsSurface) -> dict[str, NurbsCurve]:
    """The four sides of a surface as curves: ``"j0"`` (v = v0) and ``"j1"`` (v = v1) run
    in u, ``"i0"`` (u = u0) and ``"i1"`` (u = u1) run in v."""
    u0, u1, v0, v1 = surface.domain
    return {"j0": surface.isocurve(v0, Direction.V), "j1": surface.isocurve(v1, Direction.V),
            "i0": surface.isocurve(u0, Direction.U), "i1": surface.isocurve(u1, Direction.U)}


def _dims(lengths: dict[str, float], dims, size) -> tuple[int, int]:
    if dims is not None:
        if size is not None:
            raise InvalidGeometryError("give dims or size, not both")
        try:
            ni, nj = (int(d) for d in dims)
        except (TypeError, ValueError):
            raise InvalidGeometryError(f"dims must be two node counts, got {dims!r}") from None
        if ni < 2 or nj < 2 or (ni, nj) != tuple(dims):
            raise InvalidGeometryError(f"dims must be two integers >= 2, got {dims!r}")
        if max(ni, nj) > 100_001:
            raise InvalidGeometryError(f"dims {ni} x {nj}: at most 1e5 cells along a side")
        return ni, nj
    long_i = max(lengths["j0"], lengths["j1"])
    long_j = max(lengths["i0"], lengths["i1"])
    if size is None:
        size = max(long_i, long_j) / DEFAULT_CELLS
    size = float(size)
    if not math.isfinite(size) or size <= 0.0:
        raise InvalidGeometryError(f"size must be a positive length, got {size!r}")
    cells = max(long_i, long_j) / size
    if cells > 1e5:
        raise InvalidGeometryError(f"size {size:g} asks for {cells:.3g} cells along a side; at most 1e5")
    return max(2, math.ceil(long_i / size - 1e-9) + 1), max(2, math.ceil(long_j / size - 1e-9) + 1)


def _side_fractions(region: Region, lengths: dict[str, float], collapsed: set[str],
                    ni: int, nj: int, spacing: tuple[Spacing, Spacing]) -> dict[str, NDArray]:
    """Normalized side parameters ``x`` of the side nodes, by the spacing laws in arc length."""
    out = {}
    curves = side_curves(region.surface) if region.is_rectangle else {}
    for name, other, n, law in (("j0", "j1", ni, spacing[0]), ("j1", "j0", ni, spacing[0]),
                                ("i0", "i1", nj, spacing[1]), ("i1", "i0", nj, spacing[1])):
        if name in collapsed:
            if other in collapsed:
                raise DegenerateGeometryError(
                    f"sides {name} and {other} are both collapsed (a rectangle from pole to pole, as "
                    "a sphere's): split it between the poles first (faces.pole_halves; surfprep.grid "
                    "does)")
            continue
        side = region.sides[name]
        dense = side.points(np.linspace(0.0, 1.0, 257)) if law.law == "curvature" else None
        fractions = law.fractions(n, curves.get(name), lengths[name], dense)
        if name in curves:                  # an iso-line: exact arc length on the 3D curve
            curve = curves[name]
            lo, hi = curve.domain
            out[name] = (distribution.points_along(curve, fractions) - lo) / (hi - lo)
        else:
            out[name] = side.at_fractions(fractions)
    for name, other in (("j0", "j1"), ("j1", "j0"), ("i0", "i1"), ("i1", "i0")):
        if name in collapsed:
            out[name] = out[other]          # the pole's nodes coincide; keep the lines straight in (u, v)
    return out


def _spacing_error(points: NDArray, spacing: tuple[Spacing, Spacing], collapsed: set[str]) -> float:
    worst = 0.0
    for law, lines in ((spacing[0], {"j0": points[:, 0], "j1": points[:, -1]}),
                       (spacing[1], {"i0": points[0], "i1": points[-1]})):
        for name, line in lines.items():
            if name in collapsed or line.shape[0] < 3:
                continue
            legs = np.linalg.norm(np.diff(line, axis=0), axis=1)
            for asked, got in ((law.first, legs[0]), (law.last, legs[-1])):
                if asked is not None and law.law in ("tanh", "geometric"):
                    worst = max(worst, abs(got - asked) / asked)
    return worst


def _region_start(region: Region, x: dict[str, NDArray], chart: Respacing | None = None) -> NDArray:
    """TFI in ``(u, v)`` of the four sides' nodes, blended by their arc-length fractions;
    each corner the mean of its two sides' ends (a loop's pcurves meet to its tolerance).
    With ``chart``: TFI in the parameters re-spaced at the surface's C0 joins
    (:mod:`.respacing`), mapped back."""
    sides = region.sides_uv(x)
    weights = distribution_mesh(*(region.sides[name].fractions_of(x[name]) for name in SIDE_NAMES))
    if chart is None:
        return transfinite(sides["j0"], sides["j1"], sides["i0"], sides["i1"], weights=weights)
    mapped = {name: chart.to_chart(uv) for name, uv in sides.items()}
    st = chart.from_chart(transfinite(mapped["j0"], mapped["j1"], mapped["i0"], mapped["i1"],
                                      weights=weights))
    st[:, 0], st[:, -1], st[0], st[-1] = sides["j0"], sides["j1"], sides["i0"], sides["i1"]
    return st


#: an algebraic start grid whose worst cell is more skewed than this ("poor" in
#: :mod:`.quality`'s bands) is made again in the knots re-spaced at the surface's C0 joins
POOR_START = 0.5


def _respaced_start(chart: Respacing, fractions: dict[str, NDArray]) -> NDArray:
    """The distribution mesh of the sides' ``fractions`` (of the original parameters) made in
    the re-spaced parameters of ``chart`` and mapped back: (ni, nj, 2)."""
    u0, u1, v0, v1 = chart.surface.domain
    f = {}
    for name, k, lo, hi in (("j0", 0, u0, u1), ("j1", 0, u0, u1), ("i0", 1, v0, v1), ("i1", 1, v0, v1)):
        x = lo + fractions[name] * (hi - lo)
        f[name] = (chart.along(x, k) - lo) / (hi - lo)
    s, t = distribution_mesh(f["j0"], f["j1"], f["i0"], f["i1"])
    return chart.from_chart(np.stack([u0 + s * (u1 - u0), v0 + t * (v1 - v0)], axis=-1))


def _transposed(surface: NurbsSurface) -> NurbsSurface:
    """The surface with its u and v swapped (exact)."""
    weights = None if surface.weights is None else surface.weights.T
    return NurbsSurface(np.transpose(surface.control_points, (1, 0, 2)), surface.knots_v,
                        surface.knots_u, surface.degree_v, surface.degree_u, weights)


def _held_start(surface: NurbsSurface, hold: Sequence, fractions: dict[str, NDArray],
                tol: float) -> tuple[NDArray, list[tuple[int, int]], int]:
    """Start grid (normalized) with held lines, its pieces and the axis they split."""
    lines = [held_line(surface, curve, tol=tol) for curve in hold]
    families = {h.family for h in lines}
    if len(families) > 1:
        raise InvalidGeometryError("held curves must all run the same way (all from j0 to j1, or "
                                   "all from i0 to i1); crossing held lines are not supported")
    if families == {"i"}:
        xy, pieces = split_along(surface, lines, fractions["j0"], fractions["j1"], fractions["i0"],
                                 fractions["i1"])
        return xy, pieces, 0
    turned = [HeldLine("i", h.path[:, ::-1], h.distance, h.curve) for h in lines]
    xy, pieces = split_along(_transposed(surface), turned, fractions["i0"], fractions["i1"],
                             fractions["j0"], fractions["j1"])
    return np.transpose(xy, (1, 0, 2))[..., ::-1], pieces, 1


def corner_skewness(points: NDArray) -> float:
    """The equiangle skewness the face's corners alone impose: ``|angle - 90| / 90`` at the
    worst corner (None at a collapsed corner is left out)."""
    angles = [a for a in corner_angles(points) if a is not None]
    return max((abs(a - 90.0) / 90.0 for a in angles), default=0.0)


def squeezes_corners(squared: GridQuality, points: NDArray) -> bool:
    """A grid with squared sides (its quality ``squared``) whose worst cell is more skewed, by
    :data:`SKEW_SLACK`, than the corners of the block ``points`` impose: squaring the sides may
    squeeze the cells beside a sharp corner, and the grid without it is to be tried."""
    return squared.max_skewness > corner_skewness(points) + SKEW_SLACK


def plain_kept(squared: GridQuality, plain: EllipticResult, plain_quality: GridQuality,
               tol: float) -> str | None:
    """Why the grid without the sides' control (``plain``, its quality) is kept instead of the
    squared one, or None when it is not: it must have (nearly) converged, fold no more cells and
    have a worst cell better by half of :data:`SKEW_SLACK`."""
    if plain.nearly_converged(tol) and plain_quality.folded_cells <= squared.folded_cells \
            and plain_quality.max_skewness < squared.max_skewness - SKEW_SLACK / 2:
        return (f"squaring the sides made the worst cell more skewed than the face's corners do "
                f"({squared.max_skewness:.3g} against {plain_quality.max_skewness:.3g} without): the "
                "grid without it is kept")
    return None


def _refine_pieces(surface: NurbsSurface, st: NDArray, pieces: list[tuple[int, int]], axis: int,
                   **options) -> EllipticResult:
    """Refine each piece between held lines with its boundary fixed; one result for all."""
    out = st.copy()
    results = []
    for p, q in pieces:
        cut = (slice(p, q + 1), slice(None)) if axis == 0 else (slice(None), slice(p, q + 1))
        r = refine(surface, st[cut], **options)
        out[cut] = r.parameters
        results.append(r)
    if len(results) == 1:
        return results[0]
    worst = max(results, key=lambda r: r.residuals[-1] if r.residuals else 0.0)
    return EllipticResult(out, worst.residuals, all(r.converged for r in results),
                          sum(r.refused for r in results), sum(r.sweeps for r in results),
                          max(r.sides_misfit for r in results))


def grid_surface(surface: NurbsSurface, *, dims: tuple[int, int] | None = None, size: float | None = None,
                 spacing: Spacing | tuple[Spacing, Spacing] = Spacing(), smooth: str = "elliptic",
                 control: bool = True, orthogonal: bool | Collection[str] = True, tol: float = 1e-4,
                 max_sweeps: int = 2000, sides: dict[str, NDArray] | None = None,
                 hold: Sequence = (), hold_tol: float | None = None) -> SurfaceGrid:
    """A structured grid on a surface's whole parameter rectangle (003: redistribution, TFI, elliptic).

    :func:`grid_region` on :meth:`Region.rectangle`; the parameters and their meaning
    are :func:`grid_region`'s.

    Examples
    --------
    >>> import numpy as np
    >>> from surfprep import NurbsSurface
    >>> k = [0, 0, 1, 1]
    >>> plane = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[2, 0, 0], [2, 1, 0]]], float), k, k, 1, 1)
    >>> grid = grid_surface(plane, dims=(5, 3))
    >>> grid.points.shape, round(grid.quality.max_skewness, 12)
    ((5, 3, 3), 0.0)
    """
    if not isinstance(surface, NurbsSurface) or surface.dimension != 3:
        raise InvalidGeometryError("grid_surface needs a 3D NurbsSurface")
    return grid_region(Region.rectangle(surface), dims=dims, size=size, spacing=spacing, smooth=smooth,
                       control=control, orthogonal=orthogonal, tol=tol, max_sweeps=max_sweeps,
                       sides=sides, hold=hold, hold_tol=hold_tol)


def grid_region(region: Region, *, dims: tuple[int, int] | None = None, size: float | None = None,
                spacing: Spacing | tuple[Spacing, Spacing] = Spacing(), smooth: str = "elliptic",
                control: bool = True, orthogonal: bool | Collection[str] = True, tol: float = 1e-4,
                max_sweeps: int = 2000, sides: dict[str, NDArray] | None = None,
                hold: Sequence = (), hold_tol: float | None = None) -> SurfaceGrid:
    """A structured grid on a four-sided region of a surface (003: redistribution, TFI, elliptic).

    Parameters
    ----------
    region : Region
        The surface and its four sides (:meth:`Region.rectangle`, :meth:`Region.from_loop`).
    dims : (int, int), optional
        Nodes along i (the u direction) and j (v). Default from ``size``.
    size : float, optional
        Target cell size in model units; default the longest side over
        :data:`DEFAULT_CELLS`. Each direction gets ``ceil(L / size) + 1`` nodes,
        ``L`` the longer of its two sides.
    spacing : Spacing or (Spacing, Spacing)
        The law along i and along j (one for both when a single one is given).
    smooth : {"elliptic", "none"}
        Elliptic refinement on the surface metric (default), or the algebraic grid.
    control, tol, max_sweeps
        Passed to :func:`.elliptic.refine`.
    orthogonal : bool or collection of {"i0", "i1", "j0", "j1"}
        Grid lines leave the sides (all four, or those named) at 90 degrees
        (:func:`.elliptic.refine`; default),
        and the first cells off a side whose first (or last) spacing is given are that
        high all along it; where that iteration does not converge, the grid without it
        is kept and ``SurfaceGrid.orthogonal_dropped`` says so.
    sides : dict, optional
        Nodes of some sides given, instead of by the law: side name (``"j0"``,
        ``"j1"``: ``(ni,)``; ``"i0"``, ``"i1"``: ``(nj,)``) to the side's normalized
        parameters (:class:`Side`), increasing from 0 to 1 (a network uses it to give
        two faces the same nodes along their shared edge).
    hold : sequence of NurbsCurve (3D) or (m, 3) points
        Curves on the surface to hold as grid lines (:mod:`.held`): each runs from a
        side to the opposite one and becomes a line of the grid (from ``j0`` to
        ``j1``: an i-line); the pieces between are gridded and refined with the held
        lines fixed. All held curves must run the same way. Rectangles only.
    hold_tol : float, optional
        How far a held curve may lie from the surface; default 1e-4 of its box diagonal.

    Returns
    -------
    SurfaceGrid

    Raises
    ------
    InvalidGeometryError
        Bad dims/size/spacing, a spacing no law of that many nodes can reach.
    DegenerateGeometryError
        Two opposite sides collapsed, or a surface of zero size.
    """
    started = time.perf_counter()
    surface = region.surface
    if not isinstance(surface, (NurbsSurface, PoleChart)) or surface.dimension != 3:
        raise InvalidGeometryError("a grid needs a 3D NurbsSurface")
    if smooth not in ("elliptic", "none"):
        raise InvalidGeometryError(f"smooth must be 'elliptic' or 'none', got {smooth!r}")
    if isinstance(spacing, Spacing):
        spacing = (spacing, spacing)
    elif not (isinstance(spacing, tuple) and len(spacing) == 2
              and all(isinstance(s, Spacing) for s in spacing)):
        raise InvalidGeometryError("spacing must be a Spacing or a pair of them (along i, along j)")
    lengths = {name: side.length for name, side in region.sides.items()}
    diag = float(np.linalg.norm(np.ptp(surface.bounding_box(), axis=0)))
    if not diag > 0.0:
        raise DegenerateGeometryError("the surface has zero size")
    collapsed = {name for name, length in lengths.items() if length <= COLLAPSED * diag}
    ni, nj = _dims(lengths, dims, size)
    fractions = _side_fractions(region, lengths, collapsed, ni, nj, spacing)
    for name, given in (sides or {}).items():
        if name not in SIDES:
            raise InvalidGeometryError(f"unknown side {name!r}; expected one of {', '.join(SIDES)}")
        given = np.asarray(given, dtype=float)
        n = ni if name in ("j0", "j1") else nj
        if given.shape != (n,) or not np.all(np.isfinite(given)) or given[0] != 0.0 \
                or given[-1] != 1.0 or np.any(np.diff(given) <= 0.0):
            raise InvalidGeometryError(
                f"side {name}: need {n} increasing normalized parameters from 0 to 1")
        fractions[name] = given
    u0, u1, v0, v1 = surface.domain
    pieces, axis = [(0, ni - 1)], 0
    if hold and not region.is_rectangle:
        raise InvalidGeometryError("held curves are supported on a surface's whole rectangle only")
    if not region.is_rectangle:
        st = _region_start(region, fractions)
    else:
        if hold:
            xy, pieces, axis = _held_start(surface, hold, fractions,
                                           1e-4 * diag if hold_tol is None else float(hold_tol))
            s, t = xy[..., 0], xy[..., 1]
        else:
            s, t = distribution_mesh(fractions["j0"], fractions["j1"], fractions["i0"], fractions["i1"])
        st = np.stack([u0 + s * (u1 - u0), v0 + t * (v1 - v0)], axis=-1)
    st[..., 0] = np.clip(st[..., 0], u0, u1)
    st[..., 1] = np.clip(st[..., 1], v0, v1)

    # the block's normal: the surface's, or its opposite where i x j runs the other way
    # in (u, v) (a loop taken clockwise for a face used reversed)
    orientation = 1 if float(np.sum(corner_jacobians(st[..., 0], st[..., 1]))) >= 0.0 else -1

    def measured(params: NDArray) -> tuple[NDArray, GridQuality]:
        points = surface.evaluate(params[..., 0], params[..., 1])
        normals = orientation * surface_normals(surface, params[..., 0], params[..., 1])
        return points, grid_quality(points, normals)

    start_points, start_quality = measured(st)
    chart = None if hold else respaced(surface)
    if chart is not None and (start_quality.folded_cells or start_quality.max_skewness > POOR_START):
        # patches joined C0 at very different speeds, and the algebraic grid in their
        # parameters is poor: made in the knots re-spaced at the joins instead, if better
        # (the sides' nodes as they are)
        other = st.copy()
        other[1:-1, 1:-1] = (_respaced_start(chart, fractions) if region.is_rectangle
                             else _region_start(region, fractions, chart))[1:-1, 1:-1]
        other[..., 0] = np.clip(other[..., 0], u0, u1)
        other[..., 1] = np.clip(other[..., 1], v0, v1)
        other_points, other_quality = measured(other)
        if (other_quality.folded_cells, other_quality.max_skewness) \
                < (start_quality.folded_cells, start_quality.max_skewness):
            st, start_points, start_quality = other, other_points, other_quality
    # a closed face (a cylinder, a torus): its seam is solved across, not held
    seam = Seam.find(st, start_points, surface.domain, diag) if region.is_rectangle and not hold else None
    start_params = st
    result = None
    points, quality = start_points, start_quality
    kept_start = dropped = None
    if smooth == "elliptic":
        first_cells = {name: given for name, given in (("i0", spacing[0].first), ("i1", spacing[0].last),
                                                       ("j0", spacing[1].first), ("j1", spacing[1].last))
                       if given is not None and name not in collapsed}
        result = _refine_pieces(surface, st, pieces, axis, control=control, orthogonal=orthogonal,
                                heights=first_cells, seam=seam, tol=tol, max_sweeps=max_sweeps)
        if orthogonal and not result.nearly_converged(tol):
            plain = _refine_pieces(surface, st, pieces, axis, control=control, seam=seam, tol=tol,
                                   max_sweeps=max_sweeps)
            if result.yields_to(plain):
                dropped = (f"the sides' orthogonality was not reached (residual "
                           f"{result.residuals[-1]:.3g}, sides off by {result.sides_misfit:.3g} x "
                           "their tolerance); the grid without it is kept")
                result = plain
        refined_points, refined = measured(result.parameters)
        if orthogonal and dropped is None and squeezes_corners(refined, start_points):
            plain = _refine_pieces(surface, st, pieces, axis, control=control, seam=seam, tol=tol,
                                   max_sweeps=max_sweeps)
            plain_points, plain_quality = measured(plain.parameters)
            dropped = plain_kept(refined, plain, plain_quality, tol)
            if dropped is not None:
                result, refined_points, refined = plain, plain_points, plain_quality
        worse = refined.folded_cells > start_quality.folded_cells or (
            not result.converged and refined.max_skewness > start_quality.max_skewness)
        if worse:
            kept_start = (f"the elliptic refinement stopped at residual {result.residuals[-1]:.3g} "
                          f"with max skewness {refined.max_skewness:.3g} and {refined.folded_cells} "
                          f"folded cell(s), worse than the algebraic grid's "
                          f"{start_quality.max_skewness:.3g} and {start_quality.folded_cells}: "
                          "the algebraic grid is kept")
        else:
            st, points, quality = result.parameters, refined_points, refined
    held = tuple(("i" if axis == 0 else "j", q) for _, q in pieces[:-1]) if hold else ()
    return SurfaceGrid(points=points, parameters=st, quality=quality, start_quality=start_quality,
                       elliptic=result, kept_start=kept_start, held=held, orientation=orientation,
                       collapsed_sides=tuple(sorted(collapsed)),
                       spacing_error=_spacing_error(points, spacing, collapsed),
                       time_s=time.perf_counter() - started, start_points=start_points,
                       start_parameters=start_params, side_params=dict(fractions), orthogonal_dropped=dropped,
                       seam=seam)
