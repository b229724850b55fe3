"""Soak test: many random masked-policy steps, counting anything that goes wrong.

Run from the command line::

    python -m graspgait_env.envs.soak --steps 1000000 --seeds 20

Each ``(object, seed)`` run makes its share of the steps in ``gymnasium.make``'s env
(time limit included), with actions drawn uniformly from the legal moves by a NumPy
generator seeded with ``seed`` (and, with probability ``illegal_fraction``, an
illegal action instead, to exercise that path), resetting at every episode end. Every
step checks: no exception, a finite observation and reward, the observation inside
the observation space, the reward equal to the sum of its terms, and (``check_model``)
the env's mask and state against :class:`GaitModel`'s own ``action_mask`` and ``apply``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from graspgait_env.envs.registration import register_envs
from graspgait_env.objects import bundled_objects

__all__ = ["soak", "main"]


def _run_one(env_id: str, kwargs: dict[str, Any], seed: int, steps: int,
             illegal_fraction: float, check_model: bool, counts: dict[str, int],
             errors: list[str]) -> None:
    env = gym.make(env_id, **kwargs)
    space = env.observation_space
    lo, hi = space.low, space.high
    u = env.unwrapped
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    mask = info["action_mask"]
    counts["episodes"] += 1
    for _ in range(steps):
        legal = np.flatnonzero(mask)
        illegal = np.flatnonzero(~mask)
        if illegal.size and rng.random() < illegal_fraction:
            a = int(illegal[rng.integers(illegal.size)])
        else:
            a = int(legal[rng.integers(legal.size)])
        before = u.state
        try:
            obs, r, term, trunc, info = env.step(a)
        except Exception:  # noqa: BLE001 - a soak counts failures, it does not stop
            counts["exceptions"] += 1
            if len(errors) < 5:
                errors.append(traceback.format_exc())
            obs, info = env.reset()
            mask = info["action_mask"]
            continue
        counts["steps"] += 1
        if not (np.all(np.isfinite(obs)) and np.isfinite(r)):
            counts["nonfinite"] += 1
        if obs.dtype != space.dtype or obs.shape != space.shape or not (
                np.all(obs >= lo) and np.all(obs <= hi)):
            counts["outside_space"] += 1
        if r != sum(info["reward_terms"].values()):
            counts["reward_mismatch"] += 1
        if info["reward_terms"]["illegal"] != 0.0:
            counts["illegal_actions"] += 1
        mask = info["action_mask"]
        if check_model:
            m = u.model
            want = m.apply(before, a) if m.action_mask(before)[a] else before
            if u.state != want or not np.array_equal(m.action_mask(u.state), mask):
                counts["model_mismatch"] += 1
        if term or trunc:
            counts["successes"] += int(info["is_success"])
            counts["truncations"] += int(trunc and not term)
            counts["failures"] += int(term and not info["is_success"])
            obs, info = env.reset()
            mask = info["action_mask"]
            counts["episodes"] += 1
    env.close()


def soak(total_steps: int = 1_000_000, seeds: Sequence[int] | int = 20,
         objects: Sequence[str] | None = None, env_id: str = "GraspGait-v0",
         random_levels: Sequence[int] = (), illegal_fraction: float = 0.01,
         check_model: bool = True, mu: float = 0.7) -> dict[str, Any]:
    """Run ``total_steps`` random masked steps over ``objects`` × ``seeds``; return counts.

    Parameters
    ----------
    total_steps
        Steps in all, split evenly over the runs.
    seeds
        Seeds (or their number: ``range(seeds)``), one run per object and seed.
    objects
        Object names for ``env_id`` (default every bundled object).
    env_id
        The fixed-object id the objects run in.
    random_levels
        Also run ``GraspGaitRandom-v0`` at these levels (one run per level and seed).
    illegal_fraction
        Probability of an illegal action at a step.
    check_model
        Compare the env's mask and state with ``GaitModel`` at every step.
    mu
        Friction for the fixed-object runs.

    Returns
    -------
    dict
        ``steps, episodes, successes, failures, truncations, illegal_actions,
        exceptions, nonfinite, outside_space, reward_mismatch, model_mismatch, runs,
        wall_s, steps_per_s, errors`` (the first tracebacks, if any).
    """
    register_envs()
    seeds = list(range(seeds)) if isinstance(seeds, int) else list(seeds)
    objects = bundled_objects() if objects is None else list(objects)
    runs: list[tuple[str, dict[str, Any], int]] = [
        (env_id, {"object": o, "mu": mu}, s) for o in objects for s in seeds]
    runs += [("GraspGaitRandom-v0", {"level": lv}, s) for lv in random_levels for s in seeds]
    if not runs:
        raise ValueError("soak: no runs (give objects or random_levels, and seeds)")
    counts = dict.fromkeys(
        ("steps", "episodes", "successes", "failures", "truncations", "illegal_actions",
         "exceptions", "nonfinite", "outside_space", "reward_mismatch", "model_mismatch"), 0)
    errors: list[str] = []
    per_run = max(1, total_steps // len(runs))
    t0 = time.perf_counter()
    for i, (eid, kw, s) in enumerate(runs):
        n = per_run + (1 if i < total_steps - per_run * len(runs) else 0)
        _run_one(eid, kw, s, n, illegal_fraction, check_model, counts, errors)
    wall = time.perf_counter() - t0
    return {**counts, "runs": len(runs), "wall_s": wall,
            "steps_per_s": counts["steps"] / wall if wall > 0 else 0.0, "errors": errors}


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: print the counts as JSON; exit 1 if anything went wrong."""
    ap = argparse.ArgumentParser(prog="python -m graspgait_env.envs.soak", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=1_000_000, help="total steps (default 1e6)")
    ap.add_argument("--seeds", type=int, default=20, help="number of seeds (default 20)")
    ap.add_argument("--objects", nargs="*", default=None, help="default: every bundled object")
    ap.add_argument("--random-levels", type=int, nargs="*", default=[],
                    help="also run GraspGaitRandom-v0 at these levels")
    ap.add_argument("--illegal-fraction", type=float, default=0.01)
    ap.add_argument("--no-check-model", action="store_true",
                    help="skip the per-step comparison with GaitModel (faster)")
    args = ap.parse_args(argv)
    out = soak(args.steps, args.seeds, args.objects, random_levels=args.random_levels,
               illegal_fraction=args.illegal_fraction, check_model=not args.no_check_model)
    print(json.dumps(out, indent=1))
    bad = sum(out[k] for k in ("exceptions", "nonfinite", "outside_space", "reward_mismatch",
                               "model_mismatch"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
