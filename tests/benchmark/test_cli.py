"""``graspgait benchmark``: a random policy on two tasks and two seeds, its files, the
hand-checked intervals of its suite aggregate, and resuming."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from scipy import stats

import graspgait_env.benchmark.run as run_mod
from graspgait_env.benchmark.aggregate import BOOTSTRAP_SEED
from graspgait_env.benchmark.suite import task_ids
from graspgait_env.cli import main

REPS = 300
ARGS = ["benchmark", "random", "--tasks", "map-point-circle,random-l0", "--seeds", "0-1",
        "--episodes", "3", "--reps", str(REPS), "--quiet"]


@pytest.fixture
def counted(monkeypatch):
    calls = []
    real = run_mod.run_cell

    def count(spec, task_id, seed, episodes, out_dir):
        calls.append((task_id, seed))
        return real(spec, task_id, seed, episodes, out_dir)

    monkeypatch.setattr(run_mod, "run_cell", count)
    return calls


def test_random_policy_two_tasks_two_seeds(tmp_path, capsys, counted):
    out = tmp_path / "row"
    files = {f: tmp_path / f"copy.{f}" for f in ("csv", "json", "md", "png")}
    argv = ARGS + ["--out", str(out)] + [x for f, p in files.items() for x in (f"--{f}", str(p))]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "| map-point-circle | 2 |" in text and "**suite** | 2 |" in text
    assert sorted(counted) == [("map-point-circle", 0), ("map-point-circle", 1),
                               ("random-l0", 0), ("random-l0", 1)]
    for f, p in files.items():
        assert p.stat().st_size > 0, f
        assert (out / {"csv": "cells.csv", "json": "result.json", "md": "result.md",
                       "png": "profile.png"}[f]).is_file()
    rows = list(csv.DictReader(files["csv"].open()))
    assert len(rows) == 4 and {r["policy"] for r in rows} == {"random"}
    result = json.loads(files["json"].read_text())
    assert result["seeds"] == [0, 1] and result["suite_version"] >= 1
    assert result["command"].startswith("graspgait benchmark random --tasks map-point-circle")
    first = {c["task"]: c["first_test_seed"] for c in result["cells"] if c["seed"] == 1}
    assert first == {"map-point-circle": 1_000_003, "random-l0": 1_000_003}
    # the suite's interval, by hand from the per-run scores (rliable's stratified
    # bootstrap, NumPy's global generator seeded with BOOTSTRAP_SEED)
    x = np.array([[float(next(r for r in rows if r["task"] == t and r["seed"] == str(s))
                             ["score"]) for t in ("map-point-circle", "random-l0")]
                  for s in (0, 1)])
    rng = np.random.RandomState(BOOTSTRAP_SEED)
    iqm, mean = [], []
    for _ in range(REPS):
        r = x[rng.choice(2, x.shape, replace=True), np.arange(2)[None, :]]
        iqm.append(stats.trim_mean(r, 0.25, axis=None))
        mean.append(r.mean(axis=0).mean())
    overall = result["aggregate"]["overall"]
    assert overall["iqm"] == pytest.approx(stats.trim_mean(x, 0.25, axis=None))
    assert overall["iqm_ci"] == pytest.approx(list(np.percentile(iqm, [2.5, 97.5])))
    assert overall["mean_ci"] == pytest.approx(list(np.percentile(mean, [2.5, 97.5])))
    for c in result["cells"]:  # every score is success x efficiency, in [0, 1]
        s = c["summary"]
        assert 0.0 <= s["score"] <= 1.0
        assert s["score"] == pytest.approx(s["success"] * (s["efficiency"] or 0.0))


def test_a_second_run_resumes(tmp_path, capsys, counted):
    out = tmp_path / "row"
    assert main(ARGS + ["--out", str(out)]) == 0
    first = json.loads((out / "result.json").read_text())
    counted.clear()
    assert main(ARGS + ["--out", str(out)]) == 0
    assert counted == []  # every cell reused, none recomputed
    again = json.loads((out / "result.json").read_text())
    assert again["computed"] == 0 and again["reused"] == 4
    assert _scores(again) == _scores(first)
    (out / "cells" / "random-l0" / "s1.json").unlink()  # as if interrupted there
    (out / "cells" / "map-point-circle" / "s0.json").write_text("{")  # a torn file
    assert main(ARGS + ["--out", str(out)]) == 0
    assert sorted(counted) == [("map-point-circle", 0), ("random-l0", 1)]
    assert _scores(json.loads((out / "result.json").read_text())) == _scores(first)
    capsys.readouterr()
    # the folder holds this row: another policy or budget is refused in one line
    assert main(["benchmark", "rule", "--tasks", "map-point-circle", "--seeds", "0",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds another row" in err[0]


def _scores(result):
    """The aggregate without wall times (a recomputed cell takes another time)."""
    agg = dict(result["aggregate"])
    agg["tasks"] = [{k: v for k, v in t.items() if k != "wall_s"} for t in agg["tasks"]]
    return agg


def test_list_tasks(tmp_path, capsys):
    assert main(["benchmark", "--list-tasks", "--json", str(tmp_path / "suite.json")]) == 0
    out = capsys.readouterr().out
    assert all(f"| {t} |" in out for t in task_ids())
    suite = json.loads((tmp_path / "suite.json").read_text())
    assert [t["id"] for t in suite] == task_ids()
    assert main(["benchmark", "--list-tasks", "--tasks", "mujoco"]) == 0
    assert "8 tasks" in capsys.readouterr().out


@pytest.mark.parametrize("argv, words", [
    (["benchmark"], "POLICY missing"),
    (["benchmark", "nonsense"], "not a policy"),
    (["benchmark", "rule", "--tasks", "map-point-circel"], "did you mean"),
    (["benchmark", "rule", "--seeds", "3-1"], "--seeds"),
    (["benchmark", "rule", "--episodes", "0"], "--episodes 0"),
    (["benchmark", "rule", "--seeds", "100000"], "test reset seeds"),
    (["benchmark", "rule", "--md", "x.txt"], "--md"),
    (["benchmark", "bc:expert"], "bc learns"),
    (["dataset", "record", "mujoco-pose-circle"], "record that"),
])
def test_bad_input_is_one_line(argv, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err
