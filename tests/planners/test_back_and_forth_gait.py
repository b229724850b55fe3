"""The back-and-forth gait of thesis 6.3.2: rules 1-11 on box maps and bundled objects."""

from __future__ import annotations

import itertools

import pytest

from graspgait_env.gait import GaitState
from graspgait_env.planners import prototypes as P
from graspgait_env.planners.back_and_forth_gait import back_and_forth_gait
from tests.planners.helpers import W, box_map, check_plan, model, synthetic


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
