"""Model cards in the Hugging Face / CleanRL form, written from the saved runs' own cards.

``graspgait card MODEL [MODEL ...]`` (:func:`hub_card`) reads the JSON card of each model
(:func:`~graspgait_env.agents.card.read_card`: one training run, one seed, its final
evaluation) and writes one Markdown card for the recipe, as the Hugging Face Hub reads
it: YAML front matter (``library_name``, ``tags`` and a ``model-index`` whose metrics are
``"mean +/- std"`` over the runs, as ``huggingface_sb3`` and CleanRL write theirs), then
the env id and keywords, the metrics per run and over runs, the training
hyper-parameters, the versions and the commands that reproduce and evaluate it. Nothing
in it is typed by hand: run it again after retraining.

Every run must come from the same recipe: the same ``algo``, ``env_id`` and
``env_kwargs`` (the seed, the run folder and the measured figures may differ); a card
over runs of different recipes is refused, naming the field.

Metrics (from each card's ``eval``, the training run's last periodic evaluation):

- ``success``: the success rate over the evaluation starts from which a gait exists, %;
- ``regrasps / optimum``: the agent's regrasps over the exact optimum's on its
  successful episodes (1 = optimal), and ``regrasps / rule`` against the rule-based gait;
- ``training wall time`` (s) and ``PPO steps`` (the model's ``num_timesteps``: 0 for a
  recipe that learns by imitation alone), with ``imitation labels`` and ``imitation env
  steps`` (the states DAgger trained on and the env steps it took to collect them) for a
  recipe with an ``imitation:`` block.

``std`` is the population standard deviation over runs (NumPy's default, ``ddof = 0``),
as CleanRL reports; with one run it is 0 and the card says "1 run".

``--benchmark DIR`` (:func:`benchmark_section`) adds the rows of ``graspgait benchmark``
that the recipe made, read from each row folder's ``result.json``: the suite IQM and mean
with their 95% stratified bootstrap intervals and the IQM per track. Where one row is the
shipped run (``agent:NAME``) and another the recipe retrained over seeds (a model
template ``RUNS/s{seed}/model.zip`` or ``config:NAME``), on the same tasks and seeds, the
card says whether the retrained recipe's IQM is below the shipped run's: then it is
**worse**, however little (the benchmark's rule, docs/benchmark.md). Below the table, each
row's per-task figures as mean +/- std over its seeds (success over the starts with a
gait, the regrasps over the optimum's, the score), read from the row's cells.

``--against [NAME=]DIR`` adds another recipe's row on the same tasks and seeds (e.g. the
one agent ``general``'s five models on a per-object agent's tasks) and says how this
recipe compares with it: its retrained row's IQM (the shipped run's without one) is
**better** when it lies above the upper end of the other row's 95% interval, **worse**
when below the lower end, and else not measurably different. This is the rule by which a
per-object agent stays shipped beside ``general`` (docs/agents.md).
"""

from __future__ import annotations

import json
import os
import shlex
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from graspgait_env.agents.audit import beyond_lookahead_clause
from graspgait_env.errors import GraspGaitInputError

__all__ = ["METRICS", "benchmark_section", "compare_rows", "evaluation_section", "hub_card",
           "metric_stats", "task_stats", "write_hub_card"]

#: (key in a card's ``eval``, name in the card, scale, format) of each metric.
METRICS: tuple[tuple[str, str, float, str], ...] = (
    ("success_rate_solvable", "success over starts with a gait (%)", 100.0, ".1f"),
    ("regrasps_vs_optimal", "regrasps / optimum", 1.0, ".3f"),
    ("regrasps_vs_rule", "regrasps / rule-based gait", 1.0, ".3f"),
)
_SAME = ("algo", "env_id", "env_kwargs")  # what every run of one recipe shares


def metric_stats(values: Sequence[float]) -> tuple[float, float]:
    """``(mean, std)`` of one metric over runs (``std`` with ``ddof = 0``)."""
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        raise GraspGaitInputError("metric_stats: no values; give at least one run")
    return float(x.mean()), float(x.std())


def _check_same(cards: Sequence[Mapping[str, Any]], names: Sequence[str]) -> None:
    first = cards[0]
    for card, name in zip(cards[1:], names[1:], strict=True):
        for key in _SAME:
            if card.get(key) != first.get(key):
                raise GraspGaitInputError(
                    f"MODEL {name}: its {key} {card.get(key)!r} differs from {names[0]}'s "
                    f"{first.get(key)!r}; a card covers the runs (seeds) of one recipe")


def _stat(values: Sequence[float], scale: float, fmt: str) -> str:
    mean, std = metric_stats([v * scale for v in values])
    return f"{mean:{fmt}} +/- {std:{fmt}}"


def hub_card(cards: Sequence[Mapping[str, Any]], *, names: Sequence[str] | None = None,
             title: str | None = None,
             benchmarks: Sequence[Mapping[str, Any]] = (),
             benchmark_names: Sequence[str] | None = None,
             against: Sequence[tuple[str, Mapping[str, Any]]] = (),
             evaluations: Sequence[Mapping[str, Any]] = (),
             command: str | None = None) -> str:
    """The Markdown model card (Hugging Face front matter first) of one recipe's runs.

    Parameters
    ----------
    cards
        The JSON cards of the runs (:func:`~graspgait_env.agents.card.read_card`), one
        per seed, each with its ``eval``.
    names
        How each run is named in the card and in errors (default ``run 1``, ...); its
        model path, usually.
    title
        The card's heading (default: the recipe's config name and env id).
    benchmarks, benchmark_names
        ``graspgait benchmark`` rows' ``result.json`` to add as a ``## Benchmark``
        section (:func:`benchmark_section`), and how errors name them.
    against
        ``(name, result.json)`` of other recipes' rows on the same tasks and seeds, to
        compare this recipe with (module docstring; needs ``benchmarks``).
    evaluations
        ``graspgait evaluate --json`` results of these models, each a row of a
        ``## Measured results`` table with the command that made it
        (:func:`evaluation_section`).
    command
        The ``graspgait card`` command line that writes this card, for its
        ``## Reproduce`` section (default: the plain form over the run folders).

    Returns
    -------
    str
        The card, ending with a newline.

    Raises
    ------
    GraspGaitInputError
        No card, a card without an evaluation, or cards of different recipes.
    """
    if not cards:
        raise GraspGaitInputError("MODEL: give at least one model (one per seed)")
    if against and not benchmarks:
        raise GraspGaitInputError(
            "--against: give this recipe's own rows too (--benchmark DIR: the shipped run's "
            "row agent:NAME, the retrained recipe's config:NAME); the comparison is theirs")
    names = list(names) if names is not None else [f"run {i + 1}" for i in range(len(cards))]
    _check_same(cards, names)
    for card, name in zip(cards, names, strict=True):
        ev = card.get("eval")
        if not isinstance(ev, Mapping) or any(k not in ev for k, *_ in METRICS[:2]):
            raise GraspGaitInputError(
                f"MODEL {name}: its card has no final evaluation (eval with "
                "success_rate_solvable and regrasps_vs_optimal); train with eval_freq > 0 "
                "or evaluate it first")
    first = cards[0]
    cfg = first.get("config") or {}
    algo, env_id = str(first.get("algo", "")), str(first.get("env_id", ""))
    recipe = str(cfg.get("name") or "custom")
    n = len(cards)
    evals = [c["eval"] for c in cards]
    seeds = [c.get("seed") for c in cards]
    metrics = []
    for key, label, scale, fmt in METRICS:
        vals = [e[key] for e in evals if e.get(key) is not None]
        if vals:
            metrics.append((key, label, _stat(vals, scale, fmt), len(vals)))
    walls = [float(c["wall_s"]) for c in cards if c.get("wall_s") is not None]
    steps = [int(c["steps"]) for c in cards if c.get("steps") is not None]

    front = {
        "library_name": "stable-baselines3",
        "tags": [env_id, "graspgait_env", "reinforcement-learning", "stable-baselines3",
                 *(["sb3-contrib", "maskable-ppo"] if algo == "maskable_ppo" else [])],
        "model-index": [{
            "name": f"{algo} {recipe}",
            "results": [{
                "task": {"type": "reinforcement-learning", "name": "reinforcement-learning"},
                "dataset": {"name": env_id, "type": env_id},
                "metrics": [{"type": key, "name": label, "value": value, "verified": False}
                            for key, label, value, _ in metrics],
            }],
        }],
    }
    if benchmarks:  # the recipe's own row's tasks, each metric mean +/- std over its seeds
        own, _ = _own_row(benchmarks)
        for st in task_stats(own):
            if not st["runs"]:
                continue
            k = st["runs"]
            front["model-index"][0]["results"].append({
                "task": {"type": "reinforcement-learning", "name": "reinforcement-learning"},
                "dataset": {"name": f"graspgait benchmark v{own.get('suite_version')} "
                                    f"{st['task']}", "type": st["task"]},
                "metrics": [{"type": key, "name": f"{label}, {k} seeds",
                             "value": _pm(st[key], scale, fmt), "verified": False}
                            for key, label, scale, fmt in _TASK_METRICS]})
    seed_text = ",".join(str(s) for s in seeds if s is not None)
    plural = "s" if n != 1 else ""
    lines = ["---", yaml.safe_dump(front, sort_keys=False).rstrip(), "---", "",
             f"# {title or f'`{recipe}`: {algo} on {env_id}'}", "",
             f"{algo} ({'sb3-contrib' if algo == 'maskable_ppo' else 'stable-baselines3'}) "
             f"trained on `{env_id}` with the recipe `{recipe}`; {n} "
             f"run{plural} (seed{plural} {seed_text or 'unknown'}). Written by "
             "`graspgait card` from the runs' own cards.", "",
             "## Environment", "",
             f"- env id: `{env_id}`",
             f"- env keywords: `{json.dumps(first.get('env_kwargs') or {}, sort_keys=True)}`",
             f"- wrappers: `{json.dumps(first.get('wrappers') or [])}`", "",
             f"## Metrics (mean +/- std over {n} run{'s' if n != 1 else ''})", "",
             "Each run's last periodic evaluation during training "
             f"({evals[0].get('n_episodes', '?')} episodes; greedy actions).", "",
             "| metric | value | runs |", "|---|---|---:|"]
    lines += [f"| {label} | {value} | {k} |" for _, label, value, k in metrics]
    if walls:
        lines.append(f"| training wall time (s) | {_stat(walls, 1.0, '.0f')} | {len(walls)} |")
    if steps:
        lines.append(f"| PPO steps | {_stat(steps, 1.0, '.0f')} | {len(steps)} |")
    for key, label in (("labels", "imitation labels"), ("env_steps", "imitation env steps")):
        vals = [int(c["imitation"][key]) for c in cards
                if isinstance(c.get("imitation"), Mapping) and key in c["imitation"]]
        if vals:
            lines.append(f"| {label} | {_stat(vals, 1.0, '.0f')} | {len(vals)} |")
    lines += ["", "| run | seed | PPO steps | wall time (s) | success (%) | regrasps / optimum |",
              "|---|---:|---:|---:|---:|---:|"]
    for card, name in zip(cards, names, strict=True):
        ev = card["eval"]
        wall = card.get("wall_s")
        lines.append(f"| `{name}` | {card.get('seed', '')} | {card.get('steps', '')} | "
                     f"{'' if wall is None else f'{float(wall):.0f}'} | "
                     f"{100.0 * ev['success_rate_solvable']:.1f} | "
                     f"{ev['regrasps_vs_optimal']:.3f} |")
    if evaluations:
        lines += evaluation_section(evaluations)
    hyper = {k: cfg[k] for k in ("policy", "policy_kwargs", "net_arch", "features_extractor",
                                 "features_extractor_kwargs", "imitation", "n_envs",
                                 "n_steps", "batch_size", "n_epochs", "learning_rate",
                                 "gamma", "gae_lambda", "clip_range", "ent_coef",
                                 "total_timesteps", "torch_threads") if k in cfg}
    lines += ["", "## Training", "", "```yaml", yaml.safe_dump(hyper, sort_keys=False).rstrip(),
              "```", "", "## Reproduce", "", "```bash"]
    seeds_arg = seed_text if n > 1 else (seed_text or "0")
    lines.append(f"graspgait train {shlex.quote(recipe)} --seeds {seeds_arg}"
                 + (" --ray" if n > 1 else ""))
    lines.append(command or "graspgait card RUN_ROOT/*/model.zip --out README.md")
    lines += ["```"]
    if benchmarks:
        lines += benchmark_section(benchmarks, benchmark_names, against)
    lines += ["", "## Use", "", "```bash",
              f"graspgait evaluate {shlex.quote(names[0])} --episodes 100", "```", "",
              "```python", "from graspgait_env.agents.card import load_agent",
              "", f"model, card = load_agent({names[0]!r})", "```", "",
              "## Versions", ""]
    lines += [f"- {k}: {v}" for k, v in (first.get("versions") or {}).items()]
    return "\n".join(lines) + "\n"


def _num(x: Any, spec: str) -> str:
    return "-" if x is None else format(x, spec)


def _rule_starts(res: Mapping[str, Any]) -> str:
    # how many of the starts with a gait the rule-based mean is over, where not all
    share, n = res.get("rule_success_rate_solvable"), int(res.get("solvable_episodes") or 0)
    if share is None or res.get("mean_rule_regrasps") is None or round(share * n) == n:
        return ""
    k = round(share * n)
    return f" ({k} start{'s' if k != 1 else ''})"


def evaluation_section(results: Sequence[Mapping[str, Any]]) -> list[str]:
    """The card's ``## Measured results`` lines: one table row per ``graspgait evaluate
    --json`` result (the env, object, mu and contact model; the success over all episodes
    and over the starts with a gait; the agent's, the optimum's and the rule-based gait's
    mean regrasps over the agent's successes, with the ratios), then the commands.

    Raises
    ------
    GraspGaitInputError
        A result without the summary of :func:`graspgait_env.agents.evaluate.evaluate`
        or without the command line that ``graspgait evaluate`` records.
    """
    need = ("env_id", "n_episodes", "success_rate", "success_rate_solvable",
            "solvable_episodes", "mean_regrasps", "regrasps_vs_optimal", "command")
    for i, res in enumerate(results):
        missing = [k for k in need if k not in res]
        if missing:
            raise GraspGaitInputError(
                f"--evaluation {i + 1}: no {', '.join(missing)} in it; give the JSON that "
                "`graspgait evaluate MODEL ... --json FILE` writes")
    lines = ["", "## Measured results", "",
             "| evaluation | episodes | success (all) | success (starts with a gait) | "
             "regrasps | optimum's | x optimum | rule-based's | x rule-based |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for res in results:
        mu = res.get("mu")
        where = (f"{res['env_id']}, {res.get('object') or 'an object per episode'}, mu "
                 f"{'per episode' if mu is None else format(mu, 'g')}, contact "
                 f"{res.get('contact_model') or 'per object'}")
        lines.append(
            f"| {where} | {res['n_episodes']} | {_num(res['success_rate'], '.1%')} | "
            f"{_num(res['success_rate_solvable'], '.1%')} ({res['solvable_episodes']}) | "
            f"{_num(res['mean_regrasps'], '.2f')} | "
            f"{_num(res.get('mean_optimal_regrasps'), '.2f')} | "
            f"{_num(res['regrasps_vs_optimal'], '.3f')} | "
            f"{_num(res.get('mean_rule_regrasps'), '.2f')}{_rule_starts(res)} | "
            f"{_num(res.get('regrasps_vs_rule'), '.3f')} |")
    lines += ["", "Regrasps: means over the agent's successful episodes; the optimum's (the "
              "exact planner) and the rule-based gait's (thesis 6.5) from the same starts, "
              "the rule-based mean over the episodes where it also found a gait. Each row "
              "is `graspgait evaluate` of this card's model, written with `--json` and "
              "read back by `graspgait card --evaluation`:", "", "```bash"]
    lines += [str(res["command"]) for res in results]
    lines += ["```"]
    for res in results:
        a = res.get("audit")
        if a:
            lines += ["", f"Where the regrasps beyond the optimum go (`{res['command']}`): "
                      f"{a['excess_regrasps']} over {a['episodes']} successful episodes = "
                      f"{a['idle_regrasps']} idle regrasps (the goal no closer) + "
                      f"{a['excess_of_losing_regrasps']} from {a['losing_regrasps']} losing "
                      f"regrasps + {a['excess_of_losing_rotations']} from "
                      f"{a['losing_rotations']} losing rotations{beyond_lookahead_clause(a)}."]
    return lines


_SHIPPED_KINDS = ("agent",)  # a benchmark row of the one shipped run
_RETRAINED_KINDS = ("agent-template", "config")  # rows of the recipe trained once per seed


def _ci(block: Mapping[str, Any], key: str) -> str:
    lo, hi = block[f"{key}_ci"]
    return f"{100.0 * block[key]:.1f} [{100.0 * lo:.1f}, {100.0 * hi:.1f}]"


def task_stats(result: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Per task of a ``graspgait benchmark`` row, mean and std over its seeds (``ddof =
    0``) of the success over the starts with a gait, of the regrasps over the optimum's
    on the successes (``1 / efficiency``) and of the score, read from the row's
    ``cells``.

    Returns
    -------
    list of dict
        One per task, in the row's order: ``task``, ``runs`` (seeds with a start with a
        gait), and ``success``, ``ratio``, ``score``, each ``(mean, std)`` or None (no
        seed with a figure). A seed without a success has no ratio and scores 0.
    """
    out = []
    for task in result.get("tasks") or []:
        cells = [c["summary"] for c in result.get("cells") or []
                 if c.get("task") == task and (c.get("summary") or {}).get("success")
                 is not None]
        ratios = [1.0 / c["efficiency"] for c in cells if c.get("efficiency")]
        out.append({"task": task, "runs": len(cells),
                    **{k: metric_stats(v) if v else None for k, v in (
                        ("success", [c["success"] for c in cells]),
                        ("ratio", ratios),
                        ("score", [c["score"] for c in cells]))}})
    return out


def _points(diff: float) -> str:
    """A difference of two scores in [0, 1] as signed percentage points, one decimal
    (``+0.0`` for a difference that rounds to zero, never ``-0.0``)."""
    v = 100.0 * float(diff)
    return f"{0.0 if abs(v) < 0.05 else v:+.1f} points"


def compare_rows(ours: Mapping[str, Any], other: Mapping[str, Any]) -> tuple[str, float]:
    """How the suite IQM of row ``ours`` stands against row ``other``'s 95% interval:
    ``("better", d)`` above its upper end, ``("worse", d)`` below its lower end, else
    ``("not measurably different", d)``; ``d`` is the difference of the IQMs (ours minus
    other's, as fractions)."""
    a = float(ours["aggregate"]["overall"]["iqm"])
    b = other["aggregate"]["overall"]
    lo, hi = (float(x) for x in b["iqm_ci"])
    verdict = "better" if a > hi else "worse" if a < lo else "not measurably different"
    return verdict, a - float(b["iqm"])


#: (key of :func:`task_stats`, name in the card, scale, format) of each per-task metric.
_TASK_METRICS = (("success", "success over starts with a gait (%)", 100.0, ".1f"),
                 ("ratio", "regrasps / optimum", 1.0, ".3f"),
                 ("score", "benchmark score (%)", 100.0, ".1f"))


def _own_row(results: Sequence[Mapping[str, Any]]) -> tuple[Mapping[str, Any], str]:
    """The row that stands for the recipe among its benchmark rows, and how the card
    names it: the retrained one, else the shipped run, else the first."""
    kind = [str((r.get("spec") or {}).get("kind", "")) for r in results]
    for kinds, which in ((_RETRAINED_KINDS, "retrained over the seeds"),
                         (_SHIPPED_KINDS, "the shipped run")):
        for r, k in zip(results, kind, strict=True):
            if k in kinds:
                return r, which
    return results[0], f"`{results[0].get('policy')}`"


def _pm(stat: tuple[float, float] | None, scale: float, fmt: str) -> str:
    return "-" if stat is None else f"{stat[0] * scale:{fmt}} +/- {stat[1] * scale:{fmt}}"


def benchmark_section(results: Sequence[Mapping[str, Any]],
                      names: Sequence[str] | None = None,
                      against: Sequence[tuple[str, Mapping[str, Any]]] = ()) -> list[str]:
    """The card's ``## Benchmark`` lines from ``graspgait benchmark`` rows (module
    docstring).

    Parameters
    ----------
    results
        Each row's ``result.json`` (keys ``policy``, ``spec``, ``suite_version``,
        ``tasks``, ``seeds``, ``command``, ``date``, ``run_wall_s``, ``aggregate`` with
        ``overall`` and ``tracks``, and ``cells`` for the per-task figures).
    names
        How each row is named in errors (its folder, usually).
    against
        ``(name, result.json)`` of other recipes' rows on the same tasks and seeds: the
        section says how this recipe compares with each (:func:`compare_rows`).

    Raises
    ------
    GraspGaitInputError
        A row without a suite aggregate, or rows of different suite versions, tasks or
        seeds.
    """
    names = list(names) if names is not None else [f"row {i + 1}" for i in range(len(results))]
    rows = [*((f"--benchmark {n}", r) for n, r in zip(names, results, strict=True)),
            *((f"--against {n}", r) for n, r in against)]
    for flag, res in rows:
        if not isinstance(res.get("aggregate"), Mapping) or "overall" not in res["aggregate"]:
            raise GraspGaitInputError(
                f"{flag}: no suite aggregate in its result.json; give the folder "
                "of a finished `graspgait benchmark` row (its --out)")
    first = results[0]
    for flag, res in rows[1:]:
        for key in ("suite_version", "tasks", "seeds"):
            if res.get(key) != first.get(key):
                raise GraspGaitInputError(
                    f"{flag}: its {key} {res.get(key)!r} differs from "
                    f"{names[0]}'s {first.get(key)!r}; rows compared in a card share the "
                    "suite, the tasks and the seeds")
    every = [r for _, r in rows]
    tracks = list(dict.fromkeys(t for r in every for t in r["aggregate"].get("tracks", {})))
    seeds = ",".join(str(s) for s in first.get("seeds") or [])
    kind = [str((r.get("spec") or {}).get("kind", "")) for r in results]
    labels = [f"`{r.get('policy')}`" + (" (the shipped run)" if k in _SHIPPED_KINDS else
                                        " (retrained per seed)" if k in _RETRAINED_KINDS else "")
              for r, k in zip(results, kind, strict=True)]
    labels += [f"`{n}` (against)" for n, _ in against]
    lines = ["", f"## Benchmark (suite v{first.get('suite_version')}, seeds {seeds})", "",
             "Score in percent (success x efficiency) over the benchmark's test starts; "
             "IQM and mean over the (run, task) scores with 95% stratified bootstrap "
             "intervals (`graspgait benchmark`, docs/benchmark.md).", "",
             "| row | tasks | IQM [95% CI] | mean [95% CI] | "
             + " | ".join(f"{t} IQM" for t in tracks) + " | wall time (s) | date | command |",
             "|---|---:|---|---|" + "---|" * len(tracks) + "---:|---|---|"]
    for res, label in zip(every, labels, strict=True):
        agg = res["aggregate"]
        per = [_ci(agg["tracks"][t], "iqm") if t in agg.get("tracks", {}) else "-"
               for t in tracks]
        wall = res.get("run_wall_s")
        lines.append(f"| {label} | {agg['overall'].get('tasks')} | "
                     f"{_ci(agg['overall'], 'iqm')} | {_ci(agg['overall'], 'mean')} | "
                     + " | ".join(per) + f" | {'' if wall is None else f'{float(wall):.0f}'}"
                     f" | {res.get('date', '')} | `{res.get('command', '')}` |")
    shipped = [r for r, k in zip(results, kind, strict=True) if k in _SHIPPED_KINDS]
    retrained = [r for r, k in zip(results, kind, strict=True) if k in _RETRAINED_KINDS]
    if len(shipped) == 1 and len(retrained) == 1:
        a = shipped[0]["aggregate"]["overall"]["iqm"]
        b = retrained[0]["aggregate"]["overall"]["iqm"]
        verdict = ("**worse** than its shipped run" if b < a else
                   "as good as its shipped run or better")
        lines += ["", f"Retrained over the seeds, the recipe is {verdict}: IQM "
                  f"{100.0 * b:.1f} against {100.0 * a:.1f} "
                  f"({_points(b - a)})."]
    ours, which = _own_row(results)
    for name, other in against:
        verdict, diff = compare_rows(ours, other)
        lo, hi = other["aggregate"]["overall"]["iqm_ci"]
        how = {"better": f"above the upper end of its 95% interval [{100.0 * lo:.1f}, "
                         f"{100.0 * hi:.1f}]",
               "worse": f"below the lower end of its 95% interval [{100.0 * lo:.1f}, "
                        f"{100.0 * hi:.1f}]"}.get(
            verdict, f"within its 95% interval [{100.0 * lo:.1f}, {100.0 * hi:.1f}]")
        lines += ["", f"Against `{name}` on the same tasks and seeds, this recipe "
                  f"({which}) is **{verdict}**: IQM "
                  f"{100.0 * ours['aggregate']['overall']['iqm']:.1f} against "
                  f"{100.0 * other['aggregate']['overall']['iqm']:.1f} "
                  f"({_points(diff)}), {how}."]
    per_task = [(label, {x["task"]: x for x in task_stats(r)})
                for label, r in zip(labels, every, strict=True) if r.get("cells")]
    if per_task:
        lines += ["", "Per task, mean +/- std over the seeds (success over the starts with a "
                  "gait; regrasps over the optimum's on the successes; score):", "",
                  "| task | row | seeds | success (%) | regrasps / optimum | score (%) |",
                  "|---|---|---:|---|---|---|"]
        for task in first.get("tasks") or []:
            for label, stats in per_task:
                st = stats.get(task)
                if st is None or not st["runs"]:
                    continue
                lines.append(f"| {task} | {label} | {st['runs']} | "
                             f"{_pm(st['success'], 100.0, '.1f')} | "
                             f"{_pm(st['ratio'], 1.0, '.3f')} | "
                             f"{_pm(st['score'], 100.0, '.1f')} |")
    return lines


def write_hub_card(models: Sequence[str | os.PathLike[str]],
                   out: str | os.PathLike[str] | None = None,
                   title: str | None = None,
                   benchmarks: Sequence[str | os.PathLike[str]] = (),
                   against: Sequence[str] = (),
                   evaluations: Sequence[str | os.PathLike[str]] = (),
                   command: str | None = None) -> str:
    """:func:`hub_card` of the saved models ``models`` (zips with their JSON cards), with
    the ``graspgait benchmark`` row folders ``benchmarks`` (each with its
    ``result.json``) and the other recipes' row folders ``against``, each ``NAME=DIR`` or
    ``DIR`` (named by its folder), and the ``graspgait evaluate --json`` files
    ``evaluations`` (of these models; another model's is refused); written atomically to
    ``out`` when given; ``command`` is the card's own command line. Returns the card."""
    from graspgait_env.agents.card import read_card, resolve_model
    from graspgait_env.atomic import write_text_atomic

    paths = [resolve_model(m) for m in models]
    def row(flag: str, d: str | os.PathLike[str]) -> dict[str, Any]:
        path = Path(d) / "result.json"
        if not path.is_file():
            raise GraspGaitInputError(
                f"{flag} {d}: no result.json there; give the folder of a finished "
                "`graspgait benchmark` row (its --out)")
        return json.loads(path.read_text(encoding="utf-8"))

    rows = [row("--benchmark", d) for d in benchmarks]
    others = []
    for item in against:
        name, sep, folder = str(item).partition("=")
        if not sep:
            name, folder = Path(item).name, str(item)
        if not name or not folder:
            raise GraspGaitInputError(
                f"--against {item!r}: give NAME=DIR or DIR, e.g. --against "
                "general=bench/general-circle")
        others.append((name, row("--against", folder)))
    evals = []
    for f in evaluations:
        path = Path(f)
        if not path.is_file():
            raise GraspGaitInputError(
                f"--evaluation {f}: no such file; give the JSON that `graspgait evaluate "
                "MODEL ... --json FILE` writes")
        res = json.loads(path.read_text(encoding="utf-8"))
        model = (res.get("model") or {}).get("path")
        if model is None or resolve_model(model) not in paths:
            raise GraspGaitInputError(
                f"--evaluation {f}: an evaluation of {model!r}, not of this card's models "
                f"({', '.join(str(m) for m in models)}); evaluate one of them")
        evals.append(res)
    text = hub_card([read_card(p) for p in paths], names=[str(m) for m in models],
                    title=title, benchmarks=rows, benchmark_names=[str(d) for d in benchmarks],
                    against=others, evaluations=evals, command=command)
    if out is not None:
        write_text_atomic(Path(out), text)
    return text
