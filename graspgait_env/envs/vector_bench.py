"""Speed of the batched ``GraspGait-v0`` beside the single env, and of the batched
``GraspGaitRandom-v0`` beside ``SyncVectorEnv``, measured in one process.

Run from the command line (``python -m graspgait_env.envs.vector_bench``) or through
``graspgait perf`` (listed in ``BENCHMARK_MODULES``).

Both envs play the same masked random policy (a uniform legal action per step, drawn
from uniforms made beforehand): the single env through ``gymnasium.make`` (its default
wrappers, the time limit included; :func:`graspgait_env.envs.bench.graspgait_steps_per_s`),
the batched env through ``gymnasium.make_vec(..., vectorization_mode=
"vector_entry_point")`` with :func:`~graspgait_env.envs.vector_env.sample_legal_actions`
drawing all ``N`` actions in one call (its time counts, as the single env's draw does).
Both autoreset at episode ends. Rates are env-steps per second (``N`` per batched
step), the best of ``rounds`` rounds, the rounds of the two envs interleaved so that
both see the same machine.
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

from graspgait_env.envs.bench import graspgait_steps_per_s
from graspgait_env.envs.registration import register_envs
from graspgait_env.envs.vector_env import sample_legal_actions
from graspgait_env.timing import BenchRow, register

__all__ = ["BATCH_NUM_ENVS", "RANDOM_NUM_ENVS", "RATIO_TARGET", "AIM_STEPS_PER_S",
           "batched_steps_per_s", "bench_batched", "bench_rows"]

BATCH_NUM_ENVS = 256  # sub-envs of the batched env in the speed target
RANDOM_NUM_ENVS = 64  # sub-envs of the batched GraspGaitRandom-v0 row
RATIO_TARGET = 10.0  # batched env-steps/s over the single env's steps/s, same process
AIM_STEPS_PER_S = 1_000_000.0  # (env-steps/s) the aim on this 2-core machine


def batched_steps_per_s(num_envs: int = BATCH_NUM_ENVS, batch_steps: int = 1000,
                        seed: int = 0, env_id: str = "GraspGait-v0",
                        mode: str = "vector_entry_point", **kwargs: Any) -> float:
    """Env-steps per second of the batched ``env_id`` under masked random actions.

    Parameters
    ----------
    num_envs
        Sub-envs ``N``.
    batch_steps
        Calls to ``step`` timed (``N * batch_steps`` env-steps).
    seed
        Reset seed and the seed of the uniforms.
    env_id, mode
        The id (``GraspGait-v0`` or ``GraspGaitRandom-v0``) and Gymnasium's
        ``vectorization_mode``: ``"vector_entry_point"`` (the batched env) or ``"sync"``
        (``SyncVectorEnv`` over single envs, the reference).
    **kwargs
        The id's keyword arguments.
    """
    register_envs()
    env = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode=mode, **kwargs)
    u = np.random.default_rng(seed).random((batch_steps, num_envs))
    _, info = env.reset(seed=seed)
    mask = info["action_mask"]
    step = env.step
    t0 = time.perf_counter()
    for i in range(batch_steps):
        mask = step(sample_legal_actions(mask, u[i]))[4]["action_mask"]
    dt = time.perf_counter() - t0
    env.close()
    return num_envs * batch_steps / dt


def bench_batched(num_envs: int = BATCH_NUM_ENVS, batch_steps: int = 1000,
                  single_steps: int = 20_000, rounds: int = 3, seed: int = 0,
                  **kwargs: Any) -> dict[str, float]:
    """Batched and single ``GraspGait-v0`` steps/s (best of ``rounds``, interleaved).

    Returns
    -------
    dict
        ``batched_steps_per_s``, ``single_steps_per_s``, ``ratio`` (batched over single),
        ``num_envs``, ``rounds``.
    """
    if rounds < 1 or batch_steps < 1 or single_steps < 1:
        raise ValueError(f"rounds={rounds}, batch_steps={batch_steps}, "
                         f"single_steps={single_steps}: each must be >= 1")
    pairs = [(batched_steps_per_s(num_envs, batch_steps, seed + r, **kwargs),
              graspgait_steps_per_s(single_steps, seed + r, **kwargs)) for r in range(rounds)]
    b, s = (max(rates) for rates in zip(*pairs, strict=True))
    return {"batched_steps_per_s": b, "single_steps_per_s": s, "ratio": b / s,
            "num_envs": float(num_envs), "rounds": float(rounds)}


@register
def bench_rows(repeat: int) -> list[BenchRow]:
    """Rows for ``graspgait perf``: batched env-steps/s at N = 256 and the ratio to one env;
    the batched ``GraspGaitRandom-v0`` at N = 64 against ``SyncVectorEnv``."""
    rounds = max(1, min(3, repeat))
    res = bench_batched(rounds=rounds)
    b, s, ratio = res["batched_steps_per_s"], res["single_steps_per_s"], res["ratio"]
    n = BATCH_NUM_ENVS
    # GraspGaitRandom-v0, each sub-env its own objects: the batched env against
    # SyncVectorEnv over single envs (interleaved rounds, best of each)
    rn, steps = RANDOM_NUM_ENVS, 300
    pairs = [(batched_steps_per_s(rn, steps, r, env_id="GraspGaitRandom-v0", level=1),
              batched_steps_per_s(rn, steps, r, env_id="GraspGaitRandom-v0", mode="sync",
                                  level=1)) for r in range(rounds)]
    rb, rs = (max(rates) for rates in zip(*pairs, strict=True))
    # the batch of one: why the single env keeps its own scalar step (envs/rows.py)
    ones = [(batched_steps_per_s(1, 20_000, seed=r), graspgait_steps_per_s(20_000, r))
            for r in range(rounds)]
    b1, s1 = (max(rates) for rates in zip(*ones, strict=True))
    return [
        BenchRow("GraspGait-v0 single env / batched N=1", s1 / b1, "x", "", None,
                 f"{s1:.0f} against {b1:.0f} steps/s: the single env's scalar step over "
                 f"the batched step with one row; best of {rounds} x 20000 steps, same "
                 "process"),
        BenchRow(f"GraspGaitRandom-v0 batched N={rn} / SyncVectorEnv", rb / rs, "x", "", None,
                 f"{rb:.0f} against {rs:.0f} env-steps/s; level 1, masked random actions, "
                 f"best of {rounds} x {steps} steps of {rn}, same process"),
        BenchRow(f"GraspGait-v0 batched N={n} env-steps/s", b, "steps/s", "", None,
                 f"aim {AIM_STEPS_PER_S:.0f}; make_vec vector_entry_point, masked random "
                 f"actions, best of {rounds} x 1000 steps of {n}"),
        BenchRow(f"GraspGait-v0 batched N={n} / single env", ratio, "x",
                 f">= {RATIO_TARGET:g}x", ratio >= RATIO_TARGET,
                 f"single env {s:.0f} steps/s (gymnasium.make), same process, rounds "
                 "interleaved"),
    ]


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: print the measurement as JSON; exit 1 below the ratio target."""
    ap = argparse.ArgumentParser(prog="python -m graspgait_env.envs.vector_bench",
                                 description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--num-envs", type=int, default=BATCH_NUM_ENVS)
    ap.add_argument("--batch-steps", type=int, default=1000)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    res = bench_batched(args.num_envs, args.batch_steps, rounds=args.rounds)
    print(json.dumps(res, indent=1))
    return 0 if res["ratio"] >= RATIO_TARGET else 1


if __name__ == "__main__":
    sys.exit(main())
