"""The ground-truth monitor (graspgait_env.sim.monitor): drops, slips, the unwrapped angle;
on a stand-in physics (exact, fast) and once on the MuJoCo hand."""

from __future__ import annotations

import numpy as np
import pytest

from graspgait_env.sim import GaitExecutor
from graspgait_env.sim.config import load_sim_config
from graspgait_env.sim.monitor import GroundTruthMonitor, MonitorSnapshot
from graspgait_env.sim.state import ControllerState, MoveAborted


class FakePhysics:
    """The accessors the monitor reads, set by hand."""

    def __init__(self) -> None:
        self.pose = (0.0, 0.0, 0.0)
        self.tilt = 0.0
        self.contact = np.array([True, True, False])
        self.time = 0.0
        self.tips = np.array([[0.05, 0.0, 0.01], [-0.05, 0.0, 0.01], [0.0, 0.1, 0.01]])

    def object_pose(self):
        return self.pose

    def object_tilt_deg(self):
        return self.tilt

    def tip_in_contact(self):
        return self.contact

    def tip_positions(self):
        return self.tips


def _monitor(**overrides):
    cfg = load_sim_config(overrides=overrides)
    phys = FakePhysics()
    state = ControllerState(np.zeros((3, 3)))
    state.held = {0: 0.0, 1: 180.0}
    state.started = True
    mon = GroundTruthMonitor(phys, cfg, state)
    mon.start()
    return mon, phys, state


def test_no_drop_while_the_grasp_holds():
    mon, phys, _ = _monitor()
    phys.pose = (0.01, -0.01, 5.0)
    mon()
    assert not mon.dropped and mon.theta_true == pytest.approx(5.0)


def test_a_drop_by_distance_stops_the_move():
    mon, phys, _ = _monitor()
    phys.pose = (0.031, 0.0, 0.0)  # drop_distance 0.03 m
    with pytest.raises(MoveAborted, match="31 mm from the centre"):
        mon()
    assert mon.dropped and "31 mm" in mon.drop_reason
    mon()  # once dropped, no second abort
    assert mon.dropped


@pytest.mark.parametrize("tilt,limit,dropped", [(15.0, 20.0, False), (25.0, 20.0, True),
                                                 (15.0, 10.0, True)])
def test_a_drop_by_tilt_uses_the_configured_limit(tilt, limit, dropped):
    mon, phys, _ = _monitor(drop_tilt_deg=limit)
    phys.tilt = tilt
    if dropped:
        with pytest.raises(MoveAborted, match="tipped over"):
            mon()
    else:
        mon()
    assert mon.dropped is dropped


def test_a_drop_by_lost_contact_after_lost_contact_time():
    mon, phys, _ = _monitor(lost_contact_time=0.1)
    phys.contact = np.array([True, False, False])
    mon()  # the clock starts
    phys.time = 0.1
    mon()  # not more than 0.1 s yet
    assert not mon.dropped
    phys.time = 0.1001
    with pytest.raises(MoveAborted, match="1 gripping finger"):
        mon()


def test_contact_back_resets_the_lost_contact_clock():
    mon, phys, _ = _monitor(lost_contact_time=0.1)
    phys.contact = np.array([True, False, False])
    mon()
    phys.time, phys.contact = 0.05, np.array([True, True, False])
    mon()
    phys.time, phys.contact = 0.12, np.array([True, False, False])
    mon()  # lost again at 0.12: only now the clock runs
    assert not mon.dropped


def test_no_drop_without_a_grasp_to_lose():
    mon, phys, state = _monitor()
    state.held = {}
    phys.pose = (0.2, 0.0, 0.0)
    mon()
    assert not mon.dropped


def test_the_true_angle_unwraps_across_180():
    mon, phys, _ = _monitor()
    for th in (90.0, 179.0, -179.0, -90.0, 0.0, 90.0):
        phys.pose = (0.0, 0.0, th)
        mon()
    assert mon.theta_true == pytest.approx(450.0)
    assert mon.true_pose() == (0.0, 0.0, pytest.approx(450.0))


def test_slips_beyond_the_rolling_of_the_ball():
    mon, phys, _ = _monitor(slip_threshold=0.002)
    start = mon.snapshot()
    assert start.tips.shape == (3, 2)
    phys.tips = phys.tips.copy()
    phys.tips[0, 1] += 0.003  # finger 1 slides 3 mm along the object, the object still
    phys.tips[1, 1] += 0.001  # finger 2 1 mm
    count, largest = mon.slips(start, [0, 1])
    assert count == 1 and largest == pytest.approx(0.003)
    assert mon.slips(MonitorSnapshot(None, 0.0), [0, 1]) == (0, 0.0)
    assert mon.slips(start, []) == (0, 0.0)


def test_the_monitor_finds_a_drop_on_the_hand():
    """On MuJoCo: the object is knocked 5 cm away while held; the next move reports the
    drop, and every move after it too."""
    ex = GaitExecutor("circle", mu=0.7)
    assert ex.reset({1: 15.0, 2: 195.0}).ok
    ex.physics.set_object_pose(0.05, 0.0, 0.0)
    rep = ex.hold(0.05)
    assert rep.status == "dropped" and "from the centre" in rep.message
    assert ex.dropped and ex.monitor.dropped
    rep = ex.execute({"op": "rotate", "delta": 10.0})
    assert rep.status == "dropped" and "dropped earlier" in rep.message
