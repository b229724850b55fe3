"""``graspgait train`` and ``graspgait evaluate``: outputs and exit codes 0 / 2."""

from __future__ import annotations

import json

from graspgait_env.cli import main


def _one_line_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("graspgait: error: ") and "Traceback" not in err
    return lines[0]


def test_train_then_evaluate(tmp_path, capsys):
    run = tmp_path / "run"
    rc = main(["train", "smoke", "--run-dir", str(run), "--quiet", "--set", "eval_freq=0",
               "--set", "checkpoint_freq=0", "--set", "total_timesteps=128"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "trained 128 steps" in out and f"wrote {run / 'model.zip'}" in out
    assert (run / "model.zip").is_file() and (run / "model.json").is_file()
    js = tmp_path / "ev" / "eval.json"
    rc = main(["evaluate", str(run / "model.zip"), "--episodes", "2", "--seed", "3",
               "--mu", "0.8", "--json", str(js), "--quiet"])
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "success:" in out and "optimum" in out and "rule-based" in out
    data = json.loads(js.read_text())
    assert data["mu"] == 0.8 and data["seed"] == 3 and len(data["episodes"]) == 2
    for key in ("success_rate", "mean_regrasps", "mean_optimal_regrasps",
                "mean_rule_regrasps"):
        assert key in data


def test_bad_input_exits_2_with_one_line(tmp_path, capsys):
    cases = [
        (["train", "nope"], "CONFIG 'nope': no such file"),
        (["train", "smoke", "--set", "n_envs=0"], "n_envs=0: must be an integer >= 1"),
        (["train", "smoke", "--set", "seeed=1"], "did you mean 'seed'?"),
        (["train", "smoke", "--resume", str(tmp_path / "x.zip"),
          "--set", f"run_root={tmp_path}"], "no such checkpoint"),
        (["evaluate", str(tmp_path / "none.zip")], "no such file"),
        (["evaluate", str(tmp_path / "none.zip"), "--mu", "-1"], "--mu"),
        (["evaluate", str(tmp_path / "none.zip"), "--episodes", "0"], "--episodes 0"),
        (["evaluate", str(tmp_path / "none.zip"), "--json", str(tmp_path / "x.txt")],
         "--json"),
    ]
    for argv, needle in cases:
        rc = main(argv)
        err = capsys.readouterr().err
        assert rc == 2, (argv, err)
        assert needle in _one_line_error(err), (argv, err)
