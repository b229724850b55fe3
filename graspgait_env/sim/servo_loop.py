"""The servo loop (thesis 7.3, 7.4.6): one trajectory, servo cycle by servo cycle.

:class:`ServoLoop` steps the physics and the servo units of
:mod:`~graspgait_env.sim.servo` together. Each servo cycle it:

1. reads the fingertip positions (the encoders: the controller's only sensors);
2. computes the PD servo force toward the trajectory's desired point
   (:class:`~graspgait_env.sim.servo.PDServo`, 7.4.6), frozen where a finger has
   detected contact (7.4.2);
3. adds the internal grip forces of the gripping pairs
   (:func:`~graspgait_env.sim.servo.internal_forces`, 7.4.3), raised by the grip force
   and friction cone check (:class:`~graspgait_env.sim.servo.GripCheck`, 7.4.4);
4. commands the motors and holds the forces for ``servo_decimation`` physics steps;
5. counts contact on fingers making contact
   (:class:`~graspgait_env.sim.servo.ContactDetector`, 7.3).

Outside the controller, the loop also applies a disturbance force to the object (a tug,
thesis 7.5), calls a ``watch`` function every ``monitor_every`` servo cycles (the
ground-truth monitor, which may stop the run by raising
:class:`~graspgait_env.sim.state.MoveAborted`) and a frame callback for video.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from graspgait_env.sim.config import SimConfig
from graspgait_env.sim.model import HandPhysics
from graspgait_env.sim.servo import ContactDetector, GripCheck, PDServo, internal_forces
from graspgait_env.sim.state import ControllerState
from graspgait_env.sim.trajectory import CONTACT, Trajectory

__all__ = ["ServoLoop"]


class ServoLoop:
    """Track trajectories with the thesis servo on the simulated hand (7.3, 7.4.3-7.4.6).

    Parameters
    ----------
    physics
        The :class:`~graspgait_env.sim.model.HandPhysics` accessor.
    config
        Servo gains, grip, contact detection and timing (:class:`SimConfig`).
    state
        The controller state shared with the move sequences: the loop reads the
        check's grip increases (``state.adjust``) and leaves the last desired points
        and grips in ``state.xd`` and ``state.grip``.
    cone_mu
        Friction coefficient of the friction cone check (7.4.4).
    watch
        Called every ``config.monitor_every`` servo cycles and at the end of each
        trajectory; may raise :class:`~graspgait_env.sim.state.MoveAborted`.

    Attributes
    ----------
    servo, check, detector
        The PD servo, the grip force and friction cone check, the contact detector.
    frame_callback
        Called as ``frame_callback(physics)`` every ``1 / video_fps`` simulated seconds.
    disturbance_fn
        ``force(t)``: horizontal force (N, frame F) on the object's centre of mass at
        simulated time ``t``, applied every servo cycle; None for none.
    """

    def __init__(self, physics: HandPhysics, config: SimConfig, state: ControllerState,
                 cone_mu: float, watch: Callable[[], None]) -> None:
        cfg = config
        self.physics = physics
        self.config = cfg
        self.state = state
        self.watch = watch
        self.dt = cfg.servo_dt
        self.servo = PDServo([cfg.kp, cfg.kp, cfg.kp_z], [cfg.kv, cfg.kv, cfg.kv_z],
                             cfg.velocity_alpha, self.dt)
        self.check = GripCheck(cfg.grip_force, cfg.settle, cfg.grip_saturation, cone_mu)
        self.detector = ContactDetector(cfg.contact_threshold, cfg.contact_cycles)
        self.frame_callback: Callable[[HandPhysics], None] | None = None
        self.disturbance_fn: Callable[[float], tuple[float, float]] | None = None
        self.next_frame = 0.0  # simulated time of the next video frame (s)

    def reset(self) -> None:
        """Start the servo from the measured tips at rest; the next frame is now."""
        self.servo.reset(self.physics.tip_positions_flat())
        self.next_frame = self.physics.time

    def run(self, tr: Trajectory, stop_on_contact: bool = False) -> list[bool]:
        """Servo along ``tr``; returns, per finger, whether it detected contact.

        Fingers of trajectory type CONTACT stop where contact is detected: their
        desired point freezes (thesis 7.4.2), or, with ``stop_on_contact``, moves back
        to the measured point so that the finger stops pushing; the trajectory ends when
        every such finger has touched, or at its end. The motor forces computed in a
        servo cycle are held for ``servo_decimation`` physics steps.
        """
        cfg = self.config
        phys = self.physics
        st = self.state
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
        if detecting and cfg.contact_along_approach:  # each armed finger's approach line
            for f in range(3):
                d = xd_all[-1, f, :2] - xd_all[0, f, :2]
                n = math.hypot(d[0], d[1])
                if armed[f] and n > 0:
                    directions[f] = (float(d[0] / n), float(d[1] / n))
        detected = [False, False, False]
        frozen: list[float] = [0.0] * 9
        self.detector.reset()
        check = self.check if cfg.grip_check else None
        adjust = st.adjust
        dec = cfg.servo_decimation
        every = cfg.monitor_every
        watch = self.watch
        cb = self.frame_callback
        disturb = self.disturbance_fn
        frame_dt = 1.0 / cfg.video_fps
        servo_cycle = self.servo.cycle
        tips = phys.tip_positions_flat
        set_forces = phys.set_finger_forces_flat
        step = phys.step
        detector = self.detector
        xd = xdl[0]
        st.trace.append((tr.name, phys.time))
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
            fs = servo_cycle(x, xd, vd)  # PD servo (7.4.6)
            g = gl[m]
            if adjust[0] or adjust[1] or adjust[2]:
                g = [g[0] + adjust[0], g[1] + adjust[1], g[2] + adjust[2]]
            fg, u = internal_forces(x, g)  # internal force generator (7.4.3)
            ft = [a + b for a, b in zip(fs, fg, strict=True)]
            if check is not None:  # grip force and friction cone check (7.4.4)
                inc = check(ft, u, g, nl[m], kind)
                adjust[0] += inc[0]
                adjust[1] += inc[1]
                adjust[2] += inc[2]
            set_forces(ft)
            if disturb is not None:
                phys.apply_object_force(disturb(phys.time))
            step(dec)
            if detecting:  # contact detection (7.3)
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
            if m % every == 0:
                watch()
            if cb is not None and phys.time >= self.next_frame:
                cb(phys)
                self.next_frame += frame_dt
        xd = list(xd)
        for f in range(3):
            if detected[f]:
                xd[3 * f:3 * f + 3] = frozen[3 * f:3 * f + 3]
        st.xd = np.array(xd, dtype=float).reshape(3, 3)
        st.grip = np.array(gl[m], dtype=float)
        watch()
        return detected
