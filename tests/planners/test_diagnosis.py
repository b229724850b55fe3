"""Why no gait exists (thesis 1.3 (2)-(4)): the diagnosis, short and verbose."""

from __future__ import annotations

import pytest

from graspgait_env.gait import GaitModel
from graspgait_env.planners.diagnosis import diagnose_no_gait
from graspgait_env.workspace import Hand
from tests.planners.helpers import model


def test_diagnose_no_gait_categories(models):
    assert diagnose_no_gait(GaitModel("pentagon", 0.3)).startswith(
        "no stable grasp at all (mu=0.3)")
    tri = diagnose_no_gait(model(models, "triangle", 0.7))
    assert tri.startswith("stuck at angle 64 deg") and "box 10 x 10 deg < 2w x 2w" in tri
    assert diagnose_no_gait(model(models, "pentagon", 0.7)).startswith(
        "band/box smaller than the conditions need relative to w (no band; box 34 x 34 deg")
    assert diagnose_no_gait(model(models, "circle", 0.7)).startswith(
        "a gait exists: the forward gait's conditions hold")
    # workspaces whose finger pairs never hold contacts near 180 deg apart (circle, mu 0.1)
    hand = Hand(((0.0, 10.0), (90.0, 100.0), (245.0, 255.0)), "odd")
    assert diagnose_no_gait(GaitModel("circle", 0.1, hand=hand)).startswith(
        "stable grasps but none reachable inside the workspaces")


# --------------------------------------------------------------------------- short / verbose
@pytest.fixture(scope="module")
def cases(models) -> dict[str, tuple[GaitModel, str]]:
    """(model, first words of the verdict) per category of thesis 1.3 (2)-(4)."""
    return {
        "empty": (GaitModel("pentagon", 0.3), "no stable grasp at all (mu=0.3)"),
        "outside": (GaitModel("circle", 0.1, hand=Hand(((0.0, 10.0), (90.0, 100.0),
                                                         (245.0, 255.0)), "odd")),
                    "stable grasps but none reachable inside the workspaces"),
        "stuck": (model(models, "triangle", 0.7), "stuck at angle 64 deg"),
        "search only": (model(models, "pentagon", 0.7),
                        "band/box smaller than the conditions need relative to w"),
        "gait": (model(models, "circle", 0.7), "a gait exists"),
    }


@pytest.fixture(scope="module")
def texts(cases) -> dict[tuple[str, bool], str]:
    """Each case's diagnosis, short and verbose, computed once (the exact planner runs)."""
    return {(c, v): diagnose_no_gait(m, verbose=v) for c, (m, _) in cases.items()
            for v in (False, True)}


@pytest.mark.parametrize("case", ["empty", "outside", "stuck", "search only", "gait"])
def test_short_diagnosis_is_at_most_three_lines(cases, texts, case):
    _, verdict = cases[case]
    text = texts[(case, False)]
    lines = text.split("\n")
    assert 1 <= len(lines) <= 3, text
    assert lines[0].startswith(verdict)
    assert lines[-1].startswith("fix: ")
    assert all(line.strip() for line in lines) and not text.endswith("\n")


def test_short_diagnosis_gives_the_reason_and_fix(cases, texts):
    assert "raise mu" in texts[("empty", False)].split("\n")[-1]
    assert "change the hand" in texts[("outside", False)].split("\n")[-1]
    stuck = texts[("stuck", False)].split("\n")
    assert stuck[1] == "why: no band; box 10 x 10 deg < 2w x 2w = 60 x 60 deg"
    assert "raise mu" in stuck[2]
    m = cases["stuck"][0]
    from_start = diagnose_no_gait(m, m.start_states()[0]).split("\n")
    assert len(from_start) <= 3 and "try another start grasp" in from_start[-1]
    search = texts[("search only", False)].split("\n")
    assert "--planner modified" in search[-1]


@pytest.mark.parametrize("case", ["stuck", "search only", "gait"])
def test_verbose_diagnosis_has_every_detail(cases, texts, case):
    _, verdict = cases[case]
    short = texts[(case, False)].split("\n")
    full = texts[(case, True)].split("\n")
    assert len(full) > 3 and full[0].startswith(verdict)
    assert full[-1] == short[-1]  # the same fix
    text = "\n".join(full)
    assert "grasp map: " in text and "w = 30 deg" in text
    assert "forward gait (thesis 6.3.1) conditions" in text
    assert "back-and-forth gait (thesis 6.3.2) conditions" in text
    assert "exact planner from theta=0 deg" in text


def test_verbose_stuck_line_keeps_the_prototype_numbers(texts):
    full = texts[("stuck", True)].split("\n")
    assert full[0].startswith("stuck at angle 64 deg: from each of 8 start grasps tried")
    assert full[0].endswith("; no band; box 10 x 10 deg < 2w x 2w = 60 x 60 deg")
    assert sum(line.startswith("exact planner from") for line in full) == 8


@pytest.mark.parametrize("case", ["empty", "outside"])
def test_verbose_diagnosis_without_starts(cases, texts, case):
    _, verdict = cases[case]
    full = texts[(case, True)].split("\n")
    assert full[0].startswith(verdict) and full[-1].startswith("fix: ")
    assert full[1].startswith("grasp map: ")
