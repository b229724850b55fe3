"""Every planner by the name the CLI, the bench and the policies use.

Each planner is ``planner(model, start, turn_deg) -> PlannerResult``; the rule-based ones
also accept ``start=None`` (they choose a start that satisfies their conditions).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.result import PlannerResult

__all__ = ["PLANNERS", "get_planner", "run_planner", "default_start", "Planner"]

Planner = Callable[..., PlannerResult]

# name -> "module:function" (imported on first use)
PLANNERS: dict[str, str] = {
    "bfs": "graspgait_env.planners.search:breadth_first",  # thesis 5.3
    "dfs": "graspgait_env.planners.search:depth_first",  # thesis 5.4
    "best-first": "graspgait_env.planners.search:best_first",  # thesis 5.5
    "forward": "graspgait_env.planners.rule_based:forward_gait",  # thesis 6.3.1
    "back-and-forth": "graspgait_env.planners.rule_based:back_and_forth_gait",  # thesis 6.3.2
    "modified": "graspgait_env.planners.rule_based:modified_search",  # thesis 6.4
    "rule": "graspgait_env.planners.rule_based:rule_based",  # thesis 6.5, Table 6.1
    # beyond the thesis: exact minimum regrasps
    "optimal": "graspgait_env.planners.exact:optimal_gait",
}

# planners that choose their own start when given none
CHOOSE_OWN_START = frozenset({"forward", "back-and-forth", "rule"})


def get_planner(name: str) -> Planner:
    """The planner function called ``name``; refuses unknown names with the list."""
    if name not in PLANNERS:
        raise GraspGaitInputError(f"--planner {name!r}: unknown; use one of {', '.join(PLANNERS)}")
    module, func = PLANNERS[name].split(":")
    return getattr(importlib.import_module(module), func)


def default_start(model: GaitModel, candidates: int = 24) -> GaitState:
    """A deterministic start grasp at θ = 0 from which a 360° gait exists, if any.

    Tries up to ``candidates`` legal starts evenly spaced through
    :meth:`GaitModel.start_states` and returns the first from which the exact planner
    finds a gait; if none does, the first legal start. Raises when there is no legal
    start at all (no stable grasp inside the workspaces).
    """
    from graspgait_env.planners.exact import optimal_gait

    starts = model.start_states()
    if not starts:
        raise GraspGaitInputError(
            f"{model.shape.name} at mu={model.mu:g}: no stable grasp lies inside the "
            "workspaces at theta = 0; raise mu or change the hand")
    step = max(1, len(starts) // candidates)
    for s in starts[::step][:candidates]:
        if optimal_gait(model, s, 360.0).success:
            return s
    return starts[0]


def run_planner(name: str, model: GaitModel, start: GaitState | None,
                turn_deg: float = 360.0) -> PlannerResult:
    """Run planner ``name``; ``start=None`` lets rule-based planners choose, others get
    :func:`default_start`."""
    fn = get_planner(name)
    if start is None and name not in CHOOSE_OWN_START:
        start = default_start(model)
    return fn(model, start, turn_deg)
