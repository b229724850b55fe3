"""``graspgait perf`` rows of the physics level (``@register``, :mod:`graspgait_env.perf`).

Targets (the physics issue):

- a full 360° gait of the thesis ellipse (optimal plan, mu = 0.7) runs in <= 1 s of
  wall time on one core, model build included;
- the controller costs no more than the physics it drives: physics steps per second
  with the controller >= half the rate of ``mj_step`` alone, both measured in the same
  run over the same states (:func:`~graspgait_env.sim.simulate.benchmark_step_rate`).
"""

from __future__ import annotations

from graspgait_env.timing import BenchRow, register

__all__ = ["bench_simulation", "GAIT_WALL_TARGET_S", "CONTROLLER_SHARE_TARGET"]

GAIT_WALL_TARGET_S = 1.0  # (s) wall time of a 360 deg gait of the thesis ellipse
CONTROLLER_SHARE_TARGET = 0.5  # controller's share of the wall time: no more than physics


@register
def bench_simulation(repeat: int) -> list[BenchRow]:
    """Wall time of the ellipse's 360° gait; step rates with and without the controller."""
    from graspgait_env.sim.simulate import benchmark_step_rate, default_plan

    runs = max(1, min(repeat, 3))  # a gait takes ~0.4 s: a few runs give a stable median
    plan = default_plan("ellipse")
    b = benchmark_step_rate(plan, repeat=runs)
    what = (f"ellipse, optimal plan ({plan.regrasps} regrasps), {b['gait_sim_s']:.1f} s "
            f"simulated, physics {b['physics_hz']:.0f} Hz, servo {b['servo_hz']:.0f} Hz, "
            f"median of {runs}")
    ratio = b["controlled_steps_per_s"] / b["raw_steps_per_s"]
    return [
        BenchRow("sim: 360 deg gait, wall time", b["gait_wall_s"], "s",
                 f"<= {GAIT_WALL_TARGET_S:g} s", b["gait_wall_s"] <= GAIT_WALL_TARGET_S, what),
        BenchRow("sim: physics steps/s, mj_step alone", b["raw_steps_per_s"], "steps/s", "",
                 None, "wall time inside mj_step during the same run"),
        BenchRow("sim: physics steps/s, with controller", b["controlled_steps_per_s"],
                 "steps/s", ">= 0.5x mj_step alone",
                 b["controller_share"] <= CONTROLLER_SHARE_TARGET,
                 f"{ratio:.2f}x mj_step alone; controller {100 * b['controller_share']:.0f}% "
                 "of the wall time"),
    ]
