"""``map_lines``: the grasp map's two lines through the grasp, in the hand frame (thesis 4.3)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.envs.map_env import state_from_observation
from graspgait_env.errors import GraspGaitInputError


def test_lines_are_the_regrasps_of_the_mask_and_more():
    """A regrasp keeping finger f and placing the free finger h at workspace position p
    is legal exactly when f's line is 1 at h's hand-frame angle ``s_h + p``; the lines
    cover the whole circle (also where no finger reaches now)."""
    env = gym.make("graspgait_env:GraspGait-v0", object="pentagon", mu=0.7, map_lines=True)
    plain = gym.make("graspgait_env:GraspGait-v0", object="pentagon", mu=0.7)
    u = env.unwrapped
    n, R = u.model.n, u.model.R
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 2 * n
    rng = np.random.default_rng(0)
    obs, info = env.reset(seed=1)
    obs_p, _ = plain.reset(seed=1)
    regrasps_checked = 0
    for _ in range(60):
        assert env.observation_space.contains(obs)
        np.testing.assert_array_equal(obs[:obs_p.size], obs_p)  # the rest is unchanged
        s = state_from_observation(obs, u.model, 360.0)
        assert s == u.state
        lines = obs[u.layout.lines].reshape(2, n)
        f, g = s.held()
        h = 3 - f - g
        for row, c in zip(lines, (s.contacts[f], s.contacts[g]), strict=True):
            np.testing.assert_array_equal(row, u.model.stable[c, (np.arange(n) - s.k) % n])
        mask = info["action_mask"]
        for p in range(int(u.model.ws_width[h])):
            j = (int(u.model.ws_start[h]) + p) % n
            for lift, kept_row in ((0, 1), (1, 0)):  # l = 0 lifts f (keeps g)
                a = 2 * R + 2 * p + lift
                assert mask[a] == bool(lines[kept_row, j]), (s, p, lift)
                regrasps_checked += 1
        a = int(rng.choice(np.flatnonzero(mask)))
        obs, _, term, trunc, info = env.step(a)
        obs_p, *_ = plain.step(a)
        if term or trunc:
            obs, info = env.reset()
            obs_p, _ = plain.reset()
    assert regrasps_checked > 1000


def test_off_by_default_and_checked():
    env = gym.make("graspgait_env:GraspGait-v0")
    assert env.unwrapped.layout.lines.stop - env.unwrapped.layout.lines.start == 0
    with pytest.raises(GraspGaitInputError, match="map_lines='yes': must be True or False"):
        gym.make("graspgait_env:GraspGait-v0", map_lines="yes")
