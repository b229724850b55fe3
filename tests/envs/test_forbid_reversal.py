"""``forbid_reversal``: after a rotation, no rotation the other way until a regrasp."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.gait import ROTATE, GaitModel
from graspgait_env.planners.exact import RegraspsToGo


def _play(env, rng, steps):
    """Random legal play; yields (move kind before, sign before, mask after, mask of the
    gait model at the new state)."""
    u = env.unwrapped
    obs, info = env.reset(seed=int(rng.integers(1 << 30)))
    for _ in range(steps):
        a = int(rng.choice(np.flatnonzero(info["action_mask"])))
        m = u.model.decode(u.state, a)
        obs, _, term, trunc, info = env.step(a)
        yield m, info["action_mask"], u.model.action_mask(u.state)
        if term or trunc:
            obs, info = env.reset(seed=int(rng.integers(1 << 30)))


@pytest.mark.parametrize("kw", [{"object": "ellipse"},
                                {"object": "hexagon", "contact_model": "hand"}])
def test_only_rotations_against_the_last_rotation_are_removed(kw):
    env = gym.make("graspgait_env:GraspGait-v0", mu=0.7, forbid_reversal=True, **kw)
    R = env.unwrapped.model.R
    rng = np.random.default_rng(0)
    removed = 0
    for move, mask, full in _play(env, rng, 400):
        if move.kind == ROTATE:
            against = slice(R, 2 * R) if move.delta > 0 else slice(0, R)
            assert not mask[against].any()
            removed += int(full[against].sum())
            keep = np.ones_like(full)
            keep[against] = False
            np.testing.assert_array_equal(mask[keep], full[keep])
        else:  # after a regrasp (or a restart) every legal move of the gait model
            np.testing.assert_array_equal(mask, full)
    assert removed > 0  # the rule did remove legal rotations


def test_no_endless_rocking_without_regrasps():
    """Without regrasps the object turns one way only, so the rotations run out: at most
    ceil(P / 1) rotations in a row, P the widest workspace in grid steps."""
    env = gym.make("graspgait_env:GraspGait-v0", object="hexagon", mu=0.7,
                   contact_model="hand", forbid_reversal=True)
    P = int(env.unwrapped.model.P)
    rng = np.random.default_rng(1)
    run = 0
    for move, _, _ in _play(env, rng, 600):
        run = run + 1 if move.kind == ROTATE else 0
        assert run <= P


def _fewest_regrasps(model, s0, turn_steps, back_steps, forbid):
    """0-1 breadth-first search over (state, sign of the last move if a rotation):
    rotations cost 0, regrasps 1; None when no gait reaches the turn."""
    from collections import deque

    R = model.R
    dist = {(s0.k, s0.contacts, 0): 0}
    dq = deque([(s0, 0)])
    while dq:
        s, last = dq.popleft()
        d = dist[(s.k, s.contacts, last)]
        if s.k >= turn_steps:
            return d  # 0-1 BFS pops in order of cost
        mask = model.action_mask(s)
        if forbid and last > 0:
            mask[R:2 * R] = False
        elif forbid and last < 0:
            mask[:R] = False
        for a in np.flatnonzero(mask):
            m = model.decode(s, int(a))
            t = model.apply(s, int(a))
            if t.k < -back_steps:
                continue
            nl = (1 if m.delta > 0 else -1) if m.kind == ROTATE else 0
            nd = d + (m.kind != ROTATE)
            key = (t.k, t.contacts, nl)
            if nd < dist.get(key, 1 << 30):
                dist[key] = nd
                (dq.appendleft if m.kind == ROTATE else dq.append)((t, nl))
    return None


@pytest.mark.parametrize("obj", ["ellipse", "hexagon"])
def test_the_fewest_regrasps_are_unchanged(obj):
    """From a sample of starts, the fewest regrasps with reversals forbidden equal those
    without (a rotation then its reversal is one rotation by their sum), and both equal
    the exact planner's count."""
    model = GaitModel(obj, 0.7, n=36)
    K, back = model.turn_steps(120.0), model.turn_steps(40.0)
    to_go = RegraspsToGo(model, 120.0, 40.0)
    checked = 0
    for s0 in model.start_states()[::3]:
        free = _fewest_regrasps(model, s0, K, back, False)
        assert _fewest_regrasps(model, s0, K, back, True) == free
        assert (-1 if free is None else free) == to_go(s0)
        checked += free is not None
    assert checked >= 3


def test_mujoco_env_forbids_reversal_on_the_commanded_state():
    env = gym.make("graspgait_env.envs:GraspGaitMujoco-v1", object="ellipse",
                   forbid_reversal=True)
    u = env.unwrapped
    R = u.model.R
    obs, info = env.reset(seed=0)
    rot = np.flatnonzero(info["action_mask"][:R])
    assert rot.size
    obs, _, term, trunc, info = env.step(int(rot[0]))
    assert not (term or trunc)
    assert not info["action_mask"][R:2 * R].any()
