"""Run a scoreboard row: one POLICY over tasks x seeds, resumable, serially or on Ray.

A row lives in one folder (``--out``, default ``benchmark/LABEL``):

- ``run.json``: what the row is (suite version, POLICY resolved, the episode budget
  override); a folder holding another row is refused;
- ``cells/TASK/sSEED.json``: one per (task, seed), written atomically when the cell
  finishes: the summary (:func:`~graspgait_env.benchmark.score.score_records`), the
  episode records of :func:`graspgait_env.agents.evaluate.run_episodes`, the env and its
  keywords, the wall time. A later run with the same folder reads the cells that are
  there and computes only the missing ones, so an interrupted row resumes where it
  stopped;
- ``cells.csv`` (one row per cell), ``result.json`` (cells' summaries and the
  aggregates of :func:`~graspgait_env.benchmark.aggregate.aggregate_cells`),
  ``result.md`` (the row's tables) and ``profile.png`` (its performance profile),
  rewritten at the end of every run.

Each cell plays its task's test episodes ``task.test_slice(seed)`` with the policy of
:func:`~graspgait_env.benchmark.policies.prepare_policy` in the task's env
(:func:`graspgait_env.agents.envs.make_env`), one by one
(:func:`~graspgait_env.agents.evaluate.run_episodes`); the optimum's and the
rule-based gait's regrasps come from one
:class:`~graspgait_env.agents.evaluate.ReferenceGaits` cache per process. On Ray
(:func:`graspgait_env.baselines.scale_out.run_tasks`) each cell is one task, running the
same code, so the numbers are the serial ones (wall times aside); a ``config`` POLICY
first trains every (training task, seed) once, one Ray task each. A failed cell is
reported and the others kept.
"""

from __future__ import annotations

import csv
import io
import json
import time
from collections.abc import Callable, Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from graspgait_env.atomic import json_ready, write_text_atomic
from graspgait_env.benchmark.policies import (
    PolicySpec,
    observation_signature,
    parse_policy,
    policy_env_kwargs,
    prepare_policy,
    train_for,
    train_rlzoo,
    training_plan,
)
from graspgait_env.benchmark.score import SCORE_FIELDS, score_records
from graspgait_env.benchmark.suite import SUITE_VERSION, Task, check_disjoint, get_task
from graspgait_env.errors import GraspGaitInputError

__all__ = ["RowResult", "cell_path", "load_cells", "markdown_row", "run_benchmark",
           "run_cell", "write_csv"]

_REFS: Any = None  # one ReferenceGaits per process (optima and rule-based gaits, cached)


def _references() -> Any:
    global _REFS
    if _REFS is None:
        from graspgait_env.agents.evaluate import ReferenceGaits

        _REFS = ReferenceGaits()
    return _REFS


def cell_path(out_dir: str | Path, task_id: str, seed: int) -> Path:
    """Where the cell (task, seed) of a row is kept."""
    return Path(out_dir) / "cells" / task_id / f"s{int(seed)}.json"


def run_cell(spec: PolicySpec | dict, task_id: str, seed: int, episodes: int | None,
             out_dir: str | Path) -> dict[str, Any]:
    """Play one cell and write it (atomically) to :func:`cell_path`; return it."""
    from graspgait_env.agents.envs import make_env
    from graspgait_env.agents.evaluate import run_episodes

    spec = spec if isinstance(spec, PolicySpec) else PolicySpec(**spec)
    task = get_task(task_id)
    n = task.episodes if episodes is None else int(episodes)
    first = task.test_slice(seed, n)
    t0 = time.perf_counter()
    policy = prepare_policy(spec, task, seed, out_dir)
    prepared_s = time.perf_counter() - t0
    kwargs = policy_env_kwargs(task, policy.env_kwargs)
    env = policy.wrap(make_env(task.env_id, kwargs, policy.wrappers))
    try:
        gives = observation_signature(env.observation_space)
        if policy.observes is not None and gives != policy.observes:
            raise GraspGaitInputError(
                f"POLICY {spec.label}: observes {policy.observes}, task {task.id} "
                f"gives {gives} (its own env settings: hand, grid or map window differ)")
        t1 = time.perf_counter()
        records = run_episodes(policy.make_predict(env), env, n, seed=first,
                               references=_references())
        eval_s = time.perf_counter() - t1
    finally:
        env.close()
    if task.env_id == "GraspGaitRandom-v0":
        check_disjoint(task, sorted({r["object"] for r in records}))
    own = {k: v for k, v in kwargs.items() if k not in task.kwargs and k != "sim_config"}
    cell = json_ready({
        "suite_version": SUITE_VERSION, "policy": spec.label, "spec": spec.to_dict(),
        "task": task.id, "track": task.track, "seed": int(seed), "episodes": n,
        "first_test_seed": first, "env_id": task.env_id,
        "env_kwargs": {**task.describe_kwargs(), **own}, "wrappers": list(policy.wrappers),
        "policy_info": policy.info, "summary": score_records(records),
        "wall_s": eval_s, "prepare_s": prepared_s,
        "finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "records": records,
    })
    write_text_atomic(cell_path(out_dir, task.id, seed), json.dumps(cell) + "\n")
    return cell


def _read_cell(path: Path, label: str, episodes: int) -> dict[str, Any] | None:
    try:
        cell = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    ok = (cell.get("suite_version") == SUITE_VERSION and cell.get("policy") == label
          and cell.get("episodes") == episodes and "summary" in cell)
    return cell if ok else None


def load_cells(out_dir: str | Path, spec: PolicySpec, tasks: Sequence[Task],
               seeds: Sequence[int], episodes: int | None = None) -> dict[tuple[str, int], dict]:
    """The finished cells of a row's folder among ``tasks`` x ``seeds``."""
    out = {}
    for t in tasks:
        n = t.episodes if episodes is None else int(episodes)
        for s in seeds:
            p = cell_path(out_dir, t.id, s)
            cell = _read_cell(p, spec.label, n) if p.is_file() else None
            if cell is not None:
                out[(t.id, int(s))] = cell
    return out


def _manifest(out_dir: Path, spec: PolicySpec, episodes: int | None) -> None:
    """Write ``run.json``, or check that the folder holds this row."""
    path = out_dir / "run.json"
    want = {"suite_version": SUITE_VERSION, "policy": spec.to_dict(), "episodes": episodes}
    if path.is_file():
        try:
            have = json.loads(path.read_text(encoding="utf-8"))
        except ValueError:
            have = {}
        mine = {k: have.get(k) for k in want}
        if mine != want:
            raise GraspGaitInputError(
                f"--out {out_dir}: holds another row (policy {have.get('policy', {}).get('label')},"
                f" suite v{have.get('suite_version')}, episodes {have.get('episodes')}); give "
                "another --out folder")
        return
    from graspgait_env import __version__

    write_text_atomic(path, json.dumps({**want, "graspgait_env": __version__,
                                        "created": datetime.now(timezone.utc).isoformat(
                                            timespec="seconds")}, indent=1) + "\n")


def _cell_task(spec: dict, task_id: str, seed: int, episodes: int | None,
               out_dir: str) -> dict[str, Any]:
    """One cell in a Ray worker: its file is written there (a local Ray or a shared
    disk), and the cell comes back, for the driver to write where the worker's disk is
    not its own."""
    return run_cell(spec, task_id, seed, episodes, out_dir)


def _train_task(spec: dict, task_id: str, seed: int, out_dir: str) -> str:
    spec = PolicySpec(**spec)
    train = train_rlzoo if spec.kind == "rlzoo" else train_for
    return str(train(spec, get_task(task_id), seed, out_dir))


class RowResult(dict):
    """What :func:`run_benchmark` returns: ``cells`` (list), ``aggregate``, ``failures``
    (``[(label, error)]``), ``computed`` and ``reused`` (cell counts), ``files``."""


def run_benchmark(policy: str | PolicySpec, tasks: Sequence[Task], seeds: Sequence[int], *,
                  out_dir: str | Path | None = None, episodes: int | None = None,
                  ray: str | None = None, progress: bool = True,
                  reps: int | None = None, command: str = "",
                  on_cell: Callable[[dict], None] | None = None) -> RowResult:
    """Run (or resume) a scoreboard row and write its files (module docstring).

    Parameters
    ----------
    policy
        POLICY (:func:`~graspgait_env.benchmark.policies.parse_policy`).
    tasks, seeds
        The row's tasks and run seeds.
    out_dir
        The row's folder (default ``benchmark/LABEL``).
    episodes
        Test episodes per cell (default: each task's budget).
    ray
        None: serially; ``"local"`` or an address: one Ray task per cell.
    reps
        Bootstrap replications (default :data:`~graspgait_env.benchmark.aggregate.
        BOOTSTRAP_REPS`).
    command
        The command line that makes the row (recorded in ``result.json`` and ``.md``).
    on_cell
        Called with each cell computed here (tests count them).
    """
    from tqdm.auto import tqdm

    from graspgait_env.benchmark.aggregate import BOOTSTRAP_REPS, aggregate_cells

    spec = policy if isinstance(policy, PolicySpec) else parse_policy(policy)
    if not tasks or not seeds:
        raise GraspGaitInputError("give at least one task and one seed")
    if episodes is not None and int(episodes) < 1:
        raise GraspGaitInputError(f"--episodes {episodes}: must be >= 1, e.g. 10")
    for t in tasks:
        for s in seeds:
            t.test_slice(s, episodes)  # refuse seeds past the test range up front
    out = Path(out_dir) if out_dir is not None else Path("benchmark") / spec.label
    out.mkdir(parents=True, exist_ok=True)
    _manifest(out, spec, episodes)
    t0 = time.perf_counter()
    done = load_cells(out, spec, tasks, seeds, episodes)
    todo = [(t, int(s)) for t in tasks for s in seeds if (t.id, int(s)) not in done]
    failures: list[tuple[str, str]] = []
    if todo and ray is None:
        for t, s in tqdm(todo, desc=f"benchmark {spec.label}", unit="cell",
                         disable=not progress):
            try:
                cell = run_cell(spec, t.id, s, episodes, out)
            except GraspGaitInputError:
                raise
            except Exception as exc:  # noqa: BLE001 - reported, the other cells kept
                failures.append((f"{t.id} seed {s}", f"{type(exc).__name__}: {exc}"))
                continue
            done[(t.id, s)] = cell
            if on_cell is not None:
                on_cell(cell)
    elif todo:
        from graspgait_env.baselines.scale_out import ray_session, run_tasks

        with ray_session(ray):
            if spec.kind in ("config", "rlzoo"):  # train each (training task, seed) once, first
                jobs = {}
                for t, s in todo:
                    train_task, _ = training_plan(spec, t, s, out)
                    jobs.setdefault((train_task.id, s), (spec.to_dict(), t.id, s, str(out)))
                _, fails = run_tasks(_train_task, list(jobs.values()),
                                     [f"train {k[0]} seed {k[1]}" for k in jobs],
                                     address=ray, desc="train (ray)", progress=progress)
                failures += [(f.label, f.error) for f in fails]
            calls = [(spec.to_dict(), t.id, s, episodes, str(out)) for t, s in todo]
            results, fails = run_tasks(_cell_task, calls, [f"{t.id} seed {s}" for t, s in todo],
                                       address=ray, desc=f"benchmark {spec.label} (ray)",
                                       progress=progress)
        failures += [(f.label, f.error) for f in fails]
        for (t, s), cell in zip(todo, results, strict=True):
            if cell is None:
                continue
            path = cell_path(out, t.id, s)
            if not path.is_file():  # a cluster without a shared disk
                write_text_atomic(path, json.dumps(cell) + "\n")
            done[(t.id, s)] = cell
            if on_cell is not None:
                on_cell(cell)
    cells = [done[(t.id, int(s))] for t in tasks for s in seeds if (t.id, int(s)) in done]
    agg = aggregate_cells(cells, tasks, seeds, reps or BOOTSTRAP_REPS)
    result = RowResult(
        policy=spec.label, spec=spec.to_dict(), suite_version=SUITE_VERSION,
        tasks=[t.id for t in tasks], seeds=[int(s) for s in seeds], episodes=episodes,
        command=command, date=datetime.now(timezone.utc).strftime("%Y-%m-%d"),
        run_wall_s=time.perf_counter() - t0,
        cells_wall_s=sum(float(c.get("wall_s") or 0) + float(c.get("prepare_s") or 0)
                         for c in cells),
        computed=len(todo) - len(failures), reused=len(cells) - (len(todo) - len(failures)),
        failures=failures, aggregate=agg,
        cells=[{k: v for k, v in c.items() if k != "records"} for c in cells])
    files = {"csv": out / "cells.csv", "json": out / "result.json", "md": out / "result.md",
             "png": out / "profile.png"}
    write_csv(result["cells"], files["csv"])
    write_text_atomic(files["json"], json.dumps(json_ready(dict(result)), indent=1) + "\n")
    write_text_atomic(files["md"], markdown_row(result) + "\n")
    if agg.get("overall"):
        from graspgait_env.benchmark.aggregate import plot_profiles, score_matrix

        matrix, kept, _ = score_matrix(cells, [t.id for t in tasks], seeds)
        plot_profiles({spec.label: matrix}, str(files["png"]),
                      title=f"{spec.label}: {len(kept)} tasks x {len(seeds)} seeds",
                      reps=reps or BOOTSTRAP_REPS)
    else:
        files.pop("png")
    result["files"] = {k: str(v) for k, v in files.items()}
    result["out_dir"] = str(out)
    return result


CSV_FIELDS = ("task", "track", "seed", "policy", "episodes", "first_test_seed",
              *SCORE_FIELDS, "wall_s", "prepare_s")


def write_csv(cells: Sequence[dict], path: str | Path) -> Path:
    """One row per cell: task, seed, policy and the score's fields."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=CSV_FIELDS, lineterminator="\n")
    w.writeheader()
    for c in cells:
        row = {k: c.get(k) for k in CSV_FIELDS}
        row.update({k: c["summary"].get(k) for k in SCORE_FIELDS})
        w.writerow({k: ("" if v is None else v) for k, v in row.items()})
    return write_text_atomic(path, buf.getvalue())


def _f(x: Any, spec: str = ".2f") -> str:
    return "-" if x is None else format(x, spec)


def _ci(entry: dict, key: str) -> str:
    if entry.get(key) is None:
        return "-"
    lo, hi = entry[f"{key}_ci"]
    return f"{100 * entry[key]:.1f} [{100 * lo:.1f}, {100 * hi:.1f}]"


def markdown_row(result: dict) -> str:
    """The row's tables: per task, then per track and over the suite (scores in percent,
    95% bootstrap confidence intervals in brackets)."""
    agg = result["aggregate"]
    lines = [f"## {result['policy']} (suite v{result['suite_version']}, seeds "
             f"{','.join(map(str, result['seeds']))}, {result['date']})", ""]
    if result.get("command"):
        lines += [f"`{result['command']}`", ""]
    lines += [f"Cells: {len(result['cells'])} ({result['computed']} computed now, "
              f"{result['reused']} reused); cell time {result['cells_wall_s']:.0f} s, this "
              f"run {result['run_wall_s']:.0f} s.", "",
              "| task | runs | score mean [95% CI] | score IQM [95% CI] | success | efficiency "
              "| rule-based score | solvable / episodes |",
              "|---|---:|---|---|---:|---:|---:|---:|"]
    for e in agg["tasks"]:
        lines.append(
            f"| {e['task']} | {e['runs']} | {_ci(e, 'mean')} | {_ci(e, 'iqm')} | "
            f"{_f(None if e['success'] is None else 100 * e['success'], '.1f')} | "
            f"{_f(e['efficiency'], '.3f')} | "
            f"{_f(None if e['rule_score'] is None else 100 * e['rule_score'], '.1f')} | "
            f"{e['solvable']} / {e['episodes']} |")
    lines += ["", "| aggregate | tasks | IQM [95% CI] | mean [95% CI] |", "|---|---:|---|---|"]
    for name, e in agg["tracks"].items():
        lines.append(f"| {name} | {e['tasks']} | {_ci(e, 'iqm')} | {_ci(e, 'mean')} |")
    if agg.get("overall"):
        e = agg["overall"]
        lines.append(f"| **suite** | {e['tasks']} | {_ci(e, 'iqm')} | {_ci(e, 'mean')} |")
    if agg["excluded"]:
        lines += ["", f"Left out of the aggregates (a run missing or no solvable start): "
                  f"{', '.join(agg['excluded'])}."]
    if result.get("failures"):
        lines += ["", "Failed cells: " + "; ".join(f"{a}: {b}" for a, b in result["failures"])]
    return "\n".join(lines)
