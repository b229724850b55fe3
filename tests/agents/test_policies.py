"""The grasp-map features extractor, retired for training: layout, shapes, save/load of
the models saved with it, and the refusal to train a new one."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch

from graspgait_env.agents.card import load_agent, save_agent
from graspgait_env.agents.config import load_train_config
from graspgait_env.agents.policies import GraspMapExtractor, layout_of
from graspgait_env.agents.train import build_model, make_vec_env_for
from graspgait_env.errors import GraspGaitInputError
from tests.agents.helpers import assert_same_greedy_actions, gait_extractor

_EXTRACTOR = "graspgait_env.agents.policies:GraspMapExtractor"
_PARTS = "graspgait_env.agents.policies:PartsExtractor"


def _env(**kw):
    return gym.make("graspgait_env:GraspGait-v0", object="ellipse", mu=0.7, **kw)


def test_layout_of_matches_the_env_layout():
    env = _env(map_lines=True, map_window_cells=12)
    lay = layout_of(env.observation_space, 12, env.unwrapped.model.n)
    ref = env.unwrapped.layout if hasattr(env.unwrapped, "layout") else None
    assert lay.size == env.observation_space.shape[0]
    assert lay.mask.stop - lay.mask.start == env.action_space.n
    if ref is not None:
        assert (lay.window, lay.lines) == (ref.window, ref.lines)


def test_layout_that_does_not_fit_names_the_fix():
    env = _env()
    with pytest.raises(GraspGaitInputError, match="line_cells"):
        layout_of(env.observation_space, 36, 5000)


def test_extractor_reads_each_part_where_the_env_puts_it():
    env = _env(map_lines=True, map_window_cells=12)
    n = env.unwrapped.model.n
    torch.manual_seed(0)
    ext = GraspMapExtractor(env.observation_space, cells=12, line_cells=n)
    obs, _ = env.reset(seed=0)
    x = torch.as_tensor(np.stack([obs, obs]))
    f = ext(x)
    lay = ext.layout
    assert f.shape == (2, ext.features_dim)
    assert torch.equal(f[:, : lay.window.start], x[:, : lay.window.start])  # header + mask
    # changing the window changes only the window features, the lines only theirs
    y = x.clone()
    y[:, lay.window] = 1.0 - y[:, lay.window]
    g = ext(y)
    w0, w1 = lay.window.start, lay.window.start + 64
    assert torch.equal(g[:, w1:], f[:, w1:]) and not torch.equal(g[:, w0:w1], f[:, w0:w1])
    z = x.clone()
    z[:, lay.lines] = torch.roll(z[:, lay.lines].reshape(2, 2, n), 7, dims=2).reshape(2, -1)
    h = ext(z)
    assert torch.equal(h[:, :w1], f[:, :w1])


def test_without_lines_the_extractor_has_no_line_branch():
    env = _env()
    ext = GraspMapExtractor(env.observation_space, cells=36)
    assert ext.line_net is None
    assert ext.features_dim == ext.layout.window.start + 64


def test_training_with_the_retired_extractor_is_refused_with_the_fix(tmp_path):
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", f"features_extractor={_EXTRACTOR}"])
    with pytest.raises(GraspGaitInputError, match=r"GraspMapExtractor'.*retired for training.*"
                       r"observation_mode: dict.*PartsExtractor"):
        build_model(cfg, make_vec_env_for(cfg))


def test_a_model_with_the_extractor_saves_and_loads_with_identical_actions(tmp_path):
    """Built as graspgait_env 0.2 built it (SB3's policy_kwargs), a model with the
    retired extractor still saves and loads with the same weights and actions."""
    from sb3_contrib import MaskablePPO

    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [
        f"run_root={tmp_path}", "env_kwargs.map_lines=true", "env_kwargs.map_window_cells=12"])
    model = MaskablePPO("MlpPolicy", make_vec_env_for(cfg), n_steps=64, batch_size=32,
                        policy_kwargs={"features_extractor_class": GraspMapExtractor,
                                       "features_extractor_kwargs": {"cells": 12,
                                                                     "line_cells": 180}})
    model.learn(128)
    path = save_agent(model, tmp_path / "m.zip", {"algo": cfg.algo, "env_id": cfg.env_id})
    loaded, _ = load_agent(path)
    assert isinstance(loaded.policy.features_extractor, GraspMapExtractor)
    env = _env(map_lines=True, map_window_cells=12)
    assert_same_greedy_actions(model, loaded, env)
    for p, q in zip(model.policy.parameters(), loaded.policy.parameters(), strict=True):
        assert torch.equal(p, q)


def test_finishing_rotations_are_the_legal_rotations_that_reach_the_turn():
    env = _env(map_lines=True, turn_deg=60.0)  # a short turn: finishing grasps come often
    m = env.unwrapped.model
    K, R = m.turn_steps(60.0), int(m.R)
    ext = GraspMapExtractor(env.observation_space, cells=36, line_cells=m.n, conv=False,
                            turn_steps=K, rotations=R)
    assert ext.features_dim == env.observation_space.shape[0] + R
    rng = np.random.default_rng(1)
    obs, info = env.reset(seed=0)
    seen = 0
    for _ in range(200):
        mask = info["action_mask"]
        k = env.unwrapped.state.k
        want = np.array([mask[a] and k + a + 1 >= K for a in range(R)], dtype=np.float32)
        f = ext(torch.as_tensor(obs[None]))
        assert torch.equal(f[0, : obs.size], torch.as_tensor(obs))  # conv=False: flat
        assert np.array_equal(f[0, obs.size:].numpy(), want)
        seen += int(want.any())
        # walk towards the goal: the farthest legal rotation, else a random legal move
        ccw = np.flatnonzero(mask[:R])
        a = int(ccw[-1]) if ccw.size and rng.random() < 0.7 else int(
            rng.choice(np.flatnonzero(mask)))
        obs, _, term, trunc, info = env.step(np.int64(a))
        if term or trunc:
            obs, info = env.reset()
    assert seen > 0  # the walk met grasps from which a rotation finishes


def test_finishing_rotations_need_a_fitting_rotation_count():
    env = _env()
    with pytest.raises(GraspGaitInputError, match="rotations=500"):
        GraspMapExtractor(env.observation_space, turn_steps=180, rotations=500)


def test_shortfall_code_is_the_turn_left_after_the_longest_legal_rotation():
    env = _env(turn_deg=120.0)
    m = env.unwrapped.model
    K, R, bins = m.turn_steps(120.0), int(m.R), 30
    ext = GraspMapExtractor(env.observation_space, cells=36, conv=False, turn_steps=K,
                            rotations=R, shortfall_bins=bins)
    assert ext.features_dim == env.observation_space.shape[0] + R + bins
    rng = np.random.default_rng(2)
    obs, info = env.reset(seed=0)
    levels = set()
    for _ in range(200):
        mask = info["action_mask"]
        ccw = np.flatnonzero(mask[:R])
        reach = int(ccw[-1]) + 1 if ccw.size else 0
        short = max(0, K - env.unwrapped.state.k - reach)
        want = (short > np.arange(bins) * (K / bins)).astype(np.float32)
        code = ext(torch.as_tensor(obs[None]))[0, -bins:].numpy()
        assert np.array_equal(code, want), (short, code)
        levels.add(int(code.sum()))
        a = int(ccw[-1]) if ccw.size and rng.random() < 0.5 else int(
            rng.choice(np.flatnonzero(mask)))
        obs, _, term, trunc, info = env.step(np.int64(a))
        if term or trunc:
            obs, info = env.reset()
    assert len(levels) >= 5  # the walk met many shortfalls


def test_shortfall_code_needs_the_finishing_rotations():
    env = _env()
    with pytest.raises(GraspGaitInputError, match="shortfall_bins=10: needs turn_steps"):
        GraspMapExtractor(env.observation_space, shortfall_bins=10)
    with pytest.raises(GraspGaitInputError, match="shortfall_bins=500"):
        GraspMapExtractor(env.observation_space, turn_steps=180, rotations=45,
                          shortfall_bins=500)


@pytest.mark.parametrize("turn_deg", [360.0, -360.0])
def test_forward_gait_features_are_the_longest_rotation_and_the_room_after_each_regrasp(
        turn_deg):
    env = _env(turn_deg=turn_deg)
    u = env.unwrapped
    ext, m, K, R, _ = gait_extractor(env, turn_deg, best_regrasp=True)
    plain = gait_extractor(env, turn_deg)[0]
    n_reg = env.action_space.n - 2 * R
    assert ext.features_dim == env.observation_space.shape[0] + R + R + 2 * n_reg
    rng = np.random.default_rng(3)
    obs, info = env.reset(seed=0)
    rooms = set()
    for _ in range(150):
        mask, s = info["action_mask"], u.state
        way = slice(0, R) if K > 0 else slice(R, 2 * R)
        legal = np.flatnonzero(mask[way])
        longest = np.zeros(R, dtype=np.float32)
        if legal.size:
            longest[legal[-1]] = 1.0
        room = np.zeros(n_reg, dtype=np.float32)
        for a in np.flatnonzero(mask[2 * R:]) + 2 * R:
            t = m.apply(s, int(a))
            f, g = t.held()
            ccw, cw = m.rotation_room(f, int(m.position(f, t.contacts[f], t.k)),
                                      g, int(m.position(g, t.contacts[g], t.k)))
            room[a - 2 * R] = (ccw if K > 0 else cw) / R
        feats = ext(torch.as_tensor(obs[None]))[0, -(R + 2 * n_reg):].numpy()
        np.testing.assert_array_equal(feats[:R], longest)
        np.testing.assert_allclose(feats[R:R + n_reg], room, atol=1e-6)
        best = (room == room.max()) & (room.max() > 0)
        np.testing.assert_array_equal(feats[R + n_reg:], best.astype(np.float32))
        np.testing.assert_array_equal(plain(torch.as_tensor(obs[None]))[0].numpy(),
                                      ext(torch.as_tensor(obs[None]))[0, :-n_reg].numpy())
        rooms.update(np.round(room[room > 0] * R).astype(int).tolist())
        a = int(rng.choice(np.flatnonzero(mask)))
        obs, _, term, trunc, info = env.step(np.int64(a))
        if term or trunc:
            obs, info = env.reset()
    assert len(rooms) >= 10  # many different rooms met


def test_forward_gait_features_need_the_hand_widths():
    env = _env()
    with pytest.raises(GraspGaitInputError, match="workspace_widths=\\[46, 46\\]"):
        GraspMapExtractor(env.observation_space, turn_steps=180, rotations=45,
                          workspace_widths=[46, 46])
    with pytest.raises(GraspGaitInputError, match="workspace_widths"):
        GraspMapExtractor(env.observation_space, workspace_widths=[46, 46, 46])


def test_no_bundled_config_trains_the_retired_extractor():
    from graspgait_env.resources import bundled_names

    for name in bundled_names("train"):
        cfg = load_train_config(name)
        assert cfg.features_extractor in (None, _PARTS), (name, cfg.features_extractor)
