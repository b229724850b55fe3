"""Object files (docs/formats.md): bundled objects load; malformed ones are refused
with a one-line ConfigError that names the offending field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.errors import ConfigError
from graspgait_env.objects import (
    OBJECT_DEFAULTS,
    bundled_objects,
    load_object,
    load_object_physical,
    object_from_dict,
)
from graspgait_env.shapes import Circle, Ellipse, Polygon, Shape, Stadium

EXPECTED_BUNDLED = {
    "circle": Circle, "ellipse": Ellipse, "long_ellipse": Ellipse, "stadium": Stadium,
    "hexagon": Polygon, "pentagon": Polygon, "regular_hexagon": Polygon, "square": Polygon,
    "star": Polygon, "triangle": Polygon,
}


def test_bundled_list():
    assert set(EXPECTED_BUNDLED) <= set(bundled_objects())


@pytest.mark.parametrize("name", bundled_objects())
def test_every_bundled_object_loads(name):
    shape, phys = load_object_physical(name)
    assert isinstance(shape, Shape)
    assert shape.name == name
    if name in EXPECTED_BUNDLED:
        assert type(shape) is EXPECTED_BUNDLED[name]
    assert phys["thickness"] > 0 and phys["mass"] > 0 and isinstance(phys["description"], str)
    assert 1.0 <= shape.eccentricity < 10
    # by path too, and a Shape passes through unchanged
    from graspgait_env.objects import OBJECT_DIR

    again = load_object(OBJECT_DIR / f"{name}.yaml")
    np.testing.assert_array_equal(again.radius(np.arange(0, 360, 7.0)),
                                  shape.radius(np.arange(0, 360, 7.0)))
    assert load_object(shape) is shape


def test_bundled_values():
    c = load_object("circle")
    assert c.a == c.b == 0.0762
    e = load_object("ellipse")
    assert (e.a, e.b) == (0.1143, 0.0635)
    np.testing.assert_allclose(load_object("long_ellipse").eccentricity, 3.0)
    sq = load_object("square")
    np.testing.assert_allclose(sq.r_min, 0.06)
    assert sq.smoothness == 4
    assert load_object("star").smoothness == 10
    assert load_object("pentagon").smoothness == 5
    st = load_object("stadium")
    assert (st.half_length, st.rad) == (0.05, 0.04)


def test_physical_defaults_and_values(tmp_path):
    p = tmp_path / "o.yaml"
    p.write_text("name: o\ntype: circle\nradius: 0.05\n")
    _, phys = load_object_physical(p)
    assert phys == OBJECT_DEFAULTS
    p.write_text("name: o\ntype: circle\nradius: 0.05\nthickness: 0.03\nmass: 2\n"
                 "description: hi\n")
    _, phys = load_object_physical(p)
    assert phys == {"thickness": 0.03, "mass": 2.0, "description": "hi"}


def test_object_from_dict_and_winding():
    sq = [[0.05, 0.05], [-0.05, 0.05], [-0.05, -0.05], [0.05, -0.05]]
    a, _ = object_from_dict({"name": "a", "type": "polygon", "vertices": sq})
    b, _ = object_from_dict({"name": "b", "type": "polygon", "vertices": sq[::-1]})
    phi = np.arange(1.0, 360.0, 3.0)
    np.testing.assert_array_equal(a.radius(phi), b.radius(phi))


def test_unknown_bundled_name():
    with pytest.raises(ConfigError) as ei:
        load_object("no_such_object_xyz")
    assert ei.value.field == "object"
    assert "circle" in str(ei.value)  # lists the bundled names as the fix


# --------------------------------------------------------------------------- malformed files

SQ = "[[0.05, 0.05], [-0.05, 0.05], [-0.05, -0.05], [0.05, -0.05]]"
PENTAGRAM = [[round(0.1 * math.cos(math.radians(90 + 144 * k)), 6),
              round(0.1 * math.sin(math.radians(90 + 144 * k)), 6)] for k in range(5)]
HUGE_INT = "1" + "0" * 400  # a YAML integer too large for a float

# id -> (file text, field the message must name)
MALFORMED = {
    "not star-shaped (origin outside)":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.1], [0.2, 0.1], [0.2, 0.2], [0.1, 0.2]]\n",
         "vertices"),
    "not star-shaped (origin outside the kernel)":
        ("name: x\ntype: polygon\nvertices: [[0.1, -0.1], [0.1, 0.1], [-0.1, 0.1], [-0.1, 0.05],"
         " [0.05, 0.05], [0.05, 0.02], [-0.1, 0.02], [-0.1, -0.1]]\n", "vertices"),
    "self-intersecting (pentagram order)":
        (f"name: x\ntype: polygon\nvertices: {PENTAGRAM}\n", "vertices"),
    "fewer than 3 distinct vertices":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], [0.0, 0.1], [0.1, 0.0]]\n", "vertices"),
    "only two vertices":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], [0.0, 0.1]]\n", "vertices"),
    "duplicate vertices only":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.1], [0.1, 0.1], [0.1, 0.1], [0.1, 0.1]]\n",
         "vertices"),
    "zero area (collinear)":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], [0.2, 0.0], [0.3, 0.0]]\n", "vertices"),
    "vertex on the origin":
        ("name: x\ntype: polygon\nvertices: [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]]\n", "vertices"),
    "NaN coordinate":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], [0.0, .nan], [-0.1, -0.1]]\n",
         "vertices[1]"),
    "inf coordinate":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], [0.0, 0.1], [-.inf, -0.1]]\n",
         "vertices[2]"),
    "bool coordinate":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], [true, 0.1], [-0.1, -0.1]]\n",
         "vertices[1]"),
    "string coordinate":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], ['0', 0.1], [-0.1, -0.1]]\n",
         "vertices[1]"),
    "vertex with 3 coords":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0, 0.0], [0.0, 0.1], [-0.1, -0.1]]\n",
         "vertices[0]"),
    "vertex not a pair":
        ("name: x\ntype: polygon\nvertices: [[0.1, 0.0], 0.1, [-0.1, -0.1]]\n", "vertices[1]"),
    "vertices not a list":
        ("name: x\ntype: polygon\nvertices: 0.1\n", "vertices"),
    "vertices a mapping":
        ("name: x\ntype: polygon\nvertices: {x: 0.1, y: 0.2}\n", "vertices"),
    "missing vertices":
        ("name: x\ntype: polygon\n", "vertices"),
    "negative radius":
        ("name: x\ntype: circle\nradius: -0.05\n", "radius"),
    "zero radius":
        ("name: x\ntype: circle\nradius: 0\n", "radius"),
    "NaN radius":
        ("name: x\ntype: circle\nradius: .nan\n", "radius"),
    "inf radius":
        ("name: x\ntype: circle\nradius: .inf\n", "radius"),
    "huge integer radius":
        (f"name: x\ntype: circle\nradius: {HUGE_INT}\n", "radius"),
    "string where number expected":
        ("name: x\ntype: circle\nradius: '0.05'\n", "radius"),
    "bool where number expected":
        ("name: x\ntype: circle\nradius: true\n", "radius"),
    "null where number expected":
        ("name: x\ntype: circle\nradius: null\n", "radius"),
    "unknown key":
        ("name: x\ntype: circle\nradius: 0.05\ncolour: red\n", "colour"),
    "key of another type":
        (f"name: x\ntype: polygon\nvertices: {SQ}\nradius: 0.05\n", "radius"),
    "missing type":
        ("name: x\nradius: 0.05\n", "type"),
    "unknown type":
        ("name: x\ntype: blob\nradius: 0.05\n", "type"),
    "type not a string (list)":
        ("name: x\ntype: [polygon]\nvertices: []\n", "type"),
    "missing name":
        ("type: circle\nradius: 0.05\n", "name"),
    "empty name":
        ("name: ''\ntype: circle\nradius: 0.05\n", "name"),
    "name not a string":
        ("name: [a, b]\ntype: circle\nradius: 0.05\n", "name"),
    "ellipse with negative b":
        ("name: x\ntype: ellipse\na: 0.09\nb: -0.06\n", "b"),
    "ellipse a is a string":
        ("name: x\ntype: ellipse\na: big\nb: 0.06\n", "a"),
    "ellipse missing b":
        ("name: x\ntype: ellipse\na: 0.09\n", "b"),
    "stadium missing half_length":
        ("name: x\ntype: stadium\nradius: 0.04\n", "half_length"),
    "stadium zero half_length":
        ("name: x\ntype: stadium\nhalf_length: 0.0\nradius: 0.04\n", "half_length"),
    "thickness negative":
        ("name: x\ntype: circle\nradius: 0.05\nthickness: -0.01\n", "thickness"),
    "mass zero":
        ("name: x\ntype: circle\nradius: 0.05\nmass: 0\n", "mass"),
    "description not a string":
        ("name: x\ntype: circle\nradius: 0.05\ndescription: 5\n", "description"),
}


def _load(tmp_path, text):
    p = tmp_path / "obj.yaml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as ei:
        load_object(p)
    return p, ei.value


def test_enough_malformed_cases():
    assert len(MALFORMED) >= 25


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_object_refused_naming_field(tmp_path, case):
    text, field = MALFORMED[case]
    p, err = _load(tmp_path, text)
    msg = str(err)
    assert err.field == field
    assert f"field '{field}'" in msg
    assert str(p) in msg
    assert "\n" not in msg
    assert msg.count("fix:") == 1


# whole-file problems: no field; the message names the file and the problem
FILE_LEVEL = {
    "unreadable YAML syntax": ("name: x\ntype: [circle\nradius: 0.05\n", "YAML"),
    "empty file": ("", "empty"),
    "whitespace only": ("   \n\n", "empty"),
    "a YAML list, not a mapping": ("- name: x\n- type: circle\n", "mapping"),
    "a YAML scalar, not a mapping": ("just some text\n", "mapping"),
}


@pytest.mark.parametrize("case", sorted(FILE_LEVEL))
def test_malformed_file_refused(tmp_path, case):
    text, word = FILE_LEVEL[case]
    p, err = _load(tmp_path, text)
    msg = str(err)
    assert err.field == ""
    assert word in msg
    assert str(p) in msg
    assert "\n" not in msg


def test_yaml_syntax_error_gives_line(tmp_path):
    _, err = _load(tmp_path, "name: x\ntype: circle\nradius: [0.05\n")
    assert "line" in str(err)


def test_missing_file_refused(tmp_path):
    p = tmp_path / "absent.yaml"
    with pytest.raises(ConfigError) as ei:
        load_object(p)
    assert "not found" in str(ei.value) and str(p) in str(ei.value)
    assert "\n" not in str(ei.value)


def test_non_utf8_file_refused(tmp_path):
    p = tmp_path / "bin.yaml"
    p.write_bytes(b"name: \xff\xfe\ntype: circle\nradius: 0.05\n")
    with pytest.raises(ConfigError):
        load_object(p)


def test_object_from_dict_refuses_non_mapping():
    with pytest.raises(ConfigError):
        object_from_dict([("name", "x")])  # type: ignore[arg-type]


def test_config_error_is_value_error():
    with pytest.raises(ValueError):
        object_from_dict({"name": "x", "type": "circle", "radius": -1})


def test_a_folder_of_an_objects_name_does_not_hide_the_bundled_object(tmp_path, monkeypatch):
    """`graspgait story circle --out circle` then `graspgait simulate circle/...json`: the
    plan's object "circle" is the bundled one, not the folder beside it."""
    (tmp_path / "circle").mkdir()
    monkeypatch.chdir(tmp_path)
    assert load_object("circle").name == "circle"
