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

__all__ = ["METRICS", "hub_card", "metric_stats", "write_hub_card"]

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
             title: str | None = None) -> str:
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
    lines += ["```", "", "## Use", "", "```bash",
              f"graspgait evaluate {shlex.quote(names[0])} --episodes 100", "```", "",
              "```python", "from graspgait_env.agents.card import load_agent",
              "", f"model, card = load_agent({names[0]!r})", "```", "",
              "## Versions", ""]
    lines += [f"- {k}: {v}" for k, v in (first.get("versions") or {}).items()]
    return "\n".join(lines) + "\n"


def write_hub_card(models: Sequence[str | os.PathLike[str]],
                   out: str | os.PathLike[str] | None = None,
                   title: str | None = None) -> str:
    """:func:`hub_card` of the saved models ``models`` (zips with their JSON cards);
    written atomically to ``out`` when given. Returns the card."""
    from graspgait_env.agents.card import read_card, resolve_model
    from graspgait_env.atomic import write_text_atomic

    paths = [resolve_model(m) for m in models]
    text = hub_card([read_card(p) for p in paths], names=[str(m) for m in models],
                    title=title)
    if out is not None:
        write_text_atomic(Path(out), text)
    return text
