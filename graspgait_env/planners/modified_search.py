"""The modified search (thesis 6.4): pruning the search tree using prototype gaits.

When a grasp map holds no band or box of sufficient size but still follows the general
trend of its type (the thesis's pentagon: a staircase fits although no band does), a
depth-first search restricted to the gait structure known to work for that type
(:func:`map_structure`: the staircase of 6.3.1 or the + of 6.3.2) finds a gait with the
step sizes fitted to the map. See :func:`modified_search` for the structures and the
branch order; counting as in :mod:`~graspgait_env.planners.trace`.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.prototypes import (
    WorkspaceGrid,
    back_and_forth_conditions,
    band_prototypes,
)
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.starts import check_start, no_start_verdict, spread_starts
from graspgait_env.planners.trace import Trace, gait_failure, gait_pattern, gait_result

__all__ = ["modified_search", "map_structure", "DEFAULT_MAX_NODES"]

DEFAULT_MAX_NODES = 20_000  # (nodes opened) cap of the modified search

_FREE, _ROTATED, _ROTATED_B, _BACK1, _BACK2 = "free", "rotated", "rotated-b", "back1", "back2"


class _Modified:
    """Depth-first search over the moves of one gait structure (thesis 6.4)."""

    def __init__(self, model: GaitModel, g: WorkspaceGrid, K: int, plus: bool) -> None:
        self.m, self.g, self.K, self.plus = model, g, K, plus
        self.sign = 1 if K >= 0 else -1
        self.tiled = np.tile(np.asarray(model.stable, dtype=bool), (1, 2))
        self.opened = self.created = 0
        self.best_k = 0
        self.exhausted = False

    def regrasps(self, s: GaitState, forward: bool) -> Iterator[GaitState]:
        """Forward (or backward) regrasps of ``s``, smallest forward / largest backward
        step first (both: the free finger's positions from the trailing end)."""
        m, g, sign = self.m, self.g, self.sign
        f, g2 = s.held()
        h = 3 - f - g2
        ahead = g.pred(h) if sign > 0 else g.succ(h)  # the finger a forward step replaces
        lift = ahead if forward else (g2 if ahead == f else f)
        keep = g2 if lift == f else f
        W = int(m.ws_width[h])
        i0 = (int(m.ws_start[h]) - s.k) % m.n
        ok = self.tiled[s.contacts[keep], i0 : i0 + W]
        ps = np.flatnonzero(ok)
        if sign < 0:
            ps = ps[::-1]
        for p in ps:
            cs = list(s.contacts)
            cs[h] = (i0 + int(p)) % m.n
            cs[lift] = -1
            yield GaitState(s.k, tuple(cs))

    def _any_regrasp(self, s: GaitState, deltas: NDArray[np.int64]
                     ) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """For each rotation in ``deltas`` (grid steps, signed): does a forward / a backward
        regrasp exist after it? (one-step look-ahead, prefix sums over a map row)"""
        m, g, sign = self.m, self.g, self.sign
        f, g2 = s.held()
        h = 3 - f - g2
        ahead = g.pred(h) if sign > 0 else g.succ(h)
        W = int(m.ws_width[h])
        i0 = (int(m.ws_start[h]) - s.k - deltas) % m.n
        out = []
        for keep in (g2 if ahead == f else f, ahead):  # forward keeps the other finger
            cs = np.concatenate(([0], np.cumsum(self.tiled[s.contacts[keep]])))
            out.append((cs[i0 + W] - cs[i0]) > 0)
        return out[0], out[1]

    def children(self, s: GaitState, phase: str,
                 is_start: bool = False) -> Iterator[tuple[GaitState, str, str]]:
        sign = self.sign
        back_first = phase == _ROTATED_B
        if phase == _FREE:
            ccw, cw = self.m.state_rotation_room(s)  # thesis 5.2: the rotation limit
            lim = ccw if sign > 0 else cw
            togo = abs(self.K - s.k)
            if 0 < togo <= lim:  # the goal is in reach: rotate there (6.3.1 rule 1)
                yield GaitState(self.K, s.contacts), _ROTATED, "rotate to goal"
            deltas = np.arange(min(lim, togo - 1), 0, -1)
            if deltas.size:
                fwd, bwd = self._any_regrasp(s, sign * deltas)
                # first the rotation to the box edge, or as far as a forward regrasp
                # exists (6.3.1 rule 1); plus: also the last angle at which a backward
                # regrasp exists (the upper/right limit of 6.3.2 rules 2-4); then, on
                # backtracking, every other rotation after which the structure goes on
                first: list[tuple[int, str]] = []
                if fwd.any():
                    first.append((int(deltas[fwd][0]), _ROTATED))
                if self.plus and bwd.any():
                    first.append((int(deltas[bwd][0]), _ROTATED_B))
                for d, ph in first:
                    yield GaitState(s.k + sign * d, s.contacts), ph, "rotate"
                ok = (fwd | bwd) if self.plus else fwd
                for d in deltas[ok]:
                    if all(d != d0 for d0, _ in first):
                        yield GaitState(s.k + sign * int(d), s.contacts), _ROTATED, "rotate"
        # thesis 6.3.1 rules 2-3 (forward), 6.3.2 rules 6-11 (backward, plus only)
        kinds = [True, False] if self.plus and phase != _BACK2 else [True]
        if back_first:
            kinds.reverse()
        for forward in kinds:
            if forward:
                for t in self.regrasps(s, forward=True):
                    yield t, _FREE, "forward regrasp"
            else:
                nb = _BACK2 if phase == _BACK1 else _BACK1
                for t in self.regrasps(s, forward=False):
                    yield t, nb, "backward regrasp"
        if is_start:
            # from the start only: turn the other way first (6.3.2, initial conditions)
            ccw, cw = self.m.state_rotation_room(s)
            back = cw if sign > 0 else ccw
            deltas = np.arange(back, 0, -1)
            if deltas.size:
                fwd, bwd = self._any_regrasp(s, -sign * deltas)
                ok = (fwd | bwd) if self.plus else fwd
                for d in deltas[ok]:
                    yield GaitState(s.k - sign * int(d), s.contacts), _ROTATED, "turn back"

    def search(self, start: GaitState, max_nodes: int) -> tuple[list[GaitState], list[str]] | None:
        """Depth-first search; the path of states (and move labels) or ``None``."""
        seen = {(start, _FREE)}
        path = [start]
        labels: list[str] = []
        stack = [self.children(start, _FREE, is_start=True)]
        while stack:
            if self.opened >= max_nodes:
                return None
            try:
                t, phase, label = next(stack[-1])
            except StopIteration:
                stack.pop()
                path.pop()
                if labels:
                    labels.pop()
                continue
            self.created += 1
            if (t, phase) in seen:
                continue
            seen.add((t, phase))
            self.opened += 1
            self.best_k = max(self.best_k, self.sign * t.k)
            path.append(t)
            labels.append(label)
            if self.sign * (t.k - self.K) >= 0:
                return path, labels
            stack.append(self.children(t, phase))
        self.exhausted = True
        return None


def map_structure(model: GaitModel) -> str:
    """The gait structure known to work for this map's type (thesis 6.2, 6.4).

    ``"staircase"`` when a band at least ``w`` tall runs along the diagonal (stable
    regions in the direction of the finger pair boxes, fig. 6.1); ``"plus"`` when there is
    no such band but a box ``>= 2w × 2w`` placed through both box pairs (fig. 6.2);
    otherwise ``"staircase"``, the thesis's choice for a map whose band is broken but
    still follows the diagonal (the pentagon of 6.4).
    """
    g = WorkspaceGrid.from_model(model)
    if any(b.height_steps >= g.w_steps for b in band_prototypes(model.stable)):
        return "staircase"
    _, checks = back_and_forth_conditions(model.stable, g)
    return "plus" if all(checks) else "staircase"


def modified_search(model: GaitModel, start: GaitState | None = None, turn_deg: float = 360.0,
                    structure: str | None = None,
                    max_nodes: int = DEFAULT_MAX_NODES) -> PlannerResult:
    """The modified search of thesis 6.4: depth-first, restricted to one gait structure.

    Structures
    ----------
    ``"staircase"`` (6.3.1): rotations in the turn's direction only, each followed by a
    *forward* regrasp (the free finger replaces the finger whose workspace precedes it:
    a positive horizontal or vertical step into the next box); regrasps may follow each
    other without a rotation (the box corner of rules 2–3).
    ``"plus"`` (6.3.2): the same, plus *backward* regrasps (the free finger replaces the
    finger whose workspace follows it: a negative step), at most two in a row and always
    followed by a forward regrasp before the next rotation (rules 6–8, 9–11).

    Branch order (the rules first, backtracking over the step sizes): at a grasp, rotate
    as far as the box edge or as far as a forward regrasp then exists (6.3.1 rule 1); for
    the plus structure next as far as a backward regrasp then exists (the upper/right
    limit of 6.3.2), then every smaller rotation after which the structure can go on;
    after a rotation, forward regrasps with the smallest step first (to the edge of the
    next box), backward ones with the largest step first (after an upper/right-limit
    rotation the backward ones come first). Only from the start grasp may the object also
    turn the other way first (6.3.2: "would first have to rotate backwards"). A
    one-step look-ahead skips rotations after which no regrasp of the structure exists.
    A state (with its phase in the structure) is entered once. Rotations are bounded by
    :meth:`GaitModel.rotation_room`, the one definition of the rotation limit.

    Parameters
    ----------
    model
        The gait model.
    start
        Start grasp at ``k = 0``; ``None``: up to 8 legal starts spread through
        :meth:`GaitModel.start_states` are tried in turn (their nodes add up).
    turn_deg
        Requested turn (degrees; negative: clockwise).
    structure
        ``"staircase"``, ``"plus"`` or ``None``: :func:`map_structure` first, then the
        other, the first getting half of ``max_nodes``.
    max_nodes
        Cap on nodes opened.

    Returns
    -------
    PlannerResult
        ``planner="modified-search"``. ``nodes_opened`` counts the states the search
        entered (each rotation and each regrasp tried is one node), so a search that
        never backtracks has ``nodes_opened == path_length``. ``extra["structure"]``
        names the structure that found the gait; ``pattern`` is ``staircase`` when no
        backward regrasp was used, else ``plus`` / ``combined``. With ``start=None`` and
        no stable grasp inside the workspaces at θ = 0: the no-gait verdict of
        :func:`~graspgait_env.planners.starts.no_start_verdict`.

    Raises
    ------
    GraspGaitInputError
        ``start`` is not a legal grasp at ``k = 0``.
    """
    t0 = time.perf_counter()
    extra: dict[str, Any] = {"method": "modified-search"}
    if start is not None:
        check_start(model, start)
        starts = [start]
    else:
        verdict = no_start_verdict(model, "modified-search", t0)
        if verdict is not None:
            verdict.extra.update(extra)
            return verdict
        starts = spread_starts(model, 8)
    g = WorkspaceGrid.from_model(model)
    K = model.turn_steps(turn_deg)
    first = structure or map_structure(model)
    order = [first] if structure else [first, "plus" if first == "staircase" else "staircase"]
    opened = created = best = 0
    exhausted = True
    for s0 in starts:
        for i, st in enumerate(order):
            budget = max_nodes - opened
            if len(order) == 2 and i == 0:
                budget = min(budget, max_nodes // 2)
            srch = _Modified(model, g, K, plus=(st == "plus"))
            found = srch.search(s0, budget)
            opened += srch.opened
            created += srch.created
            best = max(best, srch.best_k)
            exhausted &= srch.exhausted
            if found is None:
                continue
            states, labels = found
            trace = Trace(model, [s0])
            for t, lab in zip(states[1:], labels, strict=True):
                trace.push(t, lab)
            back = sum(lab == "backward regrasp" for lab in labels)
            res = gait_result("modified-search", model, trace, t0,
                              gait_pattern(model, trace, back), {**extra, "structure": st})
            res.nodes_opened, res.nodes_created = opened, created
            if res.plan is not None:
                res.plan.stats["nodes_opened"] = opened
            return res
        if opened >= max_nodes:
            break
    why = "exhausted its" if exhausted else f"stopped at the node limit ({max_nodes}) in the"
    return gait_failure("modified-search", f"modified search ({' then '.join(order)}) {why} "
                        f"search space after {opened} nodes; best turn "
                        f"{_sign_deg(best, K, model):g} deg",
                        t0, extra, _sign_deg(best, K, model), (opened, created), exhausted)


def _sign_deg(best: int, K: int, model: GaitModel) -> float:
    """The best turn reached, in degrees, signed like the requested turn."""
    return (1 if K >= 0 else -1) * best * model.step_deg
