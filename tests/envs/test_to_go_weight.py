"""``to_go_weight``: regrasps priced against the exact optimum (opt-in reward shaping)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.baselines.policies import PlannerPolicy
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.planners.exact import RegraspsToGo, optimal_gait

W, BETA = 0.1, 0.03


def make(**kw) -> gym.Env:
    return gym.make("graspgait_env:GraspGait-v0", object="ellipse", mu=0.7, n=90, **kw)


def test_off_by_default_and_checked():
    assert make().unwrapped.config.to_go_weight == 0.0
    with pytest.raises(GraspGaitInputError, match=r"to_go_weight=-1: .*>= 0"):
        make(to_go_weight=-1)


def test_regrasp_terms_sum_to_the_fall_in_regrasps_to_go():
    """Random legal play: the regrasp terms sum to ``-beta * regrasps + w * (G0 - G_end)``
    and every regrasp term is ``-beta + w * {-1, 0, 1}``; the other five terms are those
    of the unshaped env, step for step."""
    shaped, plain = make(to_go_weight=W, beta=BETA), make(beta=BETA)
    to_go = RegraspsToGo(shaped.unwrapped.model, 360.0, 360.0)
    rng = np.random.default_rng(0)
    for seed in range(4):
        obs, info = shaped.reset(seed=seed)
        plain.reset(seed=seed)
        g0 = to_go(shaped.unwrapped.state)
        total, done = 0.0, False
        while not done:
            a = int(rng.choice(np.flatnonzero(info["action_mask"])))
            obs, r, term, trunc, info = shaped.step(a)
            _, r_plain, *_, info_plain = plain.step(a)
            terms, base = info["reward_terms"], info_plain["reward_terms"]
            assert {k: v for k, v in terms.items() if k != "regrasp"} == \
                {k: v for k, v in base.items() if k != "regrasp"}
            gained = (terms["regrasp"] - base["regrasp"]) / W
            assert gained == pytest.approx(round(gained)) and round(gained) in (-1, 0, 1)
            total += terms["regrasp"]
            done = term or trunc
        g_end = to_go(shaped.unwrapped.state)
        expected = -BETA * info["regrasps"] + (W * (g0 - g_end) if g0 >= 0 else 0.0)
        assert total == pytest.approx(expected)


@pytest.mark.parametrize("contact_model", ["point", "hand"])
def test_an_optimal_gait_gains_one_per_regrasp(contact_model):
    """Under either contact model (the table is built on the env's own gait model)."""
    env = make(to_go_weight=W, beta=BETA, contact_model=contact_model)
    policy = PlannerPolicy(env, optimal_gait)
    checked = 0
    for seed in range(6):
        obs, info = env.reset(seed=seed)
        start = env.unwrapped.state
        best = optimal_gait(env.unwrapped.model, start, 360.0)
        if best.plan is None:
            continue
        state, done, terms = None, False, []
        while not done:
            a, state = policy.predict(obs, state=state, deterministic=True)
            obs, r, term, trunc, info = env.step(int(a))
            terms.append(info["reward_terms"]["regrasp"])
            done = term or trunc
        assert info["is_success"] and info["regrasps"] == best.regrasps
        assert [t for t in terms if t] == pytest.approx([W - BETA] * best.regrasps)
        checked += 1
    assert checked >= 2


def test_random_env_keeps_the_object_for_episodes_per_object():
    """``episodes_per_object=3``: the object and mu change every third reset (a seeded
    reset draws anew); the shaped reward works on drawn objects."""
    env = gym.make("graspgait_env:GraspGaitRandom-v0", episodes_per_object=3,
                   to_go_weight=W, beta=BETA)
    drawn = []
    obs, info = env.reset(seed=5)
    drawn.append((info["object"], info["mu"], env.unwrapped.model))
    for _ in range(5):
        obs, info = env.reset()
        drawn.append((info["object"], info["mu"], env.unwrapped.model))
    assert drawn[0][2] is drawn[1][2] is drawn[2][2]
    assert drawn[3][2] is drawn[4][2] is drawn[5][2]
    assert (drawn[2][0], drawn[2][1]) != (drawn[3][0], drawn[3][1])
    env.reset(seed=5)
    assert (env.unwrapped.model.shape.name, env.unwrapped.model.mu) == drawn[0][:2]
    with pytest.raises(GraspGaitInputError, match="episodes_per_object=0"):
        gym.make("graspgait_env:GraspGaitRandom-v0", episodes_per_object=0)
