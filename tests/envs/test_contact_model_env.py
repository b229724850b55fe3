"""The env family's ``contact_model`` kwarg: map-level envs learn on the maps the hand
can execute (``"hand"``); ``GraspGait-v0`` keeps the thesis's point contacts by default
and ``GraspGaitMujoco-v1`` plans with the hand's."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import graspgait_env  # noqa: F401  (registers the ids)
from graspgait_env.contact_model import hand_contact_model
from graspgait_env.envs.config import GraspGaitConfig
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel


def test_map_env_default_is_point_contacts():
    env = gym.make("graspgait_env:GraspGait-v0", object="pentagon", mu=0.7)
    assert env.unwrapped.config.contact_model == "point"
    assert np.array_equal(env.unwrapped.model.stable, GaitModel("pentagon", 0.7).stable)


@pytest.mark.parametrize("env_id", ["GraspGait-v0", "GraspGaitRandom-v0"])
def test_hand_kwarg_gives_the_hands_maps(env_id):
    env = gym.make(f"graspgait_env:{env_id}", contact_model="hand")
    env.reset(seed=0)
    model = env.unwrapped.model
    assert model.contact_model.name == "hand"
    expected = GaitModel(model.shape, model.mu, contact_model=model.contact_model).stable
    assert np.array_equal(model.stable, expected)


def test_the_hand_model_follows_the_object_and_turn():
    env = gym.make("graspgait_env:GraspGait-v0", object="ellipse", contact_model="hand",
                   turn_deg=-360.0)
    assert env.unwrapped.model.contact_model == hand_contact_model("ellipse", turn_deg=-360)


def test_mujoco_env_plans_for_the_hand_at_finger_friction_mu():
    env = gym.make("graspgait_env:GraspGaitMujoco-v1", object="circle", mu=0.7)
    u = env.unwrapped
    assert u.config.contact_model == "hand" and u.model.contact_model.name == "hand"
    assert u.sim_config.finger_mu is None  # the contacts' friction is the plan's mu
    point = gym.make("graspgait_env:GraspGaitMujoco-v1", object="circle", contact_model="point")
    assert point.unwrapped.model.contact_model.is_point


def test_a_bad_contact_model_names_the_field_and_the_fix():
    with pytest.raises(GraspGaitInputError, match="contact_model='ball'.*'point'.*'hand'"):
        GraspGaitConfig(contact_model="ball")
