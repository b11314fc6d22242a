"""The HTML report: what the file holds (no network reference, the tables' exact figures,
the scene's geometry), the inputs it refuses, and the page in a real headless Chromium
(WebGL through SwiftShader): no console error, the 3-D view drawn and answering the mouse,
the tables in the DOM, and the fallback without WebGL."""

from __future__ import annotations

import base64
import io
import json
import math
import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from helpers.browser import chromium_path, open_page
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeSphere
from OCP.gp import gp_Pnt
from PIL import Image

from surfprep.atomic_files import new_file_mode
from surfprep.plugin.occ.mesh import face_triangles
from surfprep.plugin.occ.shapes import all_faces
from surfprep.plugin.report_html import (
    ReportTable,
    SceneGrid,
    SceneMesh,
    ScenePolyline,
    format_number,
    group_colour,
    value_colours,
    write_html_report,
)

HEALED = group_colour("healed", 0)



def _png() -> bytes:
    """A 1 x 1 red PNG."""
    stream = io.BytesIO()
    Image.new("RGB", (1, 1), (255, 0, 0)).save(stream, format="PNG")
    return stream.getvalue()


PNG = _png()

TABLE = ReportTable(
    "per face", ("face", "area", "poles", "deviation", "note", "valid"),
    (("wing <upper>", 100.92345678901234, 25, 1.2345678e-07, None, True),
     ("fuselage", 2.0 / 3.0, 1_000_000_007, np.float64(3.5e12), "kept & named", False),
     ("flap", -0.0, np.int64(-4), float("nan"), "", True)))


# ----------------------------------------------------------------- scenes
def _grid_points(ni: int = 9, nj: int = 6, offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    i, j = np.meshgrid(np.linspace(0, 1, ni), np.linspace(0, 1, nj), indexing="ij")
    return np.stack([20 * i, -45 + 20 * j + 4 * i * j, 6 * np.sin(3 * i)], axis=-1) + offset


def _skewness(points: np.ndarray) -> np.ndarray:
    """(ni - 1, nj - 1) equiangle skewness of the grid's cells, 0..1."""
    p = points
    corners = [p[:-1, :-1], p[1:, :-1], p[1:, 1:], p[:-1, 1:]]
    worst = np.zeros((p.shape[0] - 1, p.shape[1] - 1))
    for k in range(4):
        a = corners[(k - 1) % 4] - corners[k]
        b = corners[(k + 1) % 4] - corners[k]
        cos = np.einsum("ijk,ijk->ij", a, b) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
        angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
        worst = np.maximum(worst, np.maximum((angle - 90) / 90, (90 - angle) / 90))
    return worst


@pytest.fixture(scope="module")
def occ_scene():
    """A box (untouched), a sphere (healed), a sphere coloured by its z (reparametrized), a
    circle and a grid block with its skewness, from OpenCascade through face_triangles."""
    box = BRepPrimAPI_MakeBox(gp_Pnt(-40.0, -10.0, -10.0), 20.0, 20.0, 20.0).Shape()
    meshes = [SceneMesh(f"box face {k}", v, t, "untouched")
              for k, (v, t) in enumerate(face_triangles(all_faces(box), deflection=0.05))]
    sphere = BRepPrimAPI_MakeSphere(gp_Pnt(5.0, 0.0, 0.0), 12.0).Shape()
    (v, t), = face_triangles(all_faces(sphere), deflection=0.05)
    meshes.append(SceneMesh("sphere", v, t, "healed"))
    meshes.append(SceneMesh("sphere, z", v + [0.0, 35.0, 0.0], t, "reparametrized",
                            values=v[:, 2], value_label="z (mm)"))
    s = np.linspace(0, 2 * np.pi, 200)
    polylines = [ScenePolyline("equator", np.column_stack([5 + 13 * np.cos(s), 13 * np.sin(s),
                                                           np.zeros_like(s)]))]
    points = _grid_points()
    grids = [SceneGrid("block 0", points, cell_values=_skewness(points), value_label="skewness")]
    return {"meshes": meshes, "polylines": polylines, "grids": grids}


@pytest.fixture(scope="module")
def report(tmp_path_factory, occ_scene) -> Path:
    path = tmp_path_factory.mktemp("report") / "report.html"
    return write_html_report(path, title="surfprep report <test>",
                             summary=["2 faces healed", "largest deviation 1.2e-7 mm"],
                             tables=[TABLE], images={"a red pixel": PNG}, **occ_scene)


class _Cells(HTMLParser):
    """The ``<td>`` cells of a page: (attributes, text) per row."""

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[list[tuple[dict, str]]] = []
        self._cell: tuple[dict, list[str]] | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag == "td":
            self._cell = (dict(attrs), [])

    def handle_data(self, data):
        if self._cell is not None:
            self._cell[1].append(data)

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self.rows[-1].append((self._cell[0], "".join(self._cell[1])))
            self._cell = None


def _scene_json(page: str) -> dict:
    found = re.search(r'<script type="application/json" id="surfprep-scene">(.*?)</script>', page,
                      re.DOTALL)
    assert found
    return json.loads(found.group(1))


def _decode(b64: str, dtype: str) -> np.ndarray:
    return np.frombuffer(base64.b64decode(b64), dtype=dtype)


def _same_figure(value, expected) -> bool:
    if isinstance(expected, float) and math.isnan(expected):
        return math.isnan(value)
    return value == expected and type(value) is (int if isinstance(expected, int) else float)


# ----------------------------------------------------------------- the file
def test_the_page_fetches_nothing_from_a_network(report):
    page = report.read_text(encoding="utf-8")
    assert "http://" not in page and "https://" not in page
    # every src / href is a data: URI or a fragment; no CSS import or url() to elsewhere
    for ref in re.findall(r'\b(?:src|href)\s*=\s*["\']?([^"\'\s>]*)', page, re.IGNORECASE):
        assert ref.startswith(("data:", "#")), ref
    assert "@import" not in page
    assert all(u.startswith("data:") for u in re.findall(r"url\(\s*['\"]?([^'\")]*)", page))
    assert "<script src" not in page


def test_a_url_in_the_text_stays_text(tmp_path):
    path = write_html_report(tmp_path / "r.html", title="t",
                             summary=['see <a href="https://example.org">x</a>'])
    page = path.read_text(encoding="utf-8")
    assert 'href="https://' not in page
    assert "&lt;a href=&quot;https://example.org&quot;&gt;" in page


def test_tables_hold_every_figure_exactly_in_data_value(report):
    parser = _Cells()
    parser.feed(report.read_text(encoding="utf-8"))
    rows = [r for r in parser.rows if r]                   # header rows have no <td>
    assert len(rows) == len(TABLE.rows)
    for row, expected_row in zip(rows, TABLE.rows, strict=True):
        for (attrs, text), expected in zip(row, expected_row, strict=True):
            if expected is None:
                assert "data-value" not in attrs and text == "–"
            elif isinstance(expected, (bool, np.bool_)):
                assert "data-value" not in attrs and text == ("yes" if expected else "no")
            elif isinstance(expected, str):
                assert "data-value" not in attrs and text == expected
            elif isinstance(expected, (int, np.integer)):
                assert int(attrs["data-value"]) == expected and text == str(int(expected))
            else:
                value = float(attrs["data-value"])
                assert _same_figure(value, float(expected))
                assert text == format_number(float(expected))
                if math.isfinite(expected) and expected != 0:
                    # what is shown agrees with the figure to 4 significant digits
                    assert float(text) == pytest.approx(float(expected), rel=5e-4)


@pytest.mark.parametrize(("value", "text"), [
    (100.92345678901234, "100.9"), (1.2345678e-07, "1.235e-7"), (3.5e12, "3.5e12"),
    (2.0 / 3.0, "0.6667"), (25, "25"), (1_000_000_007, "1000000007"), (-0.0, "-0"),
    (float("nan"), "nan"), (float("inf"), "inf"), (np.float32(0.5), "0.5"), (np.int64(-4), "-4"),
])
def test_format_number(value, text):
    assert format_number(value) == text


def test_the_scene_holds_the_geometry(report, occ_scene):
    scene = _scene_json(report.read_text(encoding="utf-8"))
    origin = np.array(scene["origin"])
    meshes = occ_scene["meshes"]
    assert len(scene["meshes"]) == len(meshes)
    for item, mesh in zip(scene["meshes"], meshes, strict=True):
        assert item["name"] == mesh.name and item["group"] == mesh.group
        vertices = _decode(item["pos"], "<f4").reshape(-1, 3) + origin
        np.testing.assert_allclose(vertices, mesh.vertices, rtol=0, atol=1e-5)
        np.testing.assert_array_equal(_decode(item["idx"], "<u4").reshape(-1, 3), mesh.triangles)
        if mesh.values is None:
            assert item["col"] is None and item["color"] == list(group_colour(mesh.group, 0))
        else:
            colours = _decode(item["col"], "u1").reshape(-1, 3)
            low, high = mesh.values.min(), mesh.values.max()
            np.testing.assert_array_equal(colours, value_colours(mesh.values, low, high))
    (grid_item,), (grid,) = scene["grids"], occ_scene["grids"]
    assert (grid_item["ni"], grid_item["nj"]) == grid.points.shape[:2]
    np.testing.assert_allclose(_decode(grid_item["pos"], "<f4").reshape(grid.points.shape) + origin,
                               grid.points, rtol=0, atol=1e-5)
    assert len(_decode(grid_item["cellCol"], "u1")) == 3 * grid.cell_values.size
    every = np.concatenate([m.vertices for m in meshes] + [p.points for p in occ_scene["polylines"]]
                           + [grid.points.reshape(-1, 3)])
    np.testing.assert_allclose(origin, (every.min(axis=0) + every.max(axis=0)) / 2)
    assert scene["radius"] == pytest.approx(np.linalg.norm(every.max(axis=0) - every.min(axis=0)) / 2)


def test_far_from_the_origin_the_view_keeps_its_resolution(tmp_path):
    points = _grid_points(offset=(1e6, -2e6, 5e5))
    path = write_html_report(tmp_path / "far.html", title="far", grids=[SceneGrid("g", points)])
    scene = _scene_json(path.read_text(encoding="utf-8"))
    stored = _decode(scene["grids"][0]["pos"], "<f4").reshape(points.shape) + scene["origin"]
    # float32 relative to the scene's centre: micrometres, where absolute float32 would be 0.1 mm
    np.testing.assert_allclose(stored, points, rtol=0, atol=1e-5)


def test_value_colours_follow_viridis_and_grey_for_nan():
    colours = value_colours(np.array([0.0, 0.5, 1.0, np.nan, 7.0]), 0.0, 1.0)
    assert colours.dtype == np.uint8 and colours.shape == (5, 3)
    assert tuple(colours[0]) == (68, 1, 84) and tuple(colours[2]) == (253, 231, 37)
    assert tuple(colours[1]) == (33, 145, 140)
    assert tuple(colours[3]) == (150, 150, 150)
    assert tuple(colours[4]) == (253, 231, 37)                 # clamped
    assert (value_colours(np.array([2.0, 2.0]), 2.0, 2.0) == colours[1]).all()


def test_legend_and_scale_bars(report):
    page = report.read_text(encoding="utf-8")
    groups = re.findall(r'class="group-toggle" checked data-group="([^"]*)"', page)
    assert groups == ["untouched", "healed", "reparametrized", "curves", "grids"]
    scales = dict(re.findall(r'class="scale" data-label="([^"]*)" data-min="[^"]*" '
                             r'data-max="([^"]*)"', page))
    assert set(scales) == {"z (mm)", "skewness"}
    assert float(scales["z (mm)"]) == pytest.approx(12.0, abs=1e-9)


def test_a_script_breaking_name_cannot_end_the_scene(tmp_path):
    name = "</script><script>alert(1)</script>"
    path = write_html_report(tmp_path / "r.html", title=name, summary=[name],
                             polylines=[ScenePolyline(name, [[0, 0, 0], [1, 0, 0]], group=name)])
    page = path.read_text(encoding="utf-8")
    assert page.count("<script") == page.count("</script>") == 2     # the scene and the viewer
    assert _scene_json(page)["lines"][0]["name"] == name


def test_a_report_without_geometry_has_no_view(tmp_path):
    path = write_html_report(tmp_path / "r.html", title="numbers only", tables=[TABLE])
    page = path.read_text(encoding="utf-8")
    assert 'id="view-canvas"' not in page and 'id="surfprep-scene"' not in page
    assert "<table>" in page


def test_a_large_model_stays_a_few_megabytes(tmp_path):
    n = 224                                                   # 2 * 223^2 = 99 458 triangles
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    vertices = np.column_stack([i.ravel(), j.ravel(), np.sin(i.ravel() / 9.0)]).astype(float)
    k = (i[:-1, :-1] * n + j[:-1, :-1]).ravel()
    triangles = np.concatenate([np.column_stack([k, k + n, k + n + 1]),
                                np.column_stack([k, k + n + 1, k + 1])])
    assert len(triangles) > 99_000
    path = write_html_report(tmp_path / "big.html", title="big",
                             meshes=[SceneMesh("sheet", vertices, triangles, "healed",
                                               values=vertices[:, 2])])
    assert path.stat().st_size < 3_000_000


def test_the_file_is_written_atomically_with_the_usual_mode(tmp_path):
    target = tmp_path / "r.html"
    target.write_text("old")
    assert write_html_report(target, title="new") == target
    assert "<h1>new</h1>" in target.read_text(encoding="utf-8")
    assert (target.stat().st_mode & 0o777) == new_file_mode()
    assert sorted(os.listdir(tmp_path)) == ["r.html"]
    with pytest.raises(FileNotFoundError):
        write_html_report(tmp_path / "missing" / "r.html", title="t")


# ----------------------------------------------------------------- refused inputs
SQUARE = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
TWO = np.array([[0, 1, 2], [0, 2, 3]])


@pytest.mark.parametrize(("make", "message"), [
    (lambda: SceneMesh("m", SQUARE[:, :2], TWO, "g"), r"vertices must be a \(n, 3\) array"),
    (lambda: SceneMesh("m", SQUARE.ravel(), TWO, "g"), r"got shape \(12,\)"),
    (lambda: SceneMesh("m", np.where(SQUARE == 1, np.nan, SQUARE), TWO, "g"), "NaN or infinite"),
    (lambda: SceneMesh("m", SQUARE + [np.inf, 0, 0], TWO, "g"), "NaN or infinite"),
    (lambda: SceneMesh("m", SQUARE, [[0, 1, 4]], "g"), "out of range: triangle 0 is .0, 1, 4. with 4"),
    (lambda: SceneMesh("m", SQUARE, [[0, 1, 2], [-1, 1, 2]], "g"), "out of range: triangle 1"),
    (lambda: SceneMesh("m", SQUARE, TWO.astype(float), "g"), "must be an .m, 3. array of integers"),
    (lambda: SceneMesh("m", SQUARE, TWO[:, :2], "g"), r"triangles must be an \(m, 3\) array"),
    (lambda: SceneMesh("m", SQUARE, TWO, "g", values=[1.0, 2.0]), r"values must have shape \(n,\)"),
    (lambda: SceneMesh("m", SQUARE, TWO, "g", values=[1.0, 2, 3, np.inf]), "infinite numbers"),
    (lambda: SceneMesh("m", SQUARE, TWO, " "), "group must not be empty"),
    (lambda: ScenePolyline("p", [[0.0, 0, 0]]), "at least 2 points"),
    (lambda: ScenePolyline("p", [[0.0, 0, 0], [1, np.nan, 0]]), "NaN or infinite"),
    (lambda: SceneGrid("g", SQUARE), r"points must be a \(ni, nj, 3\) array"),
    (lambda: SceneGrid("g", np.zeros((1, 4, 3))), "ni, nj >= 2"),
    (lambda: SceneGrid("g", np.zeros((3, 4, 3)), cell_values=np.zeros((3, 4))),
     r"cell_values must have shape \(ni - 1, nj - 1\) = \(2, 3\)"),
    (lambda: ReportTable("t", ("a", "b"), (("x",),)), "row 0 has 1 cells for 2 headers"),
    (lambda: ReportTable("t", ("a",), ((np.zeros(2),),)), r"cell \(0, 0\) is a ndarray"),
    (lambda: ReportTable("t", ("a",), (({"a": 1},),)), r"cell \(0, 0\) is a dict"),
])
def test_bad_scene_items_and_tables_are_refused(make, message):
    with pytest.raises(ValueError, match=message):
        make()


@pytest.mark.parametrize(("kwargs", "error", "message"), [
    ({"summary": "one line"}, TypeError, "summary must be a sequence of str"),
    ({"meshes": [ScenePolyline("p", SQUARE)]}, TypeError, r"meshes\[0\] is a ScenePolyline"),
    ({"tables": [("a", 1)]}, TypeError, r"tables\[0\] is a tuple"),
    ({"images": {"x": b"not an image"}}, ValueError, "is not PNG, JPEG, GIF, WebP or SVG"),
    ({"images": {"x": "a string"}}, TypeError, "expected a str caption and bytes"),
    ({"images": [PNG]}, TypeError, "images must be a mapping"),
])
def test_bad_report_arguments_are_refused(tmp_path, kwargs, error, message):
    with pytest.raises(error, match=message):
        write_html_report(tmp_path / "r.html", title="t", **kwargs)
    assert not (tmp_path / "r.html").exists()


def test_scene_items_are_read_only_copies():
    vertices = SQUARE.copy()
    mesh = SceneMesh("m", vertices, TWO, "g")
    vertices[0, 0] = 99.0
    assert mesh.vertices[0, 0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        mesh.vertices[0, 0] = 1.0


# ----------------------------------------------------------------- in a real browser
def _pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def _shaded(pixels: np.ndarray, rgb) -> np.ndarray:
    """Mask of the pixels that are ``rgb`` under some shading factor (0.15..1.05)."""
    colour = np.asarray(rgb, dtype=float)
    k = pixels @ colour / (colour @ colour)
    residual = np.linalg.norm(pixels - k[..., None] * colour, axis=-1)
    return (residual < 6) & (k > 0.15) & (k < 1.05)


def _table_cells_js() -> str:
    return ("Array.from(document.querySelectorAll('table tbody tr')).map(function (tr) { "
            "return Array.from(tr.cells).map(function (td) { "
            "return [td.dataset.value === undefined ? null : td.dataset.value, td.textContent]; }); })")


def _check_dom_tables(rows) -> None:
    assert len(rows) == len(TABLE.rows)
    for row, expected_row in zip(rows, TABLE.rows, strict=True):
        for (value, text), expected in zip(row, expected_row, strict=True):
            if expected is None or isinstance(expected, (str, bool, np.bool_)):
                assert value is None
            elif isinstance(expected, (int, np.integer)):
                assert int(value) == expected and text == str(int(expected))
            else:
                assert _same_figure(float(value), float(expected)) and text == format_number(expected)


def test_the_page_in_chromium_draws_the_scene_and_answers_the_mouse(report, occ_scene):
    chromium_path()                                  # skips, saying how to install it, if missing
    with open_page(report, webgl=True, timeout=20) as page:
        assert page.wait_rendered() == "webgl", page.console
        assert page.errors == []
        assert all(url.startswith(("file:", "data:")) for url in page.requests), page.requests
        triangles = sum(len(m.triangles) for m in occ_scene["meshes"]) + 2 * 8 * 5
        assert int(page.js("document.body.dataset.triangles")) == triangles
        _check_dom_tables(page.js(_table_cells_js()))
        assert page.js("document.getElementById('view-message').hidden") is True

        first = _pixels(page.screenshot("#view-canvas"))
        assert first.shape[0] > 300 and first.shape[1] > 600
        colours = {tuple(p) for p in first.reshape(-1, 3)}
        assert len(colours) > 300                     # shading, colour maps, lines
        green = _shaded(first, HEALED).sum()
        assert green > 2000                            # the healed sphere, lit
        viridis_end = _shaded(first, (253, 231, 37)).sum() + _shaded(first, (68, 1, 84)).sum()
        assert viridis_end > 50                        # the sphere coloured by z
        red = _shaded(first, group_colour("curves", 0)).sum()
        assert red > 30                                # the polyline
        box = page.box("#view-canvas")
        centre = (box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)

        page.drag(centre, (centre[0] + 150, centre[1] + 60))           # rotate
        page.settle()
        rotated = _pixels(page.screenshot("#view-canvas"))
        assert np.abs(rotated - first).mean() > 1.0

        page.click("#reset-view")
        page.settle()
        assert np.abs(_pixels(page.screenshot("#view-canvas")) - first).mean() < 0.2

        page.wheel(centre, -600)                                       # zoom in
        page.settle()
        zoomed = _pixels(page.screenshot("#view-canvas"))
        assert _shaded(zoomed, HEALED).sum() > 1.5 * green

        page.click("#reset-view")
        page.drag(centre, (centre[0] + 200, centre[1]), shift=True)    # pan right
        page.settle()
        panned = _pixels(page.screenshot("#view-canvas"))
        column = np.nonzero(_shaded(first, HEALED).any(axis=0))[0].mean()
        moved = np.nonzero(_shaded(panned, HEALED).any(axis=0))[0].mean()
        assert moved - column == pytest.approx(200, abs=25)
        page.drag((centre[0] + 200, centre[1]), centre, button="right")  # and back
        page.settle()
        assert np.abs(_pixels(page.screenshot("#view-canvas")) - first).mean() < 1.0

        page.click('input.group-toggle[data-group="healed"]')           # hide a group
        page.settle()
        hidden = _pixels(page.screenshot("#view-canvas"))
        assert _shaded(hidden, HEALED).sum() < 0.02 * green
        assert page.errors == []


def test_without_webgl_the_page_says_so_and_shows_the_tables(report):
    chromium_path()
    with open_page(report, webgl=False, timeout=20) as page:
        assert page.wait_rendered() == "no-webgl"
        message = page.js("(function (m) { return {hidden: m.hidden, height: m.offsetHeight, "
                          "text: m.textContent}; })(document.getElementById('view-message'))")
        assert not message["hidden"] and message["height"] > 0
        assert "needs WebGL" in message["text"]
        assert page.js("document.getElementById('view-canvas').offsetHeight") == 0
        assert page.js("document.getElementById('legend').offsetHeight") == 0
        _check_dom_tables(page.js(_table_cells_js()))
        assert page.js("document.querySelectorAll('.summary li').length") == 2
        assert page.js("document.querySelector('figure img').naturalWidth") == 1
        assert page.errors == []
        assert all(url.startswith(("file:", "data:")) for url in page.requests), page.requests


def test_the_writer_does_not_load_opencascade():
    code = "import sys, surfprep.plugin.report_html; print('OCP' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_a_scene_of_empty_faces_is_written(tmp_path):
    empty = SceneMesh("no triangulation", np.empty((0, 3)), np.empty((0, 3), dtype=int), "untouched")
    path = write_html_report(tmp_path / "r.html", title="t", meshes=[empty])
    scene = _scene_json(path.read_text(encoding="utf-8"))
    assert scene["radius"] == 1.0 and scene["meshes"][0]["idx"] == ""
