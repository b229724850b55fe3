"""What every planner returns: a plan or a reasoned "no gait", with its search statistics."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from graspgait_env.plan import Plan

__all__ = ["PlannerResult"]


@dataclass
class PlannerResult:
    """Outcome of one planner run.

    Attributes
    ----------
    planner
        Planner name as the CLI spells it (``"optimal"``, ``"best-first"``, ...).
    plan
        The gait, or ``None`` when none was found.
    reason
        Why there is no plan (empty when there is one): a diagnosis in words.
    nodes_opened
        Nodes expanded (thesis 5.5: "explored as a possible path").
    nodes_created
        Nodes generated.
    path_length
        States in the final path after the start (regrasps + rotations, thesis 5.4).
    regrasps
        Regrasp steps in the plan.
    rotation_deg
        Net rotation the plan achieves (degrees, CCW positive).
    max_turn_deg
        Largest turn the search reached (degrees), with or without a plan.
    wall_time_s
        Wall-clock time of the search (s).
    pattern
        Gait pattern when known: ``staircase``, ``plus``, ``combined`` (thesis fig. 6.10).
    exhausted
        True when the search proved that no gait exists in its state space (as opposed
        to stopping at a node limit).
    """

    planner: str
    plan: Plan | None
    reason: str = ""
    nodes_opened: int = 0
    nodes_created: int = 0
    path_length: int = 0
    regrasps: int = 0
    rotation_deg: float = 0.0
    max_turn_deg: float = 0.0
    wall_time_s: float = 0.0
    pattern: str = ""
    exhausted: bool = False
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """A plan was found."""
        return self.plan is not None

    def stats(self) -> dict[str, Any]:
        """The statistics as a flat dict (for the plan JSON's ``stats`` and the bench)."""
        d = asdict(self)
        d.pop("plan")
        extra = d.pop("extra")
        d.update(extra)
        return d
