"""The task suite: ids, versions, budgets, disjoint training and test objects, and every
task's env."""

from __future__ import annotations

import dataclasses
import re

import gymnasium as gym
import pytest

import graspgait_env  # noqa: F401  (registers the ids)
from graspgait_env.benchmark.suite import (
    SUITE_VERSION,
    TASKS,
    TRACKS,
    check_disjoint,
    format_suite,
    get_task,
    parse_tasks,
    task_ids,
)
from graspgait_env.envs.procedural import EVAL_SEEDS
from graspgait_env.envs.registration import ENV_IDS
from graspgait_env.errors import GraspGaitInputError

THESIS = ("circle", "ellipse", "pentagon", "hexagon")


def test_ids_are_unique_and_the_suite_is_versioned():
    ids = task_ids()
    assert len(ids) == len(set(ids)) == 20
    assert isinstance(SUITE_VERSION, int) and SUITE_VERSION >= 1
    for t in TASKS:
        assert t.env_id in ENV_IDS and re.search(r"-v\d+$", t.env_id)
        assert t.train_env_id in ENV_IDS
        assert t.track in TRACKS
        assert t.episodes >= 1 and t.train_steps >= 0
        lo, hi = t.test_seeds
        assert t.train_seeds[1] <= lo < hi  # test starts never among the training seeds
    assert f"v{SUITE_VERSION}" in format_suite()


def test_the_suite_covers_the_issue():
    by_track = {tr: [t for t in TASKS if t.track == tr] for tr in TRACKS}
    for track in ("map-point", "map-hand"):
        assert sorted(t.kwargs["object"] for t in by_track[track]) == sorted(THESIS)
        assert all(t.kwargs["mu"] == 0.7 for t in by_track[track])
    assert {t.kwargs["contact_model"] for t in by_track["map-point"]} == {"point"}
    assert {t.kwargs["contact_model"] for t in by_track["map-hand"]} == {"hand"}
    assert sorted(t.kwargs["level"] for t in by_track["random"]) == [0, 1, 2, 3]
    mujoco = by_track["mujoco"]
    assert all(t.env_id == "GraspGaitMujoco-v1" and t.train_steps == 0 for t in mujoco)
    pose = [t for t in mujoco if t.kwargs.get("pose_noise") == "thesis"]
    friction = [t for t in mujoco if t.sim.get("finger_mu", 1.0) < t.kwargs["mu"]]
    assert sorted(t.kwargs["object"] for t in pose) == sorted(THESIS)
    assert sorted(t.kwargs["object"] for t in friction) == sorted(THESIS)
    for t in mujoco:  # trained on the map-level twin, the same maps
        twin = get_task(t.train_task)
        assert twin.track == "map-hand" and twin.kwargs["object"] == t.kwargs["object"]
        assert t.episodes <= 5  # MuJoCo episodes cost seconds


def test_random_tasks_test_on_held_out_objects_only():
    for t in parse_tasks("random"):
        assert tuple(t.kwargs["object_seeds"]) == EVAL_SEEDS
        assert t.kwargs["bundled_fraction"] == 0.0
        assert tuple(t.train_kwargs["exclude_seeds"]) == EVAL_SEEDS
        check_disjoint(t)
        env = gym.make(t.env_id, **t.env_kwargs())
        names = []
        for i in range(3):
            env.reset(seed=t.test_slice(0) + i)
            names.append(env.unwrapped.model.shape.name)
        env.close()
        check_disjoint(t, names)  # named for held-out seeds, none a bundled object


def test_check_disjoint_catches_overlaps():
    t = get_task("random-l1")
    overlap = dataclasses.replace(t, train_kwargs={**t.train_kwargs, "exclude_seeds": None})
    with pytest.raises(GraspGaitInputError, match="overlap"):
        check_disjoint(overlap)
    bundled = dataclasses.replace(t, kwargs={**t.kwargs, "bundled_fraction": 0.5})
    with pytest.raises(GraspGaitInputError, match="bundled"):
        check_disjoint(bundled)
    with pytest.raises(GraspGaitInputError, match="not a procedural object"):
        check_disjoint(t, ["proc-L1-5"])  # a training seed
    with pytest.raises(GraspGaitInputError, match="not a procedural object"):
        check_disjoint(t, ["ellipse"])
    check_disjoint(get_task("map-point-circle"), ["anything"])  # one object: nothing held out


@pytest.mark.parametrize("task", TASKS, ids=lambda t: t.id)
def test_every_task_makes_its_env(task):
    env = gym.make(task.env_id, **task.env_kwargs())
    obs, info = env.reset(seed=task.test_slice(0))
    assert env.observation_space.contains(obs) and info["action_mask"].any()
    if task.sim:
        assert env.unwrapped.sim_config.finger_mu == task.sim["finger_mu"]
    env.close()
    if task.train_steps:
        train = gym.make(task.train_env_id, **dict(task.train_kwargs))
        assert train.observation_space.shape == env.observation_space.shape
        train.close()


def test_seeds_select_disjoint_slices_of_the_test_seeds():
    t = get_task("map-point-ellipse")
    assert [t.test_slice(s) for s in range(3)] == [1_000_000 + s * t.episodes for s in range(3)]
    assert t.test_slice(2, 10) == 1_000_020
    with pytest.raises(GraspGaitInputError, match="test reset seeds"):
        t.test_slice(10**6)


def test_parse_tasks_by_id_and_track():
    assert [t.id for t in parse_tasks("random-l0,map-point-circle")] == [
        "map-point-circle", "random-l0"]  # suite order
    assert len(parse_tasks("mujoco")) == 8 and len(parse_tasks(None)) == len(TASKS)
    assert len(parse_tasks("all,random")) == len(TASKS)
    with pytest.raises(GraspGaitInputError, match="did you mean 'map-point-circle'"):
        parse_tasks("map-point-circel")
    with pytest.raises(GraspGaitInputError, match="give task ids"):
        parse_tasks(" , ")
