"""An SB3 ``VecEnv`` over the batched ``GraspGait-v0``, with ``action_masks()`` for MaskablePPO.

:class:`GraspGaitVecEnv` adapts :class:`~graspgait_env.envs.vector_env.GraspGaitVectorEnv`
(``N`` gait problems stepped in one NumPy call) to Stable-Baselines3's ``VecEnv`` API:
SB3's same-step autoreset (a finished sub-env's final observation goes to
``infos[i]["terminal_observation"]`` and the returned row is already the next episode's
first), ``dones`` = terminated or truncated, ``infos[i]["TimeLimit.truncated"]``, and
rewards as float32, as ``DummyVecEnv`` gives them. sb3-contrib's ``MaskablePPO`` reads
the legal moves through ``env_method("action_masks")`` (one ``(N, A)`` batch).

:func:`make_batched_vec_env` is the batched counterpart of SB3's ``make_vec_env`` for
``GraspGait-v0``: seeded like it (sub-env ``i`` gets ``seed + i``) and wrapped in
``VecMonitor`` (episode returns and lengths for SB3's logs).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from stable_baselines3.common.vec_env import VecEnv, VecMonitor

from graspgait_env.envs.registration import MAX_EPISODE_STEPS
from graspgait_env.envs.vector_env import GraspGaitVectorEnv
from graspgait_env.errors import GraspGaitInputError

__all__ = ["GraspGaitVecEnv", "make_batched_vec_env"]

# what SB3 writes into a finished sub-env's info (DummyVecEnv's keys), plus the success
# flag that SB3's logger reads at episode ends
_DONE_KEYS = ("terminal_observation", "TimeLimit.truncated", "is_success")


class GraspGaitVecEnv(VecEnv):
    """SB3 ``VecEnv`` over :class:`GraspGaitVectorEnv`; masks for MaskablePPO.

    Parameters
    ----------
    venv
        The batched env (its observation buffer is read without a copy and copied once
        per step here).

    Notes
    -----
    ``infos[i]`` is empty except at the step where sub-env ``i``'s episode ends, when it
    holds ``terminal_observation``, ``TimeLimit.truncated`` and ``is_success`` (the keys
    SB3 reads); the batched env's full info dict of the last step is
    :attr:`last_info`. ``seed(s)`` takes effect at the next ``reset()`` (sub-env ``i``
    gets ``s + i``), as for every SB3 ``VecEnv``. ``get_attr`` reads the shared config
    and model (``"config"``, ``"model"``, ``"beta"``, ...); ``set_attr`` is refused (the
    config is frozen); ``env_method`` serves ``"action_masks"``.
    """

    def __init__(self, venv: GraspGaitVectorEnv) -> None:
        if not isinstance(venv, GraspGaitVectorEnv):
            raise GraspGaitInputError(
                f"venv={venv!r}: give a GraspGaitVectorEnv, e.g. gymnasium.make_vec("
                "'graspgait_env:GraspGait-v0', num_envs=8, vectorization_mode="
                "'vector_entry_point').unwrapped, or use make_batched_vec_env(8)")
        venv.copy = False  # one copy per step, made here
        self.venv = venv
        super().__init__(venv.num_envs, venv.single_observation_space,
                         venv.single_action_space)
        self.metadata = {"render_modes": []}
        self.render_mode = None
        self.last_info: dict[str, Any] = {}
        self._actions: NDArray[np.int64] | None = None

    # ------------------------------------------------------------------ VecEnv API
    def reset(self) -> NDArray[np.float32]:
        """Reset every sub-env with the seeds and options set since the last reset."""
        opts = self._options
        if all(o == opts[0] for o in opts):
            obs, info = self.venv.reset(seed=self._seeds, options=opts[0] or None)
            self.reset_infos = [self._info_row(info, i) for i in range(self.num_envs)]
        else:  # options differ by sub-env: one reset each, in order
            for i, o in enumerate(opts):
                m = np.zeros(self.num_envs, dtype=bool)
                m[i] = True
                obs, info = self.venv.reset(seed=self._seeds, options={**o, "reset_mask": m})
                self.reset_infos[i] = self._info_row(info, i)
        self._reset_seeds()
        self._reset_options()
        self.last_info = info
        return _copy(obs)

    def step_async(self, actions: np.ndarray) -> None:
        """Store the actions (one per sub-env) for :meth:`step_wait`."""
        self._actions = actions

    def step_wait(self) -> tuple[NDArray[np.float32], NDArray[np.float32],
                                 NDArray[np.bool_], list[dict[str, Any]]]:
        """Step every sub-env; finished ones restart at once (SB3's autoreset)."""
        obs, reward, terminated, truncated, info = self.venv.step(self._actions)
        done = terminated | truncated
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        if done.any():
            idx = np.flatnonzero(done)
            success = info["is_success"]
            for i in idx.tolist():
                infos[i] = {"terminal_observation": _copy(obs, i),
                            "TimeLimit.truncated": bool(truncated[i] and not terminated[i]),
                            "is_success": bool(success[i])}
            # every row, the restarted ones their next episode's (a fresh dict of parts
            # with observation_mode "dict"; the same buffer with "box")
            obs, reset_info = self.venv.reset(options={"reset_mask": done})
            for i in idx.tolist():
                self.reset_infos[i] = self._info_row(reset_info, i)
        self.last_info = info
        return _copy(obs), reward.astype(np.float32), done, infos

    def close(self) -> None:
        """Close the batched env."""
        self.venv.close()

    def action_masks(self) -> NDArray[np.bool_]:
        """Legal actions of every sub-env, ``(N, A)`` bool (MaskablePPO's protocol)."""
        return self.venv.action_masks()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """``attr_name`` of each sub-env in ``indices`` (all by default).

        ``"action_masks"`` gives each sub-env's mask function; other names are read
        from the shared template env (config fields, ``model``, ``layout``, ...).

        Raises
        ------
        AttributeError
            No such attribute.
        """
        idx = list(self._get_indices(indices))
        if attr_name == "action_masks":
            return [(lambda i=i: self.venv.action_masks()[i]) for i in idx]
        value = getattr(self.venv.template, attr_name)
        return [value for _ in idx]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        """Refused: the sub-envs share one frozen config."""
        raise GraspGaitInputError(
            f"set_attr({attr_name!r}): the batched GraspGait env's sub-envs share one frozen "
            "config; make a new env with the value instead")

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None,
                   **method_kwargs: Any) -> list[Any]:
        """``"action_masks"``: each sub-env's mask (rows of :meth:`action_masks`).

        Raises
        ------
        GraspGaitInputError
            Any other method (the sub-envs are rows of one batched env).
        """
        if method_name != "action_masks":
            raise GraspGaitInputError(
                f"env_method({method_name!r}): the batched GraspGait env serves only "
                "'action_masks'; its sub-envs are rows of one array")
        masks = self.venv.action_masks()
        return [masks[i] for i in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        """No sub-env is wrapped (there are no per-env objects to wrap)."""
        return [False for _ in self._get_indices(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        """No images: the batched env draws nothing."""
        return [None for _ in range(self.num_envs)]

    @staticmethod
    def _info_row(info: Mapping[str, Any], i: int) -> dict[str, Any]:
        """Sub-env ``i``'s entries of a batched info dict (where its ``_key`` mask is set)."""
        return {k: v[i] for k, v in info.items()
                if not k.startswith("_") and not isinstance(v, dict) and info["_" + k][i]}


def _copy(obs: Any, row: int | None = None) -> Any:
    """A copy of a batch of observations (an array, or a dict of parts with
    ``observation_mode="dict"``), or of its row ``row``."""
    if isinstance(obs, dict):
        return {k: _copy(v, row) for k, v in obs.items()}
    return np.array(obs if row is None else obs[row], copy=True)


def make_batched_vec_env(n_envs: int, seed: int | None = None,
                         env_kwargs: Mapping[str, Any] | None = None,
                         max_episode_steps: int | None = MAX_EPISODE_STEPS,
                         monitor: bool = True, env_id: str = "GraspGait-v0") -> VecEnv:
    """``GraspGait-v0`` (or ``GraspGaitRandom-v0``) batched for SB3: the counterpart of
    ``make_vec_env`` + Monitor.

    Parameters
    ----------
    n_envs
        Number of sub-envs.
    seed
        Sub-env ``i`` is reset with ``seed + i`` at the first ``reset()`` (None: fresh
        entropy), as SB3's ``make_vec_env`` seeds.
    env_kwargs
        The id's keyword arguments (``object``, ``mu``, GraspGaitConfig fields; for
        ``GraspGaitRandom-v0`` ``level``, ``mu_range``, ...).
    max_episode_steps
        The time limit (500, the registered one).
    monitor
        Wrap in ``VecMonitor`` (episode returns, lengths and success in SB3's logs).
    env_id
        ``GraspGait-v0`` (:class:`GraspGaitVectorEnv`) or ``GraspGaitRandom-v0``
        (:class:`~graspgait_env.envs.vector_env.GraspGaitRandomVectorEnv`, each sub-env
        its own objects).

    Returns
    -------
    VecEnv
        :class:`GraspGaitVecEnv`, in ``VecMonitor`` when ``monitor``.
    """
    from graspgait_env.envs.vector_env import GraspGaitRandomVectorEnv

    classes = {"GraspGait-v0": GraspGaitVectorEnv, "GraspGaitRandom-v0": GraspGaitRandomVectorEnv}
    if env_id not in classes:
        raise GraspGaitInputError(f"env_id={env_id!r}: the batched envs are "
                                  f"{', '.join(classes)}; use SB3's make_vec_env for others")
    venv = classes[env_id](n_envs, max_episode_steps=max_episode_steps,
                           **dict(env_kwargs or {}))
    env: VecEnv = GraspGaitVecEnv(venv)
    if seed is not None:
        env.seed(seed)
    if monitor:
        env = VecMonitor(env, info_keywords=("is_success",))
    return env
