"""The thesis's planners as scripted baseline policies, and the benchmark.

- :mod:`graspgait_env.baselines.policies`:
:class:`~graspgait_env.baselines.policies.PlannerPolicy`, any planner of
  :data:`graspgait_env.planners.registry.PLANNERS` behind stable-baselines3's ``predict``;
- :mod:`graspgait_env.baselines.bench`: the thesis's Tables 1 and 6.1 regenerated (``graspgait
bench``).

The planners themselves are map-level code and live in :mod:`graspgait_env.planners`.
"""
