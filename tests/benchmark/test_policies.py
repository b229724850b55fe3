"""POLICY resolved per task and seed: planners, the greedy reach reading, a shipped agent,
a training config (trained once per task and seed, within the budget)."""

from __future__ import annotations

import pytest

from graspgait_env.benchmark.policies import parse_policy, policy_env_kwargs
from graspgait_env.benchmark.run import run_benchmark
from graspgait_env.benchmark.suite import get_task, parse_tasks
from graspgait_env.errors import GraspGaitInputError


@pytest.fixture(autouse=True)
def one_thread():
    import torch

    torch.set_num_threads(1)


def test_policy_names_resolve():
    assert parse_policy("random").kind == "random"
    assert parse_policy("rule").kind == "planner" and parse_policy("optimal").arg == "optimal"
    assert parse_policy("greedy-reach").kind == "greedy-reach"
    assert parse_policy("greedy-reach:3") == parse_policy("greedy-reach")
    assert parse_policy("greedy-reach:5").label == "greedy-reach-5"
    for bad in ("greedy-reach:0", "greedy-reach:11", "greedy-reach:x"):
        with pytest.raises(GraspGaitInputError, match="depth D of greedy-reach:D is 1 to 10"):
            parse_policy(bad)
    assert parse_policy("agent:general").kind == "agent"
    # `random` is the masked random policy; the retired shipped agent of that name says so
    with pytest.raises(GraspGaitInputError, match=r"'random' was retired after .*use general "
                       r"instead"):
        parse_policy("agent:random")
    circle = parse_policy("circle")
    assert circle.kind == "agent" and circle.arg.endswith("circle.zip")
    for retired in ("ellipse", "agent:pentagon", "hexagon"):  # retired agents: the error says so
        with pytest.raises(GraspGaitInputError, match=r"was retired after .*use general"):
            parse_policy(retired)
    assert parse_policy("config:smoke").label == "config-smoke"
    assert parse_policy("bc").arg == "optimal" and parse_policy("bc:rule").label == "bc-rule"
    with pytest.raises(GraspGaitInputError, match="did you mean"):
        parse_policy("agent:circel")
    with pytest.raises(GraspGaitInputError, match="not a bundled training config"):
        parse_policy("config:nope")


def test_a_task_keeps_its_problem_keys():
    kw = policy_env_kwargs(get_task("map-hand-ellipse"),
                           {"object": "circle", "mu": 0.5, "contact_model": "point",
                            "map_lines": True})
    assert kw == {"map_lines": True, "object": "ellipse", "mu": 0.7, "contact_model": "hand"}
    # a GraspGaitRandom-v0 agent's keywords on one object: its random-only ones dropped
    kw = policy_env_kwargs(get_task("map-point-circle"),
                           {"level": 1, "episodes_per_object": 8, "forbid_revisit": True})
    assert kw == {"forbid_revisit": True, "object": "circle", "mu": 0.7,
                  "contact_model": "point"}
    kw = policy_env_kwargs(get_task("random-l2"), {"episodes_per_object": 8, "level": 1})
    assert kw["level"] == 2 and kw["episodes_per_object"] == 8


def test_optimal_planner_scores_one_and_greedy_reach_nearly(tmp_path):
    tasks = parse_tasks("map-point-pentagon,random-l1")
    opt = run_benchmark("optimal", tasks, [0], out_dir=tmp_path / "opt", episodes=2,
                        progress=False, reps=100)
    for c in opt["cells"]:
        assert c["summary"]["success"] == 1.0 and c["summary"]["efficiency"] == 1.0
    greedy = run_benchmark("greedy-reach", tasks, [0], out_dir=tmp_path / "gr", episodes=2,
                           progress=False, reps=100)
    for c in greedy["cells"]:
        assert c["env_kwargs"]["regrasp_lookahead"] == 3 and c["env_kwargs"]["forbid_revisit"]
        assert c["summary"]["success"] == 1.0 and c["summary"]["efficiency"] > 0.7
    deep = run_benchmark("greedy-reach:5", tasks[:1], [0], out_dir=tmp_path / "g5",
                         episodes=2, progress=False, reps=100)
    cell = deep["cells"][0]
    assert cell["env_kwargs"]["regrasp_lookahead"] == 5 and cell["policy_info"]["depth"] == 5
    assert cell["summary"]["success"] == 1.0


def test_a_shipped_agent_on_its_task(tmp_path):
    row = run_benchmark("agent:circle", parse_tasks("map-hand-circle"), [0],
                        out_dir=tmp_path / "a", episodes=2, progress=False, reps=100)
    cell = row["cells"][0]
    assert cell["policy_info"]["model"].endswith("circle.zip")
    assert cell["env_kwargs"]["rotation_lookahead"] is True  # the agent's observation
    assert cell["env_kwargs"]["contact_model"] == "hand"  # the task's
    assert cell["summary"]["success"] == 1.0


def test_an_agent_on_the_named_parts_is_scored(tmp_path):
    """The shipped general reads a Dict observation (observation_mode: dict): its cells
    run, and the task's env keeps the agent's parts."""
    row = run_benchmark("agent:general", parse_tasks("map-hand-ellipse"), [0],
                        out_dir=tmp_path / "e", episodes=2, progress=False, reps=100)
    assert not row["failures"], row["failures"]
    cell = row["cells"][0]
    assert cell["env_kwargs"]["observation_mode"] == "dict"
    assert cell["summary"]["solvable"] == cell["summary"]["successes"] >= 1


def test_a_config_trains_once_per_training_task_and_seed(tmp_path):
    out = tmp_path / "cfg"
    row = run_benchmark("config:smoke", parse_tasks("map-hand-circle,mujoco-friction-circle"),
                        [0], out_dir=out, episodes=1, progress=False, reps=100)
    assert not row["failures"]
    models = {c["policy_info"]["model"] for c in row["cells"]}
    assert models == {str(out / "train" / "map-hand-circle" / "s0" / "model.zip")}
    assert row["cells"][0]["policy_info"]["steps"] == 256


def test_a_config_over_the_budget_is_refused(tmp_path):
    cfg = tmp_path / "big.yaml"
    cfg.write_text("env_id: GraspGait-v0\ntotal_timesteps: 600000\n")
    with pytest.raises(GraspGaitInputError, match="exceeds task map-point-circle's budget"):
        run_benchmark(str(cfg), parse_tasks("map-point-circle"), [0], out_dir=tmp_path / "o",
                      episodes=1, progress=False, reps=100)


@pytest.mark.slow
def test_ray_gives_the_serial_scores(tmp_path):
    tasks = parse_tasks("map-point-circle,random-l0")
    serial = run_benchmark("rule", tasks, [0, 1], out_dir=tmp_path / "s", episodes=2,
                           progress=False, reps=100)
    ray = run_benchmark("rule", tasks, [0, 1], out_dir=tmp_path / "r", episodes=2,
                        progress=False, reps=100, ray="local")
    assert not ray["failures"]
    assert [c["summary"] for c in ray["cells"]] == [c["summary"] for c in serial["cells"]]


def test_a_model_path_template_names_one_model_per_task_and_seed(tmp_path):
    import shutil

    from graspgait_env.agents.card import shipped_models_dir

    for seed in (0, 1):
        d = tmp_path / "models" / "map-hand-circle" / f"s{seed}"
        d.mkdir(parents=True)
        for suffix in (".zip", ".json"):
            shutil.copyfile(shipped_models_dir() / f"circle{suffix}", d / f"model{suffix}")
    template = str(tmp_path / "models" / "{task}" / "s{seed}" / "model.zip")
    assert parse_policy(template).kind == "agent-template"
    row = run_benchmark(template, parse_tasks("map-hand-circle"), [0, 1],
                        out_dir=tmp_path / "row", episodes=1, progress=False, reps=100)
    assert [c["policy_info"]["model"] for c in row["cells"]] == [
        str(tmp_path / "models" / "map-hand-circle" / f"s{s}" / "model.zip") for s in (0, 1)]
    hand = run_benchmark(template.replace("{task}", "{train_task}"),
                         parse_tasks("mujoco-pose-circle"), [1], out_dir=tmp_path / "hand",
                         episodes=1, progress=False, reps=100)  # the model of its twin
    assert hand["cells"][0]["policy_info"]["model"].endswith("map-hand-circle/s1/model.zip")
    with pytest.raises(GraspGaitInputError, match="only {task}, {train_task} and {seed}"):
        parse_policy("logs/{task}/{run}/model.zip")


def test_rlzoo_trains_with_rl_zoo_once_per_training_task_and_seed(tmp_path):
    """``rlzoo:ppo:STEPS``: ``python -m rl_zoo3.train`` with the bundled hyper-parameters
    and the training task's keywords; the hand task reuses its map-level twin's model,
    played with RL Zoo's saved action wrapper and without its start wrapper."""
    spec = parse_policy("rlzoo:ppo:2048")
    assert spec.kind == "rlzoo" and spec.label == "rlzoo-ppo-2048"
    tasks = parse_tasks("map-hand-pentagon,mujoco-pose-pentagon")
    result = run_benchmark(spec, tasks, [0], out_dir=tmp_path / "row", episodes=1,
                           progress=False, reps=100)
    assert not result["failures"]
    models = sorted((tmp_path / "row" / "train").glob("*/s*/ppo/GraspGait-v0_*/*.zip"))
    assert [m.relative_to(tmp_path / "row" / "train").parts[:2] for m in models] == [
        ("map-hand-pentagon", "s0")]
    log = (models[0].parents[2] / "rlzoo.log").read_text()
    assert "object:'pentagon'" in log and "contact_model:'hand'" in log and "-n 2048" in log
    for cell in result["cells"]:
        assert cell["wrappers"] == ["graspgait_env.agents.wrappers.LegalActionWrapper"]
        assert cell["policy_info"]["model"] == str(models[0])


def test_rlzoo_refuses_what_it_cannot_train(tmp_path):
    with pytest.raises(GraspGaitInputError, match="no bundled RL Zoo hyper-parameters"):
        parse_policy("rlzoo:dqn")
    with pytest.raises(GraspGaitInputError, match="STEPS"):
        parse_policy("rlzoo:ppo:many")
    with pytest.raises(GraspGaitInputError, match="GraspGait-v0 only"):
        run_benchmark("rlzoo:ppo", parse_tasks("random-l0"), [0], out_dir=tmp_path / "r",
                      episodes=1, progress=False)
    with pytest.raises(GraspGaitInputError, match="budget"):
        run_benchmark("rlzoo:ppo:600000", parse_tasks("map-point-circle"), [0],
                      out_dir=tmp_path / "b", episodes=1, progress=False)
