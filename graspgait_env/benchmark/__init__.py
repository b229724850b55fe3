"""The GraspGait benchmark: a fixed task suite, a score, a multi-seed scoreboard with
confidence intervals, and demonstration datasets (the ``[benchmark]`` extra: rliable,
Minari).

The top layer of the package: it builds on :mod:`graspgait_env.agents` (evaluation,
training, saved agents) and :mod:`graspgait_env.baselines` (planners as policies, Ray),
and nothing below imports it.

- :mod:`~graspgait_env.benchmark.suite`: the versioned task list (:data:`~graspgait_env.
  benchmark.suite.TASKS`), each task's env and keywords, training and test seeds, episode
  and step budgets; the check that training and test objects are disjoint;
- :mod:`~graspgait_env.benchmark.score`: success over the solvable starts, efficiency
  against the exact optimum, their product (the normalized score), the rule-based gait's
  beside them;
- :mod:`~graspgait_env.benchmark.aggregate`: per-task means and IQMs, per-track and suite
  IQMs with 95% stratified bootstrap confidence intervals, performance profiles
  (rliable);
- :mod:`~graspgait_env.benchmark.policies`: POLICY (``random``, a planner,
  ``greedy-reach``, a saved agent, a training config, ``bc``) per task and seed;
- :mod:`~graspgait_env.benchmark.run`: a scoreboard row over tasks x seeds, resumable,
  serially or on Ray (``graspgait benchmark``);
- :mod:`~graspgait_env.benchmark.datasets`: Minari demonstration datasets
  (``graspgait dataset record``) and the behaviour-cloning baseline;
- :mod:`~graspgait_env.benchmark.scoreboard`: finished rows side by side, their tables
  and performance profiles (``graspgait benchmark --scoreboard``).

The protocol, the score's formula, the versioning rule and the scoreboard:
docs/benchmark.md.
"""

from graspgait_env.benchmark.suite import SUITE_VERSION, TASKS, Task, get_task, parse_tasks

__all__ = ["SUITE_VERSION", "TASKS", "Task", "get_task", "parse_tasks"]
