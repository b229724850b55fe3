"""Gymnasium wrappers: for agents that cannot mask actions (plain PPO, RL Zoo, CleanRL),
and start distributions for training (``TrainConfig.train_wrappers``)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

__all__ = ["LegalActionWrapper", "RuleBasedStartWrapper", "SolvableStartWrapper",
           "legal_substitute", "rule_based_starts"]


def legal_substitute(action: int, mask: NDArray[np.bool_], group: NDArray[np.int64]) -> int:
    """The legal action nearest to ``action`` in index, preferring its own group.

    Parameters
    ----------
    action
        The requested action index.
    mask
        Legal actions (bool, one per action).
    group
        Group of each action (see :class:`LegalActionWrapper`).

    Returns
    -------
    int
        ``action`` itself when legal; else the legal action of the same group with the
        nearest index (ties: the lower index); else, when the group has no legal action,
        the nearest legal action of any group; else (no legal action at all) ``action``.

    Examples
    --------
    >>> mask = np.array([True, True, False, False, True, False])
    >>> group = np.array([0, 0, 0, 1, 1, 1])
    >>> legal_substitute(2, mask, group), legal_substitute(5, mask, group)
    (1, 4)
    >>> legal_substitute(3, np.zeros(6, bool), group)
    3
    """
    if mask[action]:
        return action
    legal = np.flatnonzero(mask)
    if legal.size == 0:
        return action
    same = legal[group[legal] == group[action]]
    pool = same if same.size else legal
    return int(pool[np.argmin(np.abs(pool - action))])


class LegalActionWrapper(gym.Wrapper):
    r"""Plays the nearest legal move in place of an illegal one, for agents without masks.

    ## Description

    A GraspGait env answers an illegal action with a penalized no-op; an agent that
    cannot read the mask (SB3's plain PPO, RL Zoo, CleanRL, RLlib without action masking)
    spends its episodes on them: plain PPO on ``GraspGait-v0`` stayed at 0% success for
    200k steps, its episodes running to the 500-step limit (issue 11). This wrapper makes
    every action a move: an illegal action is replaced by the legal action nearest to it
    in the action layout, first within its own group:

    | Group | Actions           | Meaning of "nearest"                                  |
    |-------|-------------------|-------------------------------------------------------|
    | 0     | ``0 .. R-1``      | the legal counter-clockwise rotation closest in size  |
    | 1     | ``R .. 2R-1``     | the legal clockwise rotation closest in size          |
    | 2     | ``2R + 2p``       | regrasp lifting the lower-numbered finger: the legal  |
    |       |                   | one whose workspace position ``p`` is closest         |
    | 3     | ``2R + 2p + 1``   | the same, lifting the higher-numbered finger          |

    and, when the group has no legal action, the legal action nearest in index of any
    group (:func:`legal_substitute`). So "rotate counter-clockwise by the most" becomes
    the largest legal counter-clockwise rotation, and "regrasp at p" the nearest legal
    regrasp point: the map from a wish to a move is fixed and part of the env's
    dynamics, which PPO learns like any other. The legal moves are those of the wrapped
    env's ``action_masks()`` (for ``GraspGaitMujoco-v1`` the estimate-based mask).

    ## Action Space, Observation Space, Rewards

    Those of the wrapped env, unchanged; the ``illegal`` reward term is therefore always
    0 (no illegal move is ever played).

    ## Info

    The wrapped env's keys plus ``requested_action`` (what the agent asked for) and
    ``action_substituted`` (True when it was illegal and replaced).

    ## Arguments

    ``LegalActionWrapper(env)``: a GraspGait env (any id; wrapped or not). RL Zoo:
    ``env_wrapper: graspgait_env.agents.wrappers.LegalActionWrapper`` (configs/rlzoo/ppo.yml).

    ## Version History

    - v0: initial version.
    """

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self._group: NDArray[np.int64] | None = None

    def _groups(self) -> NDArray[np.int64]:
        model = self.env.unwrapped.model
        A, R = int(model.n_actions), int(model.R)
        a = np.arange(A)
        group = np.where(a < R, 0, np.where(a < 2 * R, 1, 2 + (a - 2 * R) % 2))
        return group.astype(np.int64)

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset the wrapped env (the action layout is re-read: the hand may change)."""
        obs, info = self.env.reset(seed=seed, options=options)
        self._group = self._groups()
        return obs, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Play ``action`` if legal, else its nearest legal substitute (class docstring)."""
        if self._group is None:
            return self.env.step(action)  # before reset: the env raises ResetNeededError
        a = int(np.asarray(action).reshape(()))
        if not 0 <= a < self._group.size:
            return self.env.step(action)  # out of range: the env names the bad action
        mask = self.env.unwrapped.action_masks()
        played = legal_substitute(a, mask, self._group)
        obs, reward, terminated, truncated, info = self.env.step(np.int64(played))
        info["requested_action"] = a
        info["action_substituted"] = played != a
        return obs, reward, terminated, truncated, info


_START_REDRAWS = 64  # resets tried before giving up on a start with a gait


class SolvableStartWrapper(gym.Wrapper):
    r"""Redraws the start grasp until a gait exists from it.

    ## Description

    ``GraspGait-v0`` draws its start grasp uniformly among the legal grasps at θ = 0
    with a legal move, and from some of them no gait reaches the requested turn (on the
    ellipse at mu 0.7, 165 of its 2289 starts; the exact planner proves it). Those episodes
    can only fail, so a success rate over the env's own draws is capped below 100%
    (with RL Zoo's ``enjoy`` and its seed 0, 6 of the first 42 starts of the ellipse
    have no gait: at most 85.7%). This wrapper resets again (without a seed, so the
    sequence stays a function of the first reset's seed) until the start has a gait,
    so that success is measured, and trained for, over the starts from which a gait
    exists: the measure ``graspgait evaluate`` reports as ``success_rate_solvable``.

    A gait exists when the rule-based method (thesis 6.5, milliseconds) finds one, else
    when the exact planner (:func:`graspgait_env.planners.exact.optimal_gait`) does; the
    answers are cached per grasp map and start
    (:class:`graspgait_env.agents.evaluate.ReferenceGaits`).

    ## Action Space, Observation Space, Rewards, Episode End

    Those of the wrapped env, unchanged.

    ## Starting State

    A start of the wrapped env from which a gait exists. ``reset(options={"start": ...})``
    is kept as given (a chosen start is never replaced). After 64 draws without a gait,
    ``RuntimeError`` names the object and ``mu``.

    ## Info

    The reset ``info`` of the wrapped env plus ``start_redraws`` (resets made beyond the
    first).

    ## Arguments

    ``SolvableStartWrapper(env)``: a GraspGait env (any id). RL Zoo: listed under
    ``env_wrapper`` (configs/rlzoo/ppo.yml).

    ## Version History

    - v0: initial version.
    """

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        from graspgait_env.agents.evaluate import ReferenceGaits

        self._refs = ReferenceGaits()

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset, then reset again until a gait exists from the start (class docstring)."""
        obs, info = self.env.reset(seed=seed, options=options)
        if options and "start" in options:
            info["start_redraws"] = 0
            return obs, info
        u = self.env.unwrapped
        turn = float(u.config.turn_deg)
        for redraws in range(_START_REDRAWS):
            if self._refs.gait_exists(u.model, u.state, turn):
                info["start_redraws"] = redraws
                return obs, info
            obs, info = self.env.reset(options=options)
        raise RuntimeError(
            f"object {u.model.shape.name!r} at mu={u.model.mu:g}: {_START_REDRAWS} start "
            f"grasps in a row had no gait turning it {turn:g} deg; raise mu or use "
            "another object")


_RULE_STARTS: dict[tuple, list[Any]] = {}  # grasp map key -> its rule-based gaits' starts


def rule_based_starts(model: Any, turn_deg: float) -> list[Any]:
    """The start grasps of ``model`` (``model.start_states()``, the env's draws) from
    which the rule-based method (thesis 6.5) finds a gait turning ``turn_deg``.

    Computed once per grasp map and turn in a process (one rule-based plan per start:
    8 s for the hexagon's 582 starts under the hand's contact model, of which 35
    qualify) and cached.
    """
    from graspgait_env.agents.evaluate import ReferenceGaits
    from graspgait_env.planners.rule_based import rule_based

    key = (ReferenceGaits().model_key(model), model.turn_steps(turn_deg))
    found = _RULE_STARTS.get(key)
    if found is None:
        found = _RULE_STARTS[key] = [s for s in model.start_states()
                                     if rule_based(model, s, turn_deg).success]
    return found


class RuleBasedStartWrapper(gym.Wrapper):
    r"""Draws a quarter of the starts among those from which the rule-based gait exists.

    ## Description

    A training start distribution (``TrainConfig.train_wrappers``; evaluation runs
    without it). Under the hand's contact model the rule-based method (thesis 6.5)
    finds a gait from 35 of the hexagon's 582 start grasps, and from those its gait is
    the optimum and cheaper than the gaits from the other starts (19 regrasps against
    about 24). An agent trained on the env's own draws meets them too rarely to learn
    their gait. With probability :attr:`fraction` this wrapper replaces the env's start
    by one of those, drawn uniformly (:func:`rule_based_starts`, enumerated once per
    grasp map and process).

    ## Action Space, Observation Space, Rewards, Episode End

    Those of the wrapped env, unchanged.

    ## Starting State

    With probability :attr:`fraction` (drawn from the env's ``np_random``, so a seeded
    reset stays reproducible) a start from which the rule-based method finds a gait;
    else the env's own. ``reset(options={"start": ...})`` is kept as given, and so is
    the env's start on an object from which the rule-based method finds no gait.

    ## Info

    The reset ``info`` of the wrapped env plus ``rule_based_start`` (bool: the start was
    chosen by this wrapper).

    ## Arguments

    ``RuleBasedStartWrapper(env)``: a ``GraspGait-v0`` env. Subclass to change
    :attr:`fraction`.

    ## Version History

    - v0: initial version.
    """

    fraction: float = 0.25
    """Probability that a reset draws a start where the rule-based gait exists."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self._model: Any = None  # the grasp map whose starts _starts holds
        self._starts: list[Any] = []

    def _rule_starts(self) -> list[Any]:
        """The rule-based gait's starts of the env's present model (looked up once per
        model, not per reset)."""
        u = self.env.unwrapped
        if u.model is not self._model:
            self._model = u.model
            self._starts = rule_based_starts(u.model, float(u.config.turn_deg))
        return self._starts

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Reset; with probability :attr:`fraction`, from a rule-based gait's start."""
        obs, info = self.env.reset(seed=seed, options=options)
        info["rule_based_start"] = False
        if (options and "start" in options) or self.np_random.random() >= self.fraction:
            return obs, info
        starts = self._rule_starts()
        if not starts:
            return obs, info
        start = starts[int(self.np_random.integers(len(starts)))]
        obs, info = self.env.reset(options={**(options or {}), "start": start})
        info["rule_based_start"] = True
        return obs, info
