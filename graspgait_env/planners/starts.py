"""Start grasps at θ = 0, shared by every planner (thesis 4.3, 5.2).

A gait starts from a stable two-finger grasp with both contacts inside their fingers'
workspaces at object angle θ = 0 (the frames coincide at the start of every gait). This
module is the one place where a planner

- checks a given start (:func:`check_start`: a bad one is the user's input error,
  :class:`~graspgait_env.errors.GraspGaitInputError`);
- answers when there is no start at all (:func:`no_start_verdict`): no stable grasp lies
  inside the workspaces at θ = 0, so no gait exists — a no-gait verdict, a
  :class:`~graspgait_env.planners.result.PlannerResult` with ``plan=None``, never an
  exception;
- spreads candidate starts through the legal ones (:func:`spread_starts`).

Every planner module imports this one; it imports none of them.
"""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.result import PlannerResult

__all__ = ["NO_START", "check_start", "legal_start_exists", "no_start_verdict",
           "require_start", "spread_starts"]

NO_START = "no stable grasp lies inside the workspaces at theta = 0"  # the verdict's words

_PAIRS = ((0, 1), (0, 2), (1, 2))


def _pair_grasps(model: GaitModel) -> list[tuple[int, int, NDArray[np.int64], NDArray[np.int64]]]:
    """Per finger pair ``(f, g)``: the contacts ``(c_f, c_g)`` of every legal grasp at θ = 0,
    in :meth:`GaitModel.start_states` order (the workspaces' grid angles at ``k = 0``)."""
    n = model.n
    out = []
    for f, g in _PAIRS:
        cf = (model.ws_start[f] + np.arange(model.ws_width[f])) % n
        cg = (model.ws_start[g] + np.arange(model.ws_width[g])) % n
        i, j = np.nonzero(model.stable[np.ix_(cf, cg)])
        out.append((f, g, cf[i], cg[j]))
    return out


def legal_start_exists(model: GaitModel) -> bool:
    """Is there a stable grasp inside two fingers' workspaces at θ = 0?

    Same answer as ``bool(model.start_states())``, without building the states.
    """
    return any(a.size for _, _, a, _ in _pair_grasps(model))


def spread_starts(model: GaitModel, count: int) -> list[GaitState]:
    """``model.start_states()[::step][:count]`` with ``step = max(1, len // count)``: legal
    grasps at θ = 0 spread evenly through the list, without building every state.

    Empty when there is no legal start.
    """
    parts = _pair_grasps(model)
    total = sum(len(p[2]) for p in parts)
    out: list[GaitState] = []
    for idx in range(0, total, max(1, total // max(1, count))):
        if len(out) == count:
            break
        for f, g, a, b in parts:
            if idx < len(a):
                cs = [-1, -1, -1]
                cs[f], cs[g] = int(a[idx]), int(b[idx])
                out.append(GaitState(0, tuple(cs)))
                break
            idx -= len(a)
    return out


def check_start(model: GaitModel, start: GaitState) -> None:
    """Refuse a start that is not a legal grasp at ``k = 0`` (the caller's input error).

    Raises
    ------
    GraspGaitInputError
        ``start`` does not hold the object with two fingers in a stable grasp inside their
        workspaces at θ = 0 (a :class:`ValueError`, as before).
    """
    if not isinstance(start, GaitState) or start.k != 0 or not model.is_legal_state(start):
        raise GraspGaitInputError(
            f"start {start}: must be a legal state at k = 0 (two fingers on a stable grasp "
            "inside their workspaces); pick one of GaitModel.start_states()")


def no_start_verdict(model: GaitModel, planner: str,
                     t0: float | None = None) -> PlannerResult | None:
    """The no-gait verdict when no legal start exists, else ``None``.

    Parameters
    ----------
    model
        The gait model.
    planner
        The planner's label for :attr:`PlannerResult.planner`.
    t0
        ``time.perf_counter()`` when the planner started (for the wall time).

    Returns
    -------
    PlannerResult or None
        ``plan=None``, ``success=False``, ``exhausted=True`` (no start is a proof that no
        gait exists) and a reason beginning with :data:`NO_START` that says whether the
        grasp map is empty (raise mu) or its stable grasps all lie outside the workspaces
        (change the hand or the object); ``None`` when a legal start exists.
    """
    if legal_start_exists(model):
        return None
    name, mu = model.shape.name, model.mu
    stable = int(np.count_nonzero(model.stable)) // 2  # pairs: the map is symmetric
    if stable == 0:
        why = f"{name}'s grasp map at mu={mu:g} is empty (thesis 1.3 (2)); raise mu"
    else:
        why = (f"{name} at mu={mu:g} has {stable} stable pairs, none with both contacts in two "
               "fingers' workspaces (thesis 1.3 (2)); change the hand or the object")
    wall = 0.0 if t0 is None else time.perf_counter() - t0
    return PlannerResult(planner, None, reason=f"{NO_START}: {why}", exhausted=True,
                         wall_time_s=wall, extra={"verdict": "no start"})


def require_start(model: GaitModel, start: GaitState | None, planner: str,
                  t0: float | None = None) -> GaitState | PlannerResult:
    """The start rule of the planners that need a start (the searches, the exact planner).

    ``start`` itself when it is a legal start; the no-gait verdict
    (:func:`no_start_verdict`) when ``start`` is ``None`` and no legal start exists.

    Raises
    ------
    GraspGaitInputError
        ``start`` is ``None`` although legal starts exist (these planners do not choose
        one: pass a start, or use :func:`graspgait_env.planners.registry.run_planner`,
        which picks :func:`~graspgait_env.planners.registry.default_start`), or ``start``
        is not legal (:func:`check_start`).
    """
    if start is None:
        verdict = no_start_verdict(model, planner, t0)
        if verdict is not None:
            return verdict
        raise GraspGaitInputError(
            f"start=None: the {planner} planner needs a start grasp; pass one of "
            "GaitModel.start_states(), or call registry.run_planner, which picks "
            "registry.default_start")
    check_start(model, start)
    return start


def own_start_verdict(model: GaitModel, start: GaitState | None, t0: float,
                      method: str | None = None) -> PlannerResult | None:
    """The start rule of the planners that may choose their own start (the rule-based ones).

    With ``start=None``: the no-gait verdict (:func:`no_start_verdict`, labelled
    ``rule-based`` with ``extra["method"] = method``) when no legal start exists, else
    ``None`` (the planner chooses). With a start: ``None`` after :func:`check_start`.

    Raises
    ------
    GraspGaitInputError
        ``start`` is not legal (:func:`check_start`).
    """
    if start is not None:
        check_start(model, start)
        return None
    verdict = no_start_verdict(model, "rule-based", t0)
    if verdict is not None and method is not None:
        verdict.extra["method"] = method
    return verdict
