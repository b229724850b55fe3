"""GraspGaitMujoco-v1: API conformance, determinism, pickling, drops, warnings, a full gait."""

from __future__ import annotations

import copy
import math
import pickle
import time

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.envs.map_env import REWARD_TERMS, state_from_observation
from graspgait_env.envs.mujoco_env import MUJOCO_WARNINGS, GraspGaitMujocoEnv
from graspgait_env.envs.registration import ENV_IDS, MAX_EPISODE_STEPS

ENV_ID = "graspgait_env.envs:GraspGaitMujoco-v1"
WARNING_WHITELIST = ("cannot open a window (no display)",)
SIM_KEYS = ("dropped", "sim_status", "mujoco_warning", "pose_estimate", "estimated_turn_deg",
            "true_turn_deg", "mask_from_estimate", "sim_time_s")


def rollout(env: gym.Env, seed: int, steps: int, illegal_every: int = 0) -> list:
    """Masked random actions from a seeded generator; every transition, infos included."""
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    out = [("reset", obs.tobytes(), info["action_mask"].tobytes(),
            tuple(info[k] for k in SIM_KEYS))]
    mask = info["action_mask"]
    for t in range(steps):
        pool = (np.flatnonzero(~mask) if illegal_every and t % illegal_every == illegal_every - 1
                else np.flatnonzero(mask))
        a = int(pool[rng.integers(pool.size)])
        obs, r, term, trunc, info = env.step(a)
        out.append((a, obs.tobytes(), r, term, trunc, tuple(info["reward_terms"].items()),
                    info["action_mask"].tobytes(), info["is_success"],
                    tuple(info[k] for k in SIM_KEYS)))
        mask = info["action_mask"]
        if term or trunc:
            break
    return out


def test_registered():
    assert ENV_IDS["GraspGaitMujoco-v1"] == "graspgait_env.envs.mujoco_env:GraspGaitMujocoEnv"
    assert gym.spec("GraspGaitMujoco-v1").max_episode_steps == MAX_EPISODE_STEPS


def test_same_spaces_as_map_env():
    a = gym.make(ENV_ID)
    b = gym.make("graspgait_env.envs:GraspGait-v0")
    assert a.observation_space == b.observation_space
    assert a.action_space == b.action_space


# Gymnasium's and SB3's check_env run on this id (ellipse, pentagon) in
# tests/test_envs.py, parametrized over every registered id.


@pytest.mark.parametrize("pose_noise", [(0.0, 0.0), "thesis"])
def test_same_seed_rollouts_are_bit_identical(pose_noise):
    a = gym.make(ENV_ID, pose_noise=pose_noise)
    b = gym.make(ENV_ID, pose_noise=pose_noise)
    for seed in (0, 1):
        ra = rollout(a, seed, 5, illegal_every=3)
        assert ra == rollout(b, seed, 5, illegal_every=3)
        assert len(ra) == 6


def test_reward_is_sum_of_terms_and_mask_is_the_models():
    env = GraspGaitMujocoEnv("ellipse", 0.7)
    space = env.observation_space
    rng = np.random.default_rng(2)
    obs, info = env.reset(seed=2)
    assert space.contains(obs)
    for t in range(8):
        s = env.state
        assert state_from_observation(obs, env.model, env.turn_deg) == s
        if not info["mask_from_estimate"]:
            np.testing.assert_array_equal(info["action_mask"], env.model.action_mask(s))
        np.testing.assert_array_equal(env.action_masks(), info["action_mask"])
        mask = info["action_mask"]
        pool = np.flatnonzero(mask) if t % 4 else np.flatnonzero(~mask)
        a = int(pool[rng.integers(pool.size)])
        obs, r, term, trunc, info = env.step(a)
        terms = info["reward_terms"]
        assert tuple(terms) == REWARD_TERMS
        assert r == sum(terms.values()) and type(r) is float
        assert space.contains(obs)
        if t % 4:
            assert env.state == env.model.apply(s, a) and info["sim_status"] == "ok"
            assert abs(info["true_turn_deg"] - info["turn_deg"]) < 3.0
        else:
            assert env.state == s and info["sim_status"] == "skipped"
            assert terms["illegal"] == -env.illegal_penalty
        assert not term


@pytest.mark.parametrize("how", ["pickle", "deepcopy"])
def test_pickle_and_deepcopy_continue_identically(how):
    env = gym.make(ENV_ID, render_mode="rgb_array", pose_noise="thesis")
    rollout(env, 3, 2)  # an earlier episode: none of its physics may leak into the next
    rollout(env, 4, 4)
    twin = pickle.loads(pickle.dumps(env)) if how == "pickle" else copy.deepcopy(env)
    u, v = env.unwrapped, twin.unwrapped
    assert v.state == u.state
    np.testing.assert_array_equal(v.physics.data.qpos, u.physics.data.qpos)
    rng1, rng2 = np.random.default_rng(9), np.random.default_rng(9)
    m1, m2 = u.action_masks(), v.action_masks()
    np.testing.assert_array_equal(m1, m2)
    for _ in range(5):
        l1, l2 = np.flatnonzero(m1), np.flatnonzero(m2)
        r1 = env.step(int(l1[rng1.integers(l1.size)]))
        r2 = twin.step(int(l2[rng2.integers(l2.size)]))
        np.testing.assert_array_equal(r1[0], r2[0])
        assert r1[1:4] == r2[1:4]
        assert [r1[4][k] for k in SIM_KEYS] == [r2[4][k] for k in SIM_KEYS]
        m1, m2 = r1[4]["action_mask"], r2[4]["action_mask"]
        if r1[2] or r1[3]:
            break
    np.testing.assert_array_equal(env.render(), twin.render())


def test_pickle_before_reset():
    env = GraspGaitMujocoEnv("circle")
    twin = pickle.loads(pickle.dumps(env))
    assert twin.executor is None
    obs, _ = twin.reset(seed=0)
    np.testing.assert_array_equal(obs, env.reset(seed=0)[0])


def test_forced_drop_terminates():
    env = GraspGaitMujocoEnv("ellipse", 0.7)
    obs, info = env.reset(seed=0)
    s = env.state
    env.executor.set_disturbance(lambda t: (40.0, 0.0))  # a hard tug (N): no grip holds it
    a = int(np.flatnonzero(info["action_mask"][: env.model.R])[-1])  # the longest CCW turn
    obs, r, term, trunc, info = env.step(a)
    assert term and not trunc
    assert info["dropped"] and info["sim_status"] == "dropped"
    assert not info["is_success"] and info["mujoco_warning"] is None
    assert info["reward_terms"]["dead_end"] == -env.dead_end_penalty
    assert info["reward_terms"]["turn"] == 0.0
    assert r == sum(info["reward_terms"].values())
    assert not info["action_mask"].any() and not env.action_masks().any()
    assert env.state == s  # the move did not complete
    assert env.observation_space.contains(obs)


def test_mujoco_warning_terminates_and_is_reported(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo appends its warnings to ./MUJOCO_LOG.TXT
    env = GraspGaitMujocoEnv("ellipse", 0.7)
    obs, info = env.reset(seed=0)
    phys = env.physics

    def blow_up(t: float) -> tuple[float, float]:
        phys.data.qvel[:] = math.nan  # MuJoCo flags it (mjWARN_BADQVEL) and resets its data
        return (0.0, 0.0)

    env.executor.set_disturbance(blow_up)
    a = int(np.flatnonzero(info["action_mask"])[0])
    obs, r, term, trunc, info = env.step(a)
    assert term and not info["is_success"]
    assert info["mujoco_warning"] in MUJOCO_WARNINGS
    assert info["mujoco_warning"].startswith("mjWARN_BADQ")
    assert info["sim_status"] == "warning"
    assert info["reward_terms"]["dead_end"] == -env.dead_end_penalty
    assert r == sum(info["reward_terms"].values())
    assert env.observation_space.contains(obs)


def test_illegal_action_runs_no_physics():
    env = GraspGaitMujocoEnv("pentagon", 0.7)
    obs, info = env.reset(seed=1)
    t0 = env.physics.time
    a = int(np.flatnonzero(~info["action_mask"])[0])
    obs2, r, term, trunc, info2 = env.step(a)
    np.testing.assert_array_equal(obs2, obs)
    assert env.physics.time == t0 and r == -env.illegal_penalty and not term
    for bad in (-1, env.action_space.n):
        with pytest.raises(ValueError, match="outside the action space"):
            env.step(bad)


def test_arguments_are_validated():
    for bad in ({"pose_noise": "big"}, {"pose_noise": (0.1,)}, {"pose_noise": (-1.0, 0.0)},
                {"turn_deg": 0.0}):
        with pytest.raises(ValueError):
            GraspGaitMujocoEnv(**bad)
    with pytest.raises(RuntimeError, match="reset"):
        GraspGaitMujocoEnv().step(0)


def test_estimate_off_the_grid_angle_removes_regrasps_outside_the_workspace():
    env = GraspGaitMujocoEnv("ellipse", 0.7)
    env.reset(seed=0)
    commanded = env.model.action_mask(env.state)
    R, b, h = env.model.R, 2 * env.model.R, env._h
    W = int(env.model.ws_width[h])
    for dk in (2, -2):
        env._est_k = env._k + dk  # the localizer sees the object 4 degrees off
        mask = env._compute_mask()
        np.testing.assert_array_equal(mask[:b], commanded[:b])  # rotations: commanded
        p = np.arange((mask.size - b) // 2)
        inside = (p + dk >= 0) & (p + dk < W)
        for lift in (0, 1):
            np.testing.assert_array_equal(mask[b + lift::2], commanded[b + lift::2] & inside)
        assert env._restricted == bool((mask != commanded).any())
    assert R > 0


@pytest.mark.parametrize("pose_noise", [(0.0, 0.0), "thesis"])
def test_optimal_planner_policy_completes_a_full_turn(pose_noise):
    from graspgait_env.baselines.policies import PlannerPolicy
    from graspgait_env.planners.exact import optimal_gait

    env = gym.make(ENV_ID, object="ellipse", mu=0.7, pose_noise=pose_noise)
    policy = PlannerPolicy(env, optimal_gait)
    obs, info = env.reset(seed=1)
    t0 = time.perf_counter()
    for _ in range(MAX_EPISODE_STEPS):
        a, _ = policy.predict(obs)
        assert info["action_mask"][int(a)]
        obs, r, term, trunc, info = env.step(a)
        if term or trunc:
            break
    assert info["is_success"] and not info["dropped"], info
    assert info["turn_deg"] >= 360.0
    assert abs(info["true_turn_deg"] - info["turn_deg"]) < 3.0
    assert time.perf_counter() - t0 < 20.0
