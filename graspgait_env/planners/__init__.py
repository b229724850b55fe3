"""The thesis's planners (chapters 5-6) and the exact optimum: pure NumPy, map level.

One module per thesis section:

- :mod:`~graspgait_env.planners.search`: breadth-first, depth-first and best-first
  searches (thesis 5.3-5.5);
- :mod:`~graspgait_env.planners.prototypes`: prototype regions (band, box) and the
  necessary conditions for prototype gaits (6.2-6.3);
- :mod:`~graspgait_env.planners.rule_based`: forward gait (6.3.1), back-and-forth gait
  (6.3.2), modified search (6.4), the rule-based method (6.5) and the no-gait diagnosis;
- :mod:`~graspgait_env.planners.exact`: the exact minimum-regrasp planner (beyond the
  thesis);
- :mod:`~graspgait_env.planners.registry`: every planner by name (``PLANNERS``),
  :func:`~graspgait_env.planners.registry.run_planner`;
- :mod:`~graspgait_env.planners.result`: :class:`PlannerResult`, what every planner
  returns.
"""
