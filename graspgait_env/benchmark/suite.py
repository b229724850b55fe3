"""The benchmark's task suite: one versioned list, defined here and nowhere else.

A :class:`Task` names what is measured and how much of it:

- ``env_id`` and ``kwargs``: the env of the test episodes (``gymnasium.make(env_id,
  **kwargs)``; :meth:`Task.env_kwargs` builds them, the hand track's finger friction
  included);
- ``train_env_id`` and ``train_kwargs``: the env a learner trains in (the same problem,
  with the training objects where the task has a test set of objects);
- ``train_seeds`` and ``test_seeds``: half-open ranges of reset seeds. Training and
  demonstrations reset with seeds of the first (``graspgait train`` resets its envs with
  ``seed + i`` and evaluates periodically from 10,000 on); run seed ``s`` of the
  benchmark plays the test episodes ``test_seeds[0] + s * episodes + i``,
  ``i = 0 .. episodes - 1`` (:meth:`Task.test_slice`), so the runs of a row see
  different, disjoint starts of the same distribution;
- ``episodes``: the test episodes per run (the episode budget), and ``train_steps``: the
  environment steps a learned row may train for (0: the task is not trained in; its
  policy comes from ``train_task``, the map-level twin of a hand-track task).

Tracks (``Task.track``), ``mu`` 0.7 and a 360° counter-clockwise turn throughout:

- ``map-point``: the four thesis objects (circle, ellipse, pentagon, hexagon; thesis fig.
  5.3) in ``GraspGait-v0`` with the thesis's point contacts;
- ``map-hand``: the same with the MuJoCo hand's contact model (its rolling ball tips and
  friction margin, ``contact_model="hand"``);
- ``random``: generalization, ``GraspGaitRandom-v0`` at levels 0-3. Training objects: the
  bundled objects admitted at the level and the procedural objects of every seed outside
  :data:`~graspgait_env.envs.procedural.EVAL_SEEDS`; test objects: the procedural objects
  of the seeds in ``EVAL_SEEDS`` only (no bundled object). :func:`check_disjoint` proves
  the two sets share no object;
- ``mujoco``: the hand track, ``GraspGaitMujoco-v1`` (every move executed by the thesis
  controller on the simulated hand) on the four thesis objects, twice: from perturbed
  initial poses (``pose_noise="thesis"``: up to 6 mm and 5°, thesis 7.5) and with the
  finger friction a little below the planning ``mu`` (``finger_mu`` 0.65 against 0.7),
  so that robustness is measured, not assumed. MuJoCo episodes cost 1-10 s each, so the
  budget is small: 5 episodes per run.

Versioning (docs/benchmark.md): :data:`SUITE_VERSION` changes whenever a task, a seed
range or a budget changes; an env id's version changes whenever the env changes in a
way that can change a learning result (Gymnasium's practice), and a task names its ids
with their versions.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from graspgait_env.errors import GraspGaitInputError

__all__ = ["SUITE_VERSION", "TASKS", "TRACKS", "Task", "check_disjoint", "format_suite",
           "get_task", "object_fingerprint", "parse_tasks", "task_ids"]

SUITE_VERSION = 1
"""The suite's version: bumped by any change to a task, its seeds or its budgets."""

THESIS_OBJECTS = ("circle", "ellipse", "pentagon", "hexagon")
MU = 0.7
TRAIN_SEEDS = (0, 1_000_000)  # reset seeds of training, its evaluations, demonstrations
TEST_SEEDS = (1_000_000, 1_100_000)  # reset seeds of the test episodes
MAP_EPISODES = 40  # test episodes per run, map level
MUJOCO_EPISODES = 5  # test episodes per run on the simulated hand (1-10 s each)
MAP_TRAIN_STEPS = 500_000
RANDOM_TRAIN_STEPS = 1_000_000
FINGER_MU = 0.65  # the hand track's finger friction, a little below the planning mu
TRACKS = ("map-point", "map-hand", "random", "mujoco")

# keywords that define the problem: a task sets them, a policy's own keywords never do
TASK_KEYS = frozenset({
    "object", "mu", "contact_model", "level", "mu_range", "object_seeds", "exclude_seeds",
    "bundled_fraction", "sim_config", "pose_noise", "hand", "n",
    "turn_deg", "max_backward_deg", "turn_scale_deg"})


@dataclass(frozen=True)
class Task:
    """One benchmark task (see the module docstring for each field's meaning)."""

    id: str
    track: str
    env_id: str
    kwargs: Mapping[str, Any]
    train_env_id: str
    train_kwargs: Mapping[str, Any]
    episodes: int
    train_steps: int
    train_seeds: tuple[int, int] = TRAIN_SEEDS
    test_seeds: tuple[int, int] = TEST_SEEDS
    sim: Mapping[str, Any] = field(default_factory=dict)
    """SimConfig fields changed from the bundled default (the hand track's finger_mu)."""
    train_task: str | None = None
    """The task whose training env this one's policies learn in (None: this one)."""
    description: str = ""

    def env_kwargs(self) -> dict[str, Any]:
        """The keyword arguments of the test env (a ``SimConfig`` built for ``sim``)."""
        kw = dict(self.kwargs)
        if self.sim:
            from graspgait_env.sim.config import load_sim_config

            kw["sim_config"] = load_sim_config(None).replace(**dict(self.sim))
        return kw

    def describe_kwargs(self) -> dict[str, Any]:
        """The test env's keywords as JSON-ready values (``sim`` for the SimConfig)."""
        kw = {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.kwargs.items()}
        if self.sim:
            kw["sim"] = dict(self.sim)
        return kw

    def test_slice(self, seed: int, episodes: int | None = None) -> int:
        """The first test reset seed of run ``seed`` (episodes ``first .. first + N - 1``).

        Raises
        ------
        GraspGaitInputError
            The slice would run past the task's test seeds.
        """
        n = self.episodes if episodes is None else int(episodes)
        first = self.test_seeds[0] + int(seed) * n
        if seed < 0 or first + n > self.test_seeds[1]:
            raise GraspGaitInputError(
                f"--seeds {seed} with --episodes {n}: task {self.id} has test reset seeds "
                f"{self.test_seeds[0]}..{self.test_seeds[1] - 1}; use fewer seeds or episodes")
        return first

    def to_dict(self) -> dict[str, Any]:
        """The task as JSON-ready values (``--list-tasks --json``, the run's record)."""
        return {"id": self.id, "track": self.track, "env_id": self.env_id,
                "kwargs": self.describe_kwargs(), "train_env_id": self.train_env_id,
                "train_kwargs": {k: (list(v) if isinstance(v, tuple) else v)
                                 for k, v in self.train_kwargs.items()},
                "train_task": self.train_task or self.id,
                "train_seeds": list(self.train_seeds), "test_seeds": list(self.test_seeds),
                "episodes": self.episodes, "train_steps": self.train_steps,
                "description": self.description}


def _tasks() -> tuple[Task, ...]:
    from graspgait_env.envs.procedural import EVAL_SEEDS, SEED_RANGE

    out: list[Task] = []
    for obj in THESIS_OBJECTS:
        kw = {"object": obj, "mu": MU, "contact_model": "point"}
        out.append(Task(f"map-point-{obj}", "map-point", "GraspGait-v0", kw, "GraspGait-v0",
                        kw, MAP_EPISODES, MAP_TRAIN_STEPS,
                        description=f"the thesis's {obj} at mu {MU}, point contacts"))
    for obj in THESIS_OBJECTS:
        kw = {"object": obj, "mu": MU, "contact_model": "hand"}
        out.append(Task(f"map-hand-{obj}", "map-hand", "GraspGait-v0", kw, "GraspGait-v0",
                        kw, MAP_EPISODES, MAP_TRAIN_STEPS,
                        description=f"the thesis's {obj} at mu {MU}, the hand's contact model"))
    for level in range(4):
        test = {"level": level, "object_seeds": EVAL_SEEDS, "exclude_seeds": None,
                "bundled_fraction": 0.0}
        train = {"level": level, "object_seeds": SEED_RANGE, "exclude_seeds": EVAL_SEEDS,
                 "bundled_fraction": 0.2}
        out.append(Task(f"random-l{level}", "random", "GraspGaitRandom-v0", test,
                        "GraspGaitRandom-v0", train, MAP_EPISODES, RANDOM_TRAIN_STEPS,
                        description=f"level {level}: trained on its bundled objects and the "
                        "procedural objects outside the held-out seeds, tested on held-out "
                        "procedural objects"))
    for obj in THESIS_OBJECTS:
        twin = {"object": obj, "mu": MU, "contact_model": "hand"}
        out.append(Task(f"mujoco-pose-{obj}", "mujoco", "GraspGaitMujoco-v1",
                        {**twin, "pose_noise": "thesis"}, "GraspGait-v0", twin,
                        MUJOCO_EPISODES, 0, train_task=f"map-hand-{obj}",
                        description=f"the {obj} on the simulated hand from perturbed poses "
                        "(up to 6 mm and 5 deg, thesis 7.5)"))
        out.append(Task(f"mujoco-friction-{obj}", "mujoco", "GraspGaitMujoco-v1", twin,
                        "GraspGait-v0", twin, MUJOCO_EPISODES, 0, sim={"finger_mu": FINGER_MU},
                        train_task=f"map-hand-{obj}",
                        description=f"the {obj} on the simulated hand, finger friction "
                        f"{FINGER_MU} below the planning mu {MU}"))
    return tuple(out)


TASKS: tuple[Task, ...] = _tasks()
"""Every task of suite version :data:`SUITE_VERSION`, in the scoreboard's order."""

_BY_ID = {t.id: t for t in TASKS}


def task_ids() -> list[str]:
    """The ids of every task, in order."""
    return [t.id for t in TASKS]


def get_task(task_id: str) -> Task:
    """The task called ``task_id``.

    Raises
    ------
    GraspGaitInputError
        Unknown id; the message suggests the nearest and names the tracks.
    """
    task = _BY_ID.get(task_id)
    if task is None:
        import difflib

        near = difflib.get_close_matches(task_id, list(_BY_ID), n=1)
        hint = f"did you mean {near[0]!r}? " if near else ""
        raise GraspGaitInputError(
            f"task {task_id!r}: not in the suite; {hint}`graspgait benchmark --list-tasks` "
            f"lists them (a track name, e.g. {TRACKS[0]}, selects a whole track)")
    return task


def parse_tasks(text: str | Sequence[str] | None) -> list[Task]:
    """``"map-point-circle,random"``: task ids and track names (a track: its tasks), in
    suite order, each once; None or ``"all"``: every task.

    Raises
    ------
    GraspGaitInputError
        An unknown id or track, or an empty list.
    """
    if text is None:
        return list(TASKS)
    parts = [p.strip() for p in (text.split(",") if isinstance(text, str) else text)]
    parts = [p for p in parts if p]
    if not parts:
        raise GraspGaitInputError(f"--tasks {text!r}: give task ids or tracks, e.g. "
                                  "map-point-circle,random")
    chosen: set[str] = set()
    for p in parts:
        if p == "all":
            chosen.update(_BY_ID)
        elif p in TRACKS:
            chosen.update(t.id for t in TASKS if t.track == p)
        else:
            chosen.add(get_task(p).id)
    return [t for t in TASKS if t.id in chosen]


def object_fingerprint(shape: Any) -> str:
    """A digest of an object's contour (its radius at every half degree, to 1e-9 m):
    two objects with the same fingerprint are the same object, whatever their names."""
    r = np.asarray(shape.radius(np.arange(720) * 0.5), dtype=np.float64)
    return hashlib.sha1(np.round(r, 9).tobytes()).hexdigest()


def check_disjoint(task: Task, test_objects: Sequence[Any] = ()) -> None:
    """Check that the test objects of ``task`` are none of its training objects.

    For a ``GraspGaitRandom-v0`` task: the test seed range lies inside the range the
    training env excludes (or outside its seed range), the test env draws no bundled
    object, and both envs draw at the same level, so every test object is the procedural
    object of a seed that training never draws (the object is a pure function of the
    seed and the level). ``test_objects`` (shapes, e.g. those the test episodes drew)
    (or their names) are further checked: each must be named for a seed of the test
    range, and its :func:`object_fingerprint` must differ from every bundled object the
    training env admits. Tasks on one object
    have no held-out objects: nothing to check.

    Raises
    ------
    GraspGaitInputError
        The sets may share an object (the message says how).
    """
    if task.env_id != "GraspGaitRandom-v0":
        return
    from graspgait_env.envs.procedural import SEED_RANGE, bundled_for_level
    from graspgait_env.objects import load_object

    test, train = dict(task.kwargs), dict(task.train_kwargs)
    if test.get("level") != train.get("level"):
        raise GraspGaitInputError(f"task {task.id}: train and test levels differ")
    level = int(test["level"])
    tlo, thi = test.get("object_seeds", SEED_RANGE)
    lo, hi = train.get("object_seeds", SEED_RANGE)
    ex = train.get("exclude_seeds")
    inside_excluded = ex is not None and ex[0] <= tlo and thi <= ex[1]
    if not (inside_excluded or thi <= lo or hi <= tlo):
        raise GraspGaitInputError(
            f"task {task.id}: test object seeds {tlo}..{thi - 1} overlap the training seeds "
            f"{lo}..{hi - 1} (excluded: {ex})")
    if float(test.get("bundled_fraction", 0.2)) != 0.0:
        raise GraspGaitInputError(f"task {task.id}: the test env draws bundled objects, "
                                  "which training draws too")
    if not test_objects:
        return
    from graspgait_env.envs.procedural import procedural_object

    bundled = {object_fingerprint(load_object(name)): name
               for name in bundled_for_level(level)}
    prefix = f"proc-L{level}-"
    for item in test_objects:
        name = item if isinstance(item, str) else str(getattr(item, "name", ""))
        tail = name[len(prefix):] if name.startswith(prefix) else ""
        seed = int(tail) if tail.isdigit() else None
        if seed is None or not tlo <= seed < thi:
            raise GraspGaitInputError(f"task {task.id}: test object {name!r} is not a "
                                      f"procedural object of seeds {tlo}..{thi - 1}")
        shape = procedural_object(seed, level) if isinstance(item, str) else item
        hit = bundled.get(object_fingerprint(shape))
        if hit is not None:
            raise GraspGaitInputError(f"task {task.id}: test object {name!r} is the "
                                      f"bundled {hit!r}, a training object")


def format_suite(tasks: Sequence[Task] = TASKS) -> str:
    """The suite as a Markdown table (``graspgait benchmark --list-tasks``)."""
    lines = [f"GraspGait benchmark suite v{SUITE_VERSION}: {len(tasks)} tasks", "",
             "| task | track | env | keywords | train | train steps | test episodes per run "
             "| test reset seeds |", "|---|---|---|---|---|---:|---:|---|"]
    for t in tasks:
        kw = ", ".join(f"{k}={v}" for k, v in t.describe_kwargs().items())
        train = t.train_task or (f"{t.train_env_id} (training objects)"
                                 if t.train_kwargs != t.kwargs else "same env")
        lines.append(f"| {t.id} | {t.track} | {t.env_id} | {kw} | {train} | "
                     f"{t.train_steps:,} | {t.episodes} | {t.test_seeds[0]:,} + "
                     f"seed x episodes + i |")
    return "\n".join(lines)
