"""The trajectory planner (thesis 7.4.2), pure NumPy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.sim import trajectory as tj
from graspgait_env.sim.trajectory import CONTACT, FREE, HOLD, TRANSITION, pair_index

RES = 0.00254
X0 = np.array([[0.09, 0.0, 0.01], [-0.09, 0.0, 0.01], [0.0, -0.17, 0.01]])
NR = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
G = np.array([2.0, 0.0, 0.0])


def test_time_law_triangle_and_trapezoid():
    s = np.linspace(0, 0.1, 401)
    t, v = tj.time_law(s, np.full(401, 10.0), 2.0)  # never reaches 10 m/s
    assert t[-1] == pytest.approx(2 * math.sqrt(0.1 / 2.0), rel=1e-3)
    assert v[0] == 0 and v[-1] == 0
    t, v = tj.time_law(s, np.full(401, 0.1), 2.0)  # trapezoid: d/v + v/a
    assert t[-1] == pytest.approx(0.1 / 0.1 + 0.1 / 2.0, rel=1e-3)
    assert v.max() == pytest.approx(0.1)
    t, v = tj.time_law(s, np.full(401, 10.0), 8.0, decel=2.0)  # brake slower than speed up
    assert np.argmax(v) < 100


def test_sample_is_continuous_and_ends_at_rest():
    tr = tj.rotation(X0, [0, 0], 90.0, [0, 1], G, NR, res=RES, speed_deg=180.0, accel=3.0)
    xd, vd, g, n = tr.sample(0.004)
    step = np.linalg.norm(np.diff(xd, axis=0), axis=2).max()
    assert step < 0.09 * math.pi / 2 / 10  # no jumps
    np.testing.assert_allclose(xd[-1], tr.end, atol=1e-15)
    assert np.all(vd[-1] == 0)
    # the desired velocity is the derivative of the desired position
    fd = np.diff(xd, axis=0) / 0.004
    mid = 0.5 * (vd[1:] + vd[:-1])
    assert np.abs(fd - mid)[:-2].max() < 0.02


def test_rotation_is_an_arc_at_the_present_radius():
    tr = tj.rotation(X0, [0.001, 0.002], 40.0, [0, 1], G, NR, res=RES, speed_deg=180,
                     accel=3.0)
    c = np.array([0.001, 0.002])
    r0 = np.linalg.norm(X0[:2, :2] - c, axis=1)
    r = np.linalg.norm(tr.x[:, :2, :2] - c, axis=2)
    np.testing.assert_allclose(r, np.broadcast_to(r0, r.shape), atol=1e-12)
    a0 = np.arctan2(*(X0[0, :2] - c)[::-1])
    a1 = np.arctan2(*(tr.end[0, :2] - c)[::-1])
    assert math.degrees(a1 - a0) == pytest.approx(40.0)
    np.testing.assert_allclose(tr.x[:, 2], np.broadcast_to(X0[2], (len(tr.x), 3)))  # free stays
    # via points are res apart along the longest path
    seg = np.linalg.norm(np.diff(tr.x, axis=0), axis=2).max(axis=1)
    assert seg.max() <= RES + 1e-12
    # normals turn with the object
    assert math.degrees(math.atan2(tr.normals[-1, 0, 1], tr.normals[-1, 0, 0])) == \
        pytest.approx(180.0 + 40.0 - 360.0)
    assert tr.kind.tolist() == [HOLD, HOLD, FREE]
    assert tr.duration >= math.radians(40) / math.radians(180)


def test_free_arc_at_max_r_stays_inside_the_workspace():
    # finger 3 from F 270 deg to 250 deg inside [240, 330]; radius to max_r
    x0 = X0.copy()
    x0[2, :2] = [0.12 * math.cos(math.radians(270)), 0.12 * math.sin(math.radians(270))]
    tr = tj.free_arc(x0, [2], [0, 0], [250.0], 0.17, G, NR, res=RES, speed=0.6, accel=10.0,
                     workspaces=[(240.0, 330.0)])
    a = np.degrees(np.arctan2(tr.x[:, 2, 1], tr.x[:, 2, 0])) % 360
    assert a.min() >= 250 - 1e-9 and a.max() <= 270 + 1e-9
    assert np.hypot(*tr.end[2, :2]) == pytest.approx(0.17)
    assert tr.kind.tolist() == [HOLD, HOLD, FREE]
    # workspace through 0 deg: from 350 to 10 goes the short way through 0
    assert tj.workspace_sweep_deg(350.0, 10.0, (300.0, 390.0)) == pytest.approx(20.0)
    assert tj.workspace_sweep_deg(80.0, 10.0, (0.0, 90.0)) == pytest.approx(-70.0)


def test_approach_runs_past_the_target_in_two_parts():
    x0 = X0.copy()
    x0[2, :2] = [0.0, -0.17]
    target = np.array([[0.0, -0.07, 0.01]])
    fast, slow = tj.approach(x0, [2], target, G, NR, res=RES, speed=0.6, approach_speed=0.06,
                             standoff=0.01, overshoot=0.02, accel=10.0, approach_accel=2.0,
                             hold=[0, 1])
    assert fast.kind.tolist() == [HOLD, HOLD, FREE]
    assert slow.kind.tolist() == [HOLD, HOLD, CONTACT]
    np.testing.assert_allclose(fast.end[2], [0.0, -0.08, 0.01], atol=1e-12)
    np.testing.assert_allclose(slow.end[2], [0.0, -0.05, 0.01], atol=1e-12)
    assert slow.v.max() == pytest.approx(0.06)
    # already within the standoff: only the slow part
    near = x0.copy()
    near[2, :2] = [0.0, -0.075]
    assert len(tj.approach(near, [2], target, G, NR, res=RES, speed=0.6, approach_speed=0.06,
                           standoff=0.01, overshoot=0.02, accel=10.0,
                           approach_accel=2.0)) == 1


def test_transfer_moves_the_grip_linearly_from_old_pair_to_new():
    g0 = np.zeros(3)
    g0[pair_index(0, 1)] = 3.0
    g1 = np.zeros(3)
    g1[pair_index(1, 2)] = 2.0
    tr = tj.transfer(X0, g0, g1, NR, 0.1)
    xd, vd, g, _ = tr.sample(0.004)
    assert tr.kind.tolist() == [TRANSITION] * 3
    assert np.all(vd == 0) and np.allclose(xd, X0)
    k = len(g) // 2
    assert g[k, pair_index(0, 1)] + g[k, pair_index(1, 2)] * 1.5 == pytest.approx(3.0, abs=0.2)
    np.testing.assert_allclose(g[-1], g1)
    assert np.all(np.diff(g[:, pair_index(0, 1)]) <= 1e-12)


def test_retreat_goes_radially_out_to_max_r():
    tr = tj.retreat(X0, 1, [0.0, 0.0], 0.17, G, NR, res=RES, speed=0.6, accel=10.0)
    np.testing.assert_allclose(tr.end[1], [-0.17, 0.0, 0.01])
    assert np.allclose(tr.x[:, 1, 1], 0.0)
    assert tr.kind.tolist() == [HOLD, FREE, HOLD]  # by default the others hold
    assert np.all(tr.normals[:, 1] == 0)


def test_translate_moves_the_holding_pair():
    tr = tj.translate(X0, [0, 1], [0.003, -0.004], G, NR, res=RES, speed=0.1, accel=3.0)
    np.testing.assert_allclose(tr.end[:2, :2] - X0[:2, :2], [[0.003, -0.004]] * 2)
    np.testing.assert_allclose(tr.end[2], X0[2])


def test_pairs_cover_the_three_fingers():
    assert sorted(tj.PAIRS) == [(0, 1), (0, 2), (1, 2)]
    assert pair_index(2, 0) == pair_index(0, 2)
