"""The thesis's planners (chapters 5-6) and the exact optimum: pure NumPy, map level.

One module per thesis section, named in the thesis's words:

- :mod:`~graspgait_env.planners.search`: breadth-first, depth-first and best-first
  searches (thesis 5.3-5.5);
- :mod:`~graspgait_env.planners.prototypes`: prototype regions (band, box) and the
  necessary conditions for prototype gaits (6.2-6.3);
- :mod:`~graspgait_env.planners.forward_gait`: the forward (staircase) gait (6.3.1);
- :mod:`~graspgait_env.planners.back_and_forth_gait`: the back-and-forth (plus /
  combined) gait (6.3.2), with its entry into the box and, through
  :mod:`~graspgait_env.planners.mirror`, its clockwise mirror;
- :mod:`~graspgait_env.planners.modified_search`: the modified search, pruned by the
  prototype gaits' structure (6.4);
- :mod:`~graspgait_env.planners.rule_based`: the rule-based method that combines them
  (6.5, Table 6.1);
- :mod:`~graspgait_env.planners.diagnosis`: why no gait exists (thesis 1.3 (2)-(4));
- :mod:`~graspgait_env.planners.exact`: the exact minimum-regrasp planner (beyond the
  thesis);
- :mod:`~graspgait_env.planners.reach`: the reach of a grasp within a few regrasps, the
  exact planner's search cut at a depth (the envs' opt-in reach look-ahead);
- :mod:`~graspgait_env.planners.registry`: every planner by name (``PLANNERS``),
  :func:`~graspgait_env.planners.registry.run_planner`;
- :mod:`~graspgait_env.planners.result`: :class:`PlannerResult`, what every planner
  returns.

Shared pieces sit below the parts, which never import each other in a circle:
:mod:`~graspgait_env.planners.starts` (start grasps and the "no stable grasp at θ = 0"
verdict, for every planner) and :mod:`~graspgait_env.planners.trace` (the trace, result
builders and gait pattern of the rule-based gaits and the modified search). The gait
geometry — the workspace grid and the rotation room — is
:class:`~graspgait_env.gait.GaitModel`'s alone.
"""
