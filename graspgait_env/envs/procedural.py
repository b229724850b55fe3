"""Procedural objects for ``GraspGaitRandom-v0``: seeded star-shaped polygons and ellipses.

Every object is a pure function of ``(seed, level)``: :func:`procedural_object` draws
from ``numpy.random.default_rng([seed, level])`` and nothing else, so the same seed
gives the same object on every machine and in every process, and a *range* of seeds
names a fixed set of objects. Training draws seeds outside :data:`EVAL_SEEDS` (the
default of :class:`ObjectSampler`); evaluation draws seeds inside it, so evaluation
objects are never seen in training.

Difficulty levels (:data:`LEVELS`) follow the thesis's findings (3.3–3.4, 6.2): gaits
are easy for round objects at high friction and get harder, or vanish, as the
eccentricity ``E`` grows, the smoothness ``S`` (number of sides) drops and ``mu``
falls. Level 0 draws nearly round objects at high ``mu``; each higher level widens the
range towards more eccentric or angular objects (star notches from level 2) and lower
``mu``. Ranges are cumulative: a level's objects include easier ones.

Bundled objects (``configs/objects``) join a level when their eccentricity and
smoothness fall inside its limits (:func:`bundled_for_level`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.objects import bundled_objects, load_object
from graspgait_env.shapes import Ellipse, Polygon, Shape

__all__ = [
    "Level",
    "LEVELS",
    "EVAL_SEEDS",
    "SEED_RANGE",
    "procedural_object",
    "bundled_for_level",
    "ObjectSampler",
    "check_level",
]

SEED_RANGE = (0, 2**31 - 1)  # all object seeds, half-open [lo, hi)
EVAL_SEEDS = (1_000_000, 1_100_000)  # held out of training by default, half-open [lo, hi)
_MAX_TRIES = 50  # procedural draws per seed before falling back to a regular polygon


@dataclass(frozen=True)
class Level:
    """Ranges from which one difficulty level draws its objects and friction.

    Attributes
    ----------
    ecc_max
        Largest eccentricity ``E = r_max / r_min`` (thesis 3.3) of a drawn object.
    sides
        ``(lo, hi)`` inclusive number of polygon sides (smoothness ``S``, thesis 3.4).
    notch_max
        Largest star notch depth (fraction of the radius) between polygon corners;
        0 draws convex-ish polygons only.
    radial_noise
        Relative jitter of each polygon corner's radius.
    mu
        ``(lo, hi)`` range of the Coulomb friction coefficient.
    ellipse_prob
        Probability that a procedural object is an ellipse rather than a polygon.
    smooth_min
        Smallest smoothness ``S`` of a bundled object admitted at this level.
    """

    ecc_max: float
    sides: tuple[int, int]
    notch_max: float
    radial_noise: float
    mu: tuple[float, float]
    ellipse_prob: float
    smooth_min: float


LEVELS: tuple[Level, ...] = (
    Level(ecc_max=1.3, sides=(7, 12), notch_max=0.0, radial_noise=0.03, mu=(0.6, 0.9),
          ellipse_prob=0.5, smooth_min=6),
    Level(ecc_max=1.9, sides=(5, 10), notch_max=0.0, radial_noise=0.08, mu=(0.45, 0.9),
          ellipse_prob=0.4, smooth_min=4),
    Level(ecc_max=2.6, sides=(3, 8), notch_max=0.25, radial_noise=0.12, mu=(0.3, 0.9),
          ellipse_prob=0.35, smooth_min=3),
    Level(ecc_max=3.5, sides=(3, 8), notch_max=0.4, radial_noise=0.15, mu=(0.2, 0.9),
          ellipse_prob=0.3, smooth_min=3),
)
_SIZE_M = (0.06, 0.11)  # (m) range of the largest radius of a procedural object


def check_level(level: int) -> int:
    """Validate a difficulty level: an integer in ``0 .. len(LEVELS) - 1``."""
    if isinstance(level, bool) or not isinstance(level, (int, np.integer)) or not (
            0 <= level < len(LEVELS)):
        raise GraspGaitInputError(f"level={level!r}: must be an integer in "
                                  f"0..{len(LEVELS) - 1} (0 easiest), e.g. 0")
    return int(level)


def _polygon(rng: np.random.Generator, lv: Level, name: str) -> Polygon | None:
    m = int(rng.integers(lv.sides[0], lv.sides[1] + 1))
    spacing = 2.0 * math.pi / m
    ang = rng.uniform(0.0, 2.0 * math.pi) + spacing * np.arange(m)
    ang = ang + rng.uniform(-0.2, 0.2, m) * spacing  # consecutive gaps stay in (0.6, 1.4) x
    stretch = math.sqrt(rng.uniform(1.0, lv.ecc_max))  # affine stretch keeps it star-shaped
    r = 1.0 + lv.radial_noise * rng.uniform(-1.0, 1.0, m)
    xy = np.stack([r * np.cos(ang) * stretch, r * np.sin(ang) / stretch], axis=1)
    notch = rng.uniform(0.0, lv.notch_max) if lv.notch_max > 0 else 0.0
    if notch > 0.0:
        # a notch vertex between consecutive corners, pulled towards the origin
        mid = 0.5 * (xy + np.roll(xy, -1, axis=0)) * (1.0 - notch)
        xy = np.stack([xy, mid], axis=1).reshape(-1, 2)
    xy *= rng.uniform(*_SIZE_M) / float(np.max(np.hypot(xy[:, 0], xy[:, 1])))
    try:
        poly = Polygon(xy, name=name)
    except ValueError:
        return None
    return poly if poly.eccentricity <= lv.ecc_max else None


def procedural_object(seed: int, level: int = 0) -> Shape:
    """The procedural object of ``seed`` at difficulty ``level`` (deterministic).

    Parameters
    ----------
    seed
        Non-negative integer; the object is a pure function of ``(seed, level)``.
    level
        Difficulty level, an index into :data:`LEVELS`.

    Returns
    -------
    Shape
        An :class:`~graspgait_env.shapes.Ellipse` or a star-shaped
        :class:`~graspgait_env.shapes.Polygon` named ``"proc-L<level>-<seed>"``, with
        eccentricity at most ``LEVELS[level].ecc_max``.

    Examples
    --------
    >>> a, b = procedural_object(7, 1), procedural_object(7, 1)
    >>> repr(a) == repr(b)
    True
    >>> procedural_object(7, 1).eccentricity <= LEVELS[1].ecc_max
    True
    """
    level = check_level(level)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise GraspGaitInputError(f"seed={seed!r}: must be a non-negative integer, e.g. 42")
    lv = LEVELS[level]
    name = f"proc-L{level}-{int(seed)}"
    rng = np.random.default_rng([int(seed), level])
    if rng.random() < lv.ellipse_prob:
        e = rng.uniform(1.0, lv.ecc_max)
        big = rng.uniform(*_SIZE_M)
        if rng.random() < 0.5:
            return Ellipse(big, big / e, name=name)
        return Ellipse(big / e, big, name=name)
    for _ in range(_MAX_TRIES):
        poly = _polygon(rng, lv, name)
        if poly is not None:
            return poly
    # fallback (never met in practice): a regular polygon with the level's most sides
    m = lv.sides[1]
    a = 2.0 * math.pi * (np.arange(m) + 0.5) / m
    return Polygon(0.08 * np.stack([np.cos(a), np.sin(a)], axis=1), name=name)


def bundled_for_level(level: int) -> list[str]:
    """Bundled objects whose ``E`` and ``S`` fall inside ``LEVELS[level]`` (sorted names)."""
    lv = LEVELS[check_level(level)]
    out = []
    for name in bundled_objects():
        s = load_object(name)
        if s.eccentricity <= lv.ecc_max + 1e-9 and s.smoothness >= lv.smooth_min:
            out.append(name)
    return out


def _check_range(name: str, r: Any) -> tuple[int, int]:
    fix = "give a half-open (lo, hi) range of integer seeds with 0 <= lo < hi, e.g. (0, 1000)"
    pair = (not isinstance(r, (str, bytes)) and hasattr(r, "__len__") and len(r) == 2
            and all(isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))
                    for v in r))
    if not pair or not 0 <= r[0] < r[1]:
        raise GraspGaitInputError(f"{name}={r!r}: {fix}")
    return int(r[0]), int(r[1])


class ObjectSampler:
    """Draws ``(object, object_seed)`` from a generator: procedural or bundled.

    Parameters
    ----------
    level
        Difficulty level (see :data:`LEVELS`).
    object_seeds
        Half-open range ``(lo, hi)`` of procedural seeds to draw from.
    exclude_seeds
        Half-open range of seeds never drawn (default :data:`EVAL_SEEDS`); ``None``
        excludes nothing. Evaluate with ``object_seeds=EVAL_SEEDS, exclude_seeds=None``.
    bundled_fraction
        Probability of drawing a bundled object (from :func:`bundled_for_level`)
        instead of a procedural one; 0 draws procedural objects only.

    Raises
    ------
    GraspGaitInputError
        A bad level, range or fraction, or an empty set of seeds to draw from (a
        ``ValueError``; the message names the argument and the fix).
    """

    def __init__(self, level: int = 0, object_seeds: tuple[int, int] = SEED_RANGE,
                 exclude_seeds: tuple[int, int] | None = EVAL_SEEDS,
                 bundled_fraction: float = 0.2) -> None:
        self.level = check_level(level)
        self.object_seeds = _check_range("object_seeds", object_seeds)
        self.exclude_seeds = (None if exclude_seeds is None
                              else _check_range("exclude_seeds", exclude_seeds))
        if (isinstance(bundled_fraction, (bool, np.bool_))
                or not isinstance(bundled_fraction, (int, float, np.integer, np.floating))
                or not 0.0 <= bundled_fraction <= 1.0):
            raise GraspGaitInputError(f"bundled_fraction={bundled_fraction!r}: must be a number "
                                      "in [0, 1] (the probability of a bundled object), e.g. 0.2")
        self.bundled_fraction = float(bundled_fraction)
        self.bundled = bundled_for_level(self.level)
        self._bundled_shapes = {name: load_object(name) for name in self.bundled}
        lo, hi = self.object_seeds
        xlo, xhi = self.exclude_seeds or (lo, lo)
        self._cut_lo, self._cut_hi = max(lo, min(xlo, hi)), max(lo, min(xhi, hi))
        self.n_seeds = (hi - lo) - (self._cut_hi - self._cut_lo)
        if self.n_seeds <= 0 and self.bundled_fraction < 1.0:
            raise GraspGaitInputError(f"object_seeds={self.object_seeds} minus exclude_seeds="
                             f"{self.exclude_seeds} leaves no seed; widen object_seeds")
        if self.bundled_fraction > 0.0 and not self.bundled:
            raise GraspGaitInputError(f"level {self.level} admits no bundled object; set "
                             "bundled_fraction=0")

    def seed_at(self, i: int) -> int:
        """The ``i``-th allowed seed (``0 <= i < n_seeds``), skipping the excluded range."""
        s = self.object_seeds[0] + int(i)
        return s if s < self._cut_lo else s + (self._cut_hi - self._cut_lo)

    def is_allowed(self, seed: int) -> bool:
        """True when ``seed`` lies in ``object_seeds`` and outside ``exclude_seeds``."""
        lo, hi = self.object_seeds
        return lo <= seed < hi and not self._cut_lo <= seed < self._cut_hi

    def sample(self, rng: np.random.Generator) -> tuple[Shape, int]:
        """Draw one object with ``rng``; returns ``(shape, seed)``, seed -1 for bundled."""
        if self.bundled_fraction > 0.0 and (self.n_seeds <= 0
                                            or rng.random() < self.bundled_fraction):
            name = self.bundled[int(rng.integers(len(self.bundled)))]
            return self._bundled_shapes[name], -1
        seed = self.seed_at(int(rng.integers(self.n_seeds)))
        return procedural_object(seed, self.level), seed

    def sample_mu(self, rng: np.random.Generator,
                  mu_range: tuple[float, float] | None = None) -> float:
        """Draw ``mu`` uniformly from ``mu_range`` (default the level's range)."""
        lo, hi = LEVELS[self.level].mu if mu_range is None else mu_range
        return float(rng.uniform(lo, hi))
