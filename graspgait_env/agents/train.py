"""Train a PPO or MaskablePPO agent on a GraspGait env from a
:class:`~graspgait_env.agents.config.TrainConfig`.

A run lives in its own folder, ``{run_root}/{env_id}-{config name}-s{seed}-{YYYYmmdd-HHMMSS}``:

- ``config.yaml``: the resolved config (every field, after ``--set``);
- ``tb/``: TensorBoard logs (SB3's ``rollout/``, ``train/``, ``time/`` and this
  module's ``eval/``), with the config as hyper-parameters;
- ``evaluations.json``: every periodic evaluation;
- ``checkpoints/model_{steps}_steps.zip`` (+ ``.json`` cards), every
  ``checkpoint_freq`` steps; ``graspgait train CONFIG --resume`` one of them continues
  the run in the same folder;
- ``best.zip`` (+ card): the model of the best evaluation (:func:`selection_score`:
  highest success rate over solvable starts, then fewest regrasps relative to the
  optimum; with ``best_success_floor``, fewest regrasps among those reaching it);
- ``model.zip`` + ``model.json``: the final model and its card (:mod:`graspgait_env.agents.card`).

With ``init_model`` the run starts from the weights of a saved model (a curriculum: the
same network trained on under a new reward); its card's ``init`` says how many steps and
how much wall time lay behind those weights.

The periodic evaluation (every ``eval_freq`` steps and at the end) plays
``eval_episodes`` episodes from fixed starts (reset seeds 10000, 10001, ...) in a
separate env made like the training ones, greedy actions, and compares the agent with
the exact optimum and the rule-based gait from the same starts
(:func:`graspgait_env.agents.evaluate.run_episodes`; the references are computed once per start). In
``GraspGait-v0`` without wrappers the episodes run side by side in the batched env
(:func:`graspgait_env.agents.evaluate.run_episodes_batched`, the same records).
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

import yaml
from tqdm.auto import tqdm

from graspgait_env.agents.card import load_agent, read_card, resolve_model, save_agent
from graspgait_env.agents.config import OWN_POLICY_KWARGS, TrainConfig
from graspgait_env.agents.envs import contact_model_of, import_object, make_env
from graspgait_env.agents.evaluate import (
    EVAL_BATCH,
    EVAL_SEED,
    ReferenceGaits,
    agent_batch_predictor,
    agent_predictor,
    batched_eval_env,
    run_episodes,
    run_episodes_batched,
    summarize_episodes,
)
from graspgait_env.agents.imitation import imitate
from graspgait_env.agents.seeding import seed_everything, set_torch_threads
from graspgait_env.atomic import write_text_atomic
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.extras import require_extra

__all__ = ["TrainResult", "train", "run_name", "build_model", "make_vec_env_for",
           "selection_score", "init_from_model"]


@dataclass(frozen=True)
class TrainResult:
    """What :func:`train` returns.

    Attributes
    ----------
    run_dir
        The run's folder.
    model_path
        The final model (``run_dir/model.zip``; its card is ``model.json``).
    steps
        Environment steps trained (all envs together; counted from 0 across resumes).
    wall_s
        Training wall time (s), including the runs this one resumed.
    last_eval
        The final evaluation's numbers (:func:`graspgait_env.agents.evaluate.summarize_episodes`).
    """

    run_dir: Path
    model_path: Path
    steps: int
    wall_s: float
    last_eval: dict[str, Any]


def selection_score(summary: dict[str, Any],
                    success_floor: float | None = None) -> tuple[float, ...]:
    """The rank of a periodic evaluation for ``best.zip``: the largest score wins.

    Parameters
    ----------
    summary
        :func:`graspgait_env.agents.evaluate.summarize_episodes`' numbers
        (``success_rate_solvable``,
        ``regrasps_vs_optimal``; None counts as 0 success and infinitely many regrasps).
    success_floor
        None: ``(success rate, -regrasps vs optimum)``, success first. A rate in [0, 1]:
        every evaluation reaching it ranks above every one that does not; among those
        reaching it the fewest regrasps relative to the optimum win (success no longer
        counts), below it the rule without a floor applies.

    Examples
    --------
    >>> a = {"success_rate_solvable": 1.0, "regrasps_vs_optimal": 1.15}
    >>> b = {"success_rate_solvable": 0.99, "regrasps_vs_optimal": 1.05}
    >>> selection_score(a) > selection_score(b)
    True
    >>> selection_score(a, 0.98) > selection_score(b, 0.98)
    False
    """
    rate = summary.get("success_rate_solvable") or 0.0
    ratio = summary.get("regrasps_vs_optimal")
    fewer = -(ratio if ratio is not None else float("inf"))
    if success_floor is None:
        return (rate, fewer)
    if rate >= success_floor:
        return (1.0, fewer, rate)
    return (0.0, rate, fewer)


def run_name(config: TrainConfig, when: datetime | None = None) -> str:
    """``{env_id}-{config name}-s{seed}-{YYYYmmdd-HHMMSS}`` (local time)."""
    stamp = (when or datetime.now()).strftime("%Y%m%d-%H%M%S")
    return f"{config.env_id}-{config.name}-s{config.seed}-{stamp}"


def _new_run_dir(config: TrainConfig) -> Path:
    root = Path(config.run_root)
    base = root / run_name(config)
    path, i = base, 1
    while path.exists():  # two runs in the same second
        i += 1
        path = Path(f"{base}-{i}")
    path.mkdir(parents=True)
    return path


def make_vec_env_for(config: TrainConfig, n_envs: int | None = None) -> Any:
    """The SB3 vector env of ``config`` (``n_envs`` envs, env ``i`` seeded ``seed + i``),
    with ``wrappers`` and then ``train_wrappers``."""
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    env_id, kwargs = config.env_id, dict(config.env_kwargs)
    wrappers = (*config.wrappers, *config.train_wrappers)  # training envs: both
    make_env(env_id, kwargs, wrappers).close()  # bad keywords fail here, in this process
    if config.vec_env == "batched":
        from graspgait_env.agents.vec_env import make_batched_vec_env

        if env_id not in ("GraspGait-v0", "GraspGaitRandom-v0") or wrappers:
            raise GraspGaitInputError(
                f"vec_env='batched' with env_id={env_id!r}, wrappers={list(wrappers)}: the "
                "batched envs are GraspGait-v0 and GraspGaitRandom-v0 without wrappers or "
                "train_wrappers; use vec_env=dummy")
        return make_batched_vec_env(n_envs or config.n_envs, seed=config.seed,
                                    env_kwargs=kwargs, env_id=env_id)
    cls = SubprocVecEnv if config.vec_env == "subproc" else DummyVecEnv
    return make_vec_env(lambda: make_env(env_id, kwargs, wrappers),
                        n_envs=n_envs or config.n_envs, seed=config.seed, vec_env_cls=cls)


def _algo_class(algo: str) -> type:
    if algo == "maskable_ppo":
        from sb3_contrib import MaskablePPO

        return MaskablePPO
    from stable_baselines3 import PPO

    return PPO


def extractor_kwargs(config: TrainConfig) -> dict[str, Any]:
    """The keyword arguments ``config``'s features extractor is built with (the config's
    own).

    Raises
    ------
    GraspGaitInputError
        ``features_extractor`` is the retired
        :class:`~graspgait_env.agents.policies.GraspMapExtractor` (it only loads models
        saved with it); the message names the named-parts design that replaces it. Or a
        key of ``features_extractor_kwargs`` is not a keyword of the extractor (the
        message names those it takes).
    """
    from graspgait_env.agents.policies import GraspMapExtractor

    kwargs = dict(config.features_extractor_kwargs)
    if config.features_extractor is None:
        return kwargs
    extractor = import_object(config.features_extractor, "features_extractor")
    if isinstance(extractor, type) and issubclass(extractor, GraspMapExtractor):
        raise GraspGaitInputError(
            f"features_extractor={config.features_extractor!r}: retired for training (it "
            "only loads the models saved with it); train on the env's named parts: "
            "env_kwargs observation_mode: dict, features_extractor: "
            "graspgait_env.agents.policies:PartsExtractor, policy: "
            "graspgait_env.agents.policies:MaskableRegraspScorerPolicy, as the bundled "
            "config general does (graspgait config train general)")
    _refuse_unknown_keys("features_extractor_kwargs", kwargs, "features_extractor",
                         config.features_extractor,
                         _keywords_of(extractor) - {"observation_space"})
    return kwargs


def _keywords_of(cls: Any) -> set[str]:
    """The keyword arguments ``cls(...)`` takes by name: those of each ``__init__`` along
    its MRO, down to the first that passes no ``**kwargs`` on (none where ``cls`` is not a
    class)."""
    import inspect

    names: set[str] = set()
    for klass in inspect.getmro(cls) if isinstance(cls, type) else ():
        if "__init__" in vars(klass):
            params = inspect.signature(klass.__init__).parameters.values()
            names |= {p.name for p in params
                      if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)}
            if not any(p.kind is p.VAR_KEYWORD for p in params):
                break
    return names - {"self"}


def _refuse_unknown_keys(field: str, given: Any, owner: str, name: Any,
                         names: set[str]) -> None:
    """Raise naming the keys of ``given`` (the config's ``field``) outside ``names``, the
    keywords of the config's ``owner`` ``name``, and those it takes."""
    unknown = sorted(set(given) - names)
    if unknown:
        raise GraspGaitInputError(f"{field} {unknown}: not keywords of {owner} {name!r}; "
                                  f"it takes {sorted(names)}")


def _check_policy_kwargs(config: TrainConfig, policy: Any) -> None:
    """Refuse a ``policy_kwargs`` key the policy class does not take, naming those it does
    (SB3 would raise a bare ``TypeError`` deep in the model's construction)."""
    if not config.policy_kwargs:
        return
    cls = (_algo_class(config.algo).policy_aliases.get(policy) if isinstance(policy, str)
           else policy)
    _refuse_unknown_keys("policy_kwargs", config.policy_kwargs, "policy", config.policy,
                         _keywords_of(cls) - {"observation_space", "action_space",
                                              "lr_schedule", *OWN_POLICY_KWARGS})


def build_model(config: TrainConfig, env: Any, tensorboard_log: str | None = None) -> Any:
    """A fresh PPO / MaskablePPO model for ``config`` on the vector env ``env``."""
    import torch

    policy_kwargs: dict[str, Any] = {
        "net_arch": config.net_arch,
        "activation_fn": {"tanh": torch.nn.Tanh, "relu": torch.nn.ReLU}[config.activation],
    }
    if config.features_extractor is not None:
        policy_kwargs["features_extractor_class"] = import_object(config.features_extractor,
                                                                  "features_extractor")
        policy_kwargs["features_extractor_kwargs"] = extractor_kwargs(config)
    policy_kwargs.update(config.policy_kwargs)
    lr: Any = config.learning_rate
    if config.lr_schedule == "linear":
        lr0 = config.learning_rate

        def lr(progress_remaining: float) -> float:  # SB3: 1 at the start, 0 at the end
            return lr0 * progress_remaining

    policy: Any = (config.policy if config.policy == "MlpPolicy"
                   else import_object(config.policy, "policy"))
    _check_policy_kwargs(config, policy)
    return _algo_class(config.algo)(
        policy, env, learning_rate=lr, n_steps=config.n_steps,
        batch_size=config.batch_size, n_epochs=config.n_epochs, gamma=config.gamma,
        gae_lambda=config.gae_lambda, clip_range=config.clip_range, ent_coef=config.ent_coef,
        vf_coef=config.vf_coef, max_grad_norm=config.max_grad_norm,
        policy_kwargs=policy_kwargs, tensorboard_log=tensorboard_log, seed=config.seed,
        device=config.device, verbose=0)


def _callbacks(config: TrainConfig, run_dir: Path, card_base: dict[str, Any],
               progress: bool, wall_before: float, t0: float) -> Any:
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.logger import HParam

    class Periodic(BaseCallback):
        """Progress bar, periodic evaluation against the optimum, checkpoints, best model."""

        def __init__(self) -> None:
            super().__init__()
            # GraspGait-v0: the evaluation episodes side by side in the batched env (the
            # same records as one by one, in a fraction of the time); else one by one
            self.eval_venv = batched_eval_env(config.env_id, config.env_kwargs,
                                              config.wrappers,
                                              min(config.eval_episodes, EVAL_BATCH))
            self.eval_env = (make_env(config.env_id, config.env_kwargs, config.wrappers)
                             if self.eval_venv is None else None)
            self.refs = ReferenceGaits()
            self.evaluations: list[dict[str, Any]] = []
            path = run_dir / "evaluations.json"
            if path.is_file():  # resumed run: keep the earlier evaluations
                self.evaluations = json.loads(path.read_text(encoding="utf-8"))
            self.best: tuple[float, ...] | None = None
            self.last: dict[str, Any] = {}
            self.bar = None

        def card(self, steps: int) -> dict[str, Any]:
            return {**card_base, "steps": steps,
                    "wall_s": wall_before + time.perf_counter() - t0,
                    "eval": self.last or None}

        def _on_training_start(self) -> None:
            n = self.model.num_timesteps
            self.next_eval = (n // config.eval_freq + 1) * config.eval_freq \
                if config.eval_freq else None
            self.next_ckpt = (n // config.checkpoint_freq + 1) * config.checkpoint_freq \
                if config.checkpoint_freq else None
            self.bar = tqdm(total=config.total_timesteps, initial=n, desc=config.name,
                            unit="step", disable=not progress, dynamic_ncols=True)
            hp = {k: (v if isinstance(v, (int, float, str, bool)) else json.dumps(v))
                  for k, v in config.to_dict().items() if v is not None}
            self.logger.record("hparams", HParam(hp, {"eval/success_rate": 0.0,
                                                      "eval/regrasps_vs_optimal": 0.0}),
                               exclude=("stdout", "log", "json", "csv"))

        def evaluate(self) -> dict[str, Any]:
            if self.eval_venv is not None:
                records = run_episodes_batched(agent_batch_predictor(self.model),
                                               self.eval_venv, config.eval_episodes,
                                               EVAL_SEED, self.refs)
            else:
                records = run_episodes(agent_predictor(self.model, deterministic=True),
                                       self.eval_env, config.eval_episodes, EVAL_SEED,
                                       self.refs)
            summ = summarize_episodes(records)
            steps = int(self.model.num_timesteps)
            self.last = {"steps": steps, **summ}
            self.evaluations.append(self.last)
            write_text_atomic(run_dir / "evaluations.json",
                              json.dumps(self.evaluations, indent=1) + "\n")
            for key in ("success_rate", "success_rate_solvable", "mean_regrasps",
                        "mean_optimal_regrasps", "regrasps_vs_optimal", "mean_rule_regrasps",
                        "regrasps_vs_rule", "illegal_action_rate"):
                if summ[key] is not None:
                    self.logger.record(f"eval/{key}", summ[key])
            self.logger.dump(steps)
            rate = summ["success_rate_solvable"] or 0.0
            score = selection_score(summ, config.best_success_floor)
            if self.best is None or score > self.best:
                self.best = score
                save_agent(self.model, run_dir / "best.zip", self.card(steps))
            if self.bar is not None:
                self.bar.set_postfix(success=f"{rate:.0%}",
                                     vs_opt=f"{summ['regrasps_vs_optimal'] or 0:.2f}")
            return self.last

        def _on_step(self) -> bool:
            n = self.model.num_timesteps
            if self.bar is not None:  # the last rollout may overshoot the total
                self.bar.update(min(n, config.total_timesteps) - self.bar.n)
            if self.next_ckpt is not None and n >= self.next_ckpt:
                self.next_ckpt += config.checkpoint_freq
                save_agent(self.model, run_dir / "checkpoints" / f"model_{n}_steps.zip",
                           self.card(n))
            if self.next_eval is not None and n >= self.next_eval:
                self.next_eval += config.eval_freq
                self.evaluate()
            return True

        def close(self) -> None:
            if self.bar is not None:
                self.bar.close()
            for env in (self.eval_env, self.eval_venv):
                if env is not None:
                    env.close()

    return Periodic()


def init_from_model(model: Any, config: TrainConfig) -> dict[str, Any]:
    """Copy the policy and value weights of ``config.init_model`` into ``model``, the
    policy head scaled by ``config.init_logit_scale``.

    Parameters
    ----------
    model
        A fresh model of ``config`` (:func:`build_model`).
    config
        Its config; ``config.init_model`` names the saved model to start from.

    Returns
    -------
    dict
        The card's ``init`` record: ``model`` (the path), ``steps`` and ``wall_s`` (the
        training behind those weights, its own ``init`` included).

    Raises
    ------
    GraspGaitInputError
        No such file, or a model of another algorithm, observation or action space, or
        network.
    """
    try:
        path = resolve_model(str(config.init_model))
    except GraspGaitInputError as exc:  # the message lists the shipped agents
        raise GraspGaitInputError(f"init_model: {exc}") from None
    source, card = load_agent(path, device=config.device)  # its algo read from the zip
    if card["algo"] != config.algo:
        raise GraspGaitInputError(f"init_model={str(path)!r}: a {card['algo']} model, the "
                                  f"config trains {config.algo}; set algo={card['algo']}")
    for what in ("observation_space", "action_space"):
        mine, theirs = getattr(model, what), getattr(source, what)
        if mine != theirs:
            raise GraspGaitInputError(
                f"init_model={str(path)!r}: its {what} is {theirs}, this config's env gives "
                f"{mine}; train with the env keywords it was trained with "
                f"(env_kwargs={card.get('env_kwargs')})")
    try:
        model.policy.load_state_dict(source.policy.state_dict())
    except RuntimeError as exc:
        first = str(exc).splitlines()[0]
        raise GraspGaitInputError(
            f"init_model={str(path)!r}: its network does not fit this config's ({first}); "
            f"set net_arch={card.get('config', {}).get('net_arch')}, policy_kwargs="
            f"{card.get('config', {}).get('policy_kwargs', {})} and its features "
            "extractor") from None
    if config.init_logit_scale != 1.0:  # a flatter policy, the same greedy actions
        import torch

        with torch.no_grad():
            for param in model.policy.action_net.parameters():
                param.mul_(config.init_logit_scale)
    before = card.get("init") or {}
    return {"model": str(config.init_model),
            "steps": int(card.get("steps") or 0) + int(before.get("steps") or 0),
            "wall_s": float(card.get("wall_s") or 0.0) + float(before.get("wall_s") or 0.0)}


def _resume_dir(checkpoint: Path) -> Path:
    """The run folder of a checkpoint (``RUN/checkpoints/x.zip`` -> ``RUN``; else its folder)."""
    parent = checkpoint.resolve().parent
    return parent.parent if parent.name == "checkpoints" else parent


def train(config: TrainConfig, *, run_dir: str | os.PathLike[str] | None = None,
          resume: str | os.PathLike[str] | None = None, progress: bool = True) -> TrainResult:
    """Train an agent as ``config`` says; save it with its card; return where and how well.

    Parameters
    ----------
    config
        The hyper-parameters (:func:`graspgait_env.agents.config.load_train_config`).
    run_dir
        The run's folder; default a new one under ``config.run_root`` named by
        :func:`run_name` (or, with ``resume``, the checkpoint's run folder).
    resume
        A checkpoint ``.zip`` (``RUN/checkpoints/model_N_steps.zip``, or any model
        saved by this module): training continues from its weights, optimizer state and
        step count up to ``config.total_timesteps``. The environments restart from fresh
        episodes, so a resumed run is not bit-identical to an uninterrupted one.
    progress
        Show a tqdm progress bar.

    Returns
    -------
    TrainResult

    Raises
    ------
    GraspGaitInputError
        Bad env keywords, a missing checkpoint, or a checkpoint of another algorithm or
        observation size.
    MissingExtraError
        The ``[train]`` extra (torch, stable-baselines3, ...) is not installed.
    """
    require_extra("train", "graspgait_env.agents.train.train")
    set_torch_threads(config.torch_threads)
    seed_everything(config.seed)
    wall_before = 0.0
    ckpt: Path | None = None
    if resume is not None:
        ckpt = Path(resume)
        if not ckpt.is_file():
            raise GraspGaitInputError(f"--resume {str(resume)!r}: no such checkpoint; give a "
                                      "RUN/checkpoints/model_N_steps.zip")
        card = read_card(ckpt)
        if card.get("algo") not in (None, config.algo):
            raise GraspGaitInputError(f"--resume {str(resume)!r}: a {card['algo']} model, the "
                                      f"config trains {config.algo}; resume with its config")
        wall_before = float(card.get("wall_s") or 0.0)
        done = int(card.get("steps") or 0)
        if done >= config.total_timesteps:
            raise GraspGaitInputError(
                f"--resume {str(resume)!r}: already trained {done} steps, total_timesteps is "
                f"{config.total_timesteps}; raise it, e.g. --set total_timesteps={2 * done}")
    env = make_vec_env_for(config)
    init: dict[str, Any] | None = None
    try:
        if ckpt is not None:
            model = _algo_class(config.algo).load(ckpt, env=env, device=config.device)
            init = read_card(ckpt).get("init")  # the weights it started from, if any
        else:
            model = build_model(config, env)
            if config.init_model is not None:
                init = init_from_model(model, config)
    except BaseException:
        env.close()
        raise
    # the run folder only once the model stands: a refused init_model leaves none behind
    run = Path(run_dir) if run_dir is not None else (
        _resume_dir(ckpt) if ckpt is not None else _new_run_dir(config))
    run.mkdir(parents=True, exist_ok=True)
    model.tensorboard_log = str(run / "tb")  # read by learn()
    write_text_atomic(run / "config.yaml", yaml.safe_dump(config.to_dict(), sort_keys=False))
    probe = make_env(config.env_id, config.env_kwargs, config.wrappers)
    contact_model = contact_model_of(probe)
    probe.close()
    card_base = {"algo": config.algo, "env_id": config.env_id,
                 "env_kwargs": dict(config.env_kwargs), "wrappers": list(config.wrappers),
                 "contact_model": contact_model, "config": config.to_dict(),
                 "seed": config.seed, "run_dir": str(run)}
    if init is not None:
        card_base["init"] = init
    t0 = time.perf_counter()
    if config.imitation is not None and ckpt is None:  # DAgger first (agents/imitation)
        try:
            card_base["imitation"] = imitate(model, env, config.imitation, seed=config.seed,
                                             progress=progress)
        except BaseException:
            env.close()
            raise
    cb = _callbacks(config, run, card_base, progress, wall_before, t0)
    try:
        model.learn(total_timesteps=config.total_timesteps - int(model.num_timesteps),
                    callback=cb, reset_num_timesteps=ckpt is None, tb_log_name="run")
        if not cb.last or cb.last["steps"] != model.num_timesteps:
            cb.evaluate()
        steps = int(model.num_timesteps)
        model_path = save_agent(model, run / "model.zip", cb.card(steps))
    finally:
        cb.close()
        env.close()
    return TrainResult(run_dir=run, model_path=model_path, steps=steps,
                       wall_s=wall_before + time.perf_counter() - t0, last_eval=dict(cb.last))
