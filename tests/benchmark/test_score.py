"""The score: success over solvable starts, efficiency against the optimum, their
product; hand-computed cases."""

from __future__ import annotations

import pytest

from graspgait_env.benchmark.score import SCORE_FIELDS, score_records


def rec(success, regrasps, optimal, rule, steps=10, illegal=0):
    return {"solvable": optimal is not None, "success": success, "regrasps": regrasps,
            "optimal_regrasps": optimal, "rule_regrasps": rule, "steps": steps,
            "illegal_actions": illegal}


def test_hand_computed_mixed_run():
    records = [rec(True, 10, 8, 12), rec(True, 6, 6, 6), rec(False, 2, 9, None),
               rec(False, 0, None, None, illegal=5)]  # the last start has no gait
    s = score_records(records)
    assert set(SCORE_FIELDS) <= set(s)
    assert (s["n_episodes"], s["solvable"], s["successes"]) == (4, 3, 2)
    assert s["success"] == pytest.approx(2 / 3)
    assert s["efficiency"] == pytest.approx((8 + 6) / (10 + 6))  # ratio of sums
    assert s["score"] == pytest.approx(2 / 3 * 14 / 16)
    # the rule-based gait from the same 3 solvable starts: found 2, 18 regrasps vs 14
    assert s["rule_success"] == pytest.approx(2 / 3)
    assert s["rule_efficiency"] == pytest.approx(14 / 18)
    assert s["rule_score"] == pytest.approx(2 / 3 * 14 / 18)
    assert s["mean_regrasps"] == 8 and s["mean_optimal_regrasps"] == 7
    assert s["illegal_action_rate"] == pytest.approx(5 / 40)


def test_optimal_everywhere_scores_one():
    s = score_records([rec(True, 7, 7, 9), rec(True, 0, 0, 0)])
    assert (s["success"], s["efficiency"], s["score"]) == (1.0, 1.0, 1.0)
    assert s["rule_efficiency"] == pytest.approx(7 / 9)


def test_no_success_scores_zero_without_an_efficiency():
    s = score_records([rec(False, 3, 8, 8), rec(False, 1, 5, None)])
    assert (s["success"], s["efficiency"], s["score"]) == (0.0, None, 0.0)
    assert s["mean_regrasps"] is None and s["rule_score"] == pytest.approx(0.5)


def test_no_solvable_start_scores_nothing():
    s = score_records([rec(False, 3, None, None), rec(False, 0, None, None)])
    assert s["solvable"] == 0
    assert all(s[k] is None for k in ("success", "efficiency", "score", "rule_success",
                                      "rule_efficiency", "rule_score"))
    assert score_records([])["score"] is None


def test_zero_regrasps_on_both_sides_is_optimal():
    s = score_records([rec(True, 0, 0, 0)])
    assert s["efficiency"] == 1.0 and s["score"] == 1.0
