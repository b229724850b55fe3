"""The score of one run on one task, from the episode records of
:func:`graspgait_env.agents.evaluate.run_episodes`.

Each test episode starts from a start grasp drawn by the env; the exact planner says
whether a gait exists from it (the record's ``solvable``) and its fewest regrasps
(``optimal_regrasps``); the thesis's rule-based method plans from the same start
(``rule_regrasps``, None when it finds no gait). Over the ``n`` solvable episodes, of
which the policy succeeds in the set ``W``:

- **success** ``S = |W| / n``;
- **efficiency** ``E = sum_W optimal_regrasps / sum_W regrasps``: the optimum's regrasps
  divided by the policy's, over its successes (1 = optimal; below 1, the share of its
  regrasps the optimum would have needed; 1 when both sums are 0). None without a
  success;
- **score** ``S * E`` in ``[0, 1]`` (0 without a success): 1 only for a policy that
  succeeds from every solvable start with the fewest regrasps. Reported in percent on
  the scoreboard (Craftax's "percentage of the maximum");
- beside them, the rule-based gait's from the same solvable starts:
  ``rule_success`` (its share of them with a gait), ``rule_efficiency`` (optimum over
  its regrasps where it found one) and ``rule_score``, their product.

Without a solvable start every figure is None (the cell does not count in the
aggregates). A success from a start the exact planner calls unsolvable cannot happen
(the planner's search is exact over the env's window); such records are ignored.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["SCORE_FIELDS", "score_records"]

SCORE_FIELDS = ("n_episodes", "solvable", "successes", "success", "efficiency", "score",
                "rule_success", "rule_efficiency", "rule_score", "mean_regrasps",
                "mean_optimal_regrasps", "illegal_action_rate")


def _eff(optimal: int, taken: int) -> float:
    return 1.0 if taken == 0 else optimal / taken


def score_records(records: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Success, efficiency and score of a run's episode records (module docstring).

    Parameters
    ----------
    records
        Dicts with ``solvable``, ``success``, ``regrasps``, ``optimal_regrasps`` and
        ``rule_regrasps`` (and optionally ``steps``, ``illegal_actions``).

    Returns
    -------
    dict
        The keys of :data:`SCORE_FIELDS`.

    Examples
    --------
    >>> rec = lambda ok, g, opt, rule: {"solvable": opt is not None, "success": ok,
    ...                                 "regrasps": g, "optimal_regrasps": opt,
    ...                                 "rule_regrasps": rule}
    >>> s = score_records([rec(True, 10, 8, 12), rec(False, 3, 9, None)])
    >>> s["success"], s["efficiency"], s["score"]
    (0.5, 0.8, 0.4)
    """
    n = len(records)
    solvable = [r for r in records if r["solvable"]]
    wins = [r for r in solvable if r["success"]]
    out: dict[str, Any] = {"n_episodes": n, "solvable": len(solvable), "successes": len(wins)}
    if solvable:
        success = len(wins) / len(solvable)
        eff = (_eff(sum(int(r["optimal_regrasps"]) for r in wins),
                    sum(int(r["regrasps"]) for r in wins)) if wins else None)
        ruled = [r for r in solvable if r["rule_regrasps"] is not None]
        rule_success = len(ruled) / len(solvable)
        rule_eff = (_eff(sum(int(r["optimal_regrasps"]) for r in ruled),
                         sum(int(r["rule_regrasps"]) for r in ruled)) if ruled else None)
        out.update(success=success, efficiency=eff,
                   score=success * eff if eff is not None else 0.0,
                   rule_success=rule_success, rule_efficiency=rule_eff,
                   rule_score=rule_success * rule_eff if rule_eff is not None else 0.0)
    else:
        out.update(success=None, efficiency=None, score=None, rule_success=None,
                   rule_efficiency=None, rule_score=None)
    out["mean_regrasps"] = (sum(r["regrasps"] for r in wins) / len(wins)) if wins else None
    out["mean_optimal_regrasps"] = (sum(r["optimal_regrasps"] for r in wins) / len(wins)
                                    if wins else None)
    steps = sum(int(r.get("steps", 0)) for r in records)
    out["illegal_action_rate"] = (sum(int(r.get("illegal_actions", 0)) for r in records) / steps
                                  if steps else None)
    return out
