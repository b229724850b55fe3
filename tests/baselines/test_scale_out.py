"""Ray as the engine: the bench, the campaign and training give the serial numbers.

One local Ray (``num_cpus=2``) is shared by the module's tests (starting one takes
seconds); the library's :func:`graspgait_env.baselines.scale_out.ray_session` finds it running and
leaves it so.
"""

from __future__ import annotations

import dataclasses
import logging

import pytest

from graspgait_env.baselines.bench import markdown_report, run_bench
from graspgait_env.baselines.scale_out import bench_on_ray, campaign, parse_seeds, run_tasks
from graspgait_env.cli import main
from graspgait_env.errors import GraspGaitInputError


@pytest.fixture(scope="module")
def local_ray():
    import ray  # the [ray] extra: `make test` installs every extra, so a missing one fails
    ray.init(num_cpus=2, include_dashboard=False, logging_level=logging.ERROR,
             log_to_driver=False, object_store_memory=100 * 1024**2)
    yield ray
    ray.shutdown()


def _no_wall(x):
    """``x`` without the wall-clock entries (dict keys naming "wall"), recursively; NaN
    as a string (NaN != NaN)."""
    if isinstance(x, float) and x != x:
        return "nan"
    if isinstance(x, dict):
        return {k: _no_wall(v) for k, v in x.items() if "wall" not in k}
    if isinstance(x, (list, tuple)):
        return [_no_wall(v) for v in x]
    return x


def _no_wall_times(text: str) -> str:
    return "\n".join(ln for ln in text.splitlines() if "wall time" not in ln)


def test_parse_seeds():
    assert parse_seeds("0-3") == [0, 1, 2, 3]
    assert parse_seeds("5,0-2,1") == [5, 0, 1, 2]
    for bad in ("9-0", "a", "-1", "1.5", ""):
        with pytest.raises(GraspGaitInputError, match="--seeds"):
            parse_seeds(bad)


def test_bench_on_ray_gives_the_serial_cases(local_ray):
    args = (["hexagon", "pentagon"], [0.7], ["rule"], 1)
    serial = run_bench(*args, progress=False)
    cases, failures = bench_on_ray(*args, progress=False)
    assert failures == []
    strip = [{k: v for k, v in dataclasses.asdict(c).items() if k != "wall_time_s"}
             for c in serial]
    assert [{k: v for k, v in dataclasses.asdict(c).items() if k != "wall_time_s"}
            for c in cases] == strip
    assert _no_wall_times(markdown_report(cases)) == _no_wall_times(markdown_report(serial))


def test_cli_bench_ray_prints_the_serial_tables(local_ray, capsys):
    argv = ["bench", "--objects", "pentagon,hexagon", "--mus", "0.7", "--planners", "rule",
            "--starts", "1", "--agents", "none"]
    assert main(argv) == 0
    serial = capsys.readouterr().out
    assert main([*argv, "--ray"]) == 0
    on_ray = capsys.readouterr().out
    assert "Table 1 regenerated" in on_ray
    assert _no_wall_times(on_ray) == _no_wall_times(serial)


def test_a_failed_task_is_reported_and_the_others_kept(local_ray):
    results, failures = run_tasks(parse_seeds, [("0-2",), ("2-1",), ("5",)],
                                  ["a", "b", "c"], progress=False)
    assert results == [[0, 1, 2], None, [5]]
    assert [(f.index, f.label) for f in failures] == [(1, "b")]
    assert "GraspGaitInputError" in failures[0].error and "2-1" in failures[0].error


@pytest.mark.slow
def test_campaign_on_ray_gives_the_serial_runs(local_ray):
    from graspgait_env.sim.simulate import default_plan

    plan = default_plan("pentagon")
    serial, f1 = campaign(plan, [0, 1], progress=False)
    on_ray, f2 = campaign(plan, [0, 1], use_ray=True, progress=False)
    assert f1 == f2 == []
    assert _no_wall(on_ray) == _no_wall(serial)


@pytest.mark.slow
def test_train_seeds_as_ray_tune_trials_give_the_serial_numbers(local_ray, tmp_path):
    from graspgait_env.agents.config import load_train_config
    from graspgait_env.agents.ray_train import train_seeds

    config = load_train_config("smoke", [f"run_root={tmp_path}"])
    serial = train_seeds(config, [0, 1], progress=False)
    trials = train_seeds(config, [0, 1], use_ray=True, progress=False)
    assert [o.error for o in trials] == [None, None]
    for a, b in zip(serial, trials, strict=True):
        assert (a.seed, a.steps) == (b.seed, b.steps)
        assert _no_wall(b.last_eval) == _no_wall(a.last_eval)


@pytest.mark.slow
def test_a_failed_tune_trial_is_reported_and_the_others_kept(local_ray, tmp_path):
    """Seed 2**64 overflows torch's seed: that trial fails, seed 0's still trains."""
    from graspgait_env.agents.config import load_train_config
    from graspgait_env.agents.ray_train import train_seeds

    config = load_train_config("smoke", [f"run_root={tmp_path}"])
    trials = train_seeds(config, [0, 2**64], use_ray=True, progress=False)
    assert [o.seed for o in trials] == [0, 2**64]
    assert trials[0].error is None and trials[0].steps == 256
    assert trials[1].error and "Overflow" in trials[1].error and trials[1].steps == 0


def test_bench_agents_on_ray_gives_the_serial_rows(local_ray):
    """One Ray task per agent, object and mu; the rows are the serial bench's."""
    from graspgait_env.agents.bench import find_agents, run_agent_bench
    from graspgait_env.agents.ray_train import bench_agents_on_ray

    agents, _ = find_agents("circle,general")
    args = (agents, ["hexagon", "circle"], [0.7], 2)
    serial = run_agent_bench(*args, progress=False)
    cases, failures = bench_agents_on_ray(*args, progress=False)
    assert failures == []
    assert len(serial) == 6  # circle on its own object, general on both; 2 starts each
    assert [_no_wall(dataclasses.asdict(c)) for c in cases] == [
        _no_wall(dataclasses.asdict(c)) for c in serial]


def test_cli_bench_ray_with_an_agent_writes_the_serial_json(local_ray, tmp_path, capsys):
    import json

    argv = ["bench", "--objects", "hexagon", "--mus", "0.7", "--planners", "rule",
            "--starts", "1", "--agents", "general"]
    assert main([*argv, "--json", str(tmp_path / "serial.json")]) == 0
    assert main([*argv, "--ray", "--json", str(tmp_path / "ray.json")]) == 0
    capsys.readouterr()
    serial, on_ray = (json.loads((tmp_path / f).read_text()) for f in ("serial.json", "ray.json"))
    assert any("agent:general" in json.dumps(c) for c in serial["runs"])
    assert _no_wall(on_ray) == _no_wall(serial)


@pytest.mark.slow
def test_evaluate_on_ray_gives_the_serial_result(local_ray, tmp_path):
    from graspgait_env.agents.config import load_train_config
    from graspgait_env.agents.evaluate import evaluate
    from graspgait_env.agents.ray_train import evaluate_on_ray
    from graspgait_env.agents.train import train

    model = train(load_train_config("smoke", [f"run_root={tmp_path}"]), progress=False)
    serial = evaluate(model.model_path, episodes=5, seed=3)
    on_ray = evaluate_on_ray(model.model_path, episodes=5, seed=3, chunks=2, progress=False)
    assert _no_wall(on_ray) == _no_wall(serial)


@pytest.mark.slow
def test_cli_train_seeds_and_the_campaign(local_ray, tmp_path, capsys):
    assert main(["train", "smoke", "--seeds", "0-1", "--set", f"run_root={tmp_path}",
                 "--quiet"]) == 0
    table = capsys.readouterr().out
    assert "| 0 | 256 |" in table and "| 1 | 256 |" in table
    plan = tmp_path / "plan.json"
    assert main(["plan", "pentagon", "--mu", "0.7", "--planner", "rule",
                 "--vertex-clearance", "4", "--json", str(plan)]) == 0
    capsys.readouterr()
    out = tmp_path / "campaign.json"
    rc = main(["simulate", str(plan), "--seeds", "0-1", "--ray", "--quiet", "--json", str(out)])
    text = capsys.readouterr().out
    assert "of 2 runs turned the object" in text and out.is_file()
    assert rc in (0, 1)


def test_campaign_refuses_a_video_or_a_fixed_perturbation(tmp_path, capsys):
    plan = tmp_path / "plan.json"
    assert main(["plan", "pentagon", "--mu", "0.7", "--planner", "rule", "--json",
                 str(plan)]) == 0
    capsys.readouterr()
    assert main(["simulate", str(plan), "--seeds", "0-1", "--perturb", "0.001,0,1"]) == 2
    assert "--perturb" in capsys.readouterr().err
    assert main(["train", "smoke", "--seeds", "3-1"]) == 2
    assert "--seeds 3-1" in capsys.readouterr().err
