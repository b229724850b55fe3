"""Performance targets, measured in one process (``graspgait perf``).

A composition root: it reaches across the layers (map level, physics, envs, baselines).
Each benchmark is a function ``bench(repeat) -> list[BenchRow]`` registered in
:data:`~graspgait_env.timing.BENCHMARKS` with :func:`~graspgait_env.timing.register`;
:func:`run_benchmarks` runs them all in order and :func:`markdown_table` prints the
rows. A row with a target says PASS or FAIL; a row without one (``passed is None``) is
context (e.g. the reference loop's time).

Later work adds rows by writing one more function in its own module and decorating it
with ``@register`` (the module must be imported before :func:`run_benchmarks`; list
it in :data:`BENCHMARK_MODULES`).

Timing: :func:`time.perf_counter`, a warm-up call first, the median over repeats.
"""

from __future__ import annotations

import importlib
import json
import os
import platform
from dataclasses import asdict
from pathlib import Path

import numpy as np

from graspgait_env.timing import BENCHMARKS, BenchRow, median_time_s, register

__all__ = [
    "BenchRow",
    "BENCHMARKS",
    "BENCHMARK_EXTRAS",
    "BENCHMARK_MODULES",
    "register",
    "median_time_s",
    "run_benchmarks",
    "markdown_table",
    "write_json",
    "GRASP_MAP_TARGET_MS",
    "SPEEDUP_TARGET",
    "skipped_benchmark_modules",
    "environment_line",
]

GRASP_MAP_TARGET_MS = 2.0  # (ms) a 180 x 180 grasp map of the thesis ellipse
SPEEDUP_TARGET = 10.0  # vectorized grasp map vs the per-pair Python loop


# Modules whose import registers more benchmarks (later issues append theirs here).
BENCHMARK_MODULES: list[str] = [
    "graspgait_env.baselines.bench",
    "graspgait_env.envs.bench",
    "graspgait_env.envs.vector_bench",
    "graspgait_env.sim.perf_rows",
    "graspgait_env.envs.render_bench",
    "graspgait_env.agents.throughput",
]
# The extra a benchmark module needs; without it the module's rows are left out and
# `graspgait perf` says so (graspgait_env.extras).
BENCHMARK_EXTRAS: dict[str, str] = {"graspgait_env.agents.throughput": "train"}


def skipped_benchmark_modules() -> list[tuple[str, str]]:
    """``(module, extra)`` for each module of :data:`BENCHMARK_MODULES` whose extra is
    not installed: :func:`run_benchmarks` leaves its rows out."""
    from graspgait_env.extras import missing_modules

    return [(mod, BENCHMARK_EXTRAS[mod]) for mod in BENCHMARK_MODULES
            if mod in BENCHMARK_EXTRAS and missing_modules(BENCHMARK_EXTRAS[mod])]


@register
def bench_grasp_map(repeat: int) -> list[BenchRow]:
    """Vectorized grasp map vs the per-pair loop: thesis ellipse, n = 180, mu = 0.7."""
    from graspgait_env.grasp_map import grasp_map, grasp_map_loop
    from graspgait_env.objects import load_object

    shape = load_object("ellipse")
    mu, n = 0.7, 180
    t_vec = median_time_s(lambda: grasp_map(shape, mu, n), repeat, warmup=3)
    loop_repeat = max(1, min(5, repeat))  # the loop is slow: a few runs suffice
    t_loop = median_time_s(lambda: grasp_map_loop(shape, mu, n), loop_repeat, warmup=1)
    ratio = t_loop / t_vec
    what = f"{shape.name}, mu={mu:g}"
    return [
        BenchRow(f"grasp map {n}x{n}", 1e3 * t_vec, "ms", f"< {GRASP_MAP_TARGET_MS:g} ms",
                 1e3 * t_vec < GRASP_MAP_TARGET_MS, f"{what}, median of {repeat}"),
        BenchRow(f"grasp map {n}x{n}, per-pair loop", 1e3 * t_loop, "ms", "", None,
                 f"{what}, median of {loop_repeat}"),
        BenchRow("speed-up vs loop", ratio, "x", f">= {SPEEDUP_TARGET:g}x",
                 ratio >= SPEEDUP_TARGET, "loop time / vectorized time"),
    ]


def run_benchmarks(repeat: int = 100) -> list[BenchRow]:
    """Import :data:`BENCHMARK_MODULES` (those whose extra is installed), then run every
    registered benchmark in order."""
    if isinstance(repeat, bool) or not isinstance(repeat, int) or repeat < 1:
        raise ValueError(f"repeat={repeat!r}: must be an integer >= 1, e.g. 100")
    skipped = {mod for mod, _ in skipped_benchmark_modules()}
    for mod in BENCHMARK_MODULES:
        if mod not in skipped:
            importlib.import_module(mod)
    rows: list[BenchRow] = []
    for bench in BENCHMARKS:
        rows.extend(bench(repeat))
    return rows


def _fmt(value: float) -> str:
    return f"{value:.3g}" if abs(value) < 100 else f"{value:.0f}"


def markdown_table(rows: list[BenchRow]) -> str:
    """The rows as a Markdown table: benchmark, value, target, result, detail."""
    lines = ["| benchmark | value | target | result | detail |",
             "|---|---:|---|---|---|"]
    for r in rows:
        unit = "x" if r.unit == "x" else f" {r.unit}"
        lines.append(f"| {r.name} | {_fmt(r.value)}{unit} | {r.target or '-'} | "
                     f"{r.verdict} | {r.detail} |")
    return "\n".join(lines)


def environment_line() -> str:
    """Python, NumPy and machine, for the record beside the table."""
    return (f"Python {platform.python_version()}, NumPy {np.__version__}, "
            f"{platform.machine()} {platform.system()}, {os.cpu_count()} CPUs")


def write_json(rows: list[BenchRow], path: str | os.PathLike[str]) -> Path:
    """Write the rows (with their verdicts) to ``path`` as JSON, atomically."""
    from graspgait_env.plotting import atomic_write

    doc = {"environment": environment_line(),
           "rows": [{**asdict(r), "verdict": r.verdict} for r in rows]}
    text = json.dumps(doc, indent=2) + "\n"
    return atomic_write(path, lambda fh: fh.write(text.encode("utf-8")))
