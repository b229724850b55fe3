"""Where an agent's regrasps beyond the optimum go: each move priced against the exact optimum.

The exact planner's table of the fewest regrasps to the goal from every state
(:class:`graspgait_env.planners.exact.RegraspsToGo`, ``G(s)``; 0 once the turn is
reached) prices every move of a played gait. A move ``s -> t`` costs ``c`` regrasps
(1 for a regrasp, 0 for a rotation, thesis 5.4's count) and its **excess** is

    ``excess = c + G(t) - G(s)  >= 0``

(``>= 0`` because from ``s`` the move could be followed by an optimal gait from ``t``).
Summed over an episode that reaches the turn from a start with a gait, the excesses
telescope to ``regrasps - G(start)``: the agent's regrasps beyond the optimum's, split
move by move. Three kinds of move carry excess:

- an **idle regrasp**: ``G(t) == G(s)``, a regrasp that brings the goal no closer
  (excess 1); the optimum's regrasps lower ``G`` by one each;
- a **losing regrasp**: ``G(t) > G(s)``, after which the optimum needs more regrasps
  than before (excess ``1 + G(t) - G(s)``);
- a **losing rotation**: a rotation with ``G(t) > G(s)`` (a rotation never lowers
  ``G``: it is free, so the optimum from ``s`` could make it).

With a look-ahead of ``D`` regrasps (the env's ``regrasp_lookahead``), the excess of the
moves made from states with ``G(s) > D`` is also counted apart
(``excess_beyond_lookahead``): from such a state no chain the look-ahead reads reaches
the turn, so a policy that reads it cannot tell an optimal regrasp by the goal alone.
Choice: with ``D = 0`` (no look-ahead) the count is that of every move from a state
that needs a regrasp; a regrasp wasted where a rotation alone reaches the turn
(``G(s) = 0``) is never beyond sight, since the env's ``actions`` part says which
rotations reach it.

A move into a state with no gait left (``G(t) = -1``, e.g. past the turn's window
backwards) ends the pricing of the episode there (``lost_gait_at``).

Choices, stated where the thesis is silent: ``G`` is the optimum over the env's gait
model without the env's episode rules (``forbid_revisit``, ``forbid_reversal``: they do
not change the fewest regrasps from a state, see the env's *Arguments*), over
:class:`~graspgait_env.agents.evaluate.ReferenceGaits`'s window (one turn against the requested
one);
a state past the turn counts as ``G = 0``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState

__all__ = ["audit_moves", "summarize_audits", "beyond_lookahead_clause", "AUDIT_KEYS"]

AUDIT_KEYS: tuple[str, ...] = ("excess_regrasps", "idle_regrasps", "losing_regrasps",
                               "excess_of_losing_regrasps", "losing_rotations",
                               "excess_of_losing_rotations", "excess_beyond_lookahead")
"""The counts of :func:`audit_moves` that :func:`summarize_audits` sums."""


def audit_moves(model: GaitModel, states: Sequence[GaitState], turn_deg: float,
                to_go: Callable[[GaitState], int | None], lookahead: int = 0
                ) -> dict[str, Any]:
    """Price each move of a played gait against the optimum (see the module docstring).

    Parameters
    ----------
    model
        The gait model the gait was played on (the env's ``unwrapped.model``).
    states
        The gait states of the episode, the start first, one per move (an illegal no-op
        adds none).
    turn_deg
        The requested turn (degrees, counter-clockwise positive); a state at or past it
        has ``G = 0``.
    to_go
        ``to_go(state)``: the optimum's fewest regrasps from ``state``, None where no gait
        exists (:meth:`graspgait_env.agents.evaluate.ReferenceGaits.to_go`).
    lookahead
        ``D``, the regrasps the policy's look-ahead reads (the env's
        ``regrasp_lookahead``; 0: none): the excess of the moves from states with
        ``G(s) > D`` is summed in ``excess_beyond_lookahead`` as well.

    Returns
    -------
    dict
        ``to_go_start`` (``G`` of the start; None: no gait), the counts of
        :data:`AUDIT_KEYS` over the priced moves, ``lost_gait_at`` (index of the first
        move into a state without a gait, or None) and ``first_loss``: the first move
        with excess, as ``{"move": i, "kind": "regrasp"|"rotation", "from": state
        description, "to": state description, "to_go_before": G(s), "to_go_after":
        G(t)}``, or None.
    """
    if isinstance(lookahead, bool) or not isinstance(lookahead, (int, np.integer)) \
            or lookahead < 0:
        raise GraspGaitInputError(
            f"lookahead={lookahead!r}: the look-ahead's depth in regrasps, an int >= 0 "
            "(the env's regrasp_lookahead; 0 for none)")
    K = model.turn_steps(turn_deg)
    sign = 1 if K >= 0 else -1

    def g(s: GaitState) -> int | None:
        if sign * s.k >= sign * K:
            return 0
        return to_go(s)

    out: dict[str, Any] = {key: 0 for key in AUDIT_KEYS}
    out.update(to_go_start=None, lost_gait_at=None, first_loss=None)
    if not states:
        return out
    before = g(states[0])
    out["to_go_start"] = before
    if before is None:
        return out
    for i, (s, t) in enumerate(zip(states[:-1], states[1:], strict=True)):
        after = g(t)
        if after is None:
            out["lost_gait_at"] = i
            break
        regrasp = t.contacts != s.contacts
        excess = int(regrasp) + after - before
        if excess > 0:
            if regrasp and after == before:
                out["idle_regrasps"] += 1
            elif regrasp:
                out["losing_regrasps"] += 1
                out["excess_of_losing_regrasps"] += excess
            else:
                out["losing_rotations"] += 1
                out["excess_of_losing_rotations"] += excess
            out["excess_regrasps"] += excess
            if before > lookahead:
                out["excess_beyond_lookahead"] += excess
            if out["first_loss"] is None:
                out["first_loss"] = {"move": i, "kind": "regrasp" if regrasp else "rotation",
                                     "from": model.describe_state(s),
                                     "to": model.describe_state(t),
                                     "to_go_before": before, "to_go_after": after}
        before = after
    return out


def summarize_audits(audits: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Sum :func:`audit_moves` results: the :data:`AUDIT_KEYS` counts and ``episodes``
    (how many were summed). Give the audits of the episodes to compare, e.g. the
    successful ones from solvable starts, whose ``excess_regrasps`` add up to the agent's
    regrasps less the optimum's."""
    total: dict[str, Any] = {key: sum(int(a[key]) for a in audits) for key in AUDIT_KEYS}
    total["episodes"] = len(audits)
    return total


def beyond_lookahead_clause(audit: Mapping[str, Any]) -> str:
    """The words that ``graspgait evaluate --audit`` and the model card add after the
    split into kinds: ``"; N of them from states farther from the goal than the
    look-ahead reads"``, or ``""`` for an audit written before ``excess_beyond_lookahead``
    was counted (saying nothing rather than 0)."""
    if "excess_beyond_lookahead" not in audit:
        return ""
    return (f"; {audit['excess_beyond_lookahead']} of them from states farther from the goal "
            "than the look-ahead reads")
