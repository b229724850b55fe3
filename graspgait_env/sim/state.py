"""What the parts of the executor share: the controller's state, its account of a move,
the step report and the signal that stops a move (thesis 7.3-7.4).

:class:`~graspgait_env.sim.executor.GaitExecutor` composes three parts that never import
one another; each imports this module (and :mod:`~graspgait_env.sim.frames`):

- :mod:`~graspgait_env.sim.moves`: the trajectory planner's move sequences (7.4.2);
- :mod:`~graspgait_env.sim.servo_loop`: the servo loop that steps the physics (7.4.6);
- :mod:`~graspgait_env.sim.monitor`: the ground-truth monitor (drops, slips), which
  watches from outside and is no part of the thesis controller.

:class:`ControllerState` is the one state holder: the move sequences write the plan
side (contacts held, pose estimate), the servo loop the last desired points and grips
it ended a trajectory with, and the monitor reads which fingers grip.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from graspgait_env.sim.trajectory import Trajectory

__all__ = ["ControllerState", "MoveAborted", "MoveOutcome", "StepReport", "RunsTrajectories"]


class MoveAborted(Exception):
    """Raised inside a trajectory when the run must stop: the monitor found the object
    dropped. The move sequences catch it and report the move as ``dropped``."""


@dataclass
class ControllerState:
    """The thesis controller's state between servo cycles (thesis 7.4.2, 7.4.5).

    Attributes
    ----------
    xd
        ``(3, 3)`` last desired tip positions (m, frame F): where the next trajectory
        starts (7.4.2).
    adjust
        Grip added by the grip force and friction cone check, per pair (N, 7.4.4), not
        yet folded into a trajectory.
    grip
        Scheduled grip per pair (N) at the end of the last trajectory.
    held
        Gripping fingers (0-based) -> planned contact angle (deg, frame f).
    est
        The controller's pose estimate ``(x, y, theta_deg)``, theta unwrapped (7.4.5).
    theta_goal
        Planned object angle so far (deg).
    stabilizer
        The free finger riding on the object (7.4.2), or None.
    started
        A gait has begun (``reset``).
    trace
        ``(trajectory name, simulated start time)`` of every trajectory run.
    """

    xd: NDArray[np.float64]
    adjust: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    grip: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    held: dict[int, float] = field(default_factory=dict)
    est: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    theta_goal: float = 0.0
    stabilizer: int | None = None
    started: bool = False
    trace: list[tuple[str, float]] = field(default_factory=list)

    def clear(self, home: NDArray[np.float64]) -> None:
        """Back to the start of a gait, fingers at ``home`` (in place: the parts share
        this object)."""
        self.xd = home.copy()
        self.adjust = [0.0, 0.0, 0.0]
        self.grip = np.zeros(3)
        self.held = {}
        self.est = np.zeros(3)
        self.theta_goal = 0.0
        self.stabilizer = None
        self.trace = []

    def pose_estimate(self) -> tuple[float, float, float]:
        """The pose estimate ``(x, y, theta_deg)`` as floats."""
        return (float(self.est[0]), float(self.est[1]), float(self.est[2]))

    def grip_now(self) -> tuple[float, float, float]:
        """Pair grips (N) now: the schedule plus the check's increases."""
        return tuple(float(g) for g in self.grip + np.asarray(self.adjust))


class RunsTrajectories(Protocol):
    """What the move sequences need of the servo loop (thesis 7.4.6)."""

    def run(self, tr: Trajectory, stop_on_contact: bool = False) -> list[bool]:
        """Servo along ``tr``; per finger, whether it detected contact."""
        ...


@dataclass
class MoveOutcome:
    """The controller's account of one move, before the monitor adds the ground truth.

    Attributes
    ----------
    op
        ``grasp``, ``rotate``, ``regrasp`` or ``hold``.
    status
        ``ok``, ``dropped`` or ``no-contact`` (:class:`StepReport`).
    t0
        Simulated time the move started (s).
    slip_fingers
        Fingers (0-based) that held the object through the move, whose sliding the
        monitor measures.
    """

    op: str
    status: str
    t0: float
    slip_fingers: list[int] = field(default_factory=list)
    localized: bool = False
    rms: float = float("nan")
    message: str = ""
    trajectories: list[str] = field(default_factory=list)


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
    trajectories
        Names of the trajectories the move ran, in order.
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
