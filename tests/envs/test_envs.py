"""GraspGait Gymnasium environments: API conformance, determinism, vector envs, speed."""

from __future__ import annotations

import copy
import pickle
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

from graspgait_env.envs import register_envs
from graspgait_env.envs.map_env import REWARD_TERMS, GraspGaitEnv, state_from_observation
from graspgait_env.envs.procedural import (
    EVAL_SEEDS,
    LEVELS,
    ObjectSampler,
    bundled_for_level,
    procedural_object,
)
from graspgait_env.envs.random_env import GraspGaitRandomEnv
from graspgait_env.envs.registration import ENV_IDS, MAX_EPISODE_STEPS
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.objects import bundled_objects

ENV_PREFIX = "graspgait_env.envs:"  # importable module: works in fresh (sub)processes too
CHECK_OBJECTS = ["circle", "pentagon", "ellipse", "square"]
# warnings check_env may emit that are expected here
WARNING_WHITELIST = ("cannot open a window (no display)",)

# (id, kwargs) cases: every registered id, several objects for the fixed-object id
CASES = [("GraspGait-v0", {"object": o}) for o in CHECK_OBJECTS] + [
    ("GraspGaitRandom-v0", {"level": lv}) for lv in (0, len(LEVELS) - 1)] + [
    ("GraspGaitMujoco-v1", {"object": o}) for o in ("ellipse", "pentagon")]
assert {c[0] for c in CASES} == set(ENV_IDS)
# the physics-level id costs ~30 ms a move: its full 20 x 200 rollout check is slow
SLOW_IDS = {"GraspGaitMujoco-v1"}
DETERMINISM_IDS = [pytest.param(i, marks=pytest.mark.slow) if i in SLOW_IDS else i
                   for i in sorted(ENV_IDS)]


def make(env_id: str, **kw) -> gym.Env:
    return gym.make(ENV_PREFIX + env_id, **kw)


def masked_rollout(env: gym.Env, seed: int, steps: int, illegal_every: int = 0):
    """Masked random actions from a seeded generator; returns every transition."""
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    out = [("reset", obs.tobytes(), info["action_mask"].tobytes())]
    mask = info["action_mask"]
    for t in range(steps):
        if illegal_every and t % illegal_every == illegal_every - 1 and (~mask).any():
            illegal = np.flatnonzero(~mask)
            a = int(illegal[rng.integers(illegal.size)])
        else:
            legal = np.flatnonzero(mask)
            a = int(legal[rng.integers(legal.size)])
        obs, r, term, trunc, info = env.step(a)
        out.append((a, obs.tobytes(), r, term, trunc, tuple(info["reward_terms"].items()),
                    info["action_mask"].tobytes(), info["is_success"]))
        mask = info["action_mask"]
        if term or trunc:
            obs, info = env.reset()
            mask = info["action_mask"]
            out.append(("reset", obs.tobytes(), mask.tobytes()))
    return out


# ---------------------------------------------------------------------------- registration
def test_register_envs_is_idempotent():
    assert register_envs() == []
    for env_id, entry in ENV_IDS.items():
        spec = gym.spec(env_id)
        assert spec.entry_point == entry
        assert spec.max_episode_steps == MAX_EPISODE_STEPS


def _fresh(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)


def test_make_in_fresh_interpreter_with_envs_prefix():
    r = _fresh("import gymnasium as gym\n"
               "env = gym.make('graspgait_env.envs:GraspGait-v0')\n"
               "obs, info = env.reset(seed=0)\n"
               "env2 = gym.make('graspgait_env.envs:GraspGaitRandom-v0')\n"
               "print(obs.shape, env2.reset(seed=0)[0].shape)")
    assert r.returncode == 0, r.stderr


def test_make_in_fresh_interpreter_with_package_prefix():
    """``gym.make("graspgait_env:GraspGait-v0")`` once graspgait_env/__init__ registers."""
    r = _fresh("import gymnasium as gym, graspgait_env\n"
               "print('GraspGait-v0' in gym.registry)")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "True", ("`import graspgait_env` must register the ids "
                                        "(graspgait_env.envs.registration.register_envs())")
    r = _fresh("import gymnasium as gym\n"
               "env = gym.make('graspgait_env:GraspGait-v0')\n"
               "env.reset(seed=0)\n"
               "gym.make('graspgait_env:GraspGaitRandom-v0').reset(seed=0)")
    assert r.returncode == 0, r.stderr


# ---------------------------------------------------------------------------- checkers
@pytest.mark.parametrize(("env_id", "kw"), CASES, ids=lambda x: str(x))
def test_gymnasium_check_env(env_id, kw):
    env = make(env_id, **kw)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gym_check_env(env.unwrapped)
    bad = [str(w.message) for w in caught
           if not any(s in str(w.message) for s in WARNING_WHITELIST)]
    assert not bad, bad


@pytest.mark.parametrize(("env_id", "kw"), CASES, ids=lambda x: str(x))
def test_sb3_check_env(env_id, kw):
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = make(env_id, **kw)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sb3_check_env(env.unwrapped, warn=True)
    assert not [str(w.message) for w in caught]


# ---------------------------------------------------------------------------- semantics
@pytest.fixture(scope="module")
def ellipse_env() -> GraspGaitEnv:
    return GraspGaitEnv()


def test_spaces_and_layout(ellipse_env):
    env = ellipse_env
    m = env.model
    assert env.action_space.n == m.n_actions == 182
    assert env.observation_space.shape == (16 + 182 + 36 * 36,)
    assert env.observation_space.dtype == np.float32
    lay = env.layout
    assert lay.window.stop == lay.size == env.observation_space.shape[0]
    assert m.shape.name == "ellipse" and m.mu == 0.7


def test_reward_is_sum_of_terms_and_obs_in_space():
    env = make("GraspGait-v0", object="square")
    space = env.observation_space
    rng = np.random.default_rng(1)
    obs, info = env.reset(seed=1)
    assert space.contains(obs)
    for t in range(1500):
        mask = info["action_mask"]
        pool = np.flatnonzero(mask) if t % 7 else np.flatnonzero(~mask)
        obs, r, term, trunc, info = env.step(int(pool[rng.integers(pool.size)]))
        terms = info["reward_terms"]
        assert tuple(terms) == REWARD_TERMS
        assert r == sum(terms.values())
        assert type(r) is float
        assert space.contains(obs)
        if term or trunc:
            obs, info = env.reset()


@pytest.mark.parametrize("name", ["ellipse", "pentagon", "star"])
@pytest.mark.parametrize(("hand", "n"), [(None, 180), ("wide", 180), (None, 90), (None, 72)])
def test_mask_and_moves_match_gait_model(name, hand, n):
    """The env's mask is GaitModel.action_mask; its move arithmetic is GaitModel.apply."""
    env = GraspGaitEnv(name, 0.6, hand=hand, n=n, map_window_cells=min(36, n // 2))
    m = env.model
    rng = np.random.default_rng(0)
    obs, info = env.reset(seed=0)
    for _ in range(400):
        s = env.state
        np.testing.assert_array_equal(info["action_mask"], m.action_mask(s))
        np.testing.assert_array_equal(env.action_masks(), m.action_mask(s))
        assert state_from_observation(obs, m, env.turn_deg) == s
        legal = np.flatnonzero(info["action_mask"])
        a = int(legal[rng.integers(legal.size)])
        obs, r, term, trunc, info = env.step(a)
        assert env.state == m.apply(s, a)
        if term:
            obs, info = env.reset()
    for s in m.start_states()[::7]:  # every starting grasp with a move
        if m.action_mask(s).any():
            env.reset(options={"start": s})
            np.testing.assert_array_equal(env.action_masks(), m.action_mask(s))


def test_illegal_action_is_a_penalized_no_op(ellipse_env):
    env = ellipse_env
    obs, info = env.reset(seed=3)
    s = env.state
    a = int(np.flatnonzero(~info["action_mask"])[0])
    obs2, r, term, trunc, info2 = env.step(a)
    assert env.state == s
    np.testing.assert_array_equal(obs2, obs)
    assert r == -env.illegal_penalty
    assert info2["reward_terms"]["illegal"] == -env.illegal_penalty
    assert not term and not trunc
    assert info2["action_mask"] is not info["action_mask"]
    for bad in (-1, env.action_space.n):
        with pytest.raises(ValueError, match="outside the action space"):
            env.step(bad)


def test_rotation_and_regrasp_terms(ellipse_env):
    env = ellipse_env
    env.reset(seed=0, options={"start": {1: 50.0, 3: 270.0}})
    m = env.model
    assert env.state == m.start_state({1: 50.0, 3: 270.0})
    _, r, _, _, info = env.step(0)  # rotate CCW one grid step (2 deg)
    t = info["reward_terms"]
    assert t["turn"] == pytest.approx(env.alpha * 2.0 / 360.0)
    assert t["rotation"] == -env.gamma and t["regrasp"] == 0.0
    assert info["turn_deg"] == 2.0
    regrasp = int(np.flatnonzero(info["action_mask"][2 * m.R:])[0]) + 2 * m.R
    _, r, _, _, info = env.step(regrasp)
    t = info["reward_terms"]
    assert t["regrasp"] == -env.beta and t["turn"] == 0.0 and t["rotation"] == 0.0
    assert info["regrasps"] == 1


def test_start_option_errors(ellipse_env):
    with pytest.raises(ValueError):
        ellipse_env.reset(options={"start": {1: 50.0}})
    with pytest.raises(ValueError):
        ellipse_env.reset(options={"start": GaitState(3, (-1, 67, 148))})
    with pytest.raises(ValueError):
        ellipse_env.reset(options={"start": "50, 270"})


def test_success_ends_the_episode_with_the_bonus():
    from graspgait_env.baselines.policies import plan_actions, plan_states
    from graspgait_env.planners.exact import optimal_gait

    env = make("GraspGait-v0", object="pentagon")
    env.reset(seed=2)
    u = env.unwrapped
    res = optimal_gait(u.model, u.state, 360.0)
    pairs = plan_actions(u.model, plan_states(u.model, res.plan))
    total = 0.0
    for i, (s, a) in enumerate(pairs):
        assert u.state == s
        _, r, term, trunc, info = env.step(a)
        total += r
        assert term == (i == len(pairs) - 1)
        assert not trunc
    assert info["is_success"] and info["reward_terms"]["success"] == u.success_bonus
    assert info["regrasps"] == res.regrasps
    # the turn terms sum to alpha (the whole turn), less the move penalties
    want = u.alpha + u.success_bonus - u.beta * res.regrasps - u.gamma * (len(pairs) -
                                                                          res.regrasps)
    assert total == pytest.approx(want)


def test_wrong_way_limit_terminates():
    env = GraspGaitEnv("circle", 0.7, max_backward_deg=10.0)
    obs, info = env.reset(seed=0, options={"start": {1: 80.0, 2: 200.0}})
    R = env.model.R
    term = False
    for _ in range(10):
        cw = np.flatnonzero(info["action_mask"][R:2 * R])
        assert cw.size
        obs, r, term, trunc, info = env.step(R + int(cw[0]))
        assert env.observation_space.contains(obs)
        if term:
            break
    assert term and not info["is_success"]
    assert info["reward_terms"]["dead_end"] == -env.dead_end_penalty
    assert info["turn_deg"] < -10.0


def test_dead_end_terminates(monkeypatch):
    """Every move can be undone, so dead ends need an unusual model: force one."""
    env = GraspGaitEnv("ellipse", 0.7)
    obs, info = env.reset(seed=0)
    a = int(np.flatnonzero(info["action_mask"])[0])
    monkeypatch.setattr(env, "_compute_mask", lambda: np.zeros(env._A, dtype=bool))
    obs, r, term, trunc, info = env.step(a)
    assert term and not info["is_success"] and not info["action_mask"].any()
    assert info["reward_terms"]["dead_end"] == -env.dead_end_penalty
    assert env.observation_space.contains(obs)


def test_turn_and_window_options():
    env = GraspGaitEnv("ellipse", 0.7, turn_deg=-90.0, map_window_deg=120.0,
                       map_window_cells=20)
    obs, info = env.reset(seed=0)
    assert env.observation_space.shape == (16 + 182 + 400,)
    assert env.observation_space.contains(obs)
    assert state_from_observation(obs, env.model, -90.0) == env.state
    for bad in ({"turn_deg": 0.0}, {"beta": -1.0}, {"map_window_cells": 0},
                {"map_window_deg": 400.0}, {"render_mode": "ansi"}, {"mu": -1.0},
                {"map_window_cells": 200}):
        with pytest.raises(ValueError):
            GraspGaitEnv(**bad)


def test_window_is_the_map_around_the_grasp():
    env = GraspGaitEnv("circle", 0.7, map_window_deg=360.0, map_window_cells=180)
    obs, _ = env.reset(seed=0)
    s = env.state
    f, g = s.held()
    win = obs[env.layout.window].reshape(180, 180)
    stable = env.model.stable
    i = (np.arange(180) + s.contacts[f] - 90) % 180
    j = (np.arange(180) + s.contacts[g] - 90) % 180
    np.testing.assert_array_equal(win, stable[np.ix_(i, j)].astype(np.float32))
    assert win[90, 90] == 1.0  # the present grasp is stable, in the centre cell


# ---------------------------------------------------------------------------- determinism
@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_same_seed_rollouts_are_bit_identical_short(env_id):
    a, b = make(env_id), make(env_id)
    for seed in range(3):
        assert masked_rollout(a, seed, 12, illegal_every=5) == masked_rollout(
            b, seed, 12, illegal_every=5)


@pytest.mark.parametrize("env_id", DETERMINISM_IDS)
def test_same_seed_rollouts_are_bit_identical(env_id):
    a, b = make(env_id), make(env_id)
    for seed in range(20):
        assert masked_rollout(a, seed, 200, illegal_every=17) == masked_rollout(
            b, seed, 200, illegal_every=17)


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
@pytest.mark.parametrize("how", ["pickle", "deepcopy"])
def test_pickle_and_deepcopy_round_trip(env_id, how):
    env = make(env_id, render_mode="rgb_array")
    masked_rollout(env, 4, 30)
    twin = pickle.loads(pickle.dumps(env)) if how == "pickle" else copy.deepcopy(env)
    assert twin.unwrapped.state == env.unwrapped.state
    rng1, rng2 = np.random.default_rng(9), np.random.default_rng(9)
    m1 = env.unwrapped.action_masks()
    m2 = twin.unwrapped.action_masks()
    for _ in range(100):
        l1, l2 = np.flatnonzero(m1), np.flatnonzero(m2)
        r1 = env.step(int(l1[rng1.integers(l1.size)]))
        r2 = twin.step(int(l2[rng2.integers(l2.size)]))
        np.testing.assert_array_equal(r1[0], r2[0])
        assert r1[1:4] == r2[1:4]
        m1, m2 = r1[4]["action_mask"], r2[4]["action_mask"]
        if r1[2] or r1[3]:
            o1, i1 = env.reset()
            o2, i2 = twin.reset()
            np.testing.assert_array_equal(o1, o2)
            m1, m2 = i1["action_mask"], i2["action_mask"]
    np.testing.assert_array_equal(env.render(), twin.render())


# ---------------------------------------------------------------------------- vector envs
def _vec_masked_actions(masks: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return np.array([int(np.flatnonzero(m)[rng.integers(m.sum())]) for m in masks])


@pytest.mark.parametrize("kind", ["sync", "async"])
def test_gymnasium_vector_envs(kind):
    fns = [lambda: make("GraspGait-v0", object="pentagon") for _ in range(2)]
    cls = gym.vector.SyncVectorEnv if kind == "sync" else gym.vector.AsyncVectorEnv
    venv = cls(fns)
    try:
        obs, info = venv.reset(seed=[0, 1])
        assert obs.shape == (2, *venv.single_observation_space.shape)
        rng = np.random.default_rng(0)
        for _ in range(30):
            obs, r, term, trunc, info = venv.step(_vec_masked_actions(info["action_mask"], rng))
            assert venv.observation_space.contains(obs)
            np.testing.assert_array_equal(
                r, sum(info["reward_terms"][k] for k in REWARD_TERMS))
    finally:
        venv.close()


def _sb3_rollout(venv, steps: int = 60):
    venv.seed(5)
    obs = venv.reset()
    rng = np.random.default_rng(5)
    out = [obs.copy()]
    for _ in range(steps):
        masks = np.stack(venv.env_method("action_masks"))
        obs, r, done, infos = venv.step(_vec_masked_actions(masks, rng))
        out.append((obs.copy(), r.copy(), done.copy(),
                    [i["reward_terms"] for i in infos]))
    venv.close()
    return out


def test_sb3_dummy_and_subproc_vec_envs_agree():
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    fns = [lambda: make("GraspGait-v0", object="ellipse"),
           lambda: make("GraspGaitRandom-v0", level=1)]
    a = _sb3_rollout(DummyVecEnv(fns))
    b = _sb3_rollout(SubprocVecEnv(fns))
    assert len(a) == len(b)
    np.testing.assert_array_equal(a[0], b[0])
    for x, y in zip(a[1:], b[1:], strict=True):
        np.testing.assert_array_equal(x[0], y[0])
        # DummyVecEnv buffers rewards as float32, SubprocVecEnv stacks the floats sent
        np.testing.assert_array_equal(x[1].astype(np.float32), y[1].astype(np.float32))
        np.testing.assert_array_equal(x[2], y[2])
        assert x[3] == y[3]


# ---------------------------------------------------------------------------- rendering
def test_render_rgb_array():
    env = make("GraspGait-v0", object="pentagon", render_mode="rgb_array")
    masked_rollout(env, 0, 5)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert frame.shape[0] > 100 and frame.std() > 0


def test_render_human_headless_warns_once_and_returns_none():
    env = GraspGaitEnv("circle", render_mode="human")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env.reset(seed=0)
        assert env.render() is None
        env.step(int(np.flatnonzero(env.action_masks())[0]))
    msgs = [str(w.message) for w in caught]
    assert len(msgs) == 1 and "no display" in msgs[0]
    env.close()
    env.close()


def test_render_without_mode_warns(ellipse_env):
    with pytest.warns(UserWarning, match="render_mode"):
        assert ellipse_env.render() is None


# ---------------------------------------------------------------------------- random env
def test_random_env_draws_objects_with_fixed_spaces():
    env = make("GraspGaitRandom-v0", level=2)
    names, mus = set(), set()
    obs, info = env.reset(seed=0)
    for _ in range(12):
        assert env.observation_space.contains(obs)
        assert info["action_mask"].shape == (env.action_space.n,)
        lo, hi = LEVELS[2].mu
        assert lo <= info["mu"] <= hi
        names.add(info["object"])
        mus.add(info["mu"])
        if info["object_seed"] >= 0:
            assert not EVAL_SEEDS[0] <= info["object_seed"] < EVAL_SEEDS[1]
        obs, info = env.reset()
    assert len(names) >= 8 and len(mus) == 12


def test_random_env_options_and_eval_split():
    env = GraspGaitRandomEnv(level=1, object_seeds=EVAL_SEEDS, exclude_seeds=None,
                             bundled_fraction=0.0)
    _, info = env.reset(seed=0)
    assert EVAL_SEEDS[0] <= info["object_seed"] < EVAL_SEEDS[1]
    _, info = env.reset(options={"object": "square", "mu": 0.5})
    assert info["object"] == "square" and info["mu"] == 0.5 and info["object_seed"] == -1
    _, info = env.reset(options={"object_seed": 42, "mu": 0.8})
    assert info["object"] == "proc-L1-42" and env.model.mu == 0.8
    with pytest.raises(ValueError, match="reach"):
        GraspGaitRandomEnv(hand="circular_reach")
    with pytest.raises(ValueError):
        GraspGaitRandomEnv(level=len(LEVELS))
    with pytest.raises(ValueError):
        GraspGaitRandomEnv(mu_range=(0.5, 0.2))


def test_sampler_never_draws_excluded_seeds():
    s = ObjectSampler(0, object_seeds=(0, 100), exclude_seeds=(20, 90), bundled_fraction=0.0)
    assert s.n_seeds == 30
    assert [s.seed_at(i) for i in (0, 19, 20, 29)] == [0, 19, 90, 99]
    rng = np.random.default_rng(0)
    seeds = {s.sample(rng)[1] for _ in range(300)}
    assert seeds <= set(range(20)) | set(range(90, 100)) and len(seeds) == 30
    with pytest.raises(ValueError, match="leaves no seed"):
        ObjectSampler(0, object_seeds=(0, 10), exclude_seeds=(0, 10), bundled_fraction=0.0)


@pytest.mark.parametrize("level", range(len(LEVELS)))
def test_procedural_objects_are_deterministic_and_within_level(level):
    for seed in range(25):
        a, b = procedural_object(seed, level), procedural_object(seed, level)
        assert repr(a) == repr(b)
        assert a.eccentricity <= LEVELS[level].ecc_max + 1e-9
    assert set(bundled_for_level(level)) <= set(bundled_objects())
    assert "circle" in bundled_for_level(level)


def test_levels_get_harder():
    ecc = [lv.ecc_max for lv in LEVELS]
    mu_lo = [lv.mu[0] for lv in LEVELS]
    assert ecc == sorted(ecc) and mu_lo == sorted(mu_lo, reverse=True)
    assert len(bundled_for_level(0)) < len(bundled_for_level(len(LEVELS) - 1))


# ---------------------------------------------------------------------------- learning smoke
def test_ppo_smoke():
    from stable_baselines3 import PPO

    env = make("GraspGait-v0", object="circle")
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=64, n_epochs=1,
                policy_kwargs={"net_arch": [16]}, seed=0, device="cpu")
    model.learn(total_timesteps=256)
    obs, _ = env.reset(seed=0)
    a, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(int(a))


def test_maskable_ppo_smoke():
    from sb3_contrib import MaskablePPO

    env = make("GraspGaitRandom-v0", level=0)
    model = MaskablePPO("MlpPolicy", env, n_steps=64, batch_size=64, n_epochs=1,
                        policy_kwargs={"net_arch": [16]}, seed=0, device="cpu")
    model.learn(total_timesteps=256)
    obs, info = env.reset(seed=0)
    for _ in range(20):
        a, _ = model.predict(obs, action_masks=info["action_mask"], deterministic=True)
        assert info["action_mask"][int(a)]
        obs, _, term, trunc, info = env.step(a)
        if term or trunc:
            obs, info = env.reset()


# ---------------------------------------------------------------------------- soak, speed
def test_soak_small():
    from graspgait_env.envs.soak import soak

    out = soak(total_steps=12_000, seeds=2, objects=["pentagon", "star"], random_levels=[0, 3])
    assert out["steps"] == 12_000 and out["errors"] == []
    for k in ("exceptions", "nonfinite", "outside_space", "reward_mismatch", "model_mismatch"):
        assert out[k] == 0, k
    assert out["illegal_actions"] > 0


@pytest.mark.slow
def test_soak_million_steps():
    from graspgait_env.envs.soak import soak

    out = soak(total_steps=1_000_000, seeds=20, objects=bundled_objects(),
               random_levels=range(len(LEVELS)))
    assert out["steps"] == 1_000_000
    for k in ("exceptions", "nonfinite", "outside_space", "reward_mismatch", "model_mismatch"):
        assert out[k] == 0, (k, out["errors"])


def test_bench_runs():
    from graspgait_env.envs.bench import bench_env_steps

    res = bench_env_steps(steps=2000, rounds=1)
    assert res["graspgait_steps_per_s"] > 0 and res["cartpole_steps_per_s"] > 0
    assert res["ratio"] == res["graspgait_steps_per_s"] / res["cartpole_steps_per_s"]


@pytest.mark.slow
def test_bench_meets_targets():
    from graspgait_env.envs.bench import RATIO_TARGET, STEPS_PER_S_TARGET, bench_env_steps

    res = bench_env_steps(steps=50_000, rounds=3)
    assert res["graspgait_steps_per_s"] >= STEPS_PER_S_TARGET, res
    assert res["ratio"] >= RATIO_TARGET, res


def test_gait_model_is_the_env_model(ellipse_env):
    m = GaitModel("ellipse", 0.7)
    np.testing.assert_array_equal(m.stable, ellipse_env.model.stable)
    assert m.n_actions == ellipse_env.action_space.n
