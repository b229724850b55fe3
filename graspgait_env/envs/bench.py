"""Speed of ``GraspGait-v0`` beside ``CartPole-v1``, measured in one process.

Run from the command line (``python -m graspgait_env.envs.bench``) or through
``graspgait perf`` (this module registers a row with :func:`graspgait_env.timing.register`
once it is listed in ``BENCHMARK_MODULES``).

Both envs come from ``gymnasium.make`` (so with their default wrappers: the passive
env checker, order enforcing and the time limit). GraspGait's actions are drawn
uniformly from the legal moves (``info["action_mask"]``) with uniforms from a
preallocated array; CartPole's are preallocated random integers. Both reset at every
episode end. The rate is the best of ``rounds`` timed rounds (least disturbed by the
machine), the rounds of the two envs interleaved.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from graspgait_env.envs.registration import register_envs
from graspgait_env.timing import BenchRow, register

__all__ = ["bench_env_steps", "graspgait_steps_per_s", "cartpole_steps_per_s",
           "STEPS_PER_S_TARGET", "RATIO_TARGET", "bench_rows"]

STEPS_PER_S_TARGET = 20_000.0  # (steps/s) GraspGait-v0 under masked random actions
RATIO_TARGET = 0.3  # GraspGait-v0 steps/s over CartPole-v1 steps/s


def graspgait_steps_per_s(steps: int = 50_000, seed: int = 0, env_id: str = "GraspGait-v0",
                          **kwargs: Any) -> float:
    """Steps per second of ``gymnasium.make(env_id, **kwargs)`` under masked random actions."""
    register_envs()
    env = gym.make(env_id, **kwargs)
    u = np.random.default_rng(seed).random(steps)
    _, info = env.reset(seed=seed)
    mask = info["action_mask"]
    flatnonzero = np.flatnonzero
    t0 = time.perf_counter()
    for i in range(steps):
        legal = flatnonzero(mask)
        _, _, term, trunc, info = env.step(legal[int(u[i] * legal.size)])
        mask = info["action_mask"]
        if term or trunc:
            _, info = env.reset()
            mask = info["action_mask"]
    dt = time.perf_counter() - t0
    env.close()
    return steps / dt


def cartpole_steps_per_s(steps: int = 50_000, seed: int = 0) -> float:
    """Steps per second of ``gymnasium.make("CartPole-v1")`` under random actions."""
    env = gym.make("CartPole-v1")
    acts = np.random.default_rng(seed).integers(0, 2, steps).tolist()
    env.reset(seed=seed)
    t0 = time.perf_counter()
    for i in range(steps):
        _, _, term, trunc, _ = env.step(acts[i])
        if term or trunc:
            env.reset()
    dt = time.perf_counter() - t0
    env.close()
    return steps / dt


def bench_env_steps(steps: int = 50_000, rounds: int = 3, seed: int = 0,
                    **kwargs: Any) -> dict[str, float]:
    """GraspGait-v0 and CartPole-v1 steps/s (best of ``rounds``) and their ratio.

    Returns
    -------
    dict
        ``graspgait_steps_per_s``, ``cartpole_steps_per_s``, ``ratio`` (GraspGait over
        CartPole), ``steps``, ``rounds``.
    """
    if rounds < 1 or steps < 1:
        raise ValueError(f"steps={steps}, rounds={rounds}: both must be >= 1")
    gg, cp = [], []
    for r in range(rounds):
        gg.append(graspgait_steps_per_s(steps, seed + r, **kwargs))
        cp.append(cartpole_steps_per_s(steps, seed + r))
    g, c = max(gg), max(cp)
    return {"graspgait_steps_per_s": g, "cartpole_steps_per_s": c, "ratio": g / c,
            "steps": float(steps), "rounds": float(rounds)}


@register
def bench_rows(repeat: int) -> list[BenchRow]:
    """Rows for ``graspgait perf``: env steps/s and the ratio to CartPole-v1."""
    rounds = max(1, min(3, repeat))
    res = bench_env_steps(steps=20_000, rounds=rounds)
    g, c, ratio = res["graspgait_steps_per_s"], res["cartpole_steps_per_s"], res["ratio"]
    what = f"gymnasium.make, masked random actions, best of {rounds} x 20000 steps"
    return [
        BenchRow("GraspGait-v0 steps/s", g, "steps/s", f">= {STEPS_PER_S_TARGET:.0f}",
                 g >= STEPS_PER_S_TARGET, what),
        BenchRow("CartPole-v1 steps/s", c, "steps/s", "", None, "gymnasium.make, random actions"),
        BenchRow("GraspGait-v0 / CartPole-v1", ratio, "x", f">= {RATIO_TARGET:g}x",
                 ratio >= RATIO_TARGET, "same process"),
    ]


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: print the measurement as JSON; exit 1 below a target."""
    ap = argparse.ArgumentParser(prog="python -m graspgait_env.envs.bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=50_000)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    res = bench_env_steps(args.steps, args.rounds)
    print(json.dumps(res, indent=1))
    ok = res["graspgait_steps_per_s"] >= STEPS_PER_S_TARGET and res["ratio"] >= RATIO_TARGET
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
