"""Help that stands alone, the bundled files by name, the version, and missing extras
named in one line."""

from __future__ import annotations

import argparse
import re
from importlib.metadata import version

import pytest

import graspgait_env
import graspgait_env.extras as extras
from graspgait_env.cli import build_parser, main
from graspgait_env.resources import KINDS, bundled_file, bundled_names

LONG = {"train", "bench", "perf", "simulate", "evaluate", "sweep", "story", "benchmark",
        "dataset"}
# a path that only a clone has: a folder of the repository followed by a file or folder
CLONE_PATH = re.compile(r"\b(configs|docs|agents|baselines|tests)/[\w.<>{}-]")


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def _help(capsys, *argv: str) -> str:
    assert main([*argv, "--help"]) == 0
    return capsys.readouterr().out


def test_every_subcommand_is_covered():
    assert set(_subparsers()) == {"map", "sweep", "plan", "bench", "simulate", "perf", "train",
                                  "evaluate", "story", "card", "config", "benchmark", "dataset"}


@pytest.mark.parametrize("command", sorted(_subparsers()))
def test_help_stands_alone(command, capsys):
    text = _help(capsys, command)
    assert "examples:\n  graspgait " + command in text, text[-800:]
    assert not CLONE_PATH.search(text), CLONE_PATH.search(text).group(0)
    if command in LONG:
        assert "takes about: " in text
    # every option with a default shows it
    parser = _subparsers()[command]
    options = text.split("\noptions:\n", 1)[1].split("\nexamples:", 1)[0]
    shown = 0
    for action in parser._actions:
        if (action.default is None or action.default is False
                or action.default == argparse.SUPPRESS or not action.option_strings):
            continue
        flag = action.option_strings[-1]
        entry = re.split(rf"^  {re.escape(flag)}\b", options, maxsplit=1, flags=re.M)[1]
        entry = re.split(r"^  -", entry, maxsplit=1, flags=re.M)[0]
        assert "default" in entry, (flag, entry)
        shown += 1
    if command in {"map", "plan", "bench", "evaluate", "perf", "simulate", "story"}:
        assert shown >= 1


def test_top_level_help_and_version(capsys):
    text = _help(capsys)
    assert not CLONE_PATH.search(text)
    assert "config objects NAME" in text
    assert main(["--version"]) == 0
    out = capsys.readouterr().out.strip()
    assert out == f"graspgait {graspgait_env.__version__}"
    assert graspgait_env.__version__ == version("graspgait_env")  # one place


def test_perf_help_says_what_it_times(capsys):
    text = " ".join(_help(capsys, "perf").split())
    for what in ("grasp map", "planners", "CartPole-v1", "batched env", "MuJoCo hand",
                 "PASS/FAIL"):
        assert what in text, what


@pytest.mark.parametrize("kind", KINDS)
def test_config_prints_every_bundled_file(kind, capsys):
    names = bundled_names(kind)
    assert names, kind
    assert main(["config", kind]) == 0
    assert capsys.readouterr().out.split() == names
    for name in names:
        assert main(["config", kind, name]) == 0
        assert capsys.readouterr().out == bundled_file(kind, name).read_text()
    assert main(["config", kind, names[0], "--path"]) == 0
    assert capsys.readouterr().out.strip() == str(bundled_file(kind, names[0]))


def test_config_lists_kinds_and_refuses_unknown_names(capsys):
    assert main(["config"]) == 0
    out = capsys.readouterr().out
    for kind in KINDS:
        assert out.count(f"{kind} ") >= 1
    assert main(["config", "objects", "pentagonn"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "did you mean 'pentagon'?" in err
    assert main(["config", "shapes"]) == 2
    assert "KIND 'shapes'" in capsys.readouterr().err


def test_evaluate_without_a_model_says_what_to_give(capsys):
    assert main(["evaluate"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "evaluate --list" in err


# --- extras --------------------------------------------------------------------------


@pytest.fixture
def without(monkeypatch):
    """``without("torch", ...)``: those modules look uninstalled to graspgait_env.extras."""
    def hide(*modules: str) -> None:
        real = extras._installed
        monkeypatch.setattr(extras, "_installed", lambda m: m not in modules and real(m))
    return hide


@pytest.mark.parametrize("argv, extra", [
    (["train", "smoke"], "train"),
    (["evaluate", "ellipse"], "train"),
    (["story", "ellipse"], "train"),
    (["bench", "--starts", "1"], "train"),
    (["bench", "--starts", "1", "--agents", "none", "--ray"], "ray"),
    (["simulate", "plan.json", "--video", "v.mp4"], "video"),
    (["benchmark", "--list-tasks"], "benchmark"),
    (["dataset", "record", "map-point-circle"], "benchmark"),
])
def test_a_command_names_its_missing_extra_in_one_line(argv, extra, without, capsys,
                                                       tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    without(*extras.EXTRAS[extra][:1])
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"needs the [{extra}] extra" in err[0]
    assert f"pip install 'graspgait_env[{extra}]'" in err[0]


def test_bench_without_torch_runs_the_planners_alone(without, capsys):
    without("torch")
    assert main(["bench", "--agents", "none", "--objects", "circle", "--mus", "0.7",
                 "--planners", "rule", "--starts", "1"]) == 0
    assert "circle" in capsys.readouterr().out


def test_a_module_of_an_extra_reached_late_is_named_too(monkeypatch, capsys):
    """Past the up-front checks, an extra's ModuleNotFoundError still gives one line."""
    import graspgait_env.cli as cli

    def boom(args):
        raise ModuleNotFoundError("No module named 'moviepy'", name="moviepy")

    parser = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: _with_func(parser(), boom))
    assert main(["config"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["graspgait: error: graspgait config needs the [video] extra (moviepy not "
                   "installed): pip install 'graspgait_env[video]'"]


def _with_func(parser: argparse.ArgumentParser, func) -> argparse.ArgumentParser:
    parser.set_defaults(func=func)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                sub.set_defaults(func=func)
    return parser


def test_an_unrelated_missing_module_is_not_blamed_on_an_extra(monkeypatch):
    import graspgait_env.cli as cli

    def boom(args):
        raise ModuleNotFoundError("No module named 'nope'", name="nope")

    parser = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: _with_func(parser(), boom))
    with pytest.raises(ModuleNotFoundError):
        main(["config"])


def test_extras_table():
    assert extras.extra_for_module("torch.nn") == "train"
    assert extras.extra_for_module("ray.tune") == "ray"
    assert extras.extra_for_module("numpy") is None
    assert extras.missing_modules("train") == []  # `make test` installs every extra
    with pytest.raises(ValueError, match="extra='gpu'"):
        extras.missing_modules("gpu")
    err = extras.MissingExtraError("train", "x", ["torch"])
    assert isinstance(err, ImportError) and isinstance(err, graspgait_env.GraspGaitInputError)


def test_perf_leaves_out_the_rows_of_a_missing_extra(without, capsys, monkeypatch):
    import graspgait_env.perf as perf

    monkeypatch.setattr(perf, "BENCHMARK_MODULES", ["graspgait_env.agents.throughput"])
    monkeypatch.setattr(perf, "BENCHMARKS", [perf.bench_grasp_map])
    without("torch")
    assert perf.skipped_benchmark_modules() == [("graspgait_env.agents.throughput", "train")]
    assert main(["perf", "--repeat", "1"]) == 0
    out = capsys.readouterr().out
    assert "grasp map 180x180" in out
    assert "skipped graspgait_env.agents.throughput: needs the [train] extra" in out
