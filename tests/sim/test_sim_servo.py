"""Inner servo loop units (thesis 7.3, 7.4.3, 7.4.4, 7.4.6), each on its own."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.sim.servo import ContactDetector, GripCheck, PDServo, internal_forces
from graspgait_env.sim.trajectory import CONTACT, FREE, HOLD, TRANSITION


def test_pd_servo_is_kp_error_plus_kv_velocity_error():
    s = PDServo([100, 200, 300], [1, 2, 3], alpha=1.0, dt=0.01)
    s.reset([0.0] * 9)
    x = [0.001] * 9
    f = s.cycle(x, [0.002] * 9, [0.5] * 9)
    # v_m = (0.001 - 0) / 0.01 = 0.1 with alpha = 1
    expect = [kp * 0.001 + kv * (0.5 - 0.1)
              for kp, kv in zip([100, 200, 300] * 3, [1, 2, 3] * 3, strict=True)]
    assert f == pytest.approx(expect)


def test_velocity_filter_is_a_first_order_low_pass():
    s = PDServo([0, 0, 0], [0, 0, 0], alpha=0.1, dt=0.001)
    s.reset([0.0] * 9)
    x = 0.0
    for _ in range(10):
        x += 0.001  # true velocity 1 m/s
        s.cycle([x] * 9, [0.0] * 9, [0.0] * 9)
    assert s.v[0] == pytest.approx(1 - 0.9**10)  # step response of v <- v + a (u - v)
    with pytest.raises(ValueError):
        PDServo([1, 1, 1], [1, 1, 1], alpha=0.0, dt=0.001)


def test_internal_forces_are_equal_opposite_and_along_the_finger_line():
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = rng.normal(size=9).tolist()
        g = rng.uniform(0, 3, size=3).tolist()
        f, u = internal_forces(x, g)
        fa = np.array(f).reshape(3, 3)
        np.testing.assert_allclose(fa.sum(axis=0), 0, atol=1e-12)  # no net force (7.4.3)
        assert np.all(fa[:, 2] == 0)
        for p, (i, j) in enumerate([(0, 1), (0, 2), (1, 2)]):
            d = np.array(x[3 * j:3 * j + 2]) - np.array(x[3 * i:3 * i + 2])
            np.testing.assert_allclose(u[p], d / np.linalg.norm(d))
        # magnitudes: finger 0 gets g01 u01 + g02 u02
        expect0 = g[0] * np.array(u[0]) + g[1] * np.array(u[1])
        np.testing.assert_allclose(fa[0, :2], expect0)


def test_internal_forces_skip_pairs_without_grip():
    f, u = internal_forces([0.1, 0, 0, -0.1, 0, 0, 0, 0.2, 0], [0.0, 0.0, 1.0])
    assert u[0] is None and u[1] is None and u[2] is not None
    assert f[0] == 0 and f[1] == 0


CHK = GripCheck(nominal=1.0, settle=40, saturation=4.448, cone_mu=0.7)
U = [(1.0, 0.0), None, None]  # pair (1,2) grips along +x from finger 1 to finger 2
NORMALS = [1.0, 0.0, -1.0, 0.0, 0.0, 0.0]  # inward normals at the two contacts
G = [1.0, 0.0, 0.0]


def _total(f1, f2):
    return [f1[0], f1[1], 0.0, f2[0], f2[1], 0.0, 0.0, 0.0, 0.0]


def test_grip_check_passes_a_good_grasp():
    assert CHK(_total((1.2, 0.1), (-1.2, 0.1)), U, G, NORMALS, [HOLD, HOLD, FREE]) == [0, 0, 0]


def test_grip_check_raises_grip_when_a_finger_pushes_too_little():
    inc = CHK(_total((0.6, 0.0), (-1.4, 0.0)), U, G, NORMALS, [HOLD, HOLD, FREE])
    assert inc == [pytest.approx(1.0 / 40), 0, 0]  # nominal / settle


def test_friction_check_raises_grip_outside_the_cone():
    inc = CHK(_total((1.2, 1.0), (-1.2, 1.0)), U, G, NORMALS, [HOLD, HOLD, FREE])
    assert inc[0] == pytest.approx(1.0 / 40)  # atan(1/1.2) = 40 deg > atan(0.7) = 35 deg


def test_friction_check_is_skipped_when_the_grip_direction_is_outside_the_cone():
    # estimated normals tilted 50 deg from the grip line: more grip cannot help
    c, s = math.cos(math.radians(50)), math.sin(math.radians(50))
    normals = [c, s, -c, s, 0.0, 0.0]
    inc = CHK(_total((1.2, 1.0), (-1.2, 1.0)), U, G, normals, [HOLD, HOLD, FREE])
    assert inc == [0, 0, 0]


def test_no_grip_is_added_above_saturation_or_during_transitions():
    assert CHK(_total((3.0, 4.0), (-3.0, 4.0)), U, G, NORMALS, [HOLD, HOLD, FREE]) == [0, 0, 0]
    assert CHK(_total((0.1, 0.0), (-0.1, 0.0)), U, [4.5, 0, 0], NORMALS,
               [HOLD, HOLD, FREE]) == [0, 0, 0]
    assert CHK(_total((0.1, 0.0), (-0.1, 0.0)), U, G, NORMALS,
               [TRANSITION, TRANSITION, FREE]) == [0, 0, 0]
    assert CHK(_total((0.1, 0.0), (-0.1, 0.0)), [None] * 3, [0, 0, 0], NORMALS,
               [HOLD, HOLD, FREE]) == [0, 0, 0]


def test_contact_detection_needs_n_cycles_over_threshold():
    det = ContactDetector(0.278, 3)
    over = [0.3, 0, 0] * 3
    under = [0.2, 0, 0] * 3
    armed = [True, False, True]
    assert det.update(over, armed) == [False, False, False]
    assert det.update(over, armed) == [False, False, False]
    assert det.update(under, armed) == [False, False, False]  # the count restarts
    for _ in range(2):
        det.update(over, armed)
    assert det.update(over, armed) == [True, False, True]


def test_contact_detection_along_the_approach_direction():
    det = ContactDetector(0.278, 1)
    f = [0.5, 0, 0, -0.5, 0, 0, 0, 0.5, 0]
    dirs = [(1.0, 0.0), (1.0, 0.0), (0.0, 1.0)]  # finger 2 is pulled back, not stopped
    assert det.update(f, [True, True, True], dirs) == [True, False, True]
    assert CONTACT != HOLD
