"""Saved agents: the SB3 ``.zip`` and its model card, a JSON file beside it.

Every model ``graspgait train`` writes (final model, best model, checkpoints) is a pair
``NAME.zip`` + ``NAME.json``. The card says what the model is and how to run it again:

- ``format``: ``"graspgait-model-card/1"``;
- ``algo`` (``maskable_ppo`` | ``ppo``), ``env_id``, ``env_kwargs`` (object, mu,
  contact model, reward weights, ...), ``wrappers``, ``contact_model`` (the env's,
  ``"point"`` before contact models existed);
- ``config`` (every :class:`~graspgait_env.agents.config.TrainConfig` field), ``seed``, ``steps``
  (environment steps trained), ``wall_s`` (training wall time, seconds), ``run_dir``;
- ``init`` (a run started from ``init_model`` only): ``{model, steps, wall_s}``, the
  training behind the weights it started from;
- ``eval``: the latest periodic evaluation (success rates, regrasps against the
  optimum), when there was one;
- ``versions``: graspgait_env, stable-baselines3, sb3-contrib, torch, gymnasium, Python;
  ``created`` (UTC, ISO 8601).

:func:`load_agent` reads both back. A ``.zip`` without a card loads too: one saved by
RL Zoo gets a card made from RL Zoo's saved hyper-parameters (env id, env keywords,
``env_wrapper``); any other gets a card with only ``algo``.
"""

from __future__ import annotations

import difflib
import importlib.resources
import json
import os
import platform
import zipfile
from collections.abc import Mapping
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import yaml

from graspgait_env.agents.legacy import legacy_module_names, upgrade_card
from graspgait_env.atomic import atomic_write, write_text_atomic
from graspgait_env.envs.procedural import EVAL_SEEDS
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.extras import require_extra

__all__ = ["CARD_FORMAT", "RETIRED_AGENTS", "card_path", "describe_shipped", "load_agent",
           "read_card", "resolve_model", "retired_message", "save_agent", "shipped_agents",
           "shipped_models_dir", "versions"]

CARD_FORMAT = "graspgait-model-card/1"

RETIRED_AGENTS: dict[str, str] = {
    "ellipse": "retired after graspgait_env 0.2.0: over 5 seeds on the ellipse's three benchmark "
               "tasks the shipped agent general scores as well (IQM 100.0 [100.0, 100.0] "
               "against the ellipse recipe's 100.0 [100.0, 100.0])",
    "pentagon": "retired after graspgait_env 0.2.0: over 5 seeds on the pentagon's three "
                "benchmark tasks the shipped agent general scores as well (IQM 100.0 [100.0, "
                "100.0] against the pentagon recipe's 100.0 [99.4, 100.0])",
    "hexagon": "retired after graspgait_env 0.2.0: over 5 seeds on the hexagon's three "
               "benchmark tasks its recipe is not measurably better than the shipped agent "
               "general by the cards' rule (IQM 99.1 [98.4, 99.8] against 93.3 [81.8, 99.6], "
               "inside general's interval), although general is the weaker there (its seed "
               "0 fails from 3 of 30 map-level hexagon starts)",
    "random": "retired after graspgait_env 0.2.0: on the benchmark's held-out procedural "
              "objects (random-l1, 5 seeds) both its shipped run and its recipe score below "
              "the shipped agent general (IQM 97.8 [95.8, 98.3] and 97.4 [96.2, 98.0] "
              "against 99.8 [99.5, 100.0])",
}
"""Shipped agents that are no longer shipped, by name: why (one clause). A per-object
agent stays shipped only where it is measurably better than ``general`` on its object over
5 seeds (docs/agents.md); asking for a retired one by name raises an error that says so
and names the replacement (:func:`retired_message`): ``general`` on the same object, or
for ``random``, the generalist trained on the same procedural objects, ``general`` on
them. Its training config stays bundled (``graspgait train ellipse`` still trains the
recipe)."""

_HELD_OUT = (f"--set 'object_seeds=[{EVAL_SEEDS[0]},{EVAL_SEEDS[1]}]' "
             "--set exclude_seeds=null --set bundled_fraction=0")
"""The ``--set``s that draw ``GraspGaitRandom-v0``'s objects from its held-out seeds
alone (:data:`graspgait_env.envs.procedural.EVAL_SEEDS`)."""

_INSTEAD: dict[str, str] = {
    # not a per-object agent: general on the same procedural objects, or on a file
    "random": ("use general instead, trained on the same procedural objects (`graspgait "
               f"evaluate general --episodes 300 --seed 20000 {_HELD_OUT}` on held-out "
               "ones, `graspgait evaluate general --object FILE` on yours)"),
}
"""The replacement of a retired agent that is not ``general`` on its own object."""


def retired_message(name: str, field: str = "MODEL") -> str | None:
    """The error for asking for the retired shipped agent ``name`` (``None`` when ``name``
    is not a retired agent): why it was retired and the command that replaces it."""
    why = RETIRED_AGENTS.get(name)
    if why is None:
        return None
    instead = (_INSTEAD[name] if name in _INSTEAD else
               f"use general on that object instead (`graspgait evaluate general "
               f"--object {name}`, `graspgait story general --object {name}`)")
    return (f"{field} {name!r}: the shipped agent {name!r} was {why}; {instead}, or train "
            f"the recipe yourself with `graspgait train {name}` and give its model.zip")


def shipped_models_dir() -> Path:
    """The folder of the shipped models (package data of :mod:`graspgait_env.agents`,
    ``agents/models/`` in the repository): ``NAME.zip``, its card ``NAME.json`` and its
    Markdown card ``NAME.md``."""
    return Path(str(importlib.resources.files("graspgait_env.agents") / "models"))


def shipped_agents() -> list[str]:
    """Names of the shipped agents (``["circle", "general", ...]``), sorted: the stems of
    the model zips in :func:`shipped_models_dir` that have a card beside them."""
    folder = shipped_models_dir()
    return sorted(p.stem for p in folder.glob("*.zip") if card_path(p).is_file())


def describe_shipped() -> list[tuple[str, str]]:
    """``(name, one line)`` per shipped agent: its env id, object or level, and the
    figures of its card's latest evaluation (success over the starts with a gait,
    regrasps against the optimum)."""
    rows = []
    for name in shipped_agents():
        card = read_card(shipped_models_dir() / f"{name}.zip")
        kw = card.get("env_kwargs") or {}
        what = (f"object {kw['object']}" if "object" in kw
                else f"level {kw['level']}" if "level" in kw else "")
        ev = card.get("eval") or {}
        figs = []
        if ev.get("success_rate_solvable") is not None:
            figs.append(f"{ev['success_rate_solvable']:.0%} of the starts with a gait")
        if ev.get("regrasps_vs_optimal") is not None:
            figs.append(f"{ev['regrasps_vs_optimal']:.3f}x the optimum")
        line = ", ".join(x for x in (card.get("env_id", "?"), what, *figs) if x)
        rows.append((name, line))
    return rows


def resolve_model(spec: str | os.PathLike[str]) -> Path:
    """A model's path: ``spec`` as a path when it names a file (``.zip`` optional), else a
    shipped agent's name (``"circle"`` -> the installed package's ``models/circle.zip``).

    Raises
    ------
    GraspGaitInputError
        Neither a file nor a shipped agent; the message lists the shipped agents. For a
        retired agent's name (:data:`RETIRED_AGENTS`), the message says why it was retired
        and names its replacement.
    """
    path = Path(spec)
    if path.is_file():
        return path
    if path.suffix != ".zip" and path.with_suffix(".zip").is_file():
        return path.with_suffix(".zip")
    if len(path.parts) == 1:
        name = path.stem if path.suffix == ".zip" else path.name
        shipped = shipped_models_dir() / f"{name}.zip"
        if shipped.is_file():
            return shipped
        retired = retired_message(name)
        if retired is not None:
            raise GraspGaitInputError(retired)
    names = shipped_agents()
    near = difflib.get_close_matches(str(spec), names, n=1)
    hint = f"did you mean {near[0]!r}? " if near else ""
    raise GraspGaitInputError(
        f"MODEL {str(spec)!r}: no such file and no shipped agent of that name; {hint}give a "
        f"shipped agent ({', '.join(names) or 'none in this install'}; `graspgait evaluate "
        "--list` describes them) or the path of a .zip saved by `graspgait train` (its "
        "run folder's model.zip)")


def card_path(model_path: str | os.PathLike[str]) -> Path:
    """The card of ``model_path``: its name with ``.json`` (``model.zip`` -> ``model.json``)."""
    return Path(model_path).with_suffix(".json")


def versions() -> dict[str, str]:
    """Versions of the packages a saved model depends on."""
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for pkg in ("graspgait_env", "stable_baselines3", "sb3_contrib", "torch", "gymnasium"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def _jsonable(x: Any) -> Any:
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (str, int, float, bool)) or x is None:
        return x
    if hasattr(x, "item"):  # NumPy scalars
        return x.item()
    return str(x)


def save_agent(model: Any, path: str | os.PathLike[str], card: Mapping[str, Any]) -> Path:
    """Save ``model`` to ``path`` (``.zip``) and its card beside it, both atomically.

    ``card`` gets ``format``, ``created`` and ``versions`` added.
    """
    path = Path(path)
    if path.suffix != ".zip":
        raise GraspGaitInputError(f"model path {str(path)!r}: must end in .zip")
    atomic_write(path, lambda fh: model.save(fh))
    full = {"format": CARD_FORMAT, **_jsonable(card),
            "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "versions": versions()}
    write_text_atomic(card_path(path), json.dumps(full, indent=1) + "\n")
    return path


def read_card(model_path: str | os.PathLike[str]) -> dict[str, Any]:
    """The card beside ``model_path`` (an empty dict when there is none).

    Raises
    ------
    GraspGaitInputError
        The card exists but is not a JSON object.
    """
    p = card_path(model_path)
    if not p.is_file():
        return {}
    try:
        card = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise GraspGaitInputError(f"model card {str(p)!r}: cannot read it ({exc}); delete it "
                                  "to load the model without one") from None
    if not isinstance(card, dict):
        raise GraspGaitInputError(f"model card {str(p)!r}: must be a JSON object")
    return upgrade_card(card)  # the import paths of a card written by 0.1


class _RLZooLoader(yaml.SafeLoader):
    """Reads RL Zoo's ``config.yml`` / ``args.yml`` (OrderedDicts as Python tags) safely."""


_RLZooLoader.add_constructor(
    "tag:yaml.org,2002:python/object/apply:collections.OrderedDict",
    lambda loader, node: dict(loader.construct_sequence(node.value[0], deep=True)))


def _rlzoo_card(path: Path) -> dict[str, Any]:
    """A card made from RL Zoo's saved run (``LOG/ALGO/ENV_N/ENV/{config,args}.yml``).

    RL Zoo saves ``ENV.zip``, ``best_model.zip`` and checkpoints in the run folder and
    its hyper-parameters in the subfolder named by the env id; from them: ``algo``,
    ``env_id``, ``env_kwargs`` and ``wrappers`` (its ``env_wrapper``). Empty when the
    zip does not sit in such a folder.
    """
    for sub in sorted(p for p in path.parent.iterdir() if p.is_dir()):
        cfg, args = sub / "config.yml", sub / "args.yml"
        if not (cfg.is_file() and args.is_file()):
            continue
        try:
            hyper = yaml.load(cfg.read_text(encoding="utf-8"), Loader=_RLZooLoader) or {}
            argv = yaml.load(args.read_text(encoding="utf-8"), Loader=_RLZooLoader) or {}
        except (OSError, yaml.YAMLError):
            return {}
        if not isinstance(hyper, dict) or not isinstance(argv, dict):
            return {}
        wrapper = hyper.get("env_wrapper")
        wrappers = wrapper if isinstance(wrapper, list) else ([wrapper] if wrapper else [])
        if not all(isinstance(w, str) for w in wrappers):
            return {}  # wrappers with keyword arguments: not read here
        return {"algo": argv.get("algo"), "env_id": argv.get("env", sub.name),
                "env_kwargs": argv.get("env_kwargs") or {}, "wrappers": wrappers,
                "source": f"RL Zoo run {sub}"}
    return {}


def _is_maskable(path: Path) -> bool:
    """Whether the zip holds a MaskablePPO policy (read from its ``data`` entry)."""
    try:
        with zipfile.ZipFile(path) as zf:
            data = json.loads(zf.read("data"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return False
    policy = json.dumps(data.get("policy_class", ""))
    return "Maskable" in policy


def load_agent(model_path: str | os.PathLike[str], device: str = "cpu") -> tuple[Any, dict]:
    """Load a saved agent and its card.

    The algorithm is read from the zip: MaskablePPO when its policy class is a maskable
    one, else PPO (the returned card's ``algo`` says which).

    Parameters
    ----------
    model_path
        A shipped agent's name (``"general"``; :func:`shipped_agents`) or the path of a
        model zip (``.zip`` may be left out). A model saved by graspgait_env 0.1 (whose
        pickles and card name the packages ``agents`` / ``baselines``) loads too
        (:mod:`graspgait_env.agents.legacy`).
    device
        The torch device of the model.

    Returns
    -------
    model, card
        The SB3 model (on ``device``) and the card (``{}`` when absent).

    Raises
    ------
    GraspGaitInputError
        Neither a file nor a shipped agent, or not an SB3 model zip.
    MissingExtraError
        The ``[train]`` extra (torch, stable-baselines3, ...) is not installed.

    Examples
    --------
    >>> model, card = load_agent("general")  # doctest: +SKIP
    >>> card["env_id"]  # doctest: +SKIP
    'GraspGait-v0'
    """
    require_extra("train", "load_agent")
    path = resolve_model(model_path)
    card = read_card(path) or _rlzoo_card(path)
    # the zip itself says which algorithm saved it (a card may be stale or RL Zoo's)
    card["algo"] = algo = "maskable_ppo" if _is_maskable(path) else "ppo"
    if algo == "maskable_ppo":
        from sb3_contrib import MaskablePPO as cls
    else:
        from stable_baselines3 import PPO as cls
    try:
        with legacy_module_names():  # a model saved by graspgait_env 0.1 names `agents`
            model = cls.load(path, device=device)
    except (zipfile.BadZipFile, KeyError, ValueError) as exc:
        raise GraspGaitInputError(f"MODEL {str(model_path)!r}: not a stable-baselines3 model "
                                  f"zip ({type(exc).__name__}: {exc})") from None
    return model, card
