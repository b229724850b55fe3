"""``regrasp_lookahead``: per action, the shortfall of the turn after the best chain of a
few more regrasps (RegraspReach, a depth-limited search of the grasp map)."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.errors import GraspGaitInputError


def brute_force_reach(env, D: int) -> np.ndarray:
    """The field from GaitModel.apply/action_mask and RegraspReach.shortfall alone."""
    u = env.unwrapped
    model, reach, s, mask = u.model, u._reach, u.state, u.action_masks()
    R, P = model.R, model.P
    K = abs(model.turn_steps(u.config.turn_deg))
    none = K - reach.unreachable
    reg = np.full((2 * P, D), none, dtype=float)
    for a in np.flatnonzero(mask[2 * R:]) + 2 * R:
        t = model.apply(s, int(a))
        reg[a - 2 * R] = [reach.shortfall(t, j) for j in range(D)]
    rot = np.full((2 * R, D), none, dtype=float)
    sign = 1 if u.config.turn_deg > 0 else -1
    for a in np.flatnonzero(mask[:2 * R]):
        t = model.apply(s, int(a))
        if sign * t.k >= K:
            rot[a] = 0
            continue
        keys = [tuple(reach.shortfall(model.apply(t, int(b)), j) for j in range(D))
                for b in np.flatnonzero(model.action_mask(t)[2 * R:]) + 2 * R]
        if keys:  # best at the deepest level first, then the next, ...
            rot[a] = min(keys, key=lambda x: x[::-1])
    return np.concatenate((reg.ravel(), rot.ravel())) / K


@pytest.mark.parametrize("kw, D", [({"object": "ellipse"}, 2),
                                   ({"object": "pentagon", "n": 90, "turn_deg": -360.0}, 3),
                                   ({"object": "hexagon", "forbid_revisit": True}, 1),
                                   # the deepest table: rotations' picks by tuples
                                   ({"object": "ellipse", "contact_model": "hand"}, 10)])
def test_field_is_the_reach_of_every_move(kw, D):
    env = gym.make("graspgait_env:GraspGait-v0", mu=0.7, regrasp_lookahead=D, **kw)
    plain = gym.make("graspgait_env:GraspGait-v0", mu=0.7, **kw)
    u = env.unwrapped
    A = u.model.n_actions
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + A * D
    assert u.layout.reach.stop == u.layout.size
    rng = np.random.default_rng(1)
    obs, info = env.reset(seed=1)
    obs_p, _ = plain.reset(seed=1)
    values = set()
    for _ in range(40):
        assert env.observation_space.contains(obs)
        np.testing.assert_array_equal(obs[:obs_p.size], obs_p)
        np.testing.assert_allclose(obs[u.layout.reach], brute_force_reach(env, D), atol=1e-6)
        values.update(np.round(obs[u.layout.reach], 4).tolist())
        a = int(rng.choice(np.flatnonzero(info["action_mask"])))
        obs, _, term, trunc, info = env.step(a)
        obs_p, *_ = plain.step(a)
        if term or trunc:
            break
    assert len(values) > 3  # the field tells moves apart


def test_reading_the_field_greedily_needs_few_regrasps_beyond_the_optimum():
    """What the field is for: on procedural objects the greedy reading (the move whose
    successor falls least short at depth D, then D - 1, ...) needs about as many
    regrasps as the exact optimum; the field never contains the optimum's count."""
    D = 3
    env = gym.make("graspgait_env:GraspGaitRandom-v0", level=1, regrasp_lookahead=D,
                   forbid_revisit=True, to_go_weight=1.0, episodes_per_object=1)
    u = env.unwrapped
    regrasps = optimum = 0
    for seed in range(6):
        obs, info = env.reset(seed=seed)
        G = u._to_go(u.state)
        if G < 0:
            continue
        R, P = u.model.R, u.model.P
        n = 0
        for _ in range(200):
            keys = obs[u.layout.reach].reshape(2 * P + 2 * R, D)[:, ::-1]  # deepest first
            order = np.concatenate((np.arange(2 * R, 2 * R + 2 * P), np.arange(2 * R)))
            legal = info["action_mask"][order]
            steps_to_go = round(float(obs[15]) * abs(u.model.turn_steps(360.0)))
            finish = legal & (order < R) & (order + 1 >= steps_to_go)  # a rotation to the turn
            if finish.any():
                a = int(order[np.flatnonzero(finish)[0]])
            else:  # ties: a regrasp before a rotation, a shorter rotation first
                size = np.where(order < 2 * R, order % R + 1, 0)
                a = int(order[min((tuple(keys[i]), size[i], i)
                                  for i in np.flatnonzero(legal))[2]])
            n += a >= 2 * R
            obs, _, term, trunc, info = env.step(a)
            if term or trunc:
                break
        assert info["is_success"], (seed, n, G, term, trunc, info.get("turn_deg"))
        regrasps, optimum = regrasps + n, optimum + G
    assert optimum > 0 and regrasps <= 1.2 * optimum


def test_pickled_env_continues_with_its_field():
    env = gym.make("graspgait_env:GraspGait-v0", object="ellipse", regrasp_lookahead=2).unwrapped
    obs, info = env.reset(seed=2)
    twin = pickle.loads(pickle.dumps(env))
    rng = np.random.default_rng(2)
    for _ in range(10):
        a = int(rng.choice(np.flatnonzero(info["action_mask"])))
        obs, *_, info = env.step(a)
        obs_t, *_ = twin.step(a)
        np.testing.assert_array_equal(obs, obs_t)


def test_off_by_default_and_checked():
    env = gym.make("graspgait_env:GraspGait-v0")
    assert env.unwrapped.layout.reach.stop - env.unwrapped.layout.reach.start == 0
    assert env.unwrapped.config.regrasp_lookahead == 0
    from graspgait_env.planners.reach import MAX_REACH_DEPTH

    for bad in (-1, MAX_REACH_DEPTH + 2, 1.5, True, "2"):
        with pytest.raises(GraspGaitInputError, match="regrasp_lookahead="):
            gym.make("graspgait_env:GraspGait-v0", regrasp_lookahead=bad)


def test_batched_env_writes_the_single_envs_lookahead():
    """The batched env implements the field: each row's reach look-ahead is the single
    env's for the same seed (the same function, RegraspReach.move_shortfalls_batch)."""
    venv = gym.make_vec("graspgait_env:GraspGait-v0", num_envs=2,
                        vectorization_mode="vector_entry_point", regrasp_lookahead=2)
    obs, _ = venv.reset(seed=5)
    reach = venv.unwrapped.layout.reach
    assert reach.stop > reach.start
    for i in range(2):
        single = gym.make("graspgait_env:GraspGait-v0", regrasp_lookahead=2)
        o, _ = single.reset(seed=5 + i)
        np.testing.assert_array_equal(obs[i, reach], o[reach])
