"""Physics level: the thesis hand in MuJoCo and the controller of thesis chapter 7.

- :mod:`~graspgait_env.sim.config`: parameters (``configs/sim/default.yaml``);
- :mod:`~graspgait_env.sim.frames`: frames (F, f) and units (inch, oz, lb);
- :mod:`~graspgait_env.sim.model`: MJCF builder (``assets/hand.xml`` + the object) and
  the by-name physics accessor :class:`~graspgait_env.sim.model.HandPhysics`;
- :mod:`~graspgait_env.sim.trajectory`: trajectory primitives of the trajectory
  planner (7.4.2): arcs, approach lines, grip transfers, retreats;
- :mod:`~graspgait_env.sim.moves`: the trajectory planner's move sequences (7.4.2):
  initial grasp (with the probe), rotation, transition;
- :mod:`~graspgait_env.sim.servo`: PD servo, internal forces, grip and friction cone
  check, contact detection (7.3, 7.4.3-7.4.4, 7.4.6);
- :mod:`~graspgait_env.sim.servo_loop`: the servo loop stepping servo and physics (7.4.6);
- :mod:`~graspgait_env.sim.localizer`: the object localizer (7.4.5);
- :mod:`~graspgait_env.sim.monitor`: the ground-truth monitor (drops, slips), outside
  the controller;
- :mod:`~graspgait_env.sim.state`: what those parts share (controller state, step
  report);
- :mod:`~graspgait_env.sim.executor`: :class:`GaitExecutor`, the task composing them,
  one move at a time;
- :mod:`~graspgait_env.sim.simulate`: :func:`simulate_plan`, videos, step-rate benchmark,
  the ``graspgait simulate`` command and its input checks;
- :mod:`~graspgait_env.sim.view`: :class:`~graspgait_env.sim.view.HandView`, frames of
  the hand from above with the workspaces, finger numbers and captions overlaid (the
  ``GraspGaitMujoco-v1`` frames and the videos).

Rendering is headless: ``MUJOCO_GL`` defaults to ``egl`` here, which takes effect only
if MuJoCo has not been imported yet (the Makefile exports it too).
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")

from graspgait_env.sim.config import SimConfig, load_sim_config  # noqa: E402
from graspgait_env.sim.executor import (  # noqa: E402
    GaitExecutor,
    StepReport,
    random_pose_perturbation,
)
from graspgait_env.sim.simulate import (  # noqa: E402
    benchmark_step_rate,
    format_result,
    simulate_plan,
)

__all__ = [
    "GaitExecutor",
    "SimConfig",
    "StepReport",
    "benchmark_step_rate",
    "format_result",
    "load_sim_config",
    "random_pose_perturbation",
    "simulate_plan",
]
