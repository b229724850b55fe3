"""The shared regrasp scorer: its per-regrasp block, its logits, save/load, config errors."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch

from graspgait_env.agents.card import load_agent, save_agent
from graspgait_env.agents.config import TrainConfig, load_train_config
from graspgait_env.agents.policies import (
    REGRASP_CHANNELS,
    GraspMapExtractor,
    MaskableRegraspScorerPolicy,
)
from graspgait_env.agents.train import build_model, init_from_model, make_vec_env_for
from graspgait_env.errors import GraspGaitInputError
from tests.agents.helpers import assert_same_greedy_actions, gait_extractor

_SCORER = [
    "policy=graspgait_env.agents.policies:MaskableRegraspScorerPolicy",
    "features_extractor=graspgait_env.agents.policies:PartsExtractor",
    "env_kwargs={object: ellipse, mu: 0.7, observation_mode: dict, regrasp_lookahead: 2}",
]


def _env(**kw):
    return gym.make("graspgait_env:GraspGait-v0", object="ellipse", mu=0.7, **kw)


def _parts_env():
    """The env of :data:`_SCORER`'s models."""
    return _env(observation_mode="dict", regrasp_lookahead=2)


def _batch(obs):
    return {k: torch.as_tensor(v[None]) for k, v in obs.items()}


def _scorer_model(tmp_path, *more):
    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", *_SCORER, *more])
    return cfg, build_model(cfg, make_vec_env_for(cfg))


@pytest.mark.parametrize("turn_deg", [360.0, -360.0])
def test_regrasp_block_is_what_each_regrasp_does_in_the_gait_model(turn_deg):
    env = _env(turn_deg=turn_deg)
    u = env.unwrapped
    ext, m, K, R, widths = gait_extractor(env, turn_deg, regrasp_block=True)
    n_reg = env.action_space.n - 2 * R
    assert ext.regrasp_actions == (2 * R, n_reg)
    assert ext.features_dim == ext.block_start + n_reg * REGRASP_CHANNELS
    rng = np.random.default_rng(5)
    obs, info = env.reset(seed=1)
    met = 0
    for _ in range(150):
        mask, s = info["action_mask"], u.state
        block = ext.regrasp_block(torch.as_tensor(obs[None]))[0].numpy()
        flat = ext(torch.as_tensor(obs[None]))[0, ext.block_start:].numpy()
        np.testing.assert_array_equal(flat, block.reshape(-1))
        legal = mask[2 * R:]
        np.testing.assert_array_equal(block[:, 0], legal.astype(np.float32))
        goal = np.zeros(n_reg)
        for j in np.flatnonzero(legal):
            t = m.apply(s, int(2 * R + j))
            f, g = t.held()
            pf, pg = int(m.position(f, t.contacts[f], t.k)), int(m.position(g, t.contacts[g], t.k))
            ccw, cw = m.rotation_room(f, pf, g, pg)
            goal[j], back = (ccw, cw) if K > 0 else (cw, ccw)
            new = [i for i in (f, g) if s.contacts[i] < 0][0]  # the finger just placed
            kept = g if new == f else f
            q, l = divmod(int(j), 2)
            assert int(m.position(new, t.contacts[new], t.k)) == q
            np.testing.assert_allclose(block[j, 1:6],
                                       [goal[j] / R, back / R, q / (widths[new] - 1),
                                        (pg if kept == g else pf) / (widths[kept] - 1), l],
                                       atol=1e-6, err_msg=f"regrasp {j} in {s}")
            below = q > 0 and legal[2 * (q - 1) + l]
            above = 2 * (q + 1) + l < n_reg and legal[2 * (q + 1) + l]
            assert (block[j, 6], block[j, 7]) == (float(below), float(above))
            met += 1
        best = (goal == goal.max()) & (goal.max() > 0)
        np.testing.assert_array_equal(block[:, 8], best.astype(np.float32))
        a = int(rng.choice(np.flatnonzero(mask)))
        obs, _, term, trunc, info = env.step(np.int64(a))
        if term or trunc:
            obs, info = env.reset()
    assert met >= 100  # many legal regrasps checked


def test_regrasp_block_needs_the_forward_gait_inputs():
    env = _env()
    with pytest.raises(GraspGaitInputError, match="regrasp_block=True: needs workspace_widths"):
        GraspMapExtractor(env.observation_space, regrasp_block=True)


def test_logits_are_the_linear_head_plus_one_shared_score_per_move(tmp_path):
    _, model = _scorer_model(tmp_path)
    policy = model.policy
    assert isinstance(policy, MaskableRegraspScorerPolicy)
    ext, mlp, head = policy.features_extractor, policy.mlp_extractor, policy.action_net
    first, count = ext.regrasp_actions
    assert first == 0  # on the named parts every move is scored
    obs, _ = _parts_env().reset(seed=2)
    x = _batch(obs)
    with torch.no_grad():
        for p in mlp.scorer.parameters():  # a scorer whose output differs between rows
            p.normal_(0.0, 0.5)
        features = ext(x)
        logits = head(mlp.forward_actor(features))
        latent = mlp.mlp.forward_actor(features[:, :ext.block_start])
        block = features[0, ext.block_start:].view(count, ext.block_channels)
        context = mlp.context(latent)[0]
        scores = torch.stack([mlp.scorer(torch.cat((row, context))) for row in block])[:, 0]
        linear = head.linear(latent)[0]
    np.testing.assert_allclose(logits[0].numpy(), (linear + scores).numpy(), atol=1e-5)
    assert float(scores.std()) > 1e-3  # the scores are not a constant the test would miss
    # the same scorer for every move: two moves whose block rows agree score alike
    with torch.no_grad():
        f2 = features.clone()
        rows = f2[0, ext.block_start:].view(count, ext.block_channels)
        rows[7] = rows[3]
        out = head(mlp.forward_actor(f2))[0] - head.linear(latent)[0]
    assert float(out[7]) == pytest.approx(float(out[3]), abs=1e-6)


def test_scorer_model_trains_saves_and_loads_with_identical_actions(tmp_path):
    cfg, model = _scorer_model(tmp_path)
    before = [p.detach().clone() for p in model.policy.mlp_extractor.scorer.parameters()]
    model.learn(128)
    after = list(model.policy.mlp_extractor.scorer.parameters())
    assert any(not torch.equal(a, b) for a, b in zip(after, before, strict=True))  # it learns
    path = save_agent(model, tmp_path / "m.zip", {"algo": cfg.algo, "env_id": cfg.env_id})
    loaded, card = load_agent(path)
    assert card["algo"] == "maskable_ppo"
    assert isinstance(loaded.policy, MaskableRegraspScorerPolicy)
    assert loaded.policy.scorer_arch == [32] and loaded.policy.scorer_context == 16
    for p, q in zip(model.policy.parameters(), loaded.policy.parameters(), strict=True):
        assert torch.equal(p, q)
    assert_same_greedy_actions(model, loaded, _parts_env())


def test_init_logit_scale_scales_every_logit_scores_included(tmp_path):
    cfg, model = _scorer_model(tmp_path)
    with torch.no_grad():
        for p in model.policy.mlp_extractor.scorer.parameters():
            p.normal_(0.0, 0.5)
    path = save_agent(model, tmp_path / "src.zip", {"algo": cfg.algo, "env_id": cfg.env_id})
    cfg2, fresh = _scorer_model(tmp_path, f"init_model={path}", "init_logit_scale=0.25")
    init_from_model(fresh, cfg2)
    obs, _ = _parts_env().reset(seed=4)
    x = _batch(obs)
    with torch.no_grad():
        def logits(m):
            pol = m.policy
            return pol.action_net(pol.mlp_extractor.forward_actor(pol.extract_features(x)))
        np.testing.assert_allclose(logits(fresh).numpy(), 0.25 * logits(model).numpy(),
                                   rtol=1e-5, atol=1e-6)


def test_scorer_policy_needs_maskable_ppo_and_the_extractor(tmp_path):
    with pytest.raises(GraspGaitInputError, match="needs algo: maskable_ppo"):
        TrainConfig(name="x", algo="ppo",
                    policy="graspgait_env.agents.policies:MaskableRegraspScorerPolicy")
    with pytest.raises(GraspGaitInputError, match="policy='MlpPolicy2'"):
        TrainConfig(name="x", policy="MlpPolicy2")
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", _SCORER[0]])
    with pytest.raises(GraspGaitInputError,
                       match="needs graspgait_env.agents.policies:PartsExtractor .*"
                             "observation_mode: dict"):
        build_model(cfg, make_vec_env_for(cfg))


@pytest.mark.parametrize("turn_deg", [360.0, -360.0])
def test_action_block_scores_every_action_from_the_reach_lookahead(turn_deg):
    """With ``reach_depth`` the scored block covers every action: the regrasp channels
    (0 for rotations), legal, is-a-rotation, the signed rotation steps and the env's
    reach look-ahead of that action."""
    D = 2
    env = _env(turn_deg=turn_deg, regrasp_lookahead=D, map_lines=False)
    u = env.unwrapped
    A = env.action_space.n
    ext, m, K, R, widths = gait_extractor(env, turn_deg, regrasp_block=True, reach_depth=D,
                                          tail=A * D)
    n_reg = A - 2 * R
    C = ext.block_channels
    assert C == REGRASP_CHANNELS + 3 + D and ext.regrasp_actions == (0, A)
    assert ext.features_dim == ext.block_start + A * C
    obs, info = env.reset(seed=2)
    rng = np.random.default_rng(2)
    for _ in range(20):
        x = torch.as_tensor(obs[None])
        block = ext(x)[0, ext.block_start:].numpy().reshape(A, C)
        regrasp = ext.regrasp_block(x)[0].numpy()
        np.testing.assert_array_equal(block[2 * R:, :REGRASP_CHANNELS], regrasp)
        assert not block[:2 * R, :REGRASP_CHANNELS].any()
        np.testing.assert_array_equal(block[:, REGRASP_CHANNELS], info["action_mask"])
        np.testing.assert_array_equal(block[:, REGRASP_CHANNELS + 1], np.arange(A) < 2 * R)
        steps = np.concatenate((np.arange(1, R + 1), -np.arange(1, R + 1))) / R
        np.testing.assert_allclose(block[:2 * R, REGRASP_CHANNELS + 2],
                                   steps if K > 0 else -steps, rtol=1e-6)
        field = obs[u.layout.reach]
        np.testing.assert_array_equal(block[2 * R:, -D:], field[:n_reg * D].reshape(n_reg, D))
        np.testing.assert_array_equal(block[:2 * R, -D:], field[n_reg * D:].reshape(2 * R, D))
        obs, _, term, trunc, info = env.step(int(rng.choice(np.flatnonzero(info["action_mask"]))))
        if term or trunc:
            break


def test_reach_depth_needs_the_field_and_the_block():
    env = _env(regrasp_lookahead=2)
    A = env.action_space.n
    with pytest.raises(GraspGaitInputError, match="reach_depth"):
        gait_extractor(env, 360.0, reach_depth=2, tail=A * 2)  # no regrasp block
    with pytest.raises(GraspGaitInputError, match="reach_depth"):
        gait_extractor(env, 360.0, regrasp_block=True, reach_depth=3, tail=A * 2)  # deeper


def test_reach_relative_channels_are_each_entry_less_the_best_legal_one():
    D = 2
    env = _env(regrasp_lookahead=D, map_lines=False)
    A = env.action_space.n
    ext, m, K, R, widths = gait_extractor(env, 360.0, regrasp_block=True, reach_depth=D,
                                          reach_relative=True, tail=A * D)
    C = ext.block_channels
    assert C == REGRASP_CHANNELS + 3 + 2 * D
    obs, info = env.reset(seed=4)
    block = ext(torch.as_tensor(obs[None]))[0, ext.block_start:].numpy().reshape(A, C)
    field, rel = block[:, -2 * D:-D], block[:, -D:]
    legal = info["action_mask"]
    np.testing.assert_allclose(rel[legal], field[legal] - field[legal].min(axis=0), atol=1e-6)
    assert not rel[~legal].any() and (rel[legal] == 0).any()


def test_reach_best_channels_mark_the_legal_moves_with_the_least():
    D = 2
    env = _env(regrasp_lookahead=D, map_lines=False)
    A = env.action_space.n
    ext, *_ = gait_extractor(env, 360.0, regrasp_block=True, reach_depth=D, reach_best=True,
                             tail=A * D)
    assert ext.block_channels == REGRASP_CHANNELS + 3 + 2 * D
    obs, info = env.reset(seed=4)
    block = ext(torch.as_tensor(obs[None]))[0, ext.block_start:].numpy().reshape(A, -1)
    field, best = block[:, -2 * D:-D], block[:, -D:]
    legal = info["action_mask"]
    want = legal[:, None] & np.isclose(field, field[legal].min(axis=0), atol=1e-6)
    np.testing.assert_array_equal(best, want.astype(np.float32))
    assert best.sum(axis=0).min() >= 1
