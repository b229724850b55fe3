"""The ground-truth monitor: drops, slips and the true pose (no part of the controller).

The thesis controller (7.3) sees only fingertip positions and its own commanded forces.
:class:`GroundTruthMonitor` reads what it cannot, from the simulator: the true object
pose (its angle unwrapped over a gait), the contact sensors and the object's tilt; it
declares the object dropped (and stops the move, raising
:class:`~graspgait_env.sim.state.MoveAborted`) and measures how far held contacts slid
along the object during a move. Nothing it computes flows back into the controller.

Drop rules (``configs/sim/default.yaml``, monitoring): once two fingers grip, the
object is dropped when its centre is more than ``drop_distance`` from the palm centre,
when it tilts more than ``drop_tilt_deg``, or when fewer than two gripping fingers touch
it for more than ``lost_contact_time``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from graspgait_env.sim.config import SimConfig
from graspgait_env.sim.frames import workspace_to_object, wrap_deg
from graspgait_env.sim.model import HandPhysics
from graspgait_env.sim.state import ControllerState, MoveAborted

__all__ = ["GroundTruthMonitor", "MonitorSnapshot"]


@dataclass(frozen=True)
class MonitorSnapshot:
    """The truth at the start of a move: fingertip centres in the true object frame
    (``(3, 2)``, m) and the unwrapped true angle (deg); None tips: no slip measured."""

    tips: NDArray[np.float64] | None
    theta: float


class GroundTruthMonitor:
    """Watch the simulated object from outside the controller.

    Parameters
    ----------
    physics
        The :class:`~graspgait_env.sim.model.HandPhysics` accessor.
    config
        ``drop_distance``, ``drop_tilt_deg``, ``lost_contact_time``, ``slip_threshold``
        and ``tip_radius`` are read.
    state
        The controller state; the monitor reads only which fingers grip
        (``state.held``) and whether a gait has begun.

    Attributes
    ----------
    theta_true
        True object angle (deg), unwrapped since the reset.
    dropped, drop_reason
        Whether (and why) the object was declared dropped.
    """

    def __init__(self, physics: HandPhysics, config: SimConfig, state: ControllerState) -> None:
        self.physics = physics
        self.config = config
        self.state = state
        self.clear()

    def clear(self) -> None:
        """Forget the last gait (before the physics is reset)."""
        self.dropped = False
        self.drop_reason = ""
        self.theta_true = 0.0
        self._theta_wrapped = 0.0
        self._lost_since: float | None = None

    def start(self) -> None:
        """Take the object's present angle as the start of the unwrapped angle."""
        self._theta_wrapped = self.physics.object_pose()[2]
        self.theta_true = self._theta_wrapped

    # ------------------------------------------------------------------ watching
    def __call__(self) -> None:
        """One check (the servo loop's ``watch``): unwrap the angle; declare a drop.

        Raises
        ------
        MoveAborted
            The object was found dropped (once two fingers grip it).
        """
        phys = self.physics
        x, y, th = phys.object_pose()
        self.theta_true += wrap_deg(th - self._theta_wrapped)
        self._theta_wrapped = th
        held = self.state.held
        if self.dropped or not self.state.started or len(held) != 2:
            return  # a drop needs a grasp to lose
        cfg = self.config
        reason = ""
        if math.hypot(x, y) > cfg.drop_distance:
            reason = f"object {1e3 * math.hypot(x, y):.0f} mm from the centre"
        elif phys.object_tilt_deg() > cfg.drop_tilt_deg:
            reason = "object tipped over"
        else:
            touch = phys.tip_in_contact()
            n = sum(bool(touch[f]) for f in held)
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
            raise MoveAborted(reason)

    # ------------------------------------------------------------------ truth
    def true_pose(self) -> tuple[float, float, float]:
        """True object pose ``(x, y, theta_deg)``, theta unwrapped since the reset."""
        x, y, _ = self.physics.object_pose()
        return (x, y, self.theta_true)

    def tips_in_object_frame(self) -> NDArray[np.float64]:
        """``(3, 2)`` fingertip centres in the TRUE object frame (m)."""
        return workspace_to_object(self.physics.tip_positions()[:, :2],
                                   self.physics.object_pose())

    def touching(self) -> tuple[int, ...]:
        """Fingers (1..3) that truly touch the object now (contact sensors)."""
        touch = self.physics.tip_in_contact()
        return tuple(f + 1 for f in range(3) if touch[f])

    def snapshot(self, measure_slip: bool = True) -> MonitorSnapshot:
        """The truth at the start of a move (tips in the object frame only when
        ``measure_slip``)."""
        return MonitorSnapshot(self.tips_in_object_frame() if measure_slip else None,
                               self.theta_true)

    def slips(self, start: MonitorSnapshot, fingers: list[int]) -> tuple[int, float]:
        """Slips of ``fingers`` (0-based) since ``start``: ``(count, largest (m))``.

        A contact's sliding is how far its tip moved in the object frame beyond the
        rolling of the ball (``rho |dtheta| (1 + rho / r)``, thesis 7.2); a slip is a
        sliding above ``slip_threshold``.
        """
        cfg = self.config
        slips, max_slip = 0, 0.0
        if start.tips is None or not fingers:
            return slips, max_slip
        tips1 = self.tips_in_object_frame()
        roll = cfg.tip_radius * abs(math.radians(self.theta_true - start.theta))
        for f in fingers:
            r = float(np.hypot(*tips1[f]))
            d = float(np.hypot(*(tips1[f] - start.tips[f])))
            slip = max(0.0, d - roll * (1.0 + cfg.tip_radius / max(r, 1e-9)))
            max_slip = max(max_slip, slip)
            slips += slip > cfg.slip_threshold
        return int(slips), max_slip
