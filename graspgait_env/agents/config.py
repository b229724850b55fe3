"""One frozen, validated dataclass of training hyper-parameters, read from YAML and ``--set``.

A training config is a YAML file of :class:`TrainConfig` fields (``configs/train/NAME.yaml``
is bundled under the name ``NAME``; any path works too). Every field can be replaced
from the command line with ``key=value`` strings (``graspgait train ellipse --set
seed=3 --set env_kwargs.mu=0.8``): the value is read with YAML's scalar rules (``3`` is
an int, ``3e-4`` a float, also without a dot as in YAML 1.2, ``[64, 64]`` a list,
``null`` None) and dotted keys reach into the nested dicts (``env_kwargs.object=pentagon``).

Every check raises :class:`~graspgait_env.errors.GraspGaitInputError` naming the field,
the bad value and the fix, e.g. ``n_steps=0: must be an integer >= 1, e.g. 256``.
"""

from __future__ import annotations

import difflib
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import yaml

from graspgait_env.agents.imitation import Imitation
from graspgait_env.agents.legacy import upgrade_import_path
from graspgait_env.envs.config import check_count, check_number
from graspgait_env.envs.registration import ENV_IDS
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.resources import bundled_file, bundled_names

__all__ = [
    "ALGOS",
    "OWN_POLICY_KWARGS",
    "VEC_ENVS",
    "TrainConfig",
    "apply_overrides",
    "bundled_train_configs",
    "default_torch_threads",
    "load_train_config",
    "parse_override",
]

ALGOS = ("maskable_ppo", "ppo")
"""``maskable_ppo``: sb3-contrib MaskablePPO (reads the env's ``action_masks()``);
``ppo``: stable-baselines3 PPO (no masks; pair it with
:class:`graspgait_env.agents.wrappers.LegalActionWrapper`)."""
VEC_ENVS = ("dummy", "subproc", "batched")
"""SB3 vector envs: ``dummy`` steps the envs in this process, one after the other;
``subproc`` runs one process per env; ``batched`` steps all ``n_envs`` in one NumPy call
(:mod:`graspgait_env.agents.vec_env`; ``GraspGait-v0`` and ``GraspGaitRandom-v0`` without
wrappers only, same transitions)."""
ACTIVATIONS = ("tanh", "relu")
OWN_POLICY_KWARGS = {"net_arch": "net_arch", "activation_fn": "activation",
                     "features_extractor_class": "features_extractor",
                     "features_extractor_kwargs": "features_extractor_kwargs"}
"""SB3 policy keywords that a training config sets by its own fields (keyword -> field),
refused in ``policy_kwargs``."""


class _Loader(yaml.SafeLoader):
    """YAML's safe loader reading ``1e-3`` as a float (YAML 1.2), as users write it.

    PyYAML follows YAML 1.1, where a float needs a dot (``1.0e-3``) and ``1e-3`` is a
    string; here both are numbers, in files and in ``--set``.
    """


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"))


def default_torch_threads(cpu_count: int | None = None) -> int:
    """Torch intra-op threads for this machine: 1 up to 4 cores, else ``cores // 4`` (<= 4).

    The networks here are small MLPs on batches of a few hundred rows; extra threads
    only contend with the environment steps. Measured on a 2-core machine under load
    (issue 11): torch's default threading ran 29-189 env steps/s, one thread about 2,300.

    Parameters
    ----------
    cpu_count
        Logical cores (default :func:`os.cpu_count`).
    """
    cores = cpu_count if cpu_count is not None else (os.cpu_count() or 1)
    return 1 if cores <= 4 else min(4, cores // 4)


def _check_str(name: str, value: Any, choices: Sequence[str] | None = None,
               example: str = "") -> str:
    if not isinstance(value, str) or (choices is not None and value not in choices):
        if choices is not None:
            near = difflib.get_close_matches(str(value), choices, n=1)
            hint = f"did you mean {near[0]!r}? " if near else ""
            raise GraspGaitInputError(f"{name}={value!r}: {hint}must be one of "
                                      f"{', '.join(map(repr, choices))}")
        raise GraspGaitInputError(f"{name}={value!r}: must be a string, e.g. {example!r}")
    return value


def _check_import_path(name: str, value: Any) -> str:
    """``"package.module:Name"`` or ``"package.module.Name"`` (imported when used)."""
    ok = isinstance(value, str) and ("." in value or ":" in value) and " " not in value
    if not ok:
        raise GraspGaitInputError(
            f"{name}={value!r}: give an import path 'package.module:Name', e.g. "
            "'graspgait_env.agents.wrappers:LegalActionWrapper'")
    return upgrade_import_path(value, warn=True)  # 0.1's agents.X / baselines.X


def _check_import_paths(name: str, value: Any, example: str) -> list[str]:
    """A list of import paths (:func:`_check_import_path`), e.g. a wrappers field."""
    if isinstance(value, str) or not isinstance(value, Sequence):
        raise GraspGaitInputError(f"{name}={value!r}: must be a list of import paths, e.g. "
                                  f"['{example}']")
    return [_check_import_path(f"{name}[{i}]", v) for i, v in enumerate(value)]


def _check_net_arch(value: Any) -> list[int] | dict[str, list[int]]:
    fix = "give a list of layer widths, e.g. [64, 64], or {pi: [64, 64], vf: [64, 64]}"

    def widths(key: str, xs: Any) -> list[int]:
        if isinstance(xs, (str, bytes, Mapping)) or not isinstance(xs, Sequence):
            raise GraspGaitInputError(f"{key}={xs!r}: {fix}")
        return [check_count(f"{key}[{i}]", x, 1, 64) for i, x in enumerate(xs)]

    if isinstance(value, Mapping):
        if set(value) != {"pi", "vf"}:
            raise GraspGaitInputError(f"net_arch={dict(value)!r}: {fix}")
        return {k: widths(f"net_arch.{k}", value[k]) for k in ("pi", "vf")}
    return widths("net_arch", value)


@dataclass(frozen=True)
class TrainConfig:
    """Hyper-parameters of one training run (``graspgait train``,
    :func:`graspgait_env.agents.train.train`).

    The PPO fields keep stable-baselines3's names and meaning (``PPO(n_steps=...,
    batch_size=...)``). Values are checked at construction; numbers are stored as Python
    ints and floats, lists as lists.

    Examples
    --------
    >>> cfg = TrainConfig(env_kwargs={"object": "ellipse", "mu": 0.7}, total_timesteps=1000)
    >>> cfg.algo, cfg.n_envs, cfg.n_steps
    ('maskable_ppo', 8, 256)
    >>> TrainConfig(n_steps=0)
    Traceback (most recent call last):
    ...
    graspgait_env.errors.GraspGaitInputError: n_steps=0: must be an integer >= 1, e.g. 256
    """

    name: str = "custom"
    """Config name, part of the run's name (a bundled config: its file name)."""
    algo: str = "maskable_ppo"
    """``maskable_ppo`` (sb3-contrib MaskablePPO, legal actions only) or ``ppo`` (SB3 PPO)."""
    env_id: str = "GraspGait-v0"
    """A registered GraspGait id: ``GraspGait-v0``, ``GraspGaitRandom-v0`` or
    ``GraspGaitMujoco-v1``."""
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    """Keyword arguments of ``gymnasium.make(env_id, ...)``: ``object``, ``mu``,
    ``contact_model``, the GraspGaitConfig fields (reward weights, map window, ...)."""
    wrappers: list[str] = field(default_factory=list)
    """Gymnasium wrappers applied to every env, innermost first, as import paths
    (``"graspgait_env.agents.wrappers:LegalActionWrapper"``)."""
    train_wrappers: list[str] = field(default_factory=list)
    """Gymnasium wrappers of the training envs only, outside ``wrappers``, as import paths
    (``"graspgait_env.agents.wrappers:RuleBasedStartWrapper"``, a start distribution): the periodic
    evaluation and ``graspgait evaluate`` run without them, and the card's ``wrappers``
    leaves them out."""
    policy: str = "MlpPolicy"
    """SB3's ``MlpPolicy``, or the import path of a policy class: with ``algo:
    maskable_ppo``, ``graspgait_env.agents.policies:MaskableRegraspScorerPolicy`` (SB3's
    network plus one scorer shared by every move; needs ``features_extractor:
    graspgait_env.agents.policies:PartsExtractor`` and ``env_kwargs`` ``observation_mode:
    dict``)."""
    net_arch: list[int] | dict[str, list[int]] = field(default_factory=lambda: [64, 64])
    """Hidden layer widths of the policy and value networks (a list: shared sizes, separate
    networks; or ``{pi: [...], vf: [...]}``)."""
    activation: str = "tanh"
    """Hidden activation: ``tanh`` (SB3's default) or ``relu``."""
    features_extractor: str | None = None
    """Import path of an SB3 ``BaseFeaturesExtractor`` subclass, or None (flatten)."""
    features_extractor_kwargs: dict[str, Any] = field(default_factory=dict)
    """Its keyword arguments."""
    policy_kwargs: dict[str, Any] = field(default_factory=dict)
    """Further keyword arguments of the policy class (SB3's ``policy_kwargs``), e.g.
    ``{scorer_arch: [64], scorer_context: 32}`` for ``MaskableRegraspScorerPolicy``; the
    network and the extractor have their own fields (``net_arch``, ``activation``,
    ``features_extractor``, ``features_extractor_kwargs``), refused here."""
    n_envs: int = 8
    """Parallel environments."""
    vec_env: str = "dummy"
    """``dummy`` (one process) or ``subproc`` (one process per env)."""
    n_steps: int = 256
    """Steps per env per rollout (rollout = ``n_envs * n_steps`` transitions)."""
    batch_size: int = 64
    """Minibatch size (transitions)."""
    n_epochs: int = 10
    """Passes over each rollout."""
    learning_rate: float = 3e-4
    """Adam step size (initial value with ``lr_schedule: linear``)."""
    lr_schedule: str = "constant"
    """``constant`` or ``linear`` (decays to 0 at ``total_timesteps``)."""
    gamma: float = 0.99
    """Discount factor (PPO's gamma, not the thesis's rotation cost)."""
    gae_lambda: float = 0.95
    """GAE lambda."""
    clip_range: float = 0.2
    """PPO clip range."""
    ent_coef: float = 0.0
    """Entropy bonus coefficient."""
    vf_coef: float = 0.5
    """Value loss coefficient."""
    max_grad_norm: float = 0.5
    """Gradient clipping norm."""
    total_timesteps: int = 200_000
    """PPO's environment steps (all envs together); 0 with ``imitation``: the imitation
    alone (no PPO update; the final evaluation and the card as after PPO)."""
    eval_freq: int = 25_000
    """Evaluate every this many environment steps (0: only at the end)."""
    eval_episodes: int = 40
    """Episodes per evaluation, from fixed starts (seeds 10000, 10001, ...)."""
    best_success_floor: float | None = None
    """How ``best.zip`` is chosen among the periodic evaluations
    (:func:`graspgait_env.agents.train.selection_score`): None ranks them by success rate over
    solvable
    starts, then by fewest regrasps relative to the optimum; a number in [0, 1] ranks
    those reaching that success rate above the others and, among them, by regrasps
    relative to the optimum alone (issue 11's acceptance: 0.98, then the fewest regrasps)."""
    checkpoint_freq: int = 50_000
    """Save a checkpoint every this many environment steps (0: none)."""
    seed: int = 0
    """Seed of Python, NumPy, torch and the envs (env ``i`` gets ``seed + i``)."""
    torch_threads: int | None = None
    """Torch intra-op threads; None: :func:`default_torch_threads` (1 on a 2-core box)."""
    device: str = "cpu"
    """Torch device (``cpu``; small MLPs gain nothing from a GPU)."""
    run_root: str = "runs"
    """Folder under which each run gets its own folder."""
    init_model: str | None = None
    """A saved model (a ``.zip`` path, or a shipped model's name: ``circle`` is
    ``agents/models/circle.zip``) whose policy and value weights start this run,
    or None (a fresh network). Only the weights carry over: the optimizer, the step count and the
    learning-rate schedule start afresh, so a run can continue another under a new reward
    (a curriculum, a fine-tune). The model must have this config's algorithm, observation
    and action spaces and network. The card records its steps and wall time
    (``init``), so the training a model took is stated in full."""
    imitation: Imitation | None = None
    """DAgger from the exact optimum before PPO (:class:`~graspgait_env.agents.imitation.
    Imitation`: ``{iterations, labels, epochs, batch_size, learning_rate}``), or None (PPO
    from the start). Needs ``algo: maskable_ppo`` and ``vec_env: dummy`` or ``subproc``;
    the card records its labels, env steps and wall time (``imitation``)."""
    init_logit_scale: float = 1.0
    """With ``init_model``: multiply the policy head's weights and bias (the action
    logits) by this factor in (0, 1] before training. Below 1 the run starts from a
    flatter policy with the same greedy actions, so actions the source model had ruled
    out (probability ~0, never sampled, so never learned to be better) are tried again.
    1.0 (the default): the weights as saved."""

    def __post_init__(self) -> None:
        def put(name: str, value: Any) -> None:
            object.__setattr__(self, name, value)  # frozen: normalize once, here

        put("name", _check_str("name", self.name, example="ellipse"))
        if not self.name or any(c in self.name for c in "/\\ "):
            raise GraspGaitInputError(f"name={self.name!r}: must be a non-empty word without "
                                      "spaces or slashes, e.g. 'ellipse'")
        put("algo", _check_str("algo", self.algo, ALGOS))
        put("env_id", _check_str("env_id", self.env_id, tuple(ENV_IDS)))
        if not isinstance(self.env_kwargs, Mapping):
            raise GraspGaitInputError(f"env_kwargs={self.env_kwargs!r}: must be a mapping, "
                                      "e.g. {object: ellipse, mu: 0.7}")
        put("env_kwargs", dict(self.env_kwargs))
        put("wrappers", _check_import_paths("wrappers", self.wrappers,
                                            "graspgait_env.agents.wrappers:LegalActionWrapper"))
        put("train_wrappers", _check_import_paths("train_wrappers", self.train_wrappers,
                                                  "graspgait_env.agents.wrappers:RuleBasedStartWrapper"))
        if self.policy != "MlpPolicy":
            put("policy", _check_import_path("policy", self.policy))
            if self.algo != "maskable_ppo" and "Maskable" in self.policy:
                raise GraspGaitInputError(
                    f"policy={self.policy!r} with algo={self.algo!r}: a maskable policy "
                    "needs algo: maskable_ppo; set it, or policy: MlpPolicy")
        put("net_arch", _check_net_arch(self.net_arch))
        put("activation", _check_str("activation", self.activation, ACTIVATIONS))
        if self.features_extractor is not None:
            put("features_extractor",
                _check_import_path("features_extractor", self.features_extractor))
        if not isinstance(self.features_extractor_kwargs, Mapping):
            raise GraspGaitInputError(
                f"features_extractor_kwargs={self.features_extractor_kwargs!r}: must be a "
                "mapping, e.g. {}")
        put("features_extractor_kwargs", dict(self.features_extractor_kwargs))
        if not isinstance(self.policy_kwargs, Mapping):
            raise GraspGaitInputError(
                f"policy_kwargs={self.policy_kwargs!r}: must be a mapping, e.g. "
                "{scorer_arch: [64]}")
        own = sorted(set(self.policy_kwargs) & set(OWN_POLICY_KWARGS))
        if own:
            raise GraspGaitInputError(
                f"policy_kwargs {own}: set by their own fields; use "
                + ", ".join(OWN_POLICY_KWARGS[k] for k in own) + " instead")
        put("policy_kwargs", dict(self.policy_kwargs))
        put("n_envs", check_count("n_envs", self.n_envs, 1, 8))
        put("vec_env", _check_str("vec_env", self.vec_env, VEC_ENVS))
        put("n_steps", check_count("n_steps", self.n_steps, 1, 256))
        put("batch_size", check_count("batch_size", self.batch_size, 2, 64))
        rollout = self.n_envs * self.n_steps
        if rollout < 2:
            raise GraspGaitInputError(
                f"n_steps={self.n_steps}: n_envs * n_steps must be > 1 (PPO's advantage "
                "normalization); raise n_steps, e.g. 256")
        if self.batch_size > rollout:
            raise GraspGaitInputError(
                f"batch_size={self.batch_size}: larger than a rollout (n_envs * n_steps = "
                f"{rollout}); use at most {rollout}, e.g. 64")
        put("n_epochs", check_count("n_epochs", self.n_epochs, 1, 10))
        put("learning_rate", check_number("learning_rate", self.learning_rate, 3e-4,
                                          minimum=0.0, strict=True))
        put("lr_schedule", _check_str("lr_schedule", self.lr_schedule, ("constant", "linear")))
        put("gamma", check_number("gamma", self.gamma, 0.99, minimum=0.0, maximum=1.0))
        put("gae_lambda", check_number("gae_lambda", self.gae_lambda, 0.95, minimum=0.0,
                                       maximum=1.0))
        put("clip_range", check_number("clip_range", self.clip_range, 0.2, minimum=0.0,
                                       strict=True))
        for name, example in (("ent_coef", 0.0), ("vf_coef", 0.5)):
            put(name, check_number(name, getattr(self, name), example, minimum=0.0))
        put("max_grad_norm", check_number("max_grad_norm", self.max_grad_norm, 0.5,
                                          minimum=0.0, strict=True))
        if self.total_timesteps == 0 and self.imitation is None:
            raise GraspGaitInputError(
                "total_timesteps=0: trains nothing without an imitation block; give >= 1, "
                "e.g. 200000, or imitation: {...} (the imitation alone)")
        put("total_timesteps", check_count("total_timesteps", self.total_timesteps, 0, 200_000))
        put("eval_freq", check_count("eval_freq", self.eval_freq, 0, 25_000))
        put("eval_episodes", check_count("eval_episodes", self.eval_episodes, 1, 40))
        if self.best_success_floor is not None:
            put("best_success_floor", check_number("best_success_floor",
                                                   self.best_success_floor, 0.98,
                                                   minimum=0.0, maximum=1.0))
        put("checkpoint_freq", check_count("checkpoint_freq", self.checkpoint_freq, 0, 50_000))
        put("seed", check_count("seed", self.seed, 0, 0))
        if self.torch_threads is None:
            put("torch_threads", default_torch_threads())
        put("torch_threads", check_count("torch_threads", self.torch_threads, 1, 1))
        put("device", _check_str("device", self.device, example="cpu"))
        if not isinstance(self.run_root, (str, os.PathLike)) or not str(self.run_root):
            raise GraspGaitInputError(f"run_root={self.run_root!r}: must be a folder path, "
                                      "e.g. 'runs'")
        put("run_root", str(self.run_root))
        if self.init_model is not None:
            if not isinstance(self.init_model, (str, os.PathLike)) or not str(self.init_model):
                raise GraspGaitInputError(f"init_model={self.init_model!r}: must be a saved "
                                          "model's path or a shipped model's name, e.g. "
                                          "circle")
            put("init_model", str(self.init_model))
        put("init_logit_scale", check_number("init_logit_scale", self.init_logit_scale, 0.2,
                                             minimum=0.0, maximum=1.0, strict=True))
        if self.imitation is not None:
            put("imitation", Imitation.from_mapping(self.imitation))
            if self.algo != "maskable_ppo" or self.vec_env == "batched":
                raise GraspGaitInputError(
                    f"imitation with algo={self.algo!r}, vec_env={self.vec_env!r}: imitation "
                    "trains a maskable policy on envs that give optimal_moves(); set algo: "
                    "maskable_ppo and vec_env: dummy (or subproc), or imitation: null")
        if self.init_logit_scale != 1.0 and self.init_model is None:
            raise GraspGaitInputError(
                f"init_logit_scale={self.init_logit_scale}: scales the weights of "
                "init_model, which is not set; set init_model or leave it at 1.0")

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The fields, in order."""
        return tuple(f.name for f in fields(cls))

    def to_dict(self) -> dict[str, Any]:
        """The fields as plain YAML/JSON-able values (a deep copy)."""
        return asdict(self)


def bundled_train_configs() -> list[str]:
    """Names of the bundled training configs (``configs/train/NAME.yaml``)."""
    return bundled_names("train")


def parse_override(text: str) -> tuple[list[str], Any]:
    """``"key.sub=value"`` as ``(["key", "sub"], value)``, the value read by YAML's rules.

    Raises
    ------
    GraspGaitInputError
        No ``=``, an empty key, or a value YAML cannot read.

    Examples
    --------
    >>> parse_override("env_kwargs.mu=0.8")
    (['env_kwargs', 'mu'], 0.8)
    >>> parse_override("net_arch=[32, 32]")
    (['net_arch'], [32, 32])
    """
    if not isinstance(text, str) or "=" not in text:
        raise GraspGaitInputError(f"--set {text!r}: give key=value, e.g. --set seed=3 or "
                                  "--set env_kwargs.object=pentagon")
    key, _, raw = text.partition("=")
    path = key.strip().split(".")
    if not all(path):
        raise GraspGaitInputError(f"--set {text!r}: empty key; give key=value, e.g. seed=3")
    try:
        value = yaml.load(raw, Loader=_Loader) if raw.strip() else None
    except yaml.YAMLError as exc:
        problem = str(exc).splitlines()[0]
        raise GraspGaitInputError(f"--set {text!r}: the value is not valid YAML ({problem}); "
                                  "quote strings and write lists as [a, b]") from None
    return path, value


def _unknown_key(key: str, where: str) -> GraspGaitInputError:
    names = TrainConfig.field_names()
    near = difflib.get_close_matches(key, names, n=1)
    hint = f"did you mean {near[0]!r}? " if near else ""
    return GraspGaitInputError(f"{where}{key!r}: not a training config field; {hint}"
                               f"valid: {', '.join(names)}")


def apply_overrides(data: Mapping[str, Any], overrides: Sequence[str]) -> dict[str, Any]:
    """``data`` (config fields) with each ``key=value`` of ``overrides`` applied, in order.

    Dotted keys set entries of nested dicts (created when missing); the top-level key
    must be a :class:`TrainConfig` field.
    """
    out = {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in data.items()}
    for text in overrides:
        path, value = parse_override(text)
        if path[0] not in TrainConfig.field_names():
            raise _unknown_key(path[0], "--set ")
        node = out
        for i, part in enumerate(path[:-1]):
            child = node.get(part)
            if child is None:
                child = {}
            elif not isinstance(child, Mapping):
                raise GraspGaitInputError(
                    f"--set {text!r}: {'.'.join(path[:i + 1])} is {child!r}, not a mapping; "
                    f"set it whole, e.g. --set {'.'.join(path[:i + 1])}=value")
            node[part] = child = dict(child)
            node = child
        node[path[-1]] = value
    return out


def _read_yaml(path: Path) -> dict[str, Any]:
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=_Loader)
    except OSError as exc:
        raise GraspGaitInputError(f"CONFIG {str(path)!r}: cannot read it ({exc.strerror})") \
            from None
    except yaml.YAMLError as exc:
        problem = str(exc).splitlines()[0]
        raise GraspGaitInputError(f"CONFIG {str(path)!r}: not valid YAML ({problem})") from None
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise GraspGaitInputError(f"CONFIG {str(path)!r}: must be a mapping of training "
                                  f"config fields, got {type(data).__name__}")
    return dict(data)


def load_train_config(path_or_name: str | os.PathLike[str],
                      overrides: Sequence[str] = ()) -> TrainConfig:
    """Read a training config: a bundled name (``configs/train/NAME.yaml``) or a YAML path.

    Parameters
    ----------
    path_or_name
        ``"ellipse"`` (bundled) or a path to a YAML file of :class:`TrainConfig` fields.
        ``name`` defaults to the file's stem.
    overrides
        ``"key=value"`` strings applied after the file (see :func:`apply_overrides`).

    Raises
    ------
    GraspGaitInputError
        Unknown name or missing file (the bundled names are listed), malformed YAML, an
        unknown field (the nearest is suggested) or a bad value.
    """
    text = os.fspath(path_or_name)
    path = Path(text)
    bundled = bundled_file("train", text) if not path.suffix and os.sep not in text else None
    if bundled is not None:
        path = bundled
    elif not path.is_file():
        raise GraspGaitInputError(
            f"CONFIG {text!r}: no such file and not a bundled training config; use one of "
            f"{', '.join(bundled_train_configs())} or a path to a YAML file")
    data = _read_yaml(path)
    for key in data:
        if key not in TrainConfig.field_names():
            raise _unknown_key(str(key), f"CONFIG {str(path)!r}: ")
    data.setdefault("name", path.stem)
    data = apply_overrides(data, overrides)
    try:
        return TrainConfig(**data)
    except TypeError as exc:  # pragma: no cover - unknown keys are caught above
        raise GraspGaitInputError(f"CONFIG {str(path)!r}: {exc}") from None
