"""``graspgait perf`` rows of the rendered envs: frames/s of both envs, moves/s on the hand.

Registered with :func:`graspgait_env.timing.register` once this module is listed in
:data:`graspgait_env.perf.BENCHMARK_MODULES`. Targets (issue "a view of the hand"):

- ``GraspGait-v0`` renders at least 20 frames/s, ``GraspGaitMujoco-v1`` at least 10,
  both at 640 x 480 (their frame size), with the defaults a user gets;
- ``GraspGaitMujoco-v1``'s masked random moves per second are reported (context, no
  target: each move is a simulated physical move of the thesis controller).

Frames: ``gymnasium.make(env_id, render_mode="rgb_array")``, masked random moves, one
``render()`` after each move (what Gymnasium's ``RecordVideo`` does); only the
``render()`` calls are timed, the first one (it builds the cached picture or the GL
context) apart. The rate is the number of frames over their summed wall time.
"""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym
import numpy as np

from graspgait_env.envs.registration import register_envs
from graspgait_env.timing import BenchRow, register

__all__ = ["render_rate", "bench_render_rows", "MAP_FRAMES_PER_S_TARGET",
           "MUJOCO_FRAMES_PER_S_TARGET"]

MAP_FRAMES_PER_S_TARGET = 20.0  # (frames/s) GraspGait-v0 at 640 x 480
MUJOCO_FRAMES_PER_S_TARGET = 10.0  # (frames/s) GraspGaitMujoco-v1 at 640 x 480


def render_rate(env_id: str, frames: int = 40, seed: int = 0, **kwargs: Any) -> dict[str, Any]:
    """Frames per second of ``env.render()`` along masked random moves.

    Parameters
    ----------
    env_id
        A registered GraspGait env id, e.g. ``"GraspGait-v0"``.
    frames
        Frames timed (after the first, which is timed apart).
    seed
        Seed of the first reset and of the moves.
    **kwargs
        Passed to ``gymnasium.make`` (``render_mode`` is ``"rgb_array"``).

    Returns
    -------
    dict
        ``frames_per_s`` (frames over their summed ``render()`` wall time),
        ``first_frame_s`` (wall time of the first ``render()``), ``shape`` (of a frame),
        ``frames``.
    """
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
        raise ValueError(f"frames={frames!r}: must be an integer >= 1, e.g. 40")
    register_envs()
    env = gym.make(env_id, render_mode="rgb_array", **kwargs)
    rng = np.random.default_rng(seed)
    _, info = env.reset(seed=seed)
    t0 = time.perf_counter()
    frame = env.render()
    first = time.perf_counter() - t0
    spent = 0.0
    for _ in range(frames):
        legal = np.flatnonzero(info["action_mask"])
        _, _, term, trunc, info = env.step(int(legal[rng.integers(legal.size)]))
        t0 = time.perf_counter()
        frame = env.render()
        spent += time.perf_counter() - t0
        if term or trunc:
            _, info = env.reset()
    env.close()
    return {"frames_per_s": frames / spent, "first_frame_s": first,
            "shape": tuple(frame.shape), "frames": frames}


@register
def bench_render_rows(repeat: int) -> list[BenchRow]:
    """Rows for ``graspgait perf``: frames/s of both envs, moves/s of the MuJoCo env."""
    from graspgait_env.envs.bench import graspgait_steps_per_s

    share = min(1.0, repeat / 20)  # full counts from --repeat 20 on; a quick look below it
    rows = []
    for env_id, target, frames in (
            ("GraspGait-v0", MAP_FRAMES_PER_S_TARGET, max(10, round(60 * share))),
            ("GraspGaitMujoco-v1", MUJOCO_FRAMES_PER_S_TARGET, max(10, round(30 * share)))):
        r = render_rate(env_id, frames=frames)
        h, w = r["shape"][:2]
        rows.append(BenchRow(
            f"{env_id} frames/s, {w}x{h}", r["frames_per_s"], "frames/s", f">= {target:g}",
            r["frames_per_s"] >= target,
            f"render_mode='rgb_array', defaults, a render() after each of {frames} masked "
            f"random moves; first frame {r['first_frame_s']:.2f} s (not counted)"))
    moves = max(30, round(150 * share))
    rate = graspgait_steps_per_s(steps=moves, seed=0, env_id="GraspGaitMujoco-v1")
    rows.append(BenchRow(
        "GraspGaitMujoco-v1 moves/s", rate, "moves/s", "", None,
        f"gymnasium.make, defaults, {moves} masked random moves with resets, each "
        "executed on the simulated hand"))
    return rows
