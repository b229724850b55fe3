"""The ``graspgait`` command line: outputs, exit codes, one-line errors (docs/cli.md)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from graspgait_env import NoGaitError, cli, grasp_map, load_object
from graspgait_env.cli import main

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
SCRIPT = Path(sys.executable).parent / "graspgait"


def _one_line_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("graspgait: error: ")
    assert "Traceback" not in err
    return lines[0]


def test_map_writes_png_and_npy(tmp_path, capsys):
    png, npy = tmp_path / "out" / "m.png", tmp_path / "out" / "m.npy"
    rc = main(["map", "pentagon", "--mu", "0.7", "--n", "60", "--theta", "30",
               "--png", str(png), "--npy", str(npy)])
    out = capsys.readouterr().out
    assert rc == 0
    assert load_object("pentagon").describe() in out
    assert "w = 30 deg" in out
    expected = grasp_map(load_object("pentagon"), 0.7, 60).stable
    assert f"{int(expected.sum())} of 3600 cells stable" in out
    assert png.read_bytes()[:8] == PNG_MAGIC
    got = np.load(npy)
    assert got.dtype == bool
    np.testing.assert_array_equal(got, expected)
    assert sorted(p.name for p in png.parent.iterdir()) == ["m.npy", "m.png"]


def test_map_yaml_path_and_reach_hand(tmp_path, capsys):
    obj = tmp_path / "egg.yaml"
    obj.write_text("name: egg\ntype: ellipse\na: 0.09\nb: 0.06\n")
    rc = main(["map", str(obj), "--mu", "0.5", "--n", "36", "--hand", "circular_reach"])
    assert rc == 0
    assert "egg: Ellipse" in capsys.readouterr().out


def test_malformed_yaml_names_the_field(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\ntype: polygon\nvertices: [[0.1, 0.0], [0.0, 0.1], 3]\n")
    assert main(["map", str(bad), "--mu", "0.7"]) == 2
    line = _one_line_error(capsys.readouterr().err)
    assert "vertices[2]" in line and "fix" in line


def test_unreadable_yaml(tmp_path, capsys):
    bad = tmp_path / "broken.yaml"
    bad.write_text("name: [unclosed\n")
    assert main(["map", str(bad), "--mu", "0.7"]) == 2
    assert "YAML" in _one_line_error(capsys.readouterr().err)


def test_unknown_object_name(capsys):
    assert main(["map", "dodecahedron", "--mu", "0.7"]) == 2
    line = _one_line_error(capsys.readouterr().err)
    assert "dodecahedron" in line and "ellipse" in line  # names the choices


@pytest.mark.parametrize("args, flag", [
    (["--mu", "-1"], "--mu"),
    (["--mu", "0"], "--mu"),
    (["--mu", "nan"], "--mu"),
    (["--mu", "0.7", "--n", "2"], "--n"),
    (["--mu", "0.7", "--theta", "inf"], "--theta"),
])
def test_bad_numbers_exit_2(args, flag, capsys):
    assert main(["map", "ellipse", *args]) == 2
    assert flag in _one_line_error(capsys.readouterr().err)


def test_bad_hand(capsys):
    assert main(["map", "ellipse", "--mu", "0.7", "--hand", "octopus"]) == 2
    assert "octopus" in _one_line_error(capsys.readouterr().err)


def test_unwritable_output_exit_2(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["map", "circle", "--mu", "0.3", "--n", "36",
                 "--npy", str(blocker / "m.npy")]) == 2
    assert "--npy" in _one_line_error(capsys.readouterr().err)


def test_usage_errors_exit_2(capsys):
    assert main(["map", "ellipse"]) == 2  # --mu is required
    assert main(["sweep", "roundness"]) == 2
    assert main([]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 3  # one line per usage error, each pointing at --help
    assert all("error:" in ln and "--help" in ln for ln in lines)


def test_no_gait_exits_1(monkeypatch, capsys):
    def no_gait(args):
        raise NoGaitError("no gait exists for this object at mu=0.1")

    monkeypatch.setattr(cli, "_cmd_map", no_gait)
    assert main(["map", "ellipse", "--mu", "0.1"]) == 1
    assert "no gait exists" in _one_line_error(capsys.readouterr().err)


def test_sweep_writes_png(tmp_path, capsys):
    png = tmp_path / "s.png"
    assert main(["sweep", "smoothness", "--n", "36", "--png", str(png)]) == 0
    out = capsys.readouterr().out
    assert "S=3" in out and "mu=0.1" in out
    assert png.read_bytes()[:8] == PNG_MAGIC


def test_perf_prints_ratio_and_json(tmp_path, capsys, monkeypatch):
    """The CLI wiring, on the grasp-map rows only (the full run is the slow test below)."""
    import graspgait_env.perf as perf

    monkeypatch.setattr(perf, "BENCHMARK_MODULES", [])
    monkeypatch.setattr(perf, "BENCHMARKS", [perf.bench_grasp_map])
    js = tmp_path / "perf.json"
    assert main(["perf", "--repeat", "2", "--json", str(js)]) == 0
    out = capsys.readouterr().out
    assert "| speed-up vs loop |" in out
    assert "grasp map 180x180" in out
    assert ("PASS" in out) or ("FAIL" in out)
    doc = json.loads(js.read_text())
    names = [r["name"] for r in doc["rows"]]
    assert "speed-up vs loop" in names
    assert all(r["verdict"] in ("PASS", "FAIL", "-") for r in doc["rows"])
    assert len(names) == 3  # the grasp map, its loop, the ratio: nothing else ran


@pytest.mark.slow
def test_perf_runs_every_registered_benchmark(tmp_path, capsys):
    js = tmp_path / "perf.json"
    assert main(["perf", "--repeat", "2", "--json", str(js)]) == 0
    doc = json.loads(js.read_text())
    names = [r["name"] for r in doc["rows"]]
    assert len(names) > 3 and "speed-up vs loop" in names
    assert all(r["verdict"] in ("PASS", "FAIL", "-") for r in doc["rows"])


def test_perf_bad_repeat(capsys):
    assert main(["perf", "--repeat", "0"]) == 2
    assert "--repeat" in _one_line_error(capsys.readouterr().err)


def test_console_script(tmp_path):
    assert SCRIPT.exists(), f"the console script {SCRIPT} is not installed"
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\ntype: circle\nradius: -2\n")
    r = subprocess.run([str(SCRIPT), "map", str(bad), "--mu", "0.7"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "radius" in _one_line_error(r.stderr)
    npy = tmp_path / "c.npy"
    r = subprocess.run([str(SCRIPT), "map", "circle", "--mu", "0.3", "--n", "36",
                        "--npy", str(npy)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    np.testing.assert_array_equal(np.load(npy), grasp_map(load_object("circle"), 0.3, 36).stable)


def test_plan_of_an_object_file_names_the_file(tmp_path):
    """A plan made from an object YAML names that file, so it can be replayed anywhere."""
    from graspgait_env.objects import OBJECT_DIR
    from graspgait_env.plan import Plan, validate_plan

    obj = tmp_path / "my_ellipse.yaml"
    obj.write_text((OBJECT_DIR / "ellipse.yaml").read_text().replace("name: ellipse",
                                                                      "name: my_ellipse"))
    out = tmp_path / "plan.json"
    assert main(["plan", str(obj), "--mu", "0.7", "--planner", "rule", "--json", str(out)]) == 0
    plan = Plan.load(out)
    assert plan.object == str(obj)
    assert validate_plan(plan) is None


def test_no_gait_is_three_lines_and_verbose_tells_all(capsys):
    argv = ["plan", "ellipse", "--mu", "0.7", "--planner", "rule", "--start", "0,180"]
    assert main(argv) == 1
    short = capsys.readouterr().err.strip().splitlines()
    assert 1 <= len(short) <= 3
    assert short[0].startswith("graspgait: error: no gait turns ellipse 360 deg")
    assert main([*argv, "--verbose"]) == 1
    full = capsys.readouterr().err.strip().splitlines()
    assert len(full) > 3
    assert any(ln.startswith("grasp map:") for ln in full)
    assert any("rule-based" in ln for ln in full)  # the planner's own account


def test_bench_exit_codes(tmp_path, capsys):
    out = tmp_path / "b.json"
    argv = ["bench", "--objects", "circle", "--mus", "0.7", "--starts", "1", "--planners",
            "rule,optimal", "--agents", "none"]
    assert main([*argv, "--json", str(out)]) == 0
    assert {r["planner"] for r in json.loads(out.read_text())["runs"]} == {"rule", "optimal"}
    assert main([*argv, "--starts", "0"]) == 2


def test_simulate_exit_codes(tmp_path, capsys):
    """0 when the hand turns the object, 1 when it drops it (finger friction 0.05), 2 for
    a plan file that is not there."""
    from graspgait_env.sim.config import DEFAULT_SIM_CONFIG

    plan = tmp_path / "circle.json"
    assert main(["plan", "circle", "--mu", "0.7", "--planner", "optimal", "--turn", "60",
                 "--json", str(plan)]) == 0
    assert main(["simulate", str(plan), "--quiet"]) == 0
    slippery = tmp_path / "slippery.yaml"
    slippery.write_text(DEFAULT_SIM_CONFIG.read_text().replace("finger_mu: null ",
                                                                "finger_mu: 0.05"))
    assert main(["simulate", str(plan), "--quiet", "--config", str(slippery)]) == 1
    assert main(["simulate", str(tmp_path / "none.json")]) == 2
