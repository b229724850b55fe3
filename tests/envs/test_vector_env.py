"""The batched GraspGait-v0 (``vectorization_mode="vector_entry_point"``).

Its transitions must equal those of N single envs (Gymnasium's ``SyncVectorEnv`` over
``gymnasium.make``) bit for bit, across autoresets, for the same seeds.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import graspgait_env  # noqa: F401  (registers the ids)
from graspgait_env.envs import vector_env
from graspgait_env.envs.map_env import REWARD_TERMS, ResetNeededError
from graspgait_env.envs.vector_env import GraspGaitVectorEnv
from graspgait_env.errors import GraspGaitInputError

ID = "graspgait_env:GraspGait-v0"


RANDOM_ID = "graspgait_env:GraspGaitRandom-v0"


def _batched(num_envs: int, env_id: str = ID, **kw) -> gym.vector.VectorEnv:
    return gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                        **kw)


def _sync(num_envs: int, env_id: str = ID, **kw) -> gym.vector.VectorEnv:
    return gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="sync", **kw)


def assert_same(x, y, path="") -> None:
    """Equal values, types, dtypes and shapes, recursively (dicts of arrays)."""
    if isinstance(x, tuple):
        assert isinstance(y, tuple) and len(x) == len(y), path
        for i, (u, v) in enumerate(zip(x, y, strict=True)):
            assert_same(u, v, f"{path}[{i}]")
        return
    if isinstance(x, dict):
        assert isinstance(y, dict) and set(x) == set(y), (path, sorted(x), sorted(y))
        for key in x:
            assert_same(x[key], y[key], f"{path}/{key}")
        return
    assert type(x) is type(y), (path, type(x), type(y))
    if isinstance(x, np.ndarray):
        assert (x.dtype, x.shape) == (y.dtype, y.shape), (path, x.dtype, y.dtype, x.shape,
                                                          y.shape)
        np.testing.assert_array_equal(x, y, err_msg=path)
    else:
        assert x == y, path


def masked_actions(masks: np.ndarray, rng: np.random.Generator,
                   illegal_rate: float = 0.1) -> np.ndarray:
    """A uniform legal action per row; with probability ``illegal_rate`` a step of
    uniform actions over the whole space (illegal moves included)."""
    if rng.random() < illegal_rate:
        return rng.integers(0, masks.shape[1], masks.shape[0])
    counts = masks.sum(axis=1)
    pick = (rng.random(masks.shape[0]) * counts).astype(np.int64)
    # a row with no legal move (a dead end, e.g. with forbid_reversal) is reset on the
    # next step whatever the action
    return np.array([np.flatnonzero(m)[j] if m.any() else 0
                     for m, j in zip(masks, pick, strict=True)])


def compare_rollouts(num_envs: int, seed: int, steps: int, env_id: str = ID,
                     **kw) -> dict[str, int]:
    """Step the batched and the sync env side by side; return counts of episode ends."""
    a, b = _batched(num_envs, env_id, **kw), _sync(num_envs, env_id, **kw)
    obs_a, info_a = a.reset(seed=seed)
    obs_b, info_b = b.reset(seed=seed)
    assert_same(obs_a, obs_b)
    assert_same(info_a, info_b)
    rng = np.random.default_rng(seed)
    ends = {"success": 0, "other_end": 0, "truncated": 0}
    for t in range(steps):
        act = masked_actions(info_a["action_mask"], rng)
        out_a, out_b = a.step(act), b.step(act)
        for name, x, y in zip(("obs", "reward", "terminated", "truncated", "info"),
                              out_a, out_b, strict=True):
            assert_same(x, y, f"step {t} {name}")
        info_a = out_a[4]
        term, trunc = out_a[2], out_a[3]
        ends["success"] += int((term & info_a["is_success"]).sum())
        ends["other_end"] += int((term & ~info_a["is_success"]).sum())
        ends["truncated"] += int(trunc.sum())
    a.close()
    b.close()
    return ends


@pytest.mark.parametrize("n, seed", [(1, 0), (3, 1), (16, 2)])
def test_same_transitions_as_single_envs(n, seed):
    """Episodes end often (a 20-degree turn, a 10-degree wrong-way limit): successes,
    wrong-way ends and restarts in every run."""
    ends = compare_rollouts(n, seed, 200, object="ellipse", turn_deg=20.0,
                            max_backward_deg=10.0)
    assert ends["success"] > 0 and ends["other_end"] > 0


def test_same_transitions_at_the_registered_time_limit():
    """Default config: masked random play rarely finishes, so the 500-step limit truncates."""
    ends = compare_rollouts(2, 7, 1100)
    assert ends["truncated"] >= 2


CONFIG_CASES = [
    {"object": "pentagon", "mu": 0.5, "turn_deg": -60.0, "max_episode_steps": 40},
    {"beta": 0.2, "gamma": 0.0, "alpha": -1.0, "turn_scale_deg": 45.0, "success_bonus": 3.0,
     "illegal_penalty": 0.5, "map_window_cells": 9, "map_window_deg": 90.0, "turn_deg": 30.0},
    {"n": 90, "hand": "thesis", "map_window_cells": 30, "turn_deg": 40.0},
    {"map_lines": True, "turn_deg": 40.0},
    {"to_go_weight": 0.5, "turn_deg": 60.0},
    {"contact_model": "hand", "object": "pentagon", "turn_deg": 40.0},
    {"rotation_lookahead": True, "contact_model": "hand", "object": "hexagon",
     "turn_deg": 40.0},
    {"rotation_lookahead": True, "map_lines": True, "turn_deg": -30.0, "n": 90},
    {"forbid_reversal": True, "rotation_lookahead": True, "turn_deg": 60.0},
    {"forbid_reversal": True, "contact_model": "hand", "object": "hexagon",
     "to_go_weight": 1.0, "turn_deg": 40.0},
    {"forbid_revisit": True, "turn_deg": 60.0},
    {"forbid_revisit": True, "forbid_reversal": True, "contact_model": "hand",
     "object": "hexagon", "to_go_weight": 1.0, "turn_deg": 40.0},
    {"regrasp_lookahead": 3, "turn_deg": 60.0},
    {"regrasp_lookahead": 1, "contact_model": "hand", "object": "hexagon", "turn_deg": -40.0},
    {"regrasp_lookahead": 2, "forbid_revisit": True, "forbid_reversal": True,
     "rotation_lookahead": True, "map_lines": True, "n": 90, "turn_deg": 90.0},
    {"observation_mode": "dict", "dead_end_penalty": 2.0, "max_backward_deg": 20.0,
     "turn_deg": 60.0},
    {"observation_mode": "dict", "regrasp_lookahead": 1, "contact_model": "hand",
     "object": "hexagon", "turn_deg": -40.0, "forbid_reversal": True},
    {"observation_mode": "flat", "regrasp_lookahead": 2, "rotation_lookahead": True,
     "map_lines": True, "n": 90, "turn_deg": 40.0},
]


@pytest.mark.parametrize("kw", CONFIG_CASES)
def test_same_transitions_with_config_fields(kw):
    compare_rollouts(3, 11, 100, **kw)


# GraspGaitRandom-v0: each sub-env its own objects and mu (short turns: many episodes,
# so many objects)
RANDOM_CASES = [
    {"level": 0, "turn_deg": 40.0, "max_backward_deg": 10.0},
    {"level": 2, "episodes_per_object": 3, "regrasp_lookahead": 2, "map_lines": True,
     "rotation_lookahead": True, "n": 90, "turn_deg": 40.0, "max_backward_deg": 10.0},
    {"level": 1, "mu_range": (0.4, 0.8), "contact_model": "hand", "to_go_weight": 1.0,
     "forbid_revisit": True, "forbid_reversal": True, "observation_mode": "dict",
     "turn_deg": -40.0},
    {"level": 3, "bundled_fraction": 1.0, "hand": "thesis", "alpha": 2.0, "beta": 0.5,
     "gamma": 0.1, "turn_scale_deg": 30.0, "success_bonus": 2.0, "dead_end_penalty": 2.0,
     "illegal_penalty": 0.2, "map_window_deg": 60.0, "map_window_cells": 5,
     "observation_mode": "flat", "turn_deg": 30.0, "max_episode_steps": 40},
]


@pytest.mark.parametrize("kw", RANDOM_CASES)
def test_random_objects_batched_as_single_envs(kw):
    ends = compare_rollouts(3, 4, 80, RANDOM_ID, **kw)
    assert sum(ends.values()) > 0


@pytest.mark.parametrize("cases", [CONFIG_CASES, RANDOM_CASES], ids=["GraspGait", "Random"])
def test_the_config_cases_set_every_field_off_its_default(cases):
    """The equality tests above cover every config field, each away from its default in
    at least one case, for both ids (a field added to the config needs a case here)."""
    from dataclasses import fields

    from graspgait_env.envs.config import GraspGaitConfig

    default = GraspGaitConfig()
    covered = {name for kw in cases for name, value in kw.items()
               if name in GraspGaitConfig.field_names()
               and (name == "hand" or value != getattr(default, name))}
    missing = [f.name for f in fields(GraspGaitConfig) if f.name not in covered]
    assert not missing, f"no case sets {missing} off its default"


def test_random_sub_envs_draw_their_own_objects_and_take_per_env_options():
    envs = _batched(4, RANDOM_ID, level=1, turn_deg=40.0)
    _, info = envs.reset(seed=0)
    assert len(set(info["object_seed"].tolist())) == 4  # four objects, one per sub-env
    assert len(set(info["mu"].tolist())) == 4
    m = np.array([False, True, False, False])
    obs, info = envs.reset(options={"object": "pentagon", "mu": 0.6, "reset_mask": m})
    assert info["_object"].tolist() == [False, True, False, False]
    assert info["object"][1] == "pentagon" and info["mu"][1] == 0.6
    u = envs.unwrapped
    assert u.states()[1] == u._subs[1].state
    np.testing.assert_array_equal(info["action_mask"][1],
                                  u._subs[1].model.action_mask(u._subs[1].state))


def test_reset_mask_and_start_option_match_sync():
    a, b = _batched(3), _sync(3)
    start = {"start": {1: 50.0, 3: 270.0}}
    assert_same(a.reset(seed=4, options=start), b.reset(seed=4, options=start))
    rng = np.random.default_rng(0)
    info = a.reset(seed=[5, None, 6])[1]
    b.reset(seed=[5, 6, 7])
    b.reset(seed=[5, None, 6])  # sub-env 1 keeps its generator, as in the batched env
    for _ in range(5):
        act = masked_actions(info["action_mask"], rng, 0.0)
        out = a.step(act)
        b.step(act)
        info = out[4]
    m = np.array([False, True, True])
    ra = a.reset(seed=9, options={"reset_mask": m})
    rb = b.reset(seed=9, options={"reset_mask": m})
    assert_same(ra[1], rb[1])
    np.testing.assert_array_equal(ra[0][m], rb[0][m])


def test_masks_are_the_gait_models():
    env = _batched(8, object="pentagon").unwrapped
    _, info = env.reset(seed=3)
    rng = np.random.default_rng(3)
    for _ in range(40):
        masks = env.action_masks()
        np.testing.assert_array_equal(masks, info["action_mask"])
        for s, m in zip(env.states(), masks, strict=True):
            np.testing.assert_array_equal(m, env.model.action_mask(s))
        info = env.step(masked_actions(masks, rng))[4]


def test_rewards_are_their_terms_summed():
    env = _batched(6, turn_deg=20.0)
    _, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(60):
        _, r, *_, info = env.step(masked_actions(info["action_mask"], rng))
        terms = info["reward_terms"]
        total = sum(terms[k] for k in REWARD_TERMS)
        np.testing.assert_array_equal(r[terms["_turn"]], total[terms["_turn"]])


def test_default_vectorization_is_the_batched_env():
    env = gym.make_vec(ID, num_envs=2)
    assert isinstance(env.unwrapped, GraspGaitVectorEnv)
    assert env.metadata["autoreset_mode"] is gym.vector.AutoresetMode.NEXT_STEP
    assert env.observation_space.shape == (2, env.single_observation_space.shape[0])


def test_bad_inputs_name_the_argument():
    with pytest.raises(GraspGaitInputError, match="num_envs=0"):
        GraspGaitVectorEnv(0)
    with pytest.raises(GraspGaitInputError, match="mu='abc'"):
        _batched(2, mu="abc")
    with pytest.raises(GraspGaitInputError, match="bta"):
        _batched(2, bta=0.1)
    with pytest.raises(GraspGaitInputError, match="render_mode='rgb_array'"):
        GraspGaitVectorEnv(2, render_mode="rgb_array")
    env = GraspGaitVectorEnv(2)
    with pytest.raises(ResetNeededError):
        env.step(np.zeros(2, dtype=np.int64))
    env.reset(seed=0)
    with pytest.raises(GraspGaitInputError, match=r"shape \(2,\)"):
        env.step(np.zeros(3, dtype=np.int64))
    with pytest.raises(GraspGaitInputError, match="integer"):
        env.step(np.zeros(2))
    with pytest.raises(GraspGaitInputError, match="bools"):
        env.step(np.ones(2, dtype=bool))
    with pytest.raises(GraspGaitInputError, match=r"actions\[1\]=182"):
        env.step(np.array([0, 182]))
    with pytest.raises(GraspGaitInputError, match=r"actions\[0\]=-1"):
        env.step(np.array([-1, 0]))
    with pytest.raises(GraspGaitInputError, match="reset_mask"):
        env.reset(options={"reset_mask": np.zeros(2, dtype=bool)})
    with pytest.raises(GraspGaitInputError, match="seed="):
        env.reset(seed=[1, 2, 3])
    with pytest.raises(GraspGaitInputError, match="options\\['strat'\\]"):
        env.reset(options={"strat": {}})


def test_an_unimplemented_config_field_is_refused_by_name(monkeypatch):
    """A field added to GraspGaitConfig after the batched env: accepted at its default,
    refused (named) away from it. Simulated by withdrawing ``beta`` from the list."""
    monkeypatch.setattr(vector_env, "SUPPORTED_FIELDS", vector_env.SUPPORTED_FIELDS - {"beta"})
    GraspGaitVectorEnv(2, beta=0.01)
    with pytest.raises(GraspGaitInputError, match=r"beta=0\.05: the batched GraspGait env"):
        GraspGaitVectorEnv(2, beta=0.05)


# A valid value off the default for each config field the batched step does not
# implement; a new such field without an entry here fails the test below.
OFF_DEFAULT: dict[str, object] = {}


def test_new_config_fields_are_listed_or_refused():
    """Every config field is either implemented or refused away from its default, with a
    message that names it; and evaluation plays such settings one by one instead."""
    from dataclasses import fields

    from graspgait_env.envs.config import GraspGaitConfig

    unsupported = [f.name for f in fields(GraspGaitConfig)
                   if f.name not in vector_env.SUPPORTED_FIELDS]
    assert sorted(unsupported) == sorted(OFF_DEFAULT), (
        "give each config field outside SUPPORTED_FIELDS a valid off-default value in "
        "OFF_DEFAULT")
    checked = 0
    for name in unsupported:
        value = OFF_DEFAULT[name]
        GraspGaitConfig(**{name: value})  # a valid value: the refusal below is the batch's
        assert vector_env.unsupported_fields({name: value}) == [name]
        with pytest.raises(GraspGaitInputError, match=name):
            GraspGaitVectorEnv(1, **{name: value})
        checked += 1
    assert checked == len(unsupported)


def test_large_grids_read_the_regrasp_runs_from_the_view(monkeypatch):
    """Above RUNS_TABLE_MAX (large n) the masks gather from the strided view instead of
    the contiguous table: the same transitions."""
    monkeypatch.setattr(vector_env, "RUNS_TABLE_MAX", 0)
    env = GraspGaitVectorEnv(2)
    assert env._runs_table is None
    compare_rollouts(3, 5, 60, turn_deg=20.0)


def test_sample_legal_actions_is_uniform_over_each_rows_legal_actions():
    """Row i takes its floor(u_i L_i)-th legal action; a row without one gets A - 1."""
    rng = np.random.default_rng(5)
    for density in (0.02, 0.3, 0.9):
        masks = rng.random((64, 37)) < density
        masks[[3, 40]] = False  # dead ends
        u = rng.random(64)
        got = vector_env.sample_legal_actions(masks, u)
        for i, (m, x) in enumerate(zip(masks, u, strict=True)):
            legal = np.flatnonzero(m)
            want = legal[int(x * legal.size)] if legal.size else 36
            assert got[i] == want, (density, i)
    dead = np.zeros((4, 9), dtype=bool)
    np.testing.assert_array_equal(vector_env.sample_legal_actions(dead, rng.random(4)),
                                  [8, 8, 8, 8])


def test_start_draw_redraws_and_scans_past_starts_without_a_move():
    """The one start draw of single and batched envs: redraws, then scans from an offset."""
    from graspgait_env.envs.map_env import _START_TRIES, draw_start_index

    # only start 7 of 50 has a legal move: the redraws usually miss, the scan finds it
    rng = np.random.default_rng(0)
    seen = []
    i = draw_start_index(rng, 50, lambda j: seen.append(j) or j == 7)
    assert i == 7
    assert len(seen) > _START_TRIES or seen[-1] == 7
    assert draw_start_index(np.random.default_rng(0), 50, lambda j: False) is None
    # the draws are the generator's: same seed, same index
    a = draw_start_index(np.random.default_rng(3), 50, lambda j: j % 5 == 0)
    b = draw_start_index(np.random.default_rng(3), 50, lambda j: j % 5 == 0)
    assert a == b and a % 5 == 0


def test_autoreset_draws_the_single_envs_starts_past_dead_end_starts(monkeypatch):
    """Circle at mu 0.3: 3 of its start grasps have no legal move. With the start list cut
    to those 3 and 2 others, most draws are redrawn; restarts still match sync."""
    from graspgait_env.gait import GaitModel

    kw = {"object": "circle", "mu": 0.3, "turn_deg": 6.0, "max_backward_deg": 4.0}
    full = GaitModel.start_states
    probe = _batched(1, **kw).unwrapped
    ok = np.array(probe._start_ok, dtype=bool)
    assert (~ok).sum() == 3
    keep = [*np.flatnonzero(~ok)[:3], *np.flatnonzero(ok)[:2]]

    def few_starts(self):
        starts = full(self)
        return [starts[i] for i in keep] if len(starts) == ok.size else starts

    monkeypatch.setattr(GaitModel, "start_states", few_starts)
    a = _batched(4, **kw).unwrapped
    assert a._start_ok == [False, False, False, True, True]
    ends = compare_rollouts(4, 3, 150, **kw)
    assert sum(ends.values()) >= 8  # restarts happened
