"""Aggregation with rliable: IQM and stratified bootstrap intervals checked against hand
computations on small arrays."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from graspgait_env.benchmark.aggregate import (
    aggregate_cells,
    interval_estimates,
    performance_profile,
    plot_profiles,
    score_matrix,
)
from graspgait_env.benchmark.suite import get_task

X = np.array([[0.2, 0.9], [0.5, 1.0], [0.8, 0.7], [0.4, 0.6]])  # (runs, tasks)


def test_iqm_and_mean_by_hand():
    est = interval_estimates(X, reps=200, seed=3)
    # IQM: the 8 scores sorted 0.2 0.4 0.5 0.6 0.7 0.8 0.9 1.0, the middle four
    assert est["iqm"] == pytest.approx((0.5 + 0.6 + 0.7 + 0.8) / 4)
    # mean of per-task means: (0.475 + 0.8) / 2
    assert est["mean"] == pytest.approx((0.475 + 0.8) / 2)


def test_stratified_bootstrap_by_hand():
    """rliable resamples, for every task, the runs with replacement (NumPy's global
    generator) and takes percentiles; replayed here draw by draw."""
    reps, seed = 500, 7
    est = interval_estimates(X, reps=reps, seed=seed)
    rng = np.random.RandomState(seed)
    iqm, mean = [], []
    cols = np.arange(X.shape[1])[None, :]
    for _ in range(reps):
        idx = rng.choice(X.shape[0], X.shape, replace=True)
        r = X[idx, cols]  # task j keeps its column: runs drawn within each task
        iqm.append(stats.trim_mean(r, 0.25, axis=None))
        mean.append(r.mean(axis=0).mean())
    assert est["iqm_ci"] == pytest.approx(list(np.percentile(iqm, [2.5, 97.5])))
    assert est["mean_ci"] == pytest.approx(list(np.percentile(mean, [2.5, 97.5])))


def test_bootstrap_interval_of_two_runs_is_exact():
    """Two runs a < b per task: a resampled task mean is a, (a + b) / 2 or b with
    probabilities 1/4, 1/2, 1/4, so with two tasks the lowest suite mean has probability
    1/16 > 2.5%: the 95% interval is exactly [mean of the a's, mean of the b's]."""
    x = np.array([[0.1, 0.4], [0.3, 0.9]])
    est = interval_estimates(x, reps=4000, seed=0)
    assert est["mean_ci"] == pytest.approx([(0.1 + 0.4) / 2, (0.3 + 0.9) / 2])
    one = interval_estimates(x[:, :1], reps=4000, seed=0)  # one task: plain bootstrap
    assert one["mean_ci"] == pytest.approx([0.1, 0.3]) and one["mean"] == pytest.approx(0.2)


def test_intervals_are_reproducible_and_leave_the_global_generator_alone():
    np.random.seed(123)  # noqa: NPY002 - the global generator rliable draws from
    before = np.random.get_state()[1].copy()  # noqa: NPY002
    a = interval_estimates(X, reps=300, seed=1)
    assert (np.random.get_state()[1] == before).all()  # noqa: NPY002
    assert interval_estimates(X, reps=300, seed=1) == a
    assert interval_estimates(X, reps=300, seed=2) != a


def cell(task, seed, score, success=1.0):
    return {"task": task, "seed": seed, "wall_s": 1.0,
            "summary": {"score": score, "success": success, "efficiency": score,
                        "rule_score": 0.5, "n_episodes": 4, "solvable": 4 if score is not None
                        else 0}}


def test_aggregate_cells_per_task_track_and_suite():
    tasks = [get_task("map-point-circle"), get_task("random-l0"), get_task("random-l1")]
    cells = [cell(t.id, s, X[s, j % 2] if j < 2 else None)
             for j, t in enumerate(tasks) for s in range(4)]
    agg = aggregate_cells(cells, tasks, [0, 1, 2, 3], reps=200)
    assert agg["excluded"] == ["random-l1"]  # no solvable start: left out
    t0 = agg["tasks"][0]
    assert t0["mean"] == pytest.approx(X[:, 0].mean()) and t0["runs"] == 4
    assert t0["iqm"] == pytest.approx((0.4 + 0.5) / 2)  # middle two of 0.2 0.4 0.5 0.8
    assert "mean" not in agg["tasks"][2]
    assert agg["overall"]["tasks"] == 2
    assert agg["overall"]["iqm"] == pytest.approx(interval_estimates(X, 200)["iqm"])
    assert set(agg["tracks"]) == {"map-point", "random"}
    m, kept, excluded = score_matrix(cells, [t.id for t in tasks], [0, 1, 2, 3])
    assert m.shape == (4, 2) and kept == ["map-point-circle", "random-l0"]
    m, kept, excluded = score_matrix(cells, ["map-point-circle"], [0, 9])  # seed 9 missing
    assert kept == [] and excluded == ["map-point-circle"]


def test_performance_profile_and_plot(tmp_path):
    profiles, cis = performance_profile({"a": X}, reps=100, taus=np.array([0.0, 0.65, 1.0]))
    assert profiles["a"] == pytest.approx([1.0, 4 / 8, 0.0])  # fraction of scores > tau
    assert cis["a"].shape == (2, 3)
    path = plot_profiles({"a": X, "b": X / 2}, str(tmp_path / "p.png"), reps=50)
    assert (tmp_path / "p.png").stat().st_size > 1000 and path.endswith("p.png")
