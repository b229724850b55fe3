"""The controller executing moves (thesis 7.3-7.5): one move at a time, a whole plan, the
tug test, video, step rates. Fast cases; the 10-run acceptance campaign is in
test_sim_acceptance.py (slow)."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.plan import Plan
from graspgait_env.sim import GaitExecutor, simulate_plan
from graspgait_env.sim.config import load_sim_config
from graspgait_env.sim.simulate import benchmark_step_rate, format_result, tug_test
from graspgait_env.sim.view import offscreen_rendering_available

RESULT_KEYS = {"success", "rotation_deg", "final_angle_error_deg", "dropped", "sim_time_s",
               "wall_time_s", "final_position_error_m", "slips", "steps"}


def _plan(obj: str, steps: list[dict], mu: float = 0.7) -> Plan:
    return Plan(obj, mu, [[0.0, 90.0], [120.0, 210.0], [240.0, 330.0]], steps)


def test_probe_localizes_a_misplaced_object_before_the_grasp():
    ex = GaitExecutor("pentagon", mu=0.7)
    rep = ex.reset({1: 50.0, 3: 270.0}, pose_perturbation=(0.004, -0.003, 4.0))
    assert rep.ok and rep.localized and rep.touching == (1, 3)
    x, y, th = ex.physics.object_pose()
    ex_, ey, eth = ex.pose_estimate()
    assert math.hypot(ex_ - x, ey - y) < 1.5e-3
    assert abs(eth - th) < 1.0


def test_probe_angles_avoid_vertices_and_stay_in_the_workspaces():
    ex = GaitExecutor("hexagon", mu=0.7)
    angles = ex.probe_angles_deg()
    verts = ex.shape.vertex_angles_deg
    for a, (lo, hi) in zip(angles, ex.workspaces, strict=True):
        assert lo <= a <= hi
        assert np.min(np.abs((a - verts + 180) % 360 - 180)) >= 8.0


@pytest.mark.parametrize("compensate,expected", [(True, 60.0),
                                                  (False, 60.0 * (1 + 0.0077978 / 0.0762))])
def test_rotation_and_the_rolling_of_the_ball_tip(compensate, expected):
    """Thesis 7.2: theta_o = (1 + r_f / r_o) theta_f for a ball that rolls; with the
    compensation the fingers' arcs are shortened so the object turns as planned."""
    cfg = load_sim_config(overrides={"rolling_compensation": compensate})
    ex = GaitExecutor("circle", mu=0.7, config=cfg)
    assert ex.reset({1: 15.0, 2: 195.0}).ok
    th0 = ex.theta_true
    rep = ex.rotate(60.0)
    assert rep.ok and rep.slips == 0
    assert ex.theta_true - th0 == pytest.approx(expected, abs=0.5)


def test_orientation_error_is_folded_into_the_next_rotation():
    ex = GaitExecutor("circle", mu=0.7)
    assert ex.reset({1: 15.0, 2: 195.0}).ok
    th0 = ex.theta_true
    ex.est[2] -= 3.0  # the controller believes the object is 3 deg behind the plan
    assert ex.rotate(10.0).ok
    assert ex.theta_true - th0 == pytest.approx(13.0, abs=0.4)
    assert ex.pose_estimate()[2] == pytest.approx(10.0)


def test_one_move_at_a_time():
    """The API a Gymnasium env uses: reset(grasp), execute(step) -> StepReport."""
    ex = GaitExecutor("ellipse", mu=0.7)  # the first moves of its plan for the hand
    rep = ex.execute({"op": "grasp", "contacts": {"1": 60.0, "3": 240.0}})
    assert rep.ok and rep.op == "grasp" and set(rep.touching) == {1, 3}
    rep = ex.execute({"op": "rotate", "delta": 30.0})
    assert rep.ok and rep.pose_estimate[2] == pytest.approx(30.0)
    rep = ex.execute({"op": "regrasp", "contacts": {"2": 90.0, "3": 240.0}})
    assert rep.ok and set(rep.touching) == {2, 3} and rep.localized
    assert sorted(ex.held) == [1, 2]
    assert abs(rep.pose_true[2] - rep.pose_estimate[2]) < 1.0
    assert rep.grip_n[2] >= 2.0 and rep.grip_n[:2] == (0.0, 0.0)  # pair (2, 3) grips
    assert "transfer" in rep.trajectories and "retreat" in rep.trajectories
    d = rep.to_dict()
    assert d["status"] == "ok" and d["op"] == "regrasp"


def test_bad_moves_are_refused():
    ex = GaitExecutor("circle", mu=0.7)
    with pytest.raises(GraspGaitInputError, match="reset"):
        ex.execute({"op": "rotate", "delta": 5.0})
    assert ex.reset({1: 15.0, 2: 195.0}).ok
    with pytest.raises(GraspGaitInputError, match="keep exactly one"):
        ex.execute({"op": "regrasp", "contacts": {"1": 15.0, "2": 195.0}})
    with pytest.raises(GraspGaitInputError, match="op"):
        ex.execute({"op": "twist"})
    with pytest.raises(GraspGaitInputError, match="fingers are 1, 2, 3"):
        ex.reset({1: 15.0, 4: 195.0})


def test_an_object_out_of_reach_is_reported_not_grasped():
    rep = GaitExecutor("circle", mu=0.7).reset({1: 15.0, 2: 195.0},
                                               pose_perturbation=(0.0, 0.09, 0.0))
    assert rep.status == "no-contact" and "found no object" in rep.message


def test_simulate_plan_reports_the_run():
    plan = _plan("pentagon", [{"op": "grasp", "contacts": {"1": 50.0, "3": 270.0}},
                              {"op": "rotate", "delta": 30.0},
                              {"op": "regrasp", "contacts": {"2": 140.0, "3": 270.0}},
                              {"op": "rotate", "delta": 20.0}])
    r = simulate_plan(plan, pose_perturbation=(0.003, 0.002, -2.0))
    assert RESULT_KEYS <= set(r)
    assert r["success"] and not r["dropped"] and r["steps_done"] == 4
    assert abs(r["final_angle_error_deg"]) < 1.0
    assert r["rotation_deg"] == pytest.approx(52.0, abs=1.0)  # 50 planned + the 2 deg error
    assert r["sim_time_s"] > 1.0 and r["wall_time_s"] > 0
    assert r["physics_steps"] == pytest.approx(r["sim_time_s"] / 0.001, rel=0.01)
    assert "success" in format_result(r)


def test_simulate_plan_is_deterministic():
    plan = _plan("circle", [{"op": "grasp", "contacts": {"1": 15.0, "2": 195.0}},
                            {"op": "rotate", "delta": 45.0}])
    a = simulate_plan(plan, pose_perturbation="random", seed=3)
    b = simulate_plan(plan, pose_perturbation="random", seed=3)
    assert a["final_pose"] == b["final_pose"] and a["pose_perturbation"] == b["pose_perturbation"]
    c = simulate_plan(plan, pose_perturbation="random", seed=4)
    assert c["pose_perturbation"] != a["pose_perturbation"]
    assert max(abs(v) for v in a["pose_perturbation"][:2]) <= 0.006
    assert abs(a["pose_perturbation"][2]) <= 5.0


def test_simulate_command_for_the_cli(tmp_path, capsys):
    import json

    from graspgait_env.sim.simulate import parse_perturbation, simulate_command

    plan = _plan("circle", [{"op": "grasp", "contacts": {"1": 15.0, "2": 195.0}},
                            {"op": "rotate", "delta": 30.0}])
    plan.save(tmp_path / "plan.json")
    rc = simulate_command(tmp_path / "plan.json", perturb="0.002,0,1", progress=False,
                          json_out=str(tmp_path / "r.json"))
    assert rc == 0 and "success" in capsys.readouterr().out
    assert json.loads((tmp_path / "r.json").read_text())["success"] is True
    assert parse_perturbation("random") == "random" and parse_perturbation(None) is None
    with pytest.raises(GraspGaitInputError, match="DX,DY,DTHETA"):
        parse_perturbation("1,2")
    with pytest.raises(GraspGaitInputError, match=".mp4"):
        simulate_command(tmp_path / "plan.json", video=str(tmp_path / "x.gif"))


def test_simulate_plan_refuses_bad_input():
    with pytest.raises(GraspGaitInputError, match="grasp"):
        simulate_plan(_plan("circle", [{"op": "rotate", "delta": 5.0}]))
    plan = _plan("circle", [{"op": "grasp", "contacts": {"1": 15.0, "2": 195.0}}])
    with pytest.raises(GraspGaitInputError, match="pose_perturbation"):
        simulate_plan(plan, pose_perturbation=(0.0, 0.0))


# ----------------------------------------------------------------- tug test (thesis 7.5)
# At finger friction 0.7 the check can raise the grip to 1 lb (4.45 N), so the two
# fingers hold at most 2 x 0.7 x 4.45 = 6.2 N across the grip: a 5 N tug is 80% of that.
@pytest.mark.parametrize("along", [False, True], ids=["across-grip", "along-grip"])
def test_tug_with_the_check_on_holds(along):
    r = tug_test("circle", force=5.0, along_grip=along, grip_check=True)
    assert not r["dropped"] and not r["lost_contact"]
    assert r["slip_m"] <= 0.002  # measured ~0.1-0.3 mm
    assert r["max_grip_n"] > 2.0  # the check raised the grip


def test_tug_across_the_grip_with_the_check_off_slips():
    r = tug_test("circle", force=6.0, along_grip=False, grip_check=False)
    assert r["slip_m"] > 0.002 and r["lost_contact"]


def test_tug_along_the_grip_with_the_check_off_loses_a_finger():
    r = tug_test("circle", force=6.0, along_grip=True, grip_check=False)
    assert r["lost_contact"]


# ----------------------------------------------------------------- video and step rates


@pytest.mark.skipif(not offscreen_rendering_available(),
                    reason="no headless OpenGL (MUJOCO_GL=egl) here")
def test_video_is_written_atomically(tmp_path):
    import imageio_ffmpeg

    cfg = load_sim_config(overrides={"video_width": 160, "video_height": 120,
                                     "video_fps": 8, "initial_probe": False})
    plan = _plan("circle", [{"op": "grasp", "contacts": {"1": 15.0, "2": 195.0}},
                            {"op": "rotate", "delta": 30.0}])
    out = tmp_path / "run.mp4"
    r = simulate_plan(plan, video=out, config=cfg)
    assert r["success"] and r["video"] == str(out)
    frames, secs = imageio_ffmpeg.count_frames_and_secs(str(out))
    assert frames >= int(r["sim_time_s"] * 8)
    assert [p.name for p in tmp_path.iterdir()] == ["run.mp4"]  # no temporary left


def test_benchmark_step_rate_compares_controller_and_physics():
    plan = _plan("circle", [{"op": "grasp", "contacts": {"1": 15.0, "2": 195.0}},
                            {"op": "rotate", "delta": 90.0}])
    b = benchmark_step_rate(plan)
    assert b["raw_steps_per_s"] > b["controlled_steps_per_s"] > 0
    assert 0 <= b["controller_share"] < 1
    assert b["servo_hz"] == 250 and b["physics_hz"] == 1000


def test_mujoco_gl_defaults_to_egl():
    assert os.environ.get("MUJOCO_GL") in ("egl", "osmesa", "glfw", "glx")
