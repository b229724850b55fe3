"""``env.optimal_moves()``: the exact optimum's moves of the present state, for imitation."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.planners.exact import optimal_gait


def test_following_the_teacher_spends_the_optimum_and_succeeds() -> None:
    env = gym.make("graspgait_env:GraspGait-v0", object="pentagon", mu=0.7, n=90)
    u = env.unwrapped
    rng = np.random.default_rng(1)
    played = 0
    for seed in range(12):
        env.reset(seed=seed)
        start = u.state
        best = optimal_gait(u.model, start, 360.0)
        teacher = u.optimal_moves()
        if not best.success:
            assert not teacher.any()
            continue
        done = False
        while not done:
            teacher = u.optimal_moves()
            assert teacher.any() and not (teacher & ~u.action_masks()).any()
            _, _, term, trunc, info = env.step(int(rng.choice(np.flatnonzero(teacher))))
            done = term or trunc
        assert info["is_success"] and info["regrasps"] == best.regrasps
        played += 1
    assert played >= 6


def test_the_random_env_rebuilds_the_teacher_for_each_object() -> None:
    env = gym.make("graspgait_env:GraspGaitRandom-v0", level=1)
    u = env.unwrapped
    models = set()
    for seed in range(3):
        env.reset(seed=seed)
        u.optimal_moves()
        assert u._optimal.model is u.model
        models.add(id(u.model))
    assert len(models) == 3


def test_before_reset_it_asks_for_one() -> None:
    env = gym.make("graspgait_env:GraspGait-v0", object="ellipse", n=90)
    with pytest.raises(gym.error.ResetNeeded):
        env.unwrapped.optimal_moves()
