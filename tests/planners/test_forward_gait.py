"""The forward (staircase) gait of thesis 6.3.1: rules 1-4 on band maps and bundled objects."""

from __future__ import annotations

import pytest

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners import prototypes as P
from graspgait_env.planners.forward_gait import forward_gait
from tests.planners.helpers import band_map, check_plan, model, replay, synthetic


@pytest.mark.parametrize("lo, h", [(60, 15), (75, 15), (90, 15), (45, 30), (30, 45), (100, 20)])
@pytest.mark.parametrize("turn", [360.0, -360.0, 250.0])
def test_forward_gait_on_band_maps(lo, h, turn):
    S = band_map(lo, lo + h)
    m = synthetic(S)
    band, checks = P.forward_conditions(S, m)
    res = forward_gait(m, None, turn)
    assert res.success == all(checks), res.reason
    if res.success:
        check_plan(m, res, turn, physical=False)
        assert res.nodes_opened == res.path_length == res.nodes_created
        assert res.pattern == "staircase"


def test_forward_gait_from_every_condition_3_start():
    S = band_map(50, 80)
    m = synthetic(S)
    n_ok = 0
    for s in m.start_states()[::5]:
        _, checks = P.forward_conditions(S, m, s.contacts)
        res = forward_gait(m, s)
        assert res.success == all(checks), res.reason
        n_ok += res.success
    assert n_ok > 10


def test_forward_gait_rules_on_circle(models):
    """Rule 1 rotates to the finger pair box edge; rules 2-3 put the free finger at the
    first grid angle of its workspace and lift the finger whose workspace precedes it."""
    m = model(models, "circle", 0.7)
    res = forward_gait(m)
    check_plan(m, res)
    assert res.extra["method"] == "forward" and res.pattern == "staircase"
    assert res.nodes_opened == res.path_length == 10 and res.regrasps == 6
    states = replay(m, res)
    g = P.WorkspaceGrid.from_model(m)
    for a, b, rule in zip(states[:-1], states[1:], res.extra["rules"], strict=True):
        if b.k != a.k:
            assert rule == "6.3.1 rule 1"
            if b is not states[-1]:
                assert any(m.position(f, b.contacts[f], b.k) == m.ws_width[f] - 1
                           for f in b.held())
        else:
            assert rule in ("6.3.1 rule 2", "6.3.1 rule 3")
            (h,) = [f for f in range(3) if a.contacts[f] < 0]
            (lifted,) = [f for f in range(3) if b.contacts[f] < 0]
            assert m.position(h, b.contacts[h], b.k) == 0
            assert lifted == g.pred(h)
    cw = forward_gait(m, None, -360.0)
    check_plan(m, cw, -360.0)
    assert cw.regrasps == res.regrasps


def test_forward_gait_refuses_with_reasons(models):
    res = forward_gait(model(models, "ellipse", 0.7))
    assert not res.success and "band height 12 deg < w = 30 deg" in res.reason
    m = synthetic(band_map(60, 80))  # offsets 120..160 deg
    # fingers 1 at 0 deg and 2 at 140 deg: inner offset 140, 20 deg from the edge 160
    res = forward_gait(m, GaitState(0, (0, 70, -1)))
    assert not res.success
    assert "only 20 deg from the band's forward edge 160 deg (< w = 30 deg)" in res.reason


# --------------------------------------------------------------------------- rotation limit
@pytest.mark.parametrize("turn", [360.0, -360.0])
def test_rule_1_rotates_exactly_the_models_rotation_room(models, turn):
    """Rule 1 turns to the finger pair box edge: the room GaitModel.rotation_room gives
    (the one definition of the rotation limit), or to the goal if nearer."""
    m = model(models, "circle", 0.7)
    res = forward_gait(m, None, turn)
    check_plan(m, res, turn)
    states = replay(m, res)
    K = m.turn_steps(turn)
    rotations = 0
    for a, b, rule in zip(states[:-1], states[1:], res.extra["rules"], strict=True):
        if b.k == a.k:
            continue
        ccw, cw = m.state_rotation_room(a)
        assert (ccw, cw) == m.rotation_room(*[x for f in a.held()
                                              for x in (f, m.position(f, a.contacts[f], a.k))])
        room = ccw if turn > 0 else cw
        assert rule == "6.3.1 rule 1"
        assert abs(b.k - a.k) == min(room, abs(K - a.k)) > 0
        rotations += 1
    assert rotations >= 3


def test_forward_gait_follows_the_models_rotation_room(monkeypatch):
    """With a narrower rotation room (one step less each way), the forward gait's rule 1
    stops one step short: it reads the room from the model, it does not re-derive it
    (a re-derived room would overshoot the model's and the move would be refused)."""
    m = GaitModel("circle", 0.7)
    s0 = replay(m, forward_gait(m))[0]
    true_room = m.rotation_room

    def narrower(f, pf, g, pg):
        ccw, cw = true_room(f, pf, g, pg)
        return max(ccw - 1, 0), max(cw - 1, 0)

    monkeypatch.setattr(m, "rotation_room", narrower)
    res = forward_gait(m, s0)
    check_plan(m, res, physical=False)
    states = replay(m, res)
    for a, b, rule in zip(states[:-1], states[1:], res.extra["rules"], strict=True):
        if rule == "6.3.1 rule 1":
            ccw, _ = m.state_rotation_room(a)
            assert b.k - a.k == min(ccw, m.turn_steps(360.0) - a.k)
    assert res.plan.steps[1] == {"op": "rotate", "delta": 88.0}  # 90 deg to the edge - 2
