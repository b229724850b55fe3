"""Training throughput: MaskablePPO on the batched ``GraspGait-v0`` beside ``DummyVecEnv``.

Two measurements, each for ``vec_env="batched"`` (:mod:`graspgait_env.agents.vec_env`) and
``vec_env="dummy"`` (SB3's ``DummyVecEnv`` over ``gymnasium.make`` envs), with the same
training config (:func:`graspgait_env.agents.config.load_train_config`; the bundled ``ellipse`` by
default) and seed:

- :func:`ppo_steps_per_s`: env-steps per second of ``MaskablePPO.learn`` (rollouts and
  updates together) over a small budget; ``graspgait perf`` shows it.
- :func:`time_to_success`: training wall time (evaluations excluded) and env-steps until
  the greedy policy succeeds in ``target`` (95%) of the evaluation episodes: every
  ``eval_every`` steps, ``eval_episodes`` episodes from the starts of training's
  periodic evaluation (reset seeds ``EVAL_SEED + i``), played together in one batched
  env, each until its first episode ends. Measured once; docs/scale-out.md gives the command
  (``python -m graspgait_env.agents.throughput``) and the figures.

Both vector envs give the same transitions for the same seeds, so the two runs learn the
same policy step for step; only the wall time differs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from graspgait_env.agents.config import load_train_config
from graspgait_env.agents.evaluate import EVAL_SEED
from graspgait_env.agents.seeding import seed_everything, set_torch_threads
from graspgait_env.agents.train import build_model, make_vec_env_for
from graspgait_env.envs.vector_env import GraspGaitVectorEnv
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.timing import BenchRow, register

__all__ = ["ppo_steps_per_s", "success_rate", "time_to_success", "bench_rows",
           "SUCCESS_TARGET"]

SUCCESS_TARGET = 0.95  # success rate of the greedy policy that ends the clock


def _setup(config_name: str, vec_env: str, overrides: Sequence[str]) -> tuple[Any, Any, Any]:
    config = load_train_config(config_name, [f"vec_env={vec_env}", *overrides])
    set_torch_threads(1)
    seed_everything(config.seed)
    env = make_vec_env_for(config)
    return config, env, build_model(config, env)


def ppo_steps_per_s(vec_env: str = "batched", config_name: str = "ellipse",
                    rollouts: int = 2, overrides: Sequence[str] = ()) -> float:
    """Env-steps per second of ``MaskablePPO.learn`` for ``rollouts`` rollouts.

    Parameters
    ----------
    vec_env
        ``"batched"`` or ``"dummy"`` (``"subproc"`` works too).
    config_name
        A bundled training config or YAML path (its ``n_envs``, ``n_steps``, network...).
    rollouts
        Rollouts of ``n_envs * n_steps`` env-steps timed, each followed by its update.
    overrides
        ``key=value`` config overrides.
    """
    config, env, model = _setup(config_name, vec_env, overrides)
    steps = rollouts * config.n_envs * config.n_steps
    try:
        t0 = time.perf_counter()
        model.learn(total_timesteps=steps)
        dt = time.perf_counter() - t0
    finally:
        env.close()
    return model.num_timesteps / dt


def success_rate(model: Any, env_kwargs: dict[str, Any], episodes: int,
                 seed: int = EVAL_SEED) -> float:
    """Fraction of ``episodes`` greedy episodes that reach the turn.

    Episode ``i`` starts from ``reset(seed=seed + i)`` (the starts of training's periodic
    evaluation); all are played at once in a :class:`GraspGaitVectorEnv`, each until
    its first episode ends (success, dead end, wrong way or the 500-step limit).
    """
    venv = GraspGaitVectorEnv(episodes, **env_kwargs)
    obs, _ = venv.reset(seed=seed)
    running = np.ones(episodes, dtype=bool)
    success = np.zeros(episodes, dtype=bool)
    while running.any():
        actions, _ = model.predict(obs, deterministic=True, action_masks=venv.action_masks())
        obs, _, term, trunc, info = venv.step(np.asarray(actions, dtype=np.int64))
        ended = running & (term | trunc)
        success[ended] = info["is_success"][ended]
        running &= ~ended
    venv.close()
    return float(success.mean())


def time_to_success(vec_env: str = "batched", config_name: str = "ellipse",
                    target: float = SUCCESS_TARGET, eval_every: int = 10_000,
                    eval_episodes: int = 40, max_steps: int | None = None,
                    overrides: Sequence[str] = (), progress: bool = True) -> dict[str, Any]:
    """Train until the greedy policy succeeds in ``target`` of the evaluation episodes.

    Returns
    -------
    dict
        ``reached`` (bool), ``steps`` and ``train_s`` (training wall time, evaluations
        excluded) at the first evaluation at or above ``target`` (else at the end),
        ``steps_per_s``, and ``curve``: ``[steps, train_s, success_rate]`` per evaluation.
    """
    from stable_baselines3.common.callbacks import BaseCallback
    from tqdm.auto import tqdm

    if not 0.0 < target <= 1.0:
        raise GraspGaitInputError(f"target={target!r}: a success rate in (0, 1], e.g. 0.95")
    config, env, model = _setup(config_name, vec_env, overrides)
    if config.env_id != "GraspGait-v0":
        raise GraspGaitInputError(f"config {config_name!r}: env_id={config.env_id!r}; the "
                                  "time to success is measured on GraspGait-v0")
    budget = max_steps or config.total_timesteps
    curve: list[list[float]] = []
    bar = tqdm(total=budget, desc=f"train ({vec_env})", unit="step", disable=not progress)

    class Clock(BaseCallback):
        """Evaluate every ``eval_every`` steps; the evaluation's time is not counted."""

        def __init__(self) -> None:
            super().__init__()
            self.train_s, self.t0, self.next = 0.0, 0.0, eval_every

        def _on_training_start(self) -> None:
            self.t0 = time.perf_counter()

        def _on_step(self) -> bool:
            bar.n = self.num_timesteps
            if self.num_timesteps < self.next:
                return True
            self.train_s += time.perf_counter() - self.t0
            self.next += eval_every
            rate = success_rate(self.model, dict(config.env_kwargs), eval_episodes)
            curve.append([self.num_timesteps, self.train_s, rate])
            bar.set_postfix(success=f"{rate:.0%}")
            self.t0 = time.perf_counter()
            return rate < target

    clock = Clock()
    try:
        model.learn(total_timesteps=budget, callback=clock)
    finally:
        bar.close()
        env.close()
    hit = next((c for c in curve if c[2] >= target), None)
    last = hit or (curve[-1] if curve else [model.num_timesteps, clock.train_s, 0.0])
    return {"vec_env": vec_env, "config": config.name, "n_envs": config.n_envs,
            "target": target, "reached": hit is not None, "steps": int(last[0]),
            "train_s": last[1], "steps_per_s": last[0] / last[1] if last[1] else None,
            "curve": curve}


PERF_ROLLOUTS = 1  # rollouts timed per vec env and round in `graspgait perf`
# a rollout of the same size (2048 steps) from 64 envs, one pass of updates: the time
# goes to collecting, where the vector env matters
ROLLOUT_HEAVY = ("n_envs=64", "n_steps=32", "n_epochs=1", "batch_size=256")


@register
def bench_rows(repeat: int) -> list[BenchRow]:
    """``graspgait perf`` rows: MaskablePPO env-steps/s, batched env beside DummyVecEnv
    (best of 2 rounds, the two vector envs interleaved)."""
    cfg = load_train_config("ellipse")
    rounds = max(1, min(2, repeat))
    what = (f"ellipse config (n_envs={cfg.n_envs}, n_steps={cfg.n_steps}, "
            f"{cfg.n_epochs} epochs), best of {rounds} x {PERF_ROLLOUTS} rollout, "
            "1 torch thread")
    rows = []
    for label, overrides, detail in (
            ("", (), what),
            (", 64 envs, 1 epoch", ROLLOUT_HEAVY,
             "the ellipse config with " + ", ".join(ROLLOUT_HEAVY) + f": collection-bound; "
             f"best of {rounds} x {PERF_ROLLOUTS} rollout")):
        pairs = [(ppo_steps_per_s("dummy", rollouts=PERF_ROLLOUTS, overrides=overrides),
                  ppo_steps_per_s("batched", rollouts=PERF_ROLLOUTS, overrides=overrides))
                 for _ in range(rounds)]
        dummy, batched = (max(rates) for rates in zip(*pairs, strict=True))
        rows += [
            BenchRow(f"MaskablePPO env-steps/s{label}, DummyVecEnv", dummy, "steps/s", "",
                     None, detail),
            BenchRow(f"MaskablePPO env-steps/s{label}, batched env", batched, "steps/s", "",
                     None, f"{batched / dummy:.2f}x DummyVecEnv; {detail}"),
        ]
    return rows


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: time to 95% success for each vec env; print JSON."""
    ap = argparse.ArgumentParser(prog="python -m graspgait_env.agents.throughput",
                                 description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", default="ellipse", help="training config (default ellipse)")
    ap.add_argument("--vec-env", action="append", choices=("batched", "dummy", "subproc"),
                    help="vector env(s) to measure (default: batched and dummy)")
    ap.add_argument("--target", type=float, default=SUCCESS_TARGET)
    ap.add_argument("--eval-every", type=int, default=10_000)
    ap.add_argument("--eval-episodes", type=int, default=40)
    ap.add_argument("--max-steps", type=int)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--json", metavar="FILE", help="also write the results here")
    args = ap.parse_args(argv)
    out = [time_to_success(v, args.config, args.target, args.eval_every, args.eval_episodes,
                           args.max_steps, args.set) for v in args.vec_env or ("batched", "dummy")]
    text = json.dumps(out, indent=1)
    print(text)
    if args.json:
        from graspgait_env.atomic import write_text_atomic

        write_text_atomic(args.json, text + "\n")
    return 0 if all(r["reached"] for r in out) else 1


if __name__ == "__main__":
    sys.exit(main())
