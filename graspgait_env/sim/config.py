"""Parameters of the simulated hand and the thesis controller (``configs/sim/*.yaml``).

One dataclass, :class:`SimConfig`; every field has a one-line docstring and a default
taken from the thesis where it gives one (converted to SI), otherwise ours with the
reason in ``configs/sim/default.yaml``. :func:`load_sim_config` reads a YAML file and
refuses unknown keys and bad values with a :class:`~graspgait_env.errors.ConfigError`
naming the field and the fix.

Examples
--------
>>> cfg = load_sim_config()                 # configs/sim/default.yaml
>>> cfg.settle, round(cfg.grip_saturation, 3)
(40, 4.448)
>>> load_sim_config(overrides={"grip_check": False}).grip_check
False
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from graspgait_env.errors import ConfigError
from graspgait_env.objects import read_yaml_mapping
from graspgait_env.resources import config_dir
from graspgait_env.sim.frames import INCH, LB_TO_N, OZ_TO_N

__all__ = ["SimConfig", "load_sim_config", "DEFAULT_SIM_CONFIG", "LB_TO_N", "OZ_TO_N", "INCH"]

DEFAULT_SIM_CONFIG = config_dir("sim") / "default.yaml"  # bundled (graspgait_env.resources)


@dataclass(frozen=True)
class SimConfig:
    """Physics, hand and controller parameters (SI units; angles in degrees)."""

    # physics (thesis 7.2)
    timestep: float = 0.001
    """Physics timestep (s)."""
    integrator: str = "implicitfast"
    """MuJoCo integrator name."""
    solver: str = "Newton"
    """MuJoCo constraint solver name."""
    iterations: int = 30
    """Main solver iterations."""
    tolerance: float = 1e-10
    """Main solver tolerance."""
    cone: str = "elliptic"
    """Friction cone: ``elliptic`` (Coulomb) or ``pyramidal``."""
    impratio: float = 100.0
    """Friction-to-normal constraint impedance ratio (limits soft-friction creep)."""
    noslip_iterations: int = 0
    """Iterations of MuJoCo's no-slip post-solver (0: off)."""
    finger_solref: tuple[float, ...] = (0.004, 1.0)
    """solref (time constant s, damping ratio) of the finger-object contacts."""
    finger_solimp: tuple[float, ...] = (0.95, 0.99, 0.001, 0.5, 2.0)
    """solimp of the finger-object contacts."""
    table_solref: tuple[float, ...] = (0.004, 1.0)
    """solref of the object-table contacts."""
    table_solimp: tuple[float, ...] = (0.95, 0.99, 0.001, 0.5, 2.0)
    """solimp of the object-table contacts."""
    finger_mu: float | None = None
    """True finger-object Coulomb friction; None: the plan's mu."""
    table_mu: float = 0.3
    """Object-table Coulomb friction."""
    object_mass: float | None = None
    """Object mass (kg); None: the object file's."""
    mesh_segments: int = 128
    """Facets of the prism that stands in for a smooth contour."""
    object_settle_time: float = 0.05
    """Physics alone (no controller) at a reset, for the object to settle on the table (s)."""

    # hand
    tip_radius: float = 0.307 * INCH
    """Fingertip ball radius (m): 0.307 in (thesis 7.2)."""
    finger_mass: float = 0.05
    """Effective endpoint mass of each finger (kg)."""
    finger_damping: float = 0.1
    """Viscous friction of each finger axis (N s/m)."""
    max_force: float = 2.0 * LB_TO_N
    """Actuator force limit per axis (N): the PHANToM's ~2 lb."""
    home_angles_deg: tuple[float, ...] | None = None
    """Finger home angles (deg, frame F); None: the middle of each workspace."""
    max_r_factor: float = 1.5
    """max_r as a multiple of the object's largest radius (thesis 7.4.1)."""

    # servo (thesis 7.3, 7.4.6)
    servo_decimation: int = 4
    """Physics steps per servo cycle (ctrl held between cycles)."""
    kp: float = 1000.0
    """Proportional gain in x and y (N/m)."""
    kv: float = 10.0
    """Derivative gain in x and y (N s/m)."""
    kp_z: float = 300.0
    """Proportional gain in z (N/m)."""
    kv_z: float = 5.0
    """Derivative gain in z (N s/m)."""
    velocity_filter_tau: float = 0.0027
    """Time constant of the low-pass velocity estimate (s); thesis: 1/10 at 3500 Hz."""
    res: float = 0.1 * INCH
    """Path resolution (m): distance between via points (thesis 7.4.2)."""
    free_speed: float = 0.6
    """Speed of free finger motions (m/s)."""
    approach_speed: float = 0.06
    """Speed of the last part of an approach (m/s)."""
    standoff: float = 0.010
    """Distance outside the expected surface where the slow approach starts (m)."""
    overshoot: float = 0.02
    """How far the approach line runs into the expected object (m)."""
    rotation_speed_deg: float = 180.0
    """Object rotation speed (deg/s)."""
    free_accel: float = 10.0
    """Acceleration limit of free finger motions: arcs, fast approaches, retreats (m/s^2)."""
    rotation_accel: float = 3.0
    """Tip acceleration limit of object rotations and recentering moves (m/s^2)."""
    approach_accel: float = 2.0
    """Acceleration limit on approach lines, where contact detection is armed (m/s^2)."""
    trapezoidal_speed: bool = True
    """Speed ramps at the accelerations above; False: constant speed (thesis 7.4.6)."""
    recenter_speed: float = 0.12
    """Speed of the recentering move that drags the held object back (m/s, thesis 7.5)."""

    # grip (thesis 7.3, 7.4.3-7.4.4)
    grip_force: float = 2.0
    """Nominal grip force between the grasping pair (N)."""
    settle: int = 40
    """Servo cycles to apply a nominal grip (increment grip_force/settle per cycle)."""
    grip_saturation: float = LB_TO_N
    """No grip is added when the finger's total force exceeds this (N): 1 lb."""
    grip_check: bool = True
    """Run the grip force and friction cone checks."""
    cone_mu: float | None = None
    """Friction coefficient of the check's cone; None: the finger mu."""
    transfer_time: float = 0.10
    """Duration of the grip transfer with three fingers on (s)."""
    settle_time: float = 0.03
    """Hold after a grip change before the next trajectory (s)."""

    # contact detection (thesis 7.3)
    contact_threshold: float = 0.278014
    """Servo force that signals contact (N): 1 oz."""
    contact_cycles: int = 3
    """Servo cycles above the threshold before contact is assumed."""
    contact_along_approach: bool = True
    """Test the servo force along the approach line; False: its magnitude (thesis 7.3)."""

    # localizer (thesis 7.4.5)
    localizer: bool = True
    """Use the object localizer (``graspgait_env.sim.localizer``) when three fingers touch."""
    localize_during_transfer: bool = True
    """Localize halfway through a regrasp's grip transfer; False: after it (7.4.2)."""
    initial_probe: bool = True
    """Touch the object with all three fingers and localize it before the first grasp."""
    probe_grip: float = 0.5
    """Internal force between each pair of fingers while the probe localizes (N)."""
    probe_margin_deg: float = 10.0
    """Probe contacts stay this far in from each end of a finger's workspace (deg)."""
    probe_step_deg: float = 4.0
    """Spacing of the probe's candidate contact angles (deg)."""
    probe_vertex_clearance_deg: float = 8.0
    """Probe contacts stay this far from a vertex of the expected polygon (deg)."""
    localizer_prior_weight: float = 0.01
    """Weight of the expected pose in the localizer's search (LocalizerConfig.prior_weight)."""
    localizer_iterate: bool = True
    """Iterate (grid and Gauss-Newton) to the best fit; False: one weighted blend (thesis)."""
    recenter_distance: float = 0.25 * INCH
    """A position error above this (m) is corrected by a recentering move: 1/4 in."""
    stabilization_finger: bool = False
    """Keep the free finger on the object during rotations (thesis 7.4.2)."""
    rolling_compensation: bool = True
    """Rotations follow the rolling ball tips (thesis 7.2); False: rigid arcs (thesis)."""
    success_angle_deg: float = 3.0
    """A gait succeeds when it ends within this of the planned orientation (deg)."""

    # monitoring (ground truth, not seen by the controller)
    monitor_every: int = 5
    """Servo cycles between the monitor's ground-truth checks (drops)."""
    drop_distance: float = 0.03
    """Object farther than this (m) from where the plan wants it counts as dropped."""
    drop_tilt_deg: float = 20.0
    """Object tilted more than this (deg) from upright counts as dropped (tipped over)."""
    lost_contact_time: float = 0.1
    """Fewer than two fingers touching for this long (s) counts as dropped."""
    slip_threshold: float = 0.002
    """Contact sliding farther than this (m) along the object in one step is a slip."""

    # video
    video_fps: int = 30
    """Frames per second of the rendered video."""
    video_width: int = 640
    """Video width (pixels)."""
    video_height: int = 480
    """Video height (pixels)."""
    video_camera: str = "overview"
    """Camera name in the model: ``overview`` or ``top``."""
    video_tail_s: float = 0.5
    """The video holds the final state this long after the last move (s)."""

    # --------------------------------------------------------------- derived
    @property
    def servo_dt(self) -> float:
        """Servo period (s)."""
        return self.timestep * self.servo_decimation

    @property
    def servo_rate_hz(self) -> float:
        """Servo rate (Hz)."""
        return 1.0 / self.servo_dt

    @property
    def velocity_alpha(self) -> float:
        """Low-pass coefficient per servo cycle for ``velocity_filter_tau``."""
        return 1.0 - math.exp(-self.servo_dt / self.velocity_filter_tau)

    def replace(self, **changes: Any) -> SimConfig:
        """A copy with some fields changed (validated)."""
        return _validated(dataclasses.replace(self, **changes), "<replace>")


_CHOICES = {
    "integrator": ("Euler", "RK4", "implicit", "implicitfast"),
    "solver": ("PGS", "CG", "Newton"),
    "cone": ("pyramidal", "elliptic"),
    "video_camera": ("overview", "top"),
}
_NONNEG = {"localizer_prior_weight", "noslip_iterations", "finger_damping", "overshoot",
           "settle_time", "kv", "kv_z", "probe_margin_deg", "probe_vertex_clearance_deg",
           "object_settle_time", "video_tail_s"}
_OPTIONAL = {"finger_mu", "object_mass", "cone_mu", "home_angles_deg"}
_MAXIMUM = {  # upper bounds, with why
    "drop_tilt_deg": (90.0, "an object tilted 90 deg lies on its side"),
}


def _validated(cfg: SimConfig, src: str) -> SimConfig:
    for f in fields(SimConfig):
        v = getattr(cfg, f.name)
        if v is None and f.name in _OPTIONAL:
            continue
        if f.name in _CHOICES:
            if v not in _CHOICES[f.name]:
                raise ConfigError(src, f.name, f"{v!r} is not a choice",
                                  f"use one of {', '.join(_CHOICES[f.name])}")
            continue
        if f.type == "bool":
            if not isinstance(v, bool):
                raise ConfigError(src, f.name, f"expected true or false, got {v!r}",
                                  f"set {f.name}: true or false")
            continue
        if isinstance(v, tuple):
            if f.name.endswith("solref") and len(v) != 2:
                raise ConfigError(src, f.name, f"needs 2 numbers, got {list(v)}",
                                  "give [time constant (s), damping ratio]")
            if f.name.endswith("solimp") and len(v) != 5:
                raise ConfigError(src, f.name, f"needs 5 numbers, got {list(v)}",
                                  "give [dmin, dmax, width, midpoint, power]")
            if f.name == "home_angles_deg" and len(v) != 3:
                raise ConfigError(src, f.name, f"needs 3 angles, got {list(v)}",
                                  "give one home angle (deg) per finger")
            for x in v:
                if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                    raise ConfigError(src, f.name, f"{x!r} is not a finite number",
                                      f"give {f.name} as a list of numbers")
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ConfigError(src, f.name, f"expected a finite number, got {v!r}",
                              f"set {f.name} to a number ({f.type})")
        if f.type == "int" and int(v) != v:
            raise ConfigError(src, f.name, f"expected an integer, got {v!r}",
                              f"set {f.name} to a whole number")
        if v < 0 or (v == 0 and f.name not in _NONNEG):
            raise ConfigError(src, f.name, f"{v!r} is out of range",
                              f"set {f.name} to a value > 0" if f.name not in _NONNEG
                              else f"set {f.name} to a value >= 0")
        if f.name in _MAXIMUM and v > _MAXIMUM[f.name][0]:
            hi, why = _MAXIMUM[f.name]
            raise ConfigError(src, f.name, f"{v!r} is out of range ({why})",
                              f"set {f.name} to a value <= {hi:g}")
    return cfg


def _coerce(name: str, value: Any) -> Any:
    if isinstance(value, list):
        return tuple(value)
    f = SimConfig.__dataclass_fields__[name]
    if f.type == "int" and isinstance(value, float) and value.is_integer():
        return int(value)
    if f.type in ("float", "float | None") and isinstance(value, int) and not isinstance(
            value, bool):
        return float(value)
    return value


def load_sim_config(path: str | Path | None = None,
                    overrides: dict[str, Any] | None = None) -> SimConfig:
    """Read a simulation config YAML (default ``configs/sim/default.yaml``).

    Parameters
    ----------
    path
        YAML file; keys are :class:`SimConfig` fields, all optional.
    overrides
        Fields to change after reading (e.g. ``{"grip_check": False}``).

    Raises
    ------
    ConfigError
        An unknown key, a value of the wrong type, or one out of range.
    """
    path = Path(path) if path is not None else DEFAULT_SIM_CONFIG
    data = read_yaml_mapping(path, "simulation config")
    data = {**data, **(overrides or {})}
    known = {f.name for f in fields(SimConfig)}
    for key in data:
        if key not in known:
            raise ConfigError(str(path), str(key), "unknown key",
                              "remove it; the keys are the fields of SimConfig "
                              "(graspgait_env/sim/config.py)")
    kwargs = {k: _coerce(k, v) for k, v in data.items()}
    return _validated(SimConfig(**kwargs), str(path))
