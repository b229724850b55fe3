"""Exact minimum-regrasp planner against the general searches (thesis 5.3-5.5) and by hand."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

from graspgait_env.gait import GaitModel
from graspgait_env.objects import bundled_objects
from graspgait_env.plan import validate_plan
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.search import best_first, breadth_first, depth_first
from graspgait_env.shapes import Polygon

N = 36  # 10-degree grid: the thesis hand keeps 10 grid angles per 90-degree workspace
STEP = 360.0 / N
UNLIMITED = 10**7  # nodes: on this grid every search runs to the goal or to exhaustion
SEARCHES = [breadth_first, depth_first, best_first]


@st.composite
def star_polygons(draw):
    """Random polygons star-shaped about the origin, radii 0.04-0.09 m.

    m vertices at nominal angles 360 k / m, jittered by up to ±20 % of the spacing and
    placed 20-80 % of the way across their 10-degree grid cell, so no grid contact is
    within 2 degrees of a vertex. Consecutive vertices are at least 0.6 * 360/m - 10 > 17
    degrees apart (m <= 8) and at most 1.4 * 360/m + 10 <= 178 degrees apart (m >= 3): the
    origin is strictly inside and every ray from it meets the outline once.
    """
    m = draw(st.integers(3, 8))
    spacing = 360.0 / m
    ang = []
    for k in range(m):
        cell = np.floor((k + draw(st.floats(-0.2, 0.2))) * spacing / STEP)
        ang.append((cell + draw(st.floats(0.2, 0.8))) * STEP)
    rad = np.array([draw(st.floats(0.04, 0.09)) for _ in range(m)])
    a = np.radians(np.asarray(ang))
    return np.stack([rad * np.cos(a), rad * np.sin(a)], axis=1)


@settings(max_examples=25, deadline=None)
@given(star_polygons(), st.floats(0.3, 1.0), st.integers(0, 10**6),
       st.sampled_from([360.0, -360.0, 120.0]))
def test_exact_is_minimal_and_agrees_with_exhaustive_searches(verts, mu, pick, turn):
    """Exact regrasps <= every search's; "no gait" exactly when the searches exhaust."""
    model = GaitModel(Polygon(verts, "random"), mu, n=N)
    starts = model.start_states()
    if not starts:  # no stable grasp at theta = 0: nothing to plan
        event("no start grasp")
        return
    s = starts[pick % len(starts)]
    exact = optimal_gait(model, s, turn)
    found = [search(model, s, turn, max_nodes=UNLIMITED) for search in SEARCHES]
    event("no gait" if exact.plan is None else "gait")
    if exact.plan is None:
        assert exact.exhausted
        for r in found:
            assert r.plan is None and r.exhausted, (r.planner, r.reason)
            assert r.max_turn_deg == pytest.approx(exact.max_turn_deg), r.planner
        return
    assert validate_plan(exact.plan, model.shape, model.hand, turn) is None
    for r in found:
        assert r.plan is not None, (r.planner, r.reason, exact.regrasps)
        assert exact.regrasps <= r.regrasps, r.planner
    # exact's plan is itself a legal move sequence (each merged rotation stays in one
    # finger pair box), so breadth-first cannot need more moves
    assert found[0].path_length <= exact.path_length


@pytest.mark.parametrize("name", bundled_objects())
def test_exact_plans_validate_on_bundled_objects(name):
    model = GaitModel(name, 0.7)
    ss = model.start_states()
    checked = 0
    for s in (ss[len(ss) // 3], ss[2 * len(ss) // 3]) if ss else ():
        res = optimal_gait(model, s)
        if res.plan is None:
            assert res.exhausted and res.reason and abs(res.max_turn_deg) < 360.0
            continue
        checked += 1
        assert validate_plan(res.plan, model.shape, model.hand, 360.0) is None
        assert res.rotation_deg == pytest.approx(360.0)
        assert res.regrasps == res.plan.regrasps
        assert res.path_length == len(res.plan.steps) - 1
        assert res.plan.stats["planner"] == "optimal"
    assert checked or not ss or name not in {"circle", "ellipse", "pentagon", "hexagon"}


def test_exact_by_hand_thesis_fig_4_6():
    """Pentagon, mu = 0.7, grasp (50, 270) by fingers 1 and 3 (thesis fig. 4.6).

    Finger 1 reaches the end of its workspace (90 deg) after a 40-degree turn, so 40 deg
    needs no regrasp and anything more needs one; the figure's regrasp to (140, 270) by
    fingers 2 and 3 turns another 20 deg (finger 3 reaches 330 deg), so 60 deg needs
    exactly one.
    """
    model = GaitModel("pentagon", 0.7)
    s = model.start_state({1: 50.0, 3: 270.0})
    r40 = optimal_gait(model, s, 40.0)
    assert r40.regrasps == 0
    assert r40.plan.steps == [{"op": "grasp", "contacts": {"1": 50.0, "3": 270.0}},
                              {"op": "rotate", "delta": 40.0}]
    assert optimal_gait(model, s, 42.0).regrasps == 1
    r60 = optimal_gait(model, s, 60.0)
    assert r60.regrasps == 1
    assert validate_plan(r60.plan, model.shape, model.hand, 60.0) is None
    # the same holds clockwise: finger 3 reaches 240 deg after 30 deg
    assert optimal_gait(model, s, -30.0).regrasps == 0
    assert optimal_gait(model, s, -32.0).regrasps >= 1
    # a zero turn is the start itself
    r0 = optimal_gait(model, s, 0.0)
    assert r0.regrasps == 0 and len(r0.plan.steps) == 1


def test_exact_no_more_regrasps_than_searches_on_thesis_objects():
    """On the 2-degree grid (breadth-first capped, so only DFS and best-first)."""
    for name in ("circle", "ellipse", "pentagon", "hexagon"):
        model = GaitModel(name, 0.7)
        ss = model.start_states()
        for s in (ss[len(ss) // 4], ss[len(ss) // 2]):
            exact = optimal_gait(model, s)
            for search in (depth_first, best_first):
                r = search(model, s)
                assert (r.plan is None) == (exact.plan is None), (name, r.planner)
                if exact.plan is not None:
                    assert exact.regrasps <= r.regrasps


# --------------------------------------------------------------------------- object optimum
@st.composite
def hard_polygons(draw):
    """Star polygons (as above) made harder: stretched along x (eccentric, E up to 2.5)
    and/or with a notch (one vertex pulled in to 30-60 % of its radius)."""
    verts = draw(star_polygons())
    if draw(st.booleans()):
        verts = verts * np.array([draw(st.floats(1.3, 2.5)), 1.0])
    if draw(st.booleans()) and len(verts) >= 5:
        i = draw(st.integers(0, len(verts) - 1))
        verts = verts.copy()
        verts[i] *= draw(st.floats(0.3, 0.6))
    return verts


@settings(max_examples=20, deadline=None)
@given(hard_polygons(), st.floats(0.2, 0.8), st.sampled_from([360.0, -360.0]))
def test_optimum_without_start_is_the_minimum_over_every_start(verts, mu, turn):
    """``optimal`` without a start == the brute-force minimum of the per-start optima
    over every legal start at theta = 0, and <= the optimum from any start."""
    model = GaitModel(Polygon(verts, "random"), mu, n=N)
    starts = model.start_states()
    best = optimal_gait(model, None, turn)
    if not starts:
        event("no start grasp")
        assert best.plan is None and best.exhausted
        return
    per = [optimal_gait(model, s, turn) for s in starts]
    found = [r.regrasps for r in per if r.plan is not None]
    event("no gait" if not found else "gait")
    if not found:
        assert best.plan is None and best.exhausted
        assert str(len(starts)) in best.reason
        return
    assert best.plan is not None
    assert best.regrasps == min(found)
    assert all(best.regrasps <= r for r in found)
    assert validate_plan(best.plan, model.shape, model.hand, turn) is None
    # the plan names the start it chose: a legal start whose own optimum is the same
    chosen = [s for s in starts if model.describe_state(s) == best.extra["start"]]
    assert len(chosen) == 1 and best.extra["start_chosen"]
    assert best.extra["starts_seeded"] == len(starts)
    assert optimal_gait(model, chosen[0], turn).regrasps == best.regrasps
    assert best.plan.stats["start_chosen"] is True


def test_optimum_from_a_given_start_is_that_starts():
    model = GaitModel("pentagon", 0.7)
    s = model.start_state({1: 50.0, 3: 270.0})
    res = optimal_gait(model, s)
    assert res.extra == {"start": model.describe_state(s), "start_chosen": False,
                         "starts_seeded": 1}
    assert "start_chosen" not in res.plan.stats
    assert optimal_gait(model, None).regrasps <= res.regrasps


@pytest.mark.slow
@pytest.mark.parametrize("name", bundled_objects())
def test_object_optimum_at_n_180_on_bundled_objects(name):
    """n = 180: the optimum without a start equals the minimum over every legal start of
    the backward table (RegraspsToGo, a separate search from the goal), and the exact
    planner from 40 spread starts never needs fewer regrasps."""
    from graspgait_env.planners.exact import RegraspsToGo
    from graspgait_env.planners.starts import spread_starts

    model = GaitModel(name, 0.7)
    best = optimal_gait(model, None)
    to_go = RegraspsToGo(model, 360.0, 360.0)
    counts = [c for c in (to_go(s) for s in model.start_states()) if c >= 0]
    if best.plan is None:
        assert not counts
        return
    assert best.regrasps == min(counts)
    for s in spread_starts(model, 40):
        r = optimal_gait(model, s)
        assert r.plan is None or r.regrasps >= best.regrasps
