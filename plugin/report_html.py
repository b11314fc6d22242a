"""A self-contained HTML report a person can look at: a 3-D view of the faces, curves and
grids, the summary, the tables and the images, in one file that opens offline.

The page holds everything it needs: the CSS and the viewer's JavaScript inline (the viewer
is ``report_html.js`` beside this module: a small WebGL renderer written for this page,
no library), the geometry as base64 of little-endian ``Float32Array`` / ``Uint32Array`` /
``Uint8Array`` bytes in a ``<script type="application/json">`` block, the images as
``data:`` URIs. Nothing is fetched from a network. Coordinates are stored relative to the
centre of the scene's bounding box (in double precision here), so a model far from the
origin keeps its float32 resolution in the view.

The view: triangles with Lambert shading from a headlight (back faces a shade darker),
polylines and grid lines as lines, grid cells coloured by their value; drag to rotate
(turntable about +z), wheel to zoom, right-drag or shift-drag to pan, a "reset view"
button, fitted to the scene's bounding box on load. A checkbox per group shows or hides
it; meshes and grids with values are coloured by a colour map (viridis) with a scale bar
per value label. Without WebGL the page says so in place of the view and shows the rest.

The page tells a reader (or a test) what the view did through ``document.body.dataset``:
``rendered`` is ``"webgl"`` once the first frame is drawn without a WebGL error,
``"no-webgl"`` when the browser gives no WebGL context, ``"error"`` when drawing failed
(the message is shown and logged), ``"no-scene"`` when the report has no geometry;
``triangles`` and ``segments`` count what was drawn.

Tables show numbers to 4 significant digits and keep the full value in each numeric cell's
``data-value`` attribute (``repr`` of the float, the integer's digits).

This module is numpy only (no OpenCascade): :func:`surfprep.plugin.occ.mesh.face_triangles`
gives the triangles of OpenCascade faces.
"""

from __future__ import annotations

import base64
import html
import json
import numbers
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

__all__ = [
    "GRID_GROUP",
    "ReportTable",
    "SceneGrid",
    "SceneMesh",
    "ScenePolyline",
    "format_number",
    "group_colour",
    "value_colours",
    "write_html_report",
]

#: the legend group of every :class:`SceneGrid`
GRID_GROUP = "grids"

#: colours (RGB 0..255) of the groups the verbs use; other groups take _PALETTE in turn
_NAMED_COLOURS: dict[str, tuple[int, int, int]] = {
    "untouched": (168, 176, 190),
    "healed": (46, 160, 67),
    "reparametrized": (240, 140, 30),
    "split": (140, 80, 200),
    "curves": (215, 40, 40),
    GRID_GROUP: (120, 165, 215),
}
_PALETTE: tuple[tuple[int, int, int], ...] = (
    (31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40), (148, 103, 189),
    (140, 86, 75), (227, 119, 194), (127, 127, 127), (188, 189, 34), (23, 190, 207),
)
#: viridis, 9 stops from 0 to 1 (RGB 0..255)
_VIRIDIS = np.array([
    (68, 1, 84), (71, 45, 123), (59, 82, 139), (44, 114, 142), (33, 145, 140),
    (40, 174, 128), (94, 201, 98), (173, 220, 48), (253, 231, 37),
], dtype=float)
#: colour of a value that is NaN (not measured)
_NO_VALUE_COLOUR = (150, 150, 150)
#: colour of the grid lines over the grid cells
_GRID_LINE_COLOUR = (35, 45, 65)


# ----------------------------------------------------------------- scene types
def _points(name: str, what: str, value, last_dims: tuple[int, ...], ndim: int,
            shape_text: str) -> np.ndarray:
    """``value`` as a read-only float64 array of ``ndim`` dimensions ending in ``last_dims``,
    every coordinate finite."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: {what} must be a {shape_text} array of numbers ({exc})") from None
    if array.ndim != ndim or array.shape[ndim - len(last_dims):] != last_dims:
        raise ValueError(f"{name}: {what} must be a {shape_text} array, got shape {array.shape}")
    if not np.isfinite(array).all():
        bad = np.argwhere(~np.isfinite(array))[0][:-1]
        raise ValueError(f"{name}: {what} hold NaN or infinite coordinates "
                         f"(first at index {tuple(int(k) for k in bad)})")
    array.setflags(write=False)
    return array


def _values(name: str, what: str, value, shape: tuple[int, ...], shape_text: str) -> np.ndarray:
    """``value`` as a read-only float64 array of ``shape``: finite or NaN (no value)."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: {what} must be a {shape_text} array of numbers ({exc})") from None
    if array.shape != shape:
        raise ValueError(f"{name}: {what} must have shape {shape_text} = {shape}, got {array.shape}")
    if np.isinf(array).any():
        raise ValueError(f"{name}: {what} hold infinite numbers (NaN, for no value, is allowed)")
    array.setflags(write=False)
    return array


def _label(name: str, what: str, value) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name}: {what} must be a string, got {value!r}")
    if not value.strip():
        raise ValueError(f"{name}: {what} must not be empty")
    return value


def _optional_label(name: str, value) -> str | None:
    if value is not None and not isinstance(value, str):
        raise TypeError(f"{name}: value_label must be a string or None, got {value!r}")
    return value


@dataclass(frozen=True, eq=False)
class SceneMesh:
    """A face (or a few faces) as triangles.

    Parameters
    ----------
    name : str
        Shown nowhere yet but in error messages; names the item.
    vertices : (n, 3) float
        Points in model coordinates, all finite.
    triangles : (m, 3) int
        Indices into ``vertices``; the right-hand normal of ``(v0, v1, v2)`` is the front.
    group : str
        The legend group (``"untouched"``, ``"healed"``, ``"reparametrized"``, ``"split"``...):
        coloured by group, shown or hidden by the group's checkbox.
    values : (n,) float, optional
        A figure per vertex (the deviation from the input...): the mesh is then coloured by a
        colour map with a scale bar instead of its group colour. NaN is "no value" (grey).
    value_label : str, optional
        What ``values`` are (the scale bar's title; meshes sharing a label share a scale).

    Raises
    ------
    ValueError
        Wrong shapes, NaN or infinite coordinates, indices that are not integers or out of
        range, infinite values, an empty name or group.
    """

    name: str
    vertices: np.ndarray
    triangles: np.ndarray
    group: str
    values: np.ndarray | None = None
    value_label: str | None = None

    def __post_init__(self) -> None:
        name = f"SceneMesh {_label('SceneMesh', 'name', self.name)!r}"
        _label(name, "group", self.group)
        vertices = _points(name, "vertices", self.vertices, (3,), 2, "(n, 3)")
        raw = np.asarray(self.triangles)
        if raw.size == 0:
            raw = raw.reshape(0, 3).astype(np.int64)
        if raw.dtype.kind not in "iu":
            raise ValueError(f"{name}: triangles must be an (m, 3) array of integers, "
                             f"got dtype {raw.dtype}")
        if raw.ndim != 2 or raw.shape[1] != 3:
            raise ValueError(f"{name}: triangles must be an (m, 3) array, got shape {raw.shape}")
        triangles = raw.astype(np.int64)
        if triangles.size and (triangles.min() < 0 or triangles.max() >= len(vertices)):
            row = int(np.argwhere((triangles < 0) | (triangles >= len(vertices)))[0][0])
            raise ValueError(f"{name}: triangle indices out of range: triangle {row} is "
                             f"{tuple(int(k) for k in triangles[row])} with {len(vertices)} vertices")
        triangles.setflags(write=False)
        values = None if self.values is None else _values(name, "values", self.values,
                                                          (len(vertices),), "(n,)")
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "triangles", triangles)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "value_label", _optional_label(name, self.value_label))


@dataclass(frozen=True, eq=False)
class ScenePolyline:
    """A curve as a polyline.

    Parameters
    ----------
    name : str
        Names the item.
    points : (n, 3) float
        At least 2 points in model coordinates, all finite.
    group : str, optional
        The legend group (``"curves"``).
    """

    name: str
    points: np.ndarray
    group: str = "curves"

    def __post_init__(self) -> None:
        name = f"ScenePolyline {_label('ScenePolyline', 'name', self.name)!r}"
        _label(name, "group", self.group)
        points = _points(name, "points", self.points, (3,), 2, "(n, 3)")
        if len(points) < 2:
            raise ValueError(f"{name}: a polyline needs at least 2 points, got {len(points)}")
        object.__setattr__(self, "points", points)


@dataclass(frozen=True, eq=False)
class SceneGrid:
    """A structured surface grid block, drawn as its cells and grid lines (group ``"grids"``).

    Parameters
    ----------
    name : str
        Names the item.
    points : (ni, nj, 3) float
        The nodes, ``ni, nj >= 2``, all finite.
    cell_values : (ni - 1, nj - 1) float, optional
        A figure per cell (equiangle skewness 0..1...): the cells are coloured by a colour map
        with a scale bar. NaN is "no value" (grey).
    value_label : str, optional
        What ``cell_values`` are (the scale bar's title).
    """

    name: str
    points: np.ndarray
    cell_values: np.ndarray | None = None
    value_label: str | None = None

    def __post_init__(self) -> None:
        name = f"SceneGrid {_label('SceneGrid', 'name', self.name)!r}"
        points = _points(name, "points", self.points, (3,), 3, "(ni, nj, 3)")
        if points.shape[0] < 2 or points.shape[1] < 2:
            raise ValueError(f"{name}: a grid needs ni, nj >= 2, got {points.shape[:2]}")
        cells = (points.shape[0] - 1, points.shape[1] - 1)
        values = None if self.cell_values is None else _values(
            name, "cell_values", self.cell_values, cells, "(ni - 1, nj - 1)")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "cell_values", values)
        object.__setattr__(self, "value_label", _optional_label(name, self.value_label))


Cell = str | int | float | None


@dataclass(frozen=True)
class ReportTable:
    """A table of the report.

    Parameters
    ----------
    title : str
        The table's caption.
    headers : tuple of str
        The column titles.
    rows : tuple of tuple
        One tuple per row, as many cells as ``headers``; a cell is a ``str``, an ``int``, a
        ``float`` (numpy scalars too), a ``bool`` (shown yes / no) or ``None`` (shown as a
        dash).
    """

    title: str
    headers: tuple[str, ...]
    rows: tuple[tuple[Cell, ...], ...]

    def __post_init__(self) -> None:
        if not isinstance(self.title, str):
            raise TypeError(f"ReportTable: title must be a string, got {self.title!r}")
        what = f"ReportTable {self.title!r}"
        if isinstance(self.headers, str) or not all(isinstance(h, str) for h in self.headers):
            raise ValueError(f"{what}: headers must be a sequence of strings, got {self.headers!r}")
        headers = tuple(self.headers)
        rows = []
        for r, row in enumerate(self.rows):
            if isinstance(row, str) or not isinstance(row, Sequence):
                raise TypeError(f"{what}: row {r} must be a sequence of cells, got {row!r}")
            if len(row) != len(headers):
                raise ValueError(f"{what}: row {r} has {len(row)} cells for {len(headers)} headers")
            for c, cell in enumerate(row):
                if not (cell is None or isinstance(cell, (str, numbers.Real, np.bool_))):
                    raise ValueError(f"{what}: cell ({r}, {c}) is a {type(cell).__name__}; cells are "
                                     "str, int, float, bool or None")
            rows.append(tuple(row))
        object.__setattr__(self, "headers", headers)
        object.__setattr__(self, "rows", tuple(rows))


# ----------------------------------------------------------------- colours and numbers
def group_colour(group: str, index: int) -> tuple[int, int, int]:
    """The RGB colour (0..255) of legend group ``group``, the ``index``-th group of the report
    (named groups have fixed colours; the others take a palette in turn)."""
    return _NAMED_COLOURS.get(group, _PALETTE[index % len(_PALETTE)])


def value_colours(values: np.ndarray, low: float, high: float) -> np.ndarray:
    """Viridis colours of ``values`` on the scale ``low..high``.

    Parameters
    ----------
    values : (n,) float
        The figures; NaN gives grey.
    low, high : float
        The ends of the scale (values beyond are clamped); ``high == low`` puts every value
        in the middle.

    Returns
    -------
    (n, 3) uint8
        RGB colours.
    """
    values = np.asarray(values, dtype=float)
    t = np.full(values.shape, 0.5) if high <= low else (values - low) / (high - low)
    t = np.clip(np.nan_to_num(t, nan=0.0), 0.0, 1.0)
    stops = np.linspace(0.0, 1.0, len(_VIRIDIS))
    rgb = np.stack([np.interp(t, stops, _VIRIDIS[:, k]) for k in range(3)], axis=-1)
    rgb[np.isnan(values)] = _NO_VALUE_COLOUR
    return np.rint(rgb).astype(np.uint8)


def format_number(value: float) -> str:
    """A number as the tables show it: integers exactly, floats to 4 significant digits
    (``1.235e5`` rather than ``1.235e+05``)."""
    if isinstance(value, numbers.Integral):
        return str(int(value))
    text = f"{float(value):.4g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}e{int(exponent)}"
    return text


def _css_rgb(rgb) -> str:
    return f"rgb({int(rgb[0])}, {int(rgb[1])}, {int(rgb[2])})"


def _b64(array: np.ndarray, dtype: str) -> str:
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


# ----------------------------------------------------------------- the page
def write_html_report(path: str | os.PathLike, *, title: str, summary: Sequence[str] = (),
                      tables: Sequence[ReportTable] = (), meshes: Sequence[SceneMesh] = (),
                      polylines: Sequence[ScenePolyline] = (), grids: Sequence[SceneGrid] = (),
                      images: Mapping[str, bytes] | None = None) -> Path:
    """Write the report as one self-contained HTML file (see the module doc).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (its folder must exist); written atomically.
    title : str
        The page's title and heading.
    summary : sequence of str, optional
        Lines shown under the view.
    tables : sequence of ReportTable, optional
        Shown after the summary.
    meshes, polylines, grids : sequences of SceneMesh, ScenePolyline, SceneGrid, optional
        The 3-D scene; without any the page has no view.
    images : mapping of str to bytes, optional
        Caption -> PNG, JPEG, GIF, WebP or SVG bytes, shown last.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        An argument of the wrong kind (a scene item of another type, a string where lines are
        expected, an image that is not one of the formats above).
    FileNotFoundError
        The folder of ``path`` does not exist.
    """
    from ..atomic_files import atomic_output

    if not isinstance(title, str):
        raise TypeError(f"write_html_report: title must be a string, got {title!r}")
    summary = _checked_items("summary", summary, str)
    tables = _checked_items("tables", tables, ReportTable)
    meshes = _checked_items("meshes", meshes, SceneMesh)
    polylines = _checked_items("polylines", polylines, ScenePolyline)
    grids = _checked_items("grids", grids, SceneGrid)
    figures = _checked_images({} if images is None else images)

    scene, legend = _scene(meshes, polylines, grids)
    page = _page(title, summary, tables, scene, legend, figures)
    with atomic_output(path) as temporary:
        temporary.write_text(page, encoding="utf-8")
    return Path(path)


def _checked_items(what: str, items, kind: type) -> list:
    if isinstance(items, (str, bytes)) or not isinstance(items, Sequence):
        raise TypeError(f"write_html_report: {what} must be a sequence of {kind.__name__}, "
                         f"got {type(items).__name__}")
    for k, item in enumerate(items):
        if not isinstance(item, kind):
            raise TypeError(f"write_html_report: {what}[{k}] is a {type(item).__name__}, "
                             f"not a {kind.__name__}")
    return list(items)


def _image_type(data: bytes) -> str | None:
    head = data[:256].lstrip()
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "image/png"
    if data.startswith(b"\xff\xd8\xff"):
        return "image/jpeg"
    if data[:6] in (b"GIF87a", b"GIF89a"):
        return "image/gif"
    if data[:4] == b"RIFF" and data[8:12] == b"WEBP":
        return "image/webp"
    if head.startswith(b"<svg") or (head.startswith(b"<?xml") and b"<svg" in data[:4096]):
        return "image/svg+xml"
    return None


def _checked_images(images) -> list[tuple[str, str]]:
    if not isinstance(images, Mapping):
        raise TypeError(f"write_html_report: images must be a mapping of caption to bytes, "
                         f"got {type(images).__name__}")
    out = []
    for caption, data in images.items():
        if not isinstance(caption, str) or not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError(f"write_html_report: image {caption!r}: expected a str caption and "
                             f"bytes, got {type(caption).__name__} and {type(data).__name__}")
        data = bytes(data)
        mime = _image_type(data)
        if mime is None:
            raise ValueError(f"write_html_report: image {caption!r} is not PNG, JPEG, GIF, WebP "
                             "or SVG")
        out.append((caption, f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"))
    return out


@dataclass(frozen=True)
class _Scale:
    """The colour scale of one value label."""

    label: str
    low: float
    high: float


def _scales(meshes: list[SceneMesh], grids: list[SceneGrid]) -> dict[str, _Scale]:
    """One scale per value label over every mesh and grid showing it (NaN left out)."""
    found: dict[str, list[np.ndarray]] = {}
    for item, values in [(m, m.values) for m in meshes] + [(g, g.cell_values) for g in grids]:
        if values is not None:
            found.setdefault(item.value_label or "value", []).append(values.ravel())
    scales = {}
    for label, arrays in found.items():
        every = np.concatenate(arrays)
        every = every[~np.isnan(every)]
        low, high = (float(every.min()), float(every.max())) if every.size else (0.0, 1.0)
        scales[label] = _Scale(label, low, high)
    return scales


def _scene(meshes: list[SceneMesh], polylines: list[ScenePolyline],
           grids: list[SceneGrid]) -> tuple[dict | None, str]:
    """The scene as plain JSON data for the viewer and the legend's HTML (None and "" for
    a report without geometry)."""
    if not (meshes or polylines or grids):
        return None, ""
    groups: dict[str, tuple[int, int, int]] = {}
    counts: dict[str, _GroupCount] = {}

    def colour_of(group: str) -> tuple[int, int, int]:
        if group not in groups:
            groups[group] = group_colour(group, len(groups))
            counts[group] = _GroupCount()
        return groups[group]

    blocks = ([m.vertices for m in meshes] + [p.points for p in polylines]
              + [g.points.reshape(-1, 3) for g in grids])
    every = np.concatenate([b for b in blocks if len(b)]) if any(len(b) for b in blocks) \
        else np.zeros((1, 3))
    low, high = every.min(axis=0), every.max(axis=0)
    origin = (low + high) / 2
    radius = float(np.linalg.norm(high - low) / 2) or 1.0
    scales = _scales(meshes, grids)

    scene_meshes = []
    for mesh in meshes:
        rgb = colour_of(mesh.group)
        counts[mesh.group].add(len(mesh.triangles), mesh.value_label or "value"
                               if mesh.values is not None else None)
        item = {"name": mesh.name, "group": mesh.group, "color": list(rgb),
                "pos": _b64(mesh.vertices - origin, "<f4"), "idx": _b64(mesh.triangles, "<u4"),
                "col": None}
        if mesh.values is not None:
            scale = scales[mesh.value_label or "value"]
            item["col"] = _b64(value_colours(mesh.values, scale.low, scale.high), "u1")
        scene_meshes.append(item)
    scene_lines = []
    for line in polylines:
        rgb = colour_of(line.group)
        counts[line.group].add(0, None)
        scene_lines.append({"name": line.name, "group": line.group, "color": list(rgb),
                            "pos": _b64(line.points - origin, "<f4")})
    scene_grids = []
    for grid in grids:
        rgb = colour_of(GRID_GROUP)
        counts[GRID_GROUP].add(0, grid.value_label or "value" if grid.cell_values is not None
                               else None)
        ni, nj = grid.points.shape[:2]
        item = {"name": grid.name, "group": GRID_GROUP, "color": list(rgb),
                "lineColor": list(_GRID_LINE_COLOUR), "ni": ni, "nj": nj,
                "pos": _b64(grid.points.reshape(-1, 3) - origin, "<f4"), "cellCol": None}
        if grid.cell_values is not None:
            scale = scales[grid.value_label or "value"]
            item["cellCol"] = _b64(value_colours(grid.cell_values.ravel(), scale.low, scale.high),
                                   "u1")
        scene_grids.append(item)

    scene = {"origin": [float(x) for x in origin], "radius": radius, "meshes": scene_meshes,
             "lines": scene_lines, "grids": scene_grids}
    return scene, _legend_html(groups, counts) + _scales_html(scales)


class _GroupCount:
    """What a legend group holds: items, triangles, the value labels colouring them."""

    def __init__(self) -> None:
        self.items = 0
        self.triangles = 0
        self.labels: dict[str, None] = {}           # ordered set

    def add(self, triangles: int, label: str | None) -> None:
        self.items += 1
        self.triangles += triangles
        if label is not None:
            self.labels[label] = None


def _legend_html(groups: dict[str, tuple[int, int, int]], counts: dict[str, _GroupCount]) -> str:
    rows = []
    for group, rgb in groups.items():
        count = counts[group]
        detail = f"{count.items} item{'s' if count.items != 1 else ''}"
        if count.triangles:
            detail += f", {count.triangles} triangle{'s' if count.triangles != 1 else ''}"
        if count.labels:
            detail += f"; coloured by {', '.join(count.labels)}"
        rows.append(
            f'<label class="group"><input type="checkbox" class="group-toggle" checked '
            f'data-group="{html.escape(group)}"><span class="swatch" style="background: '
            f'{_css_rgb(rgb)}"></span><span class="group-name">{html.escape(group)}</span> '
            f'<span class="detail">({detail})</span></label>')
    return f'<div class="overlay legend" id="legend">{"".join(rows)}</div>'


def _scales_html(scales: dict[str, _Scale]) -> str:
    if not scales:
        return ""
    stops = ", ".join(f"{_css_rgb(c)} {100 * k / (len(_VIRIDIS) - 1):.1f}%"
                      for k, c in enumerate(_VIRIDIS))
    bars = []
    for scale in scales.values():
        middle = (scale.low + scale.high) / 2
        bars.append(
            f'<div class="scale" data-label="{html.escape(scale.label)}" '
            f'data-min="{scale.low!r}" data-max="{scale.high!r}">'
            f'<div class="scale-title">{html.escape(scale.label)}</div>'
            f'<div class="scale-bar" style="background: linear-gradient(to right, {stops})"></div>'
            f'<div class="scale-ticks"><span>{format_number(scale.low)}</span>'
            f'<span>{format_number(middle)}</span><span>{format_number(scale.high)}</span></div>'
            f'</div>')
    return (f'<div class="overlay scales" id="scales">{"".join(bars)}'
            f'<div class="scale-note">grey: no value</div></div>')


def _cell_html(cell: Cell) -> str:
    if cell is None:
        return '<td class="none">–</td>'
    if isinstance(cell, (bool, np.bool_)):
        return f'<td class="bool">{"yes" if cell else "no"}</td>'
    if isinstance(cell, numbers.Integral):
        return f'<td class="num" data-value="{int(cell)}">{format_number(cell)}</td>'
    if isinstance(cell, numbers.Real):
        return f'<td class="num" data-value="{float(cell)!r}">{format_number(cell)}</td>'
    return f"<td>{html.escape(str(cell))}</td>"


def _table_html(table: ReportTable) -> str:
    head = "".join(f'<th scope="col">{html.escape(h)}</th>' for h in table.headers)
    body = "".join(f"<tr>{''.join(_cell_html(c) for c in row)}</tr>" for row in table.rows)
    return (f'<table><caption>{html.escape(table.title)}</caption>'
            f'<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>')


def _json_for_script(data) -> str:
    """JSON that cannot end its ``<script>`` element (``<``, ``>`` and ``&`` escaped)."""
    text = json.dumps(data, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def _viewer_script() -> str:
    return resources.files(__package__).joinpath("report_html.js").read_text(encoding="utf-8")


_CSS = """
:root { color-scheme: light; --ink: #1d2430; --muted: #5b6577; --line: #d5dae3; }
* { box-sizing: border-box; }
[hidden] { display: none !important; }
body { margin: 0 auto; max-width: 1400px; padding: 16px 24px 48px; color: var(--ink);
       font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; }
h1 { font-size: 1.5em; margin: 0.2em 0 0.6em; }
h2 { font-size: 1.15em; margin: 1.6em 0 0.5em; }
#view { position: relative; height: 70vh; min-height: 360px; border: 1px solid var(--line);
        border-radius: 6px; overflow: hidden; background: #f4f6f9; }
#view.unavailable { height: auto; min-height: 0; }
#view.unavailable .view-message { position: static; }
#view-canvas { display: block; width: 100%; height: 100%; touch-action: none; cursor: grab; }
#view-canvas.dragging { cursor: grabbing; }
.view-message { position: absolute; inset: 0; display: flex; align-items: center;
                justify-content: center; padding: 2em; text-align: center; color: var(--muted);
                font-size: 1.05em; }
.overlay { position: absolute; background: rgba(255, 255, 255, 0.86); border: 1px solid var(--line);
           border-radius: 5px; padding: 6px 10px; font-size: 13px; }
.legend { top: 10px; left: 10px; display: flex; flex-direction: column; gap: 2px; }
.legend label { cursor: pointer; white-space: nowrap; }
.swatch { display: inline-block; width: 12px; height: 12px; margin: 0 6px 0 4px;
          border-radius: 2px; vertical-align: -1px; border: 1px solid rgba(0, 0, 0, 0.25); }
.detail { color: var(--muted); }
.scales { top: 10px; right: 10px; width: 230px; }
.scale + .scale { margin-top: 8px; }
.scale-title { font-weight: 600; }
.scale-bar { height: 12px; border-radius: 2px; margin: 3px 0; }
.scale-ticks { display: flex; justify-content: space-between; font-variant-numeric: tabular-nums; }
.scale-note { color: var(--muted); margin-top: 4px; font-size: 12px; }
.controls { bottom: 10px; left: 10px; display: flex; gap: 12px; align-items: center; }
.controls span { color: var(--muted); }
.summary ul { margin: 0; padding-left: 1.2em; }
table { border-collapse: collapse; margin: 0.4em 0 1.4em; font-size: 14px; }
caption { text-align: left; font-weight: 600; padding: 4px 0; }
th, td { padding: 3px 10px; border-bottom: 1px solid var(--line); text-align: left; }
thead th { border-bottom: 2px solid #aab2c0; }
tbody tr:nth-child(even) { background: #f7f8fa; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.none { color: var(--muted); text-align: center; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid var(--line); }
figcaption { color: var(--muted); font-size: 13px; }
"""


def _page(title: str, summary: list[str], tables: list[ReportTable], scene: dict | None,
          legend: str, figures: list[tuple[str, str]]) -> str:
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        '<meta name="generator" content="surfprep">',
        '<link rel="icon" href="data:,">',                 # no favicon request
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head>",
        f'<body data-rendered="pending"><h1>{html.escape(title)}</h1>',
    ]
    if scene is not None:
        parts += [
            '<section id="view-section"><div id="view">',
            '<canvas id="view-canvas" aria-label="3-D view of the model"></canvas>',
            '<div id="view-message" class="view-message" hidden></div>',
            ('<noscript><div class="view-message">The 3-D view needs JavaScript; '
             "the figures below are complete without it.</div></noscript>"),
            legend,
            ('<div class="overlay controls" id="controls"><button type="button" id="reset-view">'
             "reset view</button><span>drag: rotate · right-drag or shift-drag: pan · "
             "wheel: zoom</span></div>"),
            "</div></section>",
            f'<script type="application/json" id="surfprep-scene">{_json_for_script(scene)}</script>',
        ]
    if summary:
        items = "".join(f"<li>{html.escape(line)}</li>" for line in summary)
        parts.append(f'<section class="summary"><h2>Summary</h2><ul>{items}</ul></section>')
    if tables:
        parts.append('<section class="tables"><h2>Tables</h2>'
                     + "".join(_table_html(t) for t in tables) + "</section>")
    if figures:
        parts.append('<section class="images"><h2>Images</h2>' + "".join(
            f'<figure><img src="{uri}" alt="{html.escape(caption)}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>" for caption, uri in figures)
            + "</section>")
    parts += [f"<script>{_viewer_script()}</script>", "</body></html>", ""]
    return "\n".join(parts)
