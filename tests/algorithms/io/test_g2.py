"""GoTools ``.g2`` files: exact round trips of curves, surfaces and volumes, and files in the
layouts other programs write read correctly."""

from __future__ import annotations

import os

import numpy as np
import pytest

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.algorithms.io import format_g2, read_g2, write_g2
from surfprep.algorithms.volume import NurbsVolume
from surfprep.algorithms.volume_builders import block, revolve, solid_sphere, solid_torus
from surfprep.errors import ConversionError, InputFileError

# --------------------------------------------------------- reference files
# Small files written by hand in the layouts other programs use: GoTools' documented
# layout (a trailing space after the header, one coefficient a line), a sheet with two
# spaces between numbers and a trailing blank line, octants of a cube with blank lines
# between the entities, and a rational surface printed with 6 decimals and its
# coefficients pre-multiplied by the weights (GoTools' convention for rational splines).
GOTOOLS_CURVE = """100 1 0 0 
3 0
2 2
0 0 1 1
0 0 0
1 0 0
"""
GOTOOLS_SURFACE = """200 1 0 0 
3 0
2 2
0 0 1 1
2 2
0 0 1 1
0 0 0
1 0 0
0 1 0
1 1 0
"""
GOTOOLS_VOLUME = """700 1 0 0 
3 0
2 2
0 0 1 1
2 2
0 0 1 1
2 2
0 0 1 1
0 0 0
1 0 0
0 1 0
1 1 1
0 0 1
1 0 1
0 1 1
1 1 1
"""
GOTOOLS_SPHERE = """270 1 0 0
3
1.5
1.5 0 0
0 0 1
1 0 0
0 6.283185307179586
-1.5707963267948966 1.5707963267948966
0
"""
SPACED_SHEET = """200 1 0 0
3 0
3 2
0 0 1 2 2
2 2
0 0 1 1
-1  0 0
 0  0 0
 0 -1 0
-1  1 0
 1  1 0
 1 -1 0

"""


def _six_decimals(surface) -> str:
    """A rational surface as a program printing 6 decimals writes it: coefficients
    pre-multiplied by their weights, u running fastest."""
    lines = ["200 1 0 0", "3 1"]
    for n, degree, knots in ((surface.n_control[0], surface.degree_u, surface.knots_u),
                             (surface.n_control[1], surface.degree_v, surface.knots_v)):
        lines += [f"{n} {degree + 1}", " ".join(f"{k:.6f}" for k in knots)]
    for j in range(surface.n_control[1]):
        for i in range(surface.n_control[0]):
            w = surface.weights[i, j]
            x, y, z = surface.control_points[i, j] * w
            lines.append(f"{x:.6f} {y:.6f} {z:.6f} {w:.6f}")
    return "\n".join(lines) + "\n"


def _unit_sphere():
    from helpers.surfaces import sphere_patch
    return sphere_patch(1.0)


SIX_DECIMALS_SPHERE = _six_decimals(_unit_sphere())
CUBE_OCTANTS = """700 1 0 0
3 0
2 2
0 0 0.5 0.5
2 2
0 0 0.5 0.5
2 2
0 0 0.5 0.5
0 0 0
0.5 0 0
0 0.5 0
0.5 0.5 0
0 0 0.5
0.5 0 0.5
0 0.5 0.5
0.5 0.5 0.5


700 1 0 0
3 0
2 2
0 0 0.5 0.5
2 2
0 0 0.5 0.5
2 2
0 0 0.5 0.5
0.5 0 0
1 0 0
0.5 0.5 0
1 0.5 0
0.5 0 0.5
1 0 0.5
0.5 0.5 0.5
1 0.5 0.5


"""


def random_objects(rational: bool):
    """A 2D unclamped curve, a surface and a volume with interior knots, random values."""
    rng = np.random.default_rng(7 if rational else 8)

    def weights(shape):
        return rng.uniform(0.3, 3.0, shape) if rational else None

    curve = NurbsCurve(rng.uniform(-5, 5, (6, 2)), [-0.7, -0.3, 0.0, 0.1, 0.45, 0.45, 1.0, 1.3, 2.0],
                       2, weights(6))
    surface = NurbsSurface(rng.uniform(-5, 5, (5, 4, 3)), [0.1] * 4 + [0.35] + [2.0] * 4,
                           [-1, -1, 0.25, 0.5, 3, 3], 3, 1, weights((5, 4)))
    volume = NurbsVolume(rng.uniform(-5, 5, (4, 3, 5, 3)), [0, 0, 0, 1 / 3, 1, 1, 1],
                         [0, 0, 0, 1, 1, 1], [2, 2, 2.5, 2.5, 3.1, 4, 4], 2, 2, 1, weights((4, 3, 5)))
    return [curve, surface, volume]


def assert_same(a, b, exact: bool):
    assert type(a) is type(b)
    names = {NurbsCurve: ("knots", "degree"), NurbsSurface: ("knots_u", "knots_v", "degree_u", "degree_v"),
             NurbsVolume: ("knots_u", "knots_v", "knots_w", "degree_u", "degree_v", "degree_w")}[type(a)]
    for name in names:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert (a.weights is None) == (b.weights is None)
    if a.weights is not None:
        np.testing.assert_array_equal(a.weights, b.weights)
    if exact:
        np.testing.assert_array_equal(a.control_points, b.control_points)
    else:      # stored as (x w) / w: within an ulp
        np.testing.assert_allclose(b.control_points, a.control_points, rtol=2.3e-16, atol=0)


# --------------------------------------------------------------- round trips
def test_round_trip_of_non_rational_objects_is_exact(tmp_path):
    objects = random_objects(rational=False)
    path = write_g2(tmp_path / "objects.g2", objects)
    again = read_g2(path)
    assert len(again) == 3
    for a, b in zip(objects, again):
        assert_same(a, b, exact=True)
    assert format_g2(again) == path.read_text()


def test_round_trip_of_rational_objects(tmp_path):
    objects = random_objects(rational=True) + [solid_sphere(2.0, (1.0, 0.1, -3.0)),
                                               solid_torus(3.0, 0.7, (0, 1, 0), (1, 1, 1))]
    again = read_g2(write_g2(tmp_path / "rational.g2", objects))
    for a, b in zip(objects, again):
        assert_same(a, b, exact=False)
        np.testing.assert_allclose(b.homogeneous_points(), a.homogeneous_points(), rtol=4.5e-16, atol=0)
    # weights equal to one stay rational (the flag is kept)
    cube = block(1.0)
    ones = NurbsVolume(cube.control_points, *cube.knots, *cube.degrees, np.ones(cube.n_control))
    (back,) = read_g2(format_g2(ones))
    assert back.weights is not None and not back.is_rational


def test_written_layout():
    """Header, ``n order`` and knot lines per direction, coefficients with u fastest,
    pre-multiplied by the weight."""
    surface = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[2, 0, 0], [2, 1, 0.5]]]),
                           [0, 0, 1, 1], [0, 0, 0.5, 0.5], 1, 1, np.array([[1, 2.0], [0.5, 1]]))
    assert format_g2(surface) == ("200 1 0 0\n3 1\n2 2\n0.0 0.0 1.0 1.0\n2 2\n0.0 0.0 0.5 0.5\n"
                                  "0.0 0.0 0.0 1.0\n1.0 0.0 0.0 0.5\n0.0 2.0 0.0 2.0\n2.0 1.0 0.5 1.0\n")
    volume = block((2.0, 1.0, 1.0))
    lines = format_g2([volume]).splitlines()
    assert lines[:8] == ["700 1 0 0", "3 0", "2 2", "0.0 0.0 1.0 1.0", "2 2", "0.0 0.0 1.0 1.0",
                         "2 2", "0.0 0.0 1.0 1.0"]
    assert lines[8:] == ["0.0 0.0 0.0", "2.0 0.0 0.0", "0.0 1.0 0.0", "2.0 1.0 0.0",
                         "0.0 0.0 1.0", "2.0 0.0 1.0", "0.0 1.0 1.0", "2.0 1.0 1.0"]


# --------------------------------------------------- other programs' files
def test_reads_gotools_layout():
    (curve,) = read_g2(GOTOOLS_CURVE)
    assert isinstance(curve, NurbsCurve) and curve.degree == 1 and curve.weights is None
    np.testing.assert_array_equal(curve.evaluate([0.0, 0.5, 1.0]), [[0, 0, 0], [0.5, 0, 0], [1, 0, 0]])
    (surface,) = read_g2(GOTOOLS_SURFACE)
    assert isinstance(surface, NurbsSurface)
    np.testing.assert_array_equal(surface.evaluate(0.25, 0.75), [0.25, 0.75, 0.0])
    np.testing.assert_array_equal(surface.control_points[1, 0], [1, 0, 0])     # u runs fastest
    (volume,) = read_g2(GOTOOLS_VOLUME)
    assert isinstance(volume, NurbsVolume) and volume.degrees == (1, 1, 1)
    np.testing.assert_array_equal(volume.control_points[1, 0, 0], [1, 0, 0])
    np.testing.assert_array_equal(volume.control_points[0, 1, 0], [0, 1, 0])
    np.testing.assert_array_equal(volume.control_points[0, 0, 1], [0, 0, 1])
    np.testing.assert_array_equal(volume.control_points[1, 1, 0], [1, 1, 1])   # a corner off the cube
    # the trilinear map through those corners: z at the centre is the mean of the corner z's
    np.testing.assert_array_equal(volume.evaluate(0.5, 0.5, 0.5), [0.5, 0.5, 0.625])


def test_reads_other_layouts():
    (lshape,) = read_g2(SPACED_SHEET)
    assert lshape.n_control == (3, 2) and lshape.degree_u == 1
    np.testing.assert_array_equal(lshape.control_points[:, 1], [[-1, 1, 0], [1, 1, 0], [1, -1, 0]])
    octants = read_g2(CUBE_OCTANTS)
    assert len(octants) == 2 and all(isinstance(o, NurbsVolume) for o in octants)
    x = np.random.default_rng(1).uniform(0, 0.5, (50, 3))
    np.testing.assert_allclose(octants[0].evaluate(*x.T), x, atol=1e-15)
    np.testing.assert_allclose(octants[1].evaluate(*x.T), x + [0.5, 0, 0], atol=1e-15)


def test_reads_a_rational_surface_with_premultiplied_coefficients(tmp_path):
    (sphere,) = read_g2(SIX_DECIMALS_SPHERE)
    original = _unit_sphere()
    assert sphere.n_control == original.n_control and sphere.weights is not None
    np.testing.assert_allclose(sphere.weights, original.weights, atol=1e-6)
    np.testing.assert_allclose(sphere.control_points, original.control_points, atol=3e-6)
    u0, u1, v0, v1 = sphere.domain
    grid = sphere.evaluate_grid(np.linspace(u0, u1, 40), np.linspace(v0, v1, 60))
    assert np.abs(np.linalg.norm(grid, axis=-1) - 1.0).max() < 3e-6          # 6 decimals in the file
    # read from a file too
    path = tmp_path / "sphere.g2"
    path.write_text(SIX_DECIMALS_SPHERE)
    (again,) = read_g2(path)
    np.testing.assert_array_equal(again.control_points, sphere.control_points)


def test_colour_header_and_wrapped_lines_are_read():
    # a rational quadratic in 2D: colour after the header, knots and a coefficient wrapped
    text = "100 1 0 4 255 0 0 255\n2 1\n3 3\n0 0 0\n1 1 1\n1 0 1\n2 2\n2\n0 1 1\n"
    (curve,) = read_g2(text)
    np.testing.assert_array_equal(curve.control_points, [[1, 0], [1, 1], [0, 1]])
    np.testing.assert_array_equal(curve.weights, [1, 2, 1])
    np.testing.assert_allclose(curve.evaluate(0.5), [5 / 6, 5 / 6], rtol=1e-15)
    assert read_g2("\n\n") == []


# --------------------------------------------------------------------- errors
@pytest.mark.parametrize("text, message", [
    (GOTOOLS_SPHERE, r"object 1 \(line 1\): class 270 \(Sphere\) is not supported"),
    (GOTOOLS_CURVE + "\n" + GOTOOLS_SPHERE, r"object 2 \(line 8\): class 270 \(Sphere\)"),
    (GOTOOLS_CURVE.replace("1 0 0 \n3 0", "2 0 0 \n3 0"), r"unknown g2 version 2.0"),
    (GOTOOLS_CURVE.replace("0 0 1 1\n", "0 0 x 1\n"), r"line 4: expected 4 numbers for the u knots"),
    (GOTOOLS_CURVE[:-6], "the file ends before the coefficients of object 1"),
    (GOTOOLS_CURVE.replace("3 0\n", "3 1\n"), (r"the file ends before the coefficients of object 1 "
                                                r"\(line 1\) \(needs 8 values, 6 left\)")),
    ("100 1 0 0\n3 1\n2 2\n0 0 1 1\n0 0 0 1\n1 0 0 -1\n", "weights must be > 0"),
    ("100 1 0 0\n3 0\n2 2\n1 0 1 1\n0 0 0\n1 0 0\n", "knots must be non-decreasing"),
    ("100 1 0 0\n3 0\n1 1\n0 1\n0 0 0\n", r"needs order >= 2 and n >= order coefficients"),
    ("100 1 0 7\n", "auxiliary header value must be 0 or 4, got 7"),
    ("100 1 0\n", r"the file ends before the header of object 1"),
])
def test_malformed_files_are_refused(text, message):
    with pytest.raises(InputFileError, match=message):
        read_g2(text)


def test_missing_file_and_bad_arguments(tmp_path):
    with pytest.raises(InputFileError, match="no such file"):
        read_g2(tmp_path / "missing.g2")
    with pytest.raises(InputFileError, match="is a folder"):
        read_g2(tmp_path)
    with pytest.raises(ConversionError, match="read_g2 takes a path or the file's text, got int"):
        read_g2(3)
    with pytest.raises(ConversionError, match="object 1 is a str"):
        write_g2(tmp_path / "x.g2", [block(1.0), "cube"])


def test_write_is_atomic(tmp_path):
    target = tmp_path / "out.g2"
    target.write_text("old")
    write_g2(target, revolve(NurbsSurface(np.array([[[1, 0, 0], [1, 0, 1]], [[2, 0, 0], [2, 0, 1.]]]),
                                          [0, 0, 1, 1], [0, 0, 1, 1], 1, 1), (0, 0, 0), (0, 0, 1), 2.0))
    assert target.read_text().startswith("700 1 0 0\n3 1\n")
    with pytest.raises(ConversionError):
        write_g2(target, [1.0])
    assert target.read_text().startswith("700 1 0 0\n")           # untouched by the failure
    assert sorted(os.listdir(tmp_path)) == ["out.g2"]               # no temporary left
    with pytest.raises(FileNotFoundError):
        write_g2(tmp_path / "no" / "such" / "folder.g2", block(1.0))
