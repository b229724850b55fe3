"""Hugging Face-style model cards written from the runs' own JSON cards."""

from __future__ import annotations

import copy

import pytest
import yaml

from graspgait_env.agents.hub_card import hub_card, metric_stats
from graspgait_env.cli import main
from graspgait_env.errors import GraspGaitInputError

CARD = {"algo": "maskable_ppo", "env_id": "GraspGaitRandom-v0",
        "env_kwargs": {"level": 1, "contact_model": "hand"}, "wrappers": [],
        "config": {"name": "general", "gamma": 0.99, "n_envs": 8}, "seed": 0,
        "steps": 2048, "wall_s": 500.0,
        "eval": {"n_episodes": 40, "success_rate_solvable": 1.0,
                 "regrasps_vs_optimal": 1.10, "regrasps_vs_rule": 0.9},
        "versions": {"graspgait_env": "0.2.0"}}


def _run(seed: int, success: float, ratio: float, wall: float) -> dict:
    card = copy.deepcopy(CARD)
    card["seed"], card["wall_s"] = seed, wall
    card["eval"].update(success_rate_solvable=success, regrasps_vs_optimal=ratio)
    return card


def _front(text: str) -> dict:
    assert text.startswith("---\n")
    return yaml.safe_load(text.split("---\n")[1])


def test_metrics_are_mean_and_population_std_over_runs():
    # by hand: success 90, 100 -> 95 +/- 5; ratio 1.2, 1.0 -> 1.1 +/- 0.1; wall 400, 600
    text = hub_card([_run(0, 0.9, 1.2, 400.0), _run(1, 1.0, 1.0, 600.0)],
                    names=["a/model.zip", "b/model.zip"])
    front = _front(text)
    assert front["library_name"] == "stable-baselines3"
    assert {"GraspGaitRandom-v0", "reinforcement-learning", "maskable-ppo"} <= set(front["tags"])
    result = front["model-index"][0]["results"][0]
    assert result["dataset"]["name"] == "GraspGaitRandom-v0"
    values = {m["type"]: m["value"] for m in result["metrics"]}
    assert values["success_rate_solvable"] == "95.0 +/- 5.0"
    assert values["regrasps_vs_optimal"] == "1.100 +/- 0.100"
    assert "| training wall time (s) | 500 +/- 100 | 2 |" in text
    assert "graspgait train general --seeds 0,1 --ray" in text
    assert "| `b/model.zip` | 1 | 2048 | 600 | 100.0 | 1.000 |" in text
    assert "| PPO steps | 2048 +/- 0 | 2 |" in text and "imitation" not in text


def test_imitation_labels_and_env_steps_are_reported_over_runs():
    # by hand: labels 40000, 40010 -> 40005 +/- 5; env steps 140000, 140100 -> 140050 +/- 50
    runs = [_run(0, 1.0, 1.0, 400.0), _run(1, 1.0, 1.0, 400.0)]
    for card, labels, env_steps in zip(runs, (40000, 40010), (140000, 140100), strict=True):
        card["steps"] = 0
        card["imitation"] = {"iterations": 10, "labels": labels, "env_steps": env_steps}
    text = hub_card(runs, names=["a/model.zip", "b/model.zip"])
    assert "| PPO steps | 0 +/- 0 | 2 |" in text
    assert "| imitation labels | 40005 +/- 5 | 2 |" in text
    assert "| imitation env steps | 140050 +/- 50 | 2 |" in text
    assert metric_stats([1.0, 2.0, 3.0, 4.0]) == pytest.approx((2.5, 1.118033988749895))


def test_runs_of_different_recipes_are_refused_by_field():
    other = _run(1, 1.0, 1.0, 1.0)
    other["env_kwargs"] = {"level": 2, "contact_model": "hand"}
    with pytest.raises(GraspGaitInputError, match="MODEL run 2: its env_kwargs"):
        hub_card([_run(0, 1.0, 1.0, 1.0), other])
    bare = _run(1, 1.0, 1.0, 1.0)
    del bare["eval"]
    with pytest.raises(GraspGaitInputError, match="no final evaluation"):
        hub_card([bare])
    with pytest.raises(GraspGaitInputError, match="at least one model"):
        hub_card([])


def test_card_command_writes_a_shipped_agents_card(tmp_path, capsys):
    out = tmp_path / "README.md"
    assert main(["card", "circle", "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    front = _front(text)
    assert front["model-index"][0]["results"][0]["dataset"]["name"] == "GraspGait-v0"
    assert '"object": "circle"' in text and "graspgait evaluate circle" in text
    assert main(["card", "circle", "nope_model.zip"]) == 2
    assert "nope_model.zip" in capsys.readouterr().err


def _row(kind: str, iqm: float, seeds=(0, 1)) -> dict:
    block = {"iqm": iqm, "iqm_ci": [iqm - 0.01, iqm], "mean": iqm, "mean_ci": [iqm, iqm],
             "tasks": 2}
    return {"policy": f"{kind}-general", "spec": {"kind": kind}, "suite_version": 1,
            "tasks": ["map-hand-circle", "random-l1"], "seeds": list(seeds),
            "command": f"graspgait benchmark {kind}", "date": "2026-12-06",
            "run_wall_s": 120.0,
            "aggregate": {"overall": block, "tracks": {"map-hand": {**block, "tasks": 1}}}}


def test_benchmark_rows_say_when_the_retrained_recipe_is_worse():
    text = hub_card([_run(0, 1.0, 1.0, 400.0)], names=["general"],
                    benchmarks=[_row("agent", 0.998), _row("agent-template", 0.997)])
    assert "## Benchmark (suite v1, seeds 0,1)" in text
    assert ("| `agent-general` (the shipped run) | 2 | 99.8 [98.8, 99.8] | 99.8 [99.8, 99.8] | "
            "99.8 [98.8, 99.8] |") in text
    assert ("the recipe is **worse** than its shipped run: IQM 99.7 against 99.8 "
            "(-0.1 points)") in text
    even = hub_card([_run(0, 1.0, 1.0, 400.0)],
                    benchmarks=[_row("agent", 0.99), _row("config", 0.99)])
    assert "as good as its shipped run or better: IQM 99.0 against 99.0" in even
    assert "**worse**" not in even
    with pytest.raises(GraspGaitInputError, match="--benchmark b: its seeds"):
        hub_card([_run(0, 1.0, 1.0, 400.0)],
                 benchmarks=[_row("agent", 0.9), _row("config", 0.9, (0,))],
                 benchmark_names=["a", "b"])


def test_card_command_refuses_a_benchmark_folder_without_a_result(tmp_path, capsys):
    assert main(["card", "circle", "--benchmark", str(tmp_path)]) == 2
    assert "no result.json there" in capsys.readouterr().err
