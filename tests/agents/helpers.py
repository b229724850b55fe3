"""Helpers shared by the agent tests."""

from __future__ import annotations


def kwargs_on_task(card: dict, task_id: str) -> dict:
    """A model card's env keywords on one benchmark task's problem (a generalist's
    ``GraspGaitRandom-v0`` keywords dropped), as the benchmark plays it there."""
    from graspgait_env.benchmark.policies import policy_env_kwargs
    from graspgait_env.benchmark.suite import get_task

    return policy_env_kwargs(get_task(task_id), card["env_kwargs"])


def assert_same_greedy_actions(model, loaded, env, steps: int = 20, seed: int = 3) -> None:
    """``model`` and ``loaded`` pick the same legal deterministic action at each of
    ``steps`` states of ``env``, visited by random legal moves."""
    import numpy as np

    obs, info = env.reset(seed=seed)
    rng = np.random.default_rng(0)
    for _ in range(steps):
        mask = info["action_mask"]
        a0, _ = model.predict(obs, deterministic=True, action_masks=mask)
        a1, _ = loaded.predict(obs, deterministic=True, action_masks=mask)
        assert int(a0) == int(a1) and mask[int(a1)]
        obs, _, term, trunc, info = env.step(np.int64(rng.choice(np.flatnonzero(mask))))
        if term or trunc:
            obs, info = env.reset()


def gait_extractor(env, turn_deg: float, **flags):
    """A 36-cell, convolution-free ``GraspMapExtractor`` for ``env`` with the gait inputs
    read from its ``GaitModel`` (``turn_steps``, ``rotations``, ``workspace_widths``) and
    ``flags`` on top. Returns ``(extractor, model, turn_steps, rotations, widths)``."""
    from graspgait_env.agents.policies import GraspMapExtractor

    m = env.unwrapped.model
    K, R = m.turn_steps(turn_deg), int(m.R)
    widths = [int(w) for w in m._widths]
    ext = GraspMapExtractor(env.observation_space, cells=36, conv=False, turn_steps=K,
                            rotations=R, workspace_widths=widths, **flags)
    return ext, m, K, R, widths
