"""Exact planner: the minimum number of regrasps for a requested turn (beyond the thesis).

Idea. Rotation is free and reversible inside a finger pair box: with the contacts fixed,
the object can turn anywhere in the interval of angles for which both contacts stay in
their workspaces (thesis 5.2, fig. 5.1). So the state space collapses onto *segments*:
a finger pair ``(f, g)`` holding unwrapped object contacts ``(x_f, x_g)`` — a point of
the extended grasp map (thesis 4.3) — together with its interval ``[k_min, k_max]`` of
reachable object angles. Regrasps are the only cost, and a regrasp from segment
``(f, g, x_f, x_g)`` that keeps ``f`` and places the free finger ``h`` reaches every
``x_h`` in one contiguous interval (any angle ``k`` of the segment, any position of
``h``'s workspace), subject to force closure of ``(x_f, x_h)``: a horizontal or vertical
move in the extended map. Breadth-first search over segments, level by level, with the
intervals unioned by a difference array, is then exact for the minimum number of
regrasps; every level is a handful of NumPy operations on the ``(L_f, L_g)`` arrays of
the three finger pairs.

Search window: object angles ``k`` in ``[min(0, T) - 360°, max(0, T) + 360°]`` where
``T`` is the requested turn (one full turn of slack on each side; the gait graph is
periodic in θ with period 360°). "No gait" is a proof for that window.

Coordinates: finger ``f`` at workspace position ``p`` and object angle ``k`` (grid steps)
holds unwrapped contact ``x_f = s_f + p - k`` (``s_f`` the unwrapped ``F`` grid index of
its workspace's first grid angle), so ``p = x_f - s_f + k`` and the segment's interval
is ``k ∈ [s_f - x_f, s_f + W_f - 1 - x_f] ∩ (same for g) ∩ window``.
"""

from __future__ import annotations

import time

import numpy as np

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import plan_from_states
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.starts import check_start, no_start_verdict

__all__ = ["optimal_gait", "PAIRS", "RegraspsToGo"]

PAIRS = ((0, 1), (0, 2), (1, 2))


def _pair_index(a: int, b: int) -> int:
    return PAIRS.index((min(a, b), max(a, b)))


class _Segments:
    """Per finger pair: stability and the k-interval of every extended-map point."""

    def __init__(self, model: GaitModel, k_lo: int, k_hi: int) -> None:
        self.model = model
        self.k_lo, self.k_hi = k_lo, k_hi
        s, W, n = model.ws_start, model.ws_width, model.n
        # unwrapped contact range of each finger over the window
        self.x0 = [int(s[f] - k_hi) for f in range(3)]
        self.L = [int(W[f] + k_hi - k_lo) for f in range(3)]
        self.kmin, self.kmax, self.valid = [], [], []
        for f, g in PAIRS:
            xf = self.x0[f] + np.arange(self.L[f])
            xg = self.x0[g] + np.arange(self.L[g])
            # the segment's angles: from k = 0, where the fingers sit at positions
            # p = x - s (inside their workspaces or not), the object may turn ``ccw``
            # steps one way and ``cw`` the other (thesis 5.2, GaitModel.rotation_room)
            ccw, cw = model.rotation_room(f, (xf - s[f])[:, None], g, (xg - s[g])[None, :])
            kmin = np.maximum(-cw, k_lo)
            kmax = np.minimum(ccw, k_hi)
            stable = model.stable[np.ix_(xf % n, xg % n)]
            self.kmin.append(kmin)
            self.kmax.append(kmax)
            self.valid.append(stable & (kmin <= kmax))

    def h_interval(self, h: int, kmin, kmax):
        """Unwrapped x_h (array index) range that finger h can take at angles [kmin, kmax]."""
        s, W = self.model.ws_start, self.model.ws_width
        lo = s[h] - kmax - self.x0[h]
        hi = s[h] + W[h] - 1 - kmin - self.x0[h]
        return np.clip(lo, 0, self.L[h]), np.clip(hi, -1, self.L[h] - 1)


def _expand(seg: _Segments, frontier: list[np.ndarray], level: list[np.ndarray],
            lvl: int) -> tuple[list[np.ndarray], int, int]:
    """One breadth-first level: every segment one regrasp from ``frontier`` not yet
    reached gets ``level = lvl`` (written in place) and makes the next frontier.

    Returns ``(next frontier, segments expanded, segments reached)``.
    """
    nxt = [np.zeros(v.shape, dtype=bool) for v in seg.valid]
    opened = created = 0
    for p, (f, g) in enumerate(PAIRS):
        fr = frontier[p]
        if not fr.any():
            continue
        opened += int(fr.sum())
        h = 3 - f - g
        I, J = np.nonzero(fr)
        lo, hi = seg.h_interval(h, seg.kmin[p][I, J], seg.kmax[p][I, J])
        for keep, key in ((f, I), (g, J)):
            q = _pair_index(keep, h)
            Lh = seg.L[h]
            D = np.zeros((seg.L[keep], Lh + 1), dtype=np.int32)
            ok = lo <= hi
            np.add.at(D, (key[ok], lo[ok]), 1)
            np.add.at(D, (key[ok], hi[ok] + 1), -1)
            cover = np.cumsum(D[:, :Lh], axis=1) > 0
            if keep > h:  # pair q is (h, keep): rows are h
                cover = cover.T
            new = cover & seg.valid[q] & (level[q] < 0)
            level[q][new] = lvl
            nxt[q] |= new
            created += int(new.sum())
    return nxt, opened, created


def optimal_gait(model: GaitModel, start: GaitState | None,
                 turn_deg: float = 360.0) -> PlannerResult:
    """Minimum-regrasp gait from ``start`` turning the object ``turn_deg`` (sign = direction).

    Parameters
    ----------
    model
        The gait model.
    start
        Legal start state at ``k = 0``: the optimum from it. ``None``: the optimum for
        the object — the fewest regrasps over every legal start grasp at θ = 0 (every
        one is seeded at cost 0, so the breadth-first levels are the minimum over all
        starts); the plan starts from the start it chose (``extra["start"]``). With no
        legal start at all: the no-gait verdict of
        :func:`~graspgait_env.planners.starts.no_start_verdict`.
    turn_deg
        Requested turn (degrees; negative for clockwise).

    Returns
    -------
    PlannerResult
        ``planner="optimal"``. With a plan: the fewest regrasps achieving the turn
        (rotations merged, each regrasp made as far along the turn as its segment
        allows). Without: ``exhausted=True``, ``max_turn_deg`` the largest turn
        reachable in the search window, and the reason.
        ``nodes_opened`` counts segments expanded, ``nodes_created`` segments reached.
        ``extra["start"]`` describes the start of the plan, ``extra["start_chosen"]`` is
        True when the planner chose it (``start=None``) and ``extra["starts_seeded"]``
        counts the start grasps searched from.

    Raises
    ------
    GraspGaitInputError
        ``start`` is not a legal grasp at ``k = 0``.
    """
    t0 = time.perf_counter()
    if start is None:
        verdict = no_start_verdict(model, "optimal", t0)
        if verdict is not None:  # no stable grasp at theta = 0: no gait
            return verdict
    else:
        check_start(model, start)
    K = model.turn_steps(turn_deg)
    sign = 1 if K >= 0 else -1
    k_lo, k_hi = min(0, K) - model.n, max(0, K) + model.n
    seg = _Segments(model, k_lo, k_hi)
    level = [np.full(v.shape, -1, dtype=np.int32) for v in seg.valid]
    frontier = [np.zeros(v.shape, dtype=bool) for v in seg.valid]
    if start is None:  # every legal grasp at k = 0 (both contacts in their workspaces)
        for p, (f, g) in enumerate(PAIRS):
            # unwrapped contact at k = 0: x = s + p, array index x - x0
            I = model.ws_start[f] + np.arange(model.ws_width[f]) - seg.x0[f]
            J = model.ws_start[g] + np.arange(model.ws_width[g]) - seg.x0[g]
            frontier[p][np.ix_(I, J)] = seg.valid[p][np.ix_(I, J)]
    else:
        f0, g0 = start.held()
        i0 = model.ws_start[f0] + model.position(f0, start.contacts[f0], 0) - seg.x0[f0]
        j0 = model.ws_start[g0] + model.position(g0, start.contacts[g0], 0) - seg.x0[g0]
        frontier[_pair_index(f0, g0)][i0, j0] = True
    seeded = int(sum(fr.sum() for fr in frontier))
    for lv, fr in zip(level, frontier, strict=True):
        lv[fr] = 0
    opened = created = 0
    best_turn = 0
    lvl = 0
    goal = None
    while True:
        # goal test and best turn on this level
        for p in range(3):
            fr = frontier[p]
            if not fr.any():
                continue
            reach = seg.kmax[p][fr] if sign > 0 else seg.kmin[p][fr]
            best_turn = max(best_turn, int((reach * sign).max()))
            hit = fr & ((seg.kmax[p] >= K) if sign > 0 else (seg.kmin[p] <= K))
            if hit.any() and goal is None:
                i, j = np.argwhere(hit)[0]
                goal = (p, int(i), int(j))
        if goal is not None:
            break
        frontier, o, c = _expand(seg, frontier, level, lvl + 1)
        opened += o
        created += c
        lvl += 1
        if not any(fr.any() for fr in frontier):
            break

    wall = time.perf_counter() - t0
    where = (model.describe_state(start) if start is not None
             else f"any of the {seeded} start grasps at theta = 0")
    if goal is None:
        return PlannerResult(
            "optimal", None,
            reason=(f"no gait turns {turn_deg:g} deg from {where}: the "
                    f"reachable grasps turn the object at most {best_turn * model.step_deg:g} deg "
                    f"(exhaustive search of the window [{k_lo * model.step_deg:g}, "
                    f"{k_hi * model.step_deg:g}] deg)"),
            nodes_opened=opened, nodes_created=created,
            max_turn_deg=sign * best_turn * model.step_deg, wall_time_s=wall, exhausted=True)
    states = _backtrack(model, seg, level, goal, K, sign, start)
    plan = plan_from_states(model, states, merge_rotations=True)
    extra = {"start": model.describe_state(states[0]), "start_chosen": start is None,
             "starts_seeded": seeded}
    res = PlannerResult(
        "optimal", plan, nodes_opened=opened, nodes_created=created,
        path_length=len(plan.steps) - 1, regrasps=plan.regrasps, rotation_deg=plan.rotation_deg,
        max_turn_deg=sign * best_turn * model.step_deg, wall_time_s=time.perf_counter() - t0,
        extra=extra)
    plan.stats = {"planner": "optimal", "nodes_opened": opened, "regrasps": plan.regrasps,
                  "rotation_deg": plan.rotation_deg}
    if start is None:  # the plan says which start the planner chose
        plan.stats["start_chosen"] = True
    return res


def _backtrack(model: GaitModel, seg: _Segments, level, goal, K: int, sign: int,
               start: GaitState | None) -> list[GaitState]:
    """States from start to goal: regrasp at the segment angle farthest along the turn
    (``start=None``: from the level-0 segment the chain leads back to, at ``k = 0``)."""
    s, W, n = model.ws_start, model.ws_width, model.n
    chain = [goal]  # (pair, i, j) from goal back to start
    p, i, j = goal
    lv = level[p][i, j]
    regrasp_k = []
    while lv > 0:
        f, g = PAIRS[p]
        xs = {f: i, g: j}
        found = None
        for keep, h in ((f, g), (g, f)):
            t = 3 - f - g
            q = _pair_index(keep, t)
            xh = seg.x0[h] + xs[h]
            # candidate predecessors: keep's coordinate fixed, t's free
            if keep < t:
                rows = level[q][xs[keep], :]
                cand = np.flatnonzero(rows == lv - 1)
                kmin, kmax = seg.kmin[q][xs[keep], cand], seg.kmax[q][xs[keep], cand]
            else:
                cols = level[q][:, xs[keep]]
                cand = np.flatnonzero(cols == lv - 1)
                kmin, kmax = seg.kmin[q][cand, xs[keep]], seg.kmax[q][cand, xs[keep]]
            a = np.maximum(kmin, s[h] - xh)
            b = np.minimum(kmax, s[h] + W[h] - 1 - xh)
            ok = np.flatnonzero(a <= b)
            if ok.size:
                c = ok[0]
                kreg = int(b[c]) if sign > 0 else int(a[c])
                pi, pj = (xs[keep], int(cand[c])) if keep < t else (int(cand[c]), xs[keep])
                found = (q, pi, pj, kreg)
                break
        if found is None:  # a bug, never the user's input
            raise RuntimeError("exact planner: broken predecessor chain")
        p, i, j, kreg = found
        chain.append((p, i, j))
        regrasp_k.append(kreg)
        lv -= 1
    chain.reverse()
    regrasp_k.reverse()

    def state(node, k) -> GaitState:
        q, a, b = node
        f, g = PAIRS[q]
        cs = [-1, -1, -1]
        cs[f] = int((seg.x0[f] + a) % n)
        cs[g] = int((seg.x0[g] + b) % n)
        return GaitState(int(k), tuple(cs))

    states = [start if start is not None else state(chain[0], 0)]
    for node_next, kreg in zip(chain[1:], regrasp_k, strict=True):
        cur = states[-1]
        if kreg != cur.k:
            states.append(GaitState(kreg, cur.contacts))
        states.append(state(node_next, kreg))
    if states[-1].k != K:
        states.append(GaitState(K, states[-1].contacts))
    return states


def _to_go_window(model: GaitModel, turn_deg: float, max_backward_deg: float
                  ) -> tuple[int, int, int, _Segments]:
    """``(K, B, sign, segments)``: the turn and the backward reach in grid steps, the
    turn's sign, and the segments of :class:`RegraspsToGo`'s window (object angles from
    ``B`` against the turn to the turn itself)."""
    K = model.turn_steps(turn_deg)
    B = abs(model.turn_steps(max_backward_deg))
    sign = 1 if K >= 0 else -1
    k_lo, k_hi = (-B, K) if sign > 0 else (K, B)
    return K, B, sign, _Segments(model, k_lo, k_hi)


class RegraspsToGo:
    """The fewest regrasps from every state to the requested turn: one table per model.

    The exact planner's breadth-first search run backwards, from every segment that
    reaches the turn (level 0) outwards. A regrasp can be undone (the same two grasps
    share an object angle, thesis 4.2), so the regrasp graph over segments is undirected
    and the level of a segment is its fewest regrasps *to* the goal. Rotations stay inside
    a segment (thesis 5.2), so every state of a segment has the same count: calling the
    table on a start state gives what :func:`optimal_gait` reports from it.

    Search window (a choice, tested): object angles from ``max_backward_deg`` against
    the turn to the turn itself, the angles an episode of the GraspGait envs can visit
    before it ends (``optimal_gait`` also searches one more turn back; no bundled object
    needs it).

    Parameters
    ----------
    model
        The gait model.
    turn_deg
        Requested turn (degrees; negative: clockwise).
    max_backward_deg
        How far against the turn the window reaches (degrees, > 0).

    Examples
    --------
    >>> from graspgait_env.gait import GaitModel
    >>> model = GaitModel("ellipse", 0.7)
    >>> to_go = RegraspsToGo(model, 360.0, 360.0)
    >>> start = model.start_state({1: 50.0, 3: 270.0})
    >>> to_go(start) == optimal_gait(model, start, 360.0).regrasps
    True
    """

    def __init__(self, model: GaitModel, turn_deg: float = 360.0,
                 max_backward_deg: float = 360.0) -> None:
        K, B, sign, seg = _to_go_window(model, turn_deg, max_backward_deg)
        self.model, self.turn_steps = model, K
        self._seg = seg
        level = [np.full(v.shape, -1, dtype=np.int32) for v in seg.valid]
        frontier = [v & ((km >= K) if sign > 0 else (kn <= K))
                    for v, km, kn in zip(seg.valid, seg.kmax, seg.kmin, strict=True)]
        for lv, fr in zip(level, frontier, strict=True):
            lv[fr] = 0
        lvl = 0
        while any(fr.any() for fr in frontier):
            lvl += 1
            frontier, _, _ = _expand(seg, frontier, level, lvl)
        self.levels = level
        """Per finger pair (``PAIRS`` order), the count of every extended-map point
        ``(x_f, x_g)`` (array index ``x - x0``); -1: no gait from it in the window."""

    def __call__(self, state: GaitState) -> int:
        """Fewest regrasps from ``state`` to the turn; -1 when no gait exists from it
        (or ``state`` lies outside the window)."""
        seg, model = self._seg, self.model
        f, g = state.held()
        k = int(state.k)
        if not seg.k_lo <= k <= seg.k_hi:
            return -1
        # unwrapped contact x = s + p - k (see the module docstring)
        i = model.ws_start[f] + model.position(f, state.contacts[f], k) - k - seg.x0[f]
        j = model.ws_start[g] + model.position(g, state.contacts[g], k) - k - seg.x0[g]
        lv = self.levels[_pair_index(f, g)]
        if not (0 <= i < lv.shape[0] and 0 <= j < lv.shape[1]):
            return -1
        return int(lv[i, j])
