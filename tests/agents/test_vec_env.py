"""The SB3 VecEnv over the batched GraspGait-v0: DummyVecEnv's transitions, MaskablePPO trains."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import graspgait_env  # noqa: F401  (registers the ids)
from graspgait_env.agents.vec_env import GraspGaitVecEnv, make_batched_vec_env
from graspgait_env.errors import GraspGaitInputError


def _legal(masks: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return np.array([rng.choice(np.flatnonzero(m)) for m in masks])


def _assert_equal(x, y) -> None:
    """Equal arrays, or equal dicts of arrays (observation_mode "dict")."""
    if isinstance(x, dict):
        assert isinstance(y, dict) and list(x) == list(y)
        for key in x:
            np.testing.assert_array_equal(x[key], y[key])
    else:
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize(("n_envs", "mode", "env_id"), [
    (1, "box", "GraspGait-v0"), (5, "box", "GraspGait-v0"), (5, "dict", "GraspGait-v0"),
    (3, "box", "GraspGaitRandom-v0")])
def test_same_transitions_as_dummy_vec_env(n_envs, mode, env_id):
    """SB3's autoreset, terminal observations, time-limit flags and float32 rewards, as
    DummyVecEnv over gymnasium.make gives them (short turns: many episode ends)."""
    from stable_baselines3.common.env_util import make_vec_env

    kw = {"turn_deg": 20.0, "max_backward_deg": 10.0, "observation_mode": mode}
    a = make_batched_vec_env(n_envs, seed=3, env_kwargs=kw, max_episode_steps=60,
                             env_id=env_id)
    b = make_vec_env(lambda: gym.make(env_id, max_episode_steps=60, **kw),
                     n_envs=n_envs, seed=3)
    _assert_equal(a.reset(), b.reset())
    rng = np.random.default_rng(0)
    ends = 0
    for _ in range(300):
        masks = np.stack(a.env_method("action_masks"))
        np.testing.assert_array_equal(masks, np.stack(b.env_method("action_masks")))
        act = _legal(masks, rng)
        (oa, ra, da, ia), (ob, rb, db, ib) = a.step(act), b.step(act)
        _assert_equal(oa, ob)
        assert ra.dtype == rb.dtype == np.float32
        np.testing.assert_array_equal(ra, rb)
        np.testing.assert_array_equal(da, db)
        for x, y, done in zip(ia, ib, da, strict=True):
            if not done:
                assert x == {}
                continue
            ends += 1
            _assert_equal(x["terminal_observation"], y["terminal_observation"])
            assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
            assert x["is_success"] == y["is_success"]
            assert x["episode"]["l"] == y["episode"]["l"]
            assert x["episode"]["r"] == pytest.approx(y["episode"]["r"], abs=1e-5)
    assert ends > 10


def test_maskable_ppo_trains_on_it():
    import torch
    from sb3_contrib import MaskablePPO
    from sb3_contrib.common.maskable.utils import get_action_masks, is_masking_supported

    torch.set_num_threads(1)
    env = make_batched_vec_env(4, seed=0)
    assert is_masking_supported(env)
    model = MaskablePPO("MlpPolicy", env, n_steps=16, batch_size=32, n_epochs=1,
                        policy_kwargs={"net_arch": [16]}, seed=0)
    model.learn(128)
    assert model.num_timesteps == 128
    obs = env.reset()
    masks = get_action_masks(env)
    actions, _ = model.predict(obs, action_masks=masks, deterministic=True)
    assert masks[np.arange(4), actions].all()


def test_maskable_ppo_trains_on_named_parts():
    """observation_mode="dict" with sb3-contrib's MultiInputPolicy."""
    import torch
    from sb3_contrib import MaskablePPO

    torch.set_num_threads(1)
    env = make_batched_vec_env(4, seed=0, env_kwargs={"observation_mode": "dict"})
    model = MaskablePPO("MultiInputPolicy", env, n_steps=16, batch_size=32, n_epochs=1,
                        policy_kwargs={"net_arch": [16]}, seed=0)
    model.learn(64)
    assert model.num_timesteps == 64
    obs = env.reset()
    assert set(obs) == {"grasp", "actions", "window"} and obs["actions"].shape[0] == 4


def test_attributes_and_refusals():
    venv = gym.make_vec("graspgait_env:GraspGait-v0", num_envs=2,
                        vectorization_mode="vector_entry_point", beta=0.05).unwrapped
    env = GraspGaitVecEnv(venv)
    env.seed(1)
    env.reset()
    assert env.get_attr("beta") == [0.05, 0.05]
    assert env.env_is_wrapped(gym.Wrapper) == [False, False]
    np.testing.assert_array_equal(env.get_attr("action_masks", [1])[0](),
                                  env.action_masks()[1])
    with pytest.raises(AttributeError):
        env.get_attr("no_such_thing")
    with pytest.raises(GraspGaitInputError, match="frozen"):
        env.set_attr("beta", 0.1)
    with pytest.raises(GraspGaitInputError, match="'render'"):
        env.env_method("render")
    with pytest.raises(GraspGaitInputError, match="GraspGaitVectorEnv"):
        GraspGaitVecEnv(gym.make("GraspGait-v0"))


def test_per_env_reset_options():
    """SB3's set_options with one dict per env: each sub-env resets with its own."""
    env = make_batched_vec_env(2, seed=4, monitor=False)
    env.set_options([{"start": {1: 50.0, 3: 270.0}}, {}])
    env.reset()
    first, second = env.venv.states()
    assert first.k == 0 and first.contacts == (25, -1, 135)  # 50 and 270 deg on the 2-deg grid
    single = gym.make("GraspGait-v0")
    single.reset(seed=5)  # sub-env 1 is seeded 4 + 1, without options
    assert second == single.unwrapped.state
