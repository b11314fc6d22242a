"""The HTML report of surfprep.prepare and of the demo: the faces by status, the
curves and the grid in the scene, the tables holding the JSON report's figures, and
the page drawing in a real browser."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from helpers.browser import open_page
from helpers.cli import run
from helpers.paths import SAMPLES

from surfprep.plugin.prepare import prepare
from surfprep.plugin.prepare_report import scene_of, tables_of, write_prepare_report

FUSELAGE = SAMPLES / "occt_fuselage.stp"


@pytest.fixture(scope="module")
def fuselage():
    return prepare(FUSELAGE, intersect=False, grid=True, grid_options={"dims": (9, 11)})


def test_the_scene_holds_every_face_and_block(fuselage):
    meshes, polylines, grids = scene_of(fuselage)
    assert len(meshes) == 8 and {m.group for m in meshes} == {"reparametrized"}
    assert polylines == []                                 # intersect was not asked for
    assert [g.points.shape for g in grids] == [(9, 11, 3)] * 8
    for g in grids:
        assert g.cell_values.shape == (8, 10)
        assert np.all((g.cell_values >= 0) & (g.cell_values <= 1))
    # the triangles lie on the faces' box
    lo, hi = np.array(fuselage.model.bounding_box[:3]), np.array(fuselage.model.bounding_box[3:])
    pad = 1e-6 * fuselage.model.size
    for m in meshes:
        assert np.all(m.vertices >= lo - pad) and np.all(m.vertices <= hi + pad)


def test_the_tables_hold_the_reports_figures(fuselage, tmp_path):
    tables = {t.title: t for t in tables_of(fuselage)}
    stages = tables["Stages"].rows
    assert [r[:2] for r in stages] == [("heal", "done"), ("intersect", "skipped"),
                                       ("reparam", "done"), ("grid", "done")]
    assert [r[2] for r in stages] == [s.time_s for s in fuselage.stages]
    faces = fuselage.stage("reparam").report["faces"]
    rows = tables["Reparametrized faces"].rows
    assert [r[3] for r in rows] == [f["mismatch_after"] for f in faces]
    assert [r[4] for r in rows] == [f["max_deviation"] for f in faces]
    page = write_prepare_report(fuselage, tmp_path / "r.html").read_text()
    values = [float(v) for v in re.findall(r'data-value="([^"]+)"', page)]
    for f in faces:
        assert f["max_deviation"] in values and f["mismatch_after"] in values


def test_the_demo_report_draws_in_a_browser(capsys, tmp_path):
    """The newcomer's page: the demo's report opens in headless Chromium with no console
    error, draws the model with WebGL (a canvas that is not blank) and shows the stages."""
    from helpers.browser import chromium_path
    chromium_path()                                  # skips, saying why, without Chromium
    code, _, err = run(capsys, "demo", "-o", tmp_path)
    assert code == 0, err
    page_path = tmp_path / "occt_fuselage-report.html"
    report = json.loads((tmp_path / "occt_fuselage-report.json").read_text())
    assert report["outputs"]["html_report"] == str(page_path)
    with open_page(page_path) as page:
        assert page.wait_rendered() == "webgl"
        page.settle(300)
        assert page.errors == []
        png = page.screenshot("#view-canvas")
        text = page.js("document.body.innerText")
        stage_cells = page.js("Array.from(document.querySelectorAll('table')[0]"
                              ".querySelectorAll('tbody tr')).map(r => r.cells[1].innerText)")
    from io import BytesIO

    from PIL import Image
    pixels = np.asarray(Image.open(BytesIO(png)).convert("RGB")).reshape(-1, 3)
    assert len(np.unique(pixels, axis=0)) > 100       # shaded faces and grid lines, not blank
    assert stage_cells == [s["status"] for s in report["prepare"]["stages"]]
    assert "reparam: done" in text and "grid: done" in text


@pytest.mark.slow
def test_healed_faces_are_coloured_by_their_distance_from_the_input():
    """The Mars capsule: each healed face's vertices carry their distance from the input
    faces, within how far the healing moved the face; the others carry none.

    Found by this picture before gaps were closed in the geometry: the largest vertex
    distance was 0.022, twice the approximants' tolerance, on the faces' edges, whose 3D
    curves the sewing left up to 0.022 from the surfaces (edge tolerances up to 0.049).
    Now the six faces along those edges are moved onto common curves (edge tolerances
    4.1e-6) and the colours stay within the moves."""
    result = prepare(SAMPLES / "overture_marscapsule_proe.igs", intersect=False, reparam=False)
    meshes, _, _ = scene_of(result)
    healed = [m for m in meshes if m.group == "healed"]
    assert len(healed) == result.face_status.count("healed") > 0
    moved = result.stage("heal").report["closed_gaps"]["faces_moved"]
    farthest = max([m["moved"] for m in moved]
                   + [p["deviation_from_input"] for p in result.stage("heal").report["patches"]])
    for m in healed:
        assert m.values is not None and m.values.shape == (m.vertices.shape[0],)
        assert np.nanmax(m.values) <= 1.05 * farthest + 1e-5
    assert all(m.values is None for m in meshes if m.group != "healed")
