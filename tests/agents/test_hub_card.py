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


def _cell(task: str, seed: int, success: float, efficiency: float | None) -> dict:
    score = success * efficiency if efficiency is not None else 0.0
    return {"task": task, "seed": seed,
            "summary": {"success": success, "efficiency": efficiency, "score": score}}


def test_per_task_figures_are_mean_and_std_over_the_seeds():
    from graspgait_env.agents.hub_card import task_stats

    row = _row("config", 0.9)
    # by hand, map-hand-circle: success 1.0, 0.8 -> 90 +/- 10 %; ratio 1/0.8 = 1.25 and
    # 1/1.0 = 1 -> 1.125 +/- 0.125; score 0.8, 0.8 -> 80 +/- 0. random-l1: seed 1 has no
    # success (no ratio, score 0): ratio over seed 0 alone, score 0.5, 0 -> 25 +/- 25
    row["cells"] = [_cell("map-hand-circle", 0, 1.0, 0.8), _cell("map-hand-circle", 1, 0.8, 1.0),
                    _cell("random-l1", 0, 0.5, 1.0), _cell("random-l1", 1, 0.0, None)]
    stats = {s["task"]: s for s in task_stats(row)}
    assert stats["map-hand-circle"]["success"] == pytest.approx((0.9, 0.1))
    assert stats["map-hand-circle"]["ratio"] == pytest.approx((1.125, 0.125))
    assert stats["random-l1"]["ratio"] == pytest.approx((1.0, 0.0))
    assert stats["random-l1"]["score"] == pytest.approx((0.25, 0.25))
    text = hub_card([_run(0, 1.0, 1.0, 400.0)], benchmarks=[row])
    assert ("| map-hand-circle | `config-general` (retrained per seed) | 2 | 90.0 +/- 10.0 | "
            "1.125 +/- 0.125 | 80.0 +/- 0.0 |") in text
    assert ("| random-l1 | `config-general` (retrained per seed) | 2 | 25.0 +/- 25.0 | "
            "1.000 +/- 0.000 | 25.0 +/- 25.0 |") in text


def test_against_another_recipe_says_better_only_above_its_interval():
    from graspgait_env.agents.hub_card import compare_rows

    ours, shipped = _row("config", 0.99), _row("agent", 0.995)
    rival = _row("agent-template", 0.96)  # its IQM interval [0.95, 0.96]
    assert compare_rows(ours, rival) == ("better", pytest.approx(0.03))
    assert compare_rows(_row("config", 0.955), rival)[0] == "not measurably different"
    assert compare_rows(_row("config", 0.94), rival)[0] == "worse"
    text = hub_card([_run(0, 1.0, 1.0, 400.0)], names=["circle"],
                    benchmarks=[shipped, ours], against=[("general", rival)])
    assert "| `general` (against) | 2 | 96.0 [95.0, 96.0] |" in text
    assert ("Against `general` on the same tasks and seeds, this recipe (retrained over the "
            "seeds) is **better**: IQM 99.0 against 96.0 (+3.0 points), above the upper end "
            "of its 95% interval [95.0, 96.0].") in text
    # without a retrained row the shipped run is compared
    alone = hub_card([_run(0, 1.0, 1.0, 400.0)], benchmarks=[_row("agent", 0.955)],
                     against=[("general", rival)])
    assert ("this recipe (the shipped run) is **not measurably different**: IQM 95.5 "
            "against 96.0 (-0.5 points), within its 95% interval [95.0, 96.0]") in alone
    with pytest.raises(GraspGaitInputError, match="--against general: its seeds"):
        hub_card([_run(0, 1.0, 1.0, 400.0)], benchmarks=[ours],
                 against=[("general", _row("agent-template", 0.9, (0,)))])
    with pytest.raises(GraspGaitInputError, match="give this recipe's own rows too"):
        hub_card([_run(0, 1.0, 1.0, 400.0)], against=[("general", rival)])


def test_card_command_reads_against_rows_by_name_or_folder(tmp_path, capsys):
    import json

    for name, row in (("agent-circle", _row("agent", 0.99)), ("general-circle",
                                                              _row("agent-template", 0.5))):
        (tmp_path / name).mkdir()
        (tmp_path / name / "result.json").write_text(json.dumps(row), encoding="utf-8")
    bench = ["--benchmark", str(tmp_path / "agent-circle")]
    assert main(["card", "circle", *bench, "--against",
                 f"general={tmp_path / 'general-circle'}"]) == 0
    assert "Against `general` on the same tasks" in capsys.readouterr().out
    assert main(["card", "circle", *bench, "--against", str(tmp_path / "general-circle")]) == 0
    assert "Against `general-circle` on the same tasks" in capsys.readouterr().out
    assert main(["card", "circle", *bench, "--against", f"general={tmp_path}"]) == 2
    assert "--against" in capsys.readouterr().err


def test_evaluations_are_rows_with_the_commands_that_made_them(tmp_path, capsys):
    import json

    f = tmp_path / "eval.json"
    assert main(["evaluate", "circle", "--episodes", "2", "--seed", "5", "--set",
                 "forbid_reversal=true", "--json", str(f), "--quiet"]) == 0
    capsys.readouterr()
    res = json.loads(f.read_text(encoding="utf-8"))
    assert res["command"] == ("graspgait evaluate circle --episodes 2 --seed 5 --set "
                              "forbid_reversal=true")
    assert main(["card", "circle", "--evaluation", str(f)]) == 0
    text = capsys.readouterr().out
    ratio = f"{res['regrasps_vs_optimal']:.3f}"
    assert (f"| GraspGait-v0, circle, mu 0.7, contact hand | 2 | "
            f"{res['success_rate']:.1%} | {res['success_rate_solvable']:.1%} "
            f"({res['solvable_episodes']}) | {res['mean_regrasps']:.2f} |") in text
    assert ratio in text and res["command"] in text.split("## Measured results")[1]
    # the rule-based mean over fewer starts than the agent's says over how many
    part = dict(res, rule_success_rate_solvable=0.5, mean_rule_regrasps=19.0,
                solvable_episodes=2)
    from graspgait_env.agents.hub_card import evaluation_section

    assert "| 19.00 (1 start) |" in "\n".join(evaluation_section([part]))
    other = tmp_path / "other.json"
    other.write_text(json.dumps(dict(res, model={"path": "general"})), encoding="utf-8")
    assert main(["card", "circle", "--evaluation", str(other)]) == 2
    assert "an evaluation of 'general', not of this card's models" in capsys.readouterr().err
    del res["command"]
    other.write_text(json.dumps(res), encoding="utf-8")
    assert main(["card", "circle", "--evaluation", str(other)]) == 2
    assert "no command in it" in capsys.readouterr().err


def test_front_matter_gives_the_recipes_benchmark_tasks_over_its_seeds():
    shipped, retrained = _row("agent", 0.99), _row("config", 0.95)
    retrained["cells"] = [_cell("map-hand-circle", 0, 1.0, 0.8),
                          _cell("map-hand-circle", 1, 0.8, 1.0)]
    shipped["cells"] = [_cell("map-hand-circle", 0, 1.0, 1.0)]
    front = _front(hub_card([_run(0, 1.0, 1.0, 400.0)], benchmarks=[shipped, retrained]))
    results = front["model-index"][0]["results"]
    assert [r["dataset"]["type"] for r in results] == ["GraspGaitRandom-v0", "map-hand-circle"]
    # the retrained row's two seeds (by hand as in the per-task test), not the shipped run's
    values = {m["type"]: (m["name"], m["value"]) for m in results[1]["metrics"]}
    assert values["success"] == ("success over starts with a gait (%), 2 seeds", "90.0 +/- 10.0")
    assert values["ratio"][1] == "1.125 +/- 0.125" and values["score"][1] == "80.0 +/- 0.0"


def test_the_card_names_the_command_that_wrote_it(tmp_path, capsys):
    out = tmp_path / "card.md"
    assert main(["card", "circle", "--title", "the circle", "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert f"graspgait card circle --title 'the circle' --out {out}\n" in text
    assert "RUN_ROOT" in hub_card([_run(0, 1.0, 1.0, 400.0)])  # from Python: the plain form


def test_a_difference_that_rounds_to_zero_reads_plus_zero_points():
    """Two IQMs 0.0004 apart (e.g. 1.0 against 0.9996): ``+0.0 points``, not ``-0.0``."""
    from graspgait_env.agents.hub_card import _points

    assert _points(-0.0004) == "+0.0 points"
    assert _points(0.0) == "+0.0 points"
    assert _points(-0.001) == "-0.1 points"
    assert _points(0.026) == "+2.6 points"


def test_the_audit_paragraph_gives_the_excess_beyond_the_lookahead_when_measured():
    from graspgait_env.agents.hub_card import evaluation_section

    res = {"env_id": "GraspGait-v0", "object": "hexagon", "mu": 0.7, "contact_model": "hand",
           "n_episodes": 100, "success_rate": 0.68, "success_rate_solvable": 0.932,
           "solvable_episodes": 73, "mean_regrasps": 24.44, "mean_optimal_regrasps": 24.21,
           "regrasps_vs_optimal": 1.01, "command": "graspgait evaluate general --audit",
           "audit": {"episodes": 68, "excess_regrasps": 16, "idle_regrasps": 0,
                     "losing_regrasps": 8, "excess_of_losing_regrasps": 16,
                     "losing_rotations": 0, "excess_of_losing_rotations": 0,
                     "excess_beyond_lookahead": 12}}
    text = "\n".join(evaluation_section([res]))
    assert ("0 from 0 losing rotations; 12 of them from states farther from the goal than "
            "the look-ahead reads.") in text
    # an audit written before the split was measured says nothing of it (not "0")
    del res["audit"]["excess_beyond_lookahead"]
    text = "\n".join(evaluation_section([res]))
    assert "0 from 0 losing rotations." in text and "look-ahead reads" not in text
