"""The rule-based method of thesis 6.5 (Table 6.1): prototype gaits first, else the
modified search."""

from __future__ import annotations

import pytest

from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.modified_search import map_structure
from graspgait_env.planners.registry import PLANNERS, default_start, get_planner
from graspgait_env.planners.rule_based import rule_based
from tests.planners.helpers import check_plan, model, replay

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
    else:  # the modified search's nodes are grasps, rotations implicit (thesis 6.5)
        assert res.nodes_opened >= res.regrasps
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


# --------------------------------------------------------------------------- rotation limit
@pytest.mark.parametrize("name", ["circle", "ellipse", "pentagon", "hexagon"])
def test_every_planners_rotations_stay_in_the_models_rotation_room(models, name):
    """No planner turns the object further than GaitModel.state_rotation_room allows
    (both contacts inside their workspaces all the way, thesis 5.2)."""
    m = model(models, name, 0.7)
    s0 = default_start(m)
    for planner in PLANNERS:
        if planner in ("bfs", "dfs"):
            continue  # the same move function as best-first (test_search), slower
        res = get_planner(planner)(m, s0, 360.0)
        if not res.success:
            continue
        states = replay(m, res)
        for a, b in zip(states[:-1], states[1:], strict=True):
            ccw, cw = m.state_rotation_room(a)
            assert -cw <= b.k - a.k <= ccw, (planner, a, b)
