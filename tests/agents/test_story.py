"""``graspgait story`` / graspgait_env.agents.story: rule-based, optimal and learned gaits from one
start."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from graspgait_env.agents.story import GAITS, learned_gait, story_table, tell_story
from graspgait_env.cli import main
from graspgait_env.plan import Plan, validate_plan
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.registry import default_start
from graspgait_env.planners.rule_based import rule_based

GENERAL = (Path(__file__).resolve().parents[2] / "graspgait_env" / "agents" / "models"
           / "general.zip")


@pytest.fixture(scope="module")
def story(tmp_path_factory):
    import torch

    torch.set_num_threads(1)
    return tell_story(GENERAL, tmp_path_factory.mktemp("story"))  # the demo's story


def test_the_shipped_general_agent_tells_the_demo_story(story):
    """``general`` on its env's default object, the ellipse, as ``make demo`` plays it."""
    rows, files = story["rows"], story["files"]
    model, start, _, _ = learned_gait(GENERAL)  # the model card's gait model and start
    assert model.shape.name == "ellipse" and model.contact_model.name == "hand"
    assert start == default_start(model)
    assert rows["optimal"]["regrasps"] == optimal_gait(model, start, 360.0).regrasps
    assert rows["rule-based"]["regrasps"] == rule_based(model, start, 360.0).regrasps
    assert rows["learned"]["success"], story["table"]
    # no gait beats the optimum; the shipped agent is no worse than the thesis's rules here
    assert rows["optimal"]["regrasps"] <= rows["learned"]["regrasps"]
    assert rows["learned"]["regrasps"] <= rows["rule-based"]["regrasps"]
    for name in GAITS:
        plan = Plan.from_dict(json.loads(Path(files[f"{name}_plan"]).read_text()))
        validate_plan(plan)  # raises on a broken gait rule
        assert plan.regrasps == rows[name]["regrasps"]
        assert plan.steps[0]["contacts"] == story["start"]
    assert Path(files["figure"]).stat().st_size > 10_000
    assert story["table"] in Path(files["table"]).read_text()


def test_table_rows_and_ratio():
    rows = {"rule-based": {"success": True, "regrasps": 12, "rotation_deg": 360.0, "moves": 21,
                           "wall_s": 0.1},
            "optimal": {"success": True, "regrasps": 10, "rotation_deg": 360.0, "moves": 18,
                        "wall_s": 0.3},
            "learned": {"success": False, "regrasps": 40, "rotation_deg": 90.0, "moves": 500,
                        "wall_s": 0.2}}
    lines = story_table(rows).splitlines()
    assert len(lines) == 5
    assert "| rule-based | yes | 12 | 1.20 |" in lines[2]
    assert "| learned | no | - | - |" in lines[4]


def test_cli_story_writes_the_files_and_bad_start_exits_2(tmp_path, capsys):
    model, start, _, _ = learned_gait(GENERAL)
    phis = ",".join(f"{model.contact_deg(start.contacts[f]):g}" for f in start.held())
    rc = main(["story", "--start", phis, "--out", str(tmp_path)])  # MODEL: general
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "| optimal | yes |" in out
    assert (tmp_path / "ellipse_learned_plan.json").is_file()
    for argv, needle in ((["--start", "50"], "--start '50'"),
                         (["--mu", "-1"], "--mu"),
                         (["--start", "50,60"], "both contacts lie in finger 1")):
        rc = main(["story", str(GENERAL), "--out", str(tmp_path), *argv])
        err = capsys.readouterr().err.strip().splitlines()
        assert rc == 2 and len(err) == 1 and needle in err[0], (argv, err)
    rc = main(["story", str(tmp_path / "none.zip"), "--out", str(tmp_path)])
    assert rc == 2 and "no such file" in capsys.readouterr().err
    rc = main(["story", "ellipse", "--out", str(tmp_path)])  # a retired agent's name
    err = capsys.readouterr().err
    assert rc == 2 and "was retired after" in err and "story general --object ellipse" in err
