"""The greedy reading of the reach look-ahead, as a policy of any GraspGait env.

No learning: the move the reach look-ahead (``regrasp_lookahead = D``, the observation's
``reach`` field, beyond the thesis) ranks first, in the order of
:func:`~graspgait_env.envs.observation.greedy_ranks`: a rotation that completes the turn
when one is legal, else the legal move falling least short of the turn ``D - 1`` regrasps
deep, then ``D - 2``, ... 0 (ties: a regrasp before a rotation, a shorter rotation first,
then the action order). It is the benchmark's ``greedy-reach:D`` policy and the least
``reach_rank`` of a dict observation's ``actions`` part (tested equal), so it is what an
agent that reads the look-ahead gets without learning: ``graspgait evaluate MODEL
--reading`` plays it from the model's own starts beside the model.

It reads the observation only (and the env's fixed layout, hand and turn), never the
gait state or the optimum.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from graspgait_env.envs.observation import greedy_ranks
from graspgait_env.errors import GraspGaitInputError

__all__ = ["greedy_reading", "greedy_reading_batch"]

Predict = Callable[[Any, np.ndarray], int]


def _depth(env: Any) -> int:
    depth = int(env.unwrapped.config.regrasp_lookahead)
    if depth < 1:
        raise GraspGaitInputError(
            "regrasp_lookahead=0: the greedy reading reads the reach look-ahead; make the "
            "env with regrasp_lookahead: 1 or more (e.g. 8, as the general agent)")
    return depth


def greedy_reading(env: Any) -> Predict:
    """``predict(observation, action_mask) -> action``: the greedy reading (module
    docstring) of ``env``'s reach look-ahead, for any ``observation_mode``.

    Parameters
    ----------
    env
        A GraspGait env (wrapped or not) made with ``regrasp_lookahead >= 1``; the
        predictor reads its layout, hand and turn from ``env.unwrapped`` at every call,
        so it follows ``GraspGaitRandom-v0``'s object changes.

    Returns
    -------
    callable
        ``predict(obs, mask)``: ``obs`` one observation of ``env`` (a box or flat vector,
        or a dict of named parts), ``mask`` its legal moves; returns the action (0 when
        no move is legal).

    Raises
    ------
    GraspGaitInputError
        ``env`` has no reach look-ahead (``regrasp_lookahead`` 0).
    """
    u = env.unwrapped
    depth = _depth(env)
    mode = u.config.observation_mode

    def from_rank(actions: np.ndarray, legal: np.ndarray) -> int:
        rank = np.asarray(actions)[:, u.layout.feature("reach_rank")]
        return int(np.argmin(np.where(legal, rank, np.inf)))

    def predict(obs: Any, mask: np.ndarray) -> int:
        legal = np.asarray(mask, dtype=bool)
        if not legal.any():
            return 0
        if mode == "dict":
            return from_rank(obs["actions"], legal)
        if mode == "flat":
            return from_rank(u.layout.unflatten(np.asarray(obs))["actions"], legal)
        model, lay = u.model, u.layout
        R2, P2 = 2 * model.R, 2 * model.P
        box = np.asarray(obs)
        keys = box[lay.reach].reshape(P2 + R2, depth)
        reach = np.concatenate((keys[P2:], keys[:P2]))[None]  # the action order
        K = abs(model.turn_steps(u.config.turn_deg))
        sign = 1 if u.config.turn_deg > 0 else -1
        delta = np.asarray(u._rot_delta, dtype=np.int64)
        finishing = np.zeros((1, R2 + P2), dtype=bool)
        finishing[0, :R2] = legal[:R2] & (float(box[lay.achieved]) * K + sign * delta
                                          >= K - 0.5)
        none = int(round(float(u.box_space.high[lay.reach.start]) * K))
        ranks = greedy_ranks(reach, finishing, legal[None], delta, K, none)
        return int(np.argmin(ranks[0]))
    return predict


def greedy_reading_batch(env: Any) -> Callable[[Any, np.ndarray], np.ndarray]:
    """``predict_batch(observations, action_masks) -> actions``: :func:`greedy_reading`
    for a batch of observations of ``env``'s dict or flat mode (the least ``reach_rank``
    of each row's legal moves; 0 for a row without one), for the batched env of the same
    settings.

    Raises
    ------
    GraspGaitInputError
        ``env`` has no reach look-ahead, or observes a box vector (which has no
        ``reach_rank``: play :func:`greedy_reading` one episode at a time).
    """
    u = env.unwrapped
    _depth(env)
    mode = u.config.observation_mode
    if mode not in ("dict", "flat"):
        raise GraspGaitInputError(
            f"observation_mode={mode!r}: the batched greedy reading reads reach_rank, which "
            "the dict and flat observations have; use greedy_reading episode by episode")
    col = u.layout.feature("reach_rank")

    def predict_batch(obs: Any, masks: np.ndarray) -> np.ndarray:
        actions = obs["actions"] if mode == "dict" else u.layout.unflatten(np.asarray(obs))[
            "actions"]
        rank = np.asarray(actions)[..., col]
        return np.where(np.asarray(masks, dtype=bool), rank, np.inf).argmin(axis=-1)
    return predict_batch
