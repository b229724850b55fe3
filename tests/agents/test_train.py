"""Training: a smoke run at a tiny budget, run folders, cards, checkpoints, resume, seeding."""

from __future__ import annotations

import json
import re

import gymnasium as gym
import numpy as np
import pytest
import torch

from graspgait_env.agents.card import load_agent, read_card, save_agent
from graspgait_env.agents.config import load_train_config
from graspgait_env.agents.train import build_model, init_from_model, make_vec_env_for, train
from graspgait_env.errors import GraspGaitInputError


def test_smoke_run_writes_a_complete_run_folder(smoke_run):
    run = smoke_run.run_dir
    assert re.fullmatch(r"GraspGait-v0-smoke-s0-\d{8}-\d{6}(-\d+)?", run.name)
    assert smoke_run.model_path == run / "model.zip"
    assert smoke_run.steps == 256
    for name in ("config.yaml", "model.zip", "model.json", "best.zip", "best.json",
                 "evaluations.json", "checkpoints/model_128_steps.zip",
                 "checkpoints/model_128_steps.json", "checkpoints/model_256_steps.zip"):
        assert (run / name).is_file(), name
    assert list((run / "tb").rglob("events.out.tfevents.*"))
    card = read_card(run / "model.zip")
    assert card["format"] == "graspgait-model-card/1"
    assert (card["algo"], card["env_id"], card["seed"], card["steps"]) == (
        "maskable_ppo", "GraspGait-v0", 0, 256)
    assert card["env_kwargs"] == {"object": "ellipse", "mu": 0.7}
    assert card["contact_model"] == "point"
    assert card["config"]["name"] == "smoke" and card["config"]["n_envs"] == 2
    assert 0 < card["wall_s"] < 120
    assert set(card["versions"]) >= {"torch", "stable_baselines3", "sb3_contrib"}
    evals = json.loads((run / "evaluations.json").read_text())
    assert [e["steps"] for e in evals] == [128, 256]  # every eval_freq steps, and the end
    assert smoke_run.last_eval == evals[-1]
    assert smoke_run.last_eval["n_episodes"] == 3


def _observations(n: int = 16):
    env = gym.make("graspgait_env:GraspGait-v0", object="ellipse", mu=0.7)
    out = []
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for i in range(n):
        out.append((obs, info["action_mask"]))
        legal = np.flatnonzero(info["action_mask"])
        obs, _, term, trunc, info = env.step(np.int64(rng.choice(legal)))
        if term or trunc:
            obs, info = env.reset(seed=i + 1)
    return out


def test_save_and_load_give_identical_deterministic_actions(tmp_path):
    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [f"run_root={tmp_path}"])
    model = build_model(cfg, make_vec_env_for(cfg))
    model.learn(128)
    path = save_agent(model, tmp_path / "m.zip", {"algo": cfg.algo, "env_id": cfg.env_id})
    loaded, card = load_agent(path)
    assert card["algo"] == "maskable_ppo"
    for obs, mask in _observations():
        a0, _ = model.predict(obs, deterministic=True, action_masks=mask)
        a1, _ = loaded.predict(obs, deterministic=True, action_masks=mask)
        assert int(a0) == int(a1) and mask[int(a1)]
    for p, q in zip(model.policy.parameters(), loaded.policy.parameters(), strict=True):
        assert torch.equal(p, q)


def _params(path):
    model, _ = load_agent(path)
    return [p.detach().clone() for p in model.policy.parameters()]


def test_same_seed_gives_identical_training_on_cpu(tmp_path, smoke_run):
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", "checkpoint_freq=0"])
    again = train(cfg, progress=False)
    for p, q in zip(_params(smoke_run.model_path), _params(again.model_path), strict=True):
        assert torch.equal(p, q)
    first = json.loads((smoke_run.run_dir / "evaluations.json").read_text())
    second = json.loads((again.run_dir / "evaluations.json").read_text())
    strip = lambda evals: [{k: v for k, v in e.items() if "wall" not in k} for e in evals]  # noqa: E731
    assert strip(first) == strip(second)
    other = train(load_train_config("smoke", [f"run_root={tmp_path}", "seed=1",
                                              "checkpoint_freq=0", "eval_freq=0"]),
                  progress=False)
    assert not all(torch.equal(p, q) for p, q in
                   zip(_params(smoke_run.model_path), _params(other.model_path), strict=True))


def test_resume_continues_the_run_from_a_checkpoint(tmp_path, smoke_run):
    ckpt = smoke_run.run_dir / "checkpoints" / "model_128_steps.zip"
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", "total_timesteps=384",
                                      "eval_freq=0", "checkpoint_freq=0"])
    out = tmp_path / "resumed"
    res = train(cfg, run_dir=out, resume=ckpt, progress=False)
    assert res.steps == 384
    card = read_card(res.model_path)
    assert card["steps"] == 384
    assert card["wall_s"] >= read_card(ckpt)["wall_s"]
    with pytest.raises(GraspGaitInputError, match=r"--resume .*already trained 256 steps, "
                       r"total_timesteps is 256; raise it"):
        train(load_train_config("smoke", [f"run_root={tmp_path}"]),
              resume=smoke_run.run_dir / "checkpoints" / "model_256_steps.zip", progress=False)
    with pytest.raises(GraspGaitInputError, match=r"--resume 'nope.zip': no such checkpoint"):
        train(cfg, resume="nope.zip", progress=False)


def test_plain_ppo_with_the_legal_action_wrapper_trains(tmp_path):
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", "algo=ppo", "eval_freq=0",
                                      "checkpoint_freq=0",
                                      "wrappers=[graspgait_env.agents.wrappers.LegalActionWrapper]"])
    res = train(cfg, progress=False)
    card = read_card(res.model_path)
    assert card["algo"] == "ppo"
    assert card["wrappers"] == ["graspgait_env.agents.wrappers.LegalActionWrapper"]
    assert res.last_eval["illegal_action_rate"] is not None
    model, _ = load_agent(res.model_path)
    assert type(model).__name__ == "PPO"


def test_bad_env_keywords_fail_before_training(tmp_path):
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", "env_kwargs.mu=-1"])
    with pytest.raises(GraspGaitInputError, match=r"mu=-1"):
        train(cfg, progress=False)
    assert not list(tmp_path.iterdir())  # no run folder left behind


def test_init_model_starts_from_the_saved_weights_and_states_their_training(tmp_path, smoke_run):
    src = smoke_run.model_path
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", f"init_model={src}",
                                      "eval_freq=0", "checkpoint_freq=0"])
    model = build_model(cfg, make_vec_env_for(cfg))
    fresh = [p.detach().clone() for p in model.policy.parameters()]
    init = init_from_model(model, cfg)
    assert init == {"model": str(src), "steps": 256, "wall_s": read_card(src)["wall_s"]}
    loaded = _params(src)
    assert all(torch.equal(p, q) for p, q in zip(model.policy.parameters(), loaded, strict=True))
    assert not all(torch.equal(p, q) for p, q in zip(fresh, loaded, strict=True))
    res = train(cfg, progress=False)  # trains on from the weights, step count from 0
    card = read_card(res.model_path)
    assert card["steps"] == 256 and card["init"]["steps"] == 256
    assert card["config"]["init_model"] == str(src)
    # a second stage counts the whole chain behind it
    again = load_train_config("smoke", [f"run_root={tmp_path}", f"init_model={res.model_path}",
                                        "eval_freq=0", "checkpoint_freq=0"])
    chain = init_from_model(build_model(again, make_vec_env_for(again)), again)
    assert chain["steps"] == 512
    assert chain["wall_s"] == pytest.approx(card["wall_s"] + card["init"]["wall_s"])


def test_init_model_takes_a_shipped_models_name():
    from graspgait_env.agents.card import resolve_model, shipped_models_dir

    assert resolve_model("circle") == shipped_models_dir() / "circle.zip"
    with pytest.raises(GraspGaitInputError, match=r"MODEL 'nope': no such file and no "
                       r"shipped agent of that name.*circle, general"):
        resolve_model("nope")
    cfg = load_train_config("circle", ["init_model=circle"])
    model = build_model(cfg, make_vec_env_for(cfg, n_envs=1))
    init = init_from_model(model, cfg)
    card = read_card(shipped_models_dir() / "circle.zip")
    assert init == {"model": "circle", "steps": card["steps"], "wall_s": card["wall_s"]}
    assert all(torch.equal(p, q) for p, q in zip(
        model.policy.parameters(), _params(shipped_models_dir() / "circle.zip"), strict=True))


def test_init_model_refuses_a_model_that_does_not_fit(tmp_path, smoke_run):
    src = str(smoke_run.model_path)
    for overrides, message in (
            (["init_model=nope.zip"], r"init_model: MODEL 'nope.zip': no such file"),
            (["net_arch=[8]"], r"its network does not fit .*set net_arch=\[16\]"),
            (["env_kwargs.map_lines=true"], r"its observation_space is .*env_kwargs="),
            (["algo=ppo", "wrappers=[graspgait_env.agents.wrappers.LegalActionWrapper]"],
             r"a maskable_ppo model, the config trains ppo")):
        cfg = load_train_config("smoke", [f"run_root={tmp_path / 'r'}", f"init_model={src}",
                                          *overrides])
        with pytest.raises(GraspGaitInputError, match=message):
            train(cfg, progress=False)
    assert not (tmp_path / "r").exists()  # no run folder left behind


def test_train_wrappers_wrap_the_training_envs_only(tmp_path):
    from graspgait_env.agents.wrappers import SolvableStartWrapper

    cfg = load_train_config("smoke", [f"run_root={tmp_path}", "eval_freq=0",
                                      "checkpoint_freq=0",
                                      "train_wrappers=[graspgait_env.agents.wrappers.SolvableStartWrapper]"])
    venv = make_vec_env_for(cfg)
    for env in venv.envs:
        while not isinstance(env, SolvableStartWrapper):
            assert isinstance(env, gym.Wrapper), "SolvableStartWrapper missing"
            env = env.env
    venv.close()
    res = train(cfg, progress=False)
    card = read_card(res.model_path)
    assert card["wrappers"] == []  # what evaluate runs the model in
    assert card["config"]["train_wrappers"] == [
        "graspgait_env.agents.wrappers.SolvableStartWrapper"]
    with pytest.raises(GraspGaitInputError, match=r"train_wrappers='x': must be a list"):
        load_train_config("smoke", ["train_wrappers=x"])
    with pytest.raises(GraspGaitInputError, match=r"vec_env='batched'.*train_wrappers"):
        make_vec_env_for(load_train_config("smoke", [
            "vec_env=batched",
            "train_wrappers=[graspgait_env.agents.wrappers.RuleBasedStartWrapper]"]))


def test_init_logit_scale_flattens_the_policy_and_keeps_its_greedy_actions(tmp_path, smoke_run):
    src = smoke_run.model_path
    cfg = load_train_config("smoke", [f"init_model={src}", "init_logit_scale=0.25"])
    model = build_model(cfg, make_vec_env_for(cfg))
    init_from_model(model, cfg)
    source, _ = load_agent(src)
    head = {id(p) for p in model.policy.action_net.parameters()}
    for p, q in zip(model.policy.parameters(), source.policy.parameters(), strict=True):
        assert torch.allclose(p, q * 0.25 if id(p) in head else q)
    entropy = []
    for obs, mask in _observations():
        a0, _ = source.predict(obs, deterministic=True, action_masks=mask)
        a1, _ = model.predict(obs, deterministic=True, action_masks=mask)
        assert int(a0) == int(a1)
        ob = torch.as_tensor(obs[None])
        with torch.no_grad():
            entropy.append([float(m.policy.get_distribution(ob, action_masks=mask[None])
                                  .entropy()[0]) for m in (source, model)])
    assert all(flat >= sharp - 1e-6 for sharp, flat in entropy)
    assert sum(flat for _, flat in entropy) > sum(sharp for sharp, _ in entropy)
    with pytest.raises(GraspGaitInputError, match=r"init_logit_scale=0.5: .*init_model"):
        load_train_config("smoke", ["init_logit_scale=0.5"])
