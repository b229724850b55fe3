"""How far towards the turn a grasp can take the object within ``j`` more regrasps.

A depth-limited version of the exact planner's search (:mod:`~graspgait_env.planners.
exact`, beyond the thesis): on the same *segments* (a finger pair holding two fixed
contacts, with the interval of object angles its rotations reach, thesis 5.2) the
**reach** of a segment within ``j`` regrasps is the farthest object angle towards the
requested turn that some chain of at most ``j`` regrasps from it, with any rotations in
between, can turn the object to (capped at the turn). Its recursion:

- ``reach_0(s)`` = the end of ``s``'s own interval towards the turn (rotation only);
- ``reach_j(s) = max(reach_{j-1}(s), max over the segments s' one regrasp from s of
  reach_{j-1}(s'))``.

One regrasp from ``s`` keeps one of its contacts and places the free finger at any
contact it can touch at some angle of ``s``'s interval (a contiguous run of the extended
grasp map, thesis 4.2), so the inner max is a range maximum along a row of the extended
map; a sparse table answers all of them at once per level. The regrasp relation is
symmetric (both grasps share the regrasp's object angle), as in the exact planner.

Why it exists: it prices a regrasp by what it leads to, a few regrasps deep, which is
what the forward gait (thesis 6.3.1: the regrasp with the most rotation room, one
regrasp deep) cannot see. The GraspGait envs offer it as an opt-in observation field
(``regrasp_lookahead``). It is not the optimum: at depth ``J`` it tells whether the turn
is reached within ``J`` more regrasps and, when not, how close the best such chain gets;
the exact planner's count to go is the smallest ``j`` with a shortfall of 0, which for
the procedural objects is about 9 regrasps from the start (up to 21 on the held-out
ones), mostly beyond the depths offered.

Search window: the exact planner's :class:`~graspgait_env.planners.exact.RegraspsToGo`
window (object angles from ``max_backward_deg`` against the turn to the turn), so a
segment's reach never exceeds the turn.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.exact import PAIRS, _pair_index, _to_go_window

__all__ = ["MAX_REACH_DEPTH", "RegraspReach"]

MAX_REACH_DEPTH = 9
"""The deepest reach table :class:`RegraspReach` builds (regrasps); the envs'
``regrasp_lookahead`` goes one deeper, to 10. Each level is one ``(3, L, L)`` int64 table
(``L`` the longest finger's contact range) and adds a propagation per gait model; the
orders read from the tables are lexicographic sorts, so no depth overflows a packed key.
Measured on held-out procedural objects (hand contact, 300 resets from seed 20000, the
benchmark's greedy reading): 96.6% of the 146 starts with a gait at 5 regrasps deep,
97.9% at 6, 100% at 8 (1.007x the optimum's regrasps) and at 10 (1.004x)."""


def _range_max(values: NDArray[np.int64], lo: NDArray[np.int64],
               hi: NDArray[np.int64], fill: int) -> NDArray[np.int64]:
    """Row-wise ``max(values[r, lo[r, c] .. hi[r, c]])`` for every ``(r, c)``, ``fill``
    where ``lo > hi`` (empty range): a sparse table over each row."""
    L = values.shape[1]
    tables = [values]
    width = 1
    while 2 * width <= L:
        prev = tables[-1]
        nxt = prev.copy()
        nxt[:, : L - width] = np.maximum(prev[:, : L - width], prev[:, width:])
        tables.append(nxt)
        width *= 2
    length = hi - lo + 1
    empty = length < 1
    # floor(log2(length)) exactly, for integers
    lev = np.frexp(np.maximum(length, 1).astype(np.float64))[1].astype(np.int64) - 1
    rows = np.broadcast_to(np.arange(values.shape[0])[:, None], lo.shape)
    out = np.full(lo.shape, fill, dtype=np.int64)
    ok = ~empty
    r, a, b, e = rows[ok], lo[ok], hi[ok], lev[ok]
    stack = np.stack(tables)  # (levels, rows, L)
    left = stack[e, r, a]
    right = stack[e, r, b - (1 << e) + 1]
    out[ok] = np.maximum(left, right)
    return out


class RegraspReach:
    """Reach tables of one gait model and turn: ``reach_j`` for ``j = 0 .. depth``.

    Parameters
    ----------
    model
        The gait model.
    turn_deg
        Requested turn (degrees; negative: clockwise).
    max_backward_deg
        How far against the turn the search window reaches (degrees, > 0), as
        :class:`~graspgait_env.planners.exact.RegraspsToGo`.
    depth
        The deepest table (regrasps), ``0 .. MAX_REACH_DEPTH``.

    Attributes
    ----------
    depth, turn_steps
        As given (the turn in grid steps, signed).
    levels
        ``levels[j][pair]``: the reach of every extended-map point of the pair (``PAIRS``
        order, array index ``x - x0``) within ``j`` regrasps, in grid steps *towards the
        turn* (the object angle times the turn's sign); ``unreachable`` for points that
        are no legal segment of the window.

    Examples
    --------
    >>> from graspgait_env.gait import GaitModel
    >>> from graspgait_env.planners.exact import RegraspsToGo
    >>> model = GaitModel("ellipse", 0.7)
    >>> start = model.start_state({1: 50.0, 3: 270.0})
    >>> reach = RegraspReach(model, 360.0, 360.0, depth=4)
    >>> to_go = RegraspsToGo(model, 360.0, 360.0)(start)
    >>> [reach.shortfall(start, j) == 0 for j in range(to_go - 1, to_go + 1)]
    [False, True]
    """

    def __init__(self, model: GaitModel, turn_deg: float = 360.0,
                 max_backward_deg: float = 360.0, depth: int = 2) -> None:
        if isinstance(depth, bool) or not isinstance(depth, (int, np.integer)) \
                or not 0 <= int(depth) <= MAX_REACH_DEPTH:
            raise GraspGaitInputError(
                f"depth={depth!r}: the reach look-ahead is 0 .. {MAX_REACH_DEPTH} regrasps "
                "deep; give e.g. 2")
        K, B, sign, seg = _to_go_window(model, turn_deg, max_backward_deg)
        self.model, self.turn_steps, self.depth, self._sign = model, K, int(depth), sign
        self._seg = seg
        self.unreachable = -(B + 1)  # below every angle of the window, towards the turn
        first = [np.where(v, km if sign > 0 else -kn, self.unreachable).astype(np.int64)
                 for v, km, kn in zip(seg.valid, seg.kmax, seg.kmin, strict=True)]
        self.levels: list[list[NDArray[np.int64]]] = [first]
        # per (target pair, kept finger): the range of the third finger's contact that a
        # regrasp from the target's segment can place (the exact planner's h_interval)
        self._ranges = []
        for q, (a, b) in enumerate(PAIRS):
            for keep in (a, b):
                t = 3 - a - b
                lo, hi = seg.h_interval(t, seg.kmin[q], seg.kmax[q])
                # rows of the target array are `keep`: transpose when keep is its 2nd finger
                if keep != a:
                    lo, hi = lo.T, hi.T
                self._ranges.append((q, keep, t, lo, hi))
        for _ in range(self.depth):
            self.levels.append(self._propagate(self.levels[-1]))

    def _propagate(self, prev: list[NDArray[np.int64]]) -> list[NDArray[np.int64]]:
        out = [p.copy() for p in prev]
        fill = self.unreachable
        for q, keep, t, lo, hi in self._ranges:
            src = _pair_index(keep, t)
            # source values with rows = keep's contact, columns = t's contact
            vals = prev[src] if keep < t else prev[src].T
            best = _range_max(vals, lo, hi, fill)  # rows keep, columns the pair's other
            if keep != PAIRS[q][0]:
                best = best.T
            valid = self._seg.valid[q]
            np.maximum(out[q], np.where(valid, best, fill), out=out[q])
        return out

    # ------------------------------------------------------------------ queries
    def move_shortfalls(self, h: int, f: int, g: int, p_f: int, p_g: int, k: int,
                        mask: NDArray[np.bool_], rot_delta: NDArray[np.int64]
                        ) -> NDArray[np.float32]:
        """Every move's look-ahead in one state, ``D = depth + 1`` regrasps deep (the envs'
        ``regrasp_lookahead = D`` field; see ``GraspGait-v0``'s *Observation Space*):
        ``2 P x D`` per regrasp action, then ``2 R x D`` per rotation (``GaitModel``'s
        action layout).

        Held fingers ``f < g`` at workspace positions ``p_f``, ``p_g``, free finger ``h``,
        object angle ``k``; ``mask`` the legal moves (the env's, with its opt-in
        restrictions); ``rot_delta`` the signed grid steps of the ``2 R`` rotations. Entry
        values are shortfalls over ``abs(K)`` grid steps (0: the turn is reached), ``(abs(K)
        + B + 1) / abs(K)`` for an illegal action or one that opens nothing.

        The row of :meth:`move_shortfalls_batch` for this one state (one implementation
        for the single and the batched envs).
        """
        def row(x: int) -> NDArray[np.int64]:
            return np.array([x], dtype=np.int64)

        return self.move_shortfalls_batch(row(h), row(f), row(g), row(p_f), row(p_g), row(k),
                                          mask[None, :], rot_delta)[0]

    def _stacked_levels(self) -> NDArray[np.int64]:
        """``levels[j][pair]`` padded into one ``(D, 3, L, L)`` array (``L`` the longest
        finger's index range; padding ``unreachable``), built once: the batch gathers
        every row's table in one call."""
        if getattr(self, "_stack", None) is None:
            L = int(max(self._seg.L))
            st = np.full((len(self.levels), len(PAIRS), L, L), self.unreachable,
                         dtype=np.int64)
            for j, level in enumerate(self.levels):
                for q, table in enumerate(level):
                    st[j, q, :table.shape[0], :table.shape[1]] = table
            self._stack = st
        return self._stack

    def move_shortfalls_batch(self, h: NDArray[np.int64], f: NDArray[np.int64],
                              g: NDArray[np.int64], p_f: NDArray[np.int64],
                              p_g: NDArray[np.int64], k: NDArray[np.int64],
                              mask: NDArray[np.bool_], rot_delta: NDArray[np.int64]
                              ) -> NDArray[np.float32]:
        """:meth:`move_shortfalls` of ``N`` states at once: ``(N, (2 P + 2 R) D)`` float32.

        ``h, f, g, p_f, p_g, k`` are ``(N,)`` integer arrays (free finger, held fingers
        ``f < g`` and their workspace positions, object angle), ``mask`` is ``(N, A)``.
        Row ``i`` is the look-ahead of state ``i``:

        - regrasp ``(p, l)`` (the free finger to workspace position ``p``, lift ``l``):
          the reach shortfall of the grasp it makes, ``j = 0 .. D - 1`` more regrasps
          deep, from ``levels[j]`` of the pair (kept finger, ``h``) at the kept contact
          and ``h``'s new one;
        - rotation ``a``: of the regrasps legal at the angle it leads to, the one falling
          least short at ``j = D - 1``, then ``D - 2``, ... (ties: the lower lift, then the
          lower position); 0 when the rotation itself reaches the turn;
        - an illegal move, a position outside ``h``'s workspace or a contact outside the
          search window: ``abs(K) - unreachable``, the "none" value.
        """
        model, D = self.model, self.depth + 1
        K, sign, seg, P = abs(self.turn_steps), self._sign, self._seg, int(model.P)
        none = K - self.unreachable  # the shortfall written for "no such move"
        stack = self._stacked_levels()
        N, R2 = h.size, rot_delta.size
        x0 = np.asarray(seg.x0, dtype=np.int64)
        Lf = np.asarray(seg.L, dtype=np.int64)
        ws_start = np.asarray(model.ws_start, dtype=np.int64)
        q = np.arange(P)
        # object angle now, and after each rotation: (N, R2 + 1)
        ks = k[:, None] + np.concatenate(([0], rot_delta))[None, :]
        # h's contact index at each position of its workspace: (N, R2 + 1, P)
        ih = ((ws_start[h] - x0[h])[:, None, None] + q[None, None, :] - ks[:, :, None])
        inside_h = ((ih >= 0) & (ih < Lf[h][:, None, None])
                    & (q[None, None, :] < np.asarray(model.ws_width)[h][:, None, None]))
        ih = np.clip(ih, 0, Lf[h][:, None, None] - 1)
        best = np.empty((2, D, N, R2 + 1, P), dtype=np.int64)
        L = stack.shape[2]
        flat = stack.reshape(-1)  # flat gathers: one np.take per lift and depth
        for lift, (keep, p_keep) in enumerate(((g, p_g), (f, p_f))):  # l = 0 lifts f, keeps g
            pair = (keep + h - 1)  # PAIRS order (0, 1), (0, 2), (1, 2): index a + b - 1
            ik = ws_start[keep] + p_keep - k - x0[keep]
            ok = (ik >= 0) & (ik < Lf[keep])
            ik = np.clip(ik, 0, Lf[keep] - 1)
            # the table's rows are the pair's lower finger: (keep, h) or (h, keep)
            lower = keep < h
            at = (pair * L * L + np.where(lower, ik * L, ik))[:, None, None] \
                + np.where(lower[:, None, None], ih, ih * L)
            unusable = ~(inside_h & ok[:, None, None])
            for j in range(D):
                v = flat.take(at + j * 3 * L * L)
                np.subtract(K, v, out=v)
                np.maximum(v, 0, out=v)
                v[unusable] = none
                best[lift, j] = v
        A = mask.shape[1]
        # regrasps: [N, q, lift, j]; illegal ones (the mask) read none
        regrasp = best[:, :, :, 0, :].transpose(2, 3, 0, 1).copy()
        legal = mask[:, A - 2 * P:].reshape(N, P, 2)
        regrasp[~legal] = none
        # after each rotation, the regrasp that is best first at depth D - 1, then D - 2, ...
        cand = best[:, :, :, 1:, :].transpose(2, 3, 0, 4, 1).reshape(N, R2, 2 * P, D)
        # lexicographic, the deepest first (np.lexsort's last key); ties: the first
        # candidate (the lower lift, then the lower position)
        order = np.lexsort([np.broadcast_to(np.arange(2 * P), cand.shape[:3])]
                           + [cand[..., j] for j in range(D)], axis=-1)
        rot = np.take_along_axis(cand, order[:, :, :1, None], axis=2)[:, :, 0]
        rot[sign * ks[:, 1:] >= K] = 0  # the rotation itself reaches the turn
        rot[~mask[:, :R2]] = none
        out = np.empty((N, (2 * P + R2) * D), dtype=np.float32)
        out[:, :2 * P * D] = regrasp.reshape(N, -1)
        out[:, 2 * P * D:] = rot.reshape(N, -1)
        out /= K
        return out

    def _coord(self, f: int, state: GaitState) -> int:
        """Array index of finger ``f``'s unwrapped contact at ``state``: ``x = s + p - k``."""
        model = self.model
        p = model.position(f, state.contacts[f], state.k)
        return int(model.ws_start[f] + p - state.k - self._seg.x0[f])

    def reach(self, state: GaitState, j: int) -> int:
        """Farthest object angle (grid steps, signed as the turn) that the state's segment
        reaches within ``j`` regrasps; ``unreachable * sign`` outside the window."""
        f, g = state.held()
        i, jj = self._coord(f, state), self._coord(g, state)
        table = self.levels[j][_pair_index(f, g)]
        if not (0 <= i < table.shape[0] and 0 <= jj < table.shape[1]):
            return self.unreachable * self._sign
        return int(table[i, jj]) * self._sign

    def shortfall(self, state: GaitState, j: int) -> int:
        """Grid steps short of the turn after the best chain of at most ``j`` regrasps
        from ``state`` (0: it reaches the turn)."""
        f, g = state.held()
        i, jj = self._coord(f, state), self._coord(g, state)
        table = self.levels[j][_pair_index(f, g)]
        if not (0 <= i < table.shape[0] and 0 <= jj < table.shape[1]):
            return abs(self.turn_steps) - self.unreachable
        return max(abs(self.turn_steps) - int(table[i, jj]), 0)
