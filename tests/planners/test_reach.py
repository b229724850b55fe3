"""RegraspReach: the reach of a segment within j regrasps (a depth-limited exact search)."""

from __future__ import annotations

import numpy as np
import pytest

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel
from graspgait_env.planners.exact import RegraspsToGo
from graspgait_env.planners.reach import MAX_REACH_DEPTH, RegraspReach


@pytest.mark.parametrize("name, mu, n, turn", [("ellipse", 0.7, 180, 360.0),
                                               ("pentagon", 0.7, 90, -360.0),
                                               ("hexagon", 0.5, 90, 360.0)])
def test_shortfall_is_zero_exactly_from_the_optimums_count(name, mu, n, turn):
    """The turn is reached within j regrasps iff the exact planner needs at most j."""
    model = GaitModel(name, mu, n=n)
    to_go = RegraspsToGo(model, turn, 360.0)
    reach = RegraspReach(model, turn, 360.0, depth=MAX_REACH_DEPTH)
    checked = 0
    for s in model.start_states()[::5]:
        G = to_go(s)
        short = [reach.shortfall(s, j) for j in range(MAX_REACH_DEPTH + 1)]
        assert all(a >= b for a, b in zip(short, short[1:], strict=False))  # deeper: closer
        assert short[0] == max(abs(model.turn_steps(turn))
                               - model.state_rotation_room(s)[0 if turn > 0 else 1], 0)
        for j, sf in enumerate(short):
            assert (sf == 0) == (0 <= G <= j), (s, G, short)
        checked += G >= 0
    assert checked  # starts with a gait were compared


def test_one_level_is_the_best_single_regrasp_by_brute_force():
    """reach_1 of a state = the farthest reach_0 over every regrasp from every angle of its
    segment (GaitModel's legal moves alone)."""
    model = GaitModel("ellipse", 0.7, n=90)
    reach = RegraspReach(model, 360.0, 360.0, depth=1)
    K = model.turn_steps(360.0)
    for s in model.start_states()[::9]:
        ccw, cw = model.state_rotation_room(s)
        best = s.k + ccw
        for d in range(-cw, ccw + 1):
            t = type(s)(s.k + d, s.contacts)
            for a, u in model.successors(t):
                if a >= 2 * model.R:
                    best = max(best, u.k + model.state_rotation_room(u)[0])
        assert reach.reach(s, 1) == min(best, K)


def test_depth_is_checked():
    model = GaitModel("ellipse", 0.7, n=90)
    for bad in (-1, MAX_REACH_DEPTH + 1, 1.5, True):
        with pytest.raises(GraspGaitInputError, match="depth="):
            RegraspReach(model, 360.0, 360.0, depth=bad)
    assert len(RegraspReach(model, 360.0, 360.0, depth=0).levels) == 1
    assert np.all(RegraspReach(model, 360.0, 360.0, depth=2).levels[2][0]
                  >= RegraspReach(model, 360.0, 360.0, depth=2).levels[1][0])
