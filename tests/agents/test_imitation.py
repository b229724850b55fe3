"""Imitation of the exact optimum (DAgger) and the general recipe on a tiny budget."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from graspgait_env.agents.config import TrainConfig, load_train_config
from graspgait_env.agents.imitation import Imitation, set_loss
from graspgait_env.errors import GraspGaitInputError

TINY = ["n_envs=2", "n_steps=32", "batch_size=32", "n_epochs=1", "total_timesteps=64",
        "eval_freq=0", "checkpoint_freq=0", "eval_episodes=2",
        "imitation={iterations: 2, labels: 96, epochs: 2, batch_size: 32}"]


def test_set_loss_is_minus_the_log_of_the_set_probability() -> None:
    import torch

    logp = torch.log(torch.tensor([[0.5, 0.25, 0.25, 1e-12], [0.1, 0.2, 0.3, 0.4]]))
    in_set = torch.tensor([[False, True, True, False], [True, False, False, True]])
    # by hand: -(log 0.5 + log 0.5) / 2
    assert math.isclose(float(set_loss(logp, in_set)), -math.log(0.5), rel_tol=1e-6)
    assert float(set_loss(logp, torch.tensor([[True] * 4] * 2))) == pytest.approx(0.0, abs=1e-6)
    # weighted rows (the greedy teacher's corrections): set probabilities 0.5 and 0.4,
    # weights 1 and 3 -> (-log 0.5 - 3 log 0.4) / 4
    only_last = torch.tensor([[False, True, True, False], [False, False, False, True]])
    got = float(set_loss(logp, only_last, torch.tensor([1.0, 3.0])))
    assert math.isclose(got, -(math.log(0.5) + 3 * math.log(0.4)) / 4, rel_tol=1e-6)
    assert float(set_loss(logp, only_last, torch.ones(2))) == pytest.approx(
        float(set_loss(logp, only_last)))


def test_the_block_is_checked_and_round_trips() -> None:
    with pytest.raises(GraspGaitInputError, match=r"imitation\.labls: unknown key"):
        Imitation.from_mapping({"labls": 3})
    with pytest.raises(GraspGaitInputError, match=r"imitation\.iterations=0: must be an "
                       "integer >= 1"):
        Imitation(iterations=0)
    with pytest.raises(GraspGaitInputError, match=r"imitation with algo='ppo'"):
        load_train_config("general", ["algo=ppo", "policy=MlpPolicy",
                                      "features_extractor=null"])
    with pytest.raises(GraspGaitInputError, match=r"imitation\.correction_weight=0\.5"):
        Imitation(teacher="greedy", correction_weight=0.5)
    with pytest.raises(GraspGaitInputError, match=r"correction_weight=3\.0: weighs the "
                       "greedy teacher's corrections; set teacher: greedy"):
        Imitation(teacher="optimal", correction_weight=3.0)
    assert Imitation(teacher="greedy", correction_weight=30).correction_weight == 30.0
    cfg = load_train_config("general")
    assert cfg.imitation == Imitation(iterations=10, labels=4000, epochs=8, batch_size=256,
                                     teacher="greedy")
    again = TrainConfig(**yaml.safe_load(yaml.safe_dump(cfg.to_dict())))
    assert again == cfg


def _set_mass(model, env, states: int, seed: int) -> float:
    """Mean probability the policy gives the teacher's set, over states of a teacher walk."""
    import torch

    rng = np.random.default_rng(seed)
    u = env.unwrapped
    obs, _ = env.reset(seed=seed)
    mass = []
    while len(mass) < states:
        teach, mask = u.optimal_moves(), u.action_masks()
        if teach.any():
            o, _ = model.policy.obs_to_tensor(obs)
            with torch.no_grad():
                p = model.policy.get_distribution(o, action_masks=mask).distribution.probs
            mass.append(float(p[0, torch.as_tensor(teach)].sum()))
        a = rng.choice(np.flatnonzero(teach if teach.any() else mask))
        obs, _, term, trunc, _ = env.step(int(a))
        if term or trunc:
            obs, _ = env.reset()
    return float(np.mean(mass))


def test_imitation_raises_the_policy_mass_on_the_teacher_set(tmp_path) -> None:
    """A tiny DAgger run (2 iterations of 96 labels) on GraspGait-v0: the policy's mass on
    the optimal moves of states it never trained on rises well above the fresh network's."""
    import torch

    torch.set_num_threads(1)
    from graspgait_env.agents.envs import make_env
    from graspgait_env.agents.imitation import imitate
    from graspgait_env.agents.train import build_model, make_vec_env_for

    cfg = load_train_config("general", [*TINY, "env_id=GraspGait-v0",
                                        "env_kwargs={object: pentagon, n: 90, "
                                        "observation_mode: dict, regrasp_lookahead: 3, "
                                        "forbid_revisit: true}"])
    venv = make_vec_env_for(cfg)
    model = build_model(cfg, venv)
    probe = make_env(cfg.env_id, cfg.env_kwargs)
    before = _set_mass(model, probe, 60, seed=99)
    stats = imitate(model, venv, Imitation(iterations=2, labels=160, epochs=4,
                                           batch_size=32), progress=False)
    after = _set_mass(model, probe, 60, seed=99)
    venv.close()
    assert stats["labels"] >= 320 and stats["env_steps"] >= stats["labels"]
    assert stats["losses"][-1] < stats["losses"][0] + 0.5
    assert after > before + 0.2, (before, after)


def test_the_general_recipe_trains_tiny_and_plays_an_object_file_it_never_saw(tmp_path):
    """`graspgait train general` on a tiny budget, then evaluated on a user's object file
    (a square outside the procedural family): the card records the imitation and the
    evaluation reads the file."""
    import torch

    torch.set_num_threads(1)
    from graspgait_env.agents.card import read_card
    from graspgait_env.agents.evaluate import evaluate
    from graspgait_env.agents.train import train

    res = train(load_train_config("general", [*TINY, f"run_root={tmp_path}"]), progress=False)
    card = read_card(res.model_path)
    assert card["imitation"]["labels"] >= 192 and card["imitation"]["iterations"] == 2
    assert card["wall_s"] >= card["imitation"]["wall_s"] > 0
    shape = tmp_path / "my_square.yaml"
    shape.write_text("type: polygon\nname: my_square\nvertices: [[0.04, 0.04], [-0.04, 0.04], "
                     "[-0.04, -0.04], [0.04, -0.04]]\n")
    out = evaluate(res.model_path, object=str(shape), mu=0.7, episodes=4)
    assert out["env_id"] == "GraspGait-v0" and out["object"] == "my_square"
    assert len(out["episodes"]) == 4
    assert 0.0 <= out["success_rate"] <= 1.0


def test_the_greedy_teacher_keeps_the_greedy_move_unless_it_wastes_a_regrasp() -> None:
    """Four states, 2 rotations then 3 regrasps: the greedy move (least rank among the
    legal moves) is the label where the optimum has it or it is a rotation; a greedy
    regrasp outside the optimum's set gives the set; no optimal move, no label."""
    from graspgait_env.agents.imitation import greedy_labels

    rank = np.array([[0.1, 0.5, 0.0, 0.3, 0.2],   # greedy: regrasp 2, optimal
                     [0.0, 0.5, 0.2, 0.3, 0.4],   # greedy: rotation 0, not in the set
                     [0.9, 0.5, 0.0, 0.3, 0.2],   # greedy: regrasp 2, not in the set
                     [0.0, 0.5, 0.1, 0.3, 0.2]])  # no optimal move
    masks = np.ones((4, 5), dtype=bool)
    masks[2, 2] = False  # illegal: greedy is then regrasp 4 (rank 0.2)
    optimal = np.array([[0, 0, 1, 1, 0], [0, 0, 0, 1, 0], [0, 1, 0, 1, 0], [0, 0, 0, 0, 0]],
                       dtype=bool)
    got = greedy_labels(rank, masks, optimal, rotations=2)
    np.testing.assert_array_equal(got, np.array(
        [[0, 0, 1, 0, 0], [1, 0, 0, 0, 0], [0, 1, 0, 1, 0], [0, 0, 0, 0, 0]], dtype=bool))
    with pytest.raises(GraspGaitInputError, match=r"imitation\.teacher='best'"):
        Imitation(teacher="best")


def test_total_timesteps_0_trains_the_imitation_alone(tmp_path):
    """``total_timesteps: 0`` with an imitation block: DAgger, then no PPO update; the
    model is saved with its card and final evaluation at 0 steps. Without the block 0 is
    refused with the fix."""
    import torch

    torch.set_num_threads(1)
    from graspgait_env.agents.card import read_card
    from graspgait_env.agents.train import train

    res = train(load_train_config("general", [*TINY, "total_timesteps=0",
                                              f"run_root={tmp_path}"]), progress=False)
    card = read_card(res.model_path)
    assert res.steps == 0 and card["steps"] == 0
    assert card["imitation"]["labels"] >= 192
    assert card["eval"] is not None and card["eval"]["steps"] == 0
    with pytest.raises(GraspGaitInputError, match=r"total_timesteps=0: trains nothing without "
                       r"an imitation block"):
        load_train_config("smoke", ["total_timesteps=0"])
