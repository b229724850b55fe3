"""Gymnasium environments over the map-level gait model (and, later, the physics level).

Ids (registered by :func:`register_envs`, which ``import graspgait_env`` calls):

- ``GraspGait-v0`` (:class:`GraspGaitEnv`): one object, set by keyword arguments.
- ``GraspGaitRandom-v0`` (:class:`GraspGaitRandomEnv`): a new object and friction at
  every reset, by difficulty level.
- ``GraspGaitMujoco-v1`` (:class:`GraspGaitMujocoEnv`): the same spaces, each move
  executed on the MuJoCo hand by the thesis controller (ch. 7).

The keyword arguments the three ids share are one frozen dataclass,
:class:`GraspGaitConfig` (``config=`` or its fields as keywords). The environment
classes are imported lazily (``from graspgait_env.envs import GraspGaitEnv`` works), so
importing this package costs no more than Gymnasium's registry.
"""

from __future__ import annotations

from typing import Any

from graspgait_env.envs.registration import ENV_IDS, register_envs

__all__ = [
    "ENV_IDS",
    "GraspGaitConfig",
    "GraspGaitEnv",
    "GraspGaitMujocoEnv",
    "GraspGaitRandomEnv",
    "ResetNeededError",
    "register_envs",
    "state_from_observation",
]

_LAZY = {
    "GraspGaitConfig": "graspgait_env.envs.config",
    "GraspGaitEnv": "graspgait_env.envs.map_env",
    "ResetNeededError": "graspgait_env.envs.map_env",
    "state_from_observation": "graspgait_env.envs.map_env",
    "GraspGaitRandomEnv": "graspgait_env.envs.random_env",
    "GraspGaitMujocoEnv": "graspgait_env.envs.mujoco_env",
}

register_envs()


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'graspgait_env.envs' has no attribute {name!r}")
