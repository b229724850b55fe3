"""The modified search of thesis 6.4: depth-first within one gait structure."""

from __future__ import annotations

from graspgait_env.planners.modified_search import modified_search
from tests.planners.helpers import check_plan, model


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
