"""The thesis controller executing a gait one move at a time (thesis 7.3-7.4): the task.

:class:`GaitExecutor` owns a MuJoCo model of the hand and object and composes the
controller processes of thesis 7.3, each in its own module:

1. finger positioning: the move sequences (:mod:`~graspgait_env.sim.moves`, 7.4.2) turn
   each move into trajectories (:mod:`~graspgait_env.sim.trajectory`); the servo loop
   (:mod:`~graspgait_env.sim.servo_loop`, 7.4.6) tracks them with the PD servo at the
   servo rate, the motor forces held between servo cycles;
2. grasp maintenance: internal grip forces between the gripping pair, raised by the
   grip force and friction cone check (:mod:`~graspgait_env.sim.servo`, 7.4.3-7.4.4),
   inside the servo loop;
3. object tracking: the object localizer (:mod:`~graspgait_env.sim.localizer`) runs
   whenever three fingers touch (a probe before the first grasp, every regrasp, and
   after rotations with a stabilization finger); its position error is tracked
   (and recentred beyond 1/4 in) and its orientation error folded into the next
   rotation (thesis 7.4.5, 7.5).

Contact is detected from the servo forces alone. The controller sees only fingertip
positions and its own commanded forces; the ground-truth monitor
(:mod:`~graspgait_env.sim.monitor`) reads the true object pose and the contact sensors
only to *report* (drops, slips, errors). The parts share
:mod:`~graspgait_env.sim.state` and :mod:`~graspgait_env.sim.frames` and never import
one another.

One move at a time, for a Gymnasium env::

    ex = GaitExecutor("ellipse", mu=0.7)
    report = ex.reset({1: 34.0, 2: 208.0})          # the plan's grasp step
    report = ex.execute({"op": "rotate", "delta": 2.0})
    report = ex.execute({"op": "regrasp", "contacts": {"1": 34.0, "3": 238.0}})
    report.status, report.pose_estimate

Rolling: a fingertip ball that cannot spin rolls on the object (thesis 7.2): its
contact moves back along the contour as the object turns, ``rho theta`` on a flat edge,
and on a circle the object turns ``(1 + rho / r)`` times as far as the fingers' arcs
(``rho`` the ball radius, ``r`` the contact radius: ~1/10 extra). With
``rolling_compensation`` on, the fingers follow the paths of their rolling balls
(:func:`graspgait_env.contact_model.rolling_contacts_deg`), so that the object turns as
planned; off, rigid arcs (the thesis, which neglected the rolling).

Friction: the contacts' true friction is the plan's ``mu`` unless ``finger_mu`` sets
another; the grip force and friction cone check (7.4.4) uses a cone narrowed by the
hand's friction margin (:func:`check_cone_mu`) unless ``cone_mu`` sets one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.objects import OBJECT_DEFAULTS, load_object_physical
from graspgait_env.shapes import Shape
from graspgait_env.sim.config import SimConfig, load_sim_config
from graspgait_env.sim.model import HandPhysics, SimModel, build_model
from graspgait_env.sim.monitor import GroundTruthMonitor, MonitorSnapshot
from graspgait_env.sim.moves import MoveSequencer, contact_angles_deg, load_localizer
from graspgait_env.sim.servo_loop import ServoLoop
from graspgait_env.sim.state import ControllerState, MoveOutcome, StepReport
from graspgait_env.workspace import DEFAULT_WORKSPACES_DEG

__all__ = ["GaitExecutor", "StepReport", "contact_angles_deg", "load_localizer",
           "random_pose_perturbation", "PERTURBATION_MAX_OFFSET_M",
           "PERTURBATION_MAX_ANGLE_DEG", "THESIS_MU", "check_cone_mu"]

THESIS_MU = 0.7  # friction coefficient of the thesis experiments' plans (thesis 7.5)
PERTURBATION_MAX_OFFSET_M = 0.006  # (m) random placement error: an object "placed
# approximately at the center" (thesis 7.2), within the 1/4 in that needs no recentring
PERTURBATION_MAX_ANGLE_DEG = 5.0  # (deg) random placement error in angle


def check_cone_mu(shape: Shape, plan_mu: float, config: SimConfig, mass: float) -> float:
    """The friction coefficient of the grip force and friction cone check (thesis 7.4.4:
    "the friction cone angle, which is an input into the program") when
    ``config.cone_mu`` is None: the plan's cone narrowed by the hand's friction margin,
    ``tan(atan(plan_mu) - margin)``, with ``margin`` the lean of a finger's force while
    it carries a rotation's load across the object's shortest antipodal chord ``2
    r_min`` (:meth:`ContactModel.margin_deg
    <graspgait_env.contact_model.ContactModel.margin_deg>` of the hand's model; at
    least half the cone is kept).

    The check raises the grip only once a finger's commanded force has left its cone.
    At the planning friction, a cone as wide as the true one fires when the contact is
    already sliding: a 4 N tug across the circle's grip (3 N above what the nominal
    grip holds) dropped it with the grip at 3.3 N; with the narrowed cone (0.55 for the
    circle at mu 0.7) the grip rises in time and 5 N hold (tests/sim).
    """
    from graspgait_env.contact_model import hand_contact_model

    margin = hand_contact_model(shape, config, mass_kg=mass).margin_deg(2.0 * shape.r_min)
    half = math.atan(plan_mu)
    return math.tan(max(half - math.radians(float(margin)), 0.5 * half))


def random_pose_perturbation(rng: np.random.Generator,
                             max_offset: float = PERTURBATION_MAX_OFFSET_M,
                             max_angle_deg: float = PERTURBATION_MAX_ANGLE_DEG
                             ) -> tuple[float, float, float]:
    """A random initial pose error ``(dx, dy, dtheta_deg)``: offset uniform in a disc of
    radius ``max_offset`` (m), angle uniform in ``[-max_angle_deg, max_angle_deg]``."""
    r = max_offset * math.sqrt(rng.uniform())
    a = rng.uniform(0.0, 2 * math.pi)
    return (r * math.cos(a), r * math.sin(a), float(rng.uniform(-max_angle_deg, max_angle_deg)))


class GaitExecutor:
    """Execute gait moves on the simulated hand with the thesis controller (ch. 7).

    Parameters
    ----------
    shape
        Object: a bundled name, a YAML path or a :class:`~graspgait_env.shapes.Shape`.
    mu
        The friction coefficient the plan was made with (``plan.mu``, default 0.7): the
        friction cone check narrows it (:func:`check_cone_mu`) unless ``config.cone_mu``
        is set, and the physics
        too unless ``config.finger_mu`` sets the contacts' true friction.
    config
        A :class:`SimConfig`, a YAML path, or None for ``configs/sim/default.yaml``.
    workspaces_deg
        The hand's finger workspaces (deg, frame F); default the thesis hand.
    frame_callback
        Called as ``frame_callback(physics)`` every ``1 / video_fps`` simulated seconds
        (video recording).
    mass, thickness
        The object's mass (kg) and prism height (m); default the object file's (or
        ``config.object_mass``).

    Attributes
    ----------
    physics
        The :class:`~graspgait_env.sim.model.HandPhysics` accessor.
    state
        The controller's :class:`~graspgait_env.sim.state.ControllerState`.
    moves
        The move sequences (:class:`~graspgait_env.sim.moves.MoveSequencer`, 7.4.2).
    loop
        The servo loop (:class:`~graspgait_env.sim.servo_loop.ServoLoop`, 7.4.6).
    monitor
        The ground-truth monitor (:class:`~graspgait_env.sim.monitor.GroundTruthMonitor`).
    """

    def __init__(self, shape: Shape | str, *, mu: float | None = None,
                 config: SimConfig | str | None = None,
                 workspaces_deg: Sequence[tuple[float, float]] = DEFAULT_WORKSPACES_DEG,
                 frame_callback: Callable[[HandPhysics], None] | None = None,
                 mass: float | None = None, thickness: float | None = None) -> None:
        cfg = config if isinstance(config, SimConfig) else load_sim_config(config)
        self.config = cfg
        if isinstance(shape, Shape):
            self.shape = shape
            physical = {k: OBJECT_DEFAULTS[k] for k in ("thickness", "mass")}
        else:
            self.shape, physical = load_object_physical(shape)
        plan_mu = mu if mu is not None else THESIS_MU
        if not (isinstance(plan_mu, (int, float)) and math.isfinite(plan_mu) and plan_mu > 0):
            raise GraspGaitInputError(f"mu={mu!r}: the friction must be a number > 0")
        self.plan_mu = float(plan_mu)
        self.mu = float(cfg.finger_mu) if cfg.finger_mu is not None else self.plan_mu
        thickness = thickness if thickness is not None else physical["thickness"]
        mass = mass if mass is not None else (cfg.object_mass or physical["mass"])
        self.sim: SimModel = build_model(self.shape, mu=self.mu, thickness=thickness,
                                         mass=mass, config=cfg, workspaces_deg=workspaces_deg)
        self.physics = HandPhysics(self.sim)
        self.workspaces = self.sim.workspaces_deg
        self.zc = thickness / 2.0
        self.max_r = self.sim.max_r
        self.state = ControllerState(self.sim.home.copy())
        self.monitor = GroundTruthMonitor(self.physics, cfg, self.state)
        self.cone_mu = (cfg.cone_mu if cfg.cone_mu is not None
                        else check_cone_mu(self.shape, self.plan_mu, cfg, mass))
        self.loop = ServoLoop(self.physics, cfg, self.state, self.cone_mu, watch=self.monitor)
        self.loop.frame_callback = frame_callback
        self.moves = MoveSequencer(self.shape, cfg, self.physics, self.state, self.loop,
                                   self.workspaces, self.max_r, self.zc,
                                   load_localizer(self.shape, cfg))
        self._reset_state()

    @classmethod
    def for_plan(cls, plan, config: SimConfig | str | None = None, **kwargs) -> GaitExecutor:
        """An executor for a :class:`~graspgait_env.plan.Plan`: its object, its ``mu``
        (for the friction cone check), its hand's workspaces and its largest rotation
        (where a stabilization finger waits)."""
        ex = cls(plan.object, mu=plan.mu, config=config,
                 workspaces_deg=[tuple(w) for w in plan.workspaces_deg], **kwargs)
        deltas = [abs(float(st["delta"])) for st in plan.steps if st.get("op") == "rotate"]
        ex.max_rotation_deg = max(deltas) if deltas else None
        return ex

    # ------------------------------------------------------------------ state
    def _reset_state(self) -> None:
        self.state.clear(self.sim.home)
        self.monitor.clear()
        self.loop.disturbance_fn = None
        self.loop.next_frame = 0.0

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self.physics.time

    @property
    def started(self) -> bool:
        """Whether a gait has begun (:meth:`reset`)."""
        return self.state.started

    @property
    def est(self) -> NDArray[np.float64]:
        """The controller's pose estimate ``(x, y, theta_deg)`` (the array itself)."""
        return self.state.est

    @property
    def held(self) -> dict[int, float]:
        """Gripping fingers (0-based) -> planned contact angle (deg, frame f)."""
        return self.state.held

    @property
    def stabilizer(self) -> int | None:
        """The free finger riding on the object (7.4.2), or None."""
        return self.state.stabilizer

    @property
    def trace(self) -> list[tuple[str, float]]:
        """``(trajectory name, simulated start time)`` of every trajectory run."""
        return self.state.trace

    @property
    def theta_true(self) -> float:
        """True object angle (deg), unwrapped since the reset (monitoring)."""
        return self.monitor.theta_true

    @property
    def dropped(self) -> bool:
        """Whether the monitor found the object dropped."""
        return self.monitor.dropped

    @property
    def drop_reason(self) -> str:
        """Why the monitor declared a drop ("" when none)."""
        return self.monitor.drop_reason

    @property
    def max_rotation_deg(self) -> float | None:
        """The gait's largest rotation (deg), where a stabilization finger waits."""
        return self.moves.max_rotation_deg

    @max_rotation_deg.setter
    def max_rotation_deg(self, value: float | None) -> None:
        self.moves.max_rotation_deg = value

    @property
    def frame_callback(self) -> Callable[[HandPhysics], None] | None:
        """Called as ``frame_callback(physics)`` every ``1 / video_fps`` simulated s."""
        return self.loop.frame_callback

    @frame_callback.setter
    def frame_callback(self, cb: Callable[[HandPhysics], None] | None) -> None:
        self.loop.frame_callback = cb

    @property
    def disturbance_fn(self) -> Callable[[float], tuple[float, float]] | None:
        """The pull on the object (:meth:`set_disturbance`), or None."""
        return self.loop.disturbance_fn

    def true_pose(self) -> tuple[float, float, float]:
        """True object pose with theta unwrapped since the reset (monitoring)."""
        return self.monitor.true_pose()

    def pose_estimate(self) -> tuple[float, float, float]:
        """The controller's pose estimate ``(x, y, theta_deg)``."""
        return self.state.pose_estimate()

    def tips_in_object_frame(self) -> NDArray[np.float64]:
        """``(3, 2)`` fingertip centres in the TRUE object frame (m; monitoring only)."""
        return self.monitor.tips_in_object_frame()

    def probe_angles_deg(self, step_deg: float | None = None,
                         vertex_clearance_deg: float | None = None) -> list[float]:
        """F angles at which the probe touches the object, one per finger
        (:meth:`graspgait_env.sim.moves.MoveSequencer.probe_angles_deg`)."""
        return self.moves.probe_angles_deg(step_deg, vertex_clearance_deg)

    def set_disturbance(self, force: Callable[[float], tuple[float, float]] | None) -> None:
        """Pull on the object: ``force(t)`` gives the horizontal force (N, frame F) at
        simulated time ``t``, applied at its centre of mass every servo cycle (a tug,
        thesis 7.5); None removes it."""
        self.loop.disturbance_fn = force
        if force is None:
            self.physics.apply_object_force((0.0, 0.0))

    # ------------------------------------------------------------------ reports
    def _report(self, out: MoveOutcome, start: MonitorSnapshot) -> StepReport:
        """The step report: the controller's account plus the monitor's ground truth."""
        slips, max_slip = self.monitor.slips(start, out.slip_fingers)
        touching = self.monitor.touching()
        x, y, _ = self.physics.object_pose()
        return StepReport(
            out.op, out.status, self.state.pose_estimate(), (x, y, self.monitor.theta_true),
            self.physics.time - out.t0, max_slip, slips, self.state.grip_now(), touching,
            out.localized, out.rms, out.message, out.trajectories)

    # ------------------------------------------------------------------ moves
    def reset(self, contacts: dict, *, pose_perturbation=None) -> StepReport:
        """Start a gait: object at the centre (plus ``pose_perturbation`` ``(dx, dy,
        dtheta_deg)``, unknown to the controller), fingers at home; with
        ``initial_probe`` the three fingers first touch the object and localize it;
        then the plan's initial grasp ``contacts`` (``{finger: phi_deg}``, fingers 1..3):
        both fingers arc at ``max_r`` to their angles on the estimated object and
        approach until contact, and the grip rises to its nominal value
        (:meth:`~graspgait_env.sim.moves.MoveSequencer.grasp`).
        """
        cfg = self.config
        phys = self.physics
        phys.reset()
        self._reset_state()
        dx, dy, dth = pose_perturbation if pose_perturbation is not None else (0.0, 0.0, 0.0)
        phys.set_object_pose(dx, dy, dth)
        phys.apply_object_force((0.0, 0.0))
        phys.set_finger_forces(np.zeros((3, 3)))
        phys.step(max(1, int(round(cfg.object_settle_time / cfg.timestep))))
        self.monitor.start()
        self.loop.reset()
        self.state.started = True
        start = self.monitor.snapshot(measure_slip=False)
        return self._report(self.moves.grasp(contacts), start)

    def execute(self, step: dict) -> StepReport:
        """Execute one plan step (``grasp``, ``rotate`` or ``regrasp``, docs/formats.md)."""
        op = step.get("op")
        if op == "grasp":
            return self.reset(step["contacts"])
        if not self.started:
            raise GraspGaitInputError("execute: call reset() (the plan's grasp step) first")
        if self.dropped:
            return self._report(
                MoveOutcome(op, "dropped", self.time,
                            message=f"the object was dropped earlier: {self.drop_reason}"),
                self.monitor.snapshot(measure_slip=False))
        if op == "rotate":
            return self.rotate(float(step["delta"]))
        if op == "regrasp":
            return self.regrasp(step["contacts"])
        raise GraspGaitInputError(f"step op {op!r}: use grasp, rotate or regrasp")

    def hold(self, duration: float) -> StepReport:
        """Servo the fingers in place for ``duration`` (s), the grip and its check on."""
        if not self.started:
            raise GraspGaitInputError("hold: call reset() (the plan's grasp step) first")
        start = self.monitor.snapshot()
        return self._report(self.moves.hold(duration), start)

    def rotate(self, delta_deg: float) -> StepReport:
        """Rotate the object by ``delta_deg`` (CCW positive) with the gripping pair
        (:meth:`~graspgait_env.sim.moves.MoveSequencer.rotate`)."""
        start = self.monitor.snapshot()
        return self._report(self.moves.rotate(delta_deg), start)

    def regrasp(self, contacts: dict) -> StepReport:
        """Regrasp (thesis 7.4.2 transition) to ``contacts``
        (:meth:`~graspgait_env.sim.moves.MoveSequencer.regrasp`)."""
        start = self.monitor.snapshot()
        return self._report(self.moves.regrasp(contacts), start)
