"""The rule-based method (thesis 6.5, Table 6.1 "rule-based"): prototype gaits first.

The thesis's second approach to generating gaits: the rule-based gait when the
sufficient conditions of a prototype hold — the forward gait
(:mod:`~graspgait_env.planners.forward_gait`, 6.3.1) first, then the back-and-forth
gait (:mod:`~graspgait_env.planners.back_and_forth_gait`, 6.3.2, which first enters a
box from a start outside one: "there is no initial condition that would preclude a
successful gait") — else the modified search based on them
(:mod:`~graspgait_env.planners.modified_search`, 6.4).

:func:`diagnose_no_gait` (:mod:`~graspgait_env.planners.diagnosis`) is re-exported here
for callers that import it from this module.
"""

from __future__ import annotations

import time

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.back_and_forth_gait import back_and_forth_gait
from graspgait_env.planners.diagnosis import diagnose_no_gait
from graspgait_env.planners.forward_gait import forward_gait
from graspgait_env.planners.modified_search import DEFAULT_MAX_NODES, modified_search
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.starts import own_start_verdict
from graspgait_env.planners.trace import add_nodes

__all__ = ["rule_based", "diagnose_no_gait", "DEFAULT_MAX_NODES"]


def rule_based(model: GaitModel, start: GaitState | None = None, turn_deg: float = 360.0,
               max_nodes: int = DEFAULT_MAX_NODES) -> PlannerResult:
    """The thesis's prototype-gait method (6.5, Table 6.1 "rule-based").

    The forward gait when its conditions hold (6.3.1), else the back-and-forth gait
    (6.3.2), else the modified search (6.4).

    Parameters
    ----------
    model
        The gait model.
    start
        Start grasp at ``k = 0``; ``None``: each method chooses its own.
    turn_deg
        Requested turn (degrees; negative: clockwise).
    max_nodes
        Node cap of the modified search.

    Returns
    -------
    PlannerResult
        ``planner="rule-based"``; ``extra["method"]`` says which of ``forward``,
        ``back-and-forth``, ``modified-search`` produced the plan,
        ``extra["prototypes"]`` why the earlier ones did not, ``extra["entry_moves"]``
        how many moves the back-and-forth gait needed to enter its box (0 for the
        other methods, which start from the start grasp) and ``extra["entry_needed"]``
        whether it needed any. Moves made by a rule gait that then got stuck, and the
        nodes of the entry search, count as nodes opened. With ``start=None`` and no stable
        grasp inside the workspaces at θ = 0: the no-gait verdict of
        :func:`~graspgait_env.planners.starts.no_start_verdict`.

    Raises
    ------
    GraspGaitInputError
        ``start`` is not a legal grasp at ``k = 0``.
    """
    t0 = time.perf_counter()
    verdict = own_start_verdict(model, start, t0)
    if verdict is not None:
        return verdict
    notes = []
    spent = 0
    for fn in (forward_gait, back_and_forth_gait):  # thesis 6.5: a prototype gait first
        r = fn(model, start, turn_deg)
        if r.success:
            r.extra["prototypes"] = notes
            r.extra.setdefault("entry_moves", 0)
            r.extra.setdefault("entry_needed", False)
            add_nodes(r, spent, spent)
            r.wall_time_s = time.perf_counter() - t0
            return r
        notes.append(r.reason)
        spent += r.nodes_opened
    r = modified_search(model, start, turn_deg, max_nodes=max_nodes)  # thesis 6.4
    r.planner = "rule-based"
    add_nodes(r, spent, spent)
    r.extra["prototypes"] = notes
    r.extra.update(entry_moves=0, entry_needed=False)
    r.wall_time_s = time.perf_counter() - t0
    if r.plan is not None:
        r.plan.stats["planner"] = "rule-based"
    else:
        r.reason = "; ".join(notes + [r.reason])
    return r
