"""Simulation config (configs/sim/default.yaml): thesis defaults in SI, strict validation."""

from __future__ import annotations

import math
from dataclasses import fields

import pytest

from graspgait_env.errors import ConfigError
from graspgait_env.sim.config import (
    DEFAULT_SIM_CONFIG,
    INCH,
    LB_TO_N,
    OZ_TO_N,
    SimConfig,
    load_sim_config,
)


def test_default_yaml_matches_dataclass_defaults():
    """The YAML and the dataclass agree, so code that builds SimConfig() gets the same."""
    assert load_sim_config() == SimConfig()


def test_every_field_is_in_the_yaml_with_a_comment():
    text = DEFAULT_SIM_CONFIG.read_text()
    for f in fields(SimConfig):
        line = next((ln for ln in text.splitlines() if ln.startswith(f"{f.name}:")), None)
        assert line is not None, f"{f.name} missing from {DEFAULT_SIM_CONFIG.name}"


def test_thesis_values_in_si():
    cfg = load_sim_config()
    assert cfg.settle == 40  # thesis 7.4.4
    assert cfg.contact_cycles == 3  # thesis 7.3
    assert cfg.contact_threshold == pytest.approx(OZ_TO_N, abs=1e-3)  # 1 oz
    assert cfg.grip_saturation == pytest.approx(LB_TO_N, abs=1e-3)  # 1 lb = 4.448 N
    assert cfg.grip_saturation == pytest.approx(4.448, abs=1e-3)
    assert cfg.recenter_distance == pytest.approx(0.25 * INCH)  # 1/4 in (7.5)
    assert cfg.tip_radius == pytest.approx(0.307 * INCH, abs=1e-5)  # 7.8 mm (7.2)
    assert cfg.res == pytest.approx(0.1 * INCH)  # 1/10 in (7.4.2)
    assert cfg.max_r_factor == 1.5  # 7.4.1
    assert cfg.max_force == pytest.approx(2 * LB_TO_N, abs=0.01)  # PHANToM ~2 lb
    # the velocity filter keeps the thesis's time constant (1/10 at 3500 Hz)
    tau_thesis = -1 / 3500 / math.log(1 - 0.1)
    assert cfg.velocity_filter_tau == pytest.approx(tau_thesis, rel=0.03)
    assert cfg.cone == "elliptic"


def test_derived_rates():
    cfg = load_sim_config()
    assert cfg.servo_rate_hz == pytest.approx(1 / (cfg.timestep * cfg.servo_decimation))
    assert 0 < cfg.velocity_alpha < 1


def test_overrides_and_replace():
    cfg = load_sim_config(overrides={"grip_check": False, "kp": 800})
    assert cfg.grip_check is False and cfg.kp == 800.0
    assert cfg.replace(settle=20).settle == 20


@pytest.mark.parametrize("key,value,fragment", [
    ("no_such_key", 1, "unknown key"),
    ("timestep", -0.001, "out of range"),
    ("kp", "stiff", "expected a finite number"),
    ("settle", 2.5, "integer"),
    ("cone", "round", "not a choice"),
    ("grip_check", "yes", "true or false"),
    ("finger_solref", [0.004], "2 numbers"),
    ("timestep", float("nan"), "finite"),
    # the tuned numbers that once were literals in the executor
    ("drop_tilt_deg", -5.0, "out of range"),
    ("drop_tilt_deg", 120.0, "on its side"),
    ("probe_margin_deg", float("inf"), "finite"),
    ("probe_vertex_clearance_deg", -1.0, "out of range"),
    ("probe_step_deg", 0.0, "out of range"),
    ("recenter_speed", 0.0, "out of range"),
    ("monitor_every", 2.5, "integer"),
    ("monitor_every", 0, "out of range"),
    ("object_settle_time", "long", "expected a finite number"),
    ("video_tail_s", -0.5, "out of range"),
])
def test_bad_values_are_refused_with_the_field(key, value, fragment):
    with pytest.raises(ConfigError) as e:
        load_sim_config(overrides={key: value})
    assert key in str(e.value) and fragment in str(e.value)


def test_optional_fields_accept_null():
    cfg = load_sim_config(overrides={"finger_mu": None, "cone_mu": None, "object_mass": None})
    assert cfg.finger_mu is None


def test_the_once_literal_numbers_keep_their_values():
    """Tuned numbers that lived in the executor are SimConfig fields with today's values
    (the executor's results stay bit-identical with the defaults)."""
    cfg = SimConfig()
    assert cfg.drop_tilt_deg == 20.0
    assert cfg.probe_margin_deg == 10.0
    assert cfg.probe_step_deg == 4.0 and cfg.probe_vertex_clearance_deg == 8.0
    assert cfg.recenter_speed == cfg.approach_speed * 2  # exactly, in floating point
    assert cfg.monitor_every == 5 and cfg.object_settle_time == 0.05
    assert int(cfg.video_tail_s * cfg.video_fps) == cfg.video_fps // 2


def test_every_yaml_value_has_a_reason():
    """Each key's line (or the comment lines under it) carries a comment."""
    lines = DEFAULT_SIM_CONFIG.read_text().splitlines()
    for f in fields(SimConfig):
        i = next(k for k, ln in enumerate(lines) if ln.startswith(f"{f.name}:"))
        assert "#" in lines[i], f"{f.name}: no reason given in {DEFAULT_SIM_CONFIG.name}"
