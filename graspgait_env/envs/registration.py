"""Register every GraspGait environment id with Gymnasium (one place, string entry points).

``register_envs()`` is idempotent and cheap: it imports no environment module (entry
points are strings, loaded by ``gymnasium.make``). ``import graspgait_env`` calls it, so
``gymnasium.make("graspgait_env:GraspGait-v0")`` works in a fresh interpreter; without
Gymnasium installed it does nothing (the map-level core needs only NumPy).
"""

from __future__ import annotations

__all__ = ["ENV_IDS", "MAX_EPISODE_STEPS", "VECTOR_ENTRY_POINTS", "register_envs"]

MAX_EPISODE_STEPS = 500  # (steps) time limit of every id; a thesis gait needs 20-40 moves

# id -> entry point
ENV_IDS: dict[str, str] = {
    "GraspGait-v0": "graspgait_env.envs.map_env:GraspGaitEnv",
    "GraspGaitRandom-v0": "graspgait_env.envs.random_env:GraspGaitRandomEnv",
    "GraspGaitMujoco-v1": "graspgait_env.envs.mujoco_env:GraspGaitMujocoEnv",
}

# id -> batched env: `gymnasium.make_vec(id, num_envs=N, vectorization_mode=
# "vector_entry_point")` steps N copies in one NumPy call (other modes: "sync", "async")
VECTOR_ENTRY_POINTS: dict[str, str] = {
    "GraspGait-v0": "graspgait_env.envs.vector_env:GraspGaitVectorEnv",
    "GraspGaitRandom-v0": "graspgait_env.envs.vector_env:GraspGaitRandomVectorEnv",
}


def register_envs() -> list[str]:
    """Register the ids of :data:`ENV_IDS` not yet in Gymnasium's registry.

    Returns
    -------
    list of str
        The ids registered by this call (empty when all were already there, or when
        Gymnasium is not installed).
    """
    try:
        import gymnasium
    except ImportError:  # the NumPy-only core works without it
        return []
    done = []
    for env_id, entry_point in ENV_IDS.items():
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(id=env_id, entry_point=entry_point,
                           vector_entry_point=VECTOR_ENTRY_POINTS.get(env_id),
                           max_episode_steps=MAX_EPISODE_STEPS)
        done.append(env_id)
    return done
