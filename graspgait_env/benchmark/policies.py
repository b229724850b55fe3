"""What ``graspgait benchmark POLICY`` runs: POLICY resolved into a policy per task and seed.

POLICY is one of:

- ``random``: the masked random policy, a legal move drawn uniformly at every step
  (NumPy generator seeded by the run seed);
- a planner name of :data:`graspgait_env.planners.registry.PLANNERS` (``rule``,
  ``optimal``, ``best-first``, ...), run as a policy by
  :class:`graspgait_env.baselines.policies.PlannerPolicy` (it plans from the episode's
  start, follows the plan while the state is the one it expects, replans otherwise);
- ``greedy-reach`` or ``greedy-reach:D``: a scripted greedy reading of the reach
  look-ahead, no learning: the env gives each move the shortfall of the turn after the
  best chain of up to ``D - 1`` more regrasps (``regrasp_lookahead=D``, 3 by default, at
  most 5; :class:`graspgait_env.planners.reach.RegraspReach`) and the policy plays a
  rotation that completes the turn when one is legal, else the move falling least short
  at depth ``D - 1``, then ``D - 2``, ... 0 (ties: a regrasp before a rotation, a shorter
  rotation first), with ``forbid_revisit=True`` (tests/envs/test_regrasp_lookahead.py);
  the row is labelled ``greedy-reach`` at the default depth, ``greedy-reach-D`` else;
- ``agent:NAME`` or a model path (``.zip``; also a bare shipped agent name other than
  ``random``): a saved agent (:func:`graspgait_env.agents.card.load_agent`), played
  greedily with the observation settings of its card; a path with ``{task}``,
  ``{train_task}`` (the task a hand-track task trains in, else the task) or ``{seed}`` in
  it names one model per task and run seed (models trained elsewhere, e.g. by RL Zoo:
  ``logs/{train_task}/s{seed}/ppo/GraspGait-v0_1/GraspGait-v0.zip``);
- ``config:NAME`` or a training config path (``.yaml``): trained once per task and seed
  (:func:`graspgait_env.agents.train.train`, ``seed`` = the run seed) in the task's
  training env, within the task's step budget, then played greedily;
- ``rlzoo:ALGO`` or ``rlzoo:ALGO:STEPS``: RL Zoo (``python -m rl_zoo3.train``) with the
  bundled hyper-parameters ``configs/rlzoo/ALGO.yml`` (``graspgait config rlzoo``), trained
  once per task and seed (``--seed`` = the run seed, ``--env-kwargs`` = the training
  task's keywords) for the file's ``n_timesteps`` or ``STEPS``, then played greedily with
  the wrappers RL Zoo saved (its ``SolvableStartWrapper`` dropped). The bundled files
  are for ``GraspGait-v0``, so the ``random`` track is refused;
- ``bc`` or ``bc:POLICY`` (``optimal``, the default, or ``rule``): behaviour cloning,
  trained per task and seed from the task's demonstrations
  (:mod:`graspgait_env.benchmark.datasets`; ``graspgait dataset record`` first).

A task fixes the problem's keywords (:data:`~graspgait_env.benchmark.suite.TASK_KEYS`:
object, mu, contact model, level, object seeds, hand, grid, ...); a policy brings its own
observation settings and move rules (``map_lines``, ``rotation_lookahead``,
``regrasp_lookahead``, ``forbid_reversal``, ``forbid_revisit``, ...) and action wrappers
(a start-distribution wrapper such as ``SolvableStartWrapper`` is dropped: the test
starts are the task's). Neither move rule changes the fewest regrasps from a start.
"""

from __future__ import annotations

import dataclasses
import functools
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from graspgait_env.benchmark.suite import TASK_KEYS, Task, get_task
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.planners.reach import MAX_REACH_DEPTH

__all__ = ["CellPolicy", "PolicySpec", "parse_policy", "prepare_policy", "greedy_reach_predictor",
           "policy_env_kwargs", "train_rlzoo", "GREEDY_REACH_DEPTH", "START_WRAPPERS"]

Predict = Callable[[np.ndarray, np.ndarray], int]
GREEDY_REACH_DEPTH = 3
# wrappers that choose the start grasp: the task chooses it, so they are dropped
START_WRAPPERS = ("SolvableStartWrapper", "RuleBasedStartWrapper")
DEMO_POLICIES = ("optimal", "rule")


@dataclass(frozen=True)
class PolicySpec:
    """A resolved POLICY: ``kind`` (random, planner, greedy-reach, agent, agent-template,
    config, rlzoo, bc), ``arg`` (the planner, model, model path template, config or
    demonstrating policy) and ``label`` (its name in tables and the default output
    folder)."""

    kind: str
    arg: str
    label: str

    def to_dict(self) -> dict[str, str]:
        """``{"kind", "arg", "label"}`` (``PolicySpec(**d)`` makes it again)."""
        return dataclasses.asdict(self)


def _label(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "policy"


def parse_policy(text: str) -> PolicySpec:
    """Resolve POLICY (module docstring) without running anything.

    Raises
    ------
    GraspGaitInputError
        Nothing of that name; the message lists what POLICY may be.
    """
    from graspgait_env.planners.registry import PLANNERS

    text = str(text).strip()
    kind, sep, rest = text.partition(":")
    if text == "random":
        return PolicySpec("random", "", "random")
    if text in PLANNERS:
        return PolicySpec("planner", text, text)
    if text == "greedy-reach" or (sep and kind == "greedy-reach"):
        depth = rest or str(GREEDY_REACH_DEPTH)
        if not depth.isdigit() or not 1 <= int(depth) <= MAX_REACH_DEPTH + 1:
            raise GraspGaitInputError(
                f"POLICY {text!r}: the look-ahead depth D of greedy-reach:D is 1 to "
                f"{MAX_REACH_DEPTH + 1} regrasps, e.g. greedy-reach:8")
        if int(depth) == GREEDY_REACH_DEPTH:  # the default row, as before
            return PolicySpec("greedy-reach", "", "greedy-reach")
        return PolicySpec("greedy-reach", str(int(depth)), f"greedy-reach-{int(depth)}")
    if text == "bc" or (sep and kind == "bc"):
        demo = rest or "optimal"
        if demo not in DEMO_POLICIES:
            raise GraspGaitInputError(f"POLICY {text!r}: bc learns from the demonstrations of "
                                      f"{' or '.join(DEMO_POLICIES)}, e.g. bc:optimal")
        return PolicySpec("bc", demo, f"bc-{demo}")
    if any(f"{{{k}}}" in text for k in ("task", "train_task", "seed")):
        try:
            text.format(task="t", train_task="t", seed=0)
        except (KeyError, IndexError, ValueError):
            raise GraspGaitInputError(f"POLICY {text!r}: a model path template may name "
                                      "only {task}, {train_task} and {seed}") from None
        stem = Path(text.format(task="TASK", train_task="TASK", seed="SEED")).stem
        return PolicySpec("agent-template", text, f"agent-{_label(stem)}")
    if sep and kind == "rlzoo":
        algo, _, steps = rest.partition(":")
        _rlzoo_conf(algo)
        if steps and (not steps.isdigit() or int(steps) < 1):
            raise GraspGaitInputError(f"POLICY {text!r}: STEPS must be a positive integer, "
                                      "e.g. rlzoo:ppo:100000")
        return PolicySpec("rlzoo", rest, f"rlzoo-{_label(rest.replace(':', '-'))}")
    if sep and kind == "config":
        _load_config(rest)
        return PolicySpec("config", rest, f"config-{_label(Path(rest).stem)}")
    if sep and kind == "agent":
        return PolicySpec("agent", str(_resolve_model(rest)), f"agent-{_label(Path(rest).stem)}")
    path = Path(text)
    if path.suffix in (".yaml", ".yml"):
        _load_config(text)
        return PolicySpec("config", str(path), f"config-{_label(path.stem)}")
    if path.suffix == ".zip" or path.is_file() or text in _shipped() or text in _retired():
        model = _resolve_model(text)
        stem = path.stem if path.stem != "model" else f"{path.parent.name}-model"
        return PolicySpec("agent", str(model), f"agent-{_label(stem)}")
    raise GraspGaitInputError(
        f"POLICY {text!r}: not a policy; give random, a planner ({', '.join(PLANNERS)}), "
        "greedy-reach[:D], a shipped agent (agent:NAME, e.g. agent:general) or a model .zip, a "
        "training config (config:NAME, e.g. config:ellipse, or a .yaml path), RL Zoo "
        "(rlzoo:ppo), or bc[:optimal|rule]")


def _rlzoo_conf(algo: str) -> Path:
    from graspgait_env.resources import bundled_file, bundled_names

    path = bundled_file("rlzoo", algo)
    if path is None:
        raise GraspGaitInputError(
            f"POLICY rlzoo:{algo}: no bundled RL Zoo hyper-parameters {algo!r}; bundled: "
            f"{', '.join(bundled_names('rlzoo'))} (graspgait config rlzoo)")
    return path


def _rlzoo_conf_steps(conf: Path, env_id: str) -> int:
    import yaml

    hyper = yaml.safe_load(conf.read_text(encoding="utf-8")) or {}
    if env_id not in hyper:
        raise GraspGaitInputError(
            f"POLICY rlzoo: {conf.name} has hyper-parameters for {', '.join(hyper)} only, "
            f"not {env_id}; give --tasks of those envs (e.g. map-point,map-hand,mujoco)")
    return int(float(hyper[env_id]["n_timesteps"]))


def train_rlzoo(spec: PolicySpec, task: Task, seed: int, workdir: str | Path) -> Path:
    """Train an ``rlzoo`` POLICY for (task, seed) with ``python -m rl_zoo3.train`` unless
    its model is already there; the model's path (RL Zoo's log folder is
    ``workdir/train/TASK/sSEED``, its output in ``rlzoo.log`` there).

    Raises
    ------
    GraspGaitInputError
        The task's training env has no bundled hyper-parameters, or the budget exceeds
        the task's.
    """
    import os
    import subprocess
    import sys

    from graspgait_env.atomic import write_text_atomic

    train_task, run_dir = training_plan(spec, task, seed, workdir)
    algo, _, steps = spec.arg.partition(":")
    env_id = train_task.train_env_id
    found = sorted(run_dir.glob(f"{algo}/{env_id}_*/{env_id}.zip"))
    if found:
        return found[-1]
    conf = _rlzoo_conf(algo)
    n = int(steps) if steps else _rlzoo_conf_steps(conf, env_id)
    if train_task.train_steps <= 0:
        raise GraspGaitInputError(f"task {train_task.id}: not a training task")
    if n > train_task.train_steps:
        raise GraspGaitInputError(
            f"POLICY rlzoo:{spec.arg}: {n:,} steps exceed task {train_task.id}'s budget of "
            f"{train_task.train_steps:,}; give fewer, e.g. rlzoo:{algo}:{train_task.train_steps}")
    kw = [f"{k}:{v!r}" for k, v in train_task.train_kwargs.items()]
    cmd = [sys.executable, "-m", "rl_zoo3.train", "--algo", algo, "--env", env_id,
           "--gym-packages", "graspgait_env", "--conf-file", str(conf), "--seed", str(seed),
           "-n", str(n), "-f", str(run_dir), "--num-threads", "1", "--eval-freq", "-1",
           "--log-interval", "-1", *(["--env-kwargs", *kw] if kw else [])]
    run_dir.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(cmd, capture_output=True, text=True,
                          env={**os.environ, "OMP_NUM_THREADS": "1"})
    write_text_atomic(run_dir / "rlzoo.log", " ".join(cmd) + "\n" + done.stdout + done.stderr)
    found = sorted(run_dir.glob(f"{algo}/{env_id}_*/{env_id}.zip"))
    if done.returncode != 0 or not found:
        raise RuntimeError(f"rl_zoo3.train failed for {train_task.id} seed {seed} (exit "
                           f"{done.returncode}); its output: {run_dir / 'rlzoo.log'}")
    return found[-1]


def _shipped() -> list[str]:
    try:
        from graspgait_env.agents.card import shipped_agents

        return shipped_agents()
    except ImportError:  # pragma: no cover - the agents package always installs
        return []


def _retired() -> dict[str, str]:
    from graspgait_env.agents.card import RETIRED_AGENTS  # its error names the replacement

    return RETIRED_AGENTS


def _resolve_model(text: str) -> Path:
    from graspgait_env.agents.card import resolve_model

    return resolve_model(text)


def _load_config(text: str) -> Any:
    from graspgait_env.agents.config import load_train_config

    return load_train_config(text)


def _own_keys(env_id: str, own: Mapping[str, Any] | None) -> dict[str, Any]:
    """A policy's own keywords that ``env_id`` takes: without the problem's
    (:data:`~graspgait_env.benchmark.suite.TASK_KEYS`) and without those of another id
    (``episodes_per_object`` of a ``GraspGaitRandom-v0`` agent on one object)."""
    from graspgait_env.agents.envs import MUJOCO_ONLY, RANDOM_ONLY

    other = (RANDOM_ONLY if env_id != "GraspGaitRandom-v0" else ()) + (
        MUJOCO_ONLY if env_id != "GraspGaitMujoco-v1" else ())
    return {k: v for k, v in dict(own or {}).items() if k not in TASK_KEYS and k not in other}


def policy_env_kwargs(task: Task, own: Mapping[str, Any] | None) -> dict[str, Any]:
    """The test env's keywords for a policy: its own keywords without the problem's
    (:data:`~graspgait_env.benchmark.suite.TASK_KEYS`) and those the task's id does not
    take, then the task's."""
    kw = _own_keys(task.env_id, own)
    kw.update(task.env_kwargs())
    return kw


class _EpisodeStarts(gym.Wrapper):
    """Marks the first step of each episode (``fresh``), so a planner policy knows an
    episode began even when its new start equals the state it expected next."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.fresh = True

    def reset(self, **kwargs: Any) -> Any:
        self.fresh = True
        return self.env.reset(**kwargs)


@dataclass
class CellPolicy:
    """A policy ready for one task and seed.

    ``env_kwargs`` are its own env keywords (merged under the task's by
    :func:`policy_env_kwargs`), ``wrappers`` its Gymnasium wrappers (import paths);
    ``make_predict(env)`` gives ``predict(obs, mask) -> action`` for the env built from
    them; ``info`` says what lies behind it (model, training steps and wall time);
    ``observes`` (:func:`observation_signature`), where known, is the observation the
    policy was trained on, which the task's env must give.
    """

    env_kwargs: dict[str, Any]
    wrappers: tuple[str, ...]
    make_predict: Callable[[gym.Env], Predict]
    info: dict[str, Any] = field(default_factory=dict)
    observes: tuple | None = None

    def wrap(self, env: gym.Env) -> gym.Env:
        """The env as the predictor expects it (an episode-start marker outermost)."""
        return _EpisodeStarts(env)


def _random_predictor(seed: int) -> Callable[[gym.Env], Predict]:
    def make(env: gym.Env) -> Predict:
        rng = np.random.default_rng([int(seed), 0x5EED])

        def predict(obs: np.ndarray, mask: np.ndarray) -> int:
            legal = np.flatnonzero(mask)
            return int(rng.choice(legal)) if legal.size else 0
        return predict
    return make


def _planner_predictor(name: str) -> Callable[[gym.Env], Predict]:
    def make(env: gym.Env) -> Predict:
        from graspgait_env.baselines.policies import PlannerPolicy
        from graspgait_env.planners.registry import get_planner

        policy = PlannerPolicy(env, get_planner(name), name=name)

        def predict(obs: np.ndarray, mask: np.ndarray) -> int:
            start = bool(getattr(env, "fresh", False))
            if start:
                env.fresh = False
            action, _ = policy.predict(obs, episode_start=np.array([start]))
            return int(action)
        return predict
    return make


def greedy_reach_predictor(env: gym.Env, depth: int = GREEDY_REACH_DEPTH) -> Predict:
    """The greedy reading of the reach look-ahead (module docstring) for an env made with
    ``regrasp_lookahead=depth``: :func:`graspgait_env.envs.reading.greedy_reading`, the
    order of :func:`graspgait_env.envs.observation.greedy_ranks`, which also writes the
    dict observation's ``reach_rank``. An env that reads another depth is refused."""
    from graspgait_env.envs.reading import greedy_reading

    have = int(env.unwrapped.config.regrasp_lookahead)
    if have != int(depth):
        raise GraspGaitInputError(
            f"greedy-reach:{int(depth)}: the env reads regrasp_lookahead={have}; make it "
            f"with regrasp_lookahead={int(depth)}")
    return greedy_reading(env)


def _agent_policy(model_path: str, info: dict[str, Any] | None = None) -> CellPolicy:
    from graspgait_env.agents.card import load_agent
    from graspgait_env.agents.evaluate import agent_predictor

    _one_thread()
    model, card = load_agent(model_path)
    wrappers = tuple(w for w in card.get("wrappers") or ()
                     if not any(s in w for s in START_WRAPPERS))
    predict = agent_predictor(model, deterministic=True)
    meta = {"model": str(model_path), "algo": card.get("algo"), "steps": card.get("steps"),
            "train_wall_s": card.get("wall_s"), **(info or {})}
    return CellPolicy(dict(card.get("env_kwargs") or {}), wrappers, lambda env: predict,
                      meta, observation_signature(model.observation_space))


def observation_signature(space: gym.Space) -> tuple:
    """What a policy and a task's env must agree on about an observation space: a
    ``Box``'s shape, or each part's name and shape for a ``Dict`` (``observation_mode:
    dict``)."""
    if isinstance(space, gym.spaces.Dict):
        return tuple((k, tuple(v.shape)) for k, v in space.spaces.items())
    return tuple(space.shape)


def _one_thread() -> None:
    import torch

    torch.set_num_threads(1)


def training_plan(spec: PolicySpec, task: Task, seed: int, workdir: str | Path
                  ) -> tuple[Task, Path]:
    """Where a ``config`` POLICY's model for (task, seed) is trained: the task it trains
    in (``task.train_task`` or the task) and its run folder under ``workdir``."""
    train_task = get_task(task.train_task) if task.train_task else task
    return train_task, Path(workdir) / "train" / train_task.id / f"s{int(seed)}"


def train_for(spec: PolicySpec, task: Task, seed: int, workdir: str | Path,
              progress: bool = False) -> Path:
    """Train ``spec``'s config for (task, seed) unless its model is already there; the
    model's path. The config's env keywords lose the problem's keys, which the training
    task's ``train_kwargs`` give; ``seed`` is the run seed.

    Raises
    ------
    GraspGaitInputError
        The config trains for more steps than the task's budget.
    """
    from graspgait_env.agents.train import train

    train_task, run_dir = training_plan(spec, task, seed, workdir)
    model = run_dir / "model.zip"
    if model.is_file():
        return model
    config = configure_training(spec, train_task, seed, workdir)
    _one_thread()
    return train(config, run_dir=run_dir, progress=progress).model_path


def configure_training(spec: PolicySpec, train_task: Task, seed: int,
                       workdir: str | Path) -> Any:
    """The training config of ``spec`` for ``train_task`` and ``seed`` (checked against
    the task's step budget)."""
    config = _load_config(spec.arg)
    if train_task.train_steps <= 0:
        raise GraspGaitInputError(f"task {train_task.id}: not a training task")
    if config.total_timesteps > train_task.train_steps:
        raise GraspGaitInputError(
            f"config {spec.arg!r}: total_timesteps={config.total_timesteps:,} exceeds task "
            f"{train_task.id}'s budget of {train_task.train_steps:,} steps; lower it in the "
            "config")
    kw = _own_keys(train_task.train_env_id, config.env_kwargs)
    kw.update(train_task.train_kwargs)
    return dataclasses.replace(config, env_id=train_task.train_env_id, env_kwargs=kw,
                               seed=int(seed), run_root=str(Path(workdir) / "train"))


def prepare_policy(spec: PolicySpec, task: Task, seed: int, workdir: str | Path,
                   progress: bool = False) -> CellPolicy:
    """The policy of ``spec`` for one task and run seed (training it first for a
    ``config``, cloning the demonstrations for ``bc``)."""
    if spec.kind == "random":
        return CellPolicy({}, (), _random_predictor(seed))
    if spec.kind == "planner":
        return CellPolicy({}, (), _planner_predictor(spec.arg), {"planner": spec.arg})
    if spec.kind == "greedy-reach":
        depth = int(spec.arg or GREEDY_REACH_DEPTH)
        return CellPolicy({"regrasp_lookahead": depth, "forbid_revisit": True}, (),
                          functools.partial(greedy_reach_predictor, depth=depth),
                          {"depth": depth})
    if spec.kind == "agent":
        return _agent_policy(spec.arg)
    if spec.kind == "agent-template":
        path = spec.arg.format(task=task.id, train_task=task.train_task or task.id,
                               seed=int(seed))
        return _agent_policy(str(_resolve_model(path)), {"template": spec.arg})
    if spec.kind == "config":
        model = train_for(spec, task, seed, workdir, progress=progress)
        return _agent_policy(str(model), {"config": spec.arg})
    if spec.kind == "rlzoo":
        model = train_rlzoo(spec, task, seed, workdir)
        return _agent_policy(str(model), {"rlzoo": spec.arg})
    if spec.kind == "bc":
        from graspgait_env.benchmark.datasets import bc_policy_for

        return bc_policy_for(task, spec.arg, seed, workdir)
    raise GraspGaitInputError(f"policy kind {spec.kind!r}: unknown")  # pragma: no cover
