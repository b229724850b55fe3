"""``rotation_lookahead``: per rotation action, whether a regrasp is legal after it
(one step of the legal-move function looked ahead, thesis 4.2 and 5.2)."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.envs.map_env import regrasp_openings
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel


def brute_force_lookahead(model: GaitModel, state, mask: np.ndarray) -> np.ndarray:
    """Entry ``a < 2R``: rotation ``a`` is legal and the state after it has a legal regrasp,
    from ``GaitModel.apply`` and ``GaitModel.action_mask`` alone."""
    R = model.R
    return np.array([bool(mask[a]) and bool(model.action_mask(model.apply(state, a))[2 * R:].any())
                     for a in range(2 * R)])


def check_rollout(env: gym.Env, plain: gym.Env | None, seed: int, steps: int) -> int:
    """Masked random play; at every step the look-ahead equals the brute force and the
    rest of the observation equals ``plain``'s (same config without the look-ahead).
    Returns how many look-ahead entries were 1."""
    u = env.unwrapped
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    if plain is not None:
        obs_p, _ = plain.reset(seed=seed)
    ones = 0
    for _ in range(steps):
        assert env.observation_space.contains(obs)
        look = obs[u.layout.lookahead]
        assert look.size == 2 * u.model.R
        want = brute_force_lookahead(u.model, u.state, info["action_mask"])
        np.testing.assert_array_equal(look, want.astype(np.float32))
        ones += int(want.sum())
        if plain is not None:
            np.testing.assert_array_equal(obs[:obs_p.size], obs_p)
        a = int(rng.choice(np.flatnonzero(info["action_mask"])))
        obs, _, term, trunc, info = env.step(a)
        if plain is not None:
            obs_p, *_ = plain.step(a)
        if term or trunc:
            obs, info = env.reset()
            if plain is not None:
                obs_p, _ = plain.reset()
    return ones


@pytest.mark.parametrize("kw", [
    {"object": "hexagon", "contact_model": "hand"},  # regrasps open at few angles
    {"object": "ellipse", "map_lines": True},
    {"object": "pentagon", "n": 90, "turn_deg": -360.0},
])
def test_lookahead_is_the_legal_move_function_one_step_ahead(kw):
    env = gym.make("graspgait_env:GraspGait-v0", mu=0.7, rotation_lookahead=True, **kw)
    plain = gym.make("graspgait_env:GraspGait-v0", mu=0.7, **kw)
    u = env.unwrapped
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 2 * u.model.R
    assert u.layout.lookahead.stop == u.layout.size
    ones = check_rollout(env, plain, 3, 150)
    assert 0 < ones < 150 * 2 * u.model.R  # both values occur


def test_some_legal_rotations_open_no_regrasp_on_the_hexagon_with_ball_tips():
    """The case the feature is for: at the start most legal rotations open no regrasp."""
    env = gym.make("graspgait_env:GraspGait-v0", object="hexagon", mu=0.7,
                   contact_model="hand", rotation_lookahead=True)
    u = env.unwrapped
    legal = opening = 0
    for seed in range(20):
        obs, info = env.reset(seed=seed)
        legal += int(info["action_mask"][:2 * u.model.R].sum())
        opening += int(obs[u.layout.lookahead].sum())
    assert 0 < opening < legal / 2


def test_regrasp_openings_table_is_any_of_the_regrasp_rule():
    model = GaitModel("pentagon", 0.7, n=90)
    table = regrasp_openings(model)
    n = model.n
    ext = model.grasp_map.extended()  # ext[j, c]: contact j against contact c, j < 2n
    assert table.shape == (3, n, n) and not table.flags.writeable
    for h in range(3):
        w = int(model.ws_width[h])
        for c in range(0, n, 7):
            for i in range(n):
                assert table[h, c, i] == bool(ext[i:i + w, c].any()), (h, c, i)


def test_random_objects_rebuild_the_lookahead_per_episode():
    env = gym.make("graspgait_env:GraspGaitRandom-v0", rotation_lookahead=True)
    plain = gym.make("graspgait_env:GraspGaitRandom-v0")
    assert check_rollout(env, plain, 5, 80) > 0


def test_pickled_env_continues_with_its_lookahead():
    env = gym.make("graspgait_env:GraspGait-v0", object="hexagon", contact_model="hand",
                   rotation_lookahead=True).unwrapped
    obs, info = env.reset(seed=2)
    twin = pickle.loads(pickle.dumps(env))
    rng = np.random.default_rng(2)
    for _ in range(30):
        a = int(rng.choice(np.flatnonzero(info["action_mask"])))
        obs, *_, info = env.step(a)
        obs_t, *_ = twin.step(a)
        np.testing.assert_array_equal(obs, obs_t)
        np.testing.assert_array_equal(obs[env.layout.lookahead],
                                      brute_force_lookahead(env.model, env.state,
                                                            info["action_mask"]))


def test_off_by_default_and_checked():
    env = gym.make("graspgait_env:GraspGait-v0")
    layout = env.unwrapped.layout
    assert layout.lookahead.stop - layout.lookahead.start == 0
    assert layout.size == env.observation_space.shape[0] == 1494
    assert env.unwrapped.config.rotation_lookahead is False
    with pytest.raises(GraspGaitInputError,
                       match="rotation_lookahead='yes': must be True or False"):
        gym.make("graspgait_env:GraspGait-v0", rotation_lookahead="yes")


def test_mujoco_env_looks_ahead_from_the_commanded_state():
    env = gym.make("graspgait_env.envs:GraspGaitMujoco-v1", object="ellipse",
                   rotation_lookahead=True)
    u = env.unwrapped
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(3):
        mask = u.model.action_mask(u.state)  # the commanded state's (rotations as in info)
        np.testing.assert_array_equal(info["action_mask"][:2 * u.model.R], mask[:2 * u.model.R])
        np.testing.assert_array_equal(obs[u.layout.lookahead],
                                      brute_force_lookahead(u.model, u.state, mask))
        obs, _, term, _, info = env.step(int(rng.choice(np.flatnonzero(info["action_mask"]))))
        if term:
            break
    env.close()
