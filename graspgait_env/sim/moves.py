"""The controller's move sequences (thesis 7.4.2): each gait move as trajectories.

The trajectory planner of thesis 7.4.2 takes an initial grasp, a rotation or a
transition (a regrasp) and turns it into a sequence of trajectories
(:mod:`~graspgait_env.sim.trajectory`) that the servo loop tracks
(:mod:`~graspgait_env.sim.servo_loop`). :class:`MoveSequencer` holds those sequences:

- **initial grasp** (:meth:`MoveSequencer.grasp`): with ``initial_probe``, the three
  fingers first touch the object and the localizer finds it (:meth:`~MoveSequencer.probe`,
  aimed by :meth:`~MoveSequencer.probe_angles_deg`); then the two grasping fingers arc at
  ``max_r`` to their angles on the estimated object, approach until contact and the grip
  rises to its nominal value;
- **rotation** (:meth:`MoveSequencer.rotate`): the gripping fingers travel arcs about the
  estimated centre; the orientation error of the estimate is folded into the commanded
  angle (7.4.5, 7.5), and each finger follows the path of its rolling ball tip (7.2);
- **transition** (:meth:`MoveSequencer.regrasp`): the new finger arcs at ``max_r`` and
  approaches; the grip transfers from the old pair to the new with three fingers on
  (the localizer runs halfway, 7.4.5); the old finger retreats; the object is recentred
  when the estimate is off by more than 1/4 in (7.5); with ``stabilization_finger`` the
  free finger then rides on the object (7.4.2).

The sequencer sees only what the thesis controller sees: fingertip positions and its own
commanded forces (through the physics accessor), and its state
(:class:`~graspgait_env.sim.state.ControllerState`). It reports each move as a
:class:`~graspgait_env.sim.state.MoveOutcome`; the ground truth is the monitor's.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.contact_model import rolling_contacts_deg
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.shapes import Shape
from graspgait_env.sim import trajectory as tj
from graspgait_env.sim.config import SimConfig
from graspgait_env.sim.frames import object_to_workspace, rotate_deg, workspace_to_object
from graspgait_env.sim.model import HandPhysics
from graspgait_env.sim.state import ControllerState, MoveAborted, MoveOutcome, RunsTrajectories
from graspgait_env.sim.trajectory import CONTACT, FREE, HOLD, TRANSITION, pair_index

__all__ = ["MoveSequencer", "contact_angles_deg", "load_localizer", "parse_contacts"]


CONSTANT_SPEED_ACCEL = 1e6  # (m/s^2) the speed steps within one servo cycle: no ramp


def contact_angles_deg(shape: Shape, tips_xy: NDArray[np.float64], pose: ArrayLike,
                       tip_radius: float, iterations: int = 2) -> NDArray[np.float64]:
    """Object-frame polar angles (deg) of the contacts of ball tips at ``tips_xy`` (k, 2)
    on the object at ``pose`` ``(x, y, theta_deg)``: the tip centre moved ``tip_radius``
    along the inward normal (fixed-point iteration on the angle)."""
    q = workspace_to_object(tips_xy, pose)
    phi = np.degrees(np.arctan2(q[:, 1], q[:, 0]))
    for _ in range(iterations):
        p = q + tip_radius * shape.inward_normal(phi)
        phi = np.degrees(np.arctan2(p[:, 1], p[:, 0]))
    return phi


def load_localizer(shape: Shape, config: SimConfig
                   ) -> Callable[[NDArray[np.float64], tuple], Any] | None:
    """The object localizer of thesis 7.4.5 for ``shape``, or None when it is off or
    not installed: a callable ``(tips_xy (k, 2), expected_pose) -> result`` whose
    result has ``.pose`` ``(x, y, theta_deg)`` (``graspgait_env.sim.localizer``)."""
    if not config.localizer:
        return None
    try:
        from graspgait_env.sim.localizer import LocalizerConfig, ObjectLocalizer
    except ImportError:  # pragma: no cover - the localizer ships with the package
        return None
    thesis = {} if config.localizer_iterate else {"max_iterations": 1, "gauss_newton": False}
    loc = ObjectLocalizer(shape, LocalizerConfig(
        tip_radius=config.tip_radius, allowable_error=config.recenter_distance,
        prior_weight=config.localizer_prior_weight, **thesis))
    return loc.localize


def parse_contacts(contacts: dict) -> dict[int, float]:
    """A plan step's ``contacts`` (``{finger: phi_deg}``, fingers 1..3, exactly two) as
    ``{0-based finger: phi_deg}``.

    Raises
    ------
    GraspGaitInputError
        A finger outside 1..3, or not exactly two fingers.
    """
    out: dict[int, float] = {}
    for f, phi in contacts.items():
        fi = int(f)
        if fi not in (1, 2, 3):
            raise GraspGaitInputError(f"contacts: finger {f!r}: fingers are 1, 2, 3")
        out[fi - 1] = float(phi)
    if len(out) != 2:
        raise GraspGaitInputError(f"contacts {contacts!r}: name exactly two fingers")
    return out


def _kinds(hold: Sequence[int] = (), transition: Sequence[int] = (),
           contact: Sequence[int] = ()) -> NDArray[np.int64]:
    """Trajectory type per finger (thesis 7.4.2); fingers not named are FREE."""
    k = np.full(3, FREE)
    k[list(hold)] = HOLD
    k[list(transition)] = TRANSITION
    k[list(contact)] = CONTACT
    return k


class MoveSequencer:
    """The thesis trajectory planner's move sequences (7.4.2), run on a servo loop.

    Parameters
    ----------
    shape
        The object's contour (frame f).
    config
        Trajectory speeds and accelerations, grips, probe and recentring parameters.
    physics
        The :class:`~graspgait_env.sim.model.HandPhysics` accessor: the sequencer reads
        fingertip positions and commanded forces only.
    state
        The controller state (shared with the servo loop).
    loop
        Runs one trajectory (:meth:`ServoLoop.run <graspgait_env.sim.servo_loop.ServoLoop.run>`).
    workspaces
        The fingers' workspaces (deg, frame F), one ``(lo, hi)`` per finger.
    max_r
        Radius of free finger arcs (m, thesis 7.4.1).
    zc
        Height of the fingertips (m): the object's mid-height.
    localizer
        :func:`load_localizer`'s callable, or None.

    Attributes
    ----------
    max_rotation_deg
        The gait's largest rotation (deg), where a stabilization finger waits; None:
        half a workspace.
    """

    def __init__(self, shape: Shape, config: SimConfig, physics: HandPhysics,
                 state: ControllerState, loop: RunsTrajectories,
                 workspaces: Sequence[tuple[float, float]], max_r: float, zc: float,
                 localizer: Callable[[NDArray[np.float64], tuple], Any] | None) -> None:
        self.shape = shape
        self.config = config
        self.physics = physics
        self.state = state
        self.loop = loop
        self.workspaces = workspaces
        self.max_r = max_r
        self.zc = zc
        self.localizer = localizer
        self.max_rotation_deg: float | None = None

    def _accel(self, accel: float) -> float:
        """A trajectory's acceleration limit (m/s^2): ``accel`` with ``trapezoidal_speed``,
        else :data:`CONSTANT_SPEED_ACCEL`: the speed jumps to its constant value at a
        trajectory's start and back to rest at its end, as the thesis's PD moved
        (7.4.6: constant velocity between via points)."""
        return accel if self.config.trapezoidal_speed else CONSTANT_SPEED_ACCEL

    # ------------------------------------------------------------------ geometry
    def _normals(self, fingers: list[int]) -> NDArray[np.float64]:
        """Inward normals (3, 2), frame F, at the estimated contacts of ``fingers``."""
        nr = np.zeros((3, 2))
        if not fingers:
            return nr
        est = self.state.est
        tips = self.physics.tip_positions()[fingers, :2]
        phi = contact_angles_deg(self.shape, tips, est, self.config.tip_radius)
        nr[fingers] = rotate_deg(self.shape.inward_normal(phi), est[2])
        return nr

    def _rolling(self, fingers: list[int]) -> Callable[[NDArray[np.float64]], tuple]:
        """The rolling of the ball tips of ``fingers`` (ascending) during a rotation
        (thesis 7.2, :func:`~graspgait_env.contact_model.rolling_contacts_deg`): for
        object turns ``a_deg`` ``(n,)``, each ball centre's shift on the object since
        the start and the inward normals at the rolled contacts, ``(n, k, 2)`` each,
        in frame F at the estimated angle."""
        rho = self.config.tip_radius
        est = self.state.est.copy()
        tips = self.physics.tip_positions()[fingers, :2]
        phi0 = contact_angles_deg(self.shape, tips, est, rho)
        shape = self.shape

        def roll(a_deg: NDArray[np.float64]) -> tuple:
            phi = rolling_contacts_deg(shape, phi0[None, :], a_deg[:, None], rho)  # (n, k)
            n_in = shape.inward_normal(phi)  # (n, k, 2)
            ball = shape.contour_point(phi) - rho * n_in
            shift = rotate_deg(ball - ball[:1], est[2])
            return shift, rotate_deg(n_in, est[2])

        return roll

    def _ball_target(self, phi_deg: float) -> NDArray[np.float64]:
        """Ball-centre point (3,) touching the contour at ``phi_deg`` on the estimated
        object."""
        p = self.shape.contour_point(phi_deg)
        n_out = -self.shape.inward_normal(phi_deg)
        b = p + self.config.tip_radius * n_out
        xy = object_to_workspace(b, self.state.est)
        return np.array([xy[0], xy[1], self.zc])

    @staticmethod
    def _grip_vector(pair: tuple[int, int] | None, g: float) -> NDArray[np.float64]:
        v = np.zeros(3)
        if pair is not None:
            v[pair_index(*pair)] = g
        return v

    def _fold_grip(self) -> NDArray[np.float64]:
        """Scheduled grip plus the check's increases, fed back to the trajectory
        planner so the grip is continuous into the next trajectory (7.4.2)."""
        st = self.state
        g = st.grip + np.asarray(st.adjust)
        st.adjust[:] = [0.0, 0.0, 0.0]
        return g

    def _run(self, tr: tj.Trajectory, stop_on_contact: bool = False) -> list[bool]:
        return self.loop.run(tr, stop_on_contact=stop_on_contact)

    def _approach(self, fingers: list[int], targets: NDArray[np.float64],
                  grip: NDArray[np.float64], normals: NDArray[np.float64], hold: list[int],
                  names: list[str], stop_on_contact: bool = False) -> list[bool]:
        """Run the approach lines of ``fingers`` (fast, then slow with contact detection)."""
        cfg = self.config
        det = [False, False, False]
        for tr in tj.approach(self.state.xd, fingers, targets, grip, normals, res=cfg.res,
                              speed=cfg.free_speed, approach_speed=cfg.approach_speed,
                              standoff=cfg.standoff, overshoot=cfg.overshoot,
                              accel=self._accel(cfg.free_accel),
                              approach_accel=self._accel(cfg.approach_accel),
                              hold=hold):
            names.append(tr.name)
            det = self._run(tr, stop_on_contact=stop_on_contact)
        return det

    # ------------------------------------------------------------------ localizer
    def localize(self, fingers: list[int], assume_on: bool = False) -> tuple[bool, float]:
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
        st = self.state
        f_cmd = self.physics.finger_forces()
        on = [f for f in fingers
              if assume_on or f in st.held
              or math.hypot(*f_cmd[f, :2]) > self.config.contact_threshold]
        if len(on) < 3:
            return False, float("nan")
        tips = self.physics.tip_positions()[on, :2]
        res = self.localizer(tips, tuple(st.est))
        st.est = np.array(res.pose, dtype=float)
        return True, float(getattr(res, "rms_error", float("nan")))

    # ------------------------------------------------------------------ probe
    def probe_angles_deg(self, step_deg: float | None = None,
                         vertex_clearance_deg: float | None = None) -> list[float]:
        """F angles at which the probe touches the object, one per finger.

        Candidates every ``step_deg`` (default ``config.probe_step_deg``) inside each
        finger's workspace (``config.probe_margin_deg`` in from its ends), none within
        ``vertex_clearance_deg`` (default ``config.probe_vertex_clearance_deg``) of a
        polygon vertex of the expected object; of all triples, the one whose contacts
        observe the pose best: the largest smallest singular value of the Jacobian of
        the three contact distances with respect to ``(x, y, r_mean * theta)`` (rows
        ``[n_x, n_y, (p x n)_z / r]``). Two fingers on parallel flats with the third
        beside them, for one, leave a direction (a slide combined with a turn) that the
        localizer cannot see.
        """
        cfg = self.config
        step_deg = cfg.probe_step_deg if step_deg is None else step_deg
        clearance = (cfg.probe_vertex_clearance_deg if vertex_clearance_deg is None
                     else vertex_clearance_deg)
        margin = cfg.probe_margin_deg
        shape = self.shape
        th = self.state.est[2]
        verts = getattr(shape, "vertex_angles_deg", None)
        r_mean = 0.5 * (shape.r_min + shape.r_max)
        rows, angs = [], []
        for lo, hi in self.workspaces:
            cand = np.arange(lo + margin, hi - margin + 1e-9, step_deg)
            if cand.size == 0:
                cand = np.array([(lo + hi) / 2.0])
            phi = cand - th
            if verts is not None:
                d = (phi[:, None] - verts[None, :] + 180.0) % 360.0 - 180.0
                keep = np.abs(d).min(axis=1) >= clearance
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

    def probe(self, names: list[str]) -> tuple[bool, float]:
        """Before the first grasp, touch the object with all three fingers and localize
        it (7.4.5), so that the grasp lands on the planned contacts of an object placed
        only approximately (thesis 7.2); then the fingers retreat to ``max_r``."""
        cfg = self.config
        st = self.state
        fingers = [0, 1, 2]
        zero = np.zeros(3)
        nz = np.zeros((3, 2))
        ang = self.probe_angles_deg()
        targets = np.array([self._ball_target(a - st.est[2]) for a in ang])
        ta = np.degrees(np.arctan2(targets[:, 1] - st.est[1], targets[:, 0] - st.est[0]))
        tr = tj.free_arc(st.xd, fingers, st.est[:2], ta, self.max_r, zero, nz,
                         res=cfg.res, speed=cfg.free_speed, accel=self._accel(cfg.free_accel),
                         workspaces=list(self.workspaces), kind=_kinds())
        names.append("probe_" + tr.name)
        self._run(tr)
        det = self._approach(fingers, targets, zero, nz, [], names, stop_on_contact=True)
        localized, rms = False, float("nan")
        if all(det):
            # each finger stopped where it touched; a light three-way internal force
            # (no net force on the object, 7.4.3) keeps all three on while it localizes
            g = np.full(3, cfg.probe_grip)
            tr = tj.transfer(st.xd, zero, g, nz, cfg.settle_time,
                             kind=_kinds(transition=fingers))
            tr.name = "probe"
            names.append(tr.name)
            self._run(tr)
            localized, rms = self.localize(fingers, assume_on=True)
            st.grip = zero.copy()
        tr = tj.retreat(st.xd, fingers, st.est[:2], self.max_r, zero, nz, res=cfg.res,
                        speed=cfg.free_speed, accel=self._accel(cfg.free_accel), kind=_kinds())
        names.append(tr.name)
        self._run(tr)
        return localized, rms

    # ------------------------------------------------------------------ stabilization
    def _stabilize(self, names: list[str]) -> tuple[bool, float]:
        """With ``stabilization_finger``, bring the free finger onto the object without a
        grip (thesis 7.4.2): at the middle of its workspace minus half of the largest
        rotation (``max_rotation_deg``), so that rotations keep it inside the workspace;
        then localize with all three fingers on."""
        cfg = self.config
        st = self.state
        if not cfg.stabilization_finger or len(st.held) != 2 or st.stabilizer is not None:
            return False, float("nan")
        f = next(i for i in range(3) if i not in st.held)
        lo, hi = self.workspaces[f]
        max_rot = self.max_rotation_deg if self.max_rotation_deg is not None else (hi - lo) / 2
        a = min(max((lo + hi) / 2.0 - max_rot / 2.0, lo), hi)
        target = self._ball_target(a - st.est[2])
        ang = math.degrees(math.atan2(target[1] - st.est[1], target[0] - st.est[0]))
        held = sorted(st.held)
        nr = self._normals(held)
        tr = tj.free_arc(st.xd, [f], st.est[:2], [ang], self.max_r, self._fold_grip(), nr,
                         res=cfg.res, speed=cfg.free_speed, accel=self._accel(cfg.free_accel),
                         workspaces=[self.workspaces[f]], kind=_kinds(held))
        names.append("stabilizer_" + tr.name)
        self._run(tr)
        det = self._approach([f], target[None], self._fold_grip(), nr, held, names)
        if not det[f]:
            tr = tj.retreat(st.xd, f, st.est[:2], self.max_r, self._fold_grip(), nr,
                            res=cfg.res, speed=cfg.free_speed, accel=self._accel(cfg.free_accel),
                            kind=_kinds(held))
            self._run(tr)
            return False, float("nan")
        st.stabilizer = f
        return self.localize(held + [f])

    def _unstabilize(self, names: list[str]) -> None:
        """Take the stabilization finger off the object (outward to ``max_r``)."""
        st = self.state
        f = st.stabilizer
        if f is None:
            return
        cfg = self.config
        held = sorted(st.held)
        tr = tj.retreat(st.xd, f, st.est[:2], self.max_r, self._fold_grip(),
                        self._normals(held), res=cfg.res, speed=cfg.free_speed,
                        accel=self._accel(cfg.free_accel), kind=_kinds(held))
        names.append("stabilizer_" + tr.name)
        self._run(tr)
        st.stabilizer = None

    # ------------------------------------------------------------------ moves
    def grasp(self, contacts: dict) -> MoveOutcome:
        """The initial grasp (7.4.1 ``i``): with ``initial_probe`` first the probe; then
        both fingers of ``contacts`` (``{finger: phi_deg}``, fingers 1..3) arc at
        ``max_r`` to their angles on the estimated object and approach until contact,
        and the grip rises to its nominal value. The hand must be reset and at rest."""
        cfg = self.config
        st = self.state
        t0 = self.physics.time
        held = parse_contacts(contacts)
        fingers = sorted(held)
        names: list[str] = []
        localized, rms = False, float("nan")
        try:
            if cfg.initial_probe:
                localized, rms = self.probe(names)
            targets = np.array([self._ball_target(held[f]) for f in fingers])
            ang = np.degrees(np.arctan2(targets[:, 1] - st.est[1], targets[:, 0] - st.est[0]))
            zero = np.zeros(3)
            tr = tj.free_arc(st.xd, fingers, st.est[:2], ang, self.max_r, zero,
                             np.zeros((3, 2)), res=cfg.res, speed=cfg.free_speed,
                             accel=self._accel(cfg.free_accel),
                             workspaces=[self.workspaces[f] for f in fingers],
                             kind=_kinds())
            names.append(tr.name)
            self._run(tr)
            det = self._approach(fingers, targets, zero, np.zeros((3, 2)), [], names)
            if not all(det[f] for f in fingers):
                miss = [f + 1 for f in fingers if not det[f]]
                return MoveOutcome("grasp", "no-contact", t0,
                                   message=f"finger(s) {miss} found no object",
                                   trajectories=names)
            st.held = held
            pair = (fingers[0], fingers[1])
            nr = self._normals(fingers)
            g1 = self._grip_vector(pair, cfg.grip_force)
            tr = tj.transfer(st.xd, zero, g1, nr, cfg.transfer_time,
                             kind=_kinds(transition=fingers))
            names.append(tr.name)
            self._run(tr)
            tr = tj.hold(st.xd, self._fold_grip(), nr, cfg.settle_time, _kinds(fingers))
            names.append(tr.name)
            self._run(tr)
            if cfg.stabilization_finger:
                ok, r2 = self._stabilize(names)
                localized, rms = (True, r2) if ok else (localized, rms)
        except MoveAborted as exc:
            return MoveOutcome("grasp", "dropped", t0, localized=localized, rms=rms,
                               message=str(exc), trajectories=names)
        return MoveOutcome("grasp", "ok", t0, localized=localized, rms=rms,
                           trajectories=names)

    def hold(self, duration: float) -> MoveOutcome:
        """Servo the fingers in place for ``duration`` (s), the grip and its check on."""
        st = self.state
        t0 = self.physics.time
        fingers = sorted(st.held)
        tr = tj.hold(st.xd, self._fold_grip(), self._normals(fingers), duration,
                     _kinds(fingers))
        try:
            self._run(tr)
        except MoveAborted as exc:
            return MoveOutcome("hold", "dropped", t0, fingers, message=str(exc),
                               trajectories=[tr.name])
        return MoveOutcome("hold", "ok", t0, fingers, trajectories=[tr.name])

    def rotate(self, delta_deg: float) -> MoveOutcome:
        """Rotate the object by ``delta_deg`` (CCW positive) with the gripping pair.

        The orientation error of the estimate (planned angle minus estimated angle) is
        added to the commanded rotation (thesis 7.4.5, 7.5); the fingers travel arcs
        about the estimated centre at their present radius (7.4.2), or, with
        ``rolling_compensation``, the paths of their rolling ball tips (:meth:`_rolling`,
        7.2): on a circle the arcs shortened by ``r / (r + tip_radius)``, on a flat edge
        a path whose radius changes as the contact slides back along it.
        """
        cfg = self.config
        st = self.state
        t0 = self.physics.time
        fingers = sorted(st.held)
        cmd = delta_deg + (st.theta_goal - st.est[2])
        stab = [] if st.stabilizer is None else [st.stabilizer]
        moving = sorted(fingers + stab)
        rolling = self._rolling(moving) if cfg.rolling_compensation else None
        tr = tj.rotation(st.xd, st.est[:2], cmd, moving, self._fold_grip(),
                         self._normals(fingers),
                         res=cfg.res, speed_deg=cfg.rotation_speed_deg,
                         accel=self._accel(cfg.rotation_accel), max_speed=cfg.free_speed,
                         kind=_kinds(fingers, transition=stab), rolling=rolling)
        localized, rms = False, float("nan")
        try:
            self._run(tr)
            st.est[2] += cmd
            st.theta_goal += delta_deg
            if stab:  # three fingers on: localize after the rotation too (7.4.2, 7.4.5)
                localized, rms = self.localize(fingers + stab)
        except MoveAborted as exc:
            return MoveOutcome("rotate", "dropped", t0, fingers, message=str(exc),
                               trajectories=[tr.name])
        return MoveOutcome("rotate", "ok", t0, fingers, localized=localized, rms=rms,
                           trajectories=[tr.name])

    def regrasp(self, contacts: dict) -> MoveOutcome:
        """Regrasp (thesis 7.4.2 transition): the new finger arcs at ``max_r`` to its
        contact and approaches until contact; the grip transfers from the old pair to
        the new with three fingers on (the localizer runs then); the old finger retreats
        to ``max_r``; the object is recentred if the estimate is off by more than
        ``recenter_distance`` (1/4 in, 7.5)."""
        cfg = self.config
        st = self.state
        t0 = self.physics.time
        new = parse_contacts(contacts)
        kept = sorted(set(new) & set(st.held))
        if len(kept) != 1:
            raise GraspGaitInputError(
                f"regrasp {contacts!r}: must keep exactly one of the held fingers "
                f"{[f + 1 for f in sorted(st.held)]}")
        k = kept[0]
        n = next(f for f in new if f not in st.held)
        lifted = next(f for f in st.held if f != k)
        new_pair = (min(k, n), max(k, n))
        names: list[str] = []
        localized, rms = False, float("nan")
        try:
            self._unstabilize(names)  # 0. the stabilization finger leaves first (7.4.2)
            # 1. the new finger: arc at max_r to its angle, then in until contact
            g = self._fold_grip()
            nr = self._normals([k, lifted])
            target = self._ball_target(new[n])
            ang = math.degrees(math.atan2(target[1] - st.est[1], target[0] - st.est[0]))
            tr = tj.free_arc(st.xd, [n], st.est[:2], [ang], self.max_r, g, nr,
                             res=cfg.res, speed=cfg.free_speed, accel=self._accel(cfg.free_accel),
                             workspaces=[self.workspaces[n]], kind=_kinds([k, lifted]))
            names.append(tr.name)
            self._run(tr)
            det = self._approach([n], target[None], self._fold_grip(), nr, [k, lifted], names)
            if not det[n]:
                return MoveOutcome("regrasp", "no-contact", t0, [k, lifted],
                                   message=f"finger {n + 1} found no object",
                                   trajectories=names)
            # 2. three fingers on: the grip moves from the old pair to the new; halfway,
            # when all three fingers push on the object (both pairs grip), the object
            # localizer runs (7.4.5). After the transfer the lifted finger no longer
            # pushes (it servos to where it stood), so it may have left the object.
            nr = self._normals([k, lifted, n])
            g_new = self._grip_vector(new_pair, cfg.grip_force)
            g_old = self._fold_grip()
            mid = cfg.localize_during_transfer
            t1 = 0.5 * cfg.transfer_time if mid else cfg.transfer_time
            tr = tj.transfer(st.xd, g_old, 0.5 * (g_old + g_new) if mid else g_new, nr, t1,
                             kind=np.full(3, TRANSITION))
            names.append(tr.name)
            self._run(tr)
            if mid:
                # 3. the object localizer, all three fingers on the object (7.4.5)
                localized, rms = self.localize([k, lifted, n])
                tr = tj.transfer(st.xd, self._fold_grip(), g_new, nr, cfg.transfer_time - t1,
                                 kind=np.full(3, TRANSITION))
                names.append(tr.name)
                self._run(tr)
            st.held = {k: st.held[k], n: new[n]}
            tr = tj.hold(st.xd, self._fold_grip(), nr, cfg.settle_time,
                         _kinds([k, n], transition=[lifted]))
            names.append(tr.name)
            self._run(tr)
            if not mid:  # 3. after the transfer: the lifted finger may push no longer
                localized, rms = self.localize([k, lifted, n])
            # 4. the old finger leaves along a line outward
            nr = self._normals([k, n])
            tr = tj.retreat(st.xd, lifted, st.est[:2], self.max_r, self._fold_grip(), nr,
                            res=cfg.res, speed=cfg.free_speed, accel=self._accel(cfg.free_accel),
                            kind=_kinds([k, n]))
            names.append(tr.name)
            self._run(tr)
            # 5. recentre when the position error exceeds 1/4 in (7.5)
            err = -st.est[:2]
            if float(np.hypot(*err)) > cfg.recenter_distance:
                tr = tj.translate(st.xd, [k, n], err, self._fold_grip(), nr,
                                  res=cfg.res, speed=cfg.recenter_speed,
                                  accel=self._accel(cfg.rotation_accel), kind=_kinds([k, n]))
                names.append(tr.name)
                self._run(tr)
                st.est[:2] += err
            # 6. the lifted finger becomes the stabilization finger (7.4.2)
            if cfg.stabilization_finger:
                ok, r2 = self._stabilize(names)
                localized, rms = (True, r2) if ok else (localized, rms)
        except MoveAborted as exc:
            return MoveOutcome("regrasp", "dropped", t0, [k], localized=localized, rms=rms,
                               message=str(exc), trajectories=names)
        return MoveOutcome("regrasp", "ok", t0, [k], localized=localized, rms=rms,
                           trajectories=names)
