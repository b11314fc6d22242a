"""The ``info`` report (plugin.describe): the model's box is the union of its faces'
boxes and its standalone edges', the same box OpenCascade gives the whole shape."""

from __future__ import annotations

from helpers.paths import SAMPLES
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.gp import gp_Pnt

from surfprep.plugin.describe import model_report
from surfprep.plugin.io import CadModel, bounding_box, read
from surfprep.plugin.occ.shapes import compound


def _box(report):
    return tuple(report["bounding_box"]["min"] + report["bounding_box"]["max"])


def test_the_model_box_is_the_shapes_box():
    for name in ("occt_fuselage.stp", "overture_marscapsule_proe.igs", "synthetic_wing.step"):
        model = read(SAMPLES / name)
        report = model_report(model)
        assert _box(report) == model.bounding_box
        assert report["size"] == model.size


def test_a_standalone_edge_outside_the_faces_widens_the_box():
    model = read(SAMPLES / "synthetic_wing.step")
    *_, x1, y1, z1 = model.bounding_box
    far = BRepBuilderAPI_MakeEdge(gp_Pnt(x1, y1, z1), gp_Pnt(x1 + 5.0, y1, z1 + 7.0)).Edge()
    both = CadModel.from_shape(compound([*model.faces, far]))
    report = model_report(both)
    assert _box(report) == bounding_box(both.shape)
    assert _box(report)[3] >= x1 + 5.0 - 1e-9 and _box(report)[5] >= z1 + 7.0 - 1e-9
    assert len(report["edges"]) == 1
