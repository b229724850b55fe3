"""The shipped agents in ``graspgait bench``: the same starts as the planners, one row per run.

Protocol (the bench's, :mod:`graspgait_env.baselines.bench`): for each object and ``mu``, the 10
starts of :func:`graspgait_env.baselines.bench.bench_starts` (legal grasps at θ = 0 from which the
exact planner finds a 360° gait). Each agent is reset at each of those starts
(``reset(options={"start": ...})``) in ``GraspGait-v0`` with the env settings it was
trained with (its card), the object and ``mu`` of the cell, and plays greedily
(``deterministic=True``) until the episode ends. Each run is a
:class:`graspgait_env.baselines.bench.BenchCase` with ``planner = "agent:NAME"``, so the bench's
CSV, JSON and Table 1 carry the agents beside the planners; ``nodes_opened`` is 0 (an
agent searches nothing) and ``path_length`` counts the moves made.

Contact models: the planners' columns use the thesis's point contacts. An agent trained
with another contact model (the hand's, ``contact_model: hand`` in its card) cannot be
run from those starts (under the hand's maps some are not force-closure, at mu 0.8
more), and its regrasps are not comparable with point-contact gaits. Such an agent runs
from starts picked the bench's way (:func:`graspgait_env.baselines.bench.bench_starts`) on its own
env's gait model, and its case carries the optimum's and the rule-based gait's regrasps
from the same start under the same contact model (``contact_model``,
``optimal_regrasps``, ``rule_regrasps``; :class:`graspgait_env.agents.evaluate.ReferenceGaits`); the
ratios of :func:`agent_rows` use those.

Which agent runs where: an agent trained on ``GraspGaitRandom-v0`` (a generalist, e.g.
``general.zip``) runs on every object; an agent trained on one object runs on that
object only (at every ``mu`` of the bench).

:func:`agents_markdown` adds the comparison table: per object and ``mu``, each agent's
success rate, regrasps per 360°, path length and wall time, and its regrasps as a ratio
to the optimum's and the rule-based gait's from the same starts (over the starts where
both succeeded). :func:`plot_bench` draws regrasps per 360° of every method.
"""

from __future__ import annotations

import math
import os
import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tqdm.auto import tqdm

from graspgait_env.agents.card import (
    load_agent,
    resolve_model,
    shipped_agents,
    shipped_models_dir,
)
from graspgait_env.agents.envs import env_kwargs_for, make_env
from graspgait_env.agents.evaluate import agent_predictor, play_episode
from graspgait_env.atomic import atomic_write
from graspgait_env.baselines.bench import THESIS_OBJECTS, BenchCase, bench_starts
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel

__all__ = ["SHIPPED_AGENTS", "Agent", "agents_markdown", "find_agents", "plot_bench",
           "run_agent_bench", "shipped_models_dir"]

SHIPPED_AGENTS = ("general", "circle")
"""The agents the project ships (``models/NAME.zip`` of :mod:`graspgait_env.agents`, with
their cards); a test fails when one is missing from the install. The ellipse's, the
pentagon's, the hexagon's and ``random`` are retired
(:data:`graspgait_env.agents.card.RETIRED_AGENTS`)."""


@dataclass
class Agent:
    """A saved agent the bench runs: its label, model, card and where it runs."""

    name: str
    path: Path
    model: Any
    card: dict[str, Any]

    @property
    def generalist(self) -> bool:
        """Trained on ``GraspGaitRandom-v0`` (runs on every object)."""
        return self.card.get("env_id") == "GraspGaitRandom-v0"

    def runs_on(self, obj: str) -> bool:
        """Whether the bench runs this agent on object ``obj`` (see the module docstring)."""
        trained = (self.card.get("env_kwargs") or {}).get("object")
        return self.generalist or trained is None or str(trained) == obj


def find_agents(spec: str = "shipped") -> tuple[list[Agent], list[str]]:
    """The agents named by ``spec``, loaded, and notes for the report.

    Parameters
    ----------
    spec
        ``"shipped"``: every shipped agent of this install
        (:func:`~graspgait_env.agents.card.shipped_agents`); ``"none"``: no agent;
        otherwise a comma-separated list of shipped names or ``.zip`` paths.

    Returns
    -------
    agents, notes

    Raises
    ------
    GraspGaitInputError
        An empty list, or a name that is neither a file nor a shipped agent (the message
        lists the shipped agents).
    """
    if spec == "none":
        return [], []
    names = shipped_agents() if spec == "shipped" else [s.strip() for s in spec.split(",")
                                                         if s.strip()]
    if not names:
        raise GraspGaitInputError(f"--agents {spec!r}: give 'shipped', 'none' or a "
                                  "comma-separated list of shipped names or .zip paths")
    agents = []
    for item in names:
        try:
            path = resolve_model(item)
        except GraspGaitInputError as exc:
            raise GraspGaitInputError(f"--agents: {exc}") from None
        model, card = load_agent(path)
        agents.append(Agent(path.stem, path, model, card))
    return agents, []


def run_agent_bench(agents: Sequence[Agent], objects: Sequence[str] = THESIS_OBJECTS,
                    mus: Sequence[float] = (0.8, 0.7), starts: int = 10,
                    turn_deg: float = 360.0, progress: bool = True) -> list[BenchCase]:
    """Run each agent from the bench's starts on each object and ``mu``; one row per run."""
    from graspgait_env.agents.evaluate import ReferenceGaits

    jobs = []
    envs: dict[tuple[str, str, float], Any] = {}
    for obj in objects:
        for mu in mus:
            model = GaitModel(obj, mu)
            picked = bench_starts(model, starts)
            for agent in agents:
                if not agent.runs_on(obj):
                    continue
                kw = env_kwargs_for("GraspGait-v0", agent.card.get("env_id") or "GraspGait-v0",
                                    agent.card.get("env_kwargs") or {}, obj, mu,
                                    contact_model=agent.card.get("contact_model"))
                kw["turn_deg"] = turn_deg
                env = envs[(agent.name, obj, mu)] = make_env(
                    "GraspGait-v0", kw, agent.card.get("wrappers") or ())
                own = env.unwrapped.config.contact_model
                if own == "point":  # the planners' starts and references
                    jobs.extend((obj, mu, agent, s, model, None) for s in picked)
                else:  # starts and references under the agent's own contact model
                    env.reset(seed=0)
                    own_model = env.unwrapped.model
                    jobs.extend((obj, mu, agent, s, own_model, own)
                                for s in bench_starts(own_model, starts))
    refs = ReferenceGaits()
    cases: list[BenchCase] = []
    for obj, mu, agent, s, model, own in tqdm(jobs, desc="bench agents", disable=not progress,
                                              unit="run"):
        env = envs[(agent.name, obj, mu)]
        predict = agent_predictor(agent.model, deterministic=True)
        start = {f + 1: model.contact_deg(s.contacts[f]) for f in s.held()}
        ep = play_episode(predict, env, seed=0, options={"start": start})
        label = ",".join(f"{f}:{phi:g}" for f, phi in start.items())
        opt, rule = refs.regrasps(model, s, turn_deg) if own is not None else (None, None)
        cases.append(BenchCase(obj, mu, label, f"agent:{agent.name}", ep["success"], 0,
                               ep["path_length"], ep["regrasps"], ep["turn_deg"], ep["wall_s"],
                               "", contact_model=own, optimal_regrasps=opt,
                               rule_regrasps=rule))
    for env in envs.values():
        env.close()
    return cases


def _mean(xs: list[float]) -> float:
    return statistics.fmean(xs) if xs else math.nan


def _per360(c: BenchCase) -> float:
    """Regrasps per 360° of turn achieved (the bench's turn is 360°: the regrasps)."""
    return c.regrasps * 360.0 / abs(c.rotation_deg) if c.rotation_deg else math.nan


def agent_rows(cases: Sequence[BenchCase]) -> list[dict[str, Any]]:
    """Per object, ``mu`` and agent: success rate, regrasps per 360°, path length, wall
    time (ms) and the regrasp ratios to the optimum and the rule-based gait.

    Means are over the agent's successful runs; a ratio is the agent's mean regrasps over
    the starts where it and the reference both succeeded, divided by the reference's mean
    over the same starts.
    """
    by_key = {(c.object, c.mu, c.start, c.planner): c for c in cases}
    rows = []
    keys = sorted({(c.object, c.mu, c.planner) for c in cases if c.planner.startswith("agent:")},
                  key=lambda k: (THESIS_OBJECTS.index(k[0]) if k[0] in THESIS_OBJECTS else 99,
                                 k[0], -k[1], k[2]))
    for obj, mu, name in keys:
        runs = [c for c in cases if (c.object, c.mu, c.planner) == (obj, mu, name)]
        ok = [c for c in runs if c.success]
        row = {"object": obj, "mu": mu, "agent": name.removeprefix("agent:"),
               "runs": len(runs), "success": len(ok) / len(runs),
               "regrasps_per_360": _mean([_per360(c) for c in ok]),
               "path_length": _mean([c.path_length for c in ok]),
               "wall_ms": 1e3 * _mean([c.wall_time_s for c in runs])}
        row["contact_model"] = runs[0].contact_model or "point"
        for ref, col in (("optimal", "vs_optimal"), ("rule", "vs_rule")):
            if runs[0].contact_model is None:  # the point-contact planners' runs
                pairs = [(c, by_key.get((obj, mu, c.start, ref))) for c in ok]
                pairs = [(c.regrasps, r.regrasps) for c, r in pairs
                         if r is not None and r.success]
            else:  # the references under the agent's contact model, from its case
                pairs = [(c.regrasps, getattr(c, f"{ref}_regrasps")) for c in ok]
                pairs = [(a, b) for a, b in pairs if b is not None]
            mine, theirs = _mean([a for a, _ in pairs]), _mean([b for _, b in pairs])
            row[col] = mine / theirs if pairs and theirs else math.nan
        rows.append(row)
    return rows


def _f(x: float, spec: str = ".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def agents_markdown(cases: Sequence[BenchCase], notes: Sequence[str] = ()) -> str:
    """The agents' table (see :func:`agent_rows`) in Markdown, with the skip notes."""
    lines = ["### Learned agents beside the optimum and the rule-based gait (same starts)", ""]
    rows = agent_rows(cases)
    if rows:
        lines += ["| object | mu | agent | contacts | success | regrasps per 360° | x optimum "
                  "| x rule-based | path length | wall time (ms) |",
                  "|---|---|---|---|---:|---:|---:|---:|---:|---:|"]
        for r in rows:
            lines.append(f"| {r['object']} | {r['mu']:g} | {r['agent']} | "
                         f"{r['contact_model']} | {r['success']:.0%} | "
                         f"{_f(r['regrasps_per_360'])} | {_f(r['vs_optimal'], '.2f')} | "
                         f"{_f(r['vs_rule'], '.2f')} | {_f(r['path_length'])} | "
                         f"{_f(r['wall_ms'])} |")
    else:
        lines.append("No agent ran.")
    lines += [f"- {n}" for n in notes]
    return "\n".join(lines)


def _contacts_note(cases: Sequence[BenchCase], method: str) -> str:
    """``", hand contacts"`` for an agent run under a contact model other than the
    planners' point contacts (its bars come from its own starts and maps)."""
    own = {c.contact_model for c in cases if c.planner == method} - {None, "point"}
    return f", {'/'.join(sorted(own))} contacts" if own else ""


def plot_bench(cases: Sequence[BenchCase], path: str | os.PathLike[str]) -> Path:
    """Bar chart of regrasps per 360° (successful runs) per object, ``mu`` and method.

    One panel per ``mu``; each method (planner or agent) a bar per object, labelled with
    its success rate. An agent run under the hand's contact model is labelled so: its
    bars come from starts and grasp maps of that model, not the planners' point
    contacts (compare it through the table's ratios). Written atomically (PNG, SVG or
    PDF by the suffix).
    """
    from matplotlib.figure import Figure

    mus = sorted({c.mu for c in cases}, reverse=True)
    objs = [o for o in THESIS_OBJECTS if any(c.object == o for c in cases)] + sorted(
        {c.object for c in cases} - set(THESIS_OBJECTS))
    methods = sorted({c.planner for c in cases}, key=lambda p: (p.startswith("agent:"), p))
    fig = Figure(figsize=(4.0 + 2.2 * len(objs), 3.6 * len(mus)), layout="constrained")
    axes = fig.subplots(len(mus), 1, squeeze=False)[:, 0]
    width = 0.8 / max(1, len(methods))
    for ax, mu in zip(axes, mus, strict=True):
        for j, m in enumerate(methods):
            xs, ys, labels = [], [], []
            for i, o in enumerate(objs):
                runs = [c for c in cases if (c.object, c.mu, c.planner) == (o, mu, m)]
                if not runs:
                    continue
                ok = [c for c in runs if c.success]
                xs.append(i + (j - (len(methods) - 1) / 2) * width)
                ys.append(_mean([_per360(c) for c in ok]) if ok else 0.0)
                labels.append(f"{len(ok) / len(runs):.0%}")
            bars = ax.bar(xs, ys, width, label=m.removeprefix("agent:") + (
                f" (agent{_contacts_note(cases, m)})" if m.startswith("agent:") else ""))
            ax.bar_label(bars, labels=labels, fontsize=6, rotation=90, padding=2)
        ax.set_xticks(range(len(objs)), objs)
        ax.set_ylabel("regrasps per 360° (successful runs)")
        ax.set_title(f"mu = {mu:g}; bar labels: success rate over the same starts")
        ax.margins(y=0.2)
    axes[0].legend(fontsize=7, ncols=min(4, len(methods)), loc="upper left")
    suffix = Path(path).suffix.lstrip(".") or "png"
    return atomic_write(path, lambda fh: fig.savefig(fh, format=suffix, dpi=110))
