"""Imitation of the exact optimum, state by state (DAgger), before or instead of PPO.

The default teacher is the env's
:meth:`~graspgait_env.envs.map_env.GraspGaitEnv.optimal_moves`: the legal moves of the
present state that begin a fewest-regrasp gait
(:class:`~graspgait_env.planners.optimal_moves.OptimalMoves`, read from the exact
planner's regrasps-to-go table). It is a *set*, since several rotations (and sometimes
several regrasps) are equally good; the loss is minus the log of the policy's
probability of the set, so the policy is free to split its mass inside it.

DAgger (Ross, Gordon and Bagnell, 2011): iteration 0 plays the teacher's moves; every
later iteration plays the policy's own sampled moves, so the states labelled are the
ones the policy reaches, and the labels of every iteration are kept and trained on
together (the aggregate). The teacher labels a state from its gait state only; the
policy sees only its observation, so what it can learn is bounded by what the
observation says (the per-action features of the named parts).

Two teachers (``teacher:``, tested):

- ``optimal`` (the default): the optimum's set as above;
- ``greedy``: the move the greedy reading of the reach look-ahead plays (the least
  ``reach_rank`` of the dict observation's ``actions`` part, so ``regrasp_lookahead``
  must be on and ``observation_mode`` ``dict``), corrected by the optimum: the label is
  that one move when it is in the optimum's set or is a rotation, and the optimum's set
  when it is a regrasp outside it (a regrasp that does not lower the count to go).
  Choice: a rotation keeps the regrasps to go (every state of a segment has the same
  count, :class:`~graspgait_env.planners.optimal_moves.OptimalMoves`), so the greedy
  reading's rotations are kept even where the optimum's set names others; what is
  corrected is the regrasps it wastes. Why: the optimum's set is often not what the
  observation can tell apart (several moves read alike, some in the set, some not),
  whereas the greedy move is a function of the observation; measured (CHANGELOG,
  2026-12-04), ``general`` at ``regrasp_lookahead: 5``, seed 0, on 300 held-out resets
  (146 starts with a gait): 97.3% at 1.046x the optimum with ``greedy``, 96.6% at 1.146x
  with ``optimal``; on the thesis hexagon 93.3% at 1.175x and 33.3% at 4.26x.

Only the policy's action head and features are trained here (cross-entropy on the
set); the value head is left to PPO, when ``total_timesteps`` continues the run.

Configured by the ``imitation:`` block of a training config (:class:`Imitation`);
:func:`imitate` runs it on a built model and its SB3 vector env.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from graspgait_env.envs.config import check_count, check_number
from graspgait_env.errors import GraspGaitInputError

__all__ = ["TEACHERS", "Imitation", "greedy_labels", "imitate", "set_loss"]

TEACHERS: tuple[str, ...] = ("optimal", "greedy")


@dataclass(frozen=True)
class Imitation:
    """The ``imitation:`` block of a training config: DAgger from the exact optimum.

    Every field is checked on construction; an unknown key is refused by
    :meth:`from_mapping`.
    """

    iterations: int = 10
    """DAgger iterations (>= 1): iteration 0 plays the teacher, the rest the policy."""
    labels: int = 4000
    """Labelled states collected per iteration (>= 1; states with an empty optimal set,
    no gait or a move the episode's rules forbid, are not counted)."""
    epochs: int = 8
    """Passes over the aggregate after each iteration (>= 1)."""
    batch_size: int = 256
    """Minibatch size of those passes (>= 1)."""
    learning_rate: float = 1e-3
    """Adam's step size for the imitation (> 0), separate from PPO's."""
    teacher: str = "optimal"
    """``optimal`` (the optimum's set) or ``greedy`` (the greedy reading's move, corrected
    by the optimum where it wastes a regrasp; module docstring)."""
    correction_weight: float = 1.0
    """With ``teacher: greedy``, the weight in the loss of a *correction*: a state whose
    label is the optimum's set because the greedy reading's move wastes a regrasp (>= 1;
    the other states weigh 1). Corrections are rare, so at weight 1 the policy learns
    the greedy reading and few of its corrections."""

    def __post_init__(self) -> None:
        for name, example in (("iterations", 10), ("labels", 4000), ("epochs", 8),
                              ("batch_size", 256)):
            object.__setattr__(self, name,
                               check_count(f"imitation.{name}", getattr(self, name), 1, example))
        object.__setattr__(self, "learning_rate", check_number(
            "imitation.learning_rate", self.learning_rate, 1e-3, minimum=0.0, strict=True))
        if self.teacher not in TEACHERS:
            raise GraspGaitInputError(
                f"imitation.teacher={self.teacher!r}: use 'optimal' (the optimum's set) or "
                "'greedy' (the greedy reading's move, corrected by the optimum)")
        object.__setattr__(self, "correction_weight", check_number(
            "imitation.correction_weight", self.correction_weight, 10.0, minimum=1.0))
        if self.teacher != "greedy" and self.correction_weight != 1.0:
            raise GraspGaitInputError(
                f"imitation.correction_weight={self.correction_weight!r}: weighs the "
                "greedy teacher's corrections; set teacher: greedy or leave it at 1.0")

    @classmethod
    def from_mapping(cls, value: Any) -> Imitation:
        """An :class:`Imitation` from a YAML mapping (or one already built)."""
        if isinstance(value, Imitation):
            return value
        if not isinstance(value, Mapping):
            raise GraspGaitInputError(
                f"imitation={value!r}: must be a mapping of "
                f"{', '.join(f.name for f in fields(cls))}, e.g. {{iterations: 10}}, or null")
        known = {f.name for f in fields(cls)}
        for key in value:
            if key not in known:
                raise GraspGaitInputError(
                    f"imitation.{key}: unknown key; allowed: {', '.join(sorted(known))}")
        return cls(**dict(value))

    def to_dict(self) -> dict[str, Any]:
        """The fields as a plain mapping (the YAML block, the card's ``imitation.config``)."""
        return asdict(self)


def set_loss(log_probs: Any, in_set: Any, weights: Any = None) -> Any:
    """Minus the log of the probability a policy gives a set of actions, averaged.

    ``log_probs``: ``(batch, actions)`` log-probabilities (masked actions at a very
    negative value); ``in_set``: ``(batch, actions)`` bools, each row with at least one
    True; ``weights``: ``(batch,)`` row weights, or None for all 1.
    ``sum_i w_i (-log sum_{a in set_i} p_i(a)) / sum_i w_i``: 0 when all the mass is
    inside the set.
    """
    import torch

    nll = -torch.logsumexp(log_probs.masked_fill(~in_set, -1e9), dim=1)
    if weights is None:
        return nll.mean()
    return (nll * weights).sum() / weights.sum()


def greedy_labels(rank: np.ndarray, masks: np.ndarray, optimal: np.ndarray,
                  rotations: int) -> np.ndarray:
    """The ``greedy`` teacher's labels (module docstring) for a batch of states.

    ``rank``: ``(B, A)`` the ``reach_rank`` column of each state's ``actions`` part;
    ``masks``: ``(B, A)`` the legal moves; ``optimal``: ``(B, A)`` the optimum's sets
    (``optimal_moves()``); ``rotations``: ``2 R``, the rotation actions first. Returns
    ``(B, A)`` bools: the greedy move alone where it is in the optimum's set or is a
    rotation, else the optimum's set; a row with an empty optimal set stays empty (no
    label).
    """
    return _greedy_teach(rank, masks, optimal, rotations)[0]


def _greedy_teach(rank: np.ndarray, masks: np.ndarray, optimal: np.ndarray,
                  rotations: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`greedy_labels` and ``(B,)`` its *corrections*: the rows labelled with the
    optimum's set because the greedy reading's move (its least ``reach_rank`` among the
    legal moves) is a regrasp outside it."""
    rows = np.arange(len(rank))
    greedy = np.where(masks, rank, np.inf).argmin(axis=1)
    has_set = optimal.any(axis=1)
    keep = has_set & (optimal[rows, greedy] | (greedy < int(rotations)))
    out = optimal.copy()
    out[keep] = False
    out[rows[keep], greedy[keep]] = True
    return out, has_set & ~keep


def _rank_column(obs: Any, venv: Any) -> tuple[int, int]:
    """Where the greedy teacher reads: the ``reach_rank`` column of the ``actions`` part
    and the rotation count ``2 R`` (the hand's, the same for every object), checked once."""
    u = venv.get_attr("unwrapped", [0])[0]
    if not isinstance(obs, dict) or "reach_rank" not in u.layout.action_features:
        raise GraspGaitInputError(
            "imitation.teacher='greedy': reads the greedy reading's move from the dict "
            "observation's reach_rank; set env_kwargs observation_mode: dict and "
            "regrasp_lookahead: 1 or more")
    return u.layout.feature("reach_rank"), 2 * int(u.model.R)


def _obs_rows(obs: Any, keep: np.ndarray) -> Any:
    if isinstance(obs, dict):
        return {k: np.asarray(v)[keep] for k, v in obs.items()}
    return np.asarray(obs)[keep]


def _concat(parts: list[Any]) -> Any:
    if isinstance(parts[0], dict):
        return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    return np.concatenate(parts)


def imitate(model: Any, venv: Any, config: Imitation, *, seed: int = 0,
            progress: bool = True) -> dict[str, Any]:
    """Train ``model``'s policy by DAgger on ``venv``'s teacher (module docstring).

    Parameters
    ----------
    model
        A MaskablePPO model built on ``venv`` (:func:`graspgait_env.agents.train.
        build_model`).
    venv
        Its SB3 vector env; every sub-env must offer ``optimal_moves()`` and
        ``action_masks()`` (the GraspGait envs do; the batched VecEnv does not, so use
        ``vec_env: dummy`` or ``subproc``).
    config
        The imitation block.
    seed
        Seeds the teacher's choice among its moves in iteration 0.
    progress
        A tqdm bar over the labelled states.

    Returns
    -------
    dict
        ``iterations``, ``labels`` (states trained on), ``corrections`` (of them, the
        greedy teacher's corrections), ``env_steps``, ``loss`` (the
        last iteration's mean), ``losses`` (per iteration), ``wall_s``, ``config``.
    """
    import torch
    from tqdm.auto import tqdm

    if not venv.has_attr("optimal_moves"):
        raise GraspGaitInputError(
            f"imitation: the vector env {type(venv).__name__} gives no optimal_moves() "
            "(the batched VecEnv has none); train with vec_env: dummy or subproc")
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    policy = model.policy
    opt = torch.optim.Adam(policy.parameters(), lr=config.learning_rate)
    obs_parts: list[Any] = []
    mask_parts: list[np.ndarray] = []
    set_parts: list[np.ndarray] = []
    weight_parts: list[np.ndarray] = []
    losses: list[float] = []
    env_steps = corrections = 0
    total = config.iterations * config.labels
    bar = tqdm(total=total, desc="imitation", unit="label", disable=not progress)
    obs = venv.reset()
    if config.teacher == "greedy":
        rank_col, rotations = _rank_column(obs, venv)
    try:
        for it in range(config.iterations):
            got = 0
            while got < config.labels:
                masks = np.stack(venv.env_method("action_masks"))
                teach = np.stack(venv.env_method("optimal_moves"))
                weight = np.ones(len(masks))
                if config.teacher == "greedy":
                    teach, fixed = _greedy_teach(np.asarray(obs["actions"])[:, :, rank_col],
                                                 masks, teach, rotations)
                    weight[fixed] = config.correction_weight
                    corrections += int(fixed.sum())
                keep = teach.any(axis=1)
                if keep.any():
                    obs_parts.append(_obs_rows(obs, keep))
                    mask_parts.append(masks[keep])
                    set_parts.append(teach[keep])
                    weight_parts.append(weight[keep])
                    got += int(keep.sum())
                    bar.update(int(keep.sum()))
                if it == 0:  # the teacher's moves (a legal one where it has none)
                    pick = np.where(keep[:, None], teach, masks)
                    actions = np.array([rng.choice(np.flatnonzero(p)) for p in pick])
                else:  # the policy's own, sampled
                    actions, _ = model.predict(obs, deterministic=False, action_masks=masks)
                obs, _, _, _ = venv.step(actions)
                env_steps += venv.num_envs
            losses.append(_fit(policy, opt, _concat(obs_parts), np.concatenate(mask_parts),
                               np.concatenate(set_parts), np.concatenate(weight_parts),
                               config, rng))
            bar.set_postfix(loss=f"{losses[-1]:.3f}")
    finally:
        bar.close()
    return {"iterations": config.iterations, "labels": int(sum(len(m) for m in mask_parts)),
            "corrections": corrections, "env_steps": env_steps, "loss": losses[-1],
            "losses": losses, "wall_s": time.perf_counter() - t0, "config": config.to_dict()}


def _fit(policy: Any, opt: Any, obs: Any, masks: np.ndarray, sets: np.ndarray,
         weights: np.ndarray, config: Imitation, rng: np.random.Generator) -> float:
    """``config.epochs`` passes of :func:`set_loss` (rows weighted by ``weights``) over
    the aggregate; the mean loss of the last pass."""
    import torch

    n = len(masks)
    obs_t = ({k: torch.as_tensor(v) for k, v in obs.items()} if isinstance(obs, dict)
             else torch.as_tensor(obs))
    sets_t = torch.as_tensor(sets)
    weights_t = torch.as_tensor(weights, dtype=torch.float32)
    policy.set_training_mode(True)
    last: list[float] = []
    try:
        for _ in range(config.epochs):
            last = []
            order = rng.permutation(n)
            for i in range(0, n, config.batch_size):
                b = order[i:i + config.batch_size]
                bt = torch.as_tensor(b)
                o = ({k: v[bt] for k, v in obs_t.items()} if isinstance(obs_t, dict)
                     else obs_t[bt])
                dist = policy.get_distribution(o, action_masks=masks[b])
                loss = set_loss(dist.distribution.logits, sets_t[bt], weights_t[bt])
                opt.zero_grad()
                loss.backward()
                torch.nn.utils.clip_grad_norm_(policy.parameters(), 1.0)
                opt.step()
                last.append(float(loss.item()))
    finally:
        policy.set_training_mode(False)
    return float(np.mean(last))
