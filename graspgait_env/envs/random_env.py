"""``GraspGaitRandom-v0``: a new object and friction at every reset (generalization)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from graspgait_env.envs.config import (
    GraspGaitConfig,
    check_count,
    check_mu,
    check_number,
    check_object,
)
from graspgait_env.envs.map_env import GraspGaitEnv
from graspgait_env.envs.procedural import (
    EVAL_SEEDS,
    LEVELS,
    SEED_RANGE,
    ObjectSampler,
    procedural_object,
)
from graspgait_env.errors import ConfigError, GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.objects import load_object
from graspgait_env.shapes import Circle, Shape
from graspgait_env.workspace import load_hand

__all__ = ["GraspGaitRandomEnv"]

_OBJECT_TRIES = 20  # objects drawn per reset before giving up on finding a legal start


class GraspGaitRandomEnv(GraspGaitEnv):
    r"""``GraspGait-v0`` with the object and ``mu`` drawn anew at every reset.

    ## Description

    As :class:`~graspgait_env.envs.map_env.GraspGaitEnv` (actions, observation,
    rewards, starting state and episode ends are the same, documented there), but each
    ``reset`` draws, from ``self.np_random``:

    - the object: with probability ``bundled_fraction`` a bundled object admitted at
      ``level`` (:func:`~graspgait_env.envs.procedural.bundled_for_level`), otherwise
      the procedural object of a seed drawn uniformly from ``object_seeds`` minus
      ``exclude_seeds`` (:func:`~graspgait_env.envs.procedural.procedural_object`:
      ellipses and star-shaped polygons, a pure function of ``(seed, level)``);
    - ``mu`` uniformly from ``mu_range`` (default the level's range).

    If the drawn object has no legal start grasp with a legal move, another is drawn
    (up to 20 times, then ``RuntimeError`` names the level and ranges).

    With ``episodes_per_object = m > 1`` the object and ``mu`` are kept for ``m``
    episodes in a row (only the start grasp is drawn anew), so per-object work is paid
    once per ``m`` episodes: the regrasps-to-go table of ``to_go_weight`` costs
    0.05-0.2 s of CPU per object, about as much as 100 steps. A reset with a ``seed``,
    or whose options pin the object or ``mu``, always draws anew.

    Levels (:data:`~graspgait_env.envs.procedural.LEVELS`): 0 nearly round objects
    (eccentricity ≤ 1.3, 7–12 sides) at mu ∈ [0.6, 0.9]; 1 up to E = 1.9, 5–10 sides,
    mu ≥ 0.45; 2 up to E = 2.6, 3–8 sides with star notches, mu ≥ 0.3; 3 up to E = 3.5,
    deeper notches, mu ≥ 0.2.

    The hand and ``n`` are fixed, so the action and observation spaces are the same for
    every object (a reach-limited hand, whose workspaces depend on the object, is
    refused). By default the seeds of
    :data:`~graspgait_env.envs.procedural.EVAL_SEEDS` are excluded: evaluate on them with
    ``object_seeds=EVAL_SEEDS, exclude_seeds=None, bundled_fraction=0``.

    ``reset(options=...)`` may fix the episode's object: ``{"object": name | path |
    Shape}`` or ``{"object_seed": int}`` (procedural at this level), and ``{"mu": float}``;
    ``{"start": ...}`` as in ``GraspGait-v0``; any other key raises ``ValueError``
    naming it. The reset ``info`` names the object, ``mu`` and ``object_seed`` (-1 for a
    bundled or given object).

    ## Arguments

    ``gymnasium.make("graspgait_env:GraspGaitRandom-v0", level=0, mu_range=None,
    object_seeds=(0, 2**31 - 1), exclude_seeds=EVAL_SEEDS, bundled_fraction=0.2,
    episodes_per_object=1, *,
    config=None, render_mode=None, **fields)``; ``config``, ``render_mode`` and the
    ``fields`` of :class:`~graspgait_env.envs.config.GraspGaitConfig` (``hand``,
    ``turn_deg``, ``n``, the reward weights, ``max_backward_deg``, the map window) are
    those of ``GraspGait-v0``. ``object`` and ``mu`` are not arguments: they are drawn at
    every reset (pin them with ``reset(options=...)``). Every argument is checked at
    construction (a ``ValueError`` naming it, the value and the fix).

    - ``level``: an integer in ``0 .. 3``.
    - ``mu_range``: ``(lo, hi)`` with ``0 < lo <= hi``; None: the level's range.
    - ``object_seeds``, ``exclude_seeds``: half-open ranges ``(lo, hi)`` of integer
      seeds, ``0 <= lo < hi`` (``exclude_seeds`` may be None).
    - ``bundled_fraction``: the probability of a bundled object, in ``[0, 1]``.
    - ``episodes_per_object``: episodes played on each drawn object and ``mu`` (an
      integer >= 1; 1, the default, draws at every reset).

    ## Version History

    - v0: initial version. ``observation_mode`` (named parts) added since, opt-in: the
      default ``"box"`` is the observation as before.
    """

    _RESET_OPTIONS: ClassVar[tuple[str, ...]] = ("start", "object", "object_seed", "mu")
    _ARG_HINTS: ClassVar[dict[str, str]] = {
        name: ("the object and mu are drawn at every reset: pin them with "
               "reset(options={'object': ..., 'mu': ...}), or use GraspGait-v0;")
        for name in ("object", "mu")}

    def __init__(
        self,
        level: int = 0,
        mu_range: tuple[float, float] | None = None,
        object_seeds: tuple[int, int] = SEED_RANGE,
        exclude_seeds: tuple[int, int] | None = EVAL_SEEDS,
        bundled_fraction: float = 0.2,
        episodes_per_object: int = 1,
        *,
        config: GraspGaitConfig | None = None,
        render_mode: str | None = None,
        **fields: Any,
    ) -> None:
        self._configure(config, render_mode, fields)
        self.sampler = ObjectSampler(level, object_seeds, exclude_seeds, bundled_fraction)
        self.level = self.sampler.level
        self.episodes_per_object = check_count("episodes_per_object", episodes_per_object,
                                               1, 1)
        self._object_episodes = 0  # episodes played on the present object
        if mu_range is not None:
            fix = "give (lo, hi) with 0 < lo <= hi, e.g. (0.3, 0.9), or None for the level's"
            pair = (not isinstance(mu_range, (str, bytes, Mapping))
                    and hasattr(mu_range, "__len__") and len(mu_range) == 2)
            if not pair:
                raise GraspGaitInputError(f"mu_range={mu_range!r}: {fix}")
            lo, hi = (check_number(f"mu_range[{i}]", v, (0.3, 0.9)[i], minimum=0.0, strict=True)
                      for i, v in enumerate(mu_range))
            if lo > hi:
                raise GraspGaitInputError(f"mu_range={mu_range!r}: {fix}")
            mu_range = (lo, hi)
        self.mu_range = mu_range
        hand = self.config.hand
        try:
            self._hand, _ = load_hand(hand, None)
        except ConfigError as exc:
            if exc.field != "reach":
                raise
            raise GraspGaitInputError(
                f"hand={hand!r}: a reach-limited hand's workspaces depend on the object, so the "
                "action space would change between objects; give a hand with fixed "
                "workspaces_deg (e.g. 'thesis')") from None
        self.object_seed = -1
        lo, hi = LEVELS[self.level].mu if mu_range is None else mu_range
        # the spaces depend only on the hand and n: any object sets them up
        self._use_model(GaitModel(Circle(0.08, name="placeholder"), 0.5 * (lo + hi), self._hand,
                                  self.config.n))
        self._make_spaces()

    def _model_for(self, shape: Shape, mu: float) -> GaitModel:
        model = GaitModel(shape, mu, self._hand, self._n,
                          contact_model=self.config.planning_contact_model(shape))
        self._check_model_fits(model)
        return model

    def _on_reset(self, options: Mapping[str, Any]) -> GaitState | None:
        rng = self.np_random
        given = "object" in options or "object_seed" in options or "mu" in options
        if given:
            if "object" in options:
                shape, seed = load_object(check_object(options["object"],
                                                       "options['object']")), -1
            elif "object_seed" in options:
                seed = check_count("options['object_seed']", options["object_seed"], 0, 42)
                shape = procedural_object(seed, self.level)
            else:
                shape, seed = self.sampler.sample(rng)
            mu = (check_mu(options["mu"], "options['mu']") if "mu" in options
                  else self.sampler.sample_mu(rng, self.mu_range))
            self._use_model(self._model_for(shape, mu))
            self.object_seed = seed
            self._object_episodes = 1
            return None  # _draw_start / the given start report a problem with this object
        if 0 < self._object_episodes < self.episodes_per_object and not self._seeded:
            self._object_episodes += 1  # the same object and mu, a new start grasp
            return None if "start" in options else self._draw_start()
        for _ in range(_OBJECT_TRIES):
            shape, seed = self.sampler.sample(rng)
            mu = self.sampler.sample_mu(rng, self.mu_range)
            self._use_model(self._model_for(shape, mu))
            self.object_seed = seed
            self._object_episodes = 1
            if "start" in options:
                return None
            try:
                return self._draw_start()
            except ValueError:
                continue
        raise RuntimeError(
            f"level {self.level}: {_OBJECT_TRIES} objects drawn in a row had no legal start "
            f"grasp with a legal move (mu_range={self.mu_range}, seeds "
            f"{self.sampler.object_seeds}); raise mu_range or lower the level")

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Draw an object and ``mu``, then start an episode (see the class docstring)."""
        self._seeded = seed is not None
        obs, info = super().reset(seed=seed, options=options)
        info["object_seed"] = self.object_seed
        return obs, info
