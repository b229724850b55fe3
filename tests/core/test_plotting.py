"""Figures: every bundled object draws; the workspace boxes sit where thesis 4.4–4.5 puts them;
every figure reads without the thesis (axes in words, legends for cells, boxes and colours)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402  (only to check that no figure leaks into it)
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from graspgait_env import bundled_objects, grasp_map, load_object  # noqa: E402
from graspgait_env.plotting import (  # noqa: E402
    GAIT_COLORS,
    extended_box_rects,
    gait_figure,
    map_figure,
    plot_extended_map,
    plot_grasp_map,
    plot_object,
    save_figure,
    sweep_figure,
    sweep_objects,
)
from graspgait_env.workspace import Hand, load_hand  # noqa: E402

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
N = 36  # 10-degree grid: fast, enough to draw


def _box_rects(ax) -> dict[tuple[str, str], set[tuple[float, float, float, float]]]:
    """Rectangles drawn for finger pair boxes, by ("fx-fy", kind): {(x0, y0, w, h)}."""
    out: dict[tuple[str, str], set] = {}
    for p in ax.patches:
        gid = p.get_gid() or ""
        if isinstance(p, Rectangle) and gid.startswith("box "):
            _, pair, kind = gid.split()
            x, y = p.get_xy()
            out.setdefault((pair, kind), set()).add(
                (round(x, 9), round(y, 9), round(p.get_width(), 9), round(p.get_height(), 9)))
    return out


@pytest.mark.parametrize("name", bundled_objects())
def test_map_figure_builds_for_every_bundled_object(name, tmp_path):
    shape = load_object(name)
    hand, max_radius = load_hand("thesis", shape)
    fig = map_figure(shape, 0.7, N, hand, 30.0, max_radius=max_radius)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == 3
    assert shape.name in fig._suptitle.get_text()
    assert "mu=0.7" in fig._suptitle.get_text()
    out = save_figure(fig, tmp_path / "sub" / f"{name}.png")
    assert out.read_bytes()[:8] == PNG_MAGIC


def test_map_figure_with_reach_hand():
    shape = load_object("ellipse")
    hand, max_radius = load_hand("circular_reach", shape)
    fig = map_figure(shape, 0.5, N, hand, 0.0, max_radius=max_radius)
    assert len(fig.axes) == 3


def test_no_pyplot_figures_leak():
    before = plt.get_fignums()
    map_figure(load_object("pentagon"), 0.7, N)
    sweep_figure("smoothness", (0.5,), N)
    assert plt.get_fignums() == before


def test_grasp_map_image_axes():
    gm = grasp_map(load_object("hexagon"), 0.5, N)
    fig = Figure()
    ax = fig.add_subplot()
    assert plot_grasp_map(ax, gm) is fig
    (im,) = ax.get_images()
    # x = phi_i, y = phi_j: the image's row index is j, so the array shown is stable.T
    np.testing.assert_array_equal(np.asarray(im.get_array()), gm.stable.T)
    assert im.origin == "lower"
    h = 360.0 / N / 2
    np.testing.assert_allclose(im.get_extent(), [-h, 360 - h, -h, 360 - h])
    assert "phi_i (deg)" in ax.get_xlabel() and "phi_j (deg)" in ax.get_ylabel()
    assert ax.get_xlim() == (0.0, 360.0)


def test_object_with_grasp_marks_contacts():
    shape = load_object("pentagon")
    fig = Figure()
    ax = fig.add_subplot()
    plot_object(ax, shape, grasp=(50.0, 270.0), mu=0.7)
    assert len(ax.collections) == 1  # the quiver of inward normals
    # one arrow every 30 deg, none on the vertex at 90 deg (no normal there)
    assert len(ax.collections[0].U) == 11
    crosses = [ln for ln in ax.lines if ln.get_marker() == "x"]
    assert len(crosses) == 1
    np.testing.assert_allclose(np.c_[crosses[0].get_data()], shape.contour_point([50.0, 270.0]))


def test_extended_boxes_theta_0():
    """Fig. 4.4 tiled: at theta = 0 each box and its copies every 360 deg in each axis."""
    gm = grasp_map(load_object("circle"), 0.3, N)
    fig = Figure()
    ax = fig.add_subplot()
    plot_extended_map(ax, gm, Hand.default(), 0.0)
    rects = _box_rects(ax)
    # thesis fig. 4.4: box 1-3 (x = finger 1 on [0, 90], y = finger 3 on [240, 330]) is the
    # outer box at the top left; 1-2 is inner
    assert rects[("1-3", "outer")] == {(0, 240, 90, 90), (360, 240, 90, 90),
                                       (0, 600, 90, 90), (360, 600, 90, 90)}
    assert rects[("1-2", "inner")] == {(0, 120, 90, 90), (360, 120, 90, 90),
                                       (0, 480, 90, 90), (360, 480, 90, 90)}
    assert rects[("2-1", "outer")] == {(120, 0, 90, 90), (480, 0, 90, 90),
                                       (120, 360, 90, 90), (480, 360, 90, 90)}
    assert sum(len(v) for v in rects.values()) == 6 * 4
    assert {k for _, k in rects} == {"inner", "outer"}


def test_extended_boxes_theta_30():
    """Fig. 4.5 (b): seen from the object frame the boxes slide by -theta along the diagonal."""
    gm = grasp_map(load_object("circle"), 0.3, N)
    fig = Figure()
    ax = fig.add_subplot()
    hand = Hand.default()
    plot_extended_map(ax, gm, hand, 30.0)
    rects = _box_rects(ax)
    # box 1-3 moves from [0, 90] x [240, 330] to [-30, 60] x [210, 300]; the copy that
    # left across x = 0 reappears at x = 690 (its first 30 deg are visible)
    assert rects[("1-3", "outer")] == {
        (-30, 210, 90, 90), (330, 210, 90, 90), (690, 210, 90, 90),
        (-30, 570, 90, 90), (330, 570, 90, 90), (690, 570, 90, 90)}
    assert rects[("3-1", "inner")] == {
        (210, -30, 90, 90), (570, -30, 90, 90), (210, 330, 90, 90),
        (570, 330, 90, 90), (210, 690, 90, 90), (570, 690, 90, 90)}
    assert rects[("2-3", "inner")] == {(90, 210, 90, 90), (450, 210, 90, 90),
                                       (90, 570, 90, 90), (450, 570, 90, 90)}
    # brute force: every copy (any multiple of 360 in either axis) that meets (0, 720)^2
    expected = set()
    for b in hand.finger_pair_boxes:
        for a in range(-3, 4):
            for c in range(-3, 4):
                x0, y0 = b.x_deg[0] - 30 + 360 * a, b.y_deg[0] - 30 + 360 * c
                if -90 < x0 < 720 and -90 < y0 < 720:
                    expected.add((f"{b.finger_x}-{b.finger_y}", x0, y0))
    got = {(pair, x, y) for (pair, _), v in rects.items() for x, y, _, _ in v}
    assert got == expected


def test_box_shift_is_periodic():
    hand = Hand.default()
    a = sorted((b.index, x, y) for b, x, y in extended_box_rects(hand, 30.0))
    b = sorted((b.index, x, y) for b, x, y in extended_box_rects(hand, 390.0))
    c = sorted((b.index, x, y) for b, x, y in extended_box_rects(hand, -330.0))
    assert a == b == c


@pytest.mark.parametrize("kind", ["eccentricity", "smoothness"])
def test_sweep_figure(kind):
    mus = (0.9, 0.5, 0.1)
    fig = sweep_figure(kind, mus, N)
    rows = sweep_objects(kind)
    assert len(fig.axes) == len(rows) * (1 + len(mus))
    assert [ax.get_title() for ax in fig.axes[1:1 + len(mus)]] == ["mu=0.9", "mu=0.5", "mu=0.1"]


def test_sweep_objects():
    ecc = [s.eccentricity for _, s in sweep_objects("eccentricity")]
    np.testing.assert_allclose(ecc, [100, 3, 2, 1.5, 1])
    sm = [s.smoothness for _, s in sweep_objects("smoothness")]
    assert sm == [float("inf"), 8, 6, 5, 4, 3]
    with pytest.raises(ValueError, match="kind"):
        sweep_objects("roundness")


def test_save_figure_is_atomic(tmp_path):
    fig = Figure()
    fig.add_subplot().plot([0, 1])
    target = tmp_path / "a" / "b" / "fig.png"
    save_figure(fig, target)
    assert target.read_bytes()[:8] == PNG_MAGIC
    assert [p.name for p in target.parent.iterdir()] == ["fig.png"]  # no temp file left


# ------------------------------------------------------------- figures read without the thesis
# The first gait steps of `graspgait plan pentagon --mu 0.7 --planner optimal --start 50,270`
# (thesis fig. 4.6): rotate 40, finger 2 replaces finger 1, rotate 20, finger 1 replaces 3.
GAIT_STEPS = [
    {"op": "grasp", "contacts": {"1": 50.0, "3": 270.0}},
    {"op": "rotate", "delta": 40.0},
    {"op": "regrasp", "contacts": {"2": 92.0, "3": 270.0}},
    {"op": "rotate", "delta": 20.0},
    {"op": "regrasp", "contacts": {"1": 300.0, "2": 92.0}},
    {"op": "rotate", "delta": 58.0},
]


def _legend_texts(legend) -> list[str]:
    assert legend is not None, "the axes have no legend"
    return [t.get_text() for t in legend.get_texts()]


def _has(texts: list[str], *words: str) -> bool:
    """Some legend entry contains every one of ``words``."""
    return any(all(w in t for w in words) for t in texts)


def test_grasp_map_axes_in_words_and_dark_cells_explained():
    gm = grasp_map(load_object("ellipse"), 0.5, N)
    fig = Figure()
    ax = fig.add_subplot()
    plot_grasp_map(ax, gm)
    assert "contact of finger i" in ax.get_xlabel() and "object angle" in ax.get_xlabel()
    assert "contact of finger j" in ax.get_ylabel() and "object angle" in ax.get_ylabel()
    texts = _legend_texts(ax.get_legend())
    assert _has(texts, "dark", "force-closure", "mu=0.5")
    assert _has(texts, "white", "not force-closure")


def test_small_multiples_have_no_legend():
    fig = Figure()
    ax = fig.add_subplot()
    plot_grasp_map(ax, grasp_map(load_object("circle"), 0.5, N), labels=False)
    assert ax.get_legend() is None and ax.get_xlabel() == ""


def test_extended_map_names_and_explains_the_boxes():
    gm = grasp_map(load_object("circle"), 0.3, N)
    fig = Figure()
    ax = fig.add_subplot()
    plot_extended_map(ax, gm, Hand.default(), 30.0)
    legend = ax.get_legend()
    texts = _legend_texts(legend)
    assert _has(texts, "dark", "force-closure", "mu=0.3")
    assert _has(texts, "inner", "finger pair box") and _has(texts, "outer", "finger pair box")
    title = legend.get_title().get_text()
    assert "box a-b" in title and "fingers a (x) and b (y)" in title and "theta=30" in title
    # every finger pair is named on its boxes
    names = {t.get_text() for t in ax.texts}
    assert {"1-2", "1-3", "2-1", "2-3", "3-1", "3-2"} <= names
    assert "contact of finger i" in ax.get_xlabel() and "contact of finger j" in ax.get_ylabel()


def test_map_figure_every_panel_has_a_legend():
    fig = map_figure(load_object("pentagon"), 0.7, N, theta_deg=30.0)
    ax_o, ax_g, ax_e = fig.axes
    assert _has(_legend_texts(ax_o.get_legend()), "origin of f", "centre of rotation")
    assert _has(_legend_texts(ax_o.get_legend()), "inward normal")
    assert "object frame" in ax_o.get_xlabel()
    assert _has(_legend_texts(ax_g.get_legend()), "force-closure", "mu=0.7")
    assert "theta=30" in ax_e.get_legend().get_title().get_text()


def test_gait_figure_colours_explained():
    gm = grasp_map(load_object("pentagon"), 0.7, N)
    fig = gait_figure(gm, Hand.default(), GAIT_STEPS, title="t")
    ax_ws, ax_obj = fig.axes
    (legend,) = fig.legends
    texts = _legend_texts(legend)
    for words in (("rotation",), ("regrasp",), ("start",), ("end",),
                  ("grasp k", "finger a on x"), ("inner finger pair box", "fingers a (x)"),
                  ("outer finger pair box",), ("dark", "force-closure", "mu=0.7")):
        assert _has(texts, *words), (words, texts)
    # the legend's colours are the colours drawn, and rotations and regrasps differ
    by_label = dict(zip(texts, legend.legend_handles, strict=True))
    rot = next(h for t, h in by_label.items() if t.startswith("rotation"))
    reg = next(h for t, h in by_label.items() if t.startswith("regrasp"))
    assert rot.get_color() == GAIT_COLORS["rotate"] != GAIT_COLORS["regrasp"]
    assert reg.get_color() == GAIT_COLORS["regrasp"]
    for ax in (ax_ws, ax_obj):
        colors = {ln.get_color() for ln in ax.lines}
        assert {GAIT_COLORS["rotate"], GAIT_COLORS["regrasp"]} <= colors
        # grasps numbered in order with their fingers (x first): 0: 1-3, 1: 2-3, 2: 2-1
        notes = [t.get_text() for t in ax.texts if ":" in t.get_text()]
        assert notes == ["0: 1-3", "1: 2-3", "2: 2-1"]
    assert "workspace angle" in ax_ws.get_xlabel() and "finger on x" in ax_ws.get_xlabel()
    assert "object frame" in ax_obj.get_xlabel() and "finger on y" in ax_obj.get_ylabel()
    # in the workspace frame the first rotation is the diagonal (50, 270) -> (90, 310)
    rot_line = next(ln for ln in ax_ws.lines if ln.get_color() == GAIT_COLORS["rotate"])
    np.testing.assert_allclose(np.c_[rot_line.get_data()][:2], [[50, 270], [90, 310]])
    # and the finger pair boxes are named where they stand
    assert {"1-3", "2-3", "2-1"} <= {t.get_text() for t in ax_ws.texts}


def test_sweep_figure_explains_dark_cells():
    fig = sweep_figure("smoothness", (0.5,), N)
    (legend,) = fig.legends
    texts = _legend_texts(legend)
    assert _has(texts, "dark", "force-closure") and _has(texts, "S = number of sides")
    assert "phi_i" in fig.axes[-1].get_xlabel() and "finger i" in fig.axes[-1].get_xlabel()
