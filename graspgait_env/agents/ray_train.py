"""Training over many seeds (Ray Tune trials) and evaluation split over Ray tasks.

- :func:`train_seeds`: ``graspgait train CONFIG --seeds 0-9 [--ray [ADDRESS]]``: one
  :func:`graspgait_env.agents.train.train` run per seed, each its own run folder; on Ray, one Ray
  Tune trial per seed (``tune.grid_search`` over the seeds, one trial per
  ``torch_threads`` CPUs), serially without ``--ray``. A trial runs exactly what the
  serial run does (same config, same seed, same torch threads), so its numbers are the
  serial run's. A failed trial is reported and the others kept.
- :func:`evaluate_on_ray`: ``graspgait evaluate MODEL --ray``: the episodes split into
  chunks of consecutive reset seeds, one Ray task per chunk, each running
  :func:`graspgait_env.agents.evaluate.evaluate`; the per-episode records are joined in seed order
  and
  summarized once, so the result equals the serial evaluation's (wall times aside). The
  model file travels through Ray's object store, so the workers need not share a disk.

Run folders are written by the node that runs the trial, under the config's
``run_root`` made absolute on the driver: on a local Ray (the default) or a cluster with
a shared file system they are where a serial run puts them.
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from graspgait_env.agents.config import TrainConfig
from graspgait_env.errors import GraspGaitInputError

__all__ = ["SeedOutcome", "evaluate_on_ray", "train_seeds"]


@dataclass(frozen=True)
class SeedOutcome:
    """One seed's training: its results, or why it failed.

    Attributes
    ----------
    seed
        The training seed.
    run_dir, model_path
        The run's folder and final model (None when it failed).
    steps, wall_s
        Env-steps trained and the training wall time (s).
    last_eval
        The final evaluation's numbers (:func:`graspgait_env.agents.evaluate.summarize_episodes`).
    error
        None, or the error that ended the trial.
    """

    seed: int
    run_dir: str | None = None
    model_path: str | None = None
    steps: int = 0
    wall_s: float = 0.0
    last_eval: dict[str, Any] | None = None
    error: str | None = None


def _run_one(config: TrainConfig, seed: int) -> dict[str, Any]:
    """Train ``config`` with ``seed`` (quietly); the outcome as plain data."""
    from graspgait_env.agents.train import train

    r = train(replace(config, seed=int(seed)), progress=False)
    return {"seed": int(seed), "run_dir": str(r.run_dir), "model_path": str(r.model_path),
            "steps": int(r.steps), "wall_s": float(r.wall_s), "last_eval": dict(r.last_eval)}


def train_seeds(config: TrainConfig, seeds: Sequence[int], *, use_ray: bool = False,
                address: str | None = None, progress: bool = True) -> list[SeedOutcome]:
    """Train ``config`` once per seed, serially or as Ray Tune trials.

    Parameters
    ----------
    config
        The training config (its ``seed`` is replaced by each of ``seeds``).
    seeds
        Distinct seeds >= 0.
    use_ray, address
        Run the seeds as Ray Tune trials on the cluster at ``address`` (None: a local
        Ray on this machine); else one after the other here.
    progress
        A progress bar over the seeds (trials).

    Returns
    -------
    list of SeedOutcome
        In the order of ``seeds``; a failed seed has ``error`` set.
    """
    from tqdm.auto import tqdm

    if not seeds:
        raise GraspGaitInputError("--seeds: give at least one seed, e.g. 0-9")
    config = replace(config, run_root=str(Path(config.run_root).resolve()))
    if not use_ray:
        out = []
        for s in tqdm(list(seeds), desc="seeds", unit="run", disable=not progress):
            try:
                out.append(SeedOutcome(**_run_one(config, s)))
            except Exception as exc:  # noqa: BLE001 - reported, the other seeds kept
                out.append(SeedOutcome(int(s), error=f"{type(exc).__name__}: {exc}"))
        return out
    return _tune_seeds(config, list(seeds), address, progress)


def _tune_seeds(config: TrainConfig, seeds: list[int], address: str | None,
                progress: bool) -> list[SeedOutcome]:
    """One Ray Tune trial per seed; outcomes in seed order."""
    from ray import tune
    from tqdm.auto import tqdm

    from graspgait_env.baselines.scale_out import ray_session

    def trainable(params: dict[str, Any]) -> None:
        out = _run_one(config, params["seed"])
        ev = {f"eval_{k}": v for k, v in out.pop("last_eval").items()
              if v is None or isinstance(v, (int, float))}
        tune.report({**out, **ev})

    bar = tqdm(total=len(seeds), desc="seeds (ray tune)", unit="trial", disable=not progress)

    class Bar(tune.Callback):
        def on_trial_complete(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            bar.update(1)

        def on_trial_error(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            bar.update(1)

    storage = Path(config.run_root) / "ray_tune"
    with ray_session(address):
        tuner = tune.Tuner(
            tune.with_resources(trainable, {"cpu": config.torch_threads}),
            param_space={"seed": tune.grid_search(seeds)},
            tune_config=tune.TuneConfig(reuse_actors=False),
            run_config=tune.RunConfig(
                name=f"{config.name}-seeds", storage_path=str(storage), verbose=0,
                failure_config=tune.FailureConfig(max_failures=0, fail_fast=False),
                callbacks=[Bar()]))
        with contextlib.redirect_stdout(io.StringIO()):  # Tune's own tables: the bar suffices
            grid = tuner.fit()
    bar.close()
    by_seed: dict[int, SeedOutcome] = {}
    for res in grid:
        seed = int(res.config["seed"])
        if res.error is not None:
            lines = str(getattr(res.error, "cause", None) or res.error).strip().splitlines()
            by_seed[seed] = SeedOutcome(seed, error=lines[-1] if lines else repr(res.error))
            continue
        m = res.metrics
        ev = {k[len("eval_"):]: v for k, v in m.items() if k.startswith("eval_")}
        by_seed[seed] = SeedOutcome(seed, m["run_dir"], m["model_path"], int(m["steps"]),
                                    float(m["wall_s"]), ev)
    return [by_seed.get(s, SeedOutcome(s, error="the trial did not report")) for s in seeds]


# -------------------------------------------------------------------------- evaluate
def _evaluate_chunk(files: dict[str, bytes], name: str, kwargs: dict[str, Any]
                    ) -> dict[str, Any]:
    """Write the model (and its card) into a temporary folder and evaluate it there."""
    from graspgait_env.agents.evaluate import evaluate

    with tempfile.TemporaryDirectory(prefix="graspgait-eval-") as tmp:
        for suffix, data in files.items():
            Path(tmp, name).with_suffix(suffix).write_bytes(data)
        return evaluate(Path(tmp, name).with_suffix(".zip"), **kwargs)


def evaluate_on_ray(model_path: str | os.PathLike[str], *, episodes: int = 100, seed: int = 0,
                    chunks: int | None = None, address: str | None = None,
                    progress: bool = True, **kwargs: Any) -> dict[str, Any]:
    """:func:`graspgait_env.agents.evaluate.evaluate` with its episodes split over Ray tasks.

    Parameters
    ----------
    model_path
        A model zip (its card ``<stem>.json`` beside it travels with it).
    episodes, seed
        Episodes ``0 .. episodes-1`` reset with ``seed + i``, as in the serial evaluation.
    chunks
        Ray tasks (default: the cluster's CPUs, at most ``episodes``); chunk ``j`` plays
        a run of consecutive seeds.
    address
        The Ray cluster (None: a local Ray).
    **kwargs
        Further keyword arguments of ``evaluate`` (``env_id``, ``object``, ``mu``,
        ``deterministic``, ``env_overrides``, ``reading``).

    Returns
    -------
    dict
        What ``evaluate`` returns for the whole run: records in seed order, the summary
        recomputed from all of them, ``wall_s`` of the whole run.

    Raises
    ------
    GraspGaitInputError
        A missing model, bad arguments (checked here before the tasks start), or a
        failed chunk (its seeds and error).
    """
    import time

    from graspgait_env.agents.evaluate import compare_with_reading, evaluate, summarize_episodes
    from graspgait_env.baselines.scale_out import ray_session, run_tasks
    from graspgait_env.envs.config import check_count

    episodes = check_count("episodes", episodes, 1, 100)
    seed = check_count("seed", seed, 0, 0)
    path = Path(model_path)
    if not path.is_file():
        raise GraspGaitInputError(f"model {str(model_path)!r}: no such file; give a model zip, "
                                  "e.g. runs/<run>/model.zip")
    # the arguments are checked by a one-episode evaluation here, before any task starts
    evaluate(path, episodes=1, seed=seed, **kwargs)
    files = {".zip": path.read_bytes()}
    if path.with_suffix(".json").is_file():
        files[".json"] = path.with_suffix(".json").read_bytes()
    t0 = time.perf_counter()
    with ray_session(address) as ray:
        n = chunks or max(1, int(ray.cluster_resources().get("CPU", 1)))
        n = max(1, min(int(n), episodes))
        bounds = [episodes * j // n for j in range(n + 1)]
        files_ref = ray.put(files)
        calls = [(files_ref, path.stem, {**kwargs, "episodes": bounds[j + 1] - bounds[j],
                                         "seed": seed + bounds[j]}) for j in range(n)]
        labels = [f"seeds {seed + bounds[j]}-{seed + bounds[j + 1] - 1}" for j in range(n)]
        parts, failures = run_tasks(_evaluate_chunk, calls, labels, address=address,
                                    desc="evaluate (ray)", progress=progress)
    if failures:
        raise GraspGaitInputError("; ".join(f"evaluation of {f.label} failed on Ray: {f.error}"
                                            for f in failures))
    records = [r for part in parts for r in part["episodes"]]
    out = dict(parts[0])
    out.update(summarize_episodes(records))
    out["model"] = {**parts[0]["model"], "path": str(model_path)}
    objects = sorted({r["object"] for r in records})
    mus = sorted({r["mu"] for r in records})
    out.update({"object": objects[0] if len(objects) == 1 else None,
                "mu": mus[0] if len(mus) == 1 else None, "seed": seed,
                "wall_s": time.perf_counter() - t0, "episodes": records})
    if kwargs.get("reading"):  # the reading's records in seed order, compared once
        out["reading"] = compare_with_reading(
            records, [r for part in parts for r in part["reading"]["episodes"]],
            parts[0]["reading"]["depth"])
    return out


# ----------------------------------------------------------------------------- bench
def _model_files(path: Path) -> dict[str, bytes]:
    """A model zip and its card, as bytes that travel to a Ray worker."""
    files = {".zip": path.read_bytes()}
    if path.with_suffix(".json").is_file():
        files[".json"] = path.with_suffix(".json").read_bytes()
    return files


def _bench_agent_cell(files: dict[str, bytes], name: str, obj: str, mu: float, starts: int,
                      turn_deg: float) -> list[Any]:
    """The serial agent bench of one agent on one (object, mu) cell (in a Ray worker)."""
    from graspgait_env.agents.bench import Agent, run_agent_bench
    from graspgait_env.agents.card import load_agent

    with tempfile.TemporaryDirectory(prefix="graspgait-bench-") as tmp:
        for suffix, data in files.items():
            Path(tmp, name).with_suffix(suffix).write_bytes(data)
        path = Path(tmp, name).with_suffix(".zip")
        model, card = load_agent(path)
        return run_agent_bench([Agent(name, path, model, card)], [obj], [mu], starts,
                               turn_deg, progress=False)


def bench_agents_on_ray(agents: Sequence[Any], objects: Sequence[str],
                        mus: Sequence[float], starts: int = 10, turn_deg: float = 360.0, *,
                        address: str | None = None, progress: bool = True
                        ) -> tuple[list[Any], list[Any]]:
    """:func:`graspgait_env.agents.bench.run_agent_bench` with one Ray task per agent, object and
    mu.

    Each task runs the serial agent bench on its cell (the model and its card travel
    as bytes, so a remote cluster needs no copy of the files), and the cells' rows are
    concatenated in the serial order (objects, then mus, then agents), so the rows are
    those of ``run_agent_bench`` with the same arguments, wall times aside (a test
    compares them). A failed cell is reported and the others kept.

    Parameters
    ----------
    agents
        :class:`graspgait_env.agents.bench.Agent` items (``find_agents``).
    objects, mus, starts, turn_deg
        As for ``run_agent_bench``.
    address
        The Ray cluster (None: a local Ray; a Ray already running is used as it is).

    Returns
    -------
    cases, failures
        The :class:`~graspgait_env.baselines.bench.BenchCase` rows of the cells that ran, and the
        failed cells (:class:`~graspgait_env.baselines.scale_out.TaskFailure`, label
        ``"agent NAME on OBJECT mu=MU"``).
    """
    from graspgait_env.baselines.scale_out import ray_session, run_tasks

    cells = [(o, float(mu), a) for o in objects for mu in mus for a in agents if a.runs_on(o)]
    if not cells:
        return [], []
    with ray_session(address) as ray:
        refs = {id(a): ray.put(_model_files(Path(a.path))) for a in agents}
        calls = [(refs[id(a)], a.name, o, mu, starts, turn_deg) for o, mu, a in cells]
        labels = [f"agent {a.name} on {o} mu={mu:g}" for o, mu, a in cells]
        results, failures = run_tasks(_bench_agent_cell, calls, labels, address=address,
                                      desc="bench agents (ray)", progress=progress)
    return [c for r in results if r is not None for c in r], failures
