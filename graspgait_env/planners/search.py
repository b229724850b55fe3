"""The thesis's general searches for a gait (chapter 5): breadth-first, depth-first, best-first.

All three search the discretized gait graph of :class:`~graspgait_env.gait.GaitModel`
(thesis 5.2: a node is ``X = [theta, x, y]``, a branch is one rotation or one regrasp)
and expand a node with the one legal-move function, :meth:`GaitModel.action_mask`,
called once per expansion (breadth-first search opens a whole level at once with its
batched form, :meth:`GaitModel.action_masks_at`, the same rule row for row); the legal
actions are then decoded into next states all at once with NumPy, exactly as
:meth:`GaitModel.apply` decodes one (a test checks that the two agree move for move).

Common rules
------------
- **Goal**: the object turned ``turn_deg`` (``k >= K`` for a counter-clockwise turn,
  ``k <= K`` for a clockwise one, ``K = model.turn_steps(turn_deg)``). The goal test is
  made when a node is *created*; the goal node itself is not opened. Only a rotation
  can reach the goal, and the first goal child in action order is taken, so a plan
  ends exactly at ``K``.
- **First path only** (thesis 5.5): a state is created once; any later path to it is
  cut. This is the visited set of breadth- and depth-first search and the closed + open
  set of best-first search.
- **Window**: states whose object angle lies outside ``theta_window_deg`` are never
  created; the default is the exact planner's window ``[min(0, T) - 360°, max(0, T) +
  360°]`` for a turn ``T``. The state space is then finite, so a search that empties
  its queue proves that no gait exists in the window (``exhausted=True``), and its
  verdict is comparable with :func:`graspgait_env.planners.exact.optimal_gait`'s.
- **Counting**: ``nodes_opened`` = nodes expanded (``action_mask`` calls: thesis 5.5
  "explored as a possible path"); ``nodes_created`` = distinct states generated,
  the start and the goal included. ``max_nodes`` caps ``nodes_opened``; at the cap the
  search stops with no plan, ``exhausted=False`` and a reason starting "node limit".
- **Plan**: one step per move (rotations are not merged), so ``path_length`` = number
  of moves = ``len(plan.steps) - 1``.

Rotation goes either way (docs/conventions.md): the thesis discretizes CCW rotations only
(5.2, Δθ = 2°); here every legal rotation in both directions is a branch.
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState, workspace_grid
from graspgait_env.plan import plan_from_states
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.starts import require_start

__all__ = [
    "breadth_first",
    "depth_first",
    "depth_first_thesis",
    "best_first",
    "best_first_newest",
    "TIE_BREAKS",
    "best_first_metric",
    "DEFAULT_MAX_NODES",
]

DEFAULT_MAX_NODES = 200_000  # (nodes opened) default cap for every search here
_CHUNK = 4096  # breadth-first: nodes opened per batched expansion
TIE_BREAKS = ("oldest", "newest")  # best-first: which of equal-M open nodes goes first

_PAIRS = ((0, 1), (0, 2), (1, 2))
_PAIR_INDEX = {p: i for i, p in enumerate(_PAIRS)}
_PAIR_F = np.array([f for f, _ in _PAIRS], dtype=np.int64)  # pair index -> lower finger
_PAIR_G = np.array([g for _, g in _PAIRS], dtype=np.int64)  # pair index -> higher finger


def best_first_metric(theta_deg: ArrayLike, regrasps: ArrayLike, rotations: ArrayLike,
                      alpha: float = 1.0, beta: float = 1.0, gamma: float = 1.0
                      ) -> NDArray[np.float64] | float:
    """The thesis's path value ``M = alpha * theta - beta * eta - gamma * r`` (thesis 5.5).

    Parameters
    ----------
    theta_deg
        Object angle of the partial path's last state (degrees, measured along the
        requested turn: positive is progress).
    regrasps
        ``eta``, the number of regrasps in the partial path.
    rotations
        ``r``, the number of rotations in the partial path.
    alpha, beta, gamma
        Weights; the thesis found all equal to 1 satisfactory.

    Returns
    -------
    float or ndarray
        ``M`` (elementwise for arrays). The node with the highest ``M`` is opened next.

    Examples
    --------
    >>> best_first_metric(40.0, 1, 1)
    38.0
    >>> best_first_metric(0.0, 0, 0)  # the start
    0.0
    """
    m = (alpha * np.asarray(theta_deg, dtype=float) - beta * np.asarray(regrasps, dtype=float)
         - gamma * np.asarray(rotations, dtype=float))
    return float(m) if m.ndim == 0 else m


class _Graph:
    """The windowed gait graph: integer state codes, parent links, vectorized expansion.

    A legal state ``(k, pair (f, g), p_f, p_g)`` (workspace positions, ``f < g``) has code
    ``((k - k_lo) * 3 + pair) * P^2 + p_f * P + p_g``; ``parent[code]`` is -1 for a state
    not created yet and the parent's code otherwise (the start is its own parent).
    """

    def __init__(self, model: GaitModel, start: GaitState, turn_deg: float,
                 theta_window_deg: tuple[float, float] | None) -> None:
        self.model = model
        self.K = model.turn_steps(turn_deg)
        self.sign = 1 if self.K >= 0 else -1
        if theta_window_deg is None:
            self.k_lo, self.k_hi = min(0, self.K) - model.n, max(0, self.K) + model.n
        else:
            bad = GraspGaitInputError(
                f"theta_window_deg={list(theta_window_deg)}: must contain 0 and the turn "
                f"{self.K * model.step_deg:g} deg; widen it")
            try:  # the grid angles inside the window, rounded as the workspaces are
                (k0,), (width,) = workspace_grid([theta_window_deg], model.n)
            except GraspGaitInputError:  # no grid angle inside
                raise bad from None
            self.k_lo, self.k_hi = int(k0), int(k0 + width - 1)
            if not self.k_lo <= min(0, self.K) <= max(0, self.K) <= self.k_hi:
                raise bad
        self.n = model.n
        self.R = model.R
        self.P = model.P
        self.PP = self.P * self.P
        self.ws_start = [int(x) for x in model.ws_start]
        size = (self.k_hi - self.k_lo + 1) * 3 * self.PP
        dtype = np.int32 if size < 2**31 - 1 else np.int64
        self.parent = np.full(size, -1, dtype=dtype)
        self.start_code = self.encode(start)
        self.parent[self.start_code] = self.start_code
        self._action_tables()
        self.created = 1
        self.best = 0  # largest sign * k created
        self.goal = -1 if self.sign * start.k < self.sign * self.K else self.start_code

    # ------------------------------------------------------------ codes
    def encode(self, s: GaitState) -> int:
        f, g = s.held()
        pf = self.model.position(f, s.contacts[f], s.k)
        pg = self.model.position(g, s.contacts[g], s.k)
        return ((s.k - self.k_lo) * 3 + _PAIR_INDEX[(f, g)]) * self.PP + pf * self.P + pg

    def decode(self, code: int) -> GaitState:
        kk, rem = divmod(code, 3 * self.PP)
        pair, rem = divmod(rem, self.PP)
        pf, pg = divmod(rem, self.P)
        k = kk + self.k_lo
        f, g = _PAIRS[pair]
        cs = [-1, -1, -1]
        cs[f] = (self.ws_start[f] + pf - k) % self.n
        cs[g] = (self.ws_start[g] + pg - k) % self.n
        return GaitState(k, tuple(cs))

    def k_of(self, code: int) -> int:
        return code // (3 * self.PP) + self.k_lo

    # ------------------------------------------------------------ expansion
    def _action_tables(self) -> None:
        """Per finger pair and action, the child's code as ``base + off + pf*cf + pg*cg``.

        This is :meth:`GaitModel.decode` / :meth:`GaitModel.apply` for every action at
        once, in code space: rotation ``a < R`` turns ``+(a + 1)`` steps, ``R <= a < 2R``
        turns ``-(a - R + 1)`` (both positions move with ``k``); regrasp
        ``2R + 2p + lift`` puts the free finger at position ``p`` and lifts the
        lower-numbered held finger (``lift = 0``) or the higher (``lift = 1``).
        """
        R, P, PP, A = self.R, self.P, self.PP, self.model.n_actions
        a = np.arange(A)
        is_reg = a >= 2 * R
        dk = np.where(a < R, a + 1, R - 1 - a)
        dk[is_reg] = 0
        b = np.where(is_reg, a - 2 * R, 0)
        p, lift = b >> 1, b & 1
        self.act_dk = dk
        self.act_is_reg = is_reg
        off = np.zeros((3, A), dtype=np.int64)
        cf = np.zeros((3, A), dtype=np.int64)
        cg = np.zeros((3, A), dtype=np.int64)
        for pi, (f, g) in enumerate(_PAIRS):
            h = 3 - f - g
            rot = ~is_reg
            off[pi, rot] = pi * PP + dk[rot] * (3 * PP + P + 1)
            cf[pi, rot], cg[pi, rot] = P, 1
            for lv, keep, coef in ((0, g, cg), (1, f, cf)):
                sel = is_reg & (lift == lv)
                x, y = min(keep, h), max(keep, h)
                off[pi, sel] = _PAIR_INDEX[(x, y)] * PP + (p[sel] * P if h < keep else p[sel])
                coef[pi, sel] = 1 if h < keep else P
        self.act_off, self.act_cf, self.act_cg = off, cf, cg

    def children(self, code: int
                 ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """Every legal child of ``code`` inside the window, created or not: codes, actions
        and object angles ``k``, in action order (one :meth:`GaitModel.action_mask` call,
        decoded as :meth:`GaitModel.apply` does, :meth:`_action_tables`)."""
        s = self.decode(code)
        acts = np.flatnonzero(self.model.action_mask(s))
        kk, rem = divmod(code, 3 * self.PP)
        pair, rem = divmod(rem, self.PP)
        pf, pg = divmod(rem, self.P)
        k = kk + self.k_lo
        kc = k + self.act_dk[acts]
        if k - self.R < self.k_lo or k + self.R > self.k_hi:  # near the window's edge
            inside = (kc >= self.k_lo) & (kc <= self.k_hi)
            acts, kc = acts[inside], kc[inside]
        codes = (kk * 3 * self.PP + self.act_off[pair, acts] + pf * self.act_cf[pair, acts]
                 + pg * self.act_cg[pair, acts])
        return codes, acts, kc

    def children_many(self, codes: NDArray[np.int64]
                      ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """:meth:`children` of many nodes at once: ``(source, child codes, k)``, in the
        order the nodes are given and, within a node, in action order (one
        :meth:`GaitModel.action_masks_at` call); ``source[i]`` indexes ``codes``."""
        kk, rem = np.divmod(codes, 3 * self.PP)
        pair, rem = np.divmod(rem, self.PP)
        pf, pg = np.divmod(rem, self.P)
        k = kk + self.k_lo
        f, g = _PAIR_F[pair], _PAIR_G[pair]
        src, acts = np.nonzero(self.model.action_masks_at(k, f, g, pf, pg))  # row-major
        kc = k[src] + self.act_dk[acts]
        inside = (kc >= self.k_lo) & (kc <= self.k_hi)
        src, acts, kc = src[inside], acts[inside], kc[inside]
        pa = pair[src]
        out = (kk[src] * 3 * self.PP + self.act_off[pa, acts] + pf[src] * self.act_cf[pa, acts]
               + pg[src] * self.act_cg[pa, acts])
        return src, out, kc

    def expand_many(self, codes: NDArray[np.int64], budget: int) -> tuple[NDArray[np.int64], int]:
        """Open nodes ``codes`` in their order, as :meth:`expand` would one after another,
        stopping after the node that creates the goal or after ``budget`` nodes.

        Returns the new children in the order :meth:`expand` would create them (each
        node's new children in action order, a child created once, by the first node
        that reaches it) and the number of nodes opened. Parents, ``created``, ``best``
        and ``goal`` end as after that many :meth:`expand` calls (tested against them).
        """
        codes = codes[:budget]
        src, kids, kc = self.children_many(codes)
        new = self.parent[kids] < 0
        src, kids, kc = src[new], kids[new], kc[new]
        _, first = np.unique(kids, return_index=True)  # the first node to reach each child
        first.sort()
        src, kids, kc = src[first], kids[first], kc[first]
        opened = codes.size
        hit = np.flatnonzero(kc * self.sign >= self.sign * self.K)
        if hit.size:  # the goal is created by node src[hit[0]]: stop there
            last = int(src[hit[0]])
            opened = last + 1
            keep = src <= last
            src, kids, kc = src[keep], kids[keep], kc[keep]
            self.goal = int(kids[hit[0]])
        if kids.size:
            self.parent[kids] = codes[src]
            self.created += int(kids.size)
            self.best = max(self.best, int((kc * self.sign).max()))
        return kids, opened

    def expand(self, code: int
               ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
        """Open node ``code``: its *new* children's codes, actions and is-regrasp flags.

        The legal actions come from :meth:`GaitModel.action_mask` (one call); they are
        decoded as :meth:`GaitModel.apply` does (:meth:`_action_tables`), in action
        order; children outside the window or already created are dropped, the rest are
        marked created with ``code`` as parent. The goal test is made here (``self.goal``).
        """
        codes, acts, kc = self.children(code)
        new = self.parent[codes] < 0
        codes, acts, kc = codes[new], acts[new], kc[new]
        is_reg = self.act_is_reg[acts]
        if codes.size:
            self.parent[codes] = code
            self.created += int(codes.size)
            along = kc * self.sign
            far = int(along.max())
            if far > self.best:
                self.best = far
                if far >= self.sign * self.K:
                    self.goal = int(codes[np.flatnonzero(along >= self.sign * self.K)[0]])
        return codes, acts, is_reg

    # ------------------------------------------------------------ results
    def path(self) -> list[GaitState]:
        out = [self.goal]
        while self.parent[out[-1]] != out[-1]:
            out.append(int(self.parent[out[-1]]))
        return [self.decode(c) for c in reversed(out)]

    def window_deg(self) -> list[float]:
        return [self.k_lo * self.model.step_deg, self.k_hi * self.model.step_deg]

    def result(self, planner: str, opened: int, t0: float, max_nodes: int, start: GaitState,
               turn_deg: float, extra: dict) -> PlannerResult:
        model = self.model
        best_deg = self.sign * self.best * model.step_deg
        extra = {"theta_window_deg": self.window_deg(), **extra}
        if self.goal < 0:
            wall = time.perf_counter() - t0
            if opened >= max_nodes:
                reason = (f"node limit: {planner} search opened {opened} nodes "
                          f"(max_nodes={max_nodes}) without turning {turn_deg:g} deg from "
                          f"{model.describe_state(start)}; the largest turn reached is "
                          f"{best_deg:g} deg; raise max_nodes")
                exhausted = False
            else:
                reason = (f"no gait turns {turn_deg:g} deg from {model.describe_state(start)}: "
                          f"the reachable grasps turn the object at most {best_deg:g} deg "
                          f"(exhaustive {planner} search of the window "
                          f"[{self.window_deg()[0]:g}, {self.window_deg()[1]:g}] deg)")
                exhausted = True
            return PlannerResult(planner, None, reason=reason, nodes_opened=opened,
                                 nodes_created=self.created, max_turn_deg=best_deg,
                                 wall_time_s=wall, exhausted=exhausted, extra=extra)
        states = self.path()
        plan = plan_from_states(model, states)
        plan.stats = {"planner": planner, "nodes_opened": opened, "regrasps": plan.regrasps,
                      "rotation_deg": plan.rotation_deg}
        return PlannerResult(planner, plan, nodes_opened=opened, nodes_created=self.created,
                             path_length=len(states) - 1, regrasps=plan.regrasps,
                             rotation_deg=plan.rotation_deg, max_turn_deg=best_deg,
                             wall_time_s=time.perf_counter() - t0, extra=extra)


def _begin(model: GaitModel, start: GaitState | None, turn_deg: float, max_nodes: int,
           theta_window_deg: tuple[float, float] | None, planner: str
           ) -> tuple[float, int, GaitState | PlannerResult, _Graph | None]:
    """The common start of every search here: ``(t0, max_nodes, start, graph)``, the graph
    ``None`` (and ``start`` the no-gait verdict) when no legal start exists."""
    t0 = time.perf_counter()
    max_nodes = _check_max_nodes(max_nodes)
    s0 = require_start(model, start, planner, t0)
    if isinstance(s0, PlannerResult):
        return t0, max_nodes, s0, None
    return t0, max_nodes, s0, _Graph(model, s0, turn_deg, theta_window_deg)


def _check_max_nodes(max_nodes: int) -> int:
    if isinstance(max_nodes, bool) or not isinstance(max_nodes, (int, np.integer)) \
            or max_nodes < 0:
        raise GraspGaitInputError(f"max_nodes={max_nodes!r}: must be an integer >= 0")
    return int(max_nodes)


def breadth_first(model: GaitModel, start: GaitState | None, turn_deg: float = 360.0, *,
                  max_nodes: int = DEFAULT_MAX_NODES,
                  theta_window_deg: tuple[float, float] | None = None) -> PlannerResult:
    """Breadth-first search (thesis 5.3): the gait with the fewest moves.

    Every move costs one; nodes are opened level by level (FIFO), a state is created
    only once (visited set), and the goal is tested at creation, so the path found is
    a shortest one in moves (rotations + regrasps) within the window.

    A level is opened in batches of up to 4,096 nodes (one
    :meth:`~graspgait_env.gait.GaitModel.action_masks_at` call each), in queue order,
    with each child credited to the first node that reaches it: the plan, the counts and
    the node limit are those of a FIFO queue opened one node at a time (tested against
    it), about 5x faster on a search that runs to the 200,000-node limit (0.62 s against
    3.06 s from a start of the circle at mu 0.7).

    Parameters
    ----------
    model
        The gait model (object, friction, hand, grid).
    start
        Legal start state at ``k = 0``. ``None`` only answers when there is no legal
        start at all (the no-gait verdict of
        :func:`~graspgait_env.planners.starts.no_start_verdict`); otherwise it is refused
        (:func:`~graspgait_env.planners.registry.run_planner` picks a start).
    turn_deg
        Requested turn (degrees; negative for clockwise).
    max_nodes
        Cap on nodes opened.
    theta_window_deg
        ``(lo, hi)`` object angles (degrees) outside which no state is created; default
        the exact planner's window (module docstring).

    Returns
    -------
    PlannerResult
        ``planner="breadth-first"``; see the module docstring for the counts.

    Raises
    ------
    GraspGaitInputError
        A ``start`` that is not a legal grasp at ``k = 0`` (or ``None`` while legal ones
        exist), a bad ``max_nodes`` or a ``theta_window_deg`` that misses 0 or the turn.
    """
    t0, max_nodes, s0, G = _begin(model, start, turn_deg, max_nodes, theta_window_deg,
                                  "breadth-first")
    if G is None:  # no stable grasp at theta = 0: no gait
        return s0
    opened = 0
    frontier = np.array([G.start_code], dtype=np.int64)
    while G.goal < 0 and frontier.size and opened < max_nodes:
        # one level at a time, in chunks (bounded memory), each chunk opened in queue
        # order: the same nodes, parents and counts as a FIFO queue opened one by one
        nxt: list[NDArray[np.int64]] = []
        for lo in range(0, frontier.size, _CHUNK):
            kids, n_open = G.expand_many(frontier[lo:lo + _CHUNK], max_nodes - opened)
            opened += n_open
            nxt.append(kids)
            if G.goal >= 0 or opened >= max_nodes:
                break
        frontier = np.concatenate(nxt)
    return G.result("breadth-first", opened, t0, max_nodes, s0, turn_deg, {})


def depth_first(model: GaitModel, start: GaitState | None, turn_deg: float = 360.0, *,
                max_nodes: int = DEFAULT_MAX_NODES,
                theta_window_deg: tuple[float, float] | None = None) -> PlannerResult:
    """Depth-first search with rotations first (thesis 5.4).

    "Since object rotation is the goal of the search, the nodes which involved rotation
    were put at the head of the queue, in front of the nodes involving regrasps." The
    children of an opened node go on the stack so that they come off in this order:

    1. rotations toward the goal (CCW for a positive turn), the largest first;
    2. rotations away from the goal, the smallest first (the least backing up);
    3. regrasps, in action order (free finger's workspace position ascending, then
       the lower-numbered finger lifted first).

    A state is created once (visited set, marked on creation). Since every rotation of
    a grasp is created with its siblings, a node rotated as far as it goes usually has
    only regrasps left as new children: regrasps are sought when rotation is no longer
    possible, as in the thesis. Paths are long (the thesis's pentagon: over 300 moves).

    Parameters and returns as :func:`breadth_first` (``planner="depth-first"``).
    """
    t0, max_nodes, s0, G = _begin(model, start, turn_deg, max_nodes, theta_window_deg,
                                  "depth-first")
    if G is None:  # no stable grasp at theta = 0: no gait
        return s0
    R = model.R
    forward_lt = G.sign > 0  # toward the goal: actions a < R are CCW
    opened = 0
    stack: list[int] = [G.start_code]
    while G.goal < 0 and stack and opened < max_nodes:
        code = stack.pop()
        opened += 1
        codes, acts, is_reg = G.expand(code)
        if not codes.size:
            continue
        rot = ~is_reg
        fwd = rot & ((acts < R) if forward_lt else (acts >= R))
        back = rot & ~fwd
        # push in reverse pop order: regrasps (last first), backward (largest first),
        # forward (smallest first) so the largest forward rotation is on top
        stack.extend(codes[is_reg][::-1].tolist())
        stack.extend(codes[back][::-1].tolist())
        stack.extend(codes[fwd].tolist())
    return G.result("depth-first", opened, t0, max_nodes, s0, turn_deg, {})


def depth_first_thesis(model: GaitModel, start: GaitState | None, turn_deg: float = 360.0, *,
                       max_nodes: int = DEFAULT_MAX_NODES,
                       theta_window_deg: tuple[float, float] | None = None) -> PlannerResult:
    """Depth-first search in the thesis's form (thesis 5.4): a tree search, no visited set.

    Thesis 5.4: "A depth first search explores only one possible motion from a given
    grasp until either the goal is met or a dead end is reached. If a dead end is
    reached, the search continues from a possible motion from the closest previous node.
    ... the nodes which involved rotation were put at the head of the queue, in front of
    the nodes involving regrasps." The thesis introduces "considering only the first path
    found leading to a given node" only in 5.5, as the cure for this search's redundancy,
    so here a state is created again on every path that reaches it — unlike
    :func:`depth_first`, which keeps a visited set.

    Choices where the thesis is silent (each tested):

    - Rotations go toward the goal only (thesis 5.2 enumerates rotations "just greater
      than zero to an upper limit" at the right or upper edge of the finger pair box),
      the largest first, then the regrasps in action order.
    - A state already on the current path is not entered again (without this a regrasp
      and its reverse would make the search infinitely deep); it still counts as created.
    - The node cap ``max_nodes`` bounds the search (nodes opened); the thesis's run on a
      pentagon expanded over 2,000 nodes, created over 2,000,000 and found a path of
      over 300.

    Counting: ``nodes_opened`` = nodes expanded; ``nodes_created`` = every child generated
    (repeats included), the start included. The goal test is made at creation, as in
    every search here. An emptied stack proves that no gait with rotations toward the
    goal only exists in the window (``exhausted=True``; the other searches here also
    turn back).

    Parameters and returns as :func:`breadth_first` (``planner="depth-first-thesis"``).
    """
    t0, max_nodes, s0, G = _begin(model, start, turn_deg, max_nodes, theta_window_deg,
                                  "depth-first-thesis")
    if G is None:  # no stable grasp at theta = 0: no gait
        return s0
    R, sign, K = model.R, G.sign, G.K
    opened = 0
    created = 1
    best = 0
    path: list[int] = []  # codes from the start to the node being explored
    on_path: set[int] = set()
    frames: list[list[int]] = []  # per path node: its children not yet tried, last first
    goal = G.start_code if G.goal >= 0 else -1

    # a tree search opens the same few states again and again (on the ellipse, 131,072
    # openings of 18 states): what opening a state gives is kept per state
    opening: dict[int, tuple[int, int, int, list[int]]] = {}

    def open_state(code: int) -> tuple[int, int, int, list[int]]:
        """``(children, largest turn toward the goal, goal child or -1, frame)`` of
        ``code``: the frame is its children in the order they are tried, last first."""
        codes, acts, kc = G.children(code)
        is_reg = G.act_is_reg[acts]
        fwd = ~is_reg & ((acts < R) if sign > 0 else (acts >= R))
        along = kc * sign
        far = int(along[fwd].max()) if fwd.any() else 0  # best starts at 0: no change
        hit = fwd & (along >= sign * K)
        if hit.any():  # the goal child nearest the goal angle: the plan ends at K
            return codes.size, far, int(codes[np.flatnonzero(hit)[np.argmin(along[hit])]]), []
        rot = codes[fwd][np.argsort(along[fwd], kind="stable")]  # smallest first ...
        order = np.concatenate((codes[is_reg][::-1], rot))  # ... so the largest pops first
        return codes.size, far, -1, order.tolist()

    def open_node(code: int) -> int:
        """Expand ``code``: push its frame; the goal child if one is created, else -1."""
        nonlocal opened, created, best
        opened += 1
        path.append(code)
        on_path.add(code)
        got = opening.get(code)
        if got is None:
            got = opening[code] = open_state(code)
        n_children, far, goal_child, order = got
        created += n_children
        best = max(best, far)
        if goal_child >= 0:
            return goal_child
        frames.append(order.copy())
        return -1

    if goal < 0:
        goal = open_node(G.start_code)
    while goal < 0 and frames and opened < max_nodes:
        todo = frames[-1]
        if not todo:  # dead end: back to the closest previous node
            frames.pop()
            on_path.discard(path.pop())
            continue
        child = todo.pop()
        if child in on_path:
            continue
        goal = open_node(child)
    G.created = created
    G.best = best
    if goal >= 0 and goal != G.start_code:
        # the path found (the open nodes, then the goal), as parent links for _Graph.path()
        chain = path + [goal]
        for a, b in zip(chain[:-1], chain[1:], strict=True):
            G.parent[b] = a
    G.goal = goal
    return G.result("depth-first-thesis", opened, t0, max_nodes, s0, turn_deg,
                    {"visited_set": False})


def best_first(model: GaitModel, start: GaitState | None, turn_deg: float = 360.0, *,
               max_nodes: int = DEFAULT_MAX_NODES, alpha: float = 1.0, beta: float = 1.0,
               gamma: float = 1.0, theta_window_deg: tuple[float, float] | None = None,
               tie_break: str = "oldest") -> PlannerResult:
    """Best-first search with the thesis's metric and first-path-only pruning (thesis 5.5).

    Each created node carries its partial path's value :func:`best_first_metric`
    ``M = alpha * theta - beta * eta - gamma * r`` (``theta`` in degrees along the
    requested turn, ``eta`` regrasps and ``r`` rotations on the path); the open node with
    the highest ``M`` is opened next. Many open nodes share the same ``M`` (every
    regrasp of one grasp does), and the thesis does not say which of them it opened
    first; ``tie_break`` chooses (a creation counter in the heap key: deterministic;
    children are created in action order). A state reached once is never created again
    (closed + open set by state), so a node's ``M`` is that of the first path that
    reached it.

    Parameters
    ----------
    alpha, beta, gamma
        Metric weights (thesis: all 1).
    tie_break
        ``"oldest"`` (default): among equal ``M`` the node created first is opened first
        (a queue); ``"newest"``: the node created last (a stack, as a search that pushes
        children on the head of its queue would). Table 1 of the documentation's
        science pages shows both beside the thesis's figures.
    model, start, turn_deg, max_nodes
        As :func:`breadth_first`.

    Returns
    -------
    PlannerResult
        ``planner="best-first"``, ``extra`` holding the weights and ``tie_break``.

    Raises
    ------
    GraspGaitInputError
        As :func:`breadth_first`, a non-finite weight, or a ``tie_break`` not in
        :data:`TIE_BREAKS`.
    """
    for name, w in (("alpha", alpha), ("beta", beta), ("gamma", gamma)):
        if not math.isfinite(w):
            raise GraspGaitInputError(f"{name}={w!r}: must be a finite number")
    if tie_break not in TIE_BREAKS:
        raise GraspGaitInputError(f"tie_break={tie_break!r}: unknown; use one of "
                                  f"{', '.join(TIE_BREAKS)}")
    tick = 1 if tie_break == "oldest" else -1  # the heap pops the smallest counter first
    t0, max_nodes, s0, G = _begin(model, start, turn_deg, max_nodes, theta_window_deg,
                                  "best-first")
    if G is None:  # no stable grasp at theta = 0: no gait
        return s0
    step_along = G.sign * model.step_deg  # degrees of progress per grid step
    k_scale = 3 * G.PP
    opened = 0
    counter = 0
    heap: list[tuple[float, int, int, int, int]] = [(-0.0, 0, G.start_code, 0, 0)]
    push: Callable = heapq.heappush
    pop: Callable = heapq.heappop
    while G.goal < 0 and heap and opened < max_nodes:
        _, _, code, eta, r = pop(heap)
        opened += 1
        codes, _, is_reg = G.expand(code)
        if not codes.size:
            continue
        ks = codes // k_scale + G.k_lo
        etas = eta + is_reg
        rs = r + ~is_reg
        m = best_first_metric(step_along * ks, etas, rs, alpha, beta, gamma)
        for key, c, e, rr in zip((-m).tolist(), codes.tolist(), etas.tolist(), rs.tolist(),
                                 strict=True):
            counter += tick
            push(heap, (key, counter, c, e, rr))
    return G.result("best-first", opened, t0, max_nodes, s0, turn_deg,
                    {"alpha": alpha, "beta": beta, "gamma": gamma, "tie_break": tie_break})


def best_first_newest(model: GaitModel, start: GaitState | None, turn_deg: float = 360.0,
                      **kwargs) -> PlannerResult:
    """:func:`best_first` with ``tie_break="newest"`` (the planner ``best-first-newest``).

    Keyword arguments as :func:`best_first` (``tie_break`` excepted). Returns its result
    with ``planner="best-first-newest"``.
    """
    res = best_first(model, start, turn_deg, tie_break="newest", **kwargs)
    res.planner = "best-first-newest"
    if res.plan is not None:
        res.plan.stats["planner"] = res.planner
    return res
