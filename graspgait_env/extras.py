"""The optional parts of the install (``pip install 'graspgait_env[EXTRA]'``) and the one
line that names a missing one.

The base install gives the map-level library, the MuJoCo hand and every Gymnasium env.
The rest comes in extras:

=============  =========================================================================
extra          what it adds, and what needs it
=============  =========================================================================
``train``      torch (a lower bound, never a pin), stable-baselines3, sb3-contrib and
               TensorBoard: ``graspgait train``, ``evaluate``, ``story``, the agents of
               ``bench``, :mod:`graspgait_env.agents`
``ray``        Ray (Tune): every ``--ray`` option
``zoo``        RL Zoo (``rl_zoo3``), with ``train``: plain PPO with the bundled
               hyper-parameters (``graspgait config rlzoo``)
``video``      imageio with its ffmpeg plugin, and moviepy (which Gymnasium's
               ``RecordVideo`` needs): ``graspgait simulate --video``, recorded videos
``benchmark``  rliable (IQM, stratified bootstrap intervals, performance profiles) and
               Minari with Arrow files and jax (its ``DataCollector``): ``graspgait
               benchmark``, ``graspgait dataset``, :mod:`graspgait_env.benchmark`
``all``        every extra above
=============  =========================================================================

This module imports none of them: it asks :func:`importlib.util.find_spec` whether they
are there, so it belongs to the pure-NumPy core.
"""

from __future__ import annotations

import importlib.util

from graspgait_env.errors import GraspGaitInputError

__all__ = ["EXTRAS", "MissingExtraError", "extra_for_module", "missing_modules",
           "require_extra"]

DISTRIBUTION = "graspgait_env"

#: Extra -> the import names it provides (checked in this order).
EXTRAS: dict[str, tuple[str, ...]] = {
    "train": ("torch", "stable_baselines3", "sb3_contrib", "tensorboard"),
    "ray": ("ray",),
    "zoo": ("rl_zoo3",),
    "video": ("imageio", "imageio_ffmpeg", "moviepy"),
    "benchmark": ("rliable", "minari", "pyarrow", "jax"),
}


class MissingExtraError(GraspGaitInputError, ImportError):
    """A feature needs an extra that is not installed; the message is one line naming the
    extra and the ``pip install`` command (the CLI prints it and exits 2).

    It is both a :class:`~graspgait_env.errors.GraspGaitInputError` and an
    :class:`ImportError`, so ``except ImportError`` in user code still catches it.
    """

    def __init__(self, extra: str, what: str, missing: list[str]) -> None:
        self.extra = extra
        self.missing = missing
        super().__init__(f"{what} needs the [{extra}] extra ({', '.join(missing)} not "
                         f"installed): pip install '{DISTRIBUTION}[{extra}]'")


def _installed(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a broken parent package, or a bare __spec__
        return False


def missing_modules(extra: str) -> list[str]:
    """The import names of ``extra`` (a key of :data:`EXTRAS`) that are not installed.

    Raises
    ------
    ValueError
        ``extra`` is not a known extra.
    """
    if extra not in EXTRAS:
        raise ValueError(f"extra={extra!r}: must be one of {', '.join(EXTRAS)}")
    return [m for m in EXTRAS[extra] if not _installed(m)]


def require_extra(extra: str, what: str) -> None:
    """Raise :class:`MissingExtraError` when a module of ``extra`` is missing.

    Parameters
    ----------
    extra
        A key of :data:`EXTRAS` (``"train"``, ``"ray"``, ``"zoo"``, ``"video"``,
        ``"benchmark"``).
    what
        What needs it, as the message's subject (``"graspgait train"``).

    Examples
    --------
    >>> require_extra("train", "graspgait train")  # doctest: +SKIP
    Traceback (most recent call last):
    MissingExtraError: graspgait train needs the [train] extra (torch, stable_baselines3,
    sb3_contrib, tensorboard not installed): pip install 'graspgait_env[train]'
    """
    missing = missing_modules(extra)
    if missing:
        raise MissingExtraError(extra, what, missing)


def extra_for_module(name: str) -> str | None:
    """The extra that provides the module ``name`` (``"torch.nn"`` -> ``"train"``), or
    None when no extra does."""
    top = name.partition(".")[0]
    for extra, modules in EXTRAS.items():
        if top in modules:
            return extra
    return None
