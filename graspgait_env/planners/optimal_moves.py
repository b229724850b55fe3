"""The moves of a fewest-regrasp gait, read state by state (beyond the thesis).

The thesis's planners (ch. 5–6) return one gait from one start. A learner that imitates
the optimum needs more: from *any* state it reaches, which moves still begin a gait with
the fewest regrasps? :class:`RegraspsToGo` gives every state's count ``L``, so the answer
is a local rule:

- ``L > 0``, a regrasp (thesis 4.2) that lowers the count to ``L - 1`` is legal here:
  those regrasps;
- ``L > 0``, none is legal here: the rotations (thesis 5.2) landing on an object angle of
  this grasp where one is; when no rotation reaches such an angle, the longest rotation
  towards the nearest of them (ties: the one towards the turn);
- ``L = 0`` (this grasp rotates through the turn): the longest legal rotation towards
  the turn;
- ``L = -1`` (no gait within the window): none.

Rotations stay inside the grasp's finger pair box, so they keep the count (every state
of a segment has the same one, see :class:`RegraspsToGo`). Following any move of the set
from a start with ``L`` regrasps to go therefore ends the turn with exactly ``L``
regrasps: each regrasp lowers the count by one, and between regrasps every rotation
brings the object strictly closer to an angle where the next one is legal (tested).

Choice (tested): rotations count as free, as in the exact planner; among optimal
rotations the set keeps every one that lands on an optimal regrasp, since they are all
equally good by the regrasp count, and only the single longest one when the object must
travel further. At ``L = 0`` only the longest rotation towards the turn is in the set, so
a policy that imitates the set finishes in the fewest rotations the grasp allows.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.exact import RegraspsToGo

__all__ = ["OptimalMoves"]

SEGMENT_CACHE = 4096  # segments (grasp, lowest angle) whose optimal regrasps are kept


class OptimalMoves:
    """The moves that begin a fewest-regrasp gait from a state, for one model and turn.

    Parameters
    ----------
    model
        The gait model.
    turn_deg
        Requested turn (degrees; negative: clockwise).
    max_backward_deg
        How far against the turn the search window reaches (degrees, > 0), as for
        :class:`RegraspsToGo`.
    to_go
        A :class:`RegraspsToGo` of the same model, turn and window to reuse (an env that
        already prices regrasps against the optimum has one); built when None.

    Examples
    --------
    >>> from graspgait_env.gait import GaitModel
    >>> model = GaitModel("ellipse", 0.7)
    >>> moves = OptimalMoves(model, 360.0)
    >>> start = model.start_state({1: 50.0, 3: 270.0})
    >>> states = moves.gait(start)
    >>> sum(a.contacts != b.contacts for a, b in zip(states, states[1:])) == moves.to_go(start)
    True
    """

    def __init__(self, model: GaitModel, turn_deg: float = 360.0,
                 max_backward_deg: float = 360.0, to_go: RegraspsToGo | None = None) -> None:
        if to_go is None:
            to_go = RegraspsToGo(model, turn_deg, max_backward_deg)
        elif to_go.model is not model or to_go.turn_steps != model.turn_steps(turn_deg):
            raise GraspGaitInputError(
                "to_go: a RegraspsToGo of another model or turn; pass one built with "
                f"RegraspsToGo(model, {turn_deg!r}, ...) or None")
        self.model, self.to_go = model, to_go
        self.turn_steps = to_go.turn_steps
        self.sign = 1 if self.turn_steps >= 0 else -1
        R = model.R
        # the signed rotation of every rotation action (GaitModel.decode: a + 1, then
        # -(a - R + 1))
        self.rotation_delta = np.concatenate((np.arange(1, R + 1), -np.arange(1, R + 1)))
        self._segments: OrderedDict[tuple, dict[int, list[int]]] = OrderedDict()

    # ------------------------------------------------------------------ per grasp
    def _optimal_regrasps(self, s: GaitState, L: int) -> dict[int, list[int]]:
        """Object angle ``k`` of ``s``'s segment -> the regrasp actions there that lower
        the count from ``L`` to ``L - 1`` (only angles that have one). Cached per segment:
        the grasp and its lowest angle (the same contacts a full turn apart are another
        segment, with other workspace positions)."""
        model, to_go, R = self.model, self.to_go, self.model.R
        ccw, cw = model.state_rotation_room(s)
        key = (s.contacts, s.k - cw)
        hit = self._segments.get(key)
        if hit is not None:
            self._segments.move_to_end(key)
            return hit
        good: dict[int, list[int]] = {}
        for k in range(s.k - cw, s.k + ccw + 1):
            t = GaitState(k, s.contacts)
            regrasps = np.flatnonzero(model.action_mask(t)[2 * R:]) + 2 * R
            best = [int(a) for a in regrasps if to_go(model.apply(t, int(a))) == L - 1]
            if best:
                good[k] = best
        self._segments[key] = good
        if len(self._segments) > SEGMENT_CACHE:
            self._segments.popitem(last=False)
        return good

    # ------------------------------------------------------------------ public
    def __call__(self, state: GaitState) -> NDArray[np.bool_]:
        """The optimal moves of ``state`` as a mask over the model's actions (shape
        ``(model.n_actions,)``; every True entry is legal in ``state``). All False when no
        gait exists from ``state`` within the window.

        Raises
        ------
        GraspGaitInputError
            ``state`` is not a legal state of the model (two fingers in force closure,
            each inside its workspace).
        """
        model = self.model
        if not model.is_legal_state(state):
            raise GraspGaitInputError(
                f"state={state!r}: not a legal state of this model (two held contacts in "
                "force closure inside their workspaces); give a state the env or "
                "GaitModel.apply reached")
        out = np.zeros(model.n_actions, dtype=bool)
        L = self.to_go(state)
        if L < 0:
            return out
        R, k, sign = model.R, int(state.k), self.sign
        ccw, cw = model.state_rotation_room(state)
        room = np.concatenate((np.arange(1, R + 1) <= ccw, np.arange(1, R + 1) <= cw))
        delta = self.rotation_delta
        if L == 0:  # the longest rotation towards the turn
            toward = np.flatnonzero(room & (delta * sign > 0))
            if toward.size:
                out[toward[np.argmax(np.abs(delta[toward]))]] = True
            return out
        good = self._optimal_regrasps(state, L)
        if k in good:
            out[good[k]] = True
            return out
        lands = room & np.isin(k + delta, np.fromiter(good, dtype=np.int64, count=len(good)))
        if lands.any():
            out[:2 * R] = lands
            return out
        target = min(good, key=lambda kk: (abs(kk - k), -(kk - k) * sign))
        step = int(np.clip(target - k, -R, R))
        out[step - 1 if step > 0 else R - step - 1] = True
        return out

    def action(self, state: GaitState) -> int:
        """One optimal move of ``state``: its first optimal regrasp, else its longest
        optimal rotation. Raises :class:`GraspGaitInputError` when no gait exists."""
        mask = self(state)
        R = self.model.R
        regrasps = np.flatnonzero(mask[2 * R:])
        if regrasps.size:
            return int(regrasps[0]) + 2 * R
        rotations = np.flatnonzero(mask[:2 * R])
        if not rotations.size:
            raise GraspGaitInputError(
                f"state={state!r}: no gait reaches the turn from it within the window; "
                "check to_go(state) >= 0 first")
        return int(rotations[np.argmax(np.abs(self.rotation_delta[rotations]))])

    def gait(self, start: GaitState) -> list[GaitState]:
        """The states of the gait that :meth:`action` follows from ``start`` until the
        object has turned ``turn_deg`` (``start`` first); ``to_go(start)`` regrasps."""
        states, s = [start], start
        K, sign = self.turn_steps, self.sign
        seg = self.to_go._seg
        # each regrasp lowers the count and each rotation nears its next angle: a bound
        most = (max(self.to_go(start), 0) + 1) * (seg.k_hi - seg.k_lo + 2)
        while (s.k - K) * sign < 0:
            if len(states) > most:
                raise RuntimeError(f"gait from {start!r}: no end after {most} moves")
            s = self.model.apply(s, self.action(s))
            states.append(s)
        return states
