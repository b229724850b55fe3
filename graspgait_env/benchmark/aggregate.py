"""Aggregation over runs and tasks with rliable (Agarwal et al. 2021).

The scores of a row form a matrix ``(runs, tasks)``: run = benchmark seed, task = a
task of the suite, entry = the run's score on the task (:mod:`~graspgait_env.benchmark.
score`). From it:

- **per task**: the mean and the interquartile mean (IQM: the mean of the middle 50% of
  the runs, :func:`rliable.metrics.aggregate_iqm`) over the runs, each with a 95%
  bootstrap confidence interval (runs resampled with replacement);
- **per track and over the suite**: the IQM over all runs of all its tasks and the mean
  of the per-task means (:func:`rliable.metrics.aggregate_mean`), with 95% *stratified*
  bootstrap confidence intervals (:func:`rliable.library.get_interval_estimates`: each
  resample draws, for every task, as many runs with replacement from that task's runs,
  so every task keeps its weight), percentile method;
- a **performance profile**: for each threshold ``tau`` in ``[0, 1]`` the fraction of
  all (run, task) scores above ``tau``, with its stratified bootstrap band
  (:func:`rliable.library.create_performance_profile`), drawn by
  :func:`rliable.plot_utils.plot_performance_profiles`.

Reproducible intervals: rliable's bootstrap draws its indices from NumPy's *global*
generator, so each estimate is made with that generator seeded by ``seed`` (default
:data:`BOOTSTRAP_SEED`), and its previous state restored afterwards. A task without
a score for every run (a missing run, or no solvable start) is left out of the
track and suite aggregates and listed under ``excluded``.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["BOOTSTRAP_REPS", "BOOTSTRAP_SEED", "aggregate_cells", "interval_estimates",
           "performance_profile", "plot_profiles", "score_matrix", "seeded_global_rng"]

BOOTSTRAP_REPS = 2000  # replications of every interval (``--reps``; rliable's profile default)
BOOTSTRAP_SEED = 0
CONFIDENCE = 0.95
PROFILE_TAUS = np.linspace(0.0, 1.0, 101)


@contextlib.contextmanager
def seeded_global_rng(seed: int) -> Iterator[None]:
    """NumPy's global generator seeded with ``seed`` inside, restored on exit."""
    state = np.random.get_state()  # noqa: NPY002 - rliable draws from the global generator
    np.random.seed(int(seed) % 2**32)  # noqa: NPY002
    try:
        yield
    finally:
        np.random.set_state(state)  # noqa: NPY002


def interval_estimates(scores: np.ndarray, reps: int = BOOTSTRAP_REPS,
                       seed: int = BOOTSTRAP_SEED) -> dict[str, Any]:
    """IQM and mean of a ``(runs, tasks)`` score matrix, each with its 95% stratified
    bootstrap confidence interval.

    Returns
    -------
    dict
        ``{"iqm": x, "iqm_ci": [lo, hi], "mean": x, "mean_ci": [lo, hi]}``.
    """
    from rliable import library, metrics

    x = np.asarray(scores, dtype=np.float64)
    if x.ndim != 2 or x.size == 0:
        raise ValueError(f"scores of shape {x.shape}: expected (runs, tasks)")

    def both(s: np.ndarray) -> np.ndarray:
        return np.array([metrics.aggregate_iqm(s), metrics.aggregate_mean(s)])

    with seeded_global_rng(seed):
        point, ci = library.get_interval_estimates(
            {"x": x}, both, reps=int(reps), confidence_interval_size=CONFIDENCE)
    p, c = point["x"], ci["x"]
    return {"iqm": float(p[0]), "iqm_ci": [float(c[0][0]), float(c[1][0])],
            "mean": float(p[1]), "mean_ci": [float(c[0][1]), float(c[1][1])]}


def score_matrix(cells: Sequence[Mapping[str, Any]], tasks: Sequence[str],
                 seeds: Sequence[int], key: str = "score"
                 ) -> tuple[np.ndarray, list[str], list[str]]:
    """The ``(runs, tasks)`` matrix of ``key`` over the tasks with a value for every seed.

    Returns
    -------
    matrix, kept, excluded
        ``matrix[i, j]`` is seed ``seeds[i]``'s value on task ``kept[j]``; ``excluded``
        names the tasks left out (a missing run, or a None value).
    """
    by = {(c["task"], int(c["seed"])): c["summary"].get(key) for c in cells}
    kept, excluded, cols = [], [], []
    for t in tasks:
        col = [by.get((t, int(s))) for s in seeds]
        if any(v is None or not math.isfinite(float(v)) for v in col):
            excluded.append(t)
            continue
        kept.append(t)
        cols.append([float(v) for v in col])
    matrix = np.array(cols, dtype=np.float64).T if cols else np.zeros((len(seeds), 0))
    return matrix, kept, excluded


def _mean(xs: list[float]) -> float | None:
    xs = [float(x) for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None


def aggregate_cells(cells: Sequence[Mapping[str, Any]], tasks: Sequence[Any],
                    seeds: Sequence[int], reps: int = BOOTSTRAP_REPS,
                    seed: int = BOOTSTRAP_SEED) -> dict[str, Any]:
    """Per-task, per-track and suite aggregates of a row's cells (module docstring).

    Parameters
    ----------
    cells
        Cell results (``task``, ``seed``, ``summary``: :func:`~graspgait_env.benchmark.
        score.score_records`' dict).
    tasks
        The row's :class:`~graspgait_env.benchmark.suite.Task` objects, in order.
    seeds
        The row's run seeds.
    """
    ids = [t.id for t in tasks]
    by = {(c["task"], int(c["seed"])): c for c in cells}
    per_task = []
    for t in tasks:
        runs = [by[(t.id, int(s))] for s in seeds if (t.id, int(s)) in by]
        scores = [r["summary"]["score"] for r in runs]
        entry: dict[str, Any] = {
            "task": t.id, "track": t.track, "runs": len(runs),
            "success": _mean([r["summary"]["success"] for r in runs]),
            "efficiency": _mean([r["summary"]["efficiency"] for r in runs]),
            "rule_score": _mean([r["summary"]["rule_score"] for r in runs]),
            "episodes": sum(r["summary"]["n_episodes"] for r in runs),
            "solvable": sum(r["summary"]["solvable"] for r in runs),
            "wall_s": sum(float(r.get("wall_s") or 0.0) for r in runs)}
        if runs and len(runs) == len(seeds) and all(s is not None for s in scores):
            entry.update(interval_estimates(np.array(scores, dtype=np.float64)[:, None],
                                            reps, seed))
        per_task.append(entry)
    matrix, kept, excluded = score_matrix(cells, ids, seeds)
    out: dict[str, Any] = {"tasks": per_task, "tracks": {}, "excluded": excluded,
                           "seeds": [int(s) for s in seeds], "reps": int(reps),
                           "bootstrap_seed": int(seed), "confidence": CONFIDENCE}
    for track in dict.fromkeys(t.track for t in tasks):
        cols = [j for j, tid in enumerate(kept)
                if next(t for t in tasks if t.id == tid).track == track]
        if cols:
            out["tracks"][track] = {"tasks": len(cols),
                                    **interval_estimates(matrix[:, cols], reps, seed)}
    if kept:
        out["overall"] = {"tasks": len(kept), **interval_estimates(matrix, reps, seed)}
    return out


def performance_profile(score_dict: Mapping[str, np.ndarray], reps: int = BOOTSTRAP_REPS,
                        seed: int = BOOTSTRAP_SEED, taus: np.ndarray = PROFILE_TAUS
                        ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """rliable's score distributions (fraction of runs x tasks above each ``tau``) with
    their stratified bootstrap bands, for ``{label: (runs, tasks) matrix}``."""
    from rliable import library

    def above(scores: np.ndarray, tau_list: np.ndarray) -> np.ndarray:
        # rliable's score distribution (np.mean(scores > tau) per tau), one NumPy call
        return (np.asarray(scores).reshape(-1, 1) > np.asarray(tau_list)[None, :]).mean(axis=0)

    with seeded_global_rng(seed):
        return library.create_performance_profile(
            {k: np.asarray(v, dtype=np.float64) for k, v in score_dict.items()}, taus,
            custom_profile_func=above, reps=int(reps), confidence_interval_size=CONFIDENCE)


def plot_profiles(score_dict: Mapping[str, np.ndarray], path: str, *, title: str = "",
                  reps: int = BOOTSTRAP_REPS, seed: int = BOOTSTRAP_SEED) -> str:
    """Draw the performance profiles of ``{label: (runs, tasks) matrix}`` into ``path``
    (PNG or any Matplotlib format; written atomically)."""
    from matplotlib.figure import Figure
    from rliable import plot_utils

    from graspgait_env.atomic import atomic_write

    profiles, cis = performance_profile(score_dict, reps, seed)
    fig = Figure(figsize=(7, 4.5))
    ax = fig.add_subplot(1, 1, 1)
    plot_utils.plot_performance_profiles(
        profiles, PROFILE_TAUS, performance_profile_cis=cis, ax=ax,
        xlabel=r"normalized score $\tau$ (success x efficiency)",
        ylabel=r"fraction of runs x tasks with score $> \tau$", legend=len(profiles) > 1,
        xticks=[0.0, 0.25, 0.5, 0.75, 1.0], labelsize="medium", ticklabelsize="medium",
        legendsize="small")
    if len(profiles) == 1:
        ax.set_title(title or next(iter(profiles)))
    elif title:
        ax.set_title(title)
    fig.tight_layout()
    suffix = str(path).rsplit(".", 1)[-1] if "." in str(path) else "png"
    atomic_write(path, lambda fh: fig.savefig(fh, format=suffix, dpi=120))
    return str(path)
