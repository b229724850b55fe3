"""The keyword arguments of the GraspGait env family: one frozen, validated dataclass.

:class:`GraspGaitConfig` holds what every id (``GraspGait-v0``, ``GraspGaitRandom-v0``,
``GraspGaitMujoco-v1``) shares: the hand and grid, the requested turn, the reward
weights, the wrong-way limit and the grasp-map window. Each env takes it as
``config=`` and, on top of it, any of its fields as a keyword argument, so
``gymnasium.make("graspgait_env:GraspGait-v0", beta=0.05)`` and
``gymnasium.make(..., config=GraspGaitConfig(beta=0.05))`` make the same env.

Every check raises :class:`~graspgait_env.errors.GraspGaitInputError` (a ``ValueError``)
whose message names the argument, the bad value and the fix, e.g.
``mu='abc': must be a finite number > 0, e.g. 0.7``. The checks of the per-id arguments
(``object``, ``mu``, reset seeds and options) live here too, so that every message has
one form.
"""

from __future__ import annotations

import difflib
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.grasp_map import check_n
from graspgait_env.shapes import Shape
from graspgait_env.workspace import Hand

__all__ = [
    "GraspGaitConfig",
    "check_count",
    "check_mu",
    "check_number",
    "check_object",
    "check_options",
    "check_seed",
    "env_id_of",
]

_NUMBER_TYPES = (int, float, np.integer, np.floating)
# names a user may reach for, and the argument that is meant (named in the message only:
# each thing has one name)
_SYNONYMS = {
    "regrasp_cost": "beta", "regrasp_penalty": "beta", "rotation_cost": "gamma",
    "rotation_penalty": "gamma", "turn_weight": "alpha", "friction": "mu",
    "grid_size": "n", "window_cells": "map_window_cells", "window_deg": "map_window_deg",
}


def check_number(name: str, value: Any, example: Any, *, minimum: float | None = None,
                 strict: bool = False, maximum: float | None = None, nonzero: bool = False,
                 why: str = "") -> float:
    """``value`` as a float, if it is a finite real number inside the given bounds.

    Parameters
    ----------
    name
        The argument's name, as the user typed it (``"mu"``, ``"options['mu']"``).
    value
        What the user gave; a bool or a string is never a number.
    example
        A good value, shown in the message.
    minimum, strict, maximum, nonzero
        ``value >= minimum`` (``> minimum`` when ``strict``), ``value <= maximum``,
        ``value != 0``.
    why
        A parenthesis for the message (``"it is subtracted as a cost"``).

    Raises
    ------
    GraspGaitInputError
        ``"{name}={value!r}: must be a finite number > 0, e.g. 0.7"``.

    Examples
    --------
    >>> check_number("mu", 0.5, 0.7, minimum=0.0, strict=True)
    0.5
    >>> check_number("mu", "abc", 0.7, minimum=0.0, strict=True)
    Traceback (most recent call last):
    ...
    graspgait_env.errors.GraspGaitInputError: mu='abc': must be a finite number > 0, e.g. 0.7
    """
    ok = isinstance(value, _NUMBER_TYPES) and not isinstance(value, (bool, np.bool_))
    x = float(value) if ok else math.nan
    ok = (ok and math.isfinite(x)
          and (minimum is None or (x > minimum if strict else x >= minimum))
          and (maximum is None or x <= maximum) and (not nonzero or x != 0.0))
    if not ok:
        if minimum is not None and maximum is not None:
            rule = f" in {'(' if strict else '['}{minimum:g}, {maximum:g}]"
        elif minimum is not None:
            rule = f" {'>' if strict else '>='} {minimum:g}"
        else:
            rule = ""
        what = "nonzero number" if nonzero else "number"
        note = f" ({why})" if why else ""
        raise GraspGaitInputError(f"{name}={value!r}: must be a finite {what}{rule}{note}, "
                                  f"e.g. {example}")
    return x


def check_count(name: str, value: Any, minimum: int, example: int) -> int:
    """``value`` as an int, if it is an integer (not a bool; NumPy integers too) ``>= minimum``.

    Raises
    ------
    GraspGaitInputError
        ``"{name}={value!r}: must be an integer >= {minimum}, e.g. {example}"``.
    """
    if (isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer))
            or value < minimum):
        raise GraspGaitInputError(f"{name}={value!r}: must be an integer >= {minimum}, "
                                  f"e.g. {example}")
    return int(value)


def check_mu(value: Any, name: str = "mu") -> float:
    """The Coulomb friction coefficient: a finite number > 0 (thesis 3.1)."""
    return check_number(name, value, 0.7, minimum=0.0, strict=True)


def check_object(value: Any, name: str = "object") -> str | os.PathLike | Shape:
    """An object argument: a bundled name, a YAML path or a :class:`Shape`.

    Only the kind is checked here; :func:`graspgait_env.objects.load_object` (the one
    loader) reports an unknown name or a malformed file, naming the field and the fix.
    """
    if isinstance(value, (str, os.PathLike, Shape)):
        return value
    from graspgait_env.objects import bundled_objects

    raise GraspGaitInputError(
        f"{name}={value!r}: give a bundled object name ({', '.join(bundled_objects())}), "
        "a path to an object YAML or a Shape")


def check_seed(seed: Any) -> int | None:
    """A reset seed: ``None`` or an integer ``>= 0`` (NumPy integers are accepted).

    Gymnasium accepts only Python ints (and, being ints, bools); here a bool is refused
    (a flag passed where a seed goes) and a NumPy integer is taken as its value.
    """
    if seed is None or (type(seed) is int and seed >= 0):
        return seed
    if (isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_))
            and seed >= 0):
        return int(seed)
    raise GraspGaitInputError(f"seed={seed!r}: must be None or an integer >= 0, e.g. 0")


def check_options(options: Any, valid: Sequence[str], owner: str) -> Mapping[str, Any]:
    """``reset(options=...)``: None or a mapping whose keys are all in ``valid``."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise GraspGaitInputError(
            f"options={options!r}: must be None or a dict, e.g. "
            f"{{{valid[0]!r}: ...}}; {owner} reads the keys {', '.join(map(repr, valid))}")
    for key in options:
        if key not in valid:
            near = difflib.get_close_matches(str(key), valid, n=1)
            hint = f"did you mean {near[0]!r}? " if near else ""
            raise GraspGaitInputError(
                f"options[{key!r}]: {owner} has no reset option {key!r}; {hint}"
                f"valid keys: {', '.join(map(repr, valid))}")
    return options


def env_id_of(cls: type) -> str:
    """The registered id whose entry point is ``cls`` (else the class name), for messages."""
    from graspgait_env.envs.registration import ENV_IDS

    entry = f"{cls.__module__}:{cls.__qualname__}"
    return next((i for i, e in ENV_IDS.items() if e == entry), cls.__name__)


@dataclass(frozen=True)
class GraspGaitConfig:
    """Keyword arguments shared by every GraspGait env id (task, rewards, observation).

    Each field is also a keyword argument of ``gymnasium.make`` for every id, with the
    same name and default; values are checked at construction (the message names the
    field, the bad value and the fix) and numbers are stored as Python floats and ints.
    See the ``Rewards`` and ``Observation Space`` sections of
    :class:`~graspgait_env.envs.map_env.GraspGaitEnv` for what each weight does.

    Examples
    --------
    >>> cfg = GraspGaitConfig(beta=0.05)
    >>> cfg.beta, cfg.turn_scale
    (0.05, 360.0)
    >>> GraspGaitConfig(map_window_cells=0)
    Traceback (most recent call last):
    ...
    graspgait_env.errors.GraspGaitInputError: map_window_cells=0: must be an integer >= 1, e.g. 36
    """

    hand: str | os.PathLike | Hand | None = None
    """Bundled hand name, hand YAML path or :class:`~graspgait_env.workspace.Hand`; None: the
    thesis hand of fig. 4.1 (workspaces [0, 90], [120, 210], [240, 330] degrees)."""
    turn_deg: float = 360.0
    """Requested turn (degrees; the sign is the direction, counter-clockwise positive)."""
    n: int = 180
    """Grid size: contacts and rotations in steps of ``360 / n`` degrees (180: 2°, thesis)."""
    alpha: float = 1.0
    """Weight of the ``turn`` term (reward per ``turn_scale_deg`` of turn gained)."""
    beta: float = 0.01
    """Cost of a regrasp (reward units per regrasp, >= 0; thesis 5.4's beta)."""
    gamma: float = 0.01
    """Cost of a rotation (reward units per rotation, >= 0; thesis 5.4's gamma)."""
    turn_scale_deg: float | None = None
    """Degrees of turn that earn ``alpha`` (> 0); None: ``abs(turn_deg)``, the whole turn."""
    success_bonus: float = 1.0
    """Reward on reaching the turn (reward units, once per episode)."""
    dead_end_penalty: float = 1.0
    """Cost of a dead end, a drop or passing the wrong-way limit (reward units, >= 0)."""
    illegal_penalty: float = 0.1
    """Cost of an illegal action, a no-op (reward units per action, >= 0)."""
    to_go_weight: float = 0.0
    """Reward per regrasp gained towards the goal (reward units, >= 0; 0: off, the
    default): a regrasp earns ``to_go_weight * (before - after)``, the fall in the fewest
    regrasps still needed to reach the turn (the exact optimum's count, beyond the
    thesis; see the env's *Rewards*)."""
    max_backward_deg: float = 360.0
    """Wrong-way limit: the episode ends past this turn against the goal (degrees, > 0)."""
    map_window_deg: float = 360.0
    """Span of the grasp-map window around the grasp (degrees, in (0, 360])."""
    map_window_cells: int = 36
    """Cells per side of the grasp-map window (an integer >= 1, at most the grid points
    in ``map_window_deg``)."""
    map_lines: bool = False
    """Append the grasp map's two lines through the grasp (``2 n`` entries, in the hand
    frame; see the env's *Observation Space*). False (the default): no lines."""
    contact_model: str = "point"
    """What the fingertips are in the grasp map (:mod:`graspgait_env.contact_model`):
    ``"point"``, the thesis's point contacts (``GraspGait-v0``'s default); ``"hand"``, the
    simulated hand's rolling ball tips with the friction margin its rotations need, so
    that what is learned on the map runs on the hand (``GraspGaitMujoco-v1``'s
    default)."""
    rotation_lookahead: bool = False
    """Append, for each rotation action, whether a regrasp is legal after that rotation
    (``2 R`` entries, 1: the rotation opens at least one regrasp; a one-step look-ahead
    of the legal-move function of thesis 4.2 and 5.2, not the optimum's regrasps to go;
    see the env's *Observation Space*). False (the default): no look-ahead."""
    regrasp_lookahead: int = 0
    """Append the **reach look-ahead** ``D`` regrasps deep (an integer ``0 ..``
    :data:`~graspgait_env.planners.reach.MAX_REACH_DEPTH` ``+ 1``; 0, the default: none;
    beyond the thesis): for each regrasp action, how far short of the turn the grasp it
    makes stays after the best chain of ``j`` more regrasps, ``j = 0 .. D - 1``; for
    each rotation action, the least of those (``j = D - 1``) over the regrasps legal
    after it (``2 P D + 2 R`` entries; a depth-limited search of the grasp map,
    :class:`~graspgait_env.planners.reach.RegraspReach`, not the optimum's regrasps to
    go; see the env's *Observation Space*)."""
    forbid_reversal: bool = False
    """After a rotation, make the rotations the other way illegal until the next regrasp
    (True; beyond the thesis), so that a policy cannot rock the object back and forth
    without ever regrasping. No gait needs such a reversal: a rotation by ``a`` followed
    by one by ``-b`` is the single rotation by ``a - b``, legal whenever both were (its
    path lies within theirs, thesis 5.2), with the same regrasps and fewer rotations; so
    the fewest regrasps from every state, and every planner's gait, are unchanged
    (tested). False (the default): every rotation of ``model.action_mask`` is legal."""
    forbid_revisit: bool = False
    """Make every move to a state already visited in this episode illegal (True; beyond
    the thesis, whose best-first search never expands a node twice, 5.3), so that a
    deterministic policy cannot cycle (a regrasp and its undo, a rotation back and
    forth) until the time limit. A state is the object angle with the contacts
    (:class:`~graspgait_env.gait.GaitState`). The fewest regrasps from the start are
    unchanged: a gait that revisits a state contains a cycle, and cutting it out leaves a
    gait with no more regrasps that visits every state once, legal step by step (tested
    with every planner's gait). Later in an episode the fewest regrasps from the present
    state can grow (the way back is closed), and a dead end can follow a legal move
    (every move leads to a visited state). False (the default): the moves of
    ``model.action_mask``."""

    observation_mode: str = "box"
    """What ``reset`` and ``step`` return (:mod:`graspgait_env.envs.observation`):
    ``"box"`` (the default), one vector read by the offsets of the env's *Observation
    Space* table (what the shipped models read); ``"dict"``, a ``Dict`` of named parts
    (``grasp``, ``actions`` with one row of features per action, ``window``, and
    ``lines`` with ``map_lines``); ``"flat"``, that dict flattened into one ``Box``
    (``gymnasium.spaces.flatten`` of it). The moves, masks and rewards are the same in
    every mode."""

    def __post_init__(self) -> None:
        def put(name: str, value: Any) -> None:
            object.__setattr__(self, name, value)  # frozen: normalize once, here

        if not (self.hand is None or isinstance(self.hand, (str, os.PathLike, Hand))):
            from graspgait_env.workspace import bundled_hands

            raise GraspGaitInputError(
                f"hand={self.hand!r}: give a bundled hand name ({', '.join(bundled_hands())}), "
                "a path to a hand YAML, a Hand, or None for the thesis hand")
        put("turn_deg", check_number("turn_deg", self.turn_deg, "360 (CCW) or -360 (CW)",
                                     nonzero=True, why="degrees; the sign is the direction"))
        try:
            put("n", check_n(self.n))
        except ValueError as exc:
            raise GraspGaitInputError(str(exc)) from None
        put("alpha", check_number("alpha", self.alpha, 1.0))
        for name, example in (("beta", 0.01), ("gamma", 0.01), ("dead_end_penalty", 1.0),
                              ("illegal_penalty", 0.1), ("to_go_weight", 0.1)):
            put(name, check_number(name, getattr(self, name), example, minimum=0.0,
                                   why="it is subtracted as a cost"))
        if self.turn_scale_deg is not None:
            put("turn_scale_deg", check_number(
                "turn_scale_deg", self.turn_scale_deg, "360, or None for abs(turn_deg)",
                minimum=0.0, strict=True))
        put("success_bonus", check_number("success_bonus", self.success_bonus, 1.0))
        put("max_backward_deg", check_number("max_backward_deg", self.max_backward_deg,
                                             360.0, minimum=0.0, strict=True))
        put("map_window_deg", check_number("map_window_deg", self.map_window_deg, 360.0,
                                           minimum=0.0, strict=True, maximum=360.0,
                                           why="degrees; 360 is the whole map"))
        put("map_window_cells", check_count("map_window_cells", self.map_window_cells, 1, 36))
        if not isinstance(self.map_lines, (bool, np.bool_)):
            raise GraspGaitInputError(f"map_lines={self.map_lines!r}: must be True or False")
        put("map_lines", bool(self.map_lines))
        if not isinstance(self.rotation_lookahead, (bool, np.bool_)):
            raise GraspGaitInputError(
                f"rotation_lookahead={self.rotation_lookahead!r}: must be True or False")
        put("rotation_lookahead", bool(self.rotation_lookahead))
        from graspgait_env.planners.reach import MAX_REACH_DEPTH

        depth = check_count("regrasp_lookahead", self.regrasp_lookahead, 0, 3)
        if depth > MAX_REACH_DEPTH + 1:
            raise GraspGaitInputError(
                f"regrasp_lookahead={self.regrasp_lookahead!r}: at most {MAX_REACH_DEPTH + 1} "
                "regrasps deep (0: off), e.g. 3")
        put("regrasp_lookahead", depth)
        if not isinstance(self.forbid_reversal, (bool, np.bool_)):
            raise GraspGaitInputError(
                f"forbid_reversal={self.forbid_reversal!r}: must be True or False")
        put("forbid_reversal", bool(self.forbid_reversal))
        if not isinstance(self.forbid_revisit, (bool, np.bool_)):
            raise GraspGaitInputError(
                f"forbid_revisit={self.forbid_revisit!r}: must be True or False")
        put("forbid_revisit", bool(self.forbid_revisit))
        from graspgait_env.envs.observation import check_observation_mode

        check_observation_mode(self.observation_mode)
        from graspgait_env.contact_model import CONTACT_MODELS

        if self.contact_model not in CONTACT_MODELS:
            raise GraspGaitInputError(
                f"contact_model={self.contact_model!r}: use 'point' (the thesis's point "
                "contacts) or 'hand' (the simulated hand's ball tips)")
        self.window_stride()

    # ------------------------------------------------------------------ derived values
    @property
    def turn_scale(self) -> float:
        """``turn_scale_deg`` resolved: ``abs(turn_deg)`` when it is None (degrees)."""
        return abs(self.turn_deg) if self.turn_scale_deg is None else self.turn_scale_deg

    def window_stride(self) -> int:
        """Grid steps pooled per window cell, ``s``: ``s * cells`` grid steps span about
        ``map_window_deg`` (see the env's *Observation Space*).

        Raises
        ------
        GraspGaitInputError
            More cells than grid points in the span.
        """
        cells = self.map_window_cells
        step_deg = 360.0 / self.n  # the grid step (GaitModel.step_deg)
        span = max(1, round(self.map_window_deg / step_deg))
        s = max(1, span // cells)
        if s * cells > self.n:
            raise GraspGaitInputError(
                f"map_window_cells={cells}: more cells than grid points in "
                f"map_window_deg={self.map_window_deg:g} at n={self.n}; use at most "
                f"{max(1, min(self.n, span))} cells")
        return s

    def planning_contact_model(self, object: str | os.PathLike | Shape,  # noqa: A002
                               sim_config: Any = None):
        """The :class:`~graspgait_env.contact_model.ContactModel` that ``contact_model``
        names for ``object`` with this config's hand and turn (``"hand"``: from
        ``sim_config``, default ``configs/sim/default.yaml``)."""
        from graspgait_env.contact_model import contact_model_named
        from graspgait_env.objects import load_object
        from graspgait_env.workspace import load_hand

        if self.contact_model == "point":
            return contact_model_named("point", object)
        hand, _ = load_hand(self.hand, load_object(object))
        return contact_model_named("hand", object, sim_config,
                                   workspaces_deg=hand.workspaces_deg, turn_deg=self.turn_deg)

    # ------------------------------------------------------------------ construction
    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The fields, in order (each is also a keyword argument of every env id)."""
        return tuple(f.name for f in fields(cls))

    @classmethod
    def merged(cls, config: GraspGaitConfig | None, overrides: Mapping[str, Any], *,
               owner: str = "GraspGaitConfig", other_args: Sequence[str] = (),
               hints: Mapping[str, str] | None = None) -> GraspGaitConfig:
        """``config`` (default: the defaults) with the fields in ``overrides`` replaced.

        Parameters
        ----------
        config
            A :class:`GraspGaitConfig` or None.
        overrides
            Keyword arguments; each must be a field.
        owner
            Who takes them (an env id), for messages.
        other_args
            The owner's other keyword arguments, listed as valid in the message.
        hints
            Extra advice for a name that is not an argument of ``owner`` (by name).

        Raises
        ------
        GraspGaitInputError
            ``config`` is not a config, or a name is not a field nor in ``other_args``:
            the message names it, suggests the nearest valid name and lists them all.
        """
        if config is not None and not isinstance(config, GraspGaitConfig):
            raise GraspGaitInputError(
                f"config={config!r}: give a GraspGaitConfig, e.g. GraspGaitConfig(beta=0.05), "
                "or pass its fields as keyword arguments")
        names = cls.field_names()
        for key, value in overrides.items():
            if key not in names:
                valid = [*other_args, *names]
                near = difflib.get_close_matches(key, valid, n=1)
                if _SYNONYMS.get(key) in valid:
                    near = [_SYNONYMS[key]]
                hint = (hints or {}).get(key) or (f"did you mean {near[0]!r}?" if near else "")
                raise GraspGaitInputError(
                    f"{key}={value!r}: {owner} has no keyword argument {key!r}; "
                    f"{hint + ' ' if hint else ''}valid: {', '.join(valid)}")
        if config is None:
            return cls(**overrides)
        return replace(config, **overrides) if overrides else config
