"""The contact models of planning (graspgait_env.contact_model): the thesis's point
contacts bit for bit, the hand's ball tips derived from the sim config, the plan JSON's
``contact_model`` field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.contact_model import (
    GRAVITY,
    POINT_CONTACTS,
    ContactModel,
    hand_contact_model,
    polar_moment_of_inertia,
    rolling_contacts_deg,
)
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel
from graspgait_env.grasp_map import grasp_map
from graspgait_env.objects import load_object
from graspgait_env.plan import Plan

THESIS_OBJECTS = ("circle", "ellipse", "pentagon", "hexagon")
RHO = 0.0077978  # (m) the thesis's 0.307 in ball (configs/sim/default.yaml)


@pytest.mark.parametrize("obj", THESIS_OBJECTS)
def test_point_contacts_give_the_thesis_maps_bit_for_bit(obj):
    a = grasp_map(obj, 0.7)
    b = grasp_map(obj, 0.7, contact_model=POINT_CONTACTS)
    assert np.array_equal(a.stable, b.stable) and np.array_equal(a.usable, b.usable)
    assert GaitModel(obj, 0.7).contact_model is POINT_CONTACTS


@pytest.mark.parametrize("obj", THESIS_OBJECTS)
def test_the_hand_map_keeps_only_point_stable_grasps(obj):
    point = grasp_map(obj, 0.7).stable
    hand = grasp_map(obj, 0.7, contact_model=hand_contact_model(obj)).stable
    assert hand.any() and not (hand & ~point).any()
    assert np.array_equal(hand, hand.T)


def test_the_load_torque_is_table_friction_plus_inertia():
    """Circle, 0.1 kg, r = 0.0762 m: table mu m g r + (m r^2 / 2) a / (r + rho)."""
    cm = hand_contact_model("circle")
    m, r = 0.1, 0.0762
    expected = 0.3 * m * GRAVITY * r + 0.5 * m * r * r * 3.0 / (r + RHO)
    assert cm.name == "hand" and cm.load_torque_nm == pytest.approx(expected, rel=1e-3)
    assert cm.grip_n == 2.0 and cm.tip_radius_m == pytest.approx(RHO)
    assert cm.margin_deg(0.1) == pytest.approx(math.degrees(math.atan(expected / 0.2)),
                                                rel=1e-3)
    assert cm.vertex_clearance_m == pytest.approx(RHO * math.pi / 2)


def test_the_sim_config_sets_the_model(tmp_path):
    heavy = hand_contact_model("circle", {"object_mass": 0.2})
    assert heavy.load_torque_nm == pytest.approx(2 * hand_contact_model("circle").load_torque_nm)
    yaml = tmp_path / "sim.yaml"
    yaml.write_text("grip_force: 4.0\n")
    assert hand_contact_model("circle", yaml).grip_n == 4.0
    assert hand_contact_model("circle", turn_deg=-360).max_rotation_deg == -90.0
    with pytest.raises(GraspGaitInputError, match="grip_force"):
        hand_contact_model("circle", {"grip_force": 0.0})


def test_a_circle_grasp_at_the_cone_edge_is_left_out():
    """Contacts 120 deg apart lean 30 deg off the normals: 5 deg inside the 0.7 cone, less
    than the 7 deg the rotation's load needs; 130 deg apart (25 deg) keep 3 deg."""
    gm = grasp_map("circle", 0.7, contact_model=hand_contact_model("circle"))
    assert not gm.stable[0, 60] and gm.stable[0, 65]
    assert grasp_map("circle", 0.7).stable[0, 60]


def test_contacts_near_a_vertex_are_unusable_for_the_hand():
    pent = load_object("pentagon")
    cm = hand_contact_model(pent)
    gm = grasp_map(pent, 0.7, contact_model=cm)
    p = pent.contour_point(gm.phi_deg)
    d = np.linalg.norm(p[:, None] - pent.contour_point(pent.vertex_angles_deg)[None], axis=2)
    near = d.min(axis=1) < cm.vertex_clearance_m
    assert near.any() and not gm.usable[near].any()
    assert gm.usable[~near & ~pent.is_vertex(gm.phi_deg)].all()


def test_rolling_on_a_circle_is_the_thesis_equation():
    phi = rolling_contacts_deg(load_object("circle"), [10.0, 200.0], [[60.0], [-30.0]], RHO)
    r = 0.0762
    expected = np.array([[10.0, 200.0], [10.0, 200.0]]) - np.array([[60.0], [-30.0]]) * RHO / (
        r + RHO)
    np.testing.assert_allclose(phi, expected, atol=1e-3)


def test_rolling_on_a_flat_edge_slides_back_rho_theta():
    pent = load_object("pentagon")  # the edge from 234 to 306 deg is flat, foot at 270
    phi = rolling_contacts_deg(pent, 270.0, 30.0, RHO)
    moved = pent.contour_point(phi) - pent.contour_point(270.0)
    assert np.linalg.norm(moved) == pytest.approx(RHO * math.radians(30.0), rel=1e-3)
    assert moved[0] < 0  # against the (counter-clockwise) turn


def test_polar_moment_of_a_square():
    from graspgait_env.shapes import Polygon

    sq = Polygon(np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]), "square")
    assert polar_moment_of_inertia(sq, 3.0) == pytest.approx(3.0 * (4 + 4) / 12)


def test_json_round_trip_and_refusals():
    cm = hand_contact_model("hexagon")
    assert ContactModel.from_json(cm.to_json()) == cm
    assert ContactModel.from_json({"name": "point"}) == POINT_CONTACTS and POINT_CONTACTS.is_point
    for bad, field in (({"name": "ball"}, "name"), ({"name": "hand", "grip": 1}, "grip"),
                       ({"tip_radius_m": 0.01}, "name"),
                       ({"name": "hand", "tip_radius_m": -1.0}, "tip_radius_m"),
                       ({"name": "hand", "load_torque_nm": 0.1}, "grip_n")):
        with pytest.raises(GraspGaitInputError, match=field):
            ContactModel.from_json(bad)


def test_plans_record_the_contact_model(tmp_path):
    from graspgait_env.planners.registry import run_planner

    cm = hand_contact_model("ellipse")
    plan = run_planner("rule", GaitModel("ellipse", 0.7, contact_model=cm), None, 360.0).plan
    assert plan.assumed_contact_model == cm and plan.to_dict()["contact_model"]["name"] == "hand"
    plan.save(tmp_path / "p.json")
    assert Plan.load(tmp_path / "p.json").assumed_contact_model == cm
    point = run_planner("rule", GaitModel("ellipse", 0.7), None, 360.0).plan
    assert "contact_model" not in point.to_dict() and point.assumed_contact_model.is_point
    d = point.to_dict() | {"contact_model": {"name": "hand", "grip_n": -2}}
    with pytest.raises(GraspGaitInputError, match="grip_n"):
        Plan.from_dict(d)
