"""Planners as SB3-style policies: they drive the GraspGait envs to the turn, as planned."""

from __future__ import annotations

import importlib

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.baselines.policies import (
    PlannerPolicy,
    plan_actions,
    plan_states,
    planner_start,
    rebased_model,
)
from graspgait_env.envs import register_envs
from graspgait_env.envs.map_env import GraspGaitEnv
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.objects import bundled_objects
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.result import PlannerResult

register_envs()
ENV = "graspgait_env.envs:GraspGait-v0"

# (module, function): the planners with the shared signature; those not written yet skip
PLANNERS = [("graspgait_env.planners.exact", "optimal_gait"),
            ("graspgait_env.planners.forward_gait", "forward_gait"),
            ("graspgait_env.planners.back_and_forth_gait", "back_and_forth_gait"),
            ("graspgait_env.planners.modified_search", "modified_search"),
            ("graspgait_env.planners.rule_based", "rule_based"),
            ("graspgait_env.planners.search", "best_first")]


def _planner(mod: str, fn: str):
    """The planner ``mod.fn``; an import error or a missing name fails the test."""
    return getattr(importlib.import_module(mod), fn)


def run_episode(env, policy, seed: int, episode_start: bool = True, options=None):
    obs, info = env.reset(seed=seed, options=options)
    first = True
    steps = 0
    while True:
        start = np.array([first]) if episode_start else None
        a, _ = policy.predict(obs, episode_start=start, deterministic=True)
        assert a.shape == () and a.dtype == np.int64
        assert info["action_mask"][int(a)], "a planner policy plays only legal moves"
        obs, r, term, trunc, info = env.step(a)
        first = False
        steps += 1
        if term or trunc:
            return info, steps


@pytest.fixture(scope="module")
def gaits() -> dict[str, bool]:
    """Which bundled objects have a gait at mu = 0.7 from the start drawn for seed 0."""
    out = {}
    for name in bundled_objects():
        env = gym.make(ENV, object=name)
        env.reset(seed=0)
        u = env.unwrapped
        out[name] = optimal_gait(u.model, u.state, 360.0).plan is not None
    return out


@pytest.mark.parametrize(("mod", "fn"), PLANNERS, ids=lambda x: str(x))
@pytest.mark.parametrize("name", bundled_objects())
def test_planner_policy_reaches_the_turn_with_the_plans_regrasps(name, mod, fn, gaits):
    planner = _planner(mod, fn)
    env = gym.make(ENV, object=name)
    policy = PlannerPolicy(env, planner)
    info, steps = run_episode(env, policy, seed=0)
    res = policy.results[0]
    if not gaits[name]:
        assert res.plan is None and not info["is_success"]
        return
    if res.plan is None and fn != "optimal_gait":
        # rule-based planners choose their own start: evaluate from there
        try:
            start = planner_start(env.unwrapped.model, planner, 360.0)
        except TypeError:  # a planner whose start is not optional
            start = None
        if start is not None:
            policy.reset()
            info, steps = run_episode(env, policy, seed=0, options={"start": start})
            res = policy.results[0]
    if res.plan is None:
        pytest.skip(f"{fn} finds no gait for {name} (the exact planner does)")
    assert info["is_success"]
    assert info["regrasps"] == res.regrasps == res.plan.regrasps
    assert info["turn_deg"] >= 360.0
    assert policy._tracks[0].replans == 1  # planned once, never thrown off


def test_policy_without_episode_start_detects_resets():
    env = gym.make(ENV, object="pentagon")
    policy = PlannerPolicy(env, optimal_gait)
    for seed in (1, 2, 3):
        info, _ = run_episode(env, policy, seed=seed, episode_start=False)
        assert info["is_success"]


def test_policy_replans_from_a_mid_gait_state():
    """Someone else moved the object: the policy replans from θ != 0 (rebased model)."""
    env = gym.make(ENV, object="ellipse")
    policy = PlannerPolicy(env, optimal_gait)
    obs, info = env.reset(seed=5)
    a, _ = policy.predict(obs, episode_start=np.array([True]))
    rng = np.random.default_rng(0)
    for _ in range(7):  # random legal moves, not the policy's
        legal = np.flatnonzero(info["action_mask"])
        obs, _, term, _, info = env.step(int(legal[rng.integers(legal.size)]))
        assert not term
    assert env.unwrapped.state.k != 0
    while True:
        a, _ = policy.predict(obs)
        obs, _, term, trunc, info = env.step(a)
        if term or trunc:
            break
    assert info["is_success"]
    assert policy._tracks[0].replans == 2


def test_rebased_model_keeps_every_move():
    m = GaitModel("pentagon", 0.7)
    env = GraspGaitEnv("pentagon", 0.7)
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(1)
    for _ in range(60):
        legal = np.flatnonzero(info["action_mask"])
        obs, _, term, trunc, info = env.step(int(legal[rng.integers(legal.size)]))
        s = env.state
        b = rebased_model(m, s.k)
        s0 = GaitState(0, s.contacts)
        assert b.is_legal_state(s0)
        np.testing.assert_array_equal(b.action_mask(s0), m.action_mask(s))
        if term or trunc:
            obs, info = env.reset()


def test_plan_states_and_actions_round_trip():
    m = GaitModel("square", 0.7)
    start = m.start_states()[100]
    res = optimal_gait(m, start, 360.0)
    states = plan_states(m, res.plan)
    assert states[0] == start and states[-1].k >= m.turn_steps(360.0)
    pairs = plan_actions(m, states)
    s = start
    for t, a in pairs:
        assert t == s and m.action_mask(s)[a]
        s = m.apply(s, a)
    assert s == states[-1]
    # a long rotation is split into moves of at most R steps
    long = plan_actions(m, [GaitState(0, start.contacts), GaitState(2 * m.R + 3, start.contacts)])
    assert [m.decode(s, a).delta for s, a in long] == [m.R, m.R, 3]


def test_fallback_without_a_plan_plays_legal_moves():
    def no_plan(model, start, turn_deg):
        return PlannerResult("none", None, reason="test")

    env = gym.make(ENV, object="circle")
    policy = PlannerPolicy(env, no_plan)
    obs, info = env.reset(seed=0)
    for t in range(50):
        a, _ = policy.predict(obs, episode_start=np.array([t == 0]))
        assert info["action_mask"][int(a)]
        obs, _, term, trunc, info = env.step(a)
        if term or trunc:
            break
    assert policy._tracks[0].replans == 1  # no replanning while falling back


@pytest.mark.parametrize("kind", ["dummy", "sync"])
def test_batched_predict_on_vector_envs(kind):
    fns = [lambda n=n: gym.make(ENV, object=n) for n in ("pentagon", "circle", "star")]
    if kind == "dummy":
        from stable_baselines3.common.vec_env import DummyVecEnv

        venv = DummyVecEnv(fns)
        venv.seed(3)
        obs = venv.reset()
    else:
        venv = gym.vector.SyncVectorEnv(fns)
        obs, _ = venv.reset(seed=3)
    policy = PlannerPolicy(venv, optimal_gait)
    starts = np.ones(3, dtype=bool)
    successes = np.zeros(3, dtype=bool)
    for _ in range(40):
        acts, _ = policy.predict(obs, episode_start=starts)
        assert acts.shape == (3,)
        if kind == "dummy":
            obs, _, done, infos = venv.step(acts)
            successes |= np.array([i.get("is_success", False) for i in infos]) & done
            starts = done
        else:
            obs, _, term, trunc, info = venv.step(acts)
            successes |= info.get("is_success", np.zeros(3, dtype=bool)) & term
            starts = term | trunc
        if successes.all():
            break
    venv.close()
    assert successes.all()


def test_sb3_evaluate_policy_runs_a_planner_policy():
    from stable_baselines3.common.evaluation import evaluate_policy

    env = gym.make(ENV, object="regular_hexagon")
    policy = PlannerPolicy(env, optimal_gait)
    rewards, lengths = evaluate_policy(policy, env, n_eval_episodes=3, deterministic=True,
                                       return_episode_rewards=True, warn=False)
    assert len(rewards) == 3 and all(r > 1.5 for r in rewards)  # turn + success bonus
    assert all(n < 40 for n in lengths)


def test_planner_policy_on_random_env():
    env = gym.make("graspgait_env.envs:GraspGaitRandom-v0", level=0, bundled_fraction=0.0)
    policy = PlannerPolicy(env, optimal_gait)
    wins = 0
    for seed in range(3):
        info, _ = run_episode(env, policy, seed=seed)
        res = policy.results[0]
        assert info["is_success"] == (res.plan is not None)
        wins += info["is_success"]
        if res.plan is not None:
            assert info["regrasps"] == res.regrasps
    assert wins >= 2


def test_policy_rejects_bad_input():
    env = gym.make(ENV)
    with pytest.raises(TypeError):
        PlannerPolicy(env, "optimal")
    policy = PlannerPolicy(env, optimal_gait)
    obs, _ = env.reset(seed=0)
    with pytest.raises(ValueError):
        policy.predict(obs[None, None, :])
    with pytest.raises(ValueError, match="vector env"):
        policy.predict(np.stack([obs, obs]))
