"""The modified search (thesis 6.4): pruning the search tree using prototype gaits.

When a grasp map holds no band or box of sufficient size but still follows the general
trend of its type (the thesis's pentagon: a staircase fits although no band does), a
search restricted to the gait structure known to work for that type
(:func:`map_structure`: the staircase of 6.3.1 or the + of 6.3.2) finds a gait with the
step sizes fitted to the map. It is a best-first search with the thesis's metric
(5.5) whose node is a grasp with the rotation the structure makes after it ("object
rotations are implicit in the structure of the gait", 6.5). See :func:`modified_search`
for the structures, the branch order and the counting.
"""

from __future__ import annotations

import heapq
import time
import weakref
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.prototypes import (
    WorkspaceGrid,
    back_and_forth_conditions,
    band_prototypes,
)
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.search import TIE_BREAKS
from graspgait_env.planners.starts import check_start, no_start_verdict, spread_starts
from graspgait_env.planners.trace import Trace, gait_failure, gait_pattern, gait_result

__all__ = ["modified_search", "map_structure", "w_wide_grasps", "DEFAULT_MAX_NODES"]

DEFAULT_MAX_NODES = 20_000  # (nodes opened) cap of the modified search

_FREE, _ROTATED, _ROTATED_B, _BACK1, _BACK2 = "free", "rotated", "rotated-b", "back1", "back2"


def _held(contacts: tuple[int, ...]) -> tuple[int, int]:
    """The two holding fingers of a three-finger state, ascending (``GaitState.held``)."""
    if contacts[0] < 0:
        return 1, 2
    return (0, 2) if contacts[1] < 0 else (0, 1)


class _Modified:
    """Best-first search over the moves of one gait structure (thesis 6.4)."""

    def __init__(self, model: GaitModel, g: WorkspaceGrid, K: int, plus: bool,
                 tie_break: str = "newest", one_step_size: bool = False,
                 w_wide: NDArray[np.bool_] | None = None) -> None:
        self.m, self.g, self.K, self.plus = model, g, K, plus
        self.one_step_size = one_step_size  # one step size per kind of move (see search)
        self.tick = 1 if tie_break == "oldest" else -1  # heap order of equal-M nodes
        self.sign = 1 if K >= 0 else -1
        self.tiled = np.tile(np.asarray(model.stable, dtype=bool), (1, 2))
        # the grasps a regrasp may move to: every stable one, or the w-wide ones
        # (:func:`w_wide_grasps`) in the first pass of the plus structure; the look-ahead
        # of :meth:`_any_regrasp` reads the whole map (measured: reading the w-wide
        # grasps there too, ellipse 1.29 nodes per move but hexagon gaits 13.6 regrasps)
        self.movable = self.tiled if w_wide is None else np.tile(
            np.asarray(w_wide, dtype=bool), (1, 2))
        # prefix sums of every map row (the look-ahead) and the fingers' neighbours
        self.csum = np.concatenate((np.zeros((model.n, 1), dtype=np.int64),
                                    np.cumsum(self.tiled, axis=1)), axis=1)
        self.pred = [g.pred(f) for f in range(3)]
        self.succ = [g.succ(f) for f in range(3)]
        self.opened = self.created = 0
        self.best_k = 0
        self.exhausted = False

    def regrasps(self, s: GaitState, forward: bool) -> Iterator[GaitState]:
        """Forward (or backward) regrasps of ``s``, smallest forward / largest backward
        step first (both: the free finger's positions from the trailing end)."""
        m, sign = self.m, self.sign
        f, g2 = _held(s.contacts)
        h = 3 - f - g2
        ahead = self.pred[h] if sign > 0 else self.succ[h]  # the finger a forward step replaces
        lift = ahead if forward else (g2 if ahead == f else f)
        keep = g2 if lift == f else f
        W = int(m.ws_width[h])
        i0 = (int(m.ws_start[h]) - s.k) % m.n
        ok = self.movable[s.contacts[keep], i0 : i0 + W]
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
        m, sign = self.m, self.sign
        f, g2 = _held(s.contacts)
        h = 3 - f - g2
        ahead = self.pred[h] if sign > 0 else self.succ[h]
        W = int(m.ws_width[h])
        i0 = (int(m.ws_start[h]) - s.k - deltas) % m.n
        out = []
        for keep in (g2 if ahead == f else f, ahead):  # forward keeps the other finger
            cs = self.csum[s.contacts[keep]]
            out.append((cs[i0 + W] - cs[i0]) > 0)
        return out[0], out[1]

    def rotations(self, s: GaitState) -> Iterator[tuple[GaitState, str, str]]:
        """The structure's rotations of a grasp that may turn (phase free): to the goal
        when in reach, else to the box edge or as far as a forward regrasp then exists
        (6.3.1 rule 1) and, plus only, to the last angle at which a backward regrasp
        exists (the upper/right limit of 6.3.2 rules 2-4)."""
        sign = self.sign
        ccw, cw = self.m.state_rotation_room(s)  # thesis 5.2: the rotation limit
        lim = ccw if sign > 0 else cw
        togo = abs(self.K - s.k)
        if 0 < togo <= lim:  # the goal is in reach: rotate there (6.3.1 rule 1)
            yield GaitState(self.K, s.contacts), _ROTATED, "rotate to goal"
        if min(lim, togo - 1) <= 0:
            return
        deltas = np.arange(min(lim, togo - 1), 0, -1)
        fwd, bwd = self._any_regrasp(s, sign * deltas)
        if fwd.any():
            yield GaitState(s.k + sign * int(deltas[fwd][0]), s.contacts), _ROTATED, "rotate"
        if self.plus and bwd.any():
            yield GaitState(s.k + sign * int(deltas[bwd][0]), s.contacts), _ROTATED_B, "rotate"

    def children(self, s: GaitState, phase: str,
                 is_start: bool = False) -> Iterator[tuple[GaitState, str, str]]:
        sign = self.sign
        back_first = phase == _ROTATED_B
        if phase == _FREE:
            yield from self.rotations(s)
        # thesis 6.3.1 rules 2-3 (forward), 6.3.2 rules 6-11 (backward, plus only: at most
        # two in a row, backward first after the upper/right limit)
        if not self.plus or phase == _BACK2:
            kinds = [True]
        else:
            kinds = [False, True] if back_first else [True, False]
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

    def steps(self, s: GaitState, phase: str, is_start: bool
              ) -> Iterator[tuple[list[tuple[GaitState, str, str]], int, int]]:
        """The children of a node in the search: one regrasp of the structure followed by
        the rotation the structure then makes (thesis 6.4: "object rotations are
        implicit in the structure of the gait"), or one rotation from the start. Yields
        ``(moves, regrasps, rotations)`` with ``moves`` the ``(state, phase, label)``
        list; when the structure allows no rotation after the regrasp (a box corner, or
        after a backward regrasp) the regrasp alone."""
        for t, ph, label in self.children(s, phase, is_start=is_start):
            if "regrasp" not in label:
                yield [(t, ph, label)], 0, 1
                continue
            turned = False
            if ph == _FREE:
                for u, ph2, label2 in self.rotations(t):
                    turned = True
                    yield [(t, ph, label), (u, ph2, label2)], 1, 1
            if not turned:
                # the look-ahead of :meth:`rotations` extended to regrasps: a regrasp after
                # which the structure allows no rotation must allow a further regrasp
                if not self._has_regrasp(t, ph):
                    continue
                yield [(t, ph, label)], 1, 0

    def _has_regrasp(self, t: GaitState, ph: str) -> bool:
        """Does the structure allow a regrasp from ``t`` (phase ``ph``)? A forward one
        always; a second backward one after a first (6.3.2 rules 7, 10)."""
        for _ in self.regrasps(t, forward=True):
            return True
        if self.plus and ph == _BACK1:
            for _ in self.regrasps(t, forward=False):
                return True
        return False

    def search(self, start: GaitState, max_nodes: int) -> tuple[list[GaitState], list[str]] | None:
        """Best-first search with the thesis metric (thesis 5.5) over this structure's
        moves; the path of states (and move labels) or ``None``.

        A node is a grasp with the rotation the structure makes after it (:meth:`steps`).
        The open node with the highest ``M = theta - eta - r`` (degrees along the turn,
        regrasps, rotations on its path:
        :func:`~graspgait_env.planners.search.best_first_metric` with the thesis's weights
        1, computed inline) is opened next; ties go to the node created last
        (``tie_break="newest"``) or first (``"oldest"``), and among the children of one
        node, generated in the rules' order (:meth:`children`), the rules' first choice is
        opened first (pushed last for ``"newest"``). A state (with its phase in the
        structure) is created once: the first path to it is kept (thesis 5.5). With
        ``one_step_size`` only the first new child of each kind of move is created (kind:
        the regrasp's direction and the phase it leads to, so forward-then-rotate-to-the-
        forward-limit, forward-then-rotate-to-the-backward-limit, forward alone, backward,
        rotation alone). The goal test is made at creation.
        """
        key0 = (start, _FREE)
        parent: dict[tuple[GaitState, str], tuple[tuple[GaitState, str], list] | None] = {
            key0: None}
        heap: list[tuple[float, int, GaitState, str, int, int]] = [(-0.0, 0, start, _FREE, 0, 0)]
        counter = 0
        step_along = self.sign * self.m.step_deg
        goal = None
        while heap and goal is None:
            if self.opened >= max_nodes:
                return None
            _, _, s, phase, eta, r = heapq.heappop(heap)
            self.opened += 1
            kids: list[tuple[float, GaitState, str, int, int]] = []
            kinds: set[tuple[str, str, bool]] = set()
            for moves, dreg, drot in self.steps(s, phase, is_start=(s, phase) == key0):
                self.created += 1
                t, ph, _ = moves[-1]
                key = (t, ph)
                if key in parent:  # thesis 5.5: only the first path to a node
                    continue
                if self.one_step_size:
                    # the rules' step size only: the first new child of each kind of move;
                    # a first backward regrasp after which a second one exists (rules
                    # 6-7-8, 9-10-11) is another kind than one after which none does
                    # (rules 6-8, 9-11)
                    kind: tuple[str, str, bool] = (moves[0][2], ph, ph == _BACK1 and any(
                        True for _ in self.regrasps(t, forward=False)))
                    if kind in kinds:
                        continue
                    kinds.add(kind)
                parent[key] = ((s, phase), moves)
                self.best_k = max(self.best_k, self.sign * t.k)
                if self.sign * (t.k - self.K) >= 0:
                    goal = key
                    break
                e, rr = eta + dreg, r + drot
                # best_first_metric(theta, e, rr) with the thesis's weights 1, in plain
                # floats (the hot loop)
                kids.append((step_along * t.k - e - rr, t, ph, e, rr))
            # among siblings of equal M the rules' first choice is opened first: with ties
            # to the newest node it is pushed last
            for m, t, ph, e, rr in (reversed(kids) if self.tick < 0 else kids):
                counter += self.tick
                heapq.heappush(heap, (-m, counter, t, ph, e, rr))
        if goal is None:
            self.exhausted = True
            return None
        states, labels = [], []
        key = goal
        while parent[key] is not None:
            prev, moves = parent[key]
            for t, _, label in reversed(moves):
                states.append(t)
                labels.append(label)
            key = prev
        states.append(start)
        return states[::-1], labels[::-1]


def _run_lengths(stable: NDArray[np.bool_]) -> NDArray[np.int64]:
    """For each cell, the length of the run of stable cells through it along its row
    (axis 1), the map wrapping round (at most ``n``); 0 for an unstable cell."""
    S = np.asarray(stable, dtype=bool)
    n = S.shape[1]
    T = np.tile(S, (1, 3))  # the middle copy sees every wrapped run whole
    ahead = _run_so_far(T)
    behind = _run_so_far(T[:, ::-1])[:, ::-1]
    run = (ahead + behind - 1)[:, n : 2 * n]
    return np.where(S, np.minimum(run, n), 0)


def _run_so_far(T: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Stable cells in a row up to and including each cell since the last unstable one."""
    c = np.cumsum(T, axis=1)
    return c - np.maximum.accumulate(np.where(T, 0, c), axis=1)


def w_wide_grasps(stable: NDArray[np.bool_], w_steps: int) -> NDArray[np.bool_]:
    """The stable grasps whose stable region is at least ``w`` wide and tall there.

    Thesis 6.3.2 (fig. 6.11 (a)): "a forward move ... or a backward move ... can only be
    made if the dimensions of the box are at least w × w". With no box (6.4) this is
    read on the map itself: cell ``(a, b)`` qualifies when the run of stable cells
    through it is at least ``w_steps`` long along both axes (``a`` varying with ``b``
    held, and ``b`` varying with ``a`` held; the map wraps round).

    Parameters
    ----------
    stable
        The ``(n, n)`` grasp map.
    w_steps
        The gap ``w`` between workspaces, in grid steps.

    Returns
    -------
    numpy.ndarray
        ``(n, n)`` boolean, a subset of ``stable``.
    """
    S = np.asarray(stable, dtype=bool)
    along_b = _run_lengths(S)
    along_a = _run_lengths(S.T).T
    return S & (along_a >= w_steps) & (along_b >= w_steps)


# w_wide_grasps per model, keyed on its map array and w
_W_WIDE: weakref.WeakKeyDictionary[GaitModel, dict[tuple[int, int], NDArray[np.bool_]]] = (
    weakref.WeakKeyDictionary())


def _model_w_wide(model: GaitModel, w_steps: int) -> NDArray[np.bool_]:
    """:func:`w_wide_grasps` of ``model``'s map, computed once per model, map and ``w``."""
    per = _W_WIDE.setdefault(model, {})
    key = (id(model.stable), w_steps)
    if key not in per:
        per.clear()
        per[key] = w_wide_grasps(model.stable, w_steps)
    return per[key]


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
                    max_nodes: int = DEFAULT_MAX_NODES,
                    tie_break: str = "newest") -> PlannerResult:
    """The modified search of thesis 6.4: best-first, restricted to one gait structure.

    Structures
    ----------
    ``"staircase"`` (6.3.1): rotations in the turn's direction only, each followed by a
    *forward* regrasp (the free finger replaces the finger whose workspace precedes it:
    a positive horizontal or vertical step into the next box); regrasps may follow each
    other without a rotation (the box corner of rules 2–3).
    ``"plus"`` (6.3.2): the same, plus *backward* regrasps (the free finger replaces the
    finger whose workspace follows it: a negative step), at most two in a row and always
    followed by a forward regrasp before the next rotation (rules 6–8, 9–11).

    Search. Best-first with the thesis metric ``M = theta - eta - r`` (5.5, weights 1):
    a node is a grasp with the rotation the structure makes after it, so a child is one
    regrasp of the structure followed by that rotation (a regrasp alone where no
    rotation may follow: a box corner, or after a backward regrasp; from the start also a
    rotation alone). Rotations: as far as the box edge, or as far as a forward regrasp
    then exists (6.3.1 rule 1); for the plus structure also the last angle at which a
    backward regrasp exists (the upper/right limit of 6.3.2 rules 2-4); a one-step
    look-ahead skips rotations after which no regrasp of the structure exists, and
    regrasps after which the structure allows neither a rotation nor a further regrasp
    (a dead end one move deep: measured, it cuts the pentagon's nodes opened from 34.3 to
    12.5 per start over the bench's ten starts at mu 0.7). Only from
    the start may the object turn the other way first (6.3.2: "would first have to rotate
    backwards"). Regrasps: forward ones with the smallest step first (to the edge of the
    next box), backward ones with the largest step first (after an upper/right-limit
    rotation the backward ones come first), and among the children of one node the
    rules' first choice is opened first. Among other nodes of equal ``M`` the one created
    last is opened first (``tie_break``): the thesis does not say which, and its Table 1
    resembles the general best-first search with ties to the newest node (measured:
    nodes opened 1,080 on the circle and 9,855 on the ellipse at mu 0.7 against the
    thesis's 958 and 14,486; ties to the oldest open 31 and 2,482), so its modified
    search is taken to share that order. A state (with its phase in the structure) is
    created once (the first path to it, 5.5). Rotations are bounded by
    :meth:`GaitModel.rotation_room`, the one definition of the rotation limit.

    Step sizes. The thesis's modified search keeps the structure and fits "the step
    sizes ... to the specific grasp map" (6.4); the rules take one step size per move
    (6.3.1 rules 2-3: to the edge of the next box; 6.3.2 rules 5-11: ``w`` forward, the
    largest backward). So each structure is searched first with one step size per kind
    of move — the first new one in the rules' order — and, only when that tree is
    exhausted, again with every step size (the nodes of both passes add up; order:
    rules' sizes for each structure, then every size for each). In the first pass a
    first backward regrasp after which a second one exists (rules 6-7-8, 9-10-11) and
    one after which none does (rules 6-8, 9-11) are different kinds, and a regrasp
    moves only to a grasp whose stable region is at least ``w`` wide and tall there
    (:func:`w_wide_grasps`; 6.3.2, fig. 6.11 (a): a move "can only be made if the
    dimensions of the box are at least w × w"), a condition of the box prototype, so
    of the plus structure only (the staircase's band has its own, 6.3.1); the second
    pass drops both.

    Measured (``graspgait bench --mus 0.7 --planners modified``: nodes opened per path
    move, mean regrasps, over the bench's ten starts; all succeed):

    ==================================  =========  =========  =========  =========
    version                             circle     ellipse    pentagon   hexagon
    ==================================  =========  =========  =========  =========
    siblings newest-created first       1.00/148.6 54.2/29.5  0.53/14.8  72.4/16.0
    rules' first choice first           0.51/7.8   9.27/13.6  1.71/12.1  17.7/12.4
    + dead-end look-ahead               0.51/7.8   6.77/13.6  0.62/12.1  9.78/13.0
    + rules' step sizes first           0.51/7.8   2.91/13.9  0.62/12.1  1.39/13.4
    + two kinds of 1st backward, alone  0.51/7.8   3.06/13.9  0.62/12.1  1.39/13.4
    + moves to w-wide grasps alone      0.51/7.8   2.19/13.0  0.62/12.1  1.16/13.4
    + both (this)                       0.51/7.8   1.47/12.9  0.62/12.1  1.16/13.4
    ==================================  =========  =========  =========  =========

    At mu 0.8 the last row reads 0.53/7.8, 0.65/9.0, 0.56/9.0, 0.84/11.0 (the row
    before both: 0.53/7.8, 0.90/9.2, 0.56/9.0, 1.27/12.3).

    Where the nodes went on the ellipse at mu 0.7 (nodes opened per start, the
    bench's ten starts in order, before -> after the last row: 48->19, 25->25, 35->25,
    70->41, 87->25, 69->32, 77->52, 151->35, 52->35, 49->29). Two causes. *Traps*: from
    grasps in the thin strips that run off the corners of the map's large stable box
    (less than ``w`` wide, e.g. (20°, 206°), (132°, 206°)) the + structure chains small
    + cycles (backward regrasps, a forward one, a rotation of 2-8 degrees) whose ``M``
    still rises, and every node of such a trap above the path's next dip is opened
    before the search backs out: from the start (70°, 298°) about 55 nodes at theta
    208-258 degrees, the path's dip being at theta 176 degrees; the w-wide condition
    keeps the first pass out of the strips. *The every-step-size pass*: from (128°,
    314°) the first pass's one backward step per node fails (29 nodes) and the second
    pass opens each of ~30 equal-``M`` backward regrasps of a node before the children
    of any (121 nodes); with the two kinds of first backward regrasp the first pass
    finds the gait (35 nodes).

    The first row opened the rules' *last* choice first among equal-``M`` siblings
    (the largest forward step, after which the least rotation remains), which on the
    circle chains a regrasp and a 2-degree rotation at no change of ``M``. Tried and not
    kept (measured on the same starts): deferring the charge of regrasps that no
    rotation follows (ellipse 19.5), a closed set keyed on the grasp without its phase
    (6.77, no change), a deeper dead-end look-ahead (no change), rotating only to the
    forward limit when a forward regrasp exists at the rotation limit (6.3.2 rule 1;
    ellipse 4.95), only forward regrasps after a forward-limit rotation and only
    backward ones after an upper/right-limit rotation (6.3.2 rules 5, 6, 9: 2 of 10
    starts fail on the ellipse and on the hexagon), and one step size only, without the
    second pass (ellipse 2.50, but one start of ten fails). On top of this version:
    a first pass with the rotation of 6.3.2 rules 1-4 read on the map (to the
    upper/right limit when the grasp is less than ``w`` from a forward edge of its
    stable runs, else to the rotation limit; ellipse 1.02 and hexagon 0.75 nodes per
    move at mu 0.7, but at mu 0.8 the ellipse's gaits grow from 9.0 to 10.9 regrasps
    and the pentagon's from 9.0 to 9.7), and the w-wide condition read as "covered by
    a stable w × w square" (ellipse 1.47, and applied to the staircase as well it
    drops the pentagon's gaits to 9.1 regrasps at mu 0.7, which the rule-based method
    reports against Table 6.1's 14.5; the runs read on the staircase as well: pentagon
    0.65/12.0).

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
    tie_break
        ``"newest"`` (default) or ``"oldest"``: which of the open nodes with equal ``M``
        is opened first.

    Returns
    -------
    PlannerResult
        ``planner="modified-search"``. ``nodes_opened`` counts the nodes opened —
        grasps, each with its implicit rotation, as the thesis counts them (6.5: "the
        path length always equals the number of regrasps") — so a search that never
        meets a dead end opens one node per regrasp of its path (plus one for a first
        rotation from the start), about half its ``path_length`` in moves;
        ``nodes_created`` counts the children generated. ``extra["structure"]``
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
    if tie_break not in TIE_BREAKS:
        raise GraspGaitInputError(f"tie_break={tie_break!r}: unknown; use one of "
                                  f"{', '.join(TIE_BREAKS)}")
    extra: dict[str, Any] = {"method": "modified-search", "tie_break": tie_break}
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
    w_wide: NDArray[np.bool_] | None = None  # computed on the first plus pass
    for s0 in starts:
        # the rules' step sizes first (each structure), then every step size
        passes = [(i, st, one) for one in (True, False) for i, st in enumerate(order)]
        for i, st, one in passes:
            budget = max_nodes - opened
            if len(order) == 2 and i == 0:
                budget = min(budget, max_nodes // 2)
            if one and st == "plus" and w_wide is None:
                w_wide = _model_w_wide(model, g.w_steps)
            srch = _Modified(model, g, K, plus=(st == "plus"), tie_break=tie_break,
                             one_step_size=one,
                             w_wide=w_wide if one and st == "plus" else None)
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
