"""Frames and units (graspgait_env.sim.frames): round trips, conventions, degenerate input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.sim import config as config_mod
from graspgait_env.sim import frames
from graspgait_env.sim.frames import (
    INCH,
    LB_TO_N,
    OZ_TO_N,
    object_to_workspace,
    quat_from_yaw_deg,
    rotate_deg,
    rotation_matrices,
    tilt_deg_from_quat,
    workspace_to_object,
    wrap_deg,
    yaw_deg_from_quat,
)

POSES = [(0.0, 0.0, 0.0), (0.004, -0.003, 3.0), (-0.02, 0.01, -170.0), (0.1, 0.2, 720.5)]


@pytest.mark.parametrize("pose", POSES)
def test_object_and_workspace_frames_round_trip(pose):
    rng = np.random.default_rng(1)
    p_f = rng.uniform(-0.1, 0.1, size=(7, 2))
    p_F = object_to_workspace(p_f, pose)
    np.testing.assert_allclose(workspace_to_object(p_F, pose), p_f, atol=1e-15)
    np.testing.assert_allclose(object_to_workspace(workspace_to_object(p_f, pose), pose), p_f,
                               atol=1e-15)


def test_conventions_hand_computed():
    """Positive angles are counter-clockwise; the object's origin lands on the pose."""
    np.testing.assert_allclose(object_to_workspace([[0.0, 0.0]], (0.3, -0.2, 57.0)),
                               [[0.3, -0.2]], atol=1e-15)
    np.testing.assert_allclose(object_to_workspace([[1.0, 0.0]], (0.0, 0.0, 90.0)),
                               [[0.0, 1.0]], atol=1e-15)
    np.testing.assert_allclose(rotate_deg([[1.0, 0.0], [0.0, 1.0]], 90.0),
                               [[0.0, 1.0], [-1.0, 0.0]], atol=1e-15)
    # one point (2,) works as well as many (k, 2)
    assert object_to_workspace([1.0, 0.0], (0.0, 0.0, 180.0)).shape == (2,)


def test_directions_rotate_as_point_differences():
    pose = (0.01, 0.02, 33.0)
    a, b = np.array([0.03, 0.01]), np.array([-0.02, 0.05])
    d_F = object_to_workspace(b, pose) - object_to_workspace(a, pose)
    np.testing.assert_allclose(rotate_deg(b - a, pose[2]), d_F, atol=1e-15)


def test_rotation_matrices_agree_with_rotate_deg():
    ang = np.array([0.0, 0.3, -2.0])
    R = rotation_matrices(ang)
    assert R.shape == (3, 2, 2)
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(2), R.shape),
                               atol=1e-15)
    v = np.array([0.2, -0.1])
    for k, a in enumerate(ang):
        np.testing.assert_allclose(R[k] @ v, rotate_deg(v, math.degrees(a)), atol=1e-15)


def test_wrap_deg_scalar_and_array():
    assert wrap_deg(190.0) == -170.0 and wrap_deg(-190.0) == 170.0
    assert wrap_deg(180.0) == -180.0 and wrap_deg(0) == 0.0
    assert isinstance(wrap_deg(725.0), float)
    out = wrap_deg([0.0, 190.0, -190.0, 725.0])
    assert isinstance(out, np.ndarray)
    np.testing.assert_allclose(out, [0.0, -170.0, 170.0, 5.0])
    assert wrap_deg(np.array([])).shape == (0,)


@pytest.mark.parametrize("theta", [0.0, 30.0, -179.0, 179.5, 90.0])
def test_quaternion_yaw_round_trip(theta):
    q = quat_from_yaw_deg(theta)
    assert sum(c * c for c in q) == pytest.approx(1.0)
    assert yaw_deg_from_quat(*q) == pytest.approx(theta, abs=1e-12)
    assert tilt_deg_from_quat(*q) == pytest.approx(0.0, abs=1e-6)


def test_tilt_of_a_quarter_turn_about_x():
    h = math.sqrt(0.5)
    assert tilt_deg_from_quat(h, h, 0.0, 0.0) == pytest.approx(90.0)


def test_units_are_defined_once():
    assert INCH == 0.0254 and OZ_TO_N == pytest.approx(LB_TO_N / 16)
    assert OZ_TO_N == pytest.approx(0.278014, abs=1e-6)  # thesis 7.3: 1 oz
    # the config and the localizer use the same objects, not copies
    from graspgait_env.sim import localizer

    assert config_mod.INCH is frames.INCH and localizer.INCH is frames.INCH
    assert config_mod.LB_TO_N is frames.LB_TO_N and localizer.wrap_deg is frames.wrap_deg
