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
from graspgait_env.planners.starts import require_start

__all__ = ["optimal_gait", "PAIRS"]

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


def optimal_gait(model: GaitModel, start: GaitState | None,
                 turn_deg: float = 360.0) -> PlannerResult:
    """Minimum-regrasp gait from ``start`` turning the object ``turn_deg`` (sign = direction).

    Parameters
    ----------
    model
        The gait model.
    start
        Legal start state at ``k = 0``. ``None`` only answers when there is no legal
        start at all (the no-gait verdict of
        :func:`~graspgait_env.planners.starts.no_start_verdict`); otherwise it is refused
        (:func:`~graspgait_env.planners.registry.run_planner` picks a start).
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

    Raises
    ------
    GraspGaitInputError
        ``start`` is not a legal grasp at ``k = 0``, or ``None`` while legal ones exist.
    """
    t0 = time.perf_counter()
    s0 = require_start(model, start, "optimal", t0)
    if isinstance(s0, PlannerResult):  # no stable grasp at theta = 0: no gait
        return s0
    start = s0
    K = model.turn_steps(turn_deg)
    sign = 1 if K >= 0 else -1
    k_lo, k_hi = min(0, K) - model.n, max(0, K) + model.n
    seg = _Segments(model, k_lo, k_hi)
    level = [np.full(v.shape, -1, dtype=np.int32) for v in seg.valid]
    f0, g0 = start.held()
    pi0 = _pair_index(f0, g0)
    # unwrapped contact at k = 0: x = s + p
    i0 = model.ws_start[f0] + model.position(f0, start.contacts[f0], 0) - seg.x0[f0]
    j0 = model.ws_start[g0] + model.position(g0, start.contacts[g0], 0) - seg.x0[g0]
    level[pi0][i0, j0] = 0
    frontier = [np.zeros(v.shape, dtype=bool) for v in seg.valid]
    frontier[pi0][i0, j0] = True
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
        nxt = [np.zeros(v.shape, dtype=bool) for v in seg.valid]
        any_front = False
        for p, (f, g) in enumerate(PAIRS):
            fr = frontier[p]
            if not fr.any():
                continue
            any_front = True
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
                level[q][new] = lvl + 1
                nxt[q] |= new
                created += int(new.sum())
        if not any_front:
            break
        frontier = nxt
        lvl += 1
        if not any(fr.any() for fr in frontier):
            break

    wall = time.perf_counter() - t0
    if goal is None:
        return PlannerResult(
            "optimal", None,
            reason=(f"no gait turns {turn_deg:g} deg from {model.describe_state(start)}: the "
                    f"reachable grasps turn the object at most {best_turn * model.step_deg:g} deg "
                    f"(exhaustive search of the window [{k_lo * model.step_deg:g}, "
                    f"{k_hi * model.step_deg:g}] deg)"),
            nodes_opened=opened, nodes_created=created,
            max_turn_deg=sign * best_turn * model.step_deg, wall_time_s=wall, exhausted=True)
    states = _backtrack(model, seg, level, goal, K, sign, start)
    plan = plan_from_states(model, states, merge_rotations=True)
    res = PlannerResult(
        "optimal", plan, nodes_opened=opened, nodes_created=created,
        path_length=len(plan.steps) - 1, regrasps=plan.regrasps, rotation_deg=plan.rotation_deg,
        max_turn_deg=sign * best_turn * model.step_deg, wall_time_s=time.perf_counter() - t0)
    plan.stats = {"planner": "optimal", "nodes_opened": opened, "regrasps": plan.regrasps,
                  "rotation_deg": plan.rotation_deg}
    return res


def _backtrack(model: GaitModel, seg: _Segments, level, goal, K: int, sign: int,
               start: GaitState) -> list[GaitState]:
    """States from start to goal: regrasp at the segment angle farthest along the turn."""
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

    states = [start]
    for node_next, kreg in zip(chain[1:], regrasp_k, strict=True):
        cur = states[-1]
        if kreg != cur.k:
            states.append(GaitState(kreg, cur.contacts))
        states.append(state(node_next, kreg))
    if states[-1].k != K:
        states.append(GaitState(K, states[-1].contacts))
    return states
