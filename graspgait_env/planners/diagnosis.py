"""Why no gait turns the object, in the words of thesis 1.3, questions (2)–(4).

:func:`diagnose_no_gait` answers "why is there no gait?" for the command line and for
users: a short verdict with its most useful reason and fix, or (``verbose=True``) every
detail — the prototype numbers of 6.2–6.3 against ``w``, the conditions of the forward
(6.3.1) and back-and-forth (6.3.2) gaits, and what the exact planner proved from each
start tried.
"""

from __future__ import annotations

import numpy as np

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.prototypes import (
    BandPrototype,
    BoxPrototype,
    Check,
    WorkspaceGrid,
    back_and_forth_conditions,
    forward_conditions,
)
from graspgait_env.planners.starts import spread_starts

__all__ = ["diagnose_no_gait"]

_FIX_SEARCH = ("fix: plan with a search, which needs no prototype: --planner modified "
               "(thesis 6.4), best-first (5.5) or optimal")


def diagnose_no_gait(model: GaitModel, start: GaitState | None = None,
                     turn_deg: float = 360.0, candidates: int = 8,
                     verbose: bool = False) -> str:
    """Why no gait turns the object, in the words of thesis 1.3, questions (2)–(4).

    The first of these categories that applies opens the answer:

    1. ``"no stable grasp at all (mu=0.3)"`` — the grasp map is empty;
    2. ``"stable grasps but none reachable inside the workspaces"`` — no stable pair has
       its two contacts in two fingers' workspaces at θ = 0;
    3. ``"stuck at angle X deg"`` — the exact planner
       (:func:`~graspgait_env.planners.exact.optimal_gait`) proves that no gait from
       ``start`` (or from any of ``candidates`` starts spread through the legal ones)
       turns further than X; the prototype numbers (band/box against ``w``) say why
       rule-based gaits cannot help;
    4. ``"band/box smaller than the conditions need relative to w (...)"`` — a gait
       exists (found by the exact planner) but no prototype satisfies its conditions,
       so only a search finds it.

    When the forward or back-and-forth conditions hold and a gait exists, the answer
    opens with ``"a gait exists"``.

    Parameters
    ----------
    model
        The gait model.
    start
        The start grasp the planner was given, or ``None`` (the planner chose).
    turn_deg
        The requested turn (degrees).
    candidates
        Starts tried with the exact planner when ``start`` is ``None``.
    verbose
        ``False``: at most three lines — the verdict, the most useful reason, the fix.
        ``True``: the verdict line in full (the category, its numbers and the prototype
        numbers), then one line per detail: the grasp map, each gait's conditions, the
        exact planner's best turn from each start tried, the fix.

    Returns
    -------
    str
        Lines separated by ``"\\n"``, no trailing newline.

    Examples
    --------
    A regular pentagon at ``mu = 0.3`` has no stable grasp at all::

        >>> print(diagnose_no_gait(GaitModel("pentagon", 0.3)))  # doctest: +SKIP
        no stable grasp at all (mu=0.3): pentagon's grasp map is empty (thesis 1.3 (2))
        fix: raise mu (larger stable regions, thesis 3.2)
    """
    S = np.asarray(model.stable, dtype=bool)
    pairs = int(np.count_nonzero(S)) // 2  # the map is symmetric; the diagonal is False
    n = model.n
    g = WorkspaceGrid.from_model(model)
    grid = (f"grasp map: {pairs} stable pairs of {n * (n - 1) // 2} at mu={model.mu:g} "
            f"({model.step_deg:g}-degree grid); w = {g.w_deg:g} deg")
    if pairs == 0:  # thesis 1.3 (2): no stable grasp to start from
        verdict = (f"no stable grasp at all (mu={model.mu:g}): {model.shape.name}'s grasp map "
                   "is empty (thesis 1.3 (2))")
        fix = "fix: raise mu (larger stable regions, thesis 3.2)"
        return _lines(verbose, verdict, None, fix, [verdict, grid, fix])
    starts = [start] if start is not None else spread_starts(model, candidates)
    if not starts:  # thesis 1.3 (2): stable grasps, none inside the workspaces at θ = 0
        verdict = (f"stable grasps but none reachable inside the workspaces: {pairs} stable "
                   f"pairs at mu={model.mu:g}, none with both contacts in two fingers' "
                   "workspaces at theta = 0 (thesis 1.3 (2))")
        fix = ("fix: change the hand (workspaces holding a stable pair, thesis 4.2) or "
               "raise mu")
        ws = f"workspaces: {[list(w) for w in model.hand.workspaces_deg]} deg"
        return _lines(verbose, verdict, None, fix, [verdict, grid, ws, fix])
    band, fchecks = forward_conditions(S, g)
    box, bchecks = back_and_forth_conditions(S, g)
    proto = _prototype_numbers(band, fchecks, box, bchecks, g)
    details = [grid, _conditions("forward gait (thesis 6.3.1)", fchecks),
               _conditions("back-and-forth gait (thesis 6.3.2)", bchecks)]
    best = 0.0
    tried = []
    for s0 in starts:
        r = optimal_gait(model, s0, turn_deg)
        if r.success:
            tried.append(f"exact planner from {model.describe_state(s0)}: a gait with "
                         f"{r.regrasps} regrasps")
            if all(fchecks) or all(bchecks):  # thesis 6.3: a prototype gait's conditions
                kind = "forward" if all(fchecks) else "back-and-forth"
                verdict = f"a gait exists: the {kind} gait's conditions hold ({proto})"
                fix = ("fix: --planner rule (thesis 6.5) or optimal finds it; with another "
                       "planner, raise its node limit")
                return _lines(verbose, verdict, None, fix, [verdict, *details, *tried, fix])
            verdict = (f"band/box smaller than the conditions need relative to w ({proto}); a "
                       f"gait still exists (exact planner: {r.regrasps} regrasps), found by "
                       "search only")
            return _lines(verbose, verdict, None, _FIX_SEARCH,
                          [verdict, *details, *tried, _FIX_SEARCH])
        best = max(best, abs(r.max_turn_deg))
        tried.append(f"exact planner from {model.describe_state(s0)}: at most "
                     f"{abs(r.max_turn_deg):g} deg")
    # thesis 1.3 (3)-(4): no gait from here, whatever the earlier steps
    where = (model.describe_state(start) if start is not None
             else f"each of {len(starts)} start grasps tried")
    verdict = (f"stuck at angle {best:g} deg: from {where} no gait turns the object further "
               "(exhaustive exact search, thesis 1.3 (3)-(4))")
    why = f"why: {proto}"
    fix = ("fix: raise mu (larger stable regions, thesis 3.2) or change the hand (a smaller "
           "gap w between workspaces, thesis 6.3)")
    if start is not None:
        fix = "fix: try another start grasp (omit --start), " + fix[len("fix: "):]
    return _lines(verbose, verdict, why, fix, [f"{verdict}; {proto}", *details, *tried, fix])


def _lines(verbose: bool, verdict: str, why: str | None, fix: str, details: list[str]) -> str:
    """The short answer (verdict, reason, fix: at most three lines) or every detail."""
    if verbose:
        return "\n".join(details)
    return "\n".join(x for x in (verdict, why, fix) if x)


def _conditions(name: str, checks: list[Check]) -> str:
    """``forward gait (thesis 6.3.1) conditions fail: ...``, every condition's reason."""
    verdict = "hold" if all(checks) else "fail"
    return f"{name} conditions {verdict}: " + "; ".join(c.reason for c in checks)


def _prototype_numbers(band: BandPrototype | None, fchecks: list[Check],
                       box: BoxPrototype | None, bchecks: list[Check],
                       g: WorkspaceGrid) -> str:
    """``band height 12 deg < w = 30 deg; box 112 x 112 deg >= 2w x 2w = 60 x 60 deg``."""
    w = g.w_deg
    if band is None:
        parts = ["no band"]
    else:
        rel = ">=" if band.height_steps >= g.w_steps else "<"
        parts = [f"band height {band.height_deg:g} deg {rel} w = {w:g} deg"
                 + ("" if all(fchecks) or rel == "<" else " but misplaced")]
    if box is None:
        parts.append("no box")
    else:
        big = box.width_steps >= 2 * g.w_steps and box.height_steps >= 2 * g.w_steps
        parts.append(f"box {box.width_deg:g} x {box.height_deg:g} deg {'>=' if big else '<'} "
                     f"2w x 2w = {2 * w:g} x {2 * w:g} deg"
                     + ("" if all(bchecks) or not big
                        else " but not through both finger pair box pairs"))
    return "; ".join(parts)
