"""Bundled data files: objects, hands and simulation configs shipped with the package.

They live in the package folder ``graspgait_env/configs/`` (the package
``graspgait_env.configs``), so a wheel or a non-editable install carries every YAML file,
and an editable install reads them from the checkout. Code never builds a path from
``__file__`` to reach them: it asks this module, which goes through
:mod:`importlib.resources`.

Layout (``KIND/NAME.yaml``): ``objects/`` (object files), ``hands/`` (hand files),
``sim/`` (simulation configs), ``train/`` (training configs of ``graspgait train``),
``rlzoo/`` (RL Zoo hyper-parameters, ``NAME.yml`` as RL Zoo names them).
``graspgait config KIND NAME`` prints one.

>>> from graspgait_env.resources import bundled_names
>>> "ellipse" in bundled_names("objects")
True
"""

from __future__ import annotations

import importlib.resources
from pathlib import Path

__all__ = ["CONFIG_PACKAGE", "KINDS", "bundled_file", "bundled_names", "config_dir"]

CONFIG_PACKAGE = "graspgait_env.configs"
KINDS = ("objects", "hands", "sim", "train", "rlzoo")
_SUFFIX = {"rlzoo": ".yml"}  # RL Zoo's own extension; every other kind is .yaml


def config_dir(kind: str) -> Path:
    """The folder of bundled ``kind`` files (one of :data:`KINDS`).

    Raises
    ------
    ValueError
        ``kind`` is not one of :data:`KINDS`.
    RuntimeError
        The package data is missing or not on a file system (a zipped install): reinstall
        the package with pip.
    """
    if kind not in KINDS:
        raise ValueError(f"kind={kind!r}: must be one of {', '.join(KINDS)}")
    try:
        root = importlib.resources.files(CONFIG_PACKAGE)
    except ModuleNotFoundError:
        raise RuntimeError(f"package data {CONFIG_PACKAGE!r} is missing from this install; "
                           "reinstall graspgait_env with pip") from None
    folder = root / kind
    if not isinstance(folder, Path):
        raise RuntimeError(f"package data {CONFIG_PACKAGE!r} is not on a file system "
                           f"({type(folder).__name__}); install graspgait_env unzipped")
    return folder


def bundled_names(kind: str) -> list[str]:
    """Names (file stems, sorted) of the bundled ``kind`` files, e.g. ``["circle", ...]``."""
    return sorted(p.stem for p in config_dir(kind).glob(f"*{_SUFFIX.get(kind, '.yaml')}"))


def bundled_file(kind: str, name: str) -> Path | None:
    """The bundled file ``KIND/NAME.yaml`` (``.yml`` for ``rlzoo``), or None when there is
    none of that name."""
    path = config_dir(kind) / f"{name}{_SUFFIX.get(kind, '.yaml')}"
    return path if path.is_file() else None
