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
**worse**, however little (the benchmark's rule, docs/benchmark.md).
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

from graspgait_env.errors import GraspGaitInputError

__all__ = ["METRICS", "benchmark_section", "hub_card", "metric_stats", "write_hub_card"]

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
             benchmark_names: Sequence[str] | None = None) -> str:
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
    seed_text = ",".join(str(s) for s in seeds if s is not None)
    lines = ["---", yaml.safe_dump(front, sort_keys=False).rstrip(), "---", "",
             f"# {title or f'`{recipe}`: {algo} on {env_id}'}", "",
             f"{algo} ({'sb3-contrib' if algo == 'maskable_ppo' else 'stable-baselines3'}) "
             f"trained on `{env_id}` with the recipe `{recipe}`; {n} "
             f"run{'s' if n != 1 else ''} (seeds {seed_text or 'unknown'}). Written by "
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
    lines.append("graspgait card RUN_ROOT/*/model.zip --out README.md")
    lines += ["```"]
    if benchmarks:
        lines += benchmark_section(benchmarks, benchmark_names)
    lines += ["", "## Use", "", "```bash",
              f"graspgait evaluate {shlex.quote(names[0])} --episodes 100", "```", "",
              "```python", "from graspgait_env.agents.card import load_agent",
              "", f"model, card = load_agent({names[0]!r})", "```", "",
              "## Versions", ""]
    lines += [f"- {k}: {v}" for k, v in (first.get("versions") or {}).items()]
    return "\n".join(lines) + "\n"


_SHIPPED_KINDS = ("agent",)  # a benchmark row of the one shipped run
_RETRAINED_KINDS = ("agent-template", "config")  # rows of the recipe trained once per seed


def _ci(block: Mapping[str, Any], key: str) -> str:
    lo, hi = block[f"{key}_ci"]
    return f"{100.0 * block[key]:.1f} [{100.0 * lo:.1f}, {100.0 * hi:.1f}]"


def benchmark_section(results: Sequence[Mapping[str, Any]],
                      names: Sequence[str] | None = None) -> list[str]:
    """The card's ``## Benchmark`` lines from ``graspgait benchmark`` rows (module
    docstring).

    Parameters
    ----------
    results
        Each row's ``result.json`` (keys ``policy``, ``spec``, ``suite_version``,
        ``tasks``, ``seeds``, ``command``, ``date``, ``run_wall_s``, ``aggregate`` with
        ``overall`` and ``tracks``).
    names
        How each row is named in errors (its folder, usually).

    Raises
    ------
    GraspGaitInputError
        A row without a suite aggregate, or rows of different suite versions, tasks or
        seeds.
    """
    names = list(names) if names is not None else [f"row {i + 1}" for i in range(len(results))]
    for res, name in zip(results, names, strict=True):
        if not isinstance(res.get("aggregate"), Mapping) or "overall" not in res["aggregate"]:
            raise GraspGaitInputError(
                f"--benchmark {name}: no suite aggregate in its result.json; give the folder "
                "of a finished `graspgait benchmark` row (its --out)")
    first = results[0]
    for res, name in zip(results[1:], names[1:], strict=True):
        for key in ("suite_version", "tasks", "seeds"):
            if res.get(key) != first.get(key):
                raise GraspGaitInputError(
                    f"--benchmark {name}: its {key} {res.get(key)!r} differs from "
                    f"{names[0]}'s {first.get(key)!r}; rows compared in a card share the "
                    "suite, the tasks and the seeds")
    tracks = list(dict.fromkeys(t for r in results for t in r["aggregate"].get("tracks", {})))
    seeds = ",".join(str(s) for s in first.get("seeds") or [])
    lines = ["", f"## Benchmark (suite v{first.get('suite_version')}, seeds {seeds})", "",
             "Score in percent (success x efficiency) over the benchmark's test starts; "
             "IQM and mean over the (run, task) scores with 95% stratified bootstrap "
             "intervals (`graspgait benchmark`, docs/benchmark.md).", "",
             "| row | tasks | IQM [95% CI] | mean [95% CI] | "
             + " | ".join(f"{t} IQM" for t in tracks) + " | wall time (s) | date | command |",
             "|---|---:|---|---|" + "---|" * len(tracks) + "---:|---|---|"]
    for res in results:
        agg = res["aggregate"]
        per = [_ci(agg["tracks"][t], "iqm") if t in agg.get("tracks", {}) else "-"
               for t in tracks]
        wall = res.get("run_wall_s")
        what = {"agent": " (the shipped run)", "agent-template": " (retrained per seed)",
                "config": " (retrained per seed)"}.get(str((res.get("spec") or {}).get("kind")),
                                                      "")
        lines.append(f"| `{res.get('policy')}`{what} | {agg['overall'].get('tasks')} | "
                     f"{_ci(agg['overall'], 'iqm')} | {_ci(agg['overall'], 'mean')} | "
                     + " | ".join(per) + f" | {'' if wall is None else f'{float(wall):.0f}'}"
                     f" | {res.get('date', '')} | `{res.get('command', '')}` |")
    kind = [str((r.get("spec") or {}).get("kind", "")) for r in results]
    shipped = [r for r, k in zip(results, kind, strict=True) if k in _SHIPPED_KINDS]
    retrained = [r for r, k in zip(results, kind, strict=True) if k in _RETRAINED_KINDS]
    if len(shipped) == 1 and len(retrained) == 1:
        a = shipped[0]["aggregate"]["overall"]["iqm"]
        b = retrained[0]["aggregate"]["overall"]["iqm"]
        verdict = ("**worse** than its shipped run" if b < a else
                   "as good as its shipped run or better")
        lines += ["", f"Retrained over the seeds, the recipe is {verdict}: IQM "
                  f"{100.0 * b:.1f} against {100.0 * a:.1f} "
                  f"({100.0 * (b - a):+.1f} points)."]
    return lines


def write_hub_card(models: Sequence[str | os.PathLike[str]],
                   out: str | os.PathLike[str] | None = None,
                   title: str | None = None,
                   benchmarks: Sequence[str | os.PathLike[str]] = ()) -> str:
    """:func:`hub_card` of the saved models ``models`` (zips with their JSON cards), with
    the ``graspgait benchmark`` row folders ``benchmarks`` (each with its
    ``result.json``); written atomically to ``out`` when given. Returns the card."""
    from graspgait_env.agents.card import read_card, resolve_model
    from graspgait_env.atomic import write_text_atomic

    paths = [resolve_model(m) for m in models]
    rows = []
    for d in benchmarks:
        path = Path(d) / "result.json"
        if not path.is_file():
            raise GraspGaitInputError(
                f"--benchmark {d}: no result.json there; give the folder of a finished "
                "`graspgait benchmark` row (its --out)")
        rows.append(json.loads(path.read_text(encoding="utf-8")))
    text = hub_card([read_card(p) for p in paths], names=[str(m) for m in models],
                    title=title, benchmarks=rows, benchmark_names=[str(d) for d in benchmarks])
    if out is not None:
        write_text_atomic(Path(out), text)
    return text
