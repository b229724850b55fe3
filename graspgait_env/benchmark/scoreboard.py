"""The scoreboard: several rows of ``graspgait benchmark`` side by side.

Each row is a folder written by :func:`~graspgait_env.benchmark.run.run_benchmark` (its
``result.json``). :func:`scoreboard` reads them and writes, from the rows' own records:

- the summary table, one line per row: the suite IQM and mean with their 95% stratified
  bootstrap intervals, the IQM of each track, the row's wall time and the command that
  made it;
- the per-task table: each row's mean score over its runs, task by task;
- the rows' performance profiles in one figure (rliable's score distributions).

Scores are in percent (success x efficiency, docs/benchmark.md). Rows of different suite
versions, tasks or seeds are refused: their aggregates do not compare.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from graspgait_env.benchmark.suite import TRACKS
from graspgait_env.errors import GraspGaitInputError

__all__ = ["load_row", "scoreboard", "scoreboard_markdown"]


def load_row(folder: str | Path) -> dict[str, Any]:
    """The ``result.json`` of a row's folder (or the JSON file itself).

    Raises
    ------
    GraspGaitInputError
        No ``result.json`` there: run the row (``graspgait benchmark POLICY --out DIR``).
    """
    path = Path(folder)
    if path.is_dir():
        path = path / "result.json"
    if not path.is_file():
        raise GraspGaitInputError(
            f"scoreboard row {str(folder)!r}: no result.json there; run the row first "
            "(graspgait benchmark POLICY --out DIR)")
    return json.loads(path.read_text(encoding="utf-8"))


def _pct(entry: dict[str, Any] | None, key: str) -> str:
    if not entry or entry.get(key) is None:
        return "-"
    lo, hi = entry[f"{key}_ci"]
    return f"{100 * entry[key]:.1f} [{100 * lo:.1f}, {100 * hi:.1f}]"


def _wall(seconds: float) -> str:
    m, s = divmod(int(round(seconds)), 60)
    h, m = divmod(m, 60)
    return f"{h} h {m:02d} min" if h else f"{m} min {s:02d} s"


def _check_comparable(rows: Sequence[dict[str, Any]]) -> None:
    first = rows[0]
    for r in rows[1:]:
        for key in ("suite_version", "seeds"):
            if r[key] != first[key]:
                raise GraspGaitInputError(
                    f"scoreboard: row {r['policy']!r} has {key}={r[key]!r}, row "
                    f"{first['policy']!r} {first[key]!r}; rerun it with the same {key}")


def scoreboard_markdown(rows: Sequence[dict[str, Any]]) -> str:
    """The summary table and the per-task table of ``rows`` (``result.json`` dicts)."""
    if not rows:
        raise GraspGaitInputError("scoreboard: give at least one row folder")
    _check_comparable(rows)
    tracks = [t for t in TRACKS if any(t in r["aggregate"]["tracks"] for r in rows)]
    head = (["row", "suite IQM [95% CI]", "suite mean [95% CI]"]
            + [f"{t} IQM" for t in tracks] + ["wall time", "command"])
    lines = ["| " + " | ".join(head) + " |",
             "|" + "|".join(["---"] * (len(head) - 2) + ["---:", "---"]) + "|"]
    for r in rows:
        agg = r["aggregate"]
        cells = ([f"`{r['policy']}`", _pct(agg.get("overall"), "iqm"),
                  _pct(agg.get("overall"), "mean")]
                 + [_pct(agg["tracks"].get(t), "iqm") for t in tracks]
                 + [_wall(float(r["run_wall_s"])), f"`{r['command']}`"])
        lines.append("| " + " | ".join(cells) + " |")
    tasks = list(dict.fromkeys(t for r in rows for t in r["tasks"]))
    lines += ["", "| task | " + " | ".join(f"`{r['policy']}`" for r in rows) + " |",
              "|---|" + "---:|" * len(rows)]
    for t in tasks:
        vals = []
        for r in rows:
            e = next((e for e in r["aggregate"]["tasks"] if e["task"] == t), None)
            vals.append("-" if e is None or e.get("mean") is None else f"{100 * e['mean']:.1f}")
        lines.append(f"| {t} | " + " | ".join(vals) + " |")
    return "\n".join(lines)


def scoreboard(folders: Sequence[str | Path], *, md: str | Path | None = None,
               png: str | Path | None = None, reps: int | None = None) -> str:
    """Read the rows in ``folders`` and write their scoreboard.

    Parameters
    ----------
    folders
        Row folders (or their ``result.json``), in the order of the table.
    md
        Also write the tables here (atomically).
    png
        Also draw the rows' performance profiles here.
    reps
        Bootstrap replications of the profiles' bands (default: the rows' own).

    Returns
    -------
    str
        The Markdown tables.
    """
    from graspgait_env.atomic import write_text_atomic
    from graspgait_env.benchmark.aggregate import plot_profiles, score_matrix

    rows = [load_row(f) for f in folders]
    text = scoreboard_markdown(rows)
    if md is not None:
        write_text_atomic(Path(md), text + "\n")
    if png is not None:
        matrices = {}
        for r in rows:
            matrix, kept, _ = score_matrix(r["cells"], r["tasks"], r["seeds"])
            if kept:
                matrices[r["policy"]] = matrix
        if not matrices:
            raise GraspGaitInputError("scoreboard --png: no row has a complete task to plot")
        plot_profiles(matrices, str(png), reps=reps or int(rows[0]["aggregate"]["reps"]),
                      title=f"{len(matrices)} rows, seeds "
                            f"{','.join(map(str, rows[0]['seeds']))}")
    return text
