"""The thesis controller executing a gait one move at a time (thesis 7.3-7.4).

:class:`GaitExecutor` owns a MuJoCo model of the hand and object and runs the three
controller processes of thesis 7.3 on it:

1. finger positioning: the trajectory planner (:mod:`~graspgait_env.sim.trajectory`)
   turns each move into trajectories; the PD servo (:class:`~graspgait_env.sim.servo.PDServo`)
   tracks them at the servo rate, the motor forces held between servo cycles;
2. grasp maintenance: internal grip forces between the gripping pair
   (:func:`~graspgait_env.sim.servo.internal_forces`), raised by the grip force and
   friction cone check (:class:`~graspgait_env.sim.servo.GripCheck`);
3. object tracking: the object localizer (:mod:`graspgait_env.sim.localizer`) runs
   whenever three fingers touch (a probe before the first grasp, every regrasp, and
   after rotations with a stabilization finger); its position error is tracked
   (and recentred beyond 1/4 in) and its orientation error folded into the next
   rotation (thesis 7.4.5, 7.5).

Contact is detected from the servo forces alone (:class:`~graspgait_env.sim.servo.ContactDetector`).
The controller sees only fingertip positions and its own commanded forces; the true
object pose and the contact sensors are read only to *report* (drops, slips, errors).

One move at a time, for a Gymnasium env::

    ex = GaitExecutor("ellipse", mu=0.7)
    report = ex.reset({1: 34.0, 2: 208.0})          # the plan's grasp step
    report = ex.execute({"op": "rotate", "delta": 2.0})
    report = ex.execute({"op": "regrasp", "contacts": {"1": 34.0, "3": 238.0}})
    report.status, report.pose_estimate

Rolling: a fingertip ball that cannot spin rolls on the object, which then turns
``(1 + rho / r)`` times as far as the fingers' arcs (thesis 7.2, ``rho`` the ball
radius, ``r`` the contact radius: ~1/10 extra). With ``rolling_compensation`` on, the
trajectory planner shortens the arcs by that factor so the object turns as planned.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.objects import load_object_physical
from graspgait_env.shapes import Shape
from graspgait_env.sim import trajectory as tj
from graspgait_env.sim.config import SimConfig, load_sim_config
from graspgait_env.sim.model import HandPhysics, SimModel, build_model
from graspgait_env.sim.servo import ContactDetector, GripCheck, PDServo, internal_forces
from graspgait_env.sim.trajectory import CONTACT, FREE, HOLD, TRANSITION, pair_index

__all__ = ["GaitExecutor", "StepReport", "contact_angles_deg", "load_localizer",
           "random_pose_perturbation"]

_MONITOR_EVERY = 5  # servo cycles between ground-truth checks (drops, slips)
_SETTLE_PHYSICS_S = 0.05  # (s) physics settling of the object on the table at reset


def _wrap(a: float) -> float:
    return (a + 180.0) % 360.0 - 180.0


def random_pose_perturbation(rng: np.random.Generator, max_offset: float = 0.006,
                             max_angle_deg: float = 5.0) -> tuple[float, float, float]:
    """A random initial pose error ``(dx, dy, dtheta_deg)``: offset uniform in a disc of
    radius ``max_offset`` (m), angle uniform in ``[-max_angle_deg, max_angle_deg]``."""
    r = max_offset * math.sqrt(rng.uniform())
    a = rng.uniform(0.0, 2 * math.pi)
    return (r * math.cos(a), r * math.sin(a), float(rng.uniform(-max_angle_deg, max_angle_deg)))


def contact_angles_deg(shape: Shape, tips_xy: NDArray[np.float64], pose: NDArray[np.float64],
                       tip_radius: float, iterations: int = 2) -> NDArray[np.float64]:
    """Object-frame polar angles (deg) of the contacts of ball tips at ``tips_xy`` (k, 2)
    on the object at ``pose`` ``(x, y, theta_deg)``: the tip centre moved ``tip_radius``
    along the inward normal (fixed-point iteration on the angle)."""
    th = math.radians(pose[2])
    c, s = math.cos(th), math.sin(th)
    d = np.asarray(tips_xy, dtype=float) - np.asarray(pose[:2], dtype=float)
    q = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)
    phi = np.degrees(np.arctan2(q[:, 1], q[:, 0]))
    for _ in range(iterations):
        p = q + tip_radius * shape.inward_normal(phi)
        phi = np.degrees(np.arctan2(p[:, 1], p[:, 0]))
    return phi


def load_localizer(shape: Shape, config: SimConfig):
    """The object localizer of thesis 7.4.5 for ``shape``, or None when it is off or
    not installed: a callable ``(tips_xy (k, 2), expected_pose) -> result`` whose
    result has ``.pose`` ``(x, y, theta_deg)`` (``graspgait_env.sim.localizer``)."""
    if not config.localizer:
        return None
    try:
        from graspgait_env.sim.localizer import LocalizerConfig, ObjectLocalizer
    except ImportError:  # pragma: no cover - the localizer ships with the package
        return None
    loc = ObjectLocalizer(shape, LocalizerConfig(
        tip_radius=config.tip_radius, allowable_error=config.recenter_distance,
        prior_weight=config.localizer_prior_weight))
    return loc.localize


@dataclass
class StepReport:
    """What one move did.

    Attributes
    ----------
    op
        ``grasp``, ``rotate`` or ``regrasp``.
    status
        ``ok``, ``dropped`` (the object left the grasp) or ``no-contact`` (a finger
        reached the end of its approach without detecting the object).
    pose_estimate
        The controller's object pose ``(x, y, theta_deg)`` after the move (frame F;
        theta unwrapped, continuous over the gait).
    pose_true
        The true pose after the move (monitoring only; theta unwrapped).
    sim_time_s
        Simulated time the move took (s).
    max_slip_m
        Largest sliding of a held contact along the object during the move (m),
        beyond the rolling of the ball tip.
    slips
        Held contacts that slid more than ``slip_threshold``.
    grip_n
        Pair grip forces at the end (N), pairs (1,2), (1,3), (2,3).
    touching
        Fingers (1..3) that truly touch the object at the end.
    localized
        Whether the object localizer ran; ``localizer_rms_m`` its fit residual (m).
    message
        Details for a status other than ``ok``.
    """

    op: str
    status: str
    pose_estimate: tuple[float, float, float]
    pose_true: tuple[float, float, float]
    sim_time_s: float
    max_slip_m: float = 0.0
    slips: int = 0
    grip_n: tuple[float, float, float] = (0.0, 0.0, 0.0)
    touching: tuple[int, ...] = ()
    localized: bool = False
    localizer_rms_m: float = float("nan")
    message: str = ""
    trajectories: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when the move completed with the object held."""
        return self.status == "ok"

    def to_dict(self) -> dict[str, Any]:
        """Plain-type mapping (JSON-ready)."""
        return asdict(self)


class _Abort(Exception):
    """Raised inside a trajectory when the monitor finds the object dropped."""


class GaitExecutor:
    """Execute gait moves on the simulated hand with the thesis controller (ch. 7).

    Parameters
    ----------
    shape
        Object: a bundled name, a YAML path or a :class:`~graspgait_env.shapes.Shape`.
    mu
        The friction coefficient the plan was made with (``plan.mu``, default 0.7): the
        friction cone check uses it unless ``config.cone_mu`` is set, and the physics
        too unless ``config.finger_mu`` sets the contacts' true friction.
    config
        A :class:`SimConfig`, a YAML path, or None for ``configs/sim/default.yaml``.
    workspaces_deg
        The hand's finger workspaces (deg, frame F); default the thesis hand.
    frame_callback
        Called as ``frame_callback(physics)`` every ``1 / video_fps`` simulated seconds
        (video recording).

    Attributes
    ----------
    physics
        The :class:`~graspgait_env.sim.model.HandPhysics` accessor.
    """

    def __init__(self, shape: Shape | str, *, mu: float | None = None,
                 config: SimConfig | str | None = None,
                 workspaces_deg=((0.0, 90.0), (120.0, 210.0), (240.0, 330.0)),
                 frame_callback: Callable[[HandPhysics], None] | None = None,
                 mass: float | None = None, thickness: float | None = None) -> None:
        cfg = config if isinstance(config, SimConfig) else load_sim_config(config)
        self.config = cfg
        if isinstance(shape, Shape):
            self.shape, physical = shape, {"thickness": 0.02, "mass": 0.1}
        else:
            self.shape, physical = load_object_physical(shape)
        plan_mu = mu if mu is not None else 0.7
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
        self.frame_callback = frame_callback
        self.dt = cfg.servo_dt
        self.servo = PDServo([cfg.kp, cfg.kp, cfg.kp_z], [cfg.kv, cfg.kv, cfg.kv_z],
                             cfg.velocity_alpha, self.dt)
        cone_mu = cfg.cone_mu if cfg.cone_mu is not None else self.plan_mu
        self.check = GripCheck(cfg.grip_force, cfg.settle, cfg.grip_saturation, cone_mu)
        self.detector = ContactDetector(cfg.contact_threshold, cfg.contact_cycles)
        self.localizer = load_localizer(self.shape, cfg)
        self.max_rotation_deg: float | None = None  # largest rotation of the gait (deg)
        self.zc = thickness / 2.0
        self.max_r = self.sim.max_r
        self.started = False
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
        self.xd = self.sim.home.copy()  # last desired tip positions (3, 3)
        self.adjust = [0.0, 0.0, 0.0]  # grip added by the check, per pair (N)
        self.grip = np.zeros(3)  # scheduled grip per pair (N)
        self.held: dict[int, float] = {}  # finger (0-based) -> planned contact (deg, f)
        self.est = np.zeros(3)  # estimated pose (x, y, theta_deg unwrapped)
        self.theta_goal = 0.0  # planned object angle so far (deg)
        self.dropped = False
        self.drop_reason = ""
        self.theta_true = 0.0  # unwrapped true angle
        self._theta_wrapped = 0.0
        self._lost_since: float | None = None
        self._next_frame = 0.0
        self.stabilizer: int | None = None  # free finger riding on the object (7.4.2)
        self.disturbance_fn: Callable[[float], tuple[float, float]] | None = None
        self.trace: list[tuple[str, float]] = []

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self.physics.time

    def true_pose(self) -> tuple[float, float, float]:
        """True object pose with theta unwrapped since the reset (monitoring)."""
        x, y, _ = self.physics.object_pose()
        return (x, y, self.theta_true)

    def pose_estimate(self) -> tuple[float, float, float]:
        """The controller's pose estimate ``(x, y, theta_deg)``."""
        return (float(self.est[0]), float(self.est[1]), float(self.est[2]))

    def set_disturbance(self, force: Callable[[float], tuple[float, float]] | None) -> None:
        """Pull on the object: ``force(t)`` gives the horizontal force (N, frame F) at
        simulated time ``t``, applied at its centre of mass every servo cycle (a tug,
        thesis 7.5); None removes it."""
        self.disturbance_fn = force
        if force is None:
            self.physics.apply_object_force((0.0, 0.0))

    # ------------------------------------------------------------------ geometry
    def _normals(self, fingers: list[int]) -> NDArray[np.float64]:
        """Inward normals (3, 2), frame F, at the estimated contacts of ``fingers``."""
        nr = np.zeros((3, 2))
        if not fingers:
            return nr
        tips = self.physics.tip_positions()[fingers, :2]
        phi = contact_angles_deg(self.shape, tips, self.est, self.config.tip_radius)
        n = self.shape.inward_normal(phi)
        th = math.radians(self.est[2])
        c, s = math.cos(th), math.sin(th)
        nr[fingers] = np.stack([c * n[:, 0] - s * n[:, 1], s * n[:, 0] + c * n[:, 1]], axis=1)
        return nr

    def _ball_target(self, phi_deg: float) -> NDArray[np.float64]:
        """Ball-centre point (3,) touching the contour at ``phi_deg`` on the estimated object."""
        p = self.shape.contour_point(phi_deg)
        n_out = -self.shape.inward_normal(phi_deg)
        b = p + self.config.tip_radius * n_out
        th = math.radians(self.est[2])
        c, s = math.cos(th), math.sin(th)
        return np.array([self.est[0] + c * b[0] - s * b[1], self.est[1] + s * b[0] + c * b[1],
                         self.zc])

    def _grip_vector(self, pair: tuple[int, int] | None, g: float) -> NDArray[np.float64]:
        v = np.zeros(3)
        if pair is not None:
            v[pair_index(*pair)] = g
        return v

    @staticmethod
    def _kinds(hold=(), transition=(), contact=()) -> NDArray[np.int64]:
        """Trajectory type per finger (thesis 7.4.2); fingers not named are FREE."""
        k = np.full(3, FREE)
        k[list(hold)] = HOLD
        k[list(transition)] = TRANSITION
        k[list(contact)] = CONTACT
        return k

    def _fold_grip(self) -> NDArray[np.float64]:
        """Scheduled grip plus the check's increases, fed back to the trajectory
        planner so the grip is continuous into the next trajectory (7.4.2)."""
        g = self.grip + np.asarray(self.adjust)
        self.adjust[:] = [0.0, 0.0, 0.0]
        return g

    # ------------------------------------------------------------------ inner loop
    def _run(self, tr: tj.Trajectory, stop_on_contact: bool = False) -> list[bool]:
        """Servo along ``tr``; returns, per finger, whether it detected contact.

        Fingers of trajectory type CONTACT stop where contact is detected: their
        desired point freezes (thesis 7.4.2), or, with ``stop_on_contact``, moves back
        to the measured point so that the finger stops pushing; the trajectory ends when
        every such finger has touched, or at its end. The motor forces computed in a
        servo cycle are held for ``servo_decimation`` physics steps.
        """
        cfg = self.config
        phys = self.physics
        xd_all, vd_all, g_all, n_all = tr.sample(self.dt)
        M = len(xd_all)
        xdl = xd_all.reshape(M, 9).tolist()
        vdl = vd_all.reshape(M, 9).tolist()
        gl = g_all.tolist()
        nl = n_all.reshape(M, 6).tolist()
        kind = tr.kind.tolist()
        armed = [k == CONTACT for k in kind]
        detecting = any(armed)
        directions: list[tuple[float, float] | None] = [None, None, None]
        if detecting:  # approach direction of each armed finger (its straight path)
            for f in range(3):
                d = xd_all[-1, f, :2] - xd_all[0, f, :2]
                n = math.hypot(d[0], d[1])
                if armed[f] and n > 0:
                    directions[f] = (float(d[0] / n), float(d[1] / n))
        detected = [False, False, False]
        frozen: list[float] = [0.0] * 9
        self.detector.reset()
        check = self.check if cfg.grip_check else None
        adjust = self.adjust
        dec = cfg.servo_decimation
        cb = self.frame_callback
        disturb = self.disturbance_fn
        frame_dt = 1.0 / cfg.video_fps
        servo_cycle = self.servo.cycle
        tips = phys.tip_positions_flat
        set_forces = phys.set_finger_forces_flat
        step = phys.step
        detector = self.detector
        xd = xdl[0]
        self.trace.append((tr.name, phys.time))
        for m in range(M):
            x = tips()
            xd = xdl[m]
            vd = vdl[m]
            if detecting and (detected[0] or detected[1] or detected[2]):
                xd = list(xd)
                vd = list(vd)
                for f in range(3):
                    if detected[f]:
                        xd[3 * f:3 * f + 3] = frozen[3 * f:3 * f + 3]
                        vd[3 * f:3 * f + 3] = (0.0, 0.0, 0.0)
            fs = servo_cycle(x, xd, vd)
            g = gl[m]
            if adjust[0] or adjust[1] or adjust[2]:
                g = [g[0] + adjust[0], g[1] + adjust[1], g[2] + adjust[2]]
            fg, u = internal_forces(x, g)
            ft = [a + b for a, b in zip(fs, fg, strict=True)]
            if check is not None:
                inc = check(ft, u, g, nl[m], kind)
                adjust[0] += inc[0]
                adjust[1] += inc[1]
                adjust[2] += inc[2]
            set_forces(ft)
            if disturb is not None:
                phys.apply_object_force(disturb(phys.time))
            step(dec)
            if detecting:
                new = detector.update(fs, [armed[f] and not detected[f] for f in range(3)],
                                      directions)
                if new[0] or new[1] or new[2]:
                    src = tips() if stop_on_contact else xd
                    for f in range(3):
                        if new[f]:
                            frozen[3 * f:3 * f + 3] = src[3 * f:3 * f + 3]
                            detected[f] = True
                    if all(detected[f] for f in range(3) if armed[f]):
                        break
            if m % _MONITOR_EVERY == 0:
                self._monitor()
            if cb is not None and phys.time >= self._next_frame:
                cb(phys)
                self._next_frame += frame_dt
        xd = list(xd)
        for f in range(3):
            if detected[f]:
                xd[3 * f:3 * f + 3] = frozen[3 * f:3 * f + 3]
        self.xd = np.array(xd, dtype=float).reshape(3, 3)
        self.grip = np.array(gl[m], dtype=float)
        self._monitor()
        return detected

    def _approach(self, fingers: list[int], targets, grip, normals, hold: list[int],
                  names: list[str], stop_on_contact: bool = False) -> list[bool]:
        """Run the approach lines of ``fingers`` (fast, then slow with contact detection)."""
        cfg = self.config
        det = [False, False, False]
        for tr in tj.approach(self.xd, fingers, targets, grip, normals, res=cfg.res,
                              speed=cfg.free_speed, approach_speed=cfg.approach_speed,
                              standoff=cfg.standoff, overshoot=cfg.overshoot,
                              accel=cfg.free_accel, approach_accel=cfg.approach_accel,
                              hold=hold):
            names.append(tr.name)
            det = self._run(tr, stop_on_contact=stop_on_contact)
        return det

    def _monitor(self) -> None:
        """Ground-truth checks (not seen by the controller): unwrapped angle, drops."""
        phys = self.physics
        x, y, th = phys.object_pose()
        self.theta_true += _wrap(th - self._theta_wrapped)
        self._theta_wrapped = th
        if self.dropped or not self.started or len(self.held) != 2:
            return  # a drop needs a grasp to lose
        cfg = self.config
        reason = ""
        if math.hypot(x, y) > cfg.drop_distance:
            reason = f"object {1e3 * math.hypot(x, y):.0f} mm from the centre"
        elif phys.object_tilt_deg() > 20.0:
            reason = "object tipped over"
        else:
            touch = phys.tip_in_contact()
            n = sum(bool(touch[f]) for f in self.held)
            if n < 2:
                if self._lost_since is None:
                    self._lost_since = phys.time
                elif phys.time - self._lost_since > cfg.lost_contact_time:
                    reason = (f"{2 - n} gripping finger(s) off the object for more than "
                              f"{cfg.lost_contact_time:g} s")
            else:
                self._lost_since = None
        if reason:
            self.dropped = True
            self.drop_reason = reason
            raise _Abort(reason)

    # ------------------------------------------------------------------ helpers
    def tips_in_object_frame(self) -> NDArray[np.float64]:
        """``(3, 2)`` fingertip centres in the TRUE object frame (m; monitoring only)."""
        x, y, th = self.physics.object_pose()
        t = math.radians(th)
        c, s = math.cos(t), math.sin(t)
        d = self.physics.tip_positions()[:, :2] - np.array([x, y])
        return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)

    def _report(self, op: str, status: str, t0: float, tips0, theta0: float,
                fingers: list[int], localized: bool = False, rms: float = float("nan"),
                message: str = "", names: list[str] | None = None) -> StepReport:
        cfg = self.config
        slips, max_slip = 0, 0.0
        if tips0 is not None and fingers:
            tips1 = self.tips_in_object_frame()
            roll = cfg.tip_radius * abs(math.radians(self.theta_true - theta0))
            for f in fingers:
                r = float(np.hypot(*tips1[f]))
                d = float(np.hypot(*(tips1[f] - tips0[f])))
                slip = max(0.0, d - roll * (1.0 + cfg.tip_radius / max(r, 1e-9)))
                max_slip = max(max_slip, slip)
                slips += slip > cfg.slip_threshold
        touch = self.physics.tip_in_contact()
        x, y, _ = self.physics.object_pose()
        return StepReport(
            op, status, self.pose_estimate(), (x, y, self.theta_true),
            self.physics.time - t0, max_slip, int(slips),
            tuple(float(g) for g in self.grip + np.asarray(self.adjust)),
            tuple(f + 1 for f in range(3) if touch[f]), localized, rms, message,
            names or [])

    def _localize(self, fingers: list[int], assume_on: bool = False) -> tuple[bool, float]:
        """Run the object localizer (thesis 7.4.5) and take its pose as the estimate.

        Only fingers the controller believes on the object take part: the gripping
        pair, and any other finger still pushing (total commanded force above the
        contact threshold; a finger that lost contact has servoed to its desired point
        and pushes nothing). Three are needed to observe the pose; with fewer the
        estimate is kept. ``assume_on``: take all ``fingers`` as touching (the probe,
        whose fingers all detected contact). Returns whether it ran and its rms fit
        residual (m).
        """
        if self.localizer is None:
            return False, float("nan")
        f_cmd = self.physics.finger_forces()
        on = [f for f in fingers
              if assume_on or f in self.held
              or math.hypot(*f_cmd[f, :2]) > self.config.contact_threshold]
        if len(on) < 3:
            return False, float("nan")
        tips = self.physics.tip_positions()[on, :2]
        res = self.localizer(tips, tuple(self.est))
        self.est = np.array(res.pose, dtype=float)
        return True, float(getattr(res, "rms_error", float("nan")))

    # ------------------------------------------------------------------ moves
    def reset(self, contacts: dict, *, pose_perturbation=None) -> StepReport:
        """Start a gait: object at the centre (plus ``pose_perturbation`` ``(dx, dy,
        dtheta_deg)``, unknown to the controller), fingers at home; with
        ``initial_probe`` the three fingers first touch the object and localize it
        (:meth:`_probe`); then the plan's initial grasp ``contacts`` (``{finger:
        phi_deg}``, fingers 1..3): both fingers arc at ``max_r`` to their angles on the
        estimated object and approach until contact, and the grip rises to its nominal
        value.
        """
        cfg = self.config
        phys = self.physics
        phys.reset()
        self._reset_state()
        dx, dy, dth = pose_perturbation if pose_perturbation is not None else (0.0, 0.0, 0.0)
        phys.set_object_pose(dx, dy, dth)
        phys.apply_object_force((0.0, 0.0))
        phys.set_finger_forces(np.zeros((3, 3)))
        phys.step(max(1, int(round(_SETTLE_PHYSICS_S / cfg.timestep))))
        self._theta_wrapped = phys.object_pose()[2]
        self.theta_true = self._theta_wrapped
        self.servo.reset(phys.tip_positions_flat())
        self._next_frame = phys.time
        self.started = True
        t0 = phys.time
        held = self._parse_contacts(contacts)
        fingers = sorted(held)
        names: list[str] = []
        localized, rms = False, float("nan")
        try:
            if cfg.initial_probe:
                localized, rms = self._probe(names)
            targets = np.array([self._ball_target(held[f]) for f in fingers])
            ang = np.degrees(np.arctan2(targets[:, 1] - self.est[1], targets[:, 0] - self.est[0]))
            zero = np.zeros(3)
            tr = tj.free_arc(self.xd, fingers, self.est[:2], ang, self.max_r, zero,
                             np.zeros((3, 2)), res=cfg.res, speed=cfg.free_speed,
                             accel=cfg.free_accel,
                             workspaces=[self.workspaces[f] for f in fingers],
                             kind=self._kinds())
            names.append(tr.name)
            self._run(tr)
            det = self._approach(fingers, targets, zero, np.zeros((3, 2)), [], names)
            if not all(det[f] for f in fingers):
                miss = [f + 1 for f in fingers if not det[f]]
                return self._report("grasp", "no-contact", t0, None, 0.0, [],
                                    message=f"finger(s) {miss} found no object", names=names)
            self.held = held
            pair = (fingers[0], fingers[1])
            nr = self._normals(fingers)
            g1 = self._grip_vector(pair, cfg.grip_force)
            tr = tj.transfer(self.xd, zero, g1, nr, cfg.transfer_time,
                             kind=self._kinds(transition=fingers))
            names.append(tr.name)
            self._run(tr)
            tr = tj.hold(self.xd, self._fold_grip(), nr, cfg.settle_time, self._kinds(fingers))
            names.append(tr.name)
            self._run(tr)
            if cfg.stabilization_finger:
                ok, r2 = self._stabilize(names)
                localized, rms = (True, r2) if ok else (localized, rms)
        except _Abort as exc:
            return self._report("grasp", "dropped", t0, None, 0.0, [], localized=localized,
                                rms=rms, message=str(exc), names=names)
        return self._report("grasp", "ok", t0, None, 0.0, [], localized=localized, rms=rms,
                            names=names)

    def probe_angles_deg(self, step_deg: float = 4.0, vertex_clearance_deg: float = 8.0
                         ) -> list[float]:
        """F angles at which the probe touches the object, one per finger.

        Candidates every ``step_deg`` inside each finger's workspace (10° in from its
        ends), none within ``vertex_clearance_deg`` of a polygon vertex of the expected
        object; of all triples, the one whose contacts observe the pose best: the
        largest smallest singular value of the Jacobian of the three contact distances
        with respect to ``(x, y, r_mean * theta)`` (rows ``[n_x, n_y, (p x n)_z / r]``).
        Two fingers on parallel flats with the third beside them, for one, leave a
        direction (a slide combined with a turn) that the localizer cannot see.
        """
        shape = self.shape
        th = self.est[2]
        verts = getattr(shape, "vertex_angles_deg", None)
        r_mean = 0.5 * (shape.r_min + shape.r_max)
        rows, angs = [], []
        for lo, hi in self.workspaces:
            cand = np.arange(lo + 10.0, hi - 10.0 + 1e-9, step_deg)
            if cand.size == 0:
                cand = np.array([(lo + hi) / 2.0])
            phi = cand - th
            if verts is not None:
                d = (phi[:, None] - verts[None, :] + 180.0) % 360.0 - 180.0
                keep = np.abs(d).min(axis=1) >= vertex_clearance_deg
                if keep.any():
                    cand, phi = cand[keep], phi[keep]
            p = shape.contour_point(phi)
            n = shape.inward_normal(phi)
            torque = (p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0]) / r_mean
            rows.append(np.column_stack([n, torque]))
            angs.append(cand)
        J = (rows[0][:, None, None, :], rows[1][None, :, None, :], rows[2][None, None, :, :])
        J = np.stack(np.broadcast_arrays(*J), axis=-2)  # (a, b, c, 3, 3)
        smin = np.linalg.svd(J, compute_uv=False)[..., -1]
        i, j, k = np.unravel_index(int(np.argmax(smin)), smin.shape)
        return [float(angs[0][i]), float(angs[1][j]), float(angs[2][k])]

    def _probe(self, names: list[str]) -> tuple[bool, float]:
        """Before the first grasp, touch the object with all three fingers and localize
        it (7.4.5), so that the grasp lands on the planned contacts of an object placed
        only approximately (thesis 7.2); then the fingers retreat to ``max_r``."""
        cfg = self.config
        fingers = [0, 1, 2]
        zero = np.zeros(3)
        nz = np.zeros((3, 2))
        ang = self.probe_angles_deg()
        targets = np.array([self._ball_target(a - self.est[2]) for a in ang])
        ta = np.degrees(np.arctan2(targets[:, 1] - self.est[1], targets[:, 0] - self.est[0]))
        tr = tj.free_arc(self.xd, fingers, self.est[:2], ta, self.max_r, zero, nz,
                         res=cfg.res, speed=cfg.free_speed, accel=cfg.free_accel,
                         workspaces=list(self.workspaces), kind=self._kinds())
        names.append("probe_" + tr.name)
        self._run(tr)
        det = self._approach(fingers, targets, zero, nz, [], names, stop_on_contact=True)
        localized, rms = False, float("nan")
        if all(det):
            # each finger stopped where it touched; a light three-way internal force
            # (no net force on the object, 7.4.3) keeps all three on while it localizes
            g = np.full(3, cfg.probe_grip)
            tr = tj.transfer(self.xd, zero, g, nz, cfg.settle_time,
                             kind=self._kinds(transition=fingers))
            tr.name = "probe"
            names.append(tr.name)
            self._run(tr)
            localized, rms = self._localize(fingers, assume_on=True)
            self.grip = zero.copy()
        tr = tj.retreat(self.xd, fingers, self.est[:2], self.max_r, zero, nz, res=cfg.res,
                        speed=cfg.free_speed, accel=cfg.free_accel, kind=self._kinds())
        names.append(tr.name)
        self._run(tr)
        return localized, rms

    def _parse_contacts(self, contacts: dict) -> dict[int, float]:
        out: dict[int, float] = {}
        for f, phi in contacts.items():
            fi = int(f)
            if fi not in (1, 2, 3):
                raise GraspGaitInputError(f"contacts: finger {f!r}: fingers are 1, 2, 3")
            out[fi - 1] = float(phi)
        if len(out) != 2:
            raise GraspGaitInputError(f"contacts {contacts!r}: name exactly two fingers")
        return out

    def execute(self, step: dict) -> StepReport:
        """Execute one plan step (``grasp``, ``rotate`` or ``regrasp``, docs/formats.md)."""
        op = step.get("op")
        if op == "grasp":
            return self.reset(step["contacts"])
        if not self.started:
            raise GraspGaitInputError("execute: call reset() (the plan's grasp step) first")
        if self.dropped:
            return self._report(op, "dropped", self.time, None, 0.0, [],
                                message=f"the object was dropped earlier: {self.drop_reason}")
        if op == "rotate":
            return self.rotate(float(step["delta"]))
        if op == "regrasp":
            return self.regrasp(step["contacts"])
        raise GraspGaitInputError(f"step op {op!r}: use grasp, rotate or regrasp")

    def _stabilize(self, names: list[str]) -> tuple[bool, float]:
        """With ``stabilization_finger``, bring the free finger onto the object without a
        grip (thesis 7.4.2): at the middle of its workspace minus half of the largest
        rotation (``max_rotation_deg``), so that rotations keep it inside the workspace;
        then localize with all three fingers on."""
        cfg = self.config
        if not cfg.stabilization_finger or len(self.held) != 2 or self.stabilizer is not None:
            return False, float("nan")
        f = next(i for i in range(3) if i not in self.held)
        lo, hi = self.workspaces[f]
        max_rot = self.max_rotation_deg if self.max_rotation_deg is not None else (hi - lo) / 2
        a = min(max((lo + hi) / 2.0 - max_rot / 2.0, lo), hi)
        target = self._ball_target(a - self.est[2])
        ang = math.degrees(math.atan2(target[1] - self.est[1], target[0] - self.est[0]))
        held = sorted(self.held)
        nr = self._normals(held)
        tr = tj.free_arc(self.xd, [f], self.est[:2], [ang], self.max_r, self._fold_grip(), nr,
                         res=cfg.res, speed=cfg.free_speed, accel=cfg.free_accel,
                         workspaces=[self.workspaces[f]], kind=self._kinds(held))
        names.append("stabilizer_" + tr.name)
        self._run(tr)
        det = self._approach([f], target[None], self._fold_grip(), nr, held, names)
        if not det[f]:
            tr = tj.retreat(self.xd, f, self.est[:2], self.max_r, self._fold_grip(), nr,
                            res=cfg.res, speed=cfg.free_speed, accel=cfg.free_accel,
                            kind=self._kinds(held))
            self._run(tr)
            return False, float("nan")
        self.stabilizer = f
        return self._localize(held + [f])

    def _unstabilize(self, names: list[str]) -> None:
        """Take the stabilization finger off the object (outward to ``max_r``)."""
        f = self.stabilizer
        if f is None:
            return
        cfg = self.config
        held = sorted(self.held)
        tr = tj.retreat(self.xd, f, self.est[:2], self.max_r, self._fold_grip(),
                        self._normals(held), res=cfg.res, speed=cfg.free_speed,
                        accel=cfg.free_accel, kind=self._kinds(held))
        names.append("stabilizer_" + tr.name)
        self._run(tr)
        self.stabilizer = None

    def hold(self, duration: float) -> StepReport:
        """Servo the fingers in place for ``duration`` (s), the grip and its check on."""
        if not self.started:
            raise GraspGaitInputError("hold: call reset() (the plan's grasp step) first")
        t0 = self.time
        fingers = sorted(self.held)
        tips0 = self.tips_in_object_frame()
        theta0 = self.theta_true
        tr = tj.hold(self.xd, self._fold_grip(), self._normals(fingers), duration,
                     self._kinds(fingers))
        try:
            self._run(tr)
        except _Abort as exc:
            return self._report("hold", "dropped", t0, tips0, theta0, fingers,
                                message=str(exc), names=[tr.name])
        return self._report("hold", "ok", t0, tips0, theta0, fingers, names=[tr.name])

    def rotate(self, delta_deg: float) -> StepReport:
        """Rotate the object by ``delta_deg`` (CCW positive) with the gripping pair.

        The orientation error of the estimate (planned angle minus estimated angle) is
        added to the commanded rotation (thesis 7.4.5, 7.5); the fingers travel arcs
        about the estimated centre at their present radius (7.4.2).
        """
        cfg = self.config
        t0 = self.time
        fingers = sorted(self.held)
        tips0 = self.tips_in_object_frame()
        theta0 = self.theta_true
        cmd = delta_deg + (self.theta_goal - self.est[2])
        arc = cmd
        if cfg.rolling_compensation:
            tips = self.physics.tip_positions()[fingers, :2]
            phi = contact_angles_deg(self.shape, tips, self.est, cfg.tip_radius)
            r = float(np.mean(self.shape.radius(phi)))
            arc = cmd * r / (r + cfg.tip_radius)
        stab = [] if self.stabilizer is None else [self.stabilizer]
        tr = tj.rotation(self.xd, self.est[:2], arc, fingers + stab, self._fold_grip(),
                         self._normals(fingers),
                         res=cfg.res, speed_deg=cfg.rotation_speed_deg,
                         accel=cfg.rotation_accel,
                         max_speed=cfg.free_speed, kind=self._kinds(fingers, transition=stab))
        localized, rms = False, float("nan")
        try:
            self._run(tr)
            self.est[2] += cmd
            self.theta_goal += delta_deg
            if stab:  # three fingers on: localize after the rotation too (7.4.2, 7.4.5)
                localized, rms = self._localize(fingers + stab)
        except _Abort as exc:
            return self._report("rotate", "dropped", t0, tips0, theta0, fingers,
                                message=str(exc), names=[tr.name])
        return self._report("rotate", "ok", t0, tips0, theta0, fingers, localized=localized,
                            rms=rms, names=[tr.name])

    def regrasp(self, contacts: dict) -> StepReport:
        """Regrasp (thesis 7.4.2 transition): the new finger arcs at ``max_r`` to its
        contact and approaches until contact; the grip transfers from the old pair to
        the new with three fingers on (the localizer runs then); the old finger retreats
        to ``max_r``; the object is recentred if the estimate is off by > 1/4 in."""
        cfg = self.config
        t0 = self.time
        new = self._parse_contacts(contacts)
        kept = sorted(set(new) & set(self.held))
        if len(kept) != 1:
            raise GraspGaitInputError(
                f"regrasp {contacts!r}: must keep exactly one of the held fingers "
                f"{[f + 1 for f in sorted(self.held)]}")
        k = kept[0]
        n = next(f for f in new if f not in self.held)
        lifted = next(f for f in self.held if f != k)
        new_pair = (min(k, n), max(k, n))
        tips0 = self.tips_in_object_frame()
        theta0 = self.theta_true
        names: list[str] = []
        localized, rms = False, float("nan")
        try:
            self._unstabilize(names)  # 0. the stabilization finger leaves first (7.4.2)
            # 1. the new finger: arc at max_r to its angle, then in until contact
            g = self._fold_grip()
            nr = self._normals([k, lifted])
            target = self._ball_target(new[n])
            ang = math.degrees(math.atan2(target[1] - self.est[1], target[0] - self.est[0]))
            tr = tj.free_arc(self.xd, [n], self.est[:2], [ang], self.max_r, g, nr,
                             res=cfg.res, speed=cfg.free_speed, accel=cfg.free_accel,
                             workspaces=[self.workspaces[n]], kind=self._kinds([k, lifted]))
            names.append(tr.name)
            self._run(tr)
            det = self._approach([n], target[None], self._fold_grip(), nr, [k, lifted], names)
            if not det[n]:
                return self._report("regrasp", "no-contact", t0, tips0, theta0, [k, lifted],
                                    message=f"finger {n + 1} found no object", names=names)
            # 2. three fingers on: the grip moves from the old pair to the new
            nr = self._normals([k, lifted, n])
            g_new = self._grip_vector(new_pair, cfg.grip_force)
            tr = tj.transfer(self.xd, self._fold_grip(), g_new, nr, cfg.transfer_time,
                             kind=np.full(3, TRANSITION))
            names.append(tr.name)
            self._run(tr)
            self.held = {k: self.held[k], n: new[n]}
            tr = tj.hold(self.xd, self._fold_grip(), nr, cfg.settle_time,
                         self._kinds([k, n], transition=[lifted]))
            names.append(tr.name)
            self._run(tr)
            # 3. the object localizer, all three fingers on the object (7.4.5)
            localized, rms = self._localize([k, lifted, n])
            # 4. the old finger leaves along a line outward
            nr = self._normals([k, n])
            tr = tj.retreat(self.xd, lifted, self.est[:2], self.max_r, self._fold_grip(), nr,
                            res=cfg.res,
                            speed=cfg.free_speed, accel=cfg.free_accel,
                            kind=self._kinds([k, n]))
            names.append(tr.name)
            self._run(tr)
            # 5. recentre when the position error exceeds 1/4 in (7.5)
            err = -self.est[:2]
            if float(np.hypot(*err)) > cfg.recenter_distance:
                tr = tj.translate(self.xd, [k, n], err, self._fold_grip(), nr,
                                  res=cfg.res, speed=cfg.approach_speed * 2,
                                  accel=cfg.rotation_accel, kind=self._kinds([k, n]))
                names.append(tr.name)
                self._run(tr)
                self.est[:2] += err
            # 6. the lifted finger becomes the stabilization finger (7.4.2)
            if cfg.stabilization_finger:
                ok, r2 = self._stabilize(names)
                localized, rms = (True, r2) if ok else (localized, rms)
        except _Abort as exc:
            return self._report("regrasp", "dropped", t0, tips0, theta0, [k],
                                localized=localized, rms=rms, message=str(exc), names=names)
        return self._report("regrasp", "ok", t0, tips0, theta0, [k], localized=localized,
                            rms=rms, names=names)
