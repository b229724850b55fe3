"""``forbid_revisit``: no move to a state already visited in the episode."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.planners.exact import RegraspsToGo
from graspgait_env.planners.registry import run_planner
from tests.planners.helpers import replay


def _key(s):
    return int(s.k), tuple(int(x) for x in s.contacts)


@pytest.mark.parametrize("kw", [{"object": "ellipse"},
                                {"object": "hexagon", "contact_model": "hand",
                                 "forbid_reversal": True}])
def test_exactly_the_moves_to_visited_states_are_removed(kw):
    """Random legal play: the mask is the gait model's (less the reversals where those are
    forbidden too) less exactly the moves to a state of this episode; some are removed."""
    env = gym.make("graspgait_env:GraspGait-v0", mu=0.7, forbid_revisit=True, **kw)
    u, R = env.unwrapped, env.unwrapped.model.R
    rng = np.random.default_rng(0)
    removed = 0
    obs, info = env.reset(seed=0)
    visited, last = {_key(u.state)}, 0
    for _ in range(600):
        mask, s = info["action_mask"], u.state
        full = u.model.action_mask(s)
        if kw.get("forbid_reversal") and last:
            full[R:2 * R] &= last < 0
            full[:R] &= last > 0
        to_new = np.array([bool(full[a]) and _key(u.model.apply(s, a)) not in visited
                           for a in range(full.size)])
        np.testing.assert_array_equal(mask, to_new)
        removed += int(full.sum() - to_new.sum())
        a = int(rng.choice(np.flatnonzero(mask)))
        m = u.model.decode(s, a)
        obs, _, term, trunc, info = env.step(a)
        last = int(np.sign(m.delta)) if m.delta else 0
        visited.add(_key(u.state))
        if term or trunc:
            obs, info = env.reset(seed=int(rng.integers(1 << 30)))
            visited, last = {_key(u.state)}, 0
    assert removed > 50


def _cut_cycles(states):
    """The gait with every cycle cut out: each state once, consecutive states still one
    move apart (each kept pair was consecutive in the gait)."""
    out, at = [], {}
    for s in states:
        key = _key(s)
        if key in at:
            del out[at[key] + 1:]
            at = {_key(t): i for i, t in enumerate(out)}
        else:
            at[key] = len(out)
            out.append(s)
    return out


@pytest.mark.parametrize("obj", ["ellipse", "pentagon", "circle"])
def test_planners_gaits_play_with_revisits_forbidden(obj):
    """Each planner's gait from some starts, its cycles cut out, plays legally in the env
    with revisits forbidden and reaches the turn with no more regrasps; the optimal gait
    has no cycle, so its regrasps, the fewest, are unchanged."""
    env = gym.make("graspgait_env:GraspGait-v0", object=obj, mu=0.7, forbid_revisit=True)
    u = env.unwrapped
    model = u.model
    to_go = RegraspsToGo(model, 360.0, 360.0)
    played = 0
    for seed in range(3):
        env.reset(seed=seed)  # a start the env draws
        s0 = u.state
        for name in ("optimal", "rule", "best-first"):
            res = run_planner(name, model, s0, 360.0)
            if not res.success:
                continue
            states = replay(model, res)
            gait = _cut_cycles(states)
            if name == "optimal":
                assert len(gait) == len(states)
                assert res.regrasps == to_go(s0)
            obs, info = env.reset(options={"start": s0})
            for s, t in zip(gait, gait[1:], strict=False):
                a = model.encode(s, t)
                assert info["action_mask"][a], (name, s, t)
                obs, _, term, trunc, info = env.step(a)
            assert info["is_success"] and term
            assert info["regrasps"] <= res.regrasps
            played += 1
    assert played >= 6


def test_a_regrasp_and_its_undo():
    """After a regrasp the regrasp back to the grasp before it is illegal; after a
    rotation, the rotation back to the angle before it."""
    env = gym.make("graspgait_env:GraspGait-v0", object="ellipse", forbid_revisit=True)
    u = env.unwrapped
    obs, info = env.reset(seed=3)
    s0 = u.state
    R = u.model.R
    rot = np.flatnonzero(info["action_mask"][:R])
    obs, _, _, _, info = env.step(int(rot[0]))  # counter-clockwise by rot[0] + 1 steps
    back = u.model.encode(u.state, s0)
    assert u.model.action_mask(u.state)[back] and not info["action_mask"][back]
    s1 = u.state
    reg = np.flatnonzero(info["action_mask"][2 * R:]) + 2 * R
    obs, _, _, _, info = env.step(int(reg[0]))
    undo = u.model.encode(u.state, s1)
    assert u.model.action_mask(u.state)[undo] and not info["action_mask"][undo]
    obs, info = env.reset(seed=3)  # a new episode forgets the visits
    np.testing.assert_array_equal(info["action_mask"], u.model.action_mask(u.state))


@pytest.mark.parametrize("field", ["forbid_reversal", "forbid_revisit"])
def test_move_rules_off_by_default_and_checked(field):
    env = gym.make("graspgait_env:GraspGait-v0")
    assert getattr(env.unwrapped.config, field) is False
    with pytest.raises(GraspGaitInputError, match=f"{field}='no': must be True or False"):
        gym.make("graspgait_env:GraspGait-v0", **{field: "no"})


def test_mujoco_env_forbids_undoing_a_regrasp_on_the_commanded_state():
    env = gym.make("graspgait_env.envs:GraspGaitMujoco-v1", object="ellipse",
                   forbid_revisit=True)
    u = env.unwrapped
    obs, info = env.reset(seed=0)
    before = u.state
    regrasps = np.flatnonzero(info["action_mask"][2 * u.model.R:]) + 2 * u.model.R
    obs, _, term, trunc, info = env.step(int(regrasps[0]))
    assert not (term or trunc) and u.state.held() != before.held()
    undo = u.model.encode(u.state, before)
    assert u.model.action_mask(u.state)[undo] and not info["action_mask"][undo]
