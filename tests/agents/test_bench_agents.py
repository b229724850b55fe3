"""The agents in ``graspgait bench``: same starts as the planners, ratios to the optimum."""

from __future__ import annotations

import math

import pytest

from graspgait_env.agents.bench import (
    SHIPPED_AGENTS,
    agent_rows,
    agents_markdown,
    find_agents,
    plot_bench,
    run_agent_bench,
)
from graspgait_env.baselines.bench import BenchCase, bench_starts
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
    assert "| ellipse | 0.7 | x | point | 67% | 10.0 | 1.11 | 0.86 |" in md
    assert md.endswith("- agent y: not there yet; skipped")


def test_find_agents(smoke_run):
    assert find_agents("none") == ([], [])
    agents, notes = find_agents("shipped")  # every shipped agent, none missing
    assert sorted(a.name for a in agents) == sorted(SHIPPED_AGENTS) and not notes
    (agent,), notes = find_agents(str(smoke_run.model_path))
    assert agent.name == "model" and not notes
    assert agent.runs_on("ellipse") and not agent.runs_on("pentagon")
    with pytest.raises(GraspGaitInputError, match=r"--agents: MODEL 'nope': no such file "
                       r"and no shipped agent.*circle, general"):
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


def test_an_agent_with_its_own_contact_model_is_compared_under_it():
    """A hand-contact agent's ratios use the references its cases carry, not the
    point-contact planners' runs from a start of the same name."""
    own = [BenchCase("ellipse", 0.7, "a", "agent:h", True, 0, 20, 11, 360.0, 0.01, "",
                     contact_model="hand", optimal_regrasps=10, rule_regrasps=11),
           BenchCase("ellipse", 0.7, "b", "agent:h", True, 0, 20, 12, 360.0, 0.01, "",
                     contact_model="hand", optimal_regrasps=10, rule_regrasps=16)]
    point_refs = [_case("optimal", "a", True, 5), _case("rule", "a", True, 5)]
    (row,) = agent_rows(own + point_refs)
    assert row["contact_model"] == "hand"
    assert row["vs_optimal"] == pytest.approx(23 / 20)
    assert row["vs_rule"] == pytest.approx(23 / 27)
    assert "| hand |" in agents_markdown(own + point_refs)


def test_hand_agent_runs_from_starts_legal_under_its_contact_model():
    """At mu 0.8 some point-contact bench starts are not force-closure for the hand; the
    shipped general agent (hand contacts) runs on the ellipse from its own model's starts,
    with the optimum under the same model, which it never beats."""
    agents, _ = find_agents("general")
    cases = run_agent_bench(agents, ["ellipse"], [0.8], starts=2, progress=False)
    assert len(cases) == 2
    for c in cases:
        assert c.contact_model == "hand" and c.optimal_regrasps is not None
        if c.success:
            assert c.regrasps >= c.optimal_regrasps


def test_a_generalists_random_env_keywords_are_dropped_for_one_object():
    from graspgait_env.agents.envs import env_kwargs_for

    kw = env_kwargs_for("GraspGait-v0", "GraspGaitRandom-v0",
                        {"level": 1, "episodes_per_object": 8, "beta": 0.03}, "ellipse", 0.7)
    assert "episodes_per_object" not in kw and "level" not in kw
    assert (kw["beta"], kw["object"], kw["mu"]) == (0.03, "ellipse", 0.7)


def test_plot_labels_an_agent_with_the_hands_contacts(tmp_path):
    from graspgait_env.agents.bench import _contacts_note

    hand = BenchCase("ellipse", 0.7, "a", "agent:h", True, 0, 20, 11, 360.0, 0.01, "",
                     contact_model="hand", optimal_regrasps=10, rule_regrasps=11)
    cases = [hand, _case("agent:p", "a", True, 9), _case("optimal", "a", True, 8)]
    assert _contacts_note(cases, "agent:h") == ", hand contacts"
    assert _contacts_note(cases, "agent:p") == ""
    assert plot_bench(cases, tmp_path / "b.png").stat().st_size > 0


def test_tables_1_and_6_1_leave_the_agents_to_their_own_table():
    from graspgait_env.baselines.bench import markdown_report

    cases = [_case("optimal", "a", True, 8), _case("rule", "a", True, 9),
             _case("agent:x", "a", True, 12)]
    md = markdown_report(cases)
    header = next(line for line in md.splitlines() if line.startswith("| object | mu | data"))
    assert header.rstrip(" |").endswith("rule | optimal")  # no agent column
    assert "agent:x" not in md
    assert "| ellipse | 0.7 | x | point | 100% |" in agents_markdown(cases)
