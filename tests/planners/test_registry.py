"""Every planner by name: the registry, the one "no gait" answer, bad starts, the layout.

"No stable grasp at theta = 0" is a no-gait verdict from every planner (a PlannerResult
with ``plan=None``), never an exception; a bad start stays the user's input error.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import graspgait_env.planners as planners_pkg
from graspgait_env.errors import GraspGaitInputError, NoGaitError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.registry import (
    CHOOSE_OWN_START,
    PLANNERS,
    default_start,
    get_planner,
    run_planner,
)
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.starts import NO_START, legal_start_exists, spread_starts
from graspgait_env.workspace import Hand
from tests.planners.helpers import check_plan, model

# fingers whose workspaces never hold two contacts near 180 deg apart (circle, mu 0.1)
ODD_HAND = Hand(((0.0, 10.0), (90.0, 100.0), (245.0, 255.0)), "odd")


@pytest.fixture(scope="module")
def no_start_models() -> dict[str, GaitModel]:
    return {
        # a regular pentagon at mu = 0.3 has no stable grasp at all (empty grasp map)
        "empty map": GaitModel("pentagon", 0.3),
        # stable grasps exist, none inside two fingers' workspaces at theta = 0
        "outside the workspaces": GaitModel("circle", 0.1, hand=ODD_HAND),
    }


def test_the_no_start_models_are_what_they_claim(no_start_models):
    empty, outside = no_start_models["empty map"], no_start_models["outside the workspaces"]
    assert not empty.stable.any() and not empty.start_states()
    assert outside.stable.any() and not outside.start_states()
    assert not legal_start_exists(empty) and not legal_start_exists(outside)


@pytest.mark.parametrize("kind", ["empty map", "outside the workspaces"])
@pytest.mark.parametrize("name", list(PLANNERS))
def test_no_stable_grasp_at_theta_0_is_a_no_gait_verdict(no_start_models, kind, name):
    """Every planner, through run_planner and called directly with start=None: a result
    with no plan and the reason, never AssertionError or GraspGaitInputError."""
    m = no_start_models[kind]
    for how, call in (("run_planner", lambda: run_planner(name, m, None)),
                      ("direct", lambda: get_planner(name)(m, None, 360.0))):
        try:
            res = call()
        except (AssertionError, GraspGaitInputError, NoGaitError) as exc:  # pragma: no cover
            pytest.fail(f"{name} ({how}) raised {type(exc).__name__}: {exc}")
        assert isinstance(res, PlannerResult), how
        assert res.plan is None and not res.success and res.exhausted, how
        assert res.reason.startswith(NO_START), (how, res.reason)
        fix = "raise mu" if kind == "empty map" else "change the hand"
        assert fix in res.reason, (how, res.reason)


def test_default_start_without_a_legal_start_is_no_gait(no_start_models):
    with pytest.raises(NoGaitError, match=NO_START):
        default_start(no_start_models["empty map"])


@pytest.mark.parametrize("name", list(PLANNERS))
def test_a_bad_start_is_an_input_error(models, name):
    m = model(models, "circle", 0.7)
    outside = GaitState(0, (0, 2, -1))  # finger 2 at 4 deg: outside [120, 210]
    assert not m.is_legal_state(outside)
    with pytest.raises(GraspGaitInputError, match="legal state"):
        run_planner(name, m, outside)
    later = GaitState(3, m.start_states()[0].contacts)  # not at theta = 0
    with pytest.raises(GraspGaitInputError, match="legal state"):
        get_planner(name)(m, later, 360.0)


@pytest.mark.parametrize("name", sorted(set(PLANNERS) - CHOOSE_OWN_START - {"modified"}))
def test_planners_needing_a_start_refuse_none_when_starts_exist(models, name):
    with pytest.raises(GraspGaitInputError, match="needs a start grasp"):
        get_planner(name)(model(models, "circle", 0.7), None, 360.0)


@pytest.mark.parametrize("name", ["optimal", "forward", "modified"])
def test_run_planner_picks_a_start(models, name):
    m = model(models, "circle", 0.7)
    check_plan(m, run_planner(name, m, None))


def test_default_start_is_the_first_spread_start_with_a_gait(models):
    m = model(models, "pentagon", 0.7)
    starts = m.start_states()
    step = max(1, len(starts) // 24)
    assert spread_starts(m, 24) == starts[::step][:24]
    assert default_start(m) in spread_starts(m, 24)


# --------------------------------------------------------------------------- layout
def test_one_module_per_thesis_section():
    where = {name: spec.split(":")[0].rsplit(".", 1)[1] for name, spec in PLANNERS.items()}
    assert where == {"bfs": "search", "dfs": "search", "dfs-thesis": "search",
                     "best-first": "search", "best-first-newest": "search",
                     "forward": "forward_gait", "back-and-forth": "back_and_forth_gait",
                     "modified": "modified_search", "rule": "rule_based", "optimal": "exact"}
    for spec in PLANNERS.values():
        module, func = spec.split(":")
        assert callable(getattr(importlib.import_module(module), func))
    # the CLI imports the diagnosis from rule_based: the re-export must stay
    from graspgait_env.planners.diagnosis import diagnose_no_gait
    from graspgait_env.planners.rule_based import diagnose_no_gait as again
    assert again is diagnose_no_gait


# rank of each module: a module imports only planner modules of lower rank, so the
# parts never import each other (shared pieces sit below them)
RANKS = {"result": 0, "prototypes": 0, "mirror": 0, "starts": 1, "trace": 2, "search": 2,
         "exact": 2, "reach": 3, "optimal_moves": 3,
         "forward_gait": 3, "back_and_forth_gait": 3, "modified_search": 3, "diagnosis": 3,
         "rule_based": 4, "registry": 5}


def test_the_parts_never_import_each_other():
    pkg = Path(planners_pkg.__file__).parent
    modules = {p.stem for p in pkg.glob("*.py")} - {"__init__"}
    assert modules == set(RANKS), "give the new module a rank"
    for name in modules:
        tree = ast.parse((pkg / f"{name}.py").read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                parts = node.module.split(".")
                if parts[:2] == ["graspgait_env", "planners"]:
                    dep = parts[2] if len(parts) > 2 else None
                    assert dep is not None, f"{name} imports the package itself"
                    assert RANKS[dep] < RANKS[name], f"{name} imports {dep}"
