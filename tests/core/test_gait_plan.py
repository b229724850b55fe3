"""Gait model (legal moves) and plan validator / JSON / motion_file (thesis 4.3, 5.2, 7.4.1)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from graspgait_env import GraspGaitInputError, Hand
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import InvalidPlanError, Plan, plan_from_states, validate_plan
from graspgait_env.planners.exact import optimal_gait


@pytest.fixture(scope="module")
def pentagon() -> GaitModel:
    return GaitModel("pentagon", 0.7)


def test_action_layout_sizes(pentagon):
    # thesis hand: 90-degree workspaces on a 2-degree grid hold 46 grid angles
    assert pentagon.ws_width.tolist() == [46, 46, 46]
    assert pentagon.R == 45 and pentagon.P == 46
    assert pentagon.n_actions == 2 * 45 + 2 * 46


def test_fig_4_6_grasp_rotation_limits(pentagon):
    # thesis fig. 4.6: grasp (50, 270) by fingers 1 and 3 turns 40 deg CCW until finger 1
    # reaches 90 deg; clockwise it can turn 30 deg (finger 3 hits 240 deg).
    s = pentagon.start_state({1: 50.0, 3: 270.0})
    mask = pentagon.action_mask(s)
    R = pentagon.R
    assert mask[:20].all() and not mask[20:R].any()  # 20 steps of 2 deg = 40 deg CCW
    assert mask[R : R + 15].all() and not mask[R + 15 : 2 * R].any()  # 30 deg CW


def test_mask_matches_brute_force(pentagon):
    """Every masked action is legal and every legal move is masked (brute force over moves)."""
    rng = np.random.default_rng(0)
    starts = pentagon.start_states()
    for s in [starts[i] for i in rng.choice(len(starts), 25, replace=False)]:
        mask = pentagon.action_mask(s)
        for a in range(pentagon.n_actions):
            t = pentagon.apply(s, a)
            m = pentagon.decode(s, a)
            if m.kind == "rotate":
                # legal iff every intermediate angle keeps both contacts in their workspaces
                ok = all(
                    pentagon.position(f, s.contacts[f], s.k + step) >= 0
                    for f in s.held()
                    for step in range(0, m.delta + np.sign(m.delta), np.sign(m.delta))
                )
            else:
                ok = (pentagon.position(m.finger, m.contact, s.k) >= 0
                      and pentagon.is_legal_state(t))
            assert mask[a] == ok, (s, a, m)
            if ok:
                assert pentagon.encode(s, t) == a


def test_start_state_errors(pentagon):
    with pytest.raises(GraspGaitInputError, match="outside its workspace"):
        pentagon.start_state({1: 100.0, 3: 270.0})
    with pytest.raises(GraspGaitInputError, match="exactly two"):
        pentagon.start_state({1: 50.0})
    with pytest.raises(GraspGaitInputError, match="grid"):
        pentagon.start_state({1: 51.0, 3: 270.0})
    with pytest.raises(GraspGaitInputError, match="force-closure"):
        pentagon.start_state({1: 90.0, 3: 270.0})  # 90 deg is a vertex of the pentagon


def _good_plan(model: GaitModel) -> Plan:
    s = model.start_state({1: 50.0, 3: 270.0})
    res = optimal_gait(model, s, 360.0)
    assert res.plan is not None
    return res.plan


def test_plan_json_round_trip_and_motion_file(pentagon, tmp_path):
    plan = _good_plan(pentagon)
    path = tmp_path / "p.json"
    plan.save(path)
    back = Plan.load(path)
    assert back.to_dict() == json.loads(path.read_text())
    assert back.to_dict() == plan.to_dict()
    assert validate_plan(back, pentagon.shape, pentagon.hand, 360.0) is None
    lines = plan.to_motion_file().splitlines()
    assert lines[0] == "i 50 -360 270"
    assert sum(line.startswith("t ") for line in lines) == plan.regrasps
    rot = sum(float(line.split()[1]) for line in lines if line.startswith("r "))
    assert rot == pytest.approx(plan.rotation_deg)
    for line in lines:
        if line[0] in "it":
            vals = [float(v) for v in line.split()[1:]]
            assert sum(v > 0 for v in vals) == 2  # two fingers on the object


def _steps(*steps):
    return Plan("pentagon", 0.7, [[0, 90], [120, 210], [240, 330]], list(steps))


G = {"op": "grasp", "contacts": {"1": 50.0, "3": 270.0}}


@pytest.mark.parametrize(
    ("steps", "rule", "at"),
    [
        ([{"op": "rotate", "delta": 10.0}], "first-step-not-grasp", 0),
        ([{"op": "grasp", "contacts": {"1": 50.0}}], "not-two-fingers", 0),
        ([{"op": "grasp", "contacts": {"1": 50.0, "4": 270.0}}], "unknown-finger", 0),
        ([{"op": "grasp", "contacts": {"1": 100.0, "3": 270.0}}], "outside-workspace", 0),
        ([{"op": "grasp", "contacts": {"1": 90.0, "3": 270.0}}], "not-force-closure", 0),
        ([G, {"op": "rotate", "delta": 42.0}], "rotation-leaves-workspace", 1),
        ([G, {"op": "rotate", "delta": -32.0}], "rotation-leaves-workspace", 1),
        ([G, {"op": "rotate", "delta": 0.0}], "zero-rotation", 1),
        ([G, {"op": "regrasp", "contacts": {"1": 60.0, "3": 270.0}}], "same-finger-pair-box", 1),
        ([G, {"op": "regrasp", "contacts": {"2": 140.0, "3": 280.0}}],
         "more-than-one-contact-changed", 1),
        ([G, {"op": "grasp", "contacts": {"1": 50.0, "3": 270.0}}], "first-step-not-grasp", 1),
        ([G, {"op": "spin", "delta": 5}], "bad-step", 1),
        ([G, {"op": "rotate", "delta": float("nan")}], "bad-step", 1),
        ([G, {"op": "rotate", "delta": 40.0}], "turn-not-achieved", 1),
    ],
)
def test_validator_rejects_each_rule(steps, rule, at):
    v = validate_plan(_steps(*steps), turn_deg=360.0)
    assert v is not None and v.rule == rule and v.step == at, v
    with pytest.raises(InvalidPlanError, match=rule):
        raise InvalidPlanError(v)


def test_validator_accepts_thesis_fig_4_6_moves():
    # fig. 4.6: rotate 40, regrasp (140, 270) with fingers 2 and 3, rotate 20 more
    plan = _steps(G, {"op": "rotate", "delta": 40.0},
                  {"op": "regrasp", "contacts": {"2": 140.0, "3": 270.0}},
                  {"op": "rotate", "delta": 20.0})
    assert validate_plan(plan) is None
    assert validate_plan(plan, turn_deg=60.0) is None
    assert validate_plan(plan, turn_deg=62.0).rule == "turn-not-achieved"


def test_regrasp_into_unreachable_contact_is_outside_workspace():
    # after a 40 deg turn, contact 70 deg lies at F 110 deg: no finger reaches it
    plan = _steps(G, {"op": "rotate", "delta": 40.0},
                  {"op": "regrasp", "contacts": {"2": 70.0, "3": 270.0}})
    assert validate_plan(plan).rule == "outside-workspace"


def test_plan_from_states_and_turn(pentagon):
    s0 = pentagon.start_state({1: 50.0, 3: 270.0})
    s1 = GaitState(20, s0.contacts)
    s2 = pentagon.apply(s1, pentagon.encode(s1, GaitState(20, (-1, 70, 135))))
    plan = plan_from_states(pentagon, [s0, s1, s2])
    assert [st["op"] for st in plan.steps] == ["grasp", "rotate", "regrasp"]
    assert plan.steps[2]["contacts"] == {"2": 140.0, "3": 270.0}
    assert validate_plan(plan, pentagon.shape, pentagon.hand) is None


def test_gait_model_refuses_two_finger_hand():
    with pytest.raises(GraspGaitInputError, match="exactly 3"):
        GaitModel("circle", 0.7, hand=Hand(((0.0, 90.0), (180.0, 270.0)), "two"))


def test_vertex_clearance_keeps_contacts_off_corners():
    # pentagon vertices at 18, 90, 162, 234, 306 deg (2-degree grid)
    plain = GaitModel("pentagon", 0.7)
    clear = GaitModel("pentagon", 0.7, vertex_clearance_deg=4.0)
    usable = clear.grasp_map.usable
    for v in (18, 90, 162, 234, 306):
        for d in (-2, 0, 2):  # (4 deg away is the boundary: float-rounding decides)
            assert not usable[(v + d) // 2 % 180], (v, d)
        assert usable[(v + 6) // 2 % 180] and usable[(v - 6) // 2 % 180]
    assert plain.grasp_map.usable[(18 + 2) // 2]
    # clearance only removes grasps
    assert not (clear.stable & ~plain.stable).any()
    assert clear.stable.sum() < plain.stable.sum()
