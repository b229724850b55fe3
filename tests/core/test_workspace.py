"""Finger workspaces, finger pair boxes, workspace maps and effective workspaces (thesis 4.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.errors import ConfigError
from graspgait_env.objects import load_object
from graspgait_env.shapes import Circle, Ellipse
from graspgait_env.workspace import (
    DEFAULT_WORKSPACES_DEG,
    CircularReach,
    Hand,
    bundled_hands,
    effective_hand,
    effective_workspace,
    load_hand,
    workspace_map,
)

N = 180


# --------------------------------------------------------------------------- default hand


def test_default_hand_fig_4_1():
    h = Hand.default()
    assert h.workspaces_deg == ((0.0, 90.0), (120.0, 210.0), (240.0, 330.0))
    assert h.workspaces_deg == DEFAULT_WORKSPACES_DEG
    assert h.n_fingers == 3
    assert h.gaps_deg == (30.0, 30.0, 30.0)
    assert h.w_deg == 30.0
    assert Hand() == h


def test_finger_at():
    h = Hand.default()
    angles = [0.0, 45.0, 90.0, 90.5, 100.0, 119.9, 120.0, 165.0, 210.0, 225.0,
              240.0, 285.0, 330.0, 345.0, 359.9, 360.0, 405.0, -30.0, -120.0, 720.0 + 130.0]
    expect = [1, 1, 1, 0, 0, 0, 2, 2, 2, 0, 3, 3, 3, 0, 0, 1, 1, 3, 3, 2]
    got = h.finger_at(angles)
    assert got.tolist() == expect
    assert got.shape == (len(angles),)
    assert h.finger_at(np.array([[45.0, 165.0], [285.0, 100.0]])).tolist() == [[1, 2], [3, 0]]
    assert int(h.finger_at(45.0)) == 1


def test_finger_pair_boxes_and_kinds():
    """Docstring of workspace.py: kind by the box's diagonal offset d = (c_y - c_x) mod 360
    of the box centres (45°, 165°, 285°): inner when d < 180°, else outer."""
    h = Hand.default()
    boxes = h.finger_pair_boxes
    assert len(boxes) == 6
    assert {b.index for b in boxes} == {(1, 2), (1, 3), (2, 1), (2, 3), (3, 1), (3, 2)}
    kinds = {b.index: b.kind for b in boxes}
    assert kinds == {(1, 2): "inner", (2, 3): "inner", (3, 1): "inner",
                     (1, 3): "outer", (2, 1): "outer", (3, 2): "outer"}
    assert h.box_kind(1, 3) == "outer"   # fig. 4.4: top-left box, fingers 1 and 3
    assert h.box_kind(1, 2) == "inner"
    assert h.box_kind(2, 1) == "outer"   # mirror image, offset 240° in the extended band
    b13 = next(b for b in boxes if b.index == (1, 3))
    assert (b13.x_deg, b13.y_deg) == ((0.0, 90.0), (240.0, 330.0))
    with pytest.raises(ValueError):
        h.box_kind(1, 1)
    with pytest.raises(ValueError):
        h.box_kind(1, 4)


def test_to_dict():
    assert Hand.default().to_dict() == {
        "name": "thesis", "workspaces_deg": [[0.0, 90.0], [120.0, 210.0], [240.0, 330.0]]}


def test_wrapping_workspace_gaps_and_finger_at():
    h = Hand(((300.0, 400.0), (60.0, 150.0), (170.0, 280.0)), "wrap")
    assert sorted(h.gaps_deg) == [20.0, 20.0, 20.0]
    assert h.finger_at([320.0, 0.0, 39.0, 40.0, 41.0, 59.0, 100.0, 200.0]).tolist() == \
        [1, 1, 1, 1, 0, 0, 2, 3]


# --------------------------------------------------------------------------- validation


BAD_WORKSPACES = {
    "overlapping": [[0, 100], [90, 200], [240, 330]],
    "touching": [[0, 90], [90, 200], [240, 330]],
    "overlap through 0": [[300, 400], [20, 100], [150, 250]],
    "empty arc": [[0, 0], [120, 210], [240, 330]],
    "hi below lo": [[90, 0], [120, 210], [240, 330]],
    "full turn": [[0, 360], [120, 210]],
    "lo negative": [[-10, 80], [120, 210], [240, 330]],
    "lo 360": [[360, 400], [120, 210], [240, 330]],
    "nan": [[0, float("nan")], [120, 210], [240, 330]],
    "inf": [[0, 90], [120, float("inf")], [240, 330]],
    "string": [[0, "90"], [120, 210], [240, 330]],
    "bool": [[0, 90], [True, 210], [240, 330]],
    "None": [[0, 90], [120, 210], None],
    "three numbers": [[0, 45, 90], [120, 210], [240, 330]],
    "one finger": [[0, 90]],
    "empty list": [],
    "not a list": 90,
}


@pytest.mark.parametrize("case", sorted(BAD_WORKSPACES))
def test_bad_workspaces_refused(case):
    with pytest.raises(ConfigError) as ei:
        Hand(tuple(BAD_WORKSPACES[case]) if isinstance(BAD_WORKSPACES[case], list)
             else BAD_WORKSPACES[case], "bad")
    assert ei.value.field.startswith("workspaces_deg")
    assert "workspaces_deg" in str(ei.value)
    assert "\n" not in str(ei.value)


# --------------------------------------------------------------------------- workspace map


def test_workspace_map_fig_4_4():
    h = Hand.default()
    wm = workspace_map(h, N)
    boxes = h.finger_pair_boxes
    assert wm.shape == (N, N)

    def box(x_deg, y_deg):
        k = int(wm[int(x_deg / 2), int(y_deg / 2)])
        return None if k < 0 else boxes[k].index

    # thesis 4.2: the grasp (270°, 50°) lies in the box of (x finger 3, y finger 1)
    assert box(270, 50) == (3, 1)
    # after the 40° rotation it ends at (310°, 90°), still in that box (on its edge)
    assert box(310, 90) == (3, 1)
    assert box(312, 92) is None
    assert box(50, 270) == (1, 3)          # fig. 4.4 top-left box: fingers 1 and 3
    assert box(10, 130) == (1, 2)
    assert box(150, 300) == (2, 3)
    assert box(0, 0) is None and box(45, 60) is None  # same finger: not a grasp
    assert box(100, 200) is None and box(200, 336) is None  # one contact in a gap
    # by hand: valid cells are pairs of grid angles in two different workspaces
    phi = 2.0 * np.arange(N)
    f = h.finger_at(phi)
    valid = (f[:, None] > 0) & (f[None, :] > 0) & (f[:, None] != f[None, :])
    np.testing.assert_array_equal(wm >= 0, valid)
    # each workspace holds 46 grid angles (both edges included): 6 boxes of 46 x 46
    assert (wm >= 0).sum() == 6 * 46 * 46
    for k in range(6):
        assert (wm == k).sum() == 46 * 46
    # symmetric about y = x with the finger pair swapped
    for k, b in enumerate(boxes):
        k_swapped = next(m for m, c in enumerate(boxes) if c.index == b.index[::-1])
        np.testing.assert_array_equal(wm == k, (wm == k_swapped).T)


@pytest.mark.parametrize("steps", [1, 5, 20, -3, 90])
def test_theta_slides_the_map_along_the_diagonal(steps):
    h = Hand.default()
    w0 = workspace_map(h, N, 0.0)
    wt = workspace_map(h, N, 2.0 * steps)
    np.testing.assert_array_equal(wt, np.roll(w0, -steps, axis=(0, 1)))
    # a full turn is the identity
    np.testing.assert_array_equal(workspace_map(h, N, 360.0), w0)


# --------------------------------------------------------------------------- effective workspaces


def test_effective_workspace_by_hand():
    """Finger disc of radius R centred at b, |b| = D, at polar angle psi. The circle of
    radius r about the origin meets the disc's rim where, by the law of cosines,
    R² = r² + D² - 2 r D cos(phi - psi), so |phi - psi| <= acos((r² + D² - R²) / (2 r D)).

    Case: b = (0, 0.1) (psi = 90°), R = D = 0.1: cos = r / (2 D). r = 0.05: acos(0.25) =
    75.52°; r = 0.08: acos(0.4) = 66.42°. The conservative (narrower) half-width is 66.42°,
    so the effective workspace is [90 - 66.42, 90 + 66.42] = [23.578°, 156.422°].
    """
    lo, hi = effective_workspace(CircularReach((0.0, 0.1), 0.1), 0.05, 0.08)
    half = math.degrees(math.acos(0.08 / 0.2))
    np.testing.assert_allclose([lo, hi], [90 - half, 90 + half], rtol=1e-12)
    np.testing.assert_allclose([lo, hi], [23.57817847820, 156.42182152180], rtol=1e-11)
    # the ends at the large radius lie exactly on the reach circle
    for a in (lo, hi):
        pt = 0.08 * np.array([math.cos(math.radians(a)), math.sin(math.radians(a))])
        np.testing.assert_allclose(np.hypot(*(pt - [0.0, 0.1])), 0.1, rtol=1e-12)


def test_effective_workspace_origin_outside_disc_and_wrapping():
    """b = (0.1, 0), R = 0.08, radii 0.05..0.07:
    r = 0.05: (0.0025 + 0.01 - 0.0064) / 0.01 = 0.61 -> 52.41°;
    r = 0.07: (0.0049 + 0.01 - 0.0064) / 0.014 = 0.6071 -> 52.62°; narrower: 52.41°.
    The arc straddles 0°: reported as [307.59°, 412.41°] (lo in [0, 360), hi past 360)."""
    lo, hi = effective_workspace(CircularReach((0.1, 0.0), 0.08), 0.05, 0.07)
    half = math.degrees(math.acos(0.61))
    np.testing.assert_allclose([lo, hi], [360 - half, 360 + half], rtol=1e-12)


def test_effective_workspace_refusals():
    with pytest.raises(ValueError, match="out of reach"):
        effective_workspace(CircularReach((0.3, 0.0), 0.05), 0.05, 0.08)
    with pytest.raises(ValueError, match="origin"):
        effective_workspace(CircularReach((0.0, 0.0), 0.05), 0.05, 0.08)
    with pytest.raises(ValueError, match="all round"):
        effective_workspace(CircularReach((0.01, 0.0), 0.5), 0.05, 0.08)


def test_effective_hand_uses_r_min_and_r_max():
    """Two fingers, discs of R = 0.1 centred 0.1 m from the origin at 90° and 270° (D = R:
    cos = r / (2 D)). Ellipse radii 0.05..0.08: r_lo gives acos(0.25) = 75.5°, r_hi gives
    acos(0.4) = 66.4°, the narrower; a reach cap of 0.06 m replaces r_max: acos(0.3)."""
    fingers = [CircularReach((0.0, 0.1), 0.1), CircularReach((0.0, -0.1), 0.1)]
    e = Ellipse(0.08, 0.05)
    h = effective_hand(fingers, e)
    half = math.degrees(math.acos(0.4))
    for (lo, hi), c in zip(h.workspaces_deg, (90.0, 270.0), strict=True):
        np.testing.assert_allclose([lo, hi], [c - half, c + half], rtol=1e-12)
    h2 = effective_hand(fingers, e, max_radius=0.06)
    half2 = math.degrees(math.acos(0.3))
    np.testing.assert_allclose(h2.workspaces_deg[0], [90 - half2, 90 + half2], rtol=1e-12)
    np.testing.assert_allclose(h2.w_deg, 180 - 2 * half2, rtol=1e-12)


# --------------------------------------------------------------------------- hand files


def test_bundled_hands():
    assert {"thesis", "wide", "circular_reach"} <= set(bundled_hands())
    h, cap = load_hand("thesis")
    assert h.workspaces_deg == DEFAULT_WORKSPACES_DEG and cap is None
    assert h.name == "thesis"
    w, cap = load_hand("wide")
    assert w.workspaces_deg == ((0.0, 100.0), (120.0, 220.0), (240.0, 340.0))
    assert w.w_deg == 20.0 and cap is None
    d, cap = load_hand(None)
    assert d == Hand.default() and cap is None
    assert load_hand(h) == (h, None)


def test_bundled_circular_reach_hand():
    shape = Circle(0.0762)
    h, cap = load_hand("circular_reach", shape=shape)
    assert cap is None and h.n_fingers == 3
    # finger 1: base (0.0849, 0.0849), D = 0.12007, psi = 45°, R = 0.09; r_lo = r_hi = 0.0762
    D = math.hypot(0.0849, 0.0849)
    half = math.degrees(math.acos((0.0762**2 + D**2 - 0.09**2) / (2 * 0.0762 * D)))
    lo, hi = h.workspaces_deg[0]
    np.testing.assert_allclose([lo, hi], [360 + 45 - half, 360 + 45 + half], rtol=1e-12)
    for name in ("ellipse", "square", "star"):
        load_hand("circular_reach", shape=load_object(name))
    with pytest.raises(ConfigError) as ei:
        load_hand("circular_reach")
    assert ei.value.field == "reach"


def test_reach_hand_with_max_radius(tmp_path):
    p = tmp_path / "h.yaml"
    p.write_text("name: r\nreach:\n  - {base: [0.0, 0.1], reach: 0.1}\n"
                 "  - {base: [0.0, -0.1], reach: 0.1}\nmax_radius: 0.06\n")
    h, cap = load_hand(p, shape=Ellipse(0.08, 0.05))
    assert cap == 0.06
    np.testing.assert_allclose(h.workspaces_deg[0],
                               [90 - math.degrees(math.acos(0.3)),
                                90 + math.degrees(math.acos(0.3))], rtol=1e-12)


OK_ARCS = "[[0, 90], [120, 210], [240, 330]]"
BAD_HANDS = {
    "unknown key": (f"workspaces_deg: {OK_ARCS}\ncolour: red\n", "colour"),
    "both arcs and reach": (f"workspaces_deg: {OK_ARCS}\nreach: []\n", "workspaces_deg"),
    "neither": ("name: x\n", "workspaces_deg"),
    "overlapping arcs": ("workspaces_deg: [[0, 130], [120, 210], [240, 330]]\n",
                         "workspaces_deg"),
    "non-numeric arc": ("workspaces_deg: [[0, ninety], [120, 210], [240, 330]]\n",
                        "workspaces_deg"),
    "reach entry not a mapping": ("reach: [0.1, 0.2]\n", "reach[0]"),
    "reach entry missing key": ("reach: [{base: [0.1, 0.0]}]\n", "reach[0]"),
    "reach base wrong": ("reach: [{base: [0.1], reach: 0.1}]\n", "reach[0].base"),
    "reach base string": ("reach: [{base: [a, 0.1], reach: 0.1}]\n", "reach[0].base"),
    "reach radius negative": ("reach: [{base: [0.1, 0.0], reach: -0.1}]\n",
                              "reach[0].reach"),
    "reach not a list": ("reach: 0.1\n", "reach[0]"),
    "max_radius negative": ("reach: [{base: [0.1, 0.0], reach: 0.1}]\nmax_radius: -1\n",
                            "max_radius"),
    "effective workspaces overlap": ("reach: [{base: [0.0, 0.1], reach: 0.1}, "
                                     "{base: [-0.0866, -0.05], reach: 0.1}, "
                                     "{base: [0.0866, -0.05], reach: 0.1}]\n", "reach"),
    "object out of reach": ("reach: [{base: [0.5, 0.0], reach: 0.1}, "
                            "{base: [-0.5, 0.0], reach: 0.1}]\n", "reach"),
}


@pytest.mark.parametrize("case", sorted(BAD_HANDS))
def test_malformed_hand_yaml_refused(tmp_path, case):
    text, field = BAD_HANDS[case]
    p = tmp_path / "hand.yaml"
    p.write_text(text)
    with pytest.raises(ConfigError) as ei:
        load_hand(p, shape=Circle(0.05))
    assert ei.value.field.startswith(field)
    assert f"field '{field}" in str(ei.value)
    assert "\n" not in str(ei.value)
    assert str(ei.value).count("fix:") == 1


@pytest.mark.parametrize("text,word", [("", "empty"), ("- a\n- b\n", "mapping"),
                                       ("workspaces_deg: [[0, 90]\n", "YAML")])
def test_malformed_hand_file_refused(tmp_path, text, word):
    p = tmp_path / "hand.yaml"
    p.write_text(text)
    with pytest.raises(ConfigError, match=word):
        load_hand(p)


def test_missing_hand_refused(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_hand(tmp_path / "absent.yaml")
    with pytest.raises(ConfigError) as ei:
        load_hand("no_such_hand_xyz")
    assert ei.value.field == "hand"


def test_docstring_examples():
    import doctest
    import importlib

    mod = importlib.import_module("graspgait_env.workspace")
    assert doctest.testmod(mod).failed == 0
