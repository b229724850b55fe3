"""Making the environments an agent trains and is evaluated in, from an id and keywords."""

from __future__ import annotations

import importlib
from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym

from graspgait_env.envs.config import GraspGaitConfig
from graspgait_env.envs.registration import ENV_IDS
from graspgait_env.errors import GraspGaitInputError

__all__ = ["import_object", "make_env", "env_kwargs_for", "contact_model_of"]

# keyword arguments only GraspGaitRandom-v0 takes (it draws object and mu itself)
RANDOM_ONLY = ("level", "mu_range", "object_seeds", "exclude_seeds", "bundled_fraction",
               "episodes_per_object")
# keyword arguments only GraspGaitMujoco-v1 takes
MUJOCO_ONLY = ("sim_config", "pose_noise")


def import_object(path: str, what: str = "wrappers") -> Any:
    """The object named by ``"package.module:Name"`` or ``"package.module.Name"``.

    Raises
    ------
    GraspGaitInputError
        The module or the name cannot be found (the message names ``what`` and the path).
    """
    module, sep, name = path.partition(":")
    if not sep:
        module, _, name = path.rpartition(".")
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError, ValueError) as exc:
        raise GraspGaitInputError(f"{what}={path!r}: cannot import it ({exc}); give "
                                  "'package.module:Name', e.g. "
                                  "'graspgait_env.agents.wrappers:LegalActionWrapper'") from None


def make_env(env_id: str, env_kwargs: Mapping[str, Any] | None = None,
             wrappers: Sequence[str] = (), render_mode: str | None = None) -> gym.Env:
    """``gymnasium.make(env_id, **env_kwargs)`` (time limit included) with ``wrappers``.

    Parameters
    ----------
    env_id
        A GraspGait id (``GraspGait-v0``, ``GraspGaitRandom-v0``, ``GraspGaitMujoco-v1``).
    env_kwargs
        Its keyword arguments (checked by the env: a bad one raises
        :class:`~graspgait_env.errors.GraspGaitInputError` naming it).
    wrappers
        Import paths of Gymnasium wrappers, applied innermost first.
    render_mode
        Passed to ``gymnasium.make``.
    """
    if env_id not in ENV_IDS:
        raise GraspGaitInputError(f"env_id={env_id!r}: not a GraspGait id; use one of "
                                  f"{', '.join(ENV_IDS)}")
    kwargs = dict(env_kwargs or {})
    if render_mode is not None:
        kwargs["render_mode"] = render_mode
    env = gym.make(env_id, **kwargs)
    for path in wrappers:
        env = import_object(path)(env)
    return env


def env_kwargs_for(env_id: str, trained_id: str, trained_kwargs: Mapping[str, Any],
                   object: Any = None, mu: float | None = None, *,  # noqa: A002
                   contact_model: str | None = None) -> dict[str, Any]:
    """The keyword arguments for ``env_id``, from those a model was trained with.

    The GraspGaitConfig fields (hand, grid, rewards, map window) and ``contact_model``
    carry over unchanged, so the observation means what it meant in training; the
    trained env's ``contact_model`` (the model card's) is passed explicitly when the
    keywords do not name one, since ids differ in their default (``GraspGaitMujoco-v1``
    plans for the hand, the others for point contacts). Keywords
    of the training id that ``env_id`` does not take are dropped
    (``GraspGaitRandom-v0``'s ``level``, ``mu_range``, ... when evaluating on one object;
    ``GraspGaitMujoco-v1``'s ``sim_config``, ``pose_noise`` elsewhere). ``object`` and
    ``mu``, when given, replace the trained ones (refused for ``GraspGaitRandom-v0``,
    which draws both at every reset).

    Raises
    ------
    GraspGaitInputError
        ``object`` or ``mu`` given for ``GraspGaitRandom-v0``.
    """
    kw = dict(trained_kwargs)
    if env_id != trained_id:
        drop = (RANDOM_ONLY if trained_id == "GraspGaitRandom-v0" else ()) + (
            MUJOCO_ONLY if trained_id == "GraspGaitMujoco-v1" else ())
        if env_id == "GraspGaitRandom-v0":
            drop = drop + ("object", "mu")
        kw = {k: v for k, v in kw.items() if k not in drop}
    if env_id == "GraspGaitRandom-v0" and (object is not None or mu is not None):
        raise GraspGaitInputError(
            f"--object/--mu with --env {env_id}: it draws the object and mu at every reset; "
            "use --env GraspGait-v0 (or GraspGaitMujoco-v1) to evaluate on one object")
    if object is not None:
        kw["object"] = object
    if mu is not None:
        kw["mu"] = mu
    if contact_model is not None and "contact_model" not in kw and (
            "contact_model" in GraspGaitConfig.field_names()):
        kw["contact_model"] = contact_model
    return kw


def contact_model_of(env: gym.Env) -> str:
    """The env's contact model name (``"point"`` when the env predates contact models)."""
    u = env.unwrapped
    cm = getattr(getattr(u, "config", None), "contact_model", None)
    if cm is None:
        cm = getattr(getattr(u, "model", None), "contact_model", None)
    if cm is None:
        return "point"
    return str(getattr(cm, "name", cm))
