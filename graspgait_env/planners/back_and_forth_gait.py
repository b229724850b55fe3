"""The back-and-forth gait (thesis 6.3.2): the plus / combined gait of a box prototype,
rules 1–11, counter-clockwise and (mirrored) clockwise.

When the grasp map holds a box at least ``2w × 2w`` that passes through both workspace
box pairs (:func:`~graspgait_env.planners.prototypes.back_and_forth_conditions`), rules
1–11 turn the object with forward and backward steps inside the box, no search. Every
move is checked with :meth:`GaitModel.action_mask` before it is taken
(:class:`~graspgait_env.planners.trace.Trace`); counting as in
:mod:`~graspgait_env.planners.trace`.

Choices where the thesis is ambiguous (each tested in ``tests/planners``)
-------------------------------------------------------------------------
- The rotation limit (rule 1) is :meth:`GaitModel.rotation_room`, the one definition of
  it; so is the room for turning back (initial conditions).
- "Upper limit" (rule 2) is read as the rotation after which the workspace *below* the
  ``y`` finger's one ends exactly at the box's bottom edge (the last angle at which a
  backward vertical step into the box is possible, fig. 6.11 (c)); the "right limit"
  (rule 3) likewise for ``x``. When the backward rules must begin with a preparatory
  step on the other axis (the free finger is not behind the repositioned axis's finger),
  the other axis's limit bounds the rotation as well — after it the preparatory step
  no longer exists.
- Rules 6/9 "whichever is possible": the step on the axis being repositioned (vertical
  for rule 6, horizontal for rule 9) when the free finger's workspace lies behind that
  axis's finger; otherwise the preparatory step on the other axis first (rules 7/10
  then make the wanted step). "Largest possible" = the farthest grid contact inside the
  box that the free finger reaches.
- Rule 4 (near both far edges): after rotating the least limit, rules 6–8 in an inner
  finger pair box and rules 9–11 in an outer one — the set whose preparatory step moves
  the other axis back as well (the other order gets stuck on synthetic boxes).
- Rules 5/8/11 "a step of size w": the smallest positive step into the free finger's
  workspace (exactly ``w`` when the stepping finger is at its workspace edge). In rule 5
  the axis whose finger reached its edge goes first; if its successor finger is not
  free, the other axis's smallest positive step inside the box is taken instead.
- Rule 5 look-ahead: when no positive step will exist at the rotation limit (e.g. the
  ``x`` finger of an inner box reaches its edge while the workspace above ``y`` is not
  yet in the box), the axis reaching its edge is treated as "less than ``w`` from the
  far edge", so rules 2–4 and 6–11 reposition it in time.
- Ties between the rotation limit and the upper/right limit go to the backward rules.
- Initial conditions (last paragraph of 6.3.2): a start past its upper/right limit is
  first turned back (clockwise) by the deficit, as far as the workspaces allow; when a
  finger at the start of its workspace blocks the turn, the preparatory backward step
  on the other axis is taken, and the turn back goes on.
- Entry (6.3.2: "there is no initial condition that would preclude a successful
  gait"): from a start outside every box, a breadth-first search of at most
  :data:`ENTRY_MAX_MOVES` moves reaches the box nearest in moves, and the rules run
  from there (measured on the bench's starts at mu 0.7: the ellipse needs 1-3 moves
  from 2 of 10 starts, the hexagon 1-2 from 5 of 10; from a sixth hexagon start no box
  grasp lies within 4 moves and :func:`~graspgait_env.planners.rule_based.rule_based`
  goes on to the modified search). A grasp from which the rules get stuck is skipped
  for the next one; the result says where the last one got stuck.
  With ``start=None`` the rules start inside the box and, on synthetic box maps,
  succeed exactly when the box conditions hold (tested).
- Clockwise turns: the counter-clockwise rules on the mirror image
  (:mod:`~graspgait_env.planners.mirror`), every move checked again on the model.
- Pattern: ``plus`` when the last half-turn visits at most the five grasp-map points
  of the + (fig. 6.10 (b)), ``combined`` when the gait uses backward steps and more
  points (fig. 6.10 (c)), ``staircase`` when no backward step was needed. A minimum box
  centred on the diagonal gives the +; larger boxes, or a minimum box near the edge of
  its admissible placements, give the combined pattern.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.mirror import mirror_state, mirrored
from graspgait_env.planners.prototypes import (
    BoxPrototype,
    WorkspaceGrid,
    back_and_forth_conditions,
    box_prototypes,
)
from graspgait_env.planners.result import PlannerResult
from graspgait_env.planners.search import _PAIRS, _Graph
from graspgait_env.planners.starts import own_start_verdict
from graspgait_env.planners.trace import (
    Stuck,
    Trace,
    add_nodes,
    failed_reasons,
    gait_failure,
    gait_pattern,
    gait_result,
)

__all__ = ["back_and_forth_gait", "ENTRY_MAX_MOVES"]

ENTRY_MAX_MOVES = 4  # (moves) longest breadth-first entry into a box from a given start


def _reach(model: GaitModel, h: int, lo: int, hi: int, k: int) -> NDArray[np.int64]:
    """Unwrapped contacts in ``[lo, hi]`` that finger ``h`` reaches at object angle ``k``
    (their workspace position, :meth:`GaitModel.position`, is inside the workspace)."""
    if hi < lo:
        return np.empty(0, dtype=np.int64)
    u = np.arange(lo, hi + 1)
    p = (u + k - int(model.ws_start[h])) % model.n
    return u[p < model.ws_width[h]]


class _BoxGait:
    """Rules 1–11 of thesis 6.3.2 on one box, counter-clockwise.

    Unwrapped coordinates: ``X`` and ``Y`` (grid steps) with the box at
    ``[X0, X1] × [Y0, Y1]``; finger ``xf`` holds contact ``X mod n`` and ``yf`` holds
    ``Y mod n``.
    """

    def __init__(self, model: GaitModel, g: WorkspaceGrid, box: BoxPrototype,
                 trace: Trace, xf: int, yf: int, X: int, Y: int) -> None:
        self.m, self.g, self.trace = model, g, trace
        self.X0, self.X1, self.Y0, self.Y1 = box.x_lo, box.x_hi, box.y_lo, box.y_hi
        self.xf, self.yf, self.X, self.Y = xf, yf, X, Y
        self.w = g.w_steps
        self.backward = 0

    # ------------------------------------------------------------- geometry
    @property
    def k(self) -> int:
        return self.trace.s.k

    def pos(self, f: int, u: int) -> int:
        return self.m.position(f, u % self.m.n, self.k)

    def reach(self, h: int, lo: int, hi: int, k: int | None = None) -> NDArray[np.int64]:
        """Unwrapped coordinates in ``[lo, hi]`` that finger ``h`` reaches at angle ``k``
        (default: now)."""
        return _reach(self.m, h, lo, hi, self.k if k is None else k)

    def free(self) -> int:
        return 3 - self.xf - self.yf

    # ------------------------------------------------------------- moves
    def step(self, axis: str, u: int, rule: str) -> None:
        h = self.free()
        if axis == "x":
            self.trace.regrasp(h, u, self.xf, rule)
            self.xf, self.X = h, int(u)
        else:
            self.trace.regrasp(h, u, self.yf, rule)
            self.yf, self.Y = h, int(u)

    def back_step(self, axis: str, rule: str) -> bool:
        """Largest negative step on ``axis`` into the free finger (inside the box)."""
        h = self.free()
        if axis == "x":
            if self.g.pred(self.xf) != h:
                return False
            u = self.reach(h, self.X0, self.X - 1)
        else:
            if self.g.pred(self.yf) != h:
                return False
            u = self.reach(h, self.Y0, self.Y - 1)
        if u.size == 0:
            return False
        self.step(axis, int(u[0]), rule)
        self.backward += 1
        return True

    def forward_targets(self, axis: str, k: int | None = None) -> NDArray[np.int64]:
        """Positive steps on ``axis`` into the free finger inside the box (at angle ``k``)."""
        h = self.free()
        if axis == "x":
            if self.g.succ(self.xf) != h:
                return np.empty(0, dtype=np.int64)
            return self.reach(h, self.X + 1, self.X1, k)
        if self.g.succ(self.yf) != h:
            return np.empty(0, dtype=np.int64)
        return self.reach(h, self.Y + 1, self.Y1, k)

    def forward_step(self, axis: str, rule: str) -> bool:
        """Smallest positive step on ``axis`` into the free finger (inside the box)."""
        u = self.forward_targets(axis)
        if u.size == 0:
            return False
        self.step(axis, int(u[0]), rule)
        return True

    def stuck(self, why: str) -> Stuck:
        return Stuck(f"{why} at {self.trace.describe()}")

    # ------------------------------------------------------------- rules
    def run(self, K: int) -> None:
        m, g, w = self.m, self.g, self.w
        W = m.ws_width
        while self.k < K:
            px, py = self.pos(self.xf, self.X), self.pos(self.yf, self.Y)
            # thesis 6.3.2, rule 1: the rotation limit (and the room to turn back)
            rot, cap = m.rotation_room(self.xf, px, self.yf, py)
            near_top = self.Y1 - self.Y < w
            near_right = self.X1 - self.X < w
            if rot < K - self.k and not (near_top or near_right):
                # look-ahead for rule 5: if no positive step will exist at the rotation
                # limit, the axis reaching its workspace edge there is treated as too near
                # the box's far edge, so that rules 2-4 (and 6-11) reposition it in time
                ka = self.k + rot
                if not (self.forward_targets("x", ka).size or self.forward_targets("y", ka).size):
                    near_right = px + rot == W[self.xf] - 1
                    near_top = py + rot == W[self.yf] - 1
            # thesis 6.3.2, rules 2-3: upper / right limits: the workspace behind the y (x)
            # finger still reaches the box's bottom (left) edge (fig. 6.11 (c)). When that
            # finger is the other axis's one, the backward rules start with a preparatory
            # step on the other axis (rule 6 / 9), so its limit bounds the rotation too.
            up = (self.Y - py - g.gap_after(g.pred(self.yf))) - self.Y0
            rt = (self.X - px - g.gap_after(g.pred(self.xf))) - self.X0
            upper = right = None
            if near_top:
                upper = min(up, rt) if g.pred(self.yf) == self.xf else up
            if near_right:
                right = min(rt, up) if g.pred(self.xf) == self.yf else rt
            lims = [v for v in (rot, upper, right) if v is not None]
            d = min(lims)  # thesis 6.3.2, rule 4: the least of the limits
            if d < 0:
                # initial condition past the limit: turn back first (6.3.2, last paragraph)
                if cap > 0:  # as far as the workspaces allow
                    self.trace.rotate(max(d, -cap), "6.3.2 turn back")
                    continue
                # a finger at the start of its workspace blocks the turn back: take the
                # backward rules' preparatory step on the other axis first (rule 6 / 9)
                other = "y" if right is not None and d == right else "x"
                rule = "6.3.2 rule 9" if other == "y" else "6.3.2 rule 6"
                if self.back_step(other, rule + " (before turning back)"):
                    continue
                raise self.stuck("6.3.2: the grasp is past its upper/right limit and "
                                 "cannot turn back far enough")
            if d > 0:
                self.trace.rotate(min(d, K - self.k),
                                  "6.3.2 rule 1" if d == rot else "6.3.2 rules 2-4")
                if self.k >= K:
                    return
            if near_top and near_right and d in (upper, right):
                # rule 4, near both far edges: the backward rules whose preparatory step
                # moves the other axis back too (inner box: 6-8, outer box: 9-11)
                if g.box_kind(self.xf, self.yf) == "inner":
                    self.rules_6_8()
                else:
                    self.rules_9_11()
            elif near_top and d == upper:
                self.rules_6_8()
            elif near_right and d == right:
                self.rules_9_11()
            else:
                self.rule_5(px + d == W[self.xf] - 1, py + d == W[self.yf] - 1)

    def rule_5(self, x_at_edge: bool, y_at_edge: bool) -> None:
        # thesis 6.3.2, rule 5: positive step of w on the axis that reached its workspace edge
        order = ["y", "x"] if y_at_edge and not x_at_edge else ["x", "y"]
        if x_at_edge and y_at_edge:
            order = ["x", "y"]
        for axis in order:
            if self.forward_step(axis, "6.3.2 rule 5"):
                return
        raise self.stuck("6.3.2 rule 5: no positive step inside the box")

    def rules_6_8(self) -> None:
        # thesis 6.3.2, rules 6-8
        if not self.back_step("y", "6.3.2 rule 6"):
            if not self.back_step("x", "6.3.2 rule 6"):
                raise self.stuck("6.3.2 rule 6: no negative step inside the box")
            if not self.back_step("y", "6.3.2 rule 7"):
                raise self.stuck("6.3.2 rule 7: no negative vertical step inside the box")
        if not self.forward_step("y", "6.3.2 rule 8"):
            raise self.stuck("6.3.2 rule 8: no positive vertical step inside the box")

    def rules_9_11(self) -> None:
        # thesis 6.3.2, rules 9-11
        if not self.back_step("x", "6.3.2 rule 9"):
            if not self.back_step("y", "6.3.2 rule 9"):
                raise self.stuck("6.3.2 rule 9: no negative step inside the box")
            if not self.back_step("x", "6.3.2 rule 10"):
                raise self.stuck("6.3.2 rule 10: no negative horizontal step inside the box")
        if not self.forward_step("x", "6.3.2 rule 11"):
            raise self.stuck("6.3.2 rule 11: no positive horizontal step inside the box")


def _box_reading(box: BoxPrototype, s: GaitState, n: int) -> tuple[int, int, int, int] | None:
    """``(xf, yf, X, Y)`` reading grasp ``s`` inside ``box`` (either finger on x)."""
    f, g = s.held()
    for a, b in ((f, g), (g, f)):
        ca, cb = s.contacts[a], s.contacts[b]
        if box.contains(ca, cb):
            X = box.x_lo + (ca - box.x_lo) % n
            Y = box.y_lo + (cb - box.y_lo) % n
            return a, b, X, Y
    return None


def _box_starts(model: GaitModel, box: BoxPrototype) -> list[GaitState]:
    """Grasps at θ = 0 inside the box, one per finger pair reading: the grid point nearest
    the box's lower-left corner (most rotation ahead), at least ``w`` from its top and
    right edges where the workspaces allow."""
    g = WorkspaceGrid.from_model(model)
    n, w = model.n, g.w_steps
    out = []
    for xf in range(3):
        for yf in range(3):
            if xf == yf:
                continue
            # at least w from the top and right edges if possible (rule 1 applies at once)
            xs = _reach(model, xf, box.x_lo, box.x_hi - w, 0)
            xs = xs if xs.size else _reach(model, xf, box.x_lo, box.x_hi, 0)
            ys = _reach(model, yf, box.y_lo, box.y_hi - w, 0)
            ys = ys if ys.size else _reach(model, yf, box.y_lo, box.y_hi, 0)
            if xs.size and ys.size:
                cs = [-1, -1, -1]
                cs[xf], cs[yf] = int(xs[0]) % n, int(ys[0]) % n
                s = GaitState(0, tuple(cs))
                if model.is_legal_state(s):
                    out.append(s)
    return out


class _Found(NamedTuple):
    """A counter-clockwise gait of rules 1–11: its trace, backward steps, the nodes opened
    besides its moves (entry search, stuck tries) and the result's extras."""

    trace: Trace
    backward: int
    opened: int
    extra: dict[str, Any]


@lru_cache(maxsize=16)
def _placed_boxes_cached(key: bytes, n: int, ws_start: tuple[int, ...],
                         ws_width: tuple[int, ...]) -> tuple[BoxPrototype, ...]:
    S = np.frombuffer(key, dtype=bool).reshape(n, n)
    g = WorkspaceGrid(n, ws_start, ws_width)
    return tuple(box_prototypes(S, 2 * g.w_steps, geom=g, placed=True))


def _placed_boxes(model: GaitModel, g: WorkspaceGrid) -> tuple[BoxPrototype, ...]:
    """Every maximal box meeting the conditions of 6.3.2 (``>= 2w × 2w``, through an inner
    and an outer finger pair box), squarest first; cached per grasp map and hand."""
    S = np.ascontiguousarray(np.asarray(model.stable, dtype=bool))
    return _placed_boxes_cached(S.tobytes(), model.n, g.ws_start, g.ws_width)


def _first_box(boxes: tuple[BoxPrototype, ...], a: NDArray[np.int64], b: NDArray[np.int64]
               ) -> NDArray[np.int64]:
    """Per grasp ``(a[i], b[i])`` (contacts): the index of the first box holding it in
    either reading, ``len(boxes)`` when none does. Vectorized over boxes and grasps."""
    n = boxes[0].n
    x0 = np.array([bx.x_lo for bx in boxes])[:, None]
    y0 = np.array([bx.y_lo for bx in boxes])[:, None]
    wx = np.array([bx.width_steps for bx in boxes])[:, None]
    wy = np.array([bx.height_steps for bx in boxes])[:, None]
    inside = ((((a - x0) % n <= wx) & ((b - y0) % n <= wy))
              | (((b - x0) % n <= wx) & ((a - y0) % n <= wy)))
    return np.where(inside.any(axis=0), inside.argmax(axis=0), len(boxes))


def _entry_candidates(model: GaitModel, boxes: tuple[BoxPrototype, ...], start: GaitState,
                      max_moves: int, counter: list[int]
                      ) -> Iterator[tuple[list[GaitState], BoxPrototype]]:
    """Grasps inside a box, nearest the start first: a breadth-first search of at most
    ``max_moves`` moves (any legal rotation or regrasp, each state once), level by level;
    within a level by the first box holding the grasp (:func:`_placed_boxes` order,
    squarest first), then in creation order. Yields the path from ``start`` and the box;
    ``counter[0]`` counts the nodes opened."""
    if not boxes:
        return
    f0, g0 = start.held()
    first = int(_first_box(boxes, np.array([start.contacts[f0]]),
                           np.array([start.contacts[g0]]))[0])
    if first < len(boxes):  # already in a box: no search at all
        yield [start], boxes[first]
    if max_moves == 0:
        return
    # the search's window: as far as max_moves rotations reach either way
    reach = max_moves * model.R * model.step_deg
    G = _Graph(model, start, model.step_deg, (-reach, reach))
    n, PP, P = model.n, G.PP, G.P
    ws = np.asarray(model.ws_start, dtype=np.int64)
    pairs = np.array(_PAIRS)
    level = np.array([G.start_code], dtype=np.int64)
    for _ in range(max_moves):
        nxt = []
        for code in level.tolist():
            counter[0] += 1
            codes, _, _ = G.expand(code)
            nxt.append(codes)
        level = np.concatenate(nxt)
        if not level.size:
            return
        kk, rem = np.divmod(level, 3 * PP)
        pair, rem = np.divmod(rem, PP)
        pf, pg = np.divmod(rem, P)
        k = kk + G.k_lo
        f, g = pairs[pair, 0], pairs[pair, 1]
        which = _first_box(boxes, (ws[f] + pf - k) % n, (ws[g] + pg - k) % n)
        hit = np.flatnonzero(which < len(boxes))
        for i in hit[np.argsort(which[hit], kind="stable")].tolist():
            yield _path_to(G, int(level[i])), boxes[int(which[i])]


def _path_to(G: _Graph, code: int) -> list[GaitState]:
    """The states from the search's start to ``code`` (parent links)."""
    out = [code]
    while G.parent[out[-1]] != out[-1]:
        out.append(int(G.parent[out[-1]]))
    return [G.decode(c) for c in reversed(out)]


def _ccw(model: GaitModel, start: GaitState | None, turn_deg: float, max_entry: int,
         t0: float) -> _Found | PlannerResult:
    """The counter-clockwise gait of rules 1–11 (see :func:`back_and_forth_gait`)."""
    g = WorkspaceGrid.from_model(model)
    box, checks = back_and_forth_conditions(model.stable, g)
    extra: dict[str, Any] = {"method": "back-and-forth",
                             "conditions": [c.reason for c in checks],
                             "box": None if box is None else box.describe()}
    if box is None or not all(checks):
        return gait_failure("rule-based", "back-and-forth gait (thesis 6.3.2) conditions fail: "
                            + failed_reasons(checks), t0, extra)
    K = model.turn_steps(turn_deg)
    counter = [0]
    if start is None:  # a grasp at theta = 0 inside the box, no entry needed
        tries = ((([s0], box)) for s0 in _box_starts(model, box))
    else:  # thesis 6.3.2: no initial condition precludes the gait; enter a box first
        tries = _entry_candidates(model, _placed_boxes(model, g), start, max_entry, counter)
    why, best_k, spent, tried = "", 0, 0, 0
    for entry, bx in tries:
        s0 = entry[-1]
        reading = _box_reading(bx, s0, model.n)
        if reading is None:  # every candidate lies in its box (_entry_candidates, _box_starts)
            continue
        tried += 1
        trace = Trace(model, [entry[0]])
        for t in entry[1:]:
            trace.push(t, "6.3.2 entry into the box")
        gait = _BoxGait(model, g, bx, trace, *reading)
        try:
            gait.run(K)
        except Stuck as exc:
            why = str(exc)
            best_k = max(best_k, max(st.k for st in trace.states))
            spent += len(trace.states) - 1
            continue
        extra.update(box=bx.describe(), entry_moves=len(entry) - 1,
                     entry_needed=len(entry) > 1)
        return _Found(trace, gait.backward, spent + counter[0], extra)
    if start is not None and not tried:
        why = (f"no grasp within {max_entry} moves of {model.describe_state(start)} lies in a "
               "box that meets the conditions")
    return gait_failure("rule-based", f"back-and-forth gait stuck: {why}", t0, extra,
                        best_k * model.step_deg, (spent + counter[0], spent + counter[0]))


def back_and_forth_gait(model: GaitModel, start: GaitState | None = None,
                        turn_deg: float = 360.0,
                        entry_max_moves: int = ENTRY_MAX_MOVES) -> PlannerResult:
    """The back-and-forth gait of thesis 6.3.2 (rules 1–11) inside a box prototype.

    The boxes are the maximal stable boxes ``>= 2w × 2w`` placed through an inner and an
    outer finger pair box (:func:`~graspgait_env.planners.prototypes.box_prototypes`).

    Thesis 6.3.2: "Using this method, if the conditions for the box size and placement
    are met, there is no initial condition that would preclude a successful gait." So
    reaching a box is part of the method: from a given ``start`` a breadth-first search
    of at most ``entry_max_moves`` moves (any legal rotation or regrasp) finds the grasps
    inside a box, the box reachable in the fewest moves first (ties: the squarest box,
    then the first grasp found), and rules 1–11 run from there; a grasp from which the
    rules get stuck is skipped for the next. ``start=None`` tries the squarest box's
    grasps at θ = 0 (one per finger pair reading, nearest the box's lower-left corner
    while ``>= w`` from its top and right edges) and keeps the first that turns the
    object. A clockwise turn (``turn_deg < 0``) runs the same rules on the mirror image
    (:mod:`~graspgait_env.planners.mirror`: "substituting right for left, top for
    bottom, positive for negative").

    Parameters
    ----------
    model
        The gait model.
    start
        Start grasp at ``k = 0``, or ``None`` (see above).
    turn_deg
        Requested turn (degrees; negative: clockwise).
    entry_max_moves
        Longest entry into a box (moves) from a given ``start``.

    Returns
    -------
    PlannerResult
        ``planner="rule-based"``, ``extra["method"] = "back-and-forth"``,
        ``extra["box"]`` (the box the rules ran in), ``extra["conditions"]``,
        ``extra["rules"]`` (the rule behind each move: entry moves read "6.3.2 entry into
        the box"), ``extra["entry_moves"]`` (moves before the rules: 0 when the start is
        already in a box) and ``extra["entry_needed"]``; ``pattern`` is ``plus``,
        ``combined`` or ``staircase`` (module docstring). ``nodes_opened`` is the path
        length plus the entry search's nodes opened plus the moves of grasps whose rules
        got stuck. With ``start=None`` and no stable grasp inside the workspaces at
        θ = 0: the no-gait verdict of
        :func:`~graspgait_env.planners.starts.no_start_verdict`.

    Raises
    ------
    GraspGaitInputError
        ``start`` is not a legal grasp at ``k = 0``, or ``entry_max_moves`` < 0.
    """
    t0 = time.perf_counter()
    if isinstance(entry_max_moves, bool) or not isinstance(entry_max_moves, int) \
            or entry_max_moves < 0:
        raise GraspGaitInputError(f"entry_max_moves={entry_max_moves!r}: must be an integer "
                                  ">= 0, e.g. 4")
    verdict = own_start_verdict(model, start, t0, "back-and-forth")
    if verdict is not None:
        return verdict
    if turn_deg >= 0:
        found = _ccw(model, start, turn_deg, entry_max_moves, t0)
        if isinstance(found, PlannerResult):
            return found
        trace = found.trace
    else:  # thesis 6.3.2: the clockwise rules are the mirror image of the CCW ones
        mm = mirrored(model)
        found = _ccw(mm, None if start is None else mirror_state(start, model.n), -turn_deg,
                     entry_max_moves, t0)
        if isinstance(found, PlannerResult):
            found.reason = f"clockwise (mirror image, thesis 6.3.2): {found.reason}"
            found.max_turn_deg = -found.max_turn_deg
            return found
        states = [mirror_state(s, model.n) for s in found.trace.states]
        trace = Trace(model, states[:1])
        for t, rule in zip(states[1:], found.trace.rules, strict=True):
            trace.push(t, rule)  # every mirrored move checked on the original model
    res = gait_result("rule-based", model, trace, t0,
                      gait_pattern(model, trace, found.backward), found.extra)
    add_nodes(res, found.opened, found.opened)
    return res
