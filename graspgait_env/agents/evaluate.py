"""Evaluate a trained agent against the thesis's rule-based gait and the exact optimum.

Protocol. Episode ``i`` starts with ``env.reset(seed=seed + i)``: a start grasp at
θ = 0 drawn by the env (and, in ``GraspGaitRandom-v0``, an object and ``mu``). The agent
plays until the episode ends (success, dead end, wrong way, or the 500-step limit).
From the same start grasp, under the same gait model (object, ``mu``, hand, grid and
contact model: the env's own ``model``), the exact planner
(:func:`graspgait_env.planners.exact.optimal_gait`, the fewest regrasps) and the
thesis's rule-based method (:func:`graspgait_env.planners.rule_based.rule_based`, 6.5)
plan the same turn. The env draws some starts from which no gait exists (the exact
planner proves it); the success rate is reported over all episodes and over the
*solvable* starts, those with a gait.

Averages (the choice made here, where "mean regrasps" could mean several things):

- ``mean_regrasps``: the agent's regrasps over its **successful** episodes;
- ``mean_optimal_regrasps``: the optimum's regrasps over the **same** episodes, so
  ``regrasps_vs_optimal = mean_regrasps / mean_optimal_regrasps`` compares like with
  like (and is >= 1: no agent beats the optimum);
- ``mean_rule_regrasps``: the rule-based gait's regrasps over the agent's successful
  episodes from which the rule-based method also found a gait, with
  ``regrasps_vs_rule`` the agent's mean over those same episodes divided by it.

Optima and rule-based gaits are cached per (grasp map, hand grid, start, turn)
(:class:`ReferenceGaits`), so repeated evaluations (training's periodic evaluation)
pay for each start once.

Speed. With greedy actions in ``GraspGait-v0`` without wrappers, the episodes are played
side by side in the batched env (:func:`run_episodes_batched`,
:class:`~graspgait_env.envs.vector_env.GraspGaitVectorEnv`: the same transitions as the
single env, seed for seed), one policy call per step for all of them; the records are
those of :func:`run_episodes` (tested), in a fraction of the time.
"""

from __future__ import annotations

import hashlib
import json
import os
import statistics
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm.auto import tqdm

from graspgait_env.agents.audit import audit_moves, beyond_lookahead_clause, summarize_audits
from graspgait_env.agents.card import load_agent
from graspgait_env.agents.envs import contact_model_of, env_kwargs_for, make_env
from graspgait_env.agents.seeding import seed_everything
from graspgait_env.atomic import json_ready, write_text_atomic
from graspgait_env.envs.config import check_count, check_mu, check_object
from graspgait_env.envs.reading import greedy_reading, greedy_reading_batch
from graspgait_env.envs.registration import ENV_IDS
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState

__all__ = ["ReferenceGaits", "evaluate", "play_episode", "run_episodes", "run_episodes_batched",
           "batched_eval_env", "summarize_episodes", "write_evaluation", "EVAL_SEED",
           "EVAL_BATCH", "agent_predictor", "agent_batch_predictor", "compare_with_reading"]

EVAL_SEED = 10_000  # first reset seed of training's periodic evaluation (fixed starts)
EVAL_BATCH = 100  # episodes played side by side by run_episodes_batched


class ReferenceGaits:
    """Regrasps of the exact optimum and of the rule-based gait per start, cached.

    The key is the gait model's grasp map (its bytes' digest), its hand grid, the start
    contacts and the turn in grid steps: everything the planners read.

    The optimum's count is read from one
    :class:`~graspgait_env.planners.exact.RegraspsToGo` table per model and turn, with
    the window of :func:`~graspgait_env.planners.exact.optimal_gait` (one full turn
    against the requested one), so it equals ``optimal_gait(model, start,
    turn_deg).regrasps`` (tested) at the cost of one search per model instead of one
    per start (measured: 100 ellipse starts cost 44 s of exact searches one by one;
    ``graspgait evaluate`` of the hexagon agent then shipped, 100 episodes, went from 72 s
    to 14 s with the same records).
    """

    def __init__(self) -> None:
        self._cache: dict[tuple, tuple[int | None, int | None]] = {}
        self._exists: dict[tuple, bool] = {}
        self._digests: dict[int, tuple[GaitModel, str]] = {}
        self._tables: dict[tuple, Any] = {}

    def optimal_regrasps(self, model: GaitModel, start: GaitState,
                         turn_deg: float) -> int | None:
        """The exact optimum's regrasps for the turn from ``start`` (None: no gait), from
        the model's cached table (:class:`~graspgait_env.planners.exact.RegraspsToGo`
        over ``optimal_gait``'s window)."""
        return self.to_go(model, start, turn_deg)

    def to_go(self, model: GaitModel, state: GaitState, turn_deg: float) -> int | None:
        """The optimum's fewest regrasps for the turn from any gait state ``state`` (None:
        no gait from it, or it lies outside the window), from the same cached table as
        :meth:`optimal_regrasps` (:mod:`graspgait_env.agents.audit` prices moves with it)."""
        from graspgait_env.planners.exact import RegraspsToGo

        key = (self._model_key(model), model.turn_steps(turn_deg))
        table = self._tables.get(key)
        if table is None:
            if len(self._tables) >= 16:  # GraspGaitRandom-v0 makes a model per reset
                self._tables.clear()
            # optimal_gait searches one full turn (n grid steps, 360 deg) against the turn
            table = self._tables[key] = RegraspsToGo(model, turn_deg, 360.0)
        g = table(state)
        return None if g < 0 else int(g)

    def model_key(self, model: GaitModel) -> tuple:
        """A hashable key of what the planners read of ``model`` (its grasp map's
        digest, grid and hand workspaces)."""
        return self._model_key(model)

    def _model_key(self, model: GaitModel) -> tuple:
        held = self._digests.get(id(model))
        if held is None or held[0] is not model:
            digest = hashlib.sha1(np.packbits(model.stable).tobytes()).hexdigest()
            self._digests[id(model)] = held = (model, digest)
            if len(self._digests) > 256:  # GraspGaitRandom-v0 makes a model per reset
                self._digests = {id(model): held}
        return (held[1], model.n, tuple(int(x) for x in model.ws_start),
                tuple(int(x) for x in model.ws_width))

    def _key(self, model: GaitModel, start: GaitState, turn_deg: float) -> tuple:
        return (self._model_key(model), tuple(start.contacts), model.turn_steps(turn_deg))

    def gait_exists(self, model: GaitModel, start: GaitState, turn_deg: float) -> bool:
        """Whether a gait turns the object ``turn_deg`` from ``start``, decided cheaply.

        The rule-based method first (milliseconds; a plan it finds is a proof), the exact
        planner only when it finds none (its "no gait" is a proof over its window).
        """
        from graspgait_env.planners.rule_based import rule_based

        key = self._key(model, start, turn_deg)
        hit = self._cache.get(key)
        if hit is not None:
            return hit[0] is not None
        exists = self._exists.get(key)
        if exists is None:
            exists = rule_based(model, start, turn_deg).success or (
                self.regrasps(model, start, turn_deg)[0] is not None)
            self._exists[key] = exists
        return exists

    def regrasps(self, model: GaitModel, start: GaitState,
                 turn_deg: float) -> tuple[int | None, int | None]:
        """``(optimal, rule_based)`` regrasps for the turn from ``start`` (None: no gait).

        Parameters
        ----------
        model
            The gait model (the env's ``unwrapped.model``).
        start
            A legal grasp at ``k = 0``.
        turn_deg
            The requested turn (degrees, counter-clockwise positive).
        """
        from graspgait_env.planners.rule_based import rule_based

        key = self._key(model, start, turn_deg)
        hit = self._cache.get(key)
        if hit is None:
            opt = self.optimal_regrasps(model, start, turn_deg)
            rule = rule_based(model, start, turn_deg) if opt is not None else None
            hit = (opt, rule.regrasps if rule is not None and rule.success else None)
            self._cache[key] = hit
        return hit


def _start_dict(model: GaitModel, s: GaitState) -> dict[str, float]:
    """``{finger number: contact_deg}`` of the held fingers (docs/formats.md's plan form)."""
    return {str(f + 1): float(model.contact_deg(s.contacts[f])) for f in s.held()}


def play_episode(predict: Callable[[np.ndarray, np.ndarray], int], env: Any, *,
                 seed: int | None = None, options: Mapping[str, Any] | None = None,
                 record_states: bool = False) -> dict[str, Any]:
    """Reset ``env`` (``seed``, ``options``) and play one episode with ``predict``.

    Returns
    -------
    dict
        ``model`` and ``start_state`` (the env's gait model and start grasp of this
        episode), ``success``, ``regrasps``, ``path_length`` (moves made: a move changes
        the (commanded) gait state, an illegal no-op does not), ``steps``,
        ``illegal_actions`` (actions chosen that were not legal moves), ``turn_deg``
        (turn achieved, degrees) and ``wall_s``; with ``record_states``, ``states``: the
        start and the state after each move (``path_length + 1`` states).
    """
    u = env.unwrapped
    t0 = time.perf_counter()
    obs, info = env.reset(seed=seed, options=dict(options) if options else None)
    model, start = u.model, u.state
    steps = illegal = moves = 0
    state, done = start, False
    states = [start]  # with record_states
    while not done:
        mask = np.asarray(u.action_masks(), dtype=bool)
        action = int(predict(obs, mask))
        illegal += not mask[action] if 0 <= action < mask.size else 1
        obs, _, terminated, truncated, info = env.step(np.int64(action))
        steps += 1
        moved = u.state
        if moved != state:
            moves += 1
            if record_states:
                states.append(moved)
        state = moved
        done = terminated or truncated
    out = {"model": model, "start_state": start,
           "success": bool(info.get("is_success", False)),
           "regrasps": int(info.get("regrasps", 0)), "path_length": moves, "steps": steps,
           "illegal_actions": illegal, "turn_deg": float(info.get("turn_deg", 0.0)),
           "wall_s": time.perf_counter() - t0}
    if record_states:
        out["states"] = states
    return out


def run_episodes(predict: Callable[[np.ndarray, np.ndarray], int], env: Any, episodes: int,
                 seed: int = 0, references: ReferenceGaits | None = None,
                 progress: bool = False, desc: str = "evaluate", audit: bool = False
                 ) -> list[dict[str, Any]]:
    """Play ``episodes`` episodes with ``predict`` and compare each with the references.

    Parameters
    ----------
    predict
        ``predict(observation, action_mask) -> action``.
    env
        A GraspGait env made by :func:`graspgait_env.agents.envs.make_env` (any id, wrapped or not).
    episodes
        Number of episodes; episode ``i`` resets with seed ``seed + i``.
    seed
        First reset seed.
    references
        Cache of optimal and rule-based regrasps (a fresh one when None).
    progress
        Show a tqdm bar.
    audit
        Add ``audit`` to each record: every move priced against the optimum
        (:func:`graspgait_env.agents.audit.audit_moves`, with the env's
        ``regrasp_lookahead`` as the look-ahead, 0 where it has none).

    Returns
    -------
    list of dict
        One record per episode: ``start`` ({finger: contact_deg}), ``object``, ``mu``,
        ``success``, ``solvable`` (a gait exists from the start), ``regrasps``,
        ``path_length`` (moves made: regrasps + rotations), ``steps`` (actions, illegal
        ones included), ``illegal_actions`` (actions the agent chose that were not legal
        moves; a wrapper such as :class:`graspgait_env.agents.wrappers.LegalActionWrapper` may have
        played a legal one instead), ``optimal_regrasps`` and ``rule_regrasps`` (None:
        no gait found), ``wall_s`` (the agent's episode, references excluded).
    """
    refs = references if references is not None else ReferenceGaits()
    turn = float(env.unwrapped.config.turn_deg)
    lookahead = int(env.unwrapped.config.regrasp_lookahead)
    out = []
    for i in tqdm(range(episodes), desc=desc, disable=not progress, unit="ep"):
        ep = play_episode(predict, env, seed=seed + i, record_states=audit)
        model, start = ep.pop("model"), ep.pop("start_state")
        opt, rule = refs.regrasps(model, start, turn)
        record = {
            "start": _start_dict(model, start), "object": model.shape.name,
            "mu": float(model.mu), "success": ep["success"], "solvable": opt is not None,
            "regrasps": ep["regrasps"], "path_length": ep["path_length"],
            "steps": ep["steps"], "illegal_actions": ep["illegal_actions"],
            "optimal_regrasps": opt, "rule_regrasps": rule, "wall_s": ep["wall_s"],
        }
        if audit:
            record["audit"] = audit_moves(model, ep["states"], turn,
                                          lambda st, m=model: refs.to_go(m, st, turn),
                                          lookahead=lookahead)
        out.append(record)
    return out


def _take_rows(obs: Any, rows: Any) -> Any:
    """Rows ``rows`` of a batch of observations: an array, or a dict of parts
    (``observation_mode="dict"``)."""
    if isinstance(obs, dict):
        return {k: v[rows] for k, v in obs.items()}
    return obs[rows]


def _shapes(space: Any) -> Any:
    """An observation space's shape, or its parts' shapes (a ``Dict`` space)."""
    if isinstance(space, gym.spaces.Dict):
        return {k: v.shape for k, v in space.spaces.items()}
    return space.shape


def batched_eval_env(env_id: str, env_kwargs: Mapping[str, Any] | None = None,
                     wrappers: tuple[str, ...] | list[str] = (), num_envs: int = EVAL_BATCH
                     ) -> Any:
    """The batched env for :func:`run_episodes_batched`, or None where it does not apply.

    It applies to ``GraspGait-v0`` without wrappers: the batched
    :class:`~graspgait_env.envs.vector_env.GraspGaitVectorEnv` reproduces it transition
    for transition for every config field (a field it did not implement would be listed
    by :func:`~graspgait_env.envs.vector_env.unsupported_fields`). Other ids
    (``GraspGaitRandom-v0``, ``GraspGaitMujoco-v1``) and wrapped envs return None, and
    the caller plays the episodes one by one (:func:`run_episodes`), which gives the same
    records. Bad keywords raise as the single env raises them.
    """
    from graspgait_env.envs.vector_env import GraspGaitVectorEnv, unsupported_fields

    if env_id != "GraspGait-v0" or wrappers or unsupported_fields(dict(env_kwargs or {})):
        return None

    return GraspGaitVectorEnv(num_envs=check_count("num_envs", num_envs, 1, EVAL_BATCH),
                              **dict(env_kwargs or {}))


def run_episodes_batched(predict_batch: Callable[[np.ndarray, np.ndarray], np.ndarray],
                         venv: Any, episodes: int, seed: int = 0,
                         references: ReferenceGaits | None = None, progress: bool = False,
                         desc: str = "evaluate") -> list[dict[str, Any]]:
    """:func:`run_episodes`, with the episodes played side by side in a batched env.

    Episode ``i`` starts from ``reset`` seed ``seed + i`` of one sub-env of ``venv`` (a
    :class:`~graspgait_env.envs.vector_env.GraspGaitVectorEnv`, whose sub-env seeded
    ``s`` draws the start grasp a single ``GraspGait-v0`` seeded ``s`` draws), so the
    starts, moves and records are those of :func:`run_episodes` over single envs, in
    ``ceil(episodes / venv.num_envs)`` waves with one ``predict_batch`` call per step of a
    wave. The policy must be deterministic (greedy): a sampled policy would draw its
    random numbers in another order than one episode after another.

    Parameters
    ----------
    predict_batch
        ``predict_batch(observations (B, D), action_masks (B, A)) -> actions (B,)``, for
        the rows of the episodes still running.
    venv
        From :func:`batched_eval_env`.
    episodes, seed, references, progress, desc
        As for :func:`run_episodes`.

    Returns
    -------
    list of dict
        The records of :func:`run_episodes`. ``wall_s`` is the wave's wall time divided
        by its episodes (they run together), references excluded.
    """
    refs = references if references is not None else ReferenceGaits()
    turn = float(venv.config.turn_deg)
    model = venv.model
    N = int(venv.num_envs)
    out: list[dict[str, Any]] = []
    bar = tqdm(total=episodes, desc=desc, disable=not progress, unit="ep")
    for first in range(0, episodes, N):
        t0 = time.perf_counter()
        wave = min(N, episodes - first)
        obs, _ = venv.reset(seed=[seed + first + i for i in range(N)])
        starts = venv.states()[:wave]
        running = np.zeros(N, dtype=bool)
        running[:wave] = True
        steps = np.zeros(N, dtype=np.int64)
        illegal = np.zeros(N, dtype=np.int64)
        success = np.zeros(N, dtype=bool)
        regrasps = np.zeros(N, dtype=np.int64)
        actions = np.zeros(N, dtype=np.int64)
        while running.any():
            rows = running.nonzero()[0]
            masks = venv.action_masks()
            a = np.asarray(predict_batch(_take_rows(obs, rows), masks[rows]),
                           dtype=np.int64).reshape(-1)
            actions[:] = 0
            actions[rows] = a
            inside = (a >= 0) & (a < masks.shape[1])
            ok = np.zeros(rows.size, dtype=bool)
            ok[inside] = masks[rows[inside], a[inside]]
            illegal[rows] += ~ok
            steps[rows] += 1
            obs, _, terminated, truncated, info = venv.step(actions)
            ended = rows[(terminated | truncated)[rows]]
            if ended.size:
                success[ended] = np.asarray(info["is_success"])[ended]
                regrasps[ended] = np.asarray(info["regrasps"])[ended]
                running[ended] = False
                bar.update(ended.size)
        share = (time.perf_counter() - t0) / wave
        for i in range(wave):
            opt, rule = refs.regrasps(model, starts[i], turn)
            out.append({
                "start": _start_dict(model, starts[i]), "object": model.shape.name,
                "mu": float(model.mu), "success": bool(success[i]), "solvable": opt is not None,
                "regrasps": int(regrasps[i]), "path_length": int(steps[i] - illegal[i]),
                "steps": int(steps[i]), "illegal_actions": int(illegal[i]),
                "optimal_regrasps": opt, "rule_regrasps": rule, "wall_s": share,
            })
    bar.close()
    return out


def _mean(xs: list[float]) -> float | None:
    return statistics.fmean(xs) if xs else None


def _ratio(a: float | None, b: float | None) -> float | None:
    return a / b if a is not None and b else None


def summarize_episodes(records: list[dict[str, Any]]) -> dict[str, Any]:
    """The aggregate numbers of :func:`run_episodes`' records (see the module docstring).

    Returns
    -------
    dict
        ``success_rate`` (all episodes), ``success_rate_solvable`` (episodes whose start
        has a gait; None when none has), ``solvable_episodes``, ``mean_regrasps``,
        ``mean_optimal_regrasps``, ``regrasps_vs_optimal``, ``mean_rule_regrasps``,
        ``regrasps_vs_rule``, ``rule_success_rate_solvable``, ``mean_path_length``
        (successful episodes), ``illegal_action_rate`` and ``mean_wall_s``. Means are
        None when they have no episode.
    """
    n = len(records)
    ok = [r for r in records if r["success"]]
    solvable = [r for r in records if r["solvable"]]
    ok_rule = [r for r in ok if r["rule_regrasps"] is not None]
    mean_regrasps = _mean([r["regrasps"] for r in ok])
    # the agent succeeded, so a gait exists: the optimum is known for every one of `ok`
    mean_opt = _mean([r["optimal_regrasps"] for r in ok if r["optimal_regrasps"] is not None])
    mean_rule = _mean([r["rule_regrasps"] for r in ok_rule])
    steps = sum(r["steps"] for r in records)
    return {
        "n_episodes": n,
        "success_rate": len(ok) / n if n else None,
        "solvable_episodes": len(solvable),
        "success_rate_solvable": (sum(r["success"] for r in solvable) / len(solvable)
                                  if solvable else None),
        "mean_regrasps": mean_regrasps,
        "mean_optimal_regrasps": mean_opt,
        "regrasps_vs_optimal": _ratio(mean_regrasps, mean_opt),
        "mean_rule_regrasps": mean_rule,
        "regrasps_vs_rule": _ratio(_mean([r["regrasps"] for r in ok_rule]), mean_rule),
        "rule_success_rate_solvable": (sum(r["rule_regrasps"] is not None for r in solvable)
                                       / len(solvable) if solvable else None),
        "mean_path_length": _mean([r["path_length"] for r in ok]),
        "illegal_action_rate": (sum(r["illegal_actions"] for r in records) / steps
                                if steps else None),
        "mean_wall_s": _mean([r["wall_s"] for r in records]),
    }


def agent_predictor(model: Any, deterministic: bool = True
                    ) -> Callable[[np.ndarray, np.ndarray], int]:
    """``predict(obs, mask) -> action`` of an SB3 model (the mask is used by MaskablePPO)."""
    from sb3_contrib import MaskablePPO

    if isinstance(model, MaskablePPO):
        def predict(obs: np.ndarray, mask: np.ndarray) -> int:
            a, _ = model.predict(obs, deterministic=deterministic, action_masks=mask)
            return int(a)
    else:
        def predict(obs: np.ndarray, mask: np.ndarray) -> int:
            a, _ = model.predict(obs, deterministic=deterministic)
            return int(a)
    return predict


def agent_batch_predictor(model: Any) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """``predict_batch(obs, masks) -> actions``: an SB3 model's greedy actions for a batch
    (the masks used by MaskablePPO), for :func:`run_episodes_batched`."""
    from sb3_contrib import MaskablePPO

    if isinstance(model, MaskablePPO):
        def predict(obs: np.ndarray, masks: np.ndarray) -> np.ndarray:
            return model.predict(obs, deterministic=True, action_masks=masks)[0]
    else:
        def predict(obs: np.ndarray, masks: np.ndarray) -> np.ndarray:
            return model.predict(obs, deterministic=True)[0]
    return predict


def evaluate(model_path: str | os.PathLike[str], *, env_id: str | None = None,
             object: Any = None, mu: float | None = None, episodes: int = 100, seed: int = 0,
             deterministic: bool = True, env_overrides: Mapping[str, Any] | None = None,
             progress: bool = False, audit: bool = False,
             batched: bool = True, reading: bool = False) -> dict[str, Any]:
    """Evaluate a saved agent (``model.zip``) and compare it with the optimum and the rules.

    Parameters
    ----------
    model_path
        A ``.zip`` saved by ``graspgait train`` (its model card ``<stem>.json`` beside it
        gives the env it was trained in) or by SB3 / RL Zoo (then give ``env_id`` and, for
        ``GraspGait-v0``, ``object``/``mu`` unless the env defaults are meant).
    env_id
        Evaluate in this id (default: the training id). A model trained on
        ``GraspGaitRandom-v0`` is evaluated on one object with ``object=``: the id
        becomes ``GraspGait-v0`` unless given.
    object
        Bundled object name, object YAML path or Shape (default: the trained one), also
        an object the model never saw.
    mu
        Friction coefficient (default: the trained one).
    episodes
        Episodes (reset seeds ``seed .. seed + episodes - 1``).
    seed
        First reset seed.
    deterministic
        Greedy actions (the policy's mode) when True; else sampled, from torch seeded
        with ``seed`` (:func:`graspgait_env.agents.seeding.seed_everything`).
    env_overrides
        Further keyword arguments of the env (e.g. ``{"object_seeds": [1000000,
        1100000], "exclude_seeds": None, "bundled_fraction": 0}`` for held-out
        procedural objects in ``GraspGaitRandom-v0``).
    progress
        Show a progress bar.
    audit
        Price every move against the optimum (:mod:`graspgait_env.agents.audit`): each record gains
        ``audit``, the result ``audit``, the sums over the successful episodes from
        solvable starts (their ``excess_regrasps`` is the agent's regrasps there less
        the optimum's). The episodes are then played one by one (the same records as
        side by side, tested; slower).
    batched
        Play deterministic episodes side by side in the batched env where it applies
        (:func:`batched_eval_env`; one policy call per step for up to
        :data:`EVAL_BATCH` episodes); False plays them one by one in the single env.
        The records are the same either way (tested); only the wall time differs.
    reading
        Also play the greedy reading of the model's own reach look-ahead
        (:func:`graspgait_env.envs.reading.greedy_reading`: no learning, the least
        ``reach_rank``) from the same starts in the same env, and compare it with the
        model start by start (:func:`compare_with_reading`); needs a model trained with
        ``regrasp_lookahead``. With ``audit``, its moves are audited too.

    Returns
    -------
    dict
        The aggregate numbers of :func:`summarize_episodes`, the per-episode records
        under ``episodes``, and ``model`` (path, algo, card), ``env_id``, ``env_kwargs``,
        ``object``, ``mu`` (None when drawn per episode), ``contact_model``, ``seed``,
        ``deterministic``, ``wall_s``; with ``audit``, ``audit``; with ``reading``,
        ``reading`` (:func:`compare_with_reading`).

    Raises
    ------
    GraspGaitInputError
        A missing or unreadable model, a bad id, object, ``mu`` or episode count.
    """
    episodes = check_count("episodes", episodes, 1, 100)
    seed = check_count("seed", seed, 0, 0)
    if object is not None:
        check_object(object)
    if mu is not None:
        mu = check_mu(mu)
    if env_id is not None and env_id not in ENV_IDS:
        raise GraspGaitInputError(f"--env {env_id!r}: not a GraspGait id; use one of "
                                  f"{', '.join(ENV_IDS)}")
    t0 = time.perf_counter()
    seed_everything(seed)  # the policy's sampling, when not deterministic
    model, card = load_agent(model_path)
    trained_id = card.get("env_id") or env_id or "GraspGait-v0"
    if env_id is None:
        env_id = ("GraspGait-v0" if trained_id == "GraspGaitRandom-v0" and object is not None
                  else trained_id)
    kwargs = env_kwargs_for(env_id, trained_id, card.get("env_kwargs") or {}, object, mu,
                            contact_model=card.get("contact_model"))
    kwargs.update(env_overrides or {})
    env = make_env(env_id, kwargs, card.get("wrappers") or ())
    refs = ReferenceGaits()
    try:
        if reading and not int(env.unwrapped.config.regrasp_lookahead):
            raise GraspGaitInputError(
                f"reading: model {str(model_path)!r} reads no reach look-ahead "
                "(regrasp_lookahead 0 in its card), so it has no greedy reading to compare "
                "with; drop --reading, or evaluate a model trained with regrasp_lookahead")
        if _shapes(env.observation_space) != _shapes(model.observation_space):
            raise GraspGaitInputError(
                f"model {str(model_path)!r}: observes {_shapes(model.observation_space)}, "
                f"the env {env_id} gives {_shapes(env.observation_space)}; evaluate with the "
                "env settings the model was trained with (hand, n, map window, "
                "observation_mode)")
        venv = (batched_eval_env(env_id, kwargs, card.get("wrappers") or (),
                                 min(episodes, EVAL_BATCH))
                if deterministic and not audit and batched else None)
        if venv is not None:  # the same episodes side by side: one policy call per step
            try:
                records = run_episodes_batched(agent_batch_predictor(model), venv, episodes,
                                               seed, references=refs, progress=progress)
                if reading and env.unwrapped.config.observation_mode == "box":
                    read = _reading_alone(env_id, kwargs, card.get("wrappers") or (),
                                          episodes, seed, refs, progress, audit)
                elif reading:  # reach_rank in every row: the reading side by side too
                    read = run_episodes_batched(greedy_reading_batch(env), venv, episodes,
                                                seed, references=refs, progress=progress,
                                                desc="greedy reading")
            finally:
                venv.close()
        else:
            records = run_episodes(agent_predictor(model, deterministic), env, episodes,
                                   seed, references=refs, progress=progress, audit=audit)
            if reading:
                read = _reading_alone(env_id, kwargs, card.get("wrappers") or (), episodes,
                                      seed, refs, progress, audit)
        contact_model = contact_model_of(env)
    finally:
        env.close()
    summary = summarize_episodes(records)
    if audit:
        summary["audit"] = summarize_audits([r["audit"] for r in records
                                             if r["success"] and r["solvable"]])
    objects = sorted({r["object"] for r in records})
    mus = sorted({r["mu"] for r in records})
    return {
        **summary,
        "model": {"path": str(model_path), "algo": card.get("algo"),
                  "name": card.get("config", {}).get("name"), "steps": card.get("steps"),
                  "seed": card.get("seed")},
        "env_id": env_id,
        "env_kwargs": {k: (v if isinstance(v, (str, int, float, bool, list, dict, type(None)))
                           else str(v)) for k, v in kwargs.items()},
        "object": objects[0] if len(objects) == 1 else None,
        "mu": mus[0] if len(mus) == 1 else None,
        "contact_model": contact_model,
        "seed": seed,
        "deterministic": bool(deterministic),
        "wall_s": time.perf_counter() - t0,
        "episodes": records,
        **({"reading": compare_with_reading(records, read, kwargs["regrasp_lookahead"],
                                            audit=audit)} if reading else {}),
    }


def _reading_alone(env_id: str, kwargs: Mapping[str, Any], wrappers: Any, episodes: int,
                   seed: int, refs: ReferenceGaits, progress: bool, audit: bool
                   ) -> list[dict[str, Any]]:
    """The greedy reading's records, one episode at a time, in a fresh env of the model's
    settings (so its episode ``i`` starts where the model's did)."""
    env = make_env(env_id, kwargs, wrappers)
    try:
        return run_episodes(greedy_reading(env), env, episodes, seed, references=refs,
                            progress=progress, desc="greedy reading", audit=audit)
    finally:
        env.close()


def compare_with_reading(records: list[dict[str, Any]], reading: list[dict[str, Any]],
                         depth: int, audit: bool = False) -> dict[str, Any]:
    """The greedy reading's episodes beside the model's, from the same starts.

    Parameters
    ----------
    records, reading
        :func:`run_episodes` records of the model and of the greedy reading, episode
        ``i`` of each from the same reset seed (checked: the same object, ``mu`` and start
        grasp, else ``RuntimeError``).
    depth
        The look-ahead's depth (regrasps), reported.
    audit
        The reading's records carry ``audit``: sum it as :func:`evaluate` does.

    Returns
    -------
    dict
        :func:`summarize_episodes` of the reading; ``depth``; over the solvable starts,
        ``both_succeeded`` (starts both turned), ``model_fewer``, ``model_more`` and
        ``same`` (of those, where the model spent fewer, more or as many regrasps),
        ``model_regrasps`` and ``reading_regrasps`` (their totals there),
        ``only_model`` and ``only_reading`` (starts only one of them turned); the
        reading's records under ``episodes``; with ``audit``, ``audit``.
    """
    if len(records) != len(reading):
        raise RuntimeError(f"{len(records)} model episodes against {len(reading)} of the "
                           "greedy reading: they must be played from the same starts")
    for i, (a, b) in enumerate(zip(records, reading, strict=True)):
        if (a["object"], a["mu"], a["start"]) != (b["object"], b["mu"], b["start"]):
            raise RuntimeError(f"episode {i}: the model started from {a['object']} "
                               f"{a['start']} (mu {a['mu']}), the greedy reading from "
                               f"{b['object']} {b['start']} (mu {b['mu']}): not the same start")
    pairs = [(a, b) for a, b in zip(records, reading, strict=True) if a["solvable"]]
    both = [(a["regrasps"], b["regrasps"]) for a, b in pairs if a["success"] and b["success"]]
    out = {
        **summarize_episodes(reading), "depth": int(depth), "both_succeeded": len(both),
        "model_fewer": sum(x < y for x, y in both), "model_more": sum(x > y for x, y in both),
        "same": sum(x == y for x, y in both), "model_regrasps": sum(x for x, _ in both),
        "reading_regrasps": sum(y for _, y in both),
        "only_model": sum(a["success"] and not b["success"] for a, b in pairs),
        "only_reading": sum(b["success"] and not a["success"] for a, b in pairs),
        "episodes": reading,
    }
    if audit:
        out["audit"] = summarize_audits([r["audit"] for r in reading
                                         if r["success"] and r["solvable"]])
    return out


def write_evaluation(result: Mapping[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write :func:`evaluate`'s result as JSON (atomic; NaN written as null)."""
    return write_text_atomic(path, json.dumps(json_ready(result), indent=1) + "\n")


def _fmt(x: Any, spec: str = ".2f") -> str:
    """``x`` formatted by ``spec``, or ``-`` where it is ``None`` (a figure with no episodes)."""
    return "-" if x is None else format(x, spec)


def format_evaluation(result: Mapping[str, Any]) -> str:
    """A few lines for the terminal: success rates and regrasps beside the references."""
    f = _fmt
    where = (f"{result['env_id']}, object {result['object'] or 'per episode'}, "
             f"mu {f(result['mu'], 'g') if result['mu'] is not None else 'per episode'}, "
             f"contact model {result['contact_model']}")
    return "\n".join([
        f"{result['model']['path']} ({result['model']['algo'] or 'SB3 model'}) in {where}",
        f"success: {f(result['success_rate'], '.1%')} of {result['n_episodes']} episodes; "
        f"{f(result['success_rate_solvable'], '.1%')} of the {result['solvable_episodes']} "
        "starts from which a gait exists",
        f"regrasps (successful episodes): agent {f(result['mean_regrasps'])}, optimum "
        f"{f(result['mean_optimal_regrasps'])} (x{f(result['regrasps_vs_optimal'], '.3f')}), "
        f"rule-based {f(result['mean_rule_regrasps'])} "
        f"(agent/rule x{f(result['regrasps_vs_rule'], '.3f')})",
        *([_format_audit(result["audit"])] if result.get("audit") else []),
        *(_format_reading(result["reading"], result) if result.get("reading") else []),
        f"illegal actions {f(result['illegal_action_rate'], '.1%')}; "
        f"wall time {result['wall_s']:.1f} s",
    ])


def _format_reading(r: Mapping[str, Any], result: Mapping[str, Any]) -> list[str]:
    f = _fmt
    lines = [
        f"greedy reading of the look-ahead ({r['depth']} regrasps deep), same starts: "
        f"{f(r['success_rate_solvable'], '.1%')} of the {r['solvable_episodes']} starts with "
        f"a gait; regrasps x{f(r['regrasps_vs_optimal'], '.3f')} the optimum (agent "
        f"x{f(result['regrasps_vs_optimal'], '.3f')})",
        f"agent against the reading: of the {r['both_succeeded']} starts both turned, fewer "
        f"regrasps from {r['model_fewer']}, more from {r['model_more']}, as many from "
        f"{r['same']} ({r['model_regrasps']} against {r['reading_regrasps']} in all); only the "
        f"agent turned {r['only_model']}, only the reading {r['only_reading']}"]
    if r.get("audit"):
        lines.append("reading " + _format_audit(r["audit"]))
    return lines


def _format_audit(a: Mapping[str, Any]) -> str:
    return (f"beyond the optimum ({a['episodes']} successful episodes): "
            f"{a['excess_regrasps']} regrasps = {a['idle_regrasps']} idle regrasps + "
            f"{a['excess_of_losing_regrasps']} from {a['losing_regrasps']} losing regrasps + "
            f"{a['excess_of_losing_rotations']} from {a['losing_rotations']} losing rotations"
            f"{beyond_lookahead_clause(a)}")
