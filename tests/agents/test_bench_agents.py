"""The agents in ``graspgait bench``: same starts as the planners, ratios to the optimum."""

from __future__ import annotations

import math

import pytest

from agents.bench import (
    SHIPPED_AGENTS,
    agent_rows,
    agents_markdown,
    find_agents,
    plot_bench,
    run_agent_bench,
)
from baselines.bench import BenchCase, bench_starts
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel


def _case(planner, start, success, regrasps, obj="ellipse", mu=0.7):
    return BenchCase(obj, mu, start, planner, success, math.nan, 2 * regrasps, regrasps,
                     360.0 if success else 100.0, 0.01, "")


def test_ratios_pair_the_same_starts():
    cases = [_case("optimal", "a", True, 10), _case("optimal", "b", True, 8),
             _case("optimal", "c", True, 9),
             _case("rule", "a", True, 14), _case("rule", "b", False, 0),
             _case("rule", "c", True, 12),
             _case("agent:x", "a", True, 12), _case("agent:x", "b", True, 8),
             _case("agent:x", "c", False, 3)]
    (row,) = agent_rows(cases)
    assert (row["agent"], row["runs"]) == ("x", 3)
    assert row["success"] == pytest.approx(2 / 3)
    assert row["regrasps_per_360"] == 10.0  # (12 + 8) / 2, each over a full 360 deg
    assert row["vs_optimal"] == pytest.approx(20 / 18)  # starts a and b
    assert row["vs_rule"] == pytest.approx(12 / 14)  # start a only: rule failed b
    md = agents_markdown(cases, ["agent y: not there yet; skipped"])
    assert "| ellipse | 0.7 | x | 67% | 10.0 | 1.11 | 0.86 |" in md
    assert md.endswith("- agent y: not there yet; skipped")


def test_find_agents(smoke_run):
    assert find_agents("none") == ([], [])
    agents, notes = find_agents("shipped")
    assert sorted([a.name for a in agents] + [n.split()[1].rstrip(":") for n in notes]) == \
        sorted(SHIPPED_AGENTS)
    (agent,), notes = find_agents(str(smoke_run.model_path))
    assert agent.name == "model" and not notes
    assert agent.runs_on("ellipse") and not agent.runs_on("pentagon")
    with pytest.raises(GraspGaitInputError, match=r"--agents 'nope': no such model"):
        find_agents("nope")


def test_agent_runs_from_the_bench_starts_and_plots(smoke_run, tmp_path):
    (agent,), _ = find_agents(str(smoke_run.model_path))
    cases = run_agent_bench([agent], objects=["ellipse", "pentagon"], mus=[0.7], starts=2,
                            progress=False)
    starts = bench_starts(GaitModel("ellipse", 0.7), 2)
    assert len(cases) == 2  # the ellipse agent does not run on the pentagon
    model = GaitModel("ellipse", 0.7)
    for c, s in zip(cases, starts, strict=True):
        assert c.planner == "agent:model" and c.object == "ellipse"
        assert c.start == ",".join(f"{f + 1}:{model.contact_deg(s.contacts[f]):g}"
                                   for f in s.held())
        assert c.nodes_opened == 0 and c.path_length >= c.regrasps
    png = plot_bench(cases + [_case("optimal", cases[0].start, True, 10)], tmp_path / "b.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
