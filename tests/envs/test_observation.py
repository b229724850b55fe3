"""``observation_mode``: the named parts of the GraspGait observation.

The ``actions`` part's features are checked against the gait model itself (its
``apply`` and ``state_rotation_room``, thesis 5.2 and 4.2), not against the code that
computes them; the parts are checked against the box vector they come from, and the
``"flat"`` vector against ``gymnasium.spaces.flatten`` of the dict.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.utils.env_checker import check_env

import graspgait_env  # noqa: F401  (registers the ids)
from graspgait_env.envs.map_env import state_from_observation
from graspgait_env.envs.observation import (
    ACTION_FEATURES,
    GRASP_FIELDS,
    ObservationLayout,
    check_observation_mode,
)
from graspgait_env.errors import GraspGaitInputError

ID = "graspgait_env:GraspGait-v0"


def _rollout(steps: int, seed: int, **kw):
    """(box obs, dict obs, flat obs, info, env) per step of three envs driven alike by
    the same random legal actions."""
    envs = [gym.make(ID, observation_mode=m, **kw) for m in ("box", "dict", "flat")]
    rng = np.random.default_rng(seed)
    outs = [e.reset(seed=seed) for e in envs]
    for _ in range(steps):
        obs = [o[0] for o in outs]
        info = outs[0][1]
        yield obs[0], obs[1], obs[2], info, envs[1].unwrapped
        mask = info["action_mask"]
        a = int(rng.choice(np.flatnonzero(mask)))
        outs = [e.step(a) for e in envs]
        if outs[0][2] or outs[0][3]:
            outs = [e.reset() for e in envs]
        else:
            outs = [(o[0], o[4]) for o in outs]


@pytest.mark.parametrize("kw", [
    {"object": "ellipse", "turn_deg": 90.0},
    {"object": "pentagon", "turn_deg": -60.0, "mu": 0.5},
    {"object": "hexagon", "turn_deg": 45.0, "contact_model": "hand"},
    {"object": "circle", "turn_deg": 30.0},  # room / K = 3 exactly at the bound
])
def test_action_features_are_what_each_move_leads_to(kw):
    """``achieved``, ``room_on`` and ``room_back`` of every legal action equal the
    model's successor's turn and rotation room (over K, ordered by the turn's sign);
    an illegal action reads 0 there; ``legal`` is the mask, ``rotation`` the kind."""
    checked = 0
    for _, obs, _, info, u in _rollout(25, 3, **kw):
        model, sign = u.model, (1 if kw["turn_deg"] > 0 else -1)
        K = abs(model.turn_steps(kw["turn_deg"]))
        lay = u.layout
        act = obs["actions"]
        assert act.shape == (model.n_actions, len(ACTION_FEATURES))
        assert u.observation_space.contains(obs)
        col = {name: lay.feature(name) for name in ACTION_FEATURES}
        mask = info["action_mask"]
        np.testing.assert_array_equal(act[:, col["legal"]], mask.astype(np.float32))
        np.testing.assert_array_equal(act[:, col["rotation"]],
                                      np.arange(model.n_actions) < 2 * model.R)
        s = u.state
        for a in range(model.n_actions):
            if not mask[a]:
                assert not act[a, [col["achieved"], col["room_on"], col["room_back"]]].any()
                continue
            t = model.apply(s, a)
            ccw, cw = model.state_rotation_room(t)
            on, back = (ccw, cw) if sign > 0 else (cw, ccw)
            assert act[a, col["achieved"]] == pytest.approx(sign * t.k / K, abs=1e-6)
            assert act[a, col["room_on"]] == pytest.approx(on / K, abs=1e-6)
            assert act[a, col["room_back"]] == pytest.approx(back / K, abs=1e-6)
            checked += 1
    assert checked > 50


@pytest.mark.parametrize("kw", [
    {},
    {"map_lines": True, "rotation_lookahead": True, "regrasp_lookahead": 2, "n": 90},
    {"regrasp_lookahead": 1, "contact_model": "hand", "object": "hexagon",
     "turn_deg": -40.0},
])
def test_parts_are_the_box_vector_and_flat_is_the_flattened_dict(kw):
    for box, obs, flat, _, u in _rollout(12, 5, **kw):
        lay = u.layout
        space = u.observation_space
        assert space.contains(obs), {k: v.dtype for k, v in obs.items()}
        assert list(obs) == list(lay.parts)
        np.testing.assert_array_equal(obs["grasp"], box[:len(GRASP_FIELDS)])
        np.testing.assert_array_equal(obs["window"].ravel(), box[lay.window])
        if "lines" in obs:
            np.testing.assert_array_equal(obs["lines"].ravel(), box[lay.lines])
        np.testing.assert_array_equal(flat, spaces.flatten(space, obs))
        assert flat.dtype == np.float32 and flat.shape == (lay.flat_size,)
        for name, part in lay.unflatten(flat).items():
            np.testing.assert_array_equal(part, obs[name])
        np.testing.assert_array_equal(lay.flatten(obs), flat)
        R2 = 2 * u.model.R
        if lay.lookahead.stop > lay.lookahead.start:
            np.testing.assert_array_equal(obs["actions"][:R2, lay.feature("opens")],
                                          box[lay.lookahead])
            assert not obs["actions"][R2:, lay.feature("opens")].any()
        D = lay.reach_depth
        if D:
            reach = box[lay.reach]
            P2 = u.model.n_actions - R2
            cols = [lay.feature(f"reach_{j + 1}") for j in range(D)]
            np.testing.assert_array_equal(obs["actions"][R2:, cols],
                                          reach[:P2 * D].reshape(P2, D))
            np.testing.assert_array_equal(obs["actions"][:R2, cols],
                                          reach[P2 * D:].reshape(R2, D))
        state = state_from_observation(obs, u.model, u.config.turn_deg)
        assert state == u.state


def test_dict_and_flat_envs_pass_gymnasiums_checker():
    for mode in ("dict", "flat"):
        env = gym.make(ID, observation_mode=mode, regrasp_lookahead=1).unwrapped
        check_env(env, skip_render_check=True)


def test_random_objects_have_parts_sized_to_their_map():
    env = gym.make("graspgait_env:GraspGaitRandom-v0", observation_mode="dict", level=2)
    for seed in range(3):
        obs, info = env.reset(seed=seed)
        assert env.observation_space.contains(obs)
        np.testing.assert_array_equal(obs["actions"][:, 0], info["action_mask"])
        obs, *_ = env.step(int(np.flatnonzero(info["action_mask"])[0]))
        assert env.observation_space.contains(obs)


def test_mujoco_env_returns_the_same_parts():
    kw = {"object": "ellipse"}
    a = gym.make("graspgait_env:GraspGaitMujoco-v1", observation_mode="dict", **kw)
    b = gym.make("graspgait_env:GraspGaitMujoco-v1", **kw)
    (oa, ia), (ob, _) = a.reset(seed=1), b.reset(seed=1)
    assert a.observation_space.contains(oa)
    np.testing.assert_array_equal(oa["grasp"], ob[:len(GRASP_FIELDS)])
    act = int(np.flatnonzero(ia["action_mask"])[0])
    (oa, ra, *_), (ob, rb, *_) = a.step(act), b.step(act)
    assert ra == rb
    np.testing.assert_array_equal(oa["grasp"], ob[:len(GRASP_FIELDS)])


@pytest.mark.parametrize("bad", ["Dict", "boxes", 0, None])
def test_a_bad_mode_is_refused_with_the_modes(bad):
    with pytest.raises(GraspGaitInputError, match=r"observation_mode=.*'box'.*'dict'.*'flat'"):
        gym.make(ID, observation_mode=bad)
    with pytest.raises(GraspGaitInputError, match="observation_mode"):
        check_observation_mode(bad)


def test_layout_names_its_features_and_refuses_unknown_ones():
    lay = ObservationLayout(n_actions=10, cells=3, lookahead=4, reach=20)
    assert lay.action_features == ACTION_FEATURES + ("opens", "reach_1", "reach_2",
                                                     "reach_rank")
    assert [shape for _, shape in lay.parts.values()] == [(16,), (10, 9), (3, 3)]
    assert lay.flat_size == 16 + 90 + 9
    with pytest.raises(GraspGaitInputError, match="feature='reach_3'.*reach_2"):
        lay.feature("reach_3")
    with pytest.raises(GraspGaitInputError, match="flat_size|115"):
        lay.unflatten(np.zeros(114, dtype=np.float32))


def _greedy_by_tuples(act, lay, model, K):
    """The greedy reading written out with Python tuples (the order the benchmark's
    ``greedy-reach`` documents): a finishing rotation, then the shortfalls deepest
    first, then regrasp before rotation and the shorter rotation, then regrasps before
    rotations in action order."""
    R2, A = 2 * model.R, model.n_actions
    cols = [lay.feature(f"reach_{j + 1}") for j in range(lay.reach_depth)][::-1]
    legal = act[:, lay.feature("legal")] > 0.5
    order = list(range(R2, A)) + list(range(R2))

    def key(a):
        finish = a < R2 and round(float(act[a, lay.feature("achieved")]) * K) >= K
        size = abs(model.decode(None, a).delta) if a < R2 else 0  # thesis 5.2
        return (not finish, *(round(float(act[a, c]) * K) for c in cols), size,
                order.index(a))
    return sorted((a for a in range(A) if legal[a]), key=key)


@pytest.mark.parametrize("kw", [
    {"object": "ellipse", "regrasp_lookahead": 3, "contact_model": "hand"},
    {"object": "pentagon", "regrasp_lookahead": 2, "turn_deg": -90.0, "mu": 0.5},
    # deeper than 6 regrasps a key packed into one int64 overflowed (the general
    # recipe reads 8): the order must still be the tuples' order
    {"object": "hexagon", "regrasp_lookahead": 8, "contact_model": "hand"},
])
def test_reach_rank_is_the_greedy_reading(kw):
    """``reach_rank`` orders the legal moves as the greedy reading does, written here
    with tuples; its least is the move the benchmark's greedy-reach policy plays, in
    the single env and in every row of the batched one."""
    from graspgait_env.benchmark.policies import greedy_reach_predictor

    box_env = gym.make(ID, **kw)
    pred = greedy_reach_predictor(box_env, depth=kw["regrasp_lookahead"])
    checked = 0
    for box, obs, _, info, u in _rollout(40, 5, **kw):
        lay, model = u.layout, u.model
        K = abs(model.turn_steps(kw.get("turn_deg", 360.0)))
        act = obs["actions"]
        expected = _greedy_by_tuples(act, lay, model, K)
        rank = np.rint(act[:, lay.feature("reach_rank")] * (model.n_actions - 1))
        assert [int(a) for a in np.argsort(rank, kind="stable")[:len(expected)]] == expected
        assert (rank[~info["action_mask"]] == model.n_actions - 1).all()
        box_env.unwrapped._set_state(u.state)  # the box env in the same state
        assert pred(box, info["action_mask"]) == expected[0]
        checked += 1
    assert checked == 40
    vec = gym.make_vec(ID, num_envs=3, vectorization_mode="vector_entry_point",
                       observation_mode="dict", **kw)
    sync = gym.vector.SyncVectorEnv([lambda: gym.make(ID, observation_mode="dict", **kw)] * 3)
    (ov, _), (os_, _) = vec.reset(seed=9), sync.reset(seed=9)
    for _ in range(10):
        np.testing.assert_array_equal(ov["actions"], os_["actions"])
        a = np.array([int(np.argmin(r[:, -1])) for r in ov["actions"]])
        ov, *_ = vec.step(a)
        os_, *_ = sync.step(a)
