"""The controller at the planning friction: rolling ball paths, the friction cone check's
narrowed cone, the localizer halfway through a grip transfer, and the sim-config
switches that restore the thesis's controller (docs/science/hand.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.contact_model import hand_contact_model
from graspgait_env.objects import load_object
from graspgait_env.sim import trajectory as tj
from graspgait_env.sim.config import load_sim_config
from graspgait_env.sim.executor import GaitExecutor, check_cone_mu
from graspgait_env.sim.moves import CONSTANT_SPEED_ACCEL, load_localizer


def test_the_check_cone_is_the_plan_cone_less_the_hands_margin():
    cfg = load_sim_config()
    circle = load_object("circle")
    margin = hand_contact_model("circle").margin_deg(2 * circle.r_min)
    expected = math.tan(math.atan(0.7) - math.radians(margin))
    assert check_cone_mu(circle, 0.7, cfg, 0.1) == pytest.approx(expected)
    assert 0.5 < expected < 0.6
    assert GaitExecutor("circle", mu=0.7).cone_mu == pytest.approx(expected)
    thesis = GaitExecutor("circle", mu=0.7, config=cfg.replace(cone_mu=0.7))
    assert thesis.cone_mu == 0.7 and thesis.mu == 0.7  # finger friction = the plan's mu


def test_a_rotation_without_rolling_is_the_rigid_arc_and_rolling_shifts_it():
    x0 = np.array([[0.1, 0.0, 0.01], [-0.1, 0.0, 0.01], [0.0, 0.2, 0.01]])
    kw = dict(res=0.0025, speed_deg=90.0, accel=3.0)
    rigid = tj.rotation(x0, (0, 0), 30.0, [0, 1], 0.0, np.zeros((3, 2)), **kw)

    def still(a):
        n = len(a)
        return np.zeros((n, 2, 2)), np.broadcast_to([[-1.0, 0.0], [1.0, 0.0]], (n, 2, 2))

    same = tj.rotation(x0, (0, 0), 30.0, [0, 1], 0.0, np.zeros((3, 2)), rolling=still, **kw)
    np.testing.assert_allclose(same.x, rigid.x, atol=1e-15)

    def back(a):  # each ball moves 1 mm per degree along -y in the start frame
        n = len(a)
        shift = np.zeros((n, 2, 2))
        shift[:, :, 1] = -1e-3 * a[:, None]
        return shift, np.broadcast_to([[-1.0, 0.0], [1.0, 0.0]], (n, 2, 2))

    rolled = tj.rotation(x0, (0, 0), 30.0, [0, 1], 0.0, np.zeros((3, 2)), rolling=back, **kw)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(rolled.x[-1, 0, :2], [0.1 * c + 0.03 * s, 0.1 * s - 0.03 * c])
    np.testing.assert_allclose(rolled.x[:, 2], rigid.x[:, 2])  # the free finger stays


def test_the_object_turns_as_planned_with_a_ball_on_a_flat_edge():
    """Pentagon, finger 1 on the flat at 270 deg: the ball slides back 6 mm along it in
    a 45 deg turn; following the rolling path the object turns the 45 deg planned."""
    ex = GaitExecutor("pentagon", mu=0.7)
    assert ex.reset({1: 0.0, 2: 120.0}).ok
    th0 = ex.theta_true
    rep = ex.rotate(45.0)
    assert rep.ok and rep.slips == 0
    assert ex.theta_true - th0 == pytest.approx(45.0, abs=1.0)


def test_the_localizer_runs_halfway_through_each_regrasp():
    ex = GaitExecutor("circle", mu=0.7)
    assert ex.reset({1: 0.0, 2: 130.0}).ok
    rep = ex.execute({"op": "regrasp", "contacts": {"1": 0.0, "3": 230.0}})
    assert rep.ok and rep.localized
    assert rep.trajectories.count("transfer") == 2  # the localizer runs between them
    after = GaitExecutor("circle", mu=0.7,
                         config=load_sim_config(overrides={"localize_during_transfer": False}))
    assert after.reset({1: 0.0, 2: 130.0}).ok
    rep = after.execute({"op": "regrasp", "contacts": {"1": 0.0, "3": 230.0}})
    assert rep.ok and rep.trajectories.count("transfer") == 1


def test_the_thesis_switches():
    shape = load_object("ellipse")
    thesis = load_sim_config(overrides={"contact_along_approach": False,
                                        "localizer_iterate": False,
                                        "trapezoidal_speed": False})
    loc = load_localizer(shape, thesis)
    assert loc.__self__.config.max_iterations == 1 and not loc.__self__.config.gauss_newton
    assert GaitExecutor("ellipse", mu=0.7, config=thesis).moves._accel(2.0) == \
        CONSTANT_SPEED_ACCEL
    assert GaitExecutor("ellipse", mu=0.7).moves._accel(2.0) == 2.0
    magnitude = GaitExecutor("ellipse", mu=0.7, config=thesis.replace(
        trapezoidal_speed=True, localizer_iterate=True))
    rep = magnitude.reset({1: 60.0, 3: 240.0})  # the thesis's contact test still grasps
    assert rep.ok and set(rep.touching) == {1, 3}
    # at constant speed the step at each start reads as contact: the probe fingers stop
    # short and the localizer puts the object centimetres off
    jerky = GaitExecutor("ellipse", mu=0.7, config=thesis.replace(contact_along_approach=True,
                                                                    localizer_iterate=True))
    rep = jerky.reset({1: 60.0, 3: 240.0})
    assert not rep.ok and math.hypot(*rep.pose_estimate[:2]) > 0.005
