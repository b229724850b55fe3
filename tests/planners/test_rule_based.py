"""Prototype regions and rule-based gaits (thesis 6.2–6.5): prototypes, conditions, forward and
back-and-forth gaits, modified search, the combined method and the no-gait diagnosis."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import validate_plan
from graspgait_env.planners import prototypes as P
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.rule_based import (
    back_and_forth_gait,
    diagnose_no_gait,
    forward_gait,
    map_structure,
    modified_search,
    rule_based,
)
from graspgait_env.workspace import Hand

N = 180
W = 15  # w = 30 deg on the 2-degree grid
GEOM = P.WorkspaceGrid.from_hand(Hand.default(), N)


# --------------------------------------------------------------------------- helpers
def band_map(lo: int, hi: int, n: int = N) -> np.ndarray:
    """Pure band prototype: offsets lo..hi (grid steps) stable along the whole diagonal,
    mirrored below the diagonal (the map is symmetric)."""
    i = np.arange(n)
    S = np.zeros((n, n), dtype=bool)
    for d in range(lo, hi + 1):
        S[i, (i + d) % n] = True
    S |= S.T
    np.fill_diagonal(S, False)
    return S


def box_map(x0: int, y0: int, side: int, n: int = N, side_y: int | None = None) -> np.ndarray:
    """Pure box prototype: cells x0..x0+side × y0..y0+side_y (wrapping) and the mirror."""
    S = np.zeros((n, n), dtype=bool)
    xs = np.arange(x0, x0 + side + 1) % n
    ys = np.arange(y0, y0 + (side if side_y is None else side_y) + 1) % n
    S[np.ix_(xs, ys)] = True
    S |= S.T
    np.fill_diagonal(S, False)
    return S


def synthetic(S: np.ndarray) -> GaitModel:
    """A thesis-hand gait model whose grasp map is replaced by ``S``.

    GaitModel has no public hook for a hand-made map; ``action_mask`` reads a cached
    transposed tiling (``_rows``), so both are replaced here.
    """
    m = GaitModel("circle", 0.7)
    m.stable = S
    if hasattr(m, "_rows"):
        m._rows = np.ascontiguousarray(np.tile(S, (2, 2)).T)
    return m


def replay(model: GaitModel, res) -> list[GaitState]:
    """Replay a result's plan move by move, checking each move with ``action_mask``."""
    plan = res.plan
    steps = plan.steps
    cs = [-1, -1, -1]
    for f, phi in steps[0]["contacts"].items():
        cs[int(f) - 1] = model.contact_index(phi)
    s = GaitState(0, tuple(cs))
    assert model.is_legal_state(s)
    states = [s]
    for st in steps[1:]:
        if st["op"] == "rotate":
            t = GaitState(s.k + round(st["delta"] / model.step_deg), s.contacts)
        else:
            cs = [-1, -1, -1]
            for f, phi in st["contacts"].items():
                cs[int(f) - 1] = model.contact_index(phi)
            t = GaitState(s.k, tuple(cs))
        a = model.encode(s, t)
        assert model.action_mask(s)[a], (s, t)
        states.append(t)
        s = t
    return states


def check_plan(model: GaitModel, res, turn_deg: float = 360.0, physical: bool = True) -> None:
    assert res.success, res.reason
    states = replay(model, res)
    assert states[-1].k == model.turn_steps(turn_deg)
    assert res.path_length == len(res.plan.steps) - 1
    assert res.regrasps == res.plan.regrasps
    if physical:
        assert validate_plan(res.plan, model.shape, model.hand, turn_deg=turn_deg) is None


@pytest.fixture(scope="module")
def models() -> dict[tuple[str, float], GaitModel]:
    return {}


def model(models, name: str, mu: float) -> GaitModel:
    if (name, mu) not in models:
        models[(name, mu)] = GaitModel(name, mu)
    return models[(name, mu)]


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


# --------------------------------------------------------------------------- forward gait
@pytest.mark.parametrize("lo, h", [(60, 15), (75, 15), (90, 15), (45, 30), (30, 45), (100, 20)])
@pytest.mark.parametrize("turn", [360.0, -360.0, 250.0])
def test_forward_gait_on_band_maps(lo, h, turn):
    S = band_map(lo, lo + h)
    m = synthetic(S)
    band, checks = P.forward_conditions(S, m)
    res = forward_gait(m, None, turn)
    assert res.success == all(checks), res.reason
    if res.success:
        check_plan(m, res, turn, physical=False)
        assert res.nodes_opened == res.path_length == res.nodes_created
        assert res.pattern == "staircase"


def test_forward_gait_from_every_condition_3_start():
    S = band_map(50, 80)
    m = synthetic(S)
    n_ok = 0
    for s in m.start_states()[::5]:
        _, checks = P.forward_conditions(S, m, s.contacts)
        res = forward_gait(m, s)
        assert res.success == all(checks), res.reason
        n_ok += res.success
    assert n_ok > 10


def test_forward_gait_rules_on_circle(models):
    """Rule 1 rotates to the finger pair box edge; rules 2-3 put the free finger at the
    first grid angle of its workspace and lift the finger whose workspace precedes it."""
    m = model(models, "circle", 0.7)
    res = forward_gait(m)
    check_plan(m, res)
    assert res.extra["method"] == "forward" and res.pattern == "staircase"
    assert res.nodes_opened == res.path_length == 10 and res.regrasps == 6
    states = replay(m, res)
    g = P.WorkspaceGrid.from_model(m)
    for a, b, rule in zip(states[:-1], states[1:], res.extra["rules"], strict=True):
        if b.k != a.k:
            assert rule == "6.3.1 rule 1"
            if b is not states[-1]:
                assert any(m.position(f, b.contacts[f], b.k) == m.ws_width[f] - 1
                           for f in b.held())
        else:
            assert rule in ("6.3.1 rule 2", "6.3.1 rule 3")
            (h,) = [f for f in range(3) if a.contacts[f] < 0]
            (lifted,) = [f for f in range(3) if b.contacts[f] < 0]
            assert m.position(h, b.contacts[h], b.k) == 0
            assert lifted == g.pred(h)
    cw = forward_gait(m, None, -360.0)
    check_plan(m, cw, -360.0)
    assert cw.regrasps == res.regrasps


def test_forward_gait_refuses_with_reasons(models):
    res = forward_gait(model(models, "ellipse", 0.7))
    assert not res.success and "band height 12 deg < w = 30 deg" in res.reason
    m = synthetic(band_map(60, 80))  # offsets 120..160 deg
    # fingers 1 at 0 deg and 2 at 140 deg: inner offset 140, 20 deg from the edge 160
    res = forward_gait(m, GaitState(0, (0, 70, -1)))
    assert not res.success
    assert "only 20 deg from the band's forward edge 160 deg (< w = 30 deg)" in res.reason


# --------------------------------------------------------------------------- back-and-forth
@pytest.mark.parametrize("side", [2 * W, 2 * W + 5, 3 * W])
def test_back_and_forth_on_box_maps(side):
    """Whenever the box conditions hold, the rules turn the object 360 deg."""
    for d, x0 in itertools.product(range(30, 151, 10), (0, 25)):
        S = box_map(x0, x0 + d, side)
        m = synthetic(S)
        _, checks = P.back_and_forth_conditions(S, m)
        res = back_and_forth_gait(m)
        assert res.success == all(checks), (d, x0, res.reason)
        if res.success:
            check_plan(m, res, physical=False)
            assert res.nodes_opened == res.path_length


def test_back_and_forth_plus_and_combined_patterns():
    m = synthetic(box_map(0, 90, 2 * W))  # only the minimum box, centred on 180 deg
    res = back_and_forth_gait(m)
    check_plan(m, res, physical=False)
    assert res.pattern == "plus"
    assert {"6.3.2 rule 6", "6.3.2 rule 8", "6.3.2 rule 9", "6.3.2 rule 11"} <= set(
        res.extra["rules"])
    m = synthetic(box_map(0, 70, 3 * W))
    res = back_and_forth_gait(m)
    check_plan(m, res, physical=False)
    assert res.pattern == "combined"


def test_back_and_forth_turns_back_first():
    """A start past its right limit with a finger at the start of its workspace: the
    preparatory backward step of rule 9, then the turn back (6.3.2, last paragraph)."""
    m = synthetic(box_map(12, 102, 2 * W))
    s = GaitState(0, (28, -1, 120))  # finger 1 at 56 deg, finger 3 at 240 deg
    res = back_and_forth_gait(m, s)
    check_plan(m, res, physical=False)
    rules = res.extra["rules"]
    assert rules[:2] == ["6.3.2 rule 9 (before turning back)", "6.3.2 turn back"]
    assert res.plan.steps[2]["delta"] < 0


def test_back_and_forth_refusals(models):
    res = back_and_forth_gait(model(models, "pentagon", 0.7))
    assert not res.success and "box 34 x 34 deg is smaller than 2w x 2w" in res.reason
    res = back_and_forth_gait(model(models, "ellipse", 0.7), None, -360.0)
    assert not res.success and "counter-clockwise" in res.reason


# --------------------------------------------------------------------------- bundled objects
BUNDLED = ["circle", "ellipse", "pentagon", "hexagon", "square", "triangle", "regular_hexagon",
           "star", "stadium", "long_ellipse"]


@pytest.mark.parametrize("name", BUNDLED)
def test_rule_based_on_bundled_objects(models, name):
    m = model(models, name, 0.7)
    res = rule_based(m)
    if name == "triangle":
        assert not res.success
        return
    check_plan(m, res)
    if res.extra["method"] in ("forward", "back-and-forth"):
        assert res.nodes_opened == res.path_length
    else:
        assert res.nodes_opened >= res.path_length
    start = replay(m, res)[0]
    assert res.regrasps >= optimal_gait(m, start, 360.0).regrasps


def test_thesis_table_6_1_classification(models):
    """Table 6.1: circle, ellipse, hexagon by the prototype rules, pentagon by the
    modified search (its staircase structure, 6.4)."""
    got = {name: rule_based(model(models, name, 0.7)) for name in
           ("circle", "ellipse", "pentagon", "hexagon")}
    assert got["circle"].extra["method"] == "forward"
    assert got["circle"].pattern == "staircase"
    assert got["ellipse"].extra["method"] == "back-and-forth"
    assert got["hexagon"].extra["method"] == "back-and-forth"
    assert got["pentagon"].extra["method"] == "modified-search"
    assert got["pentagon"].extra["structure"] == "staircase"
    assert map_structure(model(models, "pentagon", 0.7)) == "staircase"
    assert map_structure(model(models, "hexagon", 0.7)) == "plus"


@pytest.mark.parametrize("name", ["circle", "ellipse", "pentagon", "hexagon"])
def test_rule_based_from_given_starts(models, name):
    m = model(models, name, 0.7)
    starts = m.start_states()
    for s in starts[:: len(starts) // 3][:3]:
        exact = optimal_gait(m, s, 360.0)
        res = rule_based(m, s)
        if not exact.success:
            continue
        check_plan(m, res)
        assert replay(m, res)[0] == s
        assert res.regrasps >= exact.regrasps


def test_modified_search_counts_and_structures(models):
    m = model(models, "pentagon", 0.7)
    s = m.start_state({1: 50.0, 3: 270.0})  # thesis fig. 4.6
    res = modified_search(m, s, 360.0, structure="staircase")
    check_plan(m, res)
    assert res.pattern == "staircase" and res.nodes_opened >= res.path_length
    assert all(lab in ("rotate", "rotate to goal", "forward regrasp", "turn back")
               for lab in res.extra["rules"])
    tiny = modified_search(m, s, 360.0, max_nodes=3)
    assert not tiny.success and "node limit" in tiny.reason and not tiny.exhausted
    e = model(models, "ellipse", 0.7)
    res = modified_search(e, e.start_states()[300], 360.0, structure="plus")
    check_plan(e, res)


# --------------------------------------------------------------------------- diagnosis
def test_diagnose_no_gait_categories(models):
    assert diagnose_no_gait(GaitModel("pentagon", 0.3)).startswith(
        "no stable grasp at all (mu=0.3)")
    tri = diagnose_no_gait(model(models, "triangle", 0.7))
    assert tri.startswith("stuck at angle 64 deg") and "box 10 x 10 deg < 2w x 2w" in tri
    assert diagnose_no_gait(model(models, "pentagon", 0.7)).startswith(
        "band/box smaller than the conditions need relative to w (no band; box 34 x 34 deg")
    assert diagnose_no_gait(model(models, "circle", 0.7)).startswith(
        "a gait exists: the forward gait's conditions hold")
    # workspaces whose finger pairs never hold contacts near 180 deg apart (circle, mu 0.1)
    hand = Hand(((0.0, 10.0), (90.0, 100.0), (245.0, 255.0)), "odd")
    assert diagnose_no_gait(GaitModel("circle", 0.1, hand=hand)).startswith(
        "stable grasps but none reachable inside the workspaces")
