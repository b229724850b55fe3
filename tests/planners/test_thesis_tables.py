"""The bench's planner columns (thesis Tables 1 and 6.1) as `graspgait bench` runs them."""

from __future__ import annotations

import statistics

import pytest

from baselines.bench import (
    THESIS_OBJECTS,
    THESIS_TABLE_6_1,
    bench_starts,
    markdown_report,
    run_bench,
    run_case,
    summarize,
)
from graspgait_env.gait import GaitModel


def test_run_case_records_how_the_rule_based_method_ran():
    model = GaitModel("ellipse", 0.7)
    s = bench_starts(model, 10)[-1]  # a start outside the box (measured: 3 moves)
    c = run_case("ellipse", 0.7, s, "rule")
    assert c.success and c.method == "back-and-forth" and c.pattern in ("plus", "combined")
    assert c.entry_needed and c.entry_moves == 3
    b = run_case("ellipse", 0.7, s, "best-first")
    assert b.method == "" and b.entry_needed is None and b.entry_moves is None
    md = markdown_report([c, b])
    assert "| ellipse | 0.7 | 1 | 0 | 1 | 0 | 1 (3) | " in md
    assert "nodes per path step" in md


@pytest.mark.slow
def test_table_6_1_rule_based_as_the_bench_runs_it():
    """`graspgait bench --mus 0.7`: the rule-based method succeeds from every start on the
    four thesis objects; its mean regrasps are within 10 % of Table 6.1 on the ellipse
    and hexagon; on the pentagon (the modified search, 6.4) they are at most Table 6.1's
    (measured 12.1 against 14.5: the search opens the rules' first choice, the step to
    the edge of the next box, first); on the circle the forward gait is the exact
    optimum from every start (so no gait from these starts is cheaper); the modified
    search opens at most 1.5 nodes per path step on the circle, pentagon and hexagon
    (thesis 6.5; the ellipse, measured 2.91, is guarded in test_modified_search)."""
    cases = run_bench(THESIS_OBJECTS, [0.7], ["rule", "modified", "optimal"], progress=False)
    summ = summarize(cases)
    for obj in THESIS_OBJECTS:
        assert summ[(obj, 0.7, "rule")]["success"] == 1.0, obj
        assert summ[(obj, 0.7, "modified")]["success"] == 1.0, obj
        mean = summ[(obj, 0.7, "rule")]["regrasps"]
        if obj == "pentagon":
            assert mean <= THESIS_TABLE_6_1[obj], mean
        elif obj != "circle":
            assert abs(mean - THESIS_TABLE_6_1[obj]) <= 0.1 * THESIS_TABLE_6_1[obj], (obj, mean)
    rule = [c for c in cases if (c.object, c.planner) == ("circle", "rule")]
    best = [c for c in cases if (c.object, c.planner) == ("circle", "optimal")]
    assert [c.regrasps for c in rule] == [c.regrasps for c in best]
    assert statistics.fmean(c.regrasps for c in rule) == pytest.approx(7.8)
    for obj in ("circle", "pentagon", "hexagon"):
        assert summ[(obj, 0.7, "modified")]["nodes_per_step"] <= 1.5, obj
