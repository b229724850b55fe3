"""Careless input to every GraspGait id: each raises a ValueError (or ResetNeeded) that
names the offending argument or value, and the inputs that training stacks send work."""

from __future__ import annotations

import re
from dataclasses import FrozenInstanceError

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.envs.config import GraspGaitConfig
from graspgait_env.envs.map_env import GraspGaitEnv, ResetNeededError
from graspgait_env.envs.mujoco_env import GraspGaitMujocoEnv
from graspgait_env.envs.random_env import GraspGaitRandomEnv
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitState

# gymnasium.make warns before the env refuses render_mode='ansi'
pytestmark = pytest.mark.filterwarnings("ignore:.*not in the possible render_modes")

PREFIX = "graspgait_env.envs:"
MAP, RANDOM, MUJOCO = "GraspGait-v0", "GraspGaitRandom-v0", "GraspGaitMujoco-v1"
ALL_IDS = (MAP, RANDOM, MUJOCO)


def make(env_id: str, **kw) -> gym.Env:
    return gym.make(PREFIX + env_id, **kw)


def raises_naming(exc: type[BaseException], *needles: str):
    """``pytest.raises(exc)`` whose message must contain every needle (literally)."""
    return pytest.raises(exc, match="(?s)" + "".join(f"(?=.*{re.escape(n)})" for n in needles))


# ---------------------------------------------------------------------------- constructor
# (env id, kwargs, strings the message must contain: the kwarg and its bad value)
BAD_KWARGS = [
    (MAP, {"mu": "abc"}, ["mu='abc'", "finite number > 0", "e.g. 0.7"]),
    (MAP, {"mu": -0.5}, ["mu=-0.5", "> 0"]),
    (MAP, {"mu": float("nan")}, ["mu=nan"]),
    (MAP, {"n": "180"}, ["n='180'", "integer >= 4"]),
    (MAP, {"n": 2}, ["n=2", "integer >= 4"]),
    (MAP, {"n": 180.0}, ["n=180.0", "integer"]),
    (MAP, {"turn_deg": "360"}, ["turn_deg='360'", "e.g. 360"]),
    (MAP, {"turn_deg": 0}, ["turn_deg=0", "nonzero"]),
    (MAP, {"turn_deg": float("inf")}, ["turn_deg=inf", "finite"]),
    (MAP, {"object": "blob"}, ["blob", "object", "ellipse"]),
    (MAP, {"object": 3}, ["object=3", "bundled object name"]),
    (MAP, {"hand": "claw"}, ["claw", "hand", "thesis"]),
    (MAP, {"hand": 3}, ["hand=3", "bundled hand name"]),
    (MAP, {"alpha": float("nan")}, ["alpha=nan", "finite"]),
    (MAP, {"beta": "0.1"}, ["beta='0.1'", ">= 0"]),
    (MAP, {"gamma": -0.01}, ["gamma=-0.01", ">= 0"]),
    (MAP, {"success_bonus": float("inf")}, ["success_bonus=inf"]),
    (MAP, {"illegal_penalty": True}, ["illegal_penalty=True"]),
    (MAP, {"turn_scale_deg": 0}, ["turn_scale_deg=0", "> 0"]),
    (MAP, {"max_backward_deg": -3}, ["max_backward_deg=-3", "> 0"]),
    (MAP, {"map_window_cells": 2.5}, ["map_window_cells=2.5", "integer >= 1"]),
    (MAP, {"map_window_cells": 200}, ["map_window_cells=200", "at most"]),
    (MAP, {"map_window_deg": 400}, ["map_window_deg=400", "(0, 360]"]),
    (MAP, {"render_mode": "ansi"}, ["render_mode='ansi'", "rgb_array"]),
    (MAP, {"regrasp_cost": 1.0}, ["regrasp_cost", "GraspGait-v0", "'beta'", "valid:"]),
    (MAP, {"beat": 0.1}, ["beat", "did you mean 'beta'", "valid:"]),
    (MAP, {"config": {"beta": 0.1}}, ["config={'beta': 0.1}", "GraspGaitConfig"]),
    (RANDOM, {"level": 7}, ["level=7", "0..3"]),
    (RANDOM, {"level": "1"}, ["level='1'"]),
    (RANDOM, {"mu_range": (0.5,)}, ["mu_range=(0.5,)", "(lo, hi)"]),
    (RANDOM, {"mu_range": (0.5, 0.2)}, ["mu_range=(0.5, 0.2)", "lo <= hi"]),
    (RANDOM, {"mu_range": (0.1, "x")}, ["mu_range[1]='x'"]),
    (RANDOM, {"bundled_fraction": 2}, ["bundled_fraction=2", "[0, 1]"]),
    (RANDOM, {"object_seeds": (5, 1)}, ["object_seeds=(5, 1)", "lo < hi"]),
    (RANDOM, {"object_seeds": None}, ["object_seeds=None"]),
    (RANDOM, {"object": "pentagon"}, ["object='pentagon'", "options={'object'", "valid:"]),
    (RANDOM, {"alpha": "x"}, ["alpha='x'"]),
    (RANDOM, {"hand": "circular_reach"}, ["hand='circular_reach'", "reach"]),
    (MUJOCO, {"mu": "abc"}, ["mu='abc'", "finite number > 0"]),
    (MUJOCO, {"pose_noise": "big"}, ["pose_noise='big'", "thesis"]),
    (MUJOCO, {"pose_noise": (-1.0, 0.0)}, ["pose_noise[0]=-1.0", ">= 0"]),
    (MUJOCO, {"sim_config": 3}, ["sim_config=3", "SimConfig"]),
    (MUJOCO, {"bogus": 1}, ["bogus=1", "GraspGaitMujoco-v1", "sim_config"]),
    (MUJOCO, {"illegal_penalty": -1}, ["illegal_penalty=-1", ">= 0"]),
]


@pytest.mark.parametrize(("env_id", "kw", "needles"), BAD_KWARGS,
                         ids=[f"{e}-{k}" for e, k, _ in BAD_KWARGS])
def test_bad_keyword_argument_names_itself(env_id, kw, needles):
    with raises_naming(ValueError, *needles):
        make(env_id, **kw)


def test_bad_kwargs_raise_the_projects_input_error():
    """Every message above comes from GraspGaitInputError (a ValueError): the CLI's kind."""
    with pytest.raises(GraspGaitInputError):
        GraspGaitEnv(mu="abc")
    with pytest.raises(GraspGaitInputError):
        GraspGaitRandomEnv(level=9)
    with pytest.raises(GraspGaitInputError):
        GraspGaitMujocoEnv(nn=3)


# ---------------------------------------------------------------------------- config
def test_config_is_frozen_validated_and_shared_by_every_id():
    cfg = GraspGaitConfig(beta=0.05, map_window_cells=20)
    with pytest.raises(FrozenInstanceError):
        cfg.beta = 1.0  # type: ignore[misc]
    for env_id in ALL_IDS:
        env = make(env_id, config=cfg, gamma=0.2)  # keywords replace the config's fields
        u = env.unwrapped
        assert u.config == GraspGaitConfig(beta=0.05, gamma=0.2, map_window_cells=20)
        assert (u.beta, u.gamma, u.map_window_cells) == (0.05, 0.2, 20)
        assert u.turn_scale_deg == 360.0 and u.hand.name == "thesis"
        with pytest.raises(AttributeError):
            u.beta = 1.0  # read-only: make a new env to change it
    with raises_naming(ValueError, "gamma=-1"):
        GraspGaitConfig(gamma=-1)


def test_config_docstring_examples():
    import doctest

    from graspgait_env.envs import config

    assert doctest.testmod(config).failed == 0


def test_config_defaults_are_the_documented_keyword_defaults():
    cfg = GraspGaitConfig()
    assert (cfg.hand, cfg.turn_deg, cfg.n, cfg.alpha, cfg.beta, cfg.gamma,
            cfg.turn_scale_deg, cfg.success_bonus, cfg.dead_end_penalty, cfg.illegal_penalty,
            cfg.max_backward_deg, cfg.map_window_deg, cfg.map_window_cells) == (
        None, 360.0, 180, 1.0, 0.01, 0.01, None, 1.0, 1.0, 0.1, 360.0, 360.0, 36)
    assert type(GraspGaitConfig(beta=np.float32(0.5)).beta) is float
    assert type(GraspGaitConfig(n=np.int64(90)).n) is int


# ---------------------------------------------------------------------------- actions
@pytest.fixture(scope="module")
def env() -> GraspGaitEnv:
    e = GraspGaitEnv("ellipse")
    e.reset(seed=0)
    return e


BAD_ACTIONS = [
    (1.5, ["action=1.5", "integer action index"]),
    (2.0, ["action=2.0", "integer action index"]),
    (np.float64(2.0), ["action=np.float64(2.0)"]),
    ("3", ["action='3'"]),
    (None, ["action=None"]),
    (True, ["action=True", "bool"]),
    (np.bool_(False), ["action=np.False_", "bool"]),
    ([0], ["action=[0]"]),
    (np.array([0]), ["action=array([0])"]),
    (np.array(1.0), ["action=array(1.)"]),
    (-1, ["action=-1", "outside the action space 0..181"]),
    (182, ["action=182", "outside the action space"]),
    (np.int64(10**6), ["action=np.int64(1000000)", "outside the action space"]),
]


@pytest.mark.parametrize(("action", "needles"), BAD_ACTIONS, ids=[repr(a) for a, _ in BAD_ACTIONS])
def test_bad_action_raises_naming_it(env, action, needles):
    before = env.state
    with raises_naming(ValueError, *needles):
        env.step(action)
    assert env.state == before  # nothing happened


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_bad_action_on_every_id(env_id):
    e = make(env_id)
    e.reset(seed=0)
    for bad, needle in ((0.0, "action=0.0"), ("0", "action='0'"), (None, "action=None")):
        with raises_naming(ValueError, needle):
            e.step(bad)


def test_integer_kinds_that_training_stacks_send_are_accepted():
    """SB3 VecEnvs and Gymnasium vector envs pass NumPy int64 scalars, SB3's ``predict`` on
    one observation a 0-d array; all integer kinds give the same transition as an int."""
    kinds = [int, np.int64, np.int32, np.uint8, np.intp, lambda a: np.array(a),
             lambda a: np.array(a, dtype=np.int16)]
    ref = None
    for kind in kinds:
        e = GraspGaitEnv("pentagon")
        _, info = e.reset(seed=3)
        a = int(np.flatnonzero(info["action_mask"])[0])
        obs, r, term, trunc, info = e.step(kind(a))
        out = (obs.tobytes(), r, term, trunc, info["action_mask"].tobytes())
        assert ref is None or out == ref
        ref = out


# ---------------------------------------------------------------------------- call order
@pytest.mark.parametrize("env_id", ALL_IDS)
@pytest.mark.parametrize("call", ["step", "action_masks", "state", "render"])
def test_calls_before_reset_say_reset_first(env_id, call):
    u = make(env_id, render_mode="rgb_array").unwrapped
    with raises_naming(ResetNeededError, call, "call reset() first"):
        if call == "step":
            u.step(0)
        elif call == "action_masks":
            u.action_masks()
        elif call == "state":
            _ = u.state
        else:
            u.render()


def test_reset_needed_is_gymnasiums_and_a_runtime_error():
    e = GraspGaitEnv()
    for exc in (gym.error.ResetNeeded, RuntimeError):
        with pytest.raises(exc):
            e.action_masks()
    with pytest.raises(gym.error.ResetNeeded):  # what gymnasium.make's wrapper says too
        make(MAP).step(0)


def test_a_failed_reset_leaves_the_env_needing_reset():
    e = GraspGaitEnv("ellipse")
    e.reset(seed=0)
    with raises_naming(ValueError, "options['start']"):
        e.reset(options={"start": {1: 51.0, 3: 270.0}})  # off the 2-degree grid
    with pytest.raises(ResetNeededError):
        e.step(0)
    e.reset(seed=0)
    e.step(int(np.flatnonzero(e.action_masks())[0]))


# ---------------------------------------------------------------------------- reset
BAD_SEEDS = [("abc", "seed='abc'"), (-1, "seed=-1"), (1.5, "seed=1.5"), (True, "seed=True")]


@pytest.mark.parametrize(("seed", "needle"), BAD_SEEDS, ids=[repr(s) for s, _ in BAD_SEEDS])
@pytest.mark.parametrize("env_id", [MAP, RANDOM])
def test_bad_seed_names_itself(env_id, seed, needle):
    with raises_naming(ValueError, needle, "integer >= 0"):
        make(env_id).unwrapped.reset(seed=seed)


def test_numpy_integer_seed_is_its_value():
    a, b = GraspGaitEnv(), GraspGaitEnv()
    np.testing.assert_array_equal(a.reset(seed=np.int64(7))[0], b.reset(seed=7)[0])


BAD_OPTIONS = [
    (MAP, [("start", 1)], "options=[('start', 1)]"),
    (MAP, {"strat": {1: 50.0, 3: 270.0}}, "did you mean 'start'"),
    (MAP, {"mu": 0.5}, "options['mu']"),
    (MAP, {"start": "50, 270"}, "options['start']='50, 270'"),
    (MAP, {"start": {1: "x", 3: 270.0}}, "options['start']"),
    (MAP, {"start": {1: 50.0}}, "exactly two fingers"),
    (MAP, {"start": {4: 50.0, 3: 270.0}}, "finger 4"),
    (MAP, {"start": GaitState(3, (-1, 67, 148))}, "legal state at k = 0"),
    (RANDOM, {"mu": "abc"}, "options['mu']='abc'"),
    (RANDOM, {"mu": -1}, "options['mu']=-1"),
    (RANDOM, {"object_seed": "x"}, "options['object_seed']='x'"),
    (RANDOM, {"object_seed": -5}, "options['object_seed']=-5"),
    (RANDOM, {"object": "blob"}, "blob"),
    (RANDOM, {"object": 7}, "options['object']=7"),
    (RANDOM, {"objects": "square"}, "did you mean 'object'"),
    (MUJOCO, {"strat": None}, "options['strat']"),
]


@pytest.mark.parametrize(("env_id", "options", "needle"), BAD_OPTIONS,
                         ids=[f"{e}-{o!r}" for e, o, _ in BAD_OPTIONS])
def test_bad_reset_option_names_itself(env_id, options, needle):
    with raises_naming(ValueError, needle):
        make(env_id).unwrapped.reset(seed=0, options=options)
