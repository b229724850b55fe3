"""Physics level: the thesis hand in MuJoCo and the controller of thesis chapter 7.

- :mod:`~graspgait_env.sim.config`: parameters (``configs/sim/default.yaml``);
- :mod:`~graspgait_env.sim.model`: MJCF builder (``assets/hand.xml`` + the object) and
  the by-name physics accessor :class:`~graspgait_env.sim.model.HandPhysics`;
- :mod:`~graspgait_env.sim.trajectory`: the trajectory planner (7.4.2);
- :mod:`~graspgait_env.sim.servo`: PD servo, internal forces, grip and friction cone
  check, contact detection (7.3, 7.4.3-7.4.4, 7.4.6);
- :mod:`~graspgait_env.sim.localizer`: the object localizer (7.4.5);
- :mod:`~graspgait_env.sim.executor`: :class:`GaitExecutor`, one move at a time;
- :mod:`~graspgait_env.sim.simulate`: :func:`simulate_plan`, videos, step-rate benchmark.

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
