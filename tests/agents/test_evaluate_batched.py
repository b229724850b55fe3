"""Batched evaluation: the same records as one episode after another, faster."""

from __future__ import annotations

import pytest

from graspgait_env.agents.card import load_agent
from graspgait_env.agents.envs import make_env
from graspgait_env.agents.evaluate import (
    ReferenceGaits,
    agent_batch_predictor,
    agent_predictor,
    batched_eval_env,
    evaluate,
    run_episodes,
    run_episodes_batched,
)
from tests.agents.helpers import kwargs_on_task


def _strip(records):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in records]


@pytest.mark.parametrize("name", ["circle", "general"])
def test_batched_records_equal_the_serial_ones_for_a_shipped_agent(name):
    """Starts, success, regrasps, moves and references: episode for episode, across waves
    (7 episodes in waves of 3) and for ``general``'s look-ahead observation (on the
    hexagon with the hand's contact model, the benchmark's ``map-hand-hexagon``)."""
    from graspgait_env.agents.bench import shipped_models_dir

    path = shipped_models_dir() / f"{name}.zip"
    assert path.is_file(), f"the shipped model {path} is missing from this install"
    model, card = load_agent(path)
    kwargs = card["env_kwargs"]
    if name == "general":  # trained on GraspGaitRandom-v0: its keywords on one object
        kwargs = kwargs_on_task(card, "map-hand-hexagon")
        assert kwargs["regrasp_lookahead"] == 8 and kwargs["object"] == "hexagon"
    refs = ReferenceGaits()
    serial = run_episodes(agent_predictor(model), make_env("GraspGait-v0", kwargs), 7, 321,
                          refs)
    venv = batched_eval_env("GraspGait-v0", kwargs, (), 3)
    batched = run_episodes_batched(agent_batch_predictor(model), venv, 7, 321, refs)
    assert _strip(batched) == _strip(serial)
    assert any(r["success"] for r in serial)  # the agent does play its gait here


def test_batched_counts_illegal_actions_as_the_serial_loop():
    """A plain PPO policy (no masks), untrained: illegal no-ops and the 500-step limit."""
    import torch
    from stable_baselines3 import PPO

    torch.set_num_threads(1)
    env = make_env("GraspGait-v0", {"object": "circle", "map_window_cells": 4})
    model = PPO("MlpPolicy", env, seed=3, device="cpu")
    serial = run_episodes(agent_predictor(model), env, 3, 0)
    venv = batched_eval_env("GraspGait-v0", {"object": "circle", "map_window_cells": 4}, (), 2)
    batched = run_episodes_batched(agent_batch_predictor(model), venv, 3, 0)
    assert _strip(batched) == _strip(serial)
    assert sum(r["illegal_actions"] for r in serial) > 0
    for r in batched:
        assert r["path_length"] == r["steps"] - r["illegal_actions"]


def test_batched_env_only_where_it_reproduces_the_env():
    assert batched_eval_env("GraspGaitMujoco-v1", {"object": "circle"}) is None
    assert batched_eval_env("GraspGaitRandom-v0", {}) is None
    assert batched_eval_env("GraspGait-v0", {"object": "circle"},
                            ("graspgait_env.agents.wrappers:LegalActionWrapper",)) is None
    # every config field is batched now, the reach look-ahead included
    venv = batched_eval_env("GraspGait-v0", {"object": "circle", "regrasp_lookahead": 2}, (), 5)
    assert venv.num_envs == 5


def test_a_field_the_batched_env_lacks_is_played_one_by_one(monkeypatch):
    """Should a config field be missing from the batched step, evaluation does not refuse
    it: it plays single envs (simulated by withdrawing a field from the batched list)."""
    from graspgait_env.envs import vector_env

    monkeypatch.setattr(vector_env, "SUPPORTED_FIELDS",
                        vector_env.SUPPORTED_FIELDS - {"regrasp_lookahead"})
    assert batched_eval_env("GraspGait-v0", {"object": "circle", "regrasp_lookahead": 2}) is None
    assert batched_eval_env("GraspGait-v0", {"object": "circle", "regrasp_lookahead": 0},
                            (), 2) is not None  # at its default it changes nothing


def test_evaluate_sampled_actions_stay_one_by_one(smoke_run):
    """Sampled actions draw torch's random numbers episode after episode: same seed,
    same records (the batched path is for greedy actions only)."""
    a = evaluate(smoke_run.model_path, episodes=3, seed=2, deterministic=False)
    b = evaluate(smoke_run.model_path, episodes=3, seed=2, deterministic=False)
    assert _strip(a["episodes"]) == _strip(b["episodes"])


def test_one_by_one_gives_the_batched_records_for_an_object_file(tmp_path):
    """`graspgait evaluate general --object FILE --one-by-one`: the single-env path, the
    same records as the default batched one on a file the agent never saw."""
    from graspgait_env.cli import main

    shape = tmp_path / "kite.yaml"
    shape.write_text("type: polygon\nname: kite\nvertices: [[0.06, 0.0], [0.0, 0.04], "
                     "[-0.05, 0.0], [0.0, -0.04]]\n")
    fast = evaluate("general", object=str(shape), episodes=6)
    slow = evaluate("general", object=str(shape), episodes=6, batched=False)
    assert _strip(fast["episodes"]) == _strip(slow["episodes"])
    out = tmp_path / "eval.json"
    assert main(["evaluate", "general", "--object", str(shape), "--episodes", "2",
                 "--one-by-one", "--quiet", "--json", str(out)]) == 0
    assert out.is_file()
