"""The shared scorer on the env's named parts: ``PartsExtractor`` reads the dict
observation by name and adds nothing the env does not give."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch

from graspgait_env.agents.card import load_agent, save_agent
from graspgait_env.agents.config import load_train_config
from graspgait_env.agents.evaluate import evaluate
from graspgait_env.agents.policies import PartsExtractor
from graspgait_env.agents.train import build_model, make_vec_env_for
from graspgait_env.errors import GraspGaitInputError
from tests.agents.helpers import assert_same_greedy_actions

_PARTS = [
    "env_kwargs={object: ellipse, mu: 0.7, observation_mode: dict, rotation_lookahead: true,"
    " regrasp_lookahead: 1, map_window_cells: 3}",
    "policy=graspgait_env.agents.policies:MaskableRegraspScorerPolicy",
    "features_extractor=graspgait_env.agents.policies:PartsExtractor",
]


def _env(**kw):
    return gym.make("graspgait_env:GraspGait-v0", object="ellipse", observation_mode="dict",
                    **kw)


def test_features_are_the_parts_and_each_move_against_the_best_legal_one():
    env = _env(regrasp_lookahead=2, map_lines=True, turn_deg=-90.0)
    ext = PartsExtractor(env.observation_space)
    A, F = env.observation_space["actions"].shape
    assert ext.regrasp_actions == (0, A) and ext.block_channels == 2 * F
    rng = np.random.default_rng(2)
    obs, info = env.reset(seed=4)
    for _ in range(20):
        t = {k: torch.as_tensor(v[None]) for k, v in obs.items()}
        out = ext(t)[0].numpy()
        assert out.shape == (ext.features_dim,)
        act, legal = obs["actions"], info["action_mask"]
        lo, hi = act[legal].min(axis=0), act[legal].max(axis=0)
        head = np.concatenate([obs["grasp"], legal.astype(np.float32), obs["window"].ravel(),
                               obs["lines"].ravel(), lo, hi])
        np.testing.assert_allclose(out[:ext.block_start], head)
        block = out[ext.block_start:].reshape(A, 2 * F)
        np.testing.assert_array_equal(block[:, :F], act)
        np.testing.assert_allclose(block[:, F:], (act - lo) * legal[:, None], atol=1e-6)
        obs, _, term, trunc, info = env.step(int(rng.choice(np.flatnonzero(legal))))
        if term or trunc:
            obs, info = env.reset()


def test_extremes_mark_the_best_legal_moves_by_each_feature():
    env = _env(regrasp_lookahead=2)
    ext = PartsExtractor(env.observation_space, extremes=True)
    A, F = env.observation_space["actions"].shape
    assert ext.block_channels == 4 * F
    obs, info = env.reset(seed=2)
    t = {k: torch.as_tensor(v[None]) for k, v in obs.items()}
    block = ext(t)[0, ext.block_start:].numpy().reshape(A, 4 * F)
    act, legal = obs["actions"], info["action_mask"]
    lo, hi = act[legal].min(axis=0), act[legal].max(axis=0)
    np.testing.assert_allclose(block[:, F:2 * F], (act - lo) * legal[:, None], atol=1e-6)
    np.testing.assert_array_equal(block[:, 2 * F:3 * F], (act == lo) & legal[:, None])
    np.testing.assert_array_equal(block[:, 3 * F:], (act == hi) & legal[:, None])


def test_a_box_observation_is_refused_with_the_fix():
    box = gym.make("graspgait_env:GraspGait-v0").observation_space
    with pytest.raises(GraspGaitInputError, match="observation_mode: dict"):
        PartsExtractor(box)


def test_it_trains_saves_loads_and_evaluates_batched(tmp_path):
    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS])
    model = build_model(cfg, make_vec_env_for(cfg))
    model.learn(128)
    assert isinstance(model.policy.features_extractor, PartsExtractor)
    path = save_agent(model, tmp_path / "m.zip", {"algo": cfg.algo, "env_id": cfg.env_id,
                                                  "env_kwargs": cfg.env_kwargs})
    loaded, _ = load_agent(path)
    env = gym.make("graspgait_env:GraspGait-v0", **cfg.env_kwargs)
    assert_same_greedy_actions(model, loaded, env)
    res = evaluate(str(path), episodes=6)  # batched: the dict parts of 6 envs at a time
    assert res["n_episodes"] == len(res["episodes"]) == 6
    assert res["illegal_action_rate"] == 0.0
    assert res["env_kwargs"]["observation_mode"] == "dict"


def test_policy_kwargs_reach_the_scorer_and_are_saved(tmp_path):
    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS,
                                      "policy_kwargs={scorer_arch: [8, 8], scorer_context: 4}"])
    model = build_model(cfg, make_vec_env_for(cfg))
    assert model.policy.scorer_arch == [8, 8] and model.policy.scorer_context == 4
    widths = [m.out_features for m in model.policy.mlp_extractor.scorer
              if isinstance(m, torch.nn.Linear)]
    assert widths == [8, 8, 1]
    path = save_agent(model, tmp_path / "k.zip", {"algo": cfg.algo, "env_id": cfg.env_id,
                                                  "env_kwargs": cfg.env_kwargs})
    loaded, _ = load_agent(path)
    assert loaded.policy.scorer_arch == [8, 8]


def test_without_the_linear_head_each_logit_is_its_moves_score(tmp_path):
    """``linear_head: false``: no per-action weights over the latent; every legal move's
    logit is the shared scorer's score of its row, so two moves with the same row get the
    same logit whatever their index, and the model saves and loads so."""
    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS,
                                      "policy_kwargs={linear_head: false}"])
    model = build_model(cfg, make_vec_env_for(cfg))
    policy = model.policy
    assert policy.action_net.linear is None
    env = gym.make("graspgait_env:GraspGait-v0", **cfg.env_kwargs)
    obs, _ = env.reset(seed=2)
    x = {k: torch.as_tensor(v[None]) for k, v in obs.items()}
    ext, mlp = policy.features_extractor, policy.mlp_extractor
    with torch.no_grad():
        for p in mlp.scorer.parameters():
            p.normal_(0.0, 0.5)
        features = ext(x)
        logits = policy.action_net(mlp.forward_actor(features))[0]
        latent = mlp.mlp.forward_actor(features[:, :ext.block_start])
        context = mlp.context(latent)[0]
        block = features[0, ext.block_start:].view(-1, ext.block_channels)
        scores = torch.stack([mlp.scorer(torch.cat((row, context))) for row in block])[:, 0]
    np.testing.assert_allclose(logits.numpy(), scores.numpy(), atol=1e-5)
    assert float(scores.std()) > 1e-3
    model.learn(128)
    path = save_agent(model, tmp_path / "n.zip", {"algo": cfg.algo, "env_id": cfg.env_id,
                                                  "env_kwargs": cfg.env_kwargs})
    loaded, _ = load_agent(path)
    assert loaded.policy.linear_head is False and loaded.policy.action_net.linear is None
    assert_same_greedy_actions(model, loaded, env)
    bad = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS,
                                      "policy_kwargs={linear_head: 'no'}"])
    with pytest.raises(GraspGaitInputError, match="linear_head='no': must be true or false"):
        build_model(bad, make_vec_env_for(bad))


def test_bad_policy_kwargs_name_the_field_and_the_fix(tmp_path):
    for kw, match in (("{linear_heed: false}", r"policy_kwargs \['linear_heed'\]: not keywords "
                       r"of policy .*MaskableRegraspScorerPolicy.*'linear_head'"),
                      ("{scorer_arch: 32}", r"policy_kwargs scorer_arch=32, scorer_context=16: "
                       r"widths must be positive integers")):
        cfg = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS,
                                          f"policy_kwargs={kw}"])
        with pytest.raises(GraspGaitInputError, match=match):
            build_model(cfg, make_vec_env_for(cfg))
    plain = load_train_config("smoke", [f"run_root={tmp_path}",
                                        "policy_kwargs={linear_head: false}"])
    with pytest.raises(GraspGaitInputError, match=r"not keywords of policy 'MlpPolicy'"):
        build_model(plain, make_vec_env_for(plain))


def test_an_unknown_extractor_keyword_names_those_it_takes(tmp_path):
    # `relative` was a switch of PartsExtractor (always on in every config); it is gone
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS,
                                      "features_extractor_kwargs={relative: false}"])
    with pytest.raises(GraspGaitInputError, match=r"features_extractor_kwargs \['relative'\]: "
                       r"not keywords of features_extractor .*PartsExtractor.*'extremes'"):
        build_model(cfg, make_vec_env_for(cfg))
    ok = load_train_config("smoke", [f"run_root={tmp_path}", *_PARTS,
                                     "features_extractor_kwargs={extremes: true}"])
    assert build_model(ok, make_vec_env_for(ok)).policy.features_extractor.extremes
