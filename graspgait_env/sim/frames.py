"""Frames and units of the simulated hand, in one place (thesis 7.2, 7.4.2, 7.4.5).

Frames (thesis 7.4.5): ``F`` is the fixed workspace frame (the palm, = the MuJoCo world);
the object frame ``f`` sits at pose ``(x, y, theta_deg)`` in ``F`` (metres, metres,
degrees; positive angles are counter-clockwise). A point ``p_f`` of the object lies at
``p_F = (x, y) + R(theta) p_f`` in ``F``, and ``p_f = R(-theta) (p_F - (x, y))``.
The thesis's expected, trial and actual frames ``E``, ``T``, ``A`` are three such poses.

Units: the code works in SI (metres, newtons, seconds) with angles in degrees in every
public argument; the thesis gives inches, ounces and pounds, converted here.

Every helper evaluates its formula in one fixed order (the executor's results are
compared bit for bit across refactors), with :func:`math.cos` and :func:`math.sin` on the
one angle of a pose.

Examples
--------
>>> p = object_to_workspace([[0.1, 0.0]], (0.01, 0.0, 90.0))
>>> np.round(p, 12).tolist()
[[0.01, 0.1]]
>>> np.round(workspace_to_object(p, (0.01, 0.0, 90.0)), 12).tolist()
[[0.1, 0.0]]
>>> wrap_deg(190.0), wrap_deg(-180.0)
(-170.0, -180.0)
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "INCH",
    "LB_TO_N",
    "OZ_TO_N",
    "wrap_deg",
    "rotation_cs",
    "rotate_deg",
    "rotation_matrices",
    "object_to_workspace",
    "workspace_to_object",
    "yaw_deg_from_quat",
    "tilt_deg_from_quat",
    "quat_from_yaw_deg",
]

INCH = 0.0254  # (m per inch)
LB_TO_N = 4.448222  # (N per pound-force)
OZ_TO_N = LB_TO_N / 16.0  # (N per ounce-force)


def wrap_deg(angle_deg: ArrayLike) -> float | NDArray[np.float64]:
    """Angle (degrees) wrapped to [-180, 180): a float for a scalar, else an array.

    >>> wrap_deg(540.0), wrap_deg([0.0, 190.0, -190.0]).tolist()
    (-180.0, [0.0, -170.0, 170.0])
    """
    if isinstance(angle_deg, (float, int)) and not isinstance(angle_deg, bool):
        return (angle_deg + 180.0) % 360.0 - 180.0
    return np.mod(np.asarray(angle_deg, dtype=np.float64) + 180.0, 360.0) - 180.0


def rotation_cs(theta_deg: float) -> tuple[float, float]:
    """``(cos, sin)`` of ``theta_deg`` (degrees): the rotation ``R(theta)``'s entries."""
    t = math.radians(theta_deg)
    return math.cos(t), math.sin(t)


def rotate_deg(v: ArrayLike, theta_deg: float) -> NDArray[np.float64]:
    """Vectors ``v`` (..., 2) turned counter-clockwise by ``theta_deg``: directions of
    frame ``f`` (an inward normal) in ``F`` for an object at angle ``theta_deg``."""
    c, s = rotation_cs(theta_deg)
    v = np.asarray(v, dtype=np.float64)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def rotation_matrices(angles_rad: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices ``(..., 2, 2)`` for angles in **radians** (the trajectory
    planner's arcs, thesis 7.4.2)."""
    a = np.asarray(angles_rad, dtype=np.float64)
    c, s = np.cos(a), np.sin(a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def object_to_workspace(p_f: ArrayLike, pose: ArrayLike) -> NDArray[np.float64]:
    """Points ``p_f`` (..., 2) of the object frame ``f`` in ``F``, the object at
    ``pose`` ``(x, y, theta_deg)``: ``(x, y) + R(theta) p_f``."""
    c, s = rotation_cs(pose[2])
    p = np.asarray(p_f, dtype=np.float64)
    return np.stack([pose[0] + c * p[..., 0] - s * p[..., 1],
                     pose[1] + s * p[..., 0] + c * p[..., 1]], axis=-1)


def workspace_to_object(p_F: ArrayLike, pose: ArrayLike) -> NDArray[np.float64]:
    """Points ``p_F`` (..., 2) of ``F`` in the frame ``f`` of an object at ``pose``
    ``(x, y, theta_deg)``: ``R(-theta) (p_F - (x, y))``."""
    c, s = rotation_cs(pose[2])
    d = np.asarray(p_F, dtype=np.float64) - np.asarray(pose[:2], dtype=np.float64)
    return np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], axis=-1)


def yaw_deg_from_quat(w: float, x: float, y: float, z: float) -> float:
    """Rotation about the vertical (deg, in (-180, 180]) of a unit quaternion
    ``(w, x, y, z)`` (MuJoCo's order): the planar angle of a body on the table."""
    return math.degrees(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


def tilt_deg_from_quat(w: float, x: float, y: float, z: float) -> float:
    """Angle (deg) between a body's z axis and the vertical, for the unit quaternion
    ``(w, x, y, z)``."""
    zz = 1 - 2 * (x * x + y * y)
    return math.degrees(math.acos(max(-1.0, min(1.0, zz))))


def quat_from_yaw_deg(theta_deg: float) -> tuple[float, float, float, float]:
    """Unit quaternion ``(w, x, y, z)`` of a rotation by ``theta_deg`` about the vertical."""
    t = math.radians(theta_deg) / 2.0
    return math.cos(t), 0.0, 0.0, math.sin(t)
