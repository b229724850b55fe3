"""RegraspsToGo: the exact optimum's regrasp count from every state, as one table."""

from __future__ import annotations

import pytest

from graspgait_env.baselines.policies import plan_states
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.exact import RegraspsToGo, optimal_gait
from graspgait_env.planners.starts import spread_starts

N = 90  # 4-degree grid: the same geometry as the default, four times faster


@pytest.mark.parametrize(("obj", "mu", "turn"), [
    ("ellipse", 0.7, 360.0), ("pentagon", 0.7, 360.0), ("pentagon", 0.7, -360.0),
    ("hexagon", 0.6, 200.0), ("triangle", 0.7, 360.0)])
def test_table_equals_the_exact_planner_from_every_start(obj, mu, turn):
    model = GaitModel(obj, mu, None, N)
    to_go = RegraspsToGo(model, turn, 360.0)
    seen = set()
    for s in spread_starts(model, 12):
        res = optimal_gait(model, s, turn)
        expected = res.regrasps if res.plan is not None else -1
        assert to_go(s) == expected, (obj, s)
        seen.add(expected >= 0)
    if obj != "triangle":  # the triangle at mu 0.7 has no gait (thesis Table 6.1)
        assert True in seen
    else:
        assert seen == {False}


def test_count_falls_by_one_per_regrasp_of_an_optimal_gait():
    model = GaitModel("ellipse", 0.7, None, N)
    to_go = RegraspsToGo(model, 360.0, 360.0)
    checked = 0
    for s in spread_starts(model, 6):
        res = optimal_gait(model, s, 360.0)
        if res.plan is None:
            assert to_go(s) == -1
            continue
        checked += 1
        states = plan_states(model, res.plan)
        counts = [to_go(t) for t in states]
        assert counts[0] == res.regrasps and counts[-1] == 0
        for a, b, ca, cb in zip(states, states[1:], counts, counts[1:], strict=False):
            assert cb == (ca - 1 if a.contacts != b.contacts else ca), (a, b, ca, cb)
    assert checked >= 3


def test_default_grid_and_window_edges():
    """n = 180 as the envs use it; states beyond the window (past the wrong-way limit or
    the turn) have no count (-1)."""
    model = GaitModel("ellipse", 0.7)
    to_go = RegraspsToGo(model, 360.0, 90.0)
    s = model.start_state({1: 50.0, 3: 270.0})
    assert to_go(s) == optimal_gait(model, s, 360.0).regrasps
    assert to_go(GaitState(-46, s.contacts)) == -1  # 92 degrees back: past 90
    assert to_go(GaitState(181, s.contacts)) == -1  # past the turn
