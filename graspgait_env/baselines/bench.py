"""Regenerate the thesis's Table 1 (best-first, 5.5) and Table 6.1 (general vs rule-based, 6.5).

Protocol (thesis 5.5): the four test objects of fig. 5.3 (``circle``, ``ellipse``,
``pentagon``, ``hexagon``), 90° workspaces (the default hand), μ = 0.8 and 0.7, 10
initial grasps each, a 360° counter-clockwise goal. The thesis does not list its initial
grasps; we take, for each object and μ, 10 legal grasps at θ = 0 spread evenly through
:meth:`GaitModel.start_states` among those from which the exact planner finds a gait
(so every planner is asked a question that has an answer). Every planner gets the same
10 starts. Averages are over the successful runs; the success rate is reported beside.

The thesis's own figures are kept in :data:`THESIS_TABLE_1` and
:data:`THESIS_TABLE_6_1` and printed next to ours; they are the thesis's numbers, not
measurements of this code.
"""

from __future__ import annotations

import csv
import io
import json
import math
import statistics
import time
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from tqdm.auto import tqdm

from graspgait_env.atomic import write_text_atomic
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.registry import get_planner
from graspgait_env.timing import BenchRow, register

__all__ = ["BenchCase", "bench_starts", "run_bench", "run_case", "DEFAULT_PLANNERS",
           "markdown_report", "THESIS_TABLE_1", "THESIS_TABLE_6_1", "THESIS_OBJECTS"]

THESIS_OBJECTS = ("circle", "ellipse", "pentagon", "hexagon")  # thesis fig. 5.3 (a)-(d)
# the bench's planners, in column order: best-first with both tie-breaks (5.5), the
# rule-based method (6.5), the modified search alone (6.4), the exact optimum
DEFAULT_PLANNERS = ("best-first", "best-first-newest", "rule", "modified", "optimal")
# Table 1 (best-first): (nodes opened, path length, regrasps) per object and mu.
THESIS_TABLE_1: dict[tuple[str, float], tuple[float, float, float]] = {
    ("circle", 0.8): (500.2, 44.8, 22.4), ("circle", 0.7): (957.7, 82.0, 41.1),
    ("ellipse", 0.8): (5746.5, 48.2, 31.5), ("ellipse", 0.7): (14486.3, 30.4, 20.3),
    ("pentagon", 0.8): (315.0, 37.4, 21.9), ("pentagon", 0.7): (208.2, 29.5, 18.0),
    ("hexagon", 0.8): (439.5, 42.7, 24.4), ("hexagon", 0.7): (1421.2, 83.4, 58.0),
}
# Table 6.1 (mu = 0.7), rule-based column: nodes opened = path length = regrasps (6.5),
# a path length being "the number of nodes in the final path" (5.4), the initial grasp
# included: compare it with our rule-based gait's grasps, regrasps + 1 ("path nodes").
# The pentagon's Table 1 mu=.7 entry is garbled in the text; 208.2 / 29.5 / 18.0 is its
# Table 6.1 "general" column.
THESIS_TABLE_6_1: dict[str, float] = {"circle": 9.0, "ellipse": 13.8, "pentagon": 14.5,
                                      "hexagon": 18.6}


@dataclass
class BenchCase:
    """One planner run of the bench."""

    object: str
    mu: float
    start: str
    planner: str
    success: bool
    nodes_opened: int
    path_length: int
    regrasps: int
    rotation_deg: float
    wall_time_s: float
    pattern: str
    method: str = ""
    entry_needed: bool | None = None
    entry_moves: int | None = None
    # an agent run under a contact model other than the bench's point contacts: the
    # contact model and the optimum's and rule-based gait's regrasps from the same start
    # under it (None for the planners' runs, compared with the point-contact planners)
    contact_model: str | None = None
    optimal_regrasps: int | None = None
    rule_regrasps: int | None = None


def bench_starts(model: GaitModel, count: int = 10) -> list[GaitState]:
    """``count`` legal starts at θ = 0 with a 360° gait, spread evenly (see module doc)."""
    from graspgait_env.planners.exact import optimal_gait

    starts = model.start_states()
    if not starts:
        return []
    picked: list[GaitState] = []
    # walk the list with a stride, then fill from the rest, until `count` have a gait
    stride = max(1, len(starts) // count)
    order = [i for off in range(stride) for i in range(off, len(starts), stride)]
    for i in order:
        if optimal_gait(model, starts[i], 360.0).success:
            picked.append(starts[i])
            if len(picked) == count:
                break
    return picked


@lru_cache(maxsize=16)
def _model(obj: str, mu: float) -> GaitModel:
    """The bench's gait model: the thesis's point contacts, the default hand, n = 180."""
    return GaitModel(obj, mu)


def run_case(obj: str, mu: float, start: GaitState, planner: str, turn_deg: float = 360.0,
             planner_kwargs: dict[str, Any] | None = None) -> BenchCase:
    """One run of the bench: ``planner`` from ``start`` on object ``obj`` at ``mu``.

    A plain function of its arguments (the model is rebuilt, or cached, in the process
    that runs it), so runs can be farmed out to other processes.

    Parameters
    ----------
    obj
        Object name or YAML path.
    mu
        Friction coefficient.
    start
        Start grasp at θ = 0 (a legal state of ``GaitModel(obj, mu)``).
    planner
        A planner name of :data:`~graspgait_env.planners.registry.PLANNERS`.
    turn_deg
        Requested turn (degrees).
    planner_kwargs
        Extra keyword arguments of the planner.

    Returns
    -------
    BenchCase
        The run's row; ``method``, ``entry_needed`` and ``entry_moves`` come from the
        rule-based planners' ``extra`` (empty / ``None`` for the others).
    """
    model = _model(obj, mu)
    fn = get_planner(planner)
    t0 = time.perf_counter()
    r = fn(model, start, turn_deg, **(planner_kwargs or {}))
    wall = time.perf_counter() - t0
    label = ",".join(f"{f + 1}:{model.contact_deg(start.contacts[f]):g}" for f in start.held())
    return BenchCase(obj, mu, label, planner, r.success, r.nodes_opened, r.path_length,
                     r.regrasps, r.rotation_deg, wall, r.pattern,
                     str(r.extra.get("method", "")), r.extra.get("entry_needed"),
                     r.extra.get("entry_moves"))


def run_bench(objects=THESIS_OBJECTS, mus=(0.8, 0.7), planners=DEFAULT_PLANNERS,
              starts: int = 10, turn_deg: float = 360.0, progress: bool = True,
              planner_kwargs: dict[str, dict[str, Any]] | None = None) -> list[BenchCase]:
    """Run every planner from the same starts on every object and μ; one row per run
    (:func:`run_case` per run)."""
    for p in planners:
        get_planner(p)  # refuse unknown names before any work
    kw = planner_kwargs or {}
    jobs = []
    for obj in objects:
        for mu in mus:
            for s in bench_starts(_model(obj, mu), starts):
                for p in planners:
                    jobs.append((obj, mu, s, p))
    return [run_case(obj, mu, s, p, turn_deg, kw.get(p))
            for obj, mu, s, p in tqdm(jobs, desc="bench", disable=not progress, unit="run")]


def _mean(xs: list[float]) -> float:
    return statistics.fmean(xs) if xs else math.nan


def summarize(cases: list[BenchCase]) -> dict[tuple[str, float, str], dict[str, float]]:
    """Per (object, mu, planner): mean nodes opened, path length, regrasps and path nodes
    (regrasps + 1: the grasps of the gait, thesis 5.4's count) over the successful runs,
    success rate, mean wall time (ms)."""
    out: dict[tuple[str, float, str], dict[str, float]] = {}
    keys = sorted({(c.object, c.mu, c.planner) for c in cases},
                  key=lambda k: (THESIS_OBJECTS.index(k[0]) if k[0] in THESIS_OBJECTS else 99,
                                 -k[1], k[2]))
    for key in keys:
        runs = [c for c in cases if (c.object, c.mu, c.planner) == key]
        ok = [c for c in runs if c.success]
        out[key] = {
            "nodes_opened": _mean([c.nodes_opened for c in ok]),
            "path_length": _mean([c.path_length for c in ok]),
            "regrasps": _mean([c.regrasps for c in ok]),
            # the nodes of the final path, the initial grasp included (thesis 5.4): the
            # grasps of the gait, one more than its regrasps (Table 6.1's rule-based count)
            "path_nodes": _mean([c.regrasps + 1 for c in ok]),
            "nodes_per_step": (_mean([c.nodes_opened for c in ok])
                               / _mean([c.path_length for c in ok])) if ok and any(
                                   c.path_length for c in ok) else math.nan,
            "success": len(ok) / len(runs),
            "wall_ms": 1e3 * _mean([c.wall_time_s for c in runs]),
            "runs": len(runs),
        }
    return out


def _f(x: float) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:,.1f}"


def markdown_report(cases: list[BenchCase]) -> str:
    """Tables 1 and 6.1 regenerated, with the thesis's figures beside ours, and how the
    rule-based method ran from each start.

    The planners only: learned agents' runs (planner ``"agent:NAME"``) are left out of
    these tables (some run from other starts under the hand's contact model); they have
    their own table (``graspgait_env.agents.bench.agents_markdown``)."""
    cases = [c for c in cases if not c.planner.startswith("agent:")]
    summ = summarize(cases)
    order = list(DEFAULT_PLANNERS)
    planners = sorted({c.planner for c in cases},
                      key=lambda p: (order.index(p) if p in order else len(order), p))
    objs = [o for o in THESIS_OBJECTS if any(c.object == o for c in cases)] + sorted(
        {c.object for c in cases} - set(THESIS_OBJECTS))
    mus = sorted({c.mu for c in cases}, reverse=True)
    rows = (("nodes opened", "nodes_opened"), ("path length", "path_length"),
            ("regrasps", "regrasps"), ("nodes per path step", "nodes_per_step"),
            ("success rate", "success"), ("wall time (ms)", "wall_ms"))
    lines = ["### Table 1 regenerated: best-first search (thesis 5.5) and the other planners",
             "", "| object | mu | data | thesis best-first | " + " | ".join(planners) + " |",
             "|---|---|---|---:|" + "---:|" * len(planners)]
    for o in objs:
        for mu in mus:
            th = THESIS_TABLE_1.get((o, mu))
            for j, (name, key) in enumerate(rows):
                ref = _f(th[j]) if th and j < 3 else ""
                if key == "nodes_per_step" and th:
                    ref = f"{th[0] / th[1]:,.2f}"
                vals = [summ.get((o, mu, p), {}).get(key, math.nan) for p in planners]
                fmt = [f"{v:.0%}" if key == "success" and not math.isnan(v)
                       else f"{v:,.2f}" if key == "nodes_per_step" and not math.isnan(v)
                       else _f(v) for v in vals]
                lines.append(f"| {o} | {mu:g} | {name} | {ref} | " + " | ".join(fmt) + " |")
    cols = [p for p in planners if p != "modified"]
    if 0.7 in mus:
        lines += ["", "### Table 6.1 regenerated (mu = 0.7): general (best-first) vs rule-based",
                  "", "| object | data | thesis general | thesis rule-based | "
                  + " | ".join(cols) + " |", "|---|---|---:|---:|" + "---:|" * len(cols)]
        for o in objs:
            th = THESIS_TABLE_1.get((o, 0.7))
            for j, (name, key) in enumerate(rows[:3]):
                ours = [_f(summ.get((o, 0.7, p), {}).get(key, math.nan)) for p in cols]
                lines.append(f"| {o} | {name} | {_f(th[j]) if th else ''} | "
                             f"{_f(THESIS_TABLE_6_1.get(o, math.nan))} | " + " | ".join(ours)
                             + " |")
    if 0.7 in mus and "rule" in planners:
        lines += ["", "### Table 6.1's rule-based column, counted as the thesis counts", "",
                  "The thesis's rule-based figure is the number of nodes of the final path, "
                  "the initial grasp included (5.4; \"all three measures are always equal\", "
                  "6.5): our rule-based gait's grasps, its regrasps + 1.", "",
                  "| object | thesis rule-based | rule: path nodes (initial grasp included) | "
                  "vs thesis | rule: regrasps |", "|---|---:|---:|---:|---:|"]
        for o in objs:
            cell = summ.get((o, 0.7, "rule"), {})
            nodes, th = cell.get("path_nodes", math.nan), THESIS_TABLE_6_1.get(o, math.nan)
            diff = (f"{100 * (nodes - th) / th:+.1f} %" if not (math.isnan(nodes)
                                                                 or math.isnan(th)) else "-")
            lines.append(f"| {o} | {_f(th)} | {_f(nodes)} | {diff} | "
                         f"{_f(cell.get('regrasps', math.nan))} |")
    rule = [c for c in cases if c.planner == "rule"]
    if rule:
        lines += ["", "### The rule-based method, start by start", "",
                  "| object | mu | starts | forward | back-and-forth | modified search | "
                  "box entered (moves) | patterns |", "|---|---|---:|---:|---:|---:|---|---|"]
        for o in objs:
            for mu in mus:
                runs = [c for c in rule if (c.object, c.mu) == (o, mu)]
                if not runs:
                    continue
                by = {m: sum(c.method == m for c in runs if c.success)
                      for m in ("forward", "back-and-forth", "modified-search")}
                entries = [c.entry_moves for c in runs if c.entry_needed]
                entered = (f"{len(entries)} ({', '.join(map(str, entries))})" if entries
                           else "0")
                pats = sorted({c.pattern for c in runs if c.pattern})
                lines.append(f"| {o} | {mu:g} | {len(runs)} | {by['forward']} | "
                             f"{by['back-and-forth']} | {by['modified-search']} | {entered} | "
                             f"{', '.join(pats)} |")
    return "\n".join(lines)


def write_csv(cases: list[BenchCase], path: str) -> None:
    """One row per run (atomic)."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(BenchCase.__dataclass_fields__))
    w.writeheader()
    for c in cases:
        w.writerow(c.__dict__)
    write_text_atomic(path, buf.getvalue())


def write_json(cases: list[BenchCase], path: str) -> None:
    """Runs and per-cell summary as JSON (atomic)."""
    summ = {f"{o}|{mu}|{p}": v for (o, mu, p), v in summarize(cases).items()}
    write_text_atomic(path, json.dumps({"runs": [c.__dict__ for c in cases], "summary": summ},
                                       indent=1) + "\n")


# ----------------------------------------------------------------- graspgait perf rows
RULE_TARGET_MS = 10.0  # (ms) a rule-based 360 deg gait (issue target)
EXACT_TARGET_S = 1.0  # (s) the exact planner per object at n = 180


@register
def bench_planners(repeat: int) -> list[BenchRow]:
    """Rule-based 360° gait time, exact planner time per thesis object, best-first nodes."""
    rows = []
    rule = get_planner("rule")
    exact = get_planner("optimal")
    best = get_planner("best-first")
    reps = max(1, min(repeat, 20))
    for obj in THESIS_OBJECTS:
        model = GaitModel(obj, 0.7)
        starts = bench_starts(model, 3)
        if not starts:
            rows.append(BenchRow(f"planners on {obj}", math.nan, "", "", None,
                                 "no start with a gait"))
            continue
        s = starts[0]
        t = []
        for _ in range(reps):
            t0 = time.perf_counter()
            r = rule(model, s, 360.0)
            t.append(time.perf_counter() - t0)
        ms = 1e3 * statistics.median(t)
        rows.append(BenchRow(f"rule-based 360 deg gait, {obj}", ms, "ms",
                             f"<= {RULE_TARGET_MS:g} ms", r.success and ms <= RULE_TARGET_MS,
                             f"mu=0.7, {r.planner}{', ' + r.pattern if r.pattern else ''}, "
                             f"{'ok' if r.success else 'no gait'}, median of {reps}"))
        t0 = time.perf_counter()
        r = exact(model, s, 360.0)
        sec = time.perf_counter() - t0
        rows.append(BenchRow(f"exact planner, {obj}", sec, "s", f"<= {EXACT_TARGET_S:g} s",
                             r.success and sec <= EXACT_TARGET_S,
                             f"mu=0.7, n=180, {r.regrasps} regrasps"))
        t0 = time.perf_counter()
        r = exact(model, None, 360.0)  # the object's optimum: every start seeded at once
        sec = time.perf_counter() - t0
        rows.append(BenchRow(f"exact planner, every start, {obj}", sec, "s",
                             f"<= {EXACT_TARGET_S:g} s", r.success and sec <= EXACT_TARGET_S,
                             f"mu=0.7, n=180, {r.extra.get('starts_seeded', 0)} starts, "
                             f"{r.regrasps} regrasps"))
        opened = [best(model, st, 360.0).nodes_opened for st in starts]
        th = THESIS_TABLE_1[(obj, 0.7)][0]
        rows.append(BenchRow(f"best-first nodes opened, {obj}", _mean(opened), "nodes", "",
                             None, f"mu=0.7, mean of {len(starts)} starts; thesis Table 1: "
                             f"{th:g}"))
    return rows
