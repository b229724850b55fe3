"""What the rule-based gaits and the modified search share (thesis 6.3-6.5).

- :class:`Trace`: the states of a gait being built, every move checked with
  :meth:`GaitModel.action_mask` (the one legal-move function) before it is taken, so every
  plan replays under :func:`graspgait_env.plan.validate_plan`;
- :class:`Stuck`: the rules have no legal move;
- :func:`gait_result` / :func:`gait_failure`: the :class:`PlannerResult` of a gait or of
  its absence; :func:`add_nodes` adds nodes opened elsewhere (a start that got stuck, an
  earlier method) to a result and its plan's stats;
- :func:`gait_pattern`: staircase, plus or combined (thesis fig. 6.10).

The parts (:mod:`~graspgait_env.planners.forward_gait`,
:mod:`~graspgait_env.planners.back_and_forth_gait`,
:mod:`~graspgait_env.planners.modified_search`,
:mod:`~graspgait_env.planners.rule_based`) import this module; it imports none of them.

Counting (thesis 6.5)
---------------------
A rule application produces exactly one move — a rotation *or* a regrasp — and that
move is a node of the final path; no node is ever opened off the path. So for the two
rule-based gaits ``nodes_opened == nodes_created == path_length`` = the number of plan
steps after the grasp (rotations + regrasps, thesis 5.4's path length), and ``regrasps``
is the plan's regrasp count. The thesis's Table 6.1 counts rotations implicitly (its
three measures all equal the number of regrasps); ours count them explicitly, so
``path_length`` is about twice ``regrasps``. Zero rotations are never emitted.

Coordinates (see :mod:`graspgait_env.planners.exact`): a finger at workspace position ``p``
at object angle ``k`` holds unwrapped contact ``x = s_f + p - k``; in the grasp map a
rotation moves the grasp diagonally relative to the finger pair boxes, a regrasp
horizontally (the ``x`` finger changes) or vertically (the ``y`` finger changes).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import plan_from_states
from graspgait_env.planners.prototypes import Check
from graspgait_env.planners.result import PlannerResult

__all__ = ["MAX_RULE_STEPS", "Stuck", "Trace", "add_nodes", "failed_reasons", "gait_failure",
           "gait_pattern", "gait_result"]

MAX_RULE_STEPS = 2_000  # (moves) safety cap of a rule-based gait


class Stuck(Exception):
    """The rules have no legal move; the message says where and why."""


@dataclass
class Trace:
    """The states of a gait being built; every move is checked with ``action_mask``.

    Attributes
    ----------
    model
        The gait model.
    states
        The states so far, the start first.
    rules
        The rule (or move label) behind each move, one per state after the start.
    """

    model: GaitModel
    states: list[GaitState]
    rules: list[str] = field(default_factory=list)

    @property
    def s(self) -> GaitState:
        """The present state."""
        return self.states[-1]

    def rotate(self, delta: int, rule: str) -> None:
        """Turn the object ``delta`` grid steps (CCW positive); :class:`Stuck` if illegal."""
        s = self.s
        self.push(GaitState(s.k + int(delta), s.contacts), rule)

    def regrasp(self, finger: int, contact: int, lifted: int, rule: str) -> None:
        """Place the free ``finger`` at ``contact`` (mod ``n``), then lift ``lifted``;
        :class:`Stuck` if illegal."""
        s = self.s
        cs = list(s.contacts)
        cs[finger] = int(contact) % self.model.n
        cs[lifted] = -1
        self.push(GaitState(s.k, tuple(cs)), rule)

    def push(self, t: GaitState, rule: str) -> None:
        """Move to ``t`` if one legal move takes the present state there, else :class:`Stuck`
        (also past :data:`MAX_RULE_STEPS` moves)."""
        s = self.s
        try:
            a = self.model.encode(s, t)
        except ValueError:
            a = -1
        if a < 0 or not self.model.action_mask(s)[a]:
            raise Stuck(f"{rule}: the move {self.model.describe_state(s)} -> "
                        f"{self.model.describe_state(t)} is not legal")
        if len(self.states) > MAX_RULE_STEPS:
            raise Stuck(f"{rule}: more than {MAX_RULE_STEPS} moves without reaching the goal")
        self.states.append(t)
        self.rules.append(rule)

    def describe(self) -> str:
        """The present state in words."""
        return self.model.describe_state(self.s)


def gait_result(planner: str, model: GaitModel, trace: Trace, t0: float, pattern: str,
                extra: dict[str, Any]) -> PlannerResult:
    """The result of a gait that reached its goal: one node per move (module docstring),
    ``extra["rules"]`` the rule behind each move."""
    plan = plan_from_states(model, trace.states)
    L = len(plan.steps) - 1
    plan.stats = {"planner": planner, "nodes_opened": L, "regrasps": plan.regrasps,
                  "rotation_deg": plan.rotation_deg}
    extra = dict(extra)
    extra["rules"] = list(trace.rules)
    return PlannerResult(
        planner, plan, nodes_opened=L, nodes_created=L, path_length=L,
        regrasps=plan.regrasps, rotation_deg=plan.rotation_deg,
        max_turn_deg=plan.rotation_deg, wall_time_s=time.perf_counter() - t0,
        pattern=pattern, extra=extra)


def gait_failure(planner: str, reason: str, t0: float, extra: dict[str, Any],
                 max_turn_deg: float = 0.0, nodes: tuple[int, int] = (0, 0),
                 exhausted: bool = False) -> PlannerResult:
    """The result of a gait that was not found: ``plan=None`` and the ``reason``."""
    return PlannerResult(planner, None, reason=reason, max_turn_deg=max_turn_deg,
                         nodes_opened=nodes[0], nodes_created=nodes[1],
                         wall_time_s=time.perf_counter() - t0, extra=extra,
                         exhausted=exhausted)


def add_nodes(res: PlannerResult, opened: int, created: int) -> None:
    """Add nodes opened / created outside ``res``'s own search to it (and to its plan's
    ``stats["nodes_opened"]`` when it has a plan)."""
    res.nodes_opened += opened
    res.nodes_created += created
    if res.plan is not None:
        res.plan.stats["nodes_opened"] = res.nodes_opened


def failed_reasons(checks: list[Check]) -> str:
    """The reasons of the failed checks, ``"; "``-joined."""
    return "; ".join(c.reason for c in checks if not c.ok)


def gait_pattern(model: GaitModel, trace: Trace, backward: int) -> str:
    """``staircase`` without backward steps; else ``plus`` when the last half-turn visits at
    most the five grasp-map points of the + (fig. 6.10 (b)), ``combined`` otherwise (the
    first moves from an arbitrary start are a transient and are not counted)."""
    if backward == 0:
        return "staircase"
    k_end = trace.states[-1].k
    tail = [s for s in trace.states if abs(k_end - s.k) <= model.n // 2]
    pts = {tuple(sorted(c for c in s.contacts if c >= 0)) for s in tail}
    return "plus" if len(pts) <= 5 else "combined"
