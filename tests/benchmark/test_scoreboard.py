"""``graspgait benchmark --scoreboard``: finished rows side by side, from their own records."""

from __future__ import annotations

import json

import pytest

from graspgait_env.benchmark.scoreboard import scoreboard
from graspgait_env.cli import main
from graspgait_env.errors import GraspGaitInputError

TASKS = "map-point-circle,map-point-ellipse"


@pytest.fixture(scope="module")
def rows(tmp_path_factory):
    base = tmp_path_factory.mktemp("rows")
    out = {}
    for policy, seeds in (("random", "0-1"), ("rule", "0-1"), ("optimal", "0")):
        folder = base / policy
        assert main(["benchmark", policy, "--tasks", TASKS, "--seeds", seeds,
                     "--episodes", "2", "--reps", "200", "--quiet", "--out",
                     str(folder)]) == 0
        out[policy] = folder
    return out


def test_the_board_gives_each_rows_own_aggregates(rows, tmp_path, capsys) -> None:
    capsys.readouterr()
    md, png = tmp_path / "board.md", tmp_path / "board.png"
    assert main(["benchmark", "--scoreboard", str(rows["random"]), str(rows["rule"]),
                 "--md", str(md), "--png", str(png)]) == 0
    text = md.read_text()
    assert text.strip() in capsys.readouterr().out
    assert png.stat().st_size > 0
    lines = text.splitlines()
    for policy in ("random", "rule"):
        result = json.loads((rows[policy] / "result.json").read_text())
        overall = result["aggregate"]["overall"]
        line = next(x for x in lines if x.startswith(f"| `{policy}` |"))
        lo, hi = overall["iqm_ci"]
        assert (f"| {100 * overall['iqm']:.1f} [{100 * lo:.1f}, {100 * hi:.1f}] |"
                in line)
        assert f"`{result['command']}`" in line
        for entry in result["aggregate"]["tasks"]:
            row = next(x for x in lines if x.startswith(f"| {entry['task']} |"))
            assert f"{100 * entry['mean']:.1f}" in row.split("|")[
                2 if policy == "random" else 3]
    # the rule-based method beats a random walk on the thesis objects
    r = json.loads((rows["rule"] / "result.json").read_text())["aggregate"]["overall"]
    q = json.loads((rows["random"] / "result.json").read_text())["aggregate"]["overall"]
    assert r["iqm"] > q["iqm"]


def test_rows_of_other_seeds_or_no_row_are_refused(rows, tmp_path) -> None:
    with pytest.raises(GraspGaitInputError, match="seeds"):
        scoreboard([rows["rule"], rows["optimal"]])
    with pytest.raises(GraspGaitInputError, match="no result.json"):
        scoreboard([tmp_path / "nothing"])
    assert main(["benchmark", "rule", "--scoreboard", str(rows["rule"])]) == 2
