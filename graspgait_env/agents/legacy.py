"""Models, cards and configs saved before graspgait_env 0.2, when ``agents`` and
``baselines`` installed as top-level import packages.

Since 0.2 the package has one import name: ``agents/`` and ``baselines/`` of the
repository install as :mod:`graspgait_env.agents` and :mod:`graspgait_env.baselines`.
Three things written by 0.1 still name the old packages, and each is read here:

- a model zip: stable-baselines3 pickles the policy class and the features extractor by
  module (``agents.policies``); :func:`legacy_module_names` lets them unpickle;
- a model card: ``config.policy``, ``config.features_extractor`` and ``wrappers`` are
  import paths (``"agents.policies:GraspMapExtractor"``); :func:`upgrade_card` rewrites
  them;
- a training config YAML of a user: :func:`upgrade_import_path` rewrites the same paths
  (with a :class:`DeprecationWarning`, since the file should be updated).

A user's own top-level ``agents`` or ``baselines`` package, if one is installed, is left
alone: the old names are mapped only while a model is unpickled, and what was in
:data:`sys.modules` under them before is put back afterwards.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import re
import sys
import warnings
from collections.abc import Iterator
from typing import Any

__all__ = ["LEGACY_PACKAGES", "legacy_module_names", "upgrade_card", "upgrade_import_path"]

#: Old top-level import name -> its place since graspgait_env 0.2.
LEGACY_PACKAGES: dict[str, str] = {
    "agents": "graspgait_env.agents",
    "baselines": "graspgait_env.baselines",
}

_LEGACY_PATH = re.compile(r"^(agents|baselines)(?=[.:]|$)")


def upgrade_import_path(path: str, *, warn: bool = False) -> str:
    """``path`` with a 0.1 package name replaced: ``"agents.policies:X"`` ->
    ``"graspgait_env.agents.policies:X"``; any other path is returned unchanged.

    With ``warn``, a rewritten path emits a :class:`DeprecationWarning` naming the new one.
    """
    new = _LEGACY_PATH.sub(lambda m: LEGACY_PACKAGES[m.group(1)], path)
    if warn and new != path:
        warnings.warn(f"import path {path!r} names a package of graspgait_env 0.1; it is "
                      f"{new!r} now: update the config", DeprecationWarning, stacklevel=3)
    return new


def upgrade_card(card: Any) -> Any:
    """A copy of ``card`` (a model card, or any JSON value) with every string that is a
    0.1 import path (:func:`upgrade_import_path`) rewritten; nothing else changes."""
    if isinstance(card, dict):
        return {k: upgrade_card(v) for k, v in card.items()}
    if isinstance(card, list):
        return [upgrade_card(v) for v in card]
    if isinstance(card, str) and _LEGACY_PATH.match(card) and " " not in card:
        return upgrade_import_path(card)
    return card


class _AliasFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports ``agents.X`` as the module ``graspgait_env.agents.X`` (the same object)."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None
                  ) -> importlib.machinery.ModuleSpec | None:
        top, _, _ = fullname.partition(".")
        if top not in LEGACY_PACKAGES:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def __init__(self) -> None:
        self._real_specs: dict[str, importlib.machinery.ModuleSpec] = {}

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> Any:
        top, dot, rest = spec.name.partition(".")
        module = importlib.import_module(LEGACY_PACKAGES[top] + dot + rest)
        self._real_specs[module.__name__] = module.__spec__
        return module

    def exec_module(self, module: Any) -> None:
        # already executed under its real name; the import system has just set the alias
        # spec on it, so put the real one back (a package must keep its search path)
        module.__spec__ = self._real_specs.pop(module.__name__)


def _legacy_keys() -> list[str]:
    return [k for k in sys.modules if k.partition(".")[0] in LEGACY_PACKAGES]


@contextlib.contextmanager
def legacy_module_names() -> Iterator[None]:
    """While inside, ``import agents.policies`` gives :mod:`graspgait_env.agents.policies`
    (and likewise for ``baselines``), so a model pickled by 0.1 unpickles. On exit
    :data:`sys.modules` holds under those names exactly what it held before."""
    saved = {k: sys.modules.pop(k) for k in _legacy_keys()}
    finder = _AliasFinder()
    sys.meta_path.insert(0, finder)
    try:
        yield
    finally:
        sys.meta_path.remove(finder)
        for k in _legacy_keys():
            del sys.modules[k]
        sys.modules.update(saved)
