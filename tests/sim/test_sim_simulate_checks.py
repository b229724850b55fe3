"""``graspgait simulate``'s input checks: a perturbation beyond what the hand recovers
from, a non-finite one, and an unwritable video path are refused in one line, before the
simulation runs (the CLI exits 2)."""

from __future__ import annotations

import os

import pytest

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.objects import load_object
from graspgait_env.plan import Plan
from graspgait_env.sim import simulate as sim_mod
from graspgait_env.sim.config import load_sim_config
from graspgait_env.sim.simulate import (
    check_perturbation,
    check_video_path,
    perturbation_limits,
    simulate_command,
)


class Ran(Exception):
    """simulate_plan was reached: every check passed."""


@pytest.fixture
def no_simulation(monkeypatch):
    """simulate_plan raises Ran: a refusal must come before it."""
    def fake(*args, **kwargs):
        raise Ran

    monkeypatch.setattr(sim_mod, "simulate_plan", fake)


def _plan_file(tmp_path, obj: str) -> str:
    contacts = {"circle": {"1": 15.0, "2": 195.0}, "pentagon": {"1": 50.0, "3": 270.0}}[obj]
    plan = Plan(obj, 0.7, [[0.0, 90.0], [120.0, 210.0], [240.0, 330.0]],
                [{"op": "grasp", "contacts": contacts}, {"op": "rotate", "delta": 10.0}])
    path = tmp_path / f"{obj}.json"
    plan.save(path)
    return str(path)


def test_limits_come_from_the_config_and_the_shape():
    cfg = load_sim_config()
    pent, circle = load_object("pentagon"), load_object("circle")
    assert perturbation_limits(pent, cfg) == (cfg.standoff, cfg.probe_vertex_clearance_deg)
    assert perturbation_limits(circle, cfg) == (cfg.standoff, None)  # any angle
    assert perturbation_limits(pent, cfg.replace(overshoot=0.004))[0] == 0.004
    assert perturbation_limits(pent, cfg.replace(probe_vertex_clearance_deg=6.0))[1] == 6.0


@pytest.mark.parametrize("perturb,fragment", [
    ("0.05,0,0", "--perturb dx=0.05 m: beyond the 0.01 m"),
    ("0,-0.02,0", "--perturb dy=-0.02 m: beyond the 0.01 m"),
    ("0.008,0.008,0", "--perturb sqrt(dx^2 + dy^2)=0.0113137 m"),
    ("0,0,12", "--perturb dtheta=12 deg: beyond the 8 deg"),
    ("0,0,-8.5", "give |dtheta| <= 8 deg"),
    ("nan,0,0", "--perturb dx=nan m: not a finite number"),
    ("0,inf,0", "--perturb dy=inf m: not a finite number"),
    ("0,0,-inf", "--perturb dtheta=-inf deg: not a finite number"),
])
def test_a_perturbation_beyond_the_hand_is_refused_first(tmp_path, no_simulation, perturb,
                                                         fragment):
    with pytest.raises(GraspGaitInputError) as e:
        simulate_command(_plan_file(tmp_path, "pentagon"), perturb=perturb, progress=False)
    msg = str(e.value)
    assert fragment in msg and "\n" not in msg


def test_the_message_names_the_bound_and_the_fix(tmp_path, no_simulation):
    with pytest.raises(GraspGaitInputError) as e:
        simulate_command(_plan_file(tmp_path, "pentagon"), perturb="0.05,0,0",
                         progress=False)
    msg = str(e.value)
    assert "standoff=0.01 m" in msg and "overshoot=0.02 m" in msg
    assert msg.endswith("give sqrt(dx^2 + dy^2) <= 0.01 m")


@pytest.mark.parametrize("obj,perturb", [("pentagon", "0.01,0,8"), ("pentagon", "0.006,-0.007,-8"),
                                         ("pentagon", "random"), ("circle", "0.004,0,90")])
def test_perturbations_within_the_limits_pass(tmp_path, no_simulation, obj, perturb):
    with pytest.raises(Ran):
        simulate_command(_plan_file(tmp_path, obj), perturb=perturb, progress=False)


def test_random_is_refused_when_the_config_cannot_take_its_range(tmp_path, no_simulation):
    cfg = tmp_path / "sim.yaml"
    cfg.write_text("standoff: 0.004\n")
    with pytest.raises(GraspGaitInputError, match="random: draws offsets up to 0.006 m"):
        simulate_command(_plan_file(tmp_path, "pentagon"), perturb="random", config=str(cfg),
                         progress=False)


def test_check_perturbation_for_api_callers():
    cfg, pent = load_sim_config(), load_object("pentagon")
    check_perturbation(None, pent, cfg)
    check_perturbation((0.0, 0.0, 0.0), pent, cfg)
    with pytest.raises(GraspGaitInputError, match="pose dx=0.02 m"):
        check_perturbation((0.02, 0.0, 0.0), pent, cfg, option="pose")
    with pytest.raises(GraspGaitInputError, match="DX,DY,DTHETA or 'random'"):
        check_perturbation("jitter", pent, cfg)


@pytest.mark.parametrize("name,fragment", [
    ("run.gif", "use one of .mp4"),
    ("run", "use one of .mp4"),
    ("run.mp4.tmp", "use one of .mp4"),
])
def test_a_video_of_another_format_is_refused_first(tmp_path, no_simulation, name, fragment):
    with pytest.raises(GraspGaitInputError, match=fragment):
        simulate_command(_plan_file(tmp_path, "circle"), video=str(tmp_path / name),
                         progress=False)


def test_a_video_whose_folder_cannot_be_created_is_refused_first(tmp_path, no_simulation):
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where the folder should be")
    with pytest.raises(GraspGaitInputError, match="not a folder"):
        simulate_command(_plan_file(tmp_path, "circle"), video=str(blocker / "run.mp4"),
                         progress=False)


def test_a_video_path_that_is_a_folder_is_refused(tmp_path):
    (tmp_path / "dir.mp4").mkdir()
    with pytest.raises(GraspGaitInputError, match="is a directory"):
        check_video_path(tmp_path / "dir.mp4")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="needs POSIX permissions and a user they apply to (not root)")
def test_a_video_in_a_read_only_folder_is_refused(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(GraspGaitInputError, match="cannot write in the folder"):
            check_video_path(ro / "run.mp4")
    finally:
        ro.chmod(0o700)


def test_a_good_video_path_passes_and_its_folder_is_made(tmp_path, no_simulation):
    out = tmp_path / "new" / "deeper" / "Run.MP4"
    assert check_video_path(out) == out and out.parent.is_dir()
    assert list(out.parent.iterdir()) == []  # the write test leaves nothing behind
    with pytest.raises(Ran):
        simulate_command(_plan_file(tmp_path, "circle"), video=str(out), progress=False)


def test_the_cli_exits_2_with_one_line(tmp_path, capsys, no_simulation):
    from graspgait_env.cli import main

    rc = main(["simulate", _plan_file(tmp_path, "pentagon"), "--perturb", "0.03,0,0",
               "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.count("\n") == 0 and "dx=0.03 m" in err
