"""Timing helpers and the registry of ``graspgait perf`` rows (core: no layer above it).

Each layer that has something to time writes a function ``bench(repeat) ->
list[BenchRow]`` and decorates it with :func:`register`; the composition root
:mod:`graspgait_env.perf` imports those modules (its ``BENCHMARK_MODULES``) and runs
every registered benchmark. Keeping the row type and the registry here lets the
physics, env and baseline layers register rows without importing the composition root.

Timing: :func:`time.perf_counter`, a warm-up call first, the median over repeats.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["BENCHMARKS", "BenchRow", "Benchmark", "median_time_s", "register"]


@dataclass
class BenchRow:
    """One line of the performance table.

    Attributes
    ----------
    name
        What was measured, e.g. ``"grasp map 180x180"``.
    value
        The measurement, in ``unit``.
    unit
        ``"ms"``, ``"x"`` (a ratio), ...
    target
        The target as text (``"< 2 ms"``), or ``""`` for a context row.
    passed
        True / False against the target; None for a context row.
    detail
        Free text: object, repeats, ...
    """

    name: str
    value: float
    unit: str
    target: str = ""
    passed: bool | None = None
    detail: str = ""

    @property
    def verdict(self) -> str:
        """``PASS``, ``FAIL`` or ``-``."""
        return "-" if self.passed is None else ("PASS" if self.passed else "FAIL")


Benchmark = Callable[[int], list[BenchRow]]
BENCHMARKS: list[Benchmark] = []
def register(fn: Benchmark) -> Benchmark:
    """Decorator: add a benchmark ``fn(repeat) -> list[BenchRow]`` to the table."""
    if fn not in BENCHMARKS:
        BENCHMARKS.append(fn)
    return fn


def median_time_s(fn: Callable[[], Any], repeat: int, warmup: int = 1) -> float:
    """Median wall time (s) of ``fn()`` over ``repeat`` calls after ``warmup`` calls."""
    if repeat < 1:
        raise ValueError(f"repeat={repeat!r}: must be >= 1")
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


