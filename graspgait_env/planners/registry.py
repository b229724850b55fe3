"""Every planner by the name the CLI, the bench and the policies use.

Each planner is ``planner(model, start, turn_deg) -> PlannerResult``; the rule-based ones
(``forward``, ``back-and-forth``, ``rule``) choose their own start when given
``start=None``, ``optimal`` then answers the fewest regrasps over every legal start, and
:func:`run_planner` picks :func:`default_start` for the others.

No gait is an answer, not an error: every planner returns a
:class:`~graspgait_env.planners.result.PlannerResult` with ``plan=None`` and a
``reason`` when it finds no gait — also when no stable grasp lies inside the workspaces
at θ = 0, so that no gait can even start (thesis 1.3 (2)). Only bad input raises
(:class:`~graspgait_env.errors.GraspGaitInputError`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from graspgait_env.errors import GraspGaitInputError, NoGaitError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.starts import NO_START, legal_start_exists, spread_starts

__all__ = ["PLANNERS", "get_planner", "run_planner", "default_start", "Planner"]

Planner = Callable[..., PlannerResult]

# name -> "module:function" (imported on first use); one module per thesis section
PLANNERS: dict[str, str] = {
    "bfs": "graspgait_env.planners.search:breadth_first",  # thesis 5.3
    "dfs": "graspgait_env.planners.search:depth_first",  # thesis 5.4, with a visited set
    "dfs-thesis": "graspgait_env.planners.search:depth_first_thesis",  # 5.4 as the thesis ran it
    "best-first": "graspgait_env.planners.search:best_first",  # thesis 5.5, ties: oldest
    "best-first-newest": "graspgait_env.planners.search:best_first_newest",  # ties: newest
    "forward": "graspgait_env.planners.forward_gait:forward_gait",  # thesis 6.3.1
    "back-and-forth": "graspgait_env.planners.back_and_forth_gait:back_and_forth_gait",  # 6.3.2
    "modified": "graspgait_env.planners.modified_search:modified_search",  # thesis 6.4
    "rule": "graspgait_env.planners.rule_based:rule_based",  # thesis 6.5, Table 6.1
    # beyond the thesis: exact minimum regrasps
    "optimal": "graspgait_env.planners.exact:optimal_gait",
}

# planners that choose their own start when given none (optimal: the object's optimum
# over every legal start grasp at theta = 0)
CHOOSE_OWN_START = frozenset({"forward", "back-and-forth", "rule", "optimal"})


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
    finds a gait; if none does, the first legal start.

    Raises
    ------
    NoGaitError
        There is no legal start at all (no stable grasp inside the workspaces at
        θ = 0): a question with no answer, not bad input. :func:`run_planner` never
        calls this then; it returns the planner's no-gait verdict instead.
    """
    from graspgait_env.planners.exact import optimal_gait

    starts = spread_starts(model, candidates)
    if not starts:
        raise NoGaitError(f"{model.shape.name} at mu={model.mu:g}: {NO_START}; raise mu or "
                          "change the hand")
    for s in starts:
        if optimal_gait(model, s, 360.0).success:
            return s
    return starts[0]


def run_planner(name: str, model: GaitModel, start: GaitState | None,
                turn_deg: float = 360.0) -> PlannerResult:
    """Run planner ``name`` from ``start``.

    Parameters
    ----------
    name
        A key of :data:`PLANNERS`.
    model
        The gait model.
    start
        Start grasp at ``k = 0``, or ``None``: the rule-based planners (``forward``,
        ``back-and-forth``, ``rule``) choose their own, ``optimal`` returns the fewest
        regrasps over every legal start (and says which it chose), the others get
        :func:`default_start`.
    turn_deg
        Requested turn (degrees, counter-clockwise positive).

    Returns
    -------
    PlannerResult
        The gait, or ``plan=None`` (``success`` False) with a ``reason``: every "no gait"
        is returned this way, never raised, by every planner. That includes an object
        with no stable grasp inside the workspaces at θ = 0 (``start=None`` included):
        ``exhausted=True`` and a reason beginning "no stable grasp lies inside the
        workspaces at theta = 0".

    Raises
    ------
    GraspGaitInputError
        An unknown ``name``, or a ``start`` that is not a legal grasp at ``k = 0``.
    """
    fn = get_planner(name)
    if start is None and name not in CHOOSE_OWN_START and legal_start_exists(model):
        start = default_start(model)
    # with start=None and no legal start, every planner returns its no-gait verdict
    return fn(model, start, turn_deg)
