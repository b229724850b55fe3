"""Minari demonstrations: record, load_dataset, recover_environment; behaviour cloning on
a tiny dataset; the bc row."""

from __future__ import annotations

import numpy as np
import pytest

import graspgait_env.benchmark.datasets as datasets
from graspgait_env.cli import main


@pytest.fixture
def minari_path(tmp_path, monkeypatch):
    import torch

    torch.set_num_threads(1)
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "minari"))
    monkeypatch.setattr(datasets, "REFERENCE_EPISODES", 2)  # Minari's reference scores
    return tmp_path / "minari"


def test_record_load_and_recover(minari_path, capsys):
    import minari

    assert main(["dataset", "record", "map-point-circle", "--episodes", "2", "--quiet"]) == 0
    did = "graspgait/map-point-circle/optimal-v1"
    assert did == datasets.dataset_id("map-point-circle")
    assert f"recorded {did}: 2 episodes" in capsys.readouterr().out
    assert (minari_path / "graspgait" / "map-point-circle" / "optimal-v1").is_dir()
    ds = minari.load_dataset(did)
    assert ds.total_episodes == 2 and ds.total_steps > 0
    meta = ds.storage.metadata
    assert meta["algorithm_name"] == "graspgait_env optimal planner"
    assert meta["ref_max_score"] is not None  # from expert_policy, the optimal planner
    assert ds.spec.env_spec.id == "GraspGait-v0"
    env = ds.recover_environment()
    assert env.spec.kwargs == {"object": "circle", "mu": 0.7, "contact_model": "point"}
    assert env.unwrapped.model.shape.name == "circle"
    env.close()
    ev = ds.recover_environment(eval_env=True)
    assert ev.spec.kwargs == env.spec.kwargs
    ev.close()
    for ep in ds.iterate_episodes():  # demonstrations are gaits: each reaches the turn
        assert ep.terminations[-1] and ep.rewards[-1] > 0.5
    assert main(["dataset", "record", "map-point-circle", "--episodes", "2"]) == 2
    assert "--overwrite" in capsys.readouterr().err


def test_random_task_records_training_objects_and_tests_on_held_out_ones(minari_path):
    ds = datasets.record_dataset("random-l0", "rule", 2)
    assert ds.id == "graspgait/random-l0/rule-v1"
    assert ds.storage.metadata["ref_max_score"] is not None
    train = ds.recover_environment()
    assert tuple(train.spec.kwargs["exclude_seeds"]) == (1_000_000, 1_100_000)
    test = ds.recover_environment(eval_env=True)
    test.reset(seed=0)
    seed = int(test.unwrapped.model.shape.name.rsplit("-", 1)[1])
    assert 1_000_000 <= seed < 1_100_000  # a held-out object
    train.close()
    test.close()


def test_behaviour_cloning_trains_and_plays_legal_moves(minari_path, tmp_path):
    datasets.record_dataset("map-point-circle", "optimal", 2)
    X, y, masks = datasets.load_demonstrations(datasets.dataset_id("map-point-circle"))
    assert len(X) == len(y) == len(masks) and masks[np.arange(len(y)), y].all()
    losses = []
    bc = datasets.train_bc(datasets.dataset_id("map-point-circle"), seed=0, max_steps=20,
                           batch_size=16, log=lambda step, loss: losses.append(loss))
    assert bc.info["steps"] == 20 and losses[-1] < losses[0]
    path = bc.save(tmp_path / "bc.pt")
    again = datasets.BCPolicy.load(path)
    assert np.allclose(again.logits(X[0]), bc.logits(X[0]))
    for x, m in zip(X[:5], masks[:5], strict=True):
        assert m[bc.predict(x, m)]
    from graspgait_env.benchmark.run import run_benchmark
    from graspgait_env.benchmark.suite import parse_tasks

    row = run_benchmark("bc", parse_tasks("map-point-circle"), [0], out_dir=tmp_path / "row",
                        episodes=2, progress=False, reps=100)
    cell = row["cells"][0]
    assert cell["policy_info"]["dataset"] == "graspgait/map-point-circle/optimal-v1"
    assert cell["summary"]["illegal_action_rate"] == 0.0
    assert (tmp_path / "row" / "bc" / "map-point-circle" / "s0.pt").is_file()


def test_bc_without_its_dataset_says_how_to_record_it(minari_path, tmp_path, capsys):
    assert main(["benchmark", "bc", "--tasks", "map-point-circle", "--seeds", "0",
                 "--episodes", "1", "--out", str(tmp_path / "row"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "graspgait dataset record map-point-circle --policy optimal" in err
