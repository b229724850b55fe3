"""Ray as the engine for the long runs: the planner bench and the perturbed MuJoCo campaign.

:func:`ray_session` connects to a Ray cluster, or starts a local one on this machine
(the default: ``address=None``), quietly (no dashboard, warnings only) and lightly (as
many CPUs as the machine has, a small object store). :func:`run_tasks` runs one Ray
task per argument tuple with a progress bar, keeps the results in submission order and
reports a failed task (its index and error) instead of losing the others.

- :func:`bench_on_ray`: ``graspgait bench --ray``: one task per (object, mu) cell, each
  running :func:`graspgait_env.baselines.bench.run_bench` on that cell exactly as the serial bench
  does, so the cases (and the summary) are the serial ones; only wall times differ.
- :func:`campaign`: the perturbed MuJoCo campaign of thesis 7.5 (``graspgait simulate
  PLAN --perturb random --seeds 0-9 [--ray]``): one run of
  :func:`graspgait_env.sim.simulate_plan` per seed, serially or on Ray, same results.

On a cluster every node needs this package installed (``pip install graspgait_env``),
as for any Ray job; results come back to the machine that started the run.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from tqdm.auto import tqdm

from graspgait_env.errors import GraspGaitInputError

__all__ = ["LOCAL", "TaskFailure", "bench_on_ray", "campaign", "parse_seeds", "ray_session",
           "run_tasks", "summarize_campaign"]

LOCAL = "local"  # --ray without ADDRESS: start a local Ray on this machine
LOCAL_OBJECT_STORE_BYTES = 256 * 1024**2  # a local Ray's object store (results are small)


@dataclass(frozen=True)
class TaskFailure:
    """A task that raised: its position among the submitted tasks, what it was, why."""

    index: int
    label: str
    error: str


def parse_seeds(text: str, flag: str = "--seeds") -> list[int]:
    """``"0-9"``, ``"0,3,5"`` or ``"0-4,7"`` as a list of distinct seeds >= 0, in order.

    Raises
    ------
    GraspGaitInputError
        Anything else, e.g. ``--seeds 9-0: give seeds like 0-9 or 0,3,5``.
    """
    seeds: list[int] = []
    for part in str(text).split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if not m or (m.group(2) is not None and int(m.group(2)) < int(m.group(1))):
            raise GraspGaitInputError(f"{flag} {text}: give seeds like 0-9 or 0,3,5 "
                                      "(integers >= 0, ranges low-high)")
        lo = int(m.group(1))
        hi = int(m.group(2)) if m.group(2) is not None else lo
        seeds.extend(s for s in range(lo, hi + 1) if s not in seeds)
    return seeds


@contextlib.contextmanager
def ray_session(address: str | None = None, num_cpus: int | None = None) -> Iterator[Any]:
    """A connected Ray: the running one, the cluster at ``address``, or a new local one.

    Parameters
    ----------
    address
        None or ``"local"``: start Ray on this machine (``num_cpus`` CPUs, default all),
        without dashboard; ``"auto"``, ``"HOST:6379"`` or ``"ray://HOST:10001"``: connect
        to that cluster (started with ``ray start --head``).
    num_cpus
        CPUs of a local Ray.

    Yields
    ------
    module
        ``ray``. A Ray started here is shut down on exit; one already running (or a
        cluster's) is left as it is.
    """
    import ray

    if ray.is_initialized():
        yield ray
        return
    quiet = {"logging_level": logging.ERROR, "log_to_driver": False,
             "configure_logging": True}
    try:
        if address in (None, LOCAL):
            ray.init(num_cpus=num_cpus or os.cpu_count(), include_dashboard=False,
                     object_store_memory=LOCAL_OBJECT_STORE_BYTES, **quiet)
        else:
            ray.init(address=address, **quiet)
    except (ConnectionError, ValueError, RuntimeError) as exc:
        where = "a local Ray" if address in (None, LOCAL) else f"the Ray cluster at {address!r}"
        raise GraspGaitInputError(
            f"--ray {address or ''}: could not start or reach {where} ({exc}); start one with "
            "`ray start --head` and give its address, or omit ADDRESS for a local Ray") from None
    try:
        yield ray
    finally:
        ray.shutdown()


def run_tasks(fn: Callable[..., Any], calls: Sequence[tuple], labels: Sequence[str], *,
              address: str | None = None, desc: str = "ray", progress: bool = True,
              num_cpus_per_task: float = 1.0) -> tuple[list[Any], list[TaskFailure]]:
    """``fn(*args)`` for each ``args`` in ``calls``, as Ray tasks.

    Returns
    -------
    results, failures
        ``results[i]`` is call ``i``'s return value (None if it failed); ``failures``
        lists the calls that raised, with ``labels[i]`` and the error's last line.
    """
    with ray_session(address) as ray:
        remote = ray.remote(num_cpus=num_cpus_per_task)(fn)
        refs = [remote.remote(*args) for args in calls]
        index = {ref: i for i, ref in enumerate(refs)}
        results: list[Any] = [None] * len(refs)
        failures: list[TaskFailure] = []
        pending = list(refs)
        with tqdm(total=len(refs), desc=desc, unit="task", disable=not progress) as bar:
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                for ref in done:
                    i = index[ref]
                    try:
                        results[i] = ray.get(ref)
                    except Exception as exc:  # noqa: BLE001 - a task's own error, reported
                        cause = getattr(exc, "cause", None) or exc
                        lines = str(cause).strip().splitlines() or [type(cause).__name__]
                        failures.append(TaskFailure(i, labels[i],
                                                    f"{type(cause).__name__}: {lines[-1]}"))
                    bar.update(1)
    failures.sort(key=lambda f: f.index)
    return results, failures


# ----------------------------------------------------------------------------- bench
def _bench_cell(obj: str, mu: float, planners: Sequence[str], starts: int,
                turn_deg: float, planner_kwargs: dict | None) -> list[Any]:
    """The serial bench on one (object, mu) cell (runs in a Ray worker)."""
    from graspgait_env.baselines.bench import run_bench

    return run_bench(objects=[obj], mus=[mu], planners=list(planners), starts=starts,
                     turn_deg=turn_deg, progress=False, planner_kwargs=planner_kwargs)


def bench_on_ray(objects: Sequence[str], mus: Sequence[float], planners: Sequence[str],
                 starts: int = 10, turn_deg: float = 360.0, *, address: str | None = None,
                 progress: bool = True, planner_kwargs: dict | None = None
                 ) -> tuple[list[Any], list[TaskFailure]]:
    """:func:`graspgait_env.baselines.bench.run_bench` with one Ray task per (object, mu) cell.

    The cells run the serial bench's own code, and their cases are concatenated in the
    serial order (objects, then mus), so the cases and
    :func:`~graspgait_env.baselines.bench.markdown_report` are those of ``run_bench`` with the same
    arguments, wall times aside. A failed cell is reported and the others kept.

    Returns
    -------
    cases, failures
        :class:`~graspgait_env.baselines.bench.BenchCase` rows of the cells that ran, and the failed
        cells (label ``"object mu=..."``).
    """
    cells = [(o, float(mu)) for o in objects for mu in mus]
    calls = [(o, mu, tuple(planners), starts, turn_deg, planner_kwargs) for o, mu in cells]
    labels = [f"{o} mu={mu:g}" for o, mu in cells]
    results, failures = run_tasks(_bench_cell, calls, labels, address=address,
                                  desc="bench (ray)", progress=progress)
    cases = [c for r in results if r is not None for c in r]
    return cases, failures


# -------------------------------------------------------------------------- campaign
def _campaign_run(plan: Any, seed: int, config: Any) -> dict[str, Any]:
    """One perturbed run of ``plan`` (runs in a Ray worker or here)."""
    from graspgait_env.sim import simulate_plan

    return simulate_plan(plan, pose_perturbation="random", seed=seed, config=config)


def campaign(plan: Any, seeds: Sequence[int], config: Any = None, *,
             address: str | None = None, use_ray: bool = False, progress: bool = True
             ) -> tuple[list[dict[str, Any] | None], list[TaskFailure]]:
    """The perturbed MuJoCo campaign (thesis 7.5): ``plan`` from a random initial pose
    error per seed (``simulate_plan(plan, pose_perturbation="random", seed=s)``).

    Parameters
    ----------
    plan
        A :class:`~graspgait_env.plan.Plan` (``graspgait plan`` writes one).
    seeds
        One run per seed; run ``i``'s perturbation is drawn from ``seeds[i]``.
    config
        Simulation config (a ``SimConfig`` or YAML path; None: the default).
    address, use_ray
        With ``use_ray``, run on Ray (``address`` None: a local Ray); else serially here.
        The results are the same either way.

    Returns
    -------
    results, failures
        One result dict per seed (None where it raised) and the runs that raised.
    """
    labels = [f"seed {s}" for s in seeds]
    calls = [(plan, int(s), config) for s in seeds]
    if use_ray:
        return run_tasks(_campaign_run, calls, labels, address=address,
                         desc="campaign (ray)", progress=progress)
    results: list[dict[str, Any] | None] = []
    failures: list[TaskFailure] = []
    for i, args in enumerate(tqdm(calls, desc="campaign", unit="run", disable=not progress)):
        try:
            results.append(_campaign_run(*args))
        except Exception as exc:  # noqa: BLE001 - reported, the other runs kept
            results.append(None)
            failures.append(TaskFailure(i, labels[i], f"{type(exc).__name__}: {exc}"))
    return results, failures


def summarize_campaign(results: Sequence[dict[str, Any] | None], seeds: Sequence[int],
                       angle_tol_deg: float = 3.0) -> str:
    """One line per run (seed, status, drop, final error) and the tally of good runs:
    ``status == "ok"``, no drop, final orientation within ``angle_tol_deg`` (the turn's
    error for a circle, whose orientation cannot be observed)."""
    lines = ["| seed | status | dropped | error (deg) | perturbation (m, m, deg) |",
             "|---:|---|---|---:|---|"]
    good = 0
    for s, r in zip(seeds, results, strict=True):
        if r is None:
            lines.append(f"| {s} | failed | - | - | - |")
            continue
        err = (r["final_angle_error_deg"] if r.get("orientation_observable", True)
               else r["rotation_error_deg"])
        ok = r["status"] == "ok" and not r["dropped"] and abs(err) <= angle_tol_deg
        good += ok
        pert = ", ".join(f"{v:.4g}" for v in r["pose_perturbation"])
        lines.append(f"| {s} | {r['status']} | {r['dropped']} | {err:.2f} | {pert} |")
    lines.append(f"\n{good} of {len(seeds)} runs turned the object without a drop and ended "
                 f"within {angle_tol_deg:g} deg")
    return "\n".join(lines)
