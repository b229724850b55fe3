"""Prototype regions and the necessary conditions for prototype gaits (thesis 6.2-6.3)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from graspgait_env.planners import prototypes as P
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.workspace import Hand
from tests.planners.helpers import GEOM, N, W, band_map, box_map, model, synthetic


# --------------------------------------------------------------------------- band prototype
def test_band_prototype_on_pure_band_map():
    S = band_map(60, 75)  # offsets 120..150 deg and the mirror 210..240 deg
    bands = P.band_prototypes(S)
    assert [(b.d_lo, b.d_hi) for b in bands] == [(60, 75), (105, 120)]
    b = P.largest_band(S)
    assert (b.d_lo, b.d_hi) == (60, 75)
    assert b.height_deg == 30.0 and b.offsets_deg == (120.0, 150.0)
    assert b.width_perp_deg == pytest.approx(30.0 / np.sqrt(2))
    assert b.mirror() == bands[1]
    assert b.contains(60) and b.contains(75) and not b.contains(76)


def test_band_prototype_degenerate_maps():
    assert P.largest_band(np.zeros((N, N), bool)) is None
    assert P.band_prototypes(np.zeros((N, N), bool)) == []
    full = np.ones((12, 12), bool)
    (b,) = P.band_prototypes(full)  # every offset, one run round the circle
    assert b.height_steps == 11
    # a run through offset 0 (not a grasp map, but the run finder is circular)
    S = band_map(1, 2, 12) | np.eye(12, dtype=bool)
    (b,) = P.band_prototypes(S)
    assert (b.d_lo, b.d_hi) == (10, 14) and b.contains(0)


def test_band_needs_the_whole_diagonal():
    S = band_map(60, 75)
    S[7, :] = S[:, 7] = False  # one contact unusable (a polygon vertex) breaks the band
    assert P.largest_band(S) is None


def test_circle_band(models):
    b = P.largest_band(model(models, "circle", 0.7).stable)
    # two-point grasp on a circle: offset within 180 +- 2 atan(mu) (70 deg at mu = 0.7)
    assert b.offsets_deg == (112.0, 248.0) and b.height_deg == 136.0


# --------------------------------------------------------------------------- box prototype
def test_box_prototype_on_pure_box_map():
    S = box_map(170, 40, 20, side_y=30)  # wraps through contact 0 in x
    b = P.largest_box(S)
    assert {(b.width_steps, b.height_steps), (b.height_steps, b.width_steps)} == {(20, 30),
                                                                                  (30, 20)}
    assert b.cells == 21 * 31
    bb = b if b.width_steps == 20 else b.transpose()
    assert (bb.x_lo, bb.x_hi, bb.y_lo, bb.y_hi) == (170, 190, 40, 70)
    assert bb.contains(5, 50) and not bb.contains(11, 50)
    assert bb.width_deg == 40.0 and bb.height_deg == 60.0


def test_largest_box_area_vs_squarest():
    S = np.zeros((60, 60), bool)
    S[0:3, 0:40] = True  # 3 x 40 = 120 cells, thin
    S[10:20, 10:20] = True  # 10 x 10 = 100 cells, square
    a = P.largest_box(S)
    q = P.largest_box(S, squarest=True)
    assert a.cells == 120 and min(a.width_steps, a.height_steps) == 2
    assert q.cells == 100 and q.width_steps == q.height_steps == 9
    assert P.largest_box(np.zeros((8, 8), bool)) is None


def _brute_max_area(S: np.ndarray) -> int:
    n = S.shape[0]
    best = 0
    for x0, y0 in itertools.product(range(n), range(n)):
        for h in range(1, n + 1):
            if not S[(x0 + h - 1) % n, y0]:
                break
            for w in range(1, n + 1):
                xs = np.arange(x0, x0 + h) % n
                ys = np.arange(y0, y0 + w) % n
                if not S[np.ix_(xs, ys)].all():
                    break
                best = max(best, h * w)
    return best


@pytest.mark.parametrize("seed", range(6))
def test_largest_box_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    S = rng.random((9, 9)) < 0.7
    assert P.largest_box(S).cells == _brute_max_area(S)
    b = P.largest_box(S)
    assert all(S[x % 9, y % 9] for x in range(b.x_lo, b.x_hi + 1)
               for y in range(b.y_lo, b.y_hi + 1))


# --------------------------------------------------------------------------- conditions
def test_workspace_grid_of_thesis_hand(models):
    assert GEOM == P.WorkspaceGrid.from_model(model(models, "circle", 0.7))
    assert GEOM.w_steps == W and GEOM.w_deg == 30.0
    assert GEOM.box_offsets(0, 1) == (15, 105)  # inner box (1, 2): offsets 30..210 deg
    assert GEOM.box_offsets(0, 2) == (75, 165)  # outer box (1, 3): offsets 150..330 deg
    assert sorted(GEOM.boxes("inner")) == [(0, 1), (1, 2), (2, 0)]
    assert [GEOM.succ(f) for f in range(3)] == [1, 2, 0]


def test_band_conditions_true_and_false():
    ok = P.BandPrototype(60, 75, N)
    c1, c2 = P.band_condition_1(ok, GEOM), P.band_condition_2(ok, W)
    assert c1.ok and c2.ok
    assert "meets the inner boxes' offsets [30, 210] deg" in c1.reason
    low = P.BandPrototype(60, 72, N)
    c2 = P.band_condition_2(low, W)
    assert not c2.ok and c2.reason == "band height 24 deg < w = 30 deg"
    far = P.BandPrototype(10, 40, N)  # 20..80 deg: never reaches an outer box
    c1 = P.band_condition_1(far, GEOM)
    assert not c1.ok and "misses the outer box" in c1.reason
    # condition 3: the inner-box offset must be >= w below the forward edge
    assert P.band_condition_3(ok, 60, W).ok
    c3 = P.band_condition_3(ok, 61, W)
    assert not c3.ok and "only 28 deg from the band's forward edge 150 deg" in c3.reason
    assert not P.band_condition_3(ok, 80, W).ok  # outside the band


def test_forward_conditions_on_maps(models):
    band, checks = P.forward_conditions(band_map(60, 75))
    assert band.d_lo == 60 and all(checks)
    band, checks = P.forward_conditions(band_map(60, 70))
    assert not checks[1].ok and "band height 20 deg < w = 30 deg" in checks[1].reason
    # with a start grasp: fingers 1 at 0 deg, 2 at 120 deg -> inner offset 120 deg
    _, checks = P.forward_conditions(band_map(60, 75), GEOM, {0: 0, 1: 60})
    assert all(checks)
    _, checks = P.forward_conditions(band_map(60, 75), GEOM, {0: 0, 1: 70})
    assert [c.ok for c in checks] == [True, True, False]
    _, checks = P.forward_conditions(model(models, "pentagon", 0.7).stable)
    assert len(checks) == 1 and checks[0].reason.startswith("no band")


def test_box_conditions_true_and_false():
    good = P.BoxPrototype(0, 30, 90, 120, N)  # 60 x 60 deg, centre offset 180 deg
    assert P.box_size_condition(good, W).ok
    assert P.box_placement_condition(good, GEOM).ok
    small = P.BoxPrototype(0, 17, 90, 107, N)
    c = P.box_size_condition(small, W)
    assert not c.ok and c.reason == "box 34 x 34 deg is smaller than 2w x 2w = 60 x 60 deg"
    # centre offset 118 deg: overlaps the outer boxes (from 150 deg) by only 28 deg < w
    near = P.BoxPrototype(0, 30, 59, 89, N)
    c = P.box_placement_condition(near, GEOM)
    assert not c.ok and "the outer boxes by 28 deg" in c.reason
    assert P.box_placement_condition(P.BoxPrototype(0, 30, 60, 90, N), GEOM).ok


@pytest.mark.parametrize("d, expect", [(60, True), (59, False), (120, True), (121, False)])
def test_box_placement_condition_matches_exact_planner(d, expect):
    """The 'passes through both box pairs' reading (overlaps >= w) is exactly when a gait
    exists on a pure 2w x 2w box map (checked with the exact planner from a few starts)."""
    S = box_map(0, d, 2 * W)
    m = synthetic(S)
    box, checks = P.back_and_forth_conditions(S, m)
    assert all(checks) == expect
    starts = m.start_states()
    found = any(optimal_gait(m, s, 360.0).success for s in starts[:: max(1, len(starts) // 4)])
    assert found == expect


def test_conditions_on_a_map_with_no_stable_grasp():
    """An empty map (a regular pentagon at mu 0.3) fails both prototypes with a reason,
    never an assertion."""
    S = np.zeros((N, N), bool)
    band, checks = P.forward_conditions(S, GEOM)
    assert band is None and [c.ok for c in checks] == [False]
    box, checks = P.back_and_forth_conditions(S, GEOM)
    assert box is None and [c.ok for c in checks] == [False]
    assert checks[0].reason.startswith("no box")


def test_workspace_grid_from_hand_is_the_models_rounding():
    """WorkspaceGrid.from_hand rounds with gait.workspace_grid, as GaitModel does, also
    for workspace edges off the grid."""
    from graspgait_env.gait import GaitModel, workspace_grid

    hand = Hand(((1.0, 91.0), (119.0, 211.5), (245.0, 255.0)), "off-grid")
    g = P.WorkspaceGrid.from_hand(hand, N)
    assert g == P.WorkspaceGrid.from_model(GaitModel("circle", 0.7, hand=hand))
    starts, widths = workspace_grid(hand.workspaces_deg, N)
    assert g.ws_start == tuple(starts) and g.ws_width == tuple(widths) == (45, 46, 5)
