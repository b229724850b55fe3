"""Rule-based prototype gaits and the modified search (thesis 6.3–6.5).

- :func:`forward_gait` — the staircase gait of a band prototype (6.3.1, rules 1–4);
- :func:`back_and_forth_gait` — the plus / combined gait of a box prototype (6.3.2,
  rules 1–11);
- :func:`modified_search` — a depth-first search restricted to the gait structure that
  works for the map's type (6.4);
- :func:`rule_based` — the thesis's method of Table 6.1: a prototype gait when its
  conditions hold (forward first, then back-and-forth), else the modified search;
- :func:`diagnose_no_gait` — why there is no gait, in the words of thesis 1.3 (2)–(4).

Every move is checked with :meth:`GaitModel.action_mask` (the one legal-move function)
before it is taken, so every plan replays under :func:`graspgait_env.plan.validate_plan`.

Counting (thesis 6.5)
---------------------
A rule application produces exactly one move — a rotation *or* a regrasp — and that
move is a node of the final path; no node is ever opened off the path. So for the two
rule-based gaits ``nodes_opened == nodes_created == path_length`` = the number of plan
steps after the grasp (rotations + regrasps, thesis 5.4's path length), and ``regrasps``
is the plan's regrasp count. The thesis's Table 6.1 counts rotations implicitly (its
three measures all equal the number of regrasps); ours count them explicitly, so
``path_length`` is about twice ``regrasps``. Zero rotations are never emitted.

Coordinates (see :mod:`graspgait_env.planners.exact`): a finger at workspace position ``p`` at
object angle ``k`` holds unwrapped contact ``x = s_f + p - k``; in the grasp map a
rotation moves the grasp diagonally relative to the finger pair boxes, a regrasp
horizontally (the ``x`` finger changes) or vertically (the ``y`` finger changes).

Choices where the thesis is ambiguous (each tested in ``tests/test_rule_based.py``)
------------------------------------------------------------------------------------
Forward gait (6.3.1):

- Rule 1 ("rotate until the grasp reaches the edge of its finger pair box, or until the
  distance to the next finger pair box is <= the distance to the upcoming edge"): we
  rotate to the finger pair box edge — the thesis shows this is sufficient under the
  three conditions and achieves the most rotation per regrasp; the second clause only
  names the earliest point a regrasp becomes possible (fig. 6.10).
- Rules 2–3 step "to the edge" of the next box: the free finger is placed at the first
  grid angle of its workspace (counter-clockwise turn) and the finger whose workspace
  precedes it round the palm is lifted — a positive horizontal step from an outer box,
  a positive vertical step from an inner box. When the grasp hit the side edge of an
  inner box (``x`` at its limit), the vertical step lands on the outer box's corner, no
  rotation is possible there, and rule 2 follows at once: two regrasps in a row.
- With ``start=None`` the start is an inner-box grasp at θ = 0 meeting condition 3 with
  both fingers as near the start of their workspaces as the band allows (most
  rotation before the first regrasp).
- A clockwise turn (``turn_deg < 0``) uses the rules' parenthesised mirror images.

Back-and-forth gait (6.3.2), counter-clockwise only:

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
  From some starts the rules still get stuck; the result then says where, and
  :func:`rule_based` goes on to the modified search. With ``start=None`` the rules
  start inside the box and, on synthetic box maps, succeed exactly when the box
  conditions hold (tested).
- Pattern: ``plus`` when the last half-turn visits at most the five grasp-map points
  of the + (fig. 6.10 (b)), ``combined`` when the gait uses backward steps and more
  points (fig. 6.10 (c)), ``staircase`` when no backward step was needed. A minimum box
  centred on the diagonal gives the +; larger boxes, or a minimum box near the edge of
  its admissible placements, give the combined pattern.

Modified search (6.4): see :func:`modified_search`.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import plan_from_states
from graspgait_env.planners.prototypes import (
    BandPrototype,
    BoxPrototype,
    Check,
    WorkspaceGrid,
    _intersect,
    back_and_forth_conditions,
    band_prototypes,
    forward_conditions,
    inner_offset,
)
from graspgait_env.planners.result import PlannerResult

__all__ = [
    "forward_gait",
    "back_and_forth_gait",
    "modified_search",
    "rule_based",
    "diagnose_no_gait",
    "map_structure",
    "DEFAULT_MAX_NODES",
]

DEFAULT_MAX_NODES = 20_000  # (nodes opened) cap of the modified search
_MAX_RULE_STEPS = 2_000  # (moves) safety cap of a rule-based gait


class _Stuck(Exception):
    """The rules have no legal move; the message says where and why."""


@dataclass
class _Trace:
    """The states of a gait being built; every move is checked with ``action_mask``."""

    model: GaitModel
    states: list[GaitState]
    rules: list[str] = field(default_factory=list)

    @property
    def s(self) -> GaitState:
        return self.states[-1]

    def rotate(self, delta: int, rule: str) -> None:
        s = self.s
        self._push(GaitState(s.k + int(delta), s.contacts), rule)

    def regrasp(self, finger: int, contact: int, lifted: int, rule: str) -> None:
        s = self.s
        cs = list(s.contacts)
        cs[finger] = int(contact) % self.model.n
        cs[lifted] = -1
        self._push(GaitState(s.k, tuple(cs)), rule)

    def _push(self, t: GaitState, rule: str) -> None:
        s = self.s
        try:
            a = self.model.encode(s, t)
        except ValueError:
            a = -1
        if a < 0 or not self.model.action_mask(s)[a]:
            raise _Stuck(f"{rule}: the move {self.model.describe_state(s)} -> "
                         f"{self.model.describe_state(t)} is not legal")
        if len(self.states) > _MAX_RULE_STEPS:
            raise _Stuck(f"{rule}: more than {_MAX_RULE_STEPS} moves without reaching the goal")
        self.states.append(t)
        self.rules.append(rule)

    def describe(self) -> str:
        return self.model.describe_state(self.s)


def _result(planner: str, model: GaitModel, trace: _Trace, t0: float, pattern: str,
            extra: dict[str, Any]) -> PlannerResult:
    plan = plan_from_states(model, trace.states)
    L = len(plan.steps) - 1
    plan.stats = {"planner": planner, "nodes_opened": L, "regrasps": plan.regrasps,
                  "rotation_deg": plan.rotation_deg}
    extra = dict(extra)
    extra["rules"] = list(trace.rules)
    return PlannerResult(
        planner, plan, nodes_opened=L, nodes_created=L, path_length=L,
        regrasps=plan.regrasps, rotation_deg=plan.rotation_deg,
        max_turn_deg=plan.rotation_deg, wall_time_s=time.perf_counter() - t0,
        pattern=pattern, extra=extra)


def _failure(planner: str, reason: str, t0: float, extra: dict[str, Any],
             max_turn_deg: float = 0.0, nodes: tuple[int, int] = (0, 0),
             exhausted: bool = False) -> PlannerResult:
    return PlannerResult(planner, None, reason=reason, max_turn_deg=max_turn_deg,
                         nodes_opened=nodes[0], nodes_created=nodes[1],
                         wall_time_s=time.perf_counter() - t0, extra=extra,
                         exhausted=exhausted)


def _failed(checks: list[Check]) -> str:
    return "; ".join(c.reason for c in checks if not c.ok)


# =========================================================================== forward
def _forward_start(model: GaitModel, g: WorkspaceGrid, band: BandPrototype,
                   sign: int) -> GaitState | None:
    """An inner-box grasp at θ = 0 meeting condition 3, fingers nearest the start of their
    workspaces in the turn's direction (see the module docstring)."""
    best: tuple[int, GaitState] | None = None
    for fx, fy in g.boxes("inner"):
        if g.succ(fx) != fy:
            continue
        a, b = g.box_offsets(fx, fy)
        lo, hi = _intersect(band.d_lo, band.d_hi - g.w_steps, a, b, g.n)
        if lo > hi:
            continue
        D = (g.ws_start[fy] - g.ws_start[fx]) % g.n
        Wx, Wy = g.ws_width[fx], g.ws_width[fy]
        ideal = D if sign > 0 else D + (Wy - 1) - (Wx - 1)
        d = min(max(ideal, lo), hi)
        t = d - D  # p_y - p_x
        if sign > 0:
            px = max(0, -t)
            score = Wx - 1 - max(px, px + t)
        else:
            px = min(Wx - 1, Wy - 1 - t)
            score = min(px, px + t)
        py = px + t
        if not (0 <= px < Wx and 0 <= py < Wy):
            continue
        cs = [-1, -1, -1]
        cs[fx] = (g.ws_start[fx] + px) % g.n
        cs[fy] = (g.ws_start[fy] + py) % g.n
        s = GaitState(0, tuple(int(c) for c in cs))
        if model.is_legal_state(s) and (best is None or score > best[0]):
            best = (score, s)
    return None if best is None else best[1]


def forward_gait(model: GaitModel, start: GaitState | None = None,
                 turn_deg: float = 360.0) -> PlannerResult:
    """The forward (staircase) gait of thesis 6.3.1, generated by rules 1–4, no search.

    Parameters
    ----------
    model
        The gait model (object, friction, hand).
    start
        Start grasp at ``k = 0``; ``None``: a grasp in the band chosen by the conditions
        (module docstring).
    turn_deg
        Requested turn (degrees; negative: clockwise, with the mirrored rules).

    Returns
    -------
    PlannerResult
        ``planner="rule-based"``, ``pattern="staircase"``, ``extra["method"] =
        "forward"``, ``extra["band"]`` (the band used), ``extra["conditions"]`` (the
        three reasons) and ``extra["rules"]`` (the rule behind each move). With a plan,
        ``nodes_opened == path_length``. Without: the failed conditions as the reason.
    """
    t0 = time.perf_counter()
    g = WorkspaceGrid.from_model(model)
    sign = 1 if turn_deg >= 0 else -1
    band, checks = forward_conditions(model.stable, g, None if start is None else start.contacts)
    extra: dict[str, Any] = {"method": "forward", "conditions": [c.reason for c in checks],
                             "band": None if band is None else band.describe()}
    if not all(checks) or band is None:
        return _failure("rule-based", "forward gait (thesis 6.3.1) conditions fail: "
                        + _failed(checks), t0, extra)
    if start is None:
        start = _forward_start(model, g, band, sign)
        if start is None:
            return _failure("rule-based", f"forward gait: no grasp at theta = 0 of the "
                            f"{band.describe()} meets condition 3", t0, extra)
    elif not model.is_legal_state(start) or start.k != 0:
        raise ValueError(f"start {start}: must be a legal state at k = 0")
    trace = _Trace(model, [start])
    K = model.turn_steps(turn_deg)
    W = model.ws_width
    # the staircase's reading: x/y roles kept through the gait (thesis fig. 6.10 (a))
    _, xf, yf = inner_offset(start.contacts, g)
    try:
        while (K - trace.s.k) * sign > 0:
            s = trace.s
            f, h2 = s.held()
            pf, pg = model.position(f, s.contacts[f], s.k), model.position(h2, s.contacts[h2], s.k)
            lim = min(W[f] - 1 - pf, W[h2] - 1 - pg) if sign > 0 else min(pf, pg)
            if lim > 0:  # rule 1: rotate to the finger pair box edge (or the goal)
                trace.rotate(sign * min(lim, abs(K - s.k)), "6.3.1 rule 1")
                continue
            h = 3 - f - h2
            lift = g.pred(h) if sign > 0 else g.succ(h)
            p = 0 if sign > 0 else int(W[h]) - 1
            inner = g.box_kind(xf, yf) == "inner"
            # CCW: inner box -> positive vertical step (rule 3), outer -> positive
            # horizontal step (rule 2); CW: the parenthesised mirror images
            rule = "6.3.1 rule 3" if inner else "6.3.1 rule 2"
            trace.regrasp(h, int(model.ws_start[h]) + p - s.k, lift, rule)
            if lift == yf:
                yf = h
            else:
                xf = h
    except _Stuck as exc:
        moves = len(trace.states) - 1
        return _failure("rule-based", f"forward gait stuck at {trace.describe()}: {exc}", t0,
                        extra, max(st.k for st in trace.states) * model.step_deg, (moves, moves))
    return _result("rule-based", model, trace, t0, "staircase", extra)


# =========================================================================== back-and-forth
class _BoxGait:
    """Rules 1–11 of thesis 6.3.2 on one box, counter-clockwise.

    Unwrapped coordinates: ``X`` and ``Y`` (grid steps) with the box at
    ``[X0, X1] × [Y0, Y1]``; finger ``xf`` holds contact ``X mod n`` and ``yf`` holds
    ``Y mod n``.
    """

    def __init__(self, model: GaitModel, g: WorkspaceGrid, box: BoxPrototype,
                 trace: _Trace, xf: int, yf: int, X: int, Y: int) -> None:
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

    def reach(self, h: int, lo: int, hi: int, k: int | None = None) -> np.ndarray:
        """Unwrapped coordinates in ``[lo, hi]`` that finger ``h`` reaches at angle ``k``
        (default: now)."""
        if hi < lo:
            return np.empty(0, dtype=np.int64)
        k = self.k if k is None else k
        u = np.arange(lo, hi + 1)
        p = (u + k - int(self.m.ws_start[h])) % self.m.n
        return u[p < self.m.ws_width[h]]

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

    def forward_targets(self, axis: str, k: int | None = None) -> np.ndarray:
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

    def stuck(self, why: str) -> _Stuck:
        return _Stuck(f"{why} at {self.trace.describe()}")

    # ------------------------------------------------------------- rules
    def run(self, K: int) -> None:
        m, g, w = self.m, self.g, self.w
        W = m.ws_width
        while self.k < K:
            px, py = self.pos(self.xf, self.X), self.pos(self.yf, self.Y)
            rot = min(W[self.xf] - 1 - px, W[self.yf] - 1 - py)  # rotation limit (rule 1)
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
            # upper / right limits: the workspace behind the y (x) finger still reaches
            # the box's bottom (left) edge (rules 2, 3; fig. 6.11 (c)). When that finger is
            # the other axis's one, the backward rules start with a preparatory step on
            # the other axis (rule 6 / 9), so its limit bounds the rotation too.
            up = (self.Y - py - g.gap_after(g.pred(self.yf))) - self.Y0
            rt = (self.X - px - g.gap_after(g.pred(self.xf))) - self.X0
            upper = right = None
            if near_top:
                upper = min(up, rt) if g.pred(self.yf) == self.xf else up
            if near_right:
                right = min(rt, up) if g.pred(self.xf) == self.yf else rt
            lims = [v for v in (rot, upper, right) if v is not None]
            d = min(lims)
            if d < 0:
                # initial condition past the limit: turn back first (6.3.2, last paragraph)
                cap = min(px, py)
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
        # positive step of w on the axis that reached its workspace edge
        order = ["y", "x"] if y_at_edge and not x_at_edge else ["x", "y"]
        if x_at_edge and y_at_edge:
            order = ["x", "y"]
        for axis in order:
            if self.forward_step(axis, "6.3.2 rule 5"):
                return
        raise self.stuck("6.3.2 rule 5: no positive step inside the box")

    def rules_6_8(self) -> None:
        if not self.back_step("y", "6.3.2 rule 6"):
            if not self.back_step("x", "6.3.2 rule 6"):
                raise self.stuck("6.3.2 rule 6: no negative step inside the box")
            if not self.back_step("y", "6.3.2 rule 7"):
                raise self.stuck("6.3.2 rule 7: no negative vertical step inside the box")
        if not self.forward_step("y", "6.3.2 rule 8"):
            raise self.stuck("6.3.2 rule 8: no positive vertical step inside the box")

    def rules_9_11(self) -> None:
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
            xs = _reach0(model, xf, box.x_lo, box.x_hi - w)
            xs = xs if xs.size else _reach0(model, xf, box.x_lo, box.x_hi)
            ys = _reach0(model, yf, box.y_lo, box.y_hi - w)
            ys = ys if ys.size else _reach0(model, yf, box.y_lo, box.y_hi)
            if xs.size and ys.size:
                cs = [-1, -1, -1]
                cs[xf], cs[yf] = int(xs[0]) % n, int(ys[0]) % n
                s = GaitState(0, tuple(cs))
                if model.is_legal_state(s):
                    out.append(s)
    return out


def _reach0(model: GaitModel, f: int, lo: int, hi: int) -> np.ndarray:
    if hi < lo:
        return np.empty(0, dtype=np.int64)
    u = np.arange(lo, hi + 1)
    return u[(u - int(model.ws_start[f])) % model.n < model.ws_width[f]]


def _pattern(model: GaitModel, trace: _Trace, backward: int) -> str:
    """``staircase`` without backward steps; else ``plus`` when the last half-turn visits at
    most the five grasp-map points of the + (fig. 6.10 (b)), ``combined`` otherwise (the
    first moves from an arbitrary start are a transient and are not counted)."""
    if backward == 0:
        return "staircase"
    k_end = trace.states[-1].k
    tail = [s for s in trace.states if abs(k_end - s.k) <= model.n // 2]
    pts = {tuple(sorted(c for c in s.contacts if c >= 0)) for s in tail}
    return "plus" if len(pts) <= 5 else "combined"


def back_and_forth_gait(model: GaitModel, start: GaitState | None = None,
                        turn_deg: float = 360.0) -> PlannerResult:
    """The back-and-forth gait of thesis 6.3.2 (rules 1–11) inside a box prototype.

    The box is the squarest maximal stable box ``>= 2w × 2w`` placed through an inner and
    an outer finger pair box (holding ``start`` when given). ``start=None`` tries the
    box's grasps at θ = 0 (one per finger pair reading, nearest the box's lower-left
    corner while ``>= w`` from its top and right edges) and keeps the first that turns
    the object. Counter-clockwise turns only (a negative ``turn_deg`` is refused with a
    reason).

    Returns
    -------
    PlannerResult
        ``planner="rule-based"``, ``extra["method"] = "back-and-forth"``,
        ``extra["box"]``, ``extra["conditions"]``, ``extra["rules"]`` (the rule behind
        each move); ``pattern`` is ``plus``, ``combined`` or ``staircase`` (module
        docstring). ``nodes_opened == path_length`` unless a start grasp tried first got
        stuck (its moves are counted as opened nodes too).
    """
    t0 = time.perf_counter()
    g = WorkspaceGrid.from_model(model)
    box, checks = back_and_forth_conditions(model.stable, g,
                                            None if start is None else start.contacts)
    extra: dict[str, Any] = {"method": "back-and-forth",
                             "conditions": [c.reason for c in checks],
                             "box": None if box is None else box.describe()}
    if turn_deg < 0:
        return _failure("rule-based", "back-and-forth gait: only counter-clockwise turns are "
                        "implemented (thesis 6.3.2 lists the CCW rules)", t0, extra)
    if box is None or not all(checks):
        return _failure("rule-based", "back-and-forth gait (thesis 6.3.2) conditions fail: "
                        + _failed(checks), t0, extra)
    if start is not None and (not model.is_legal_state(start) or start.k != 0):
        raise ValueError(f"start {start}: must be a legal state at k = 0")
    starts = [start] if start is not None else _box_starts(model, box)
    if not starts:
        return _failure("rule-based", f"back-and-forth gait: no grasp at theta = 0 inside the "
                        f"{box.describe()}", t0, extra)
    K = model.turn_steps(turn_deg)
    why, best_k, spent = "", 0, 0
    for s0 in starts:
        reading = _box_reading(box, s0, model.n)
        assert reading is not None
        trace = _Trace(model, [s0])
        gait = _BoxGait(model, g, box, trace, *reading)
        try:
            gait.run(K)
        except _Stuck as exc:
            why = str(exc)
            best_k = max(best_k, max(st.k for st in trace.states))
            spent += len(trace.states) - 1
            continue
        res = _result("rule-based", model, trace, t0, _pattern(model, trace, gait.backward),
                      extra)
        if spent:  # moves of start grasps whose rules got stuck count as opened nodes
            res.nodes_opened += spent
            res.nodes_created += spent
            assert res.plan is not None
            res.plan.stats["nodes_opened"] = res.nodes_opened
        return res
    return _failure("rule-based", f"back-and-forth gait stuck: {why}", t0, extra,
                    best_k * model.step_deg, (spent, spent))


# =========================================================================== modified search
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

    def _any_regrasp(self, s: GaitState, deltas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
        m, sign = self.m, self.sign
        back_first = phase == _ROTATED_B
        if phase == _FREE:
            f, g2 = s.held()
            pf = m.position(f, s.contacts[f], s.k)
            pg = m.position(g2, s.contacts[g2], s.k)
            W = m.ws_width
            lim = min(W[f] - 1 - pf, W[g2] - 1 - pg) if sign > 0 else min(pf, pg)
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
            f, g2 = s.held()
            pf = m.position(f, s.contacts[f], s.k)
            pg = m.position(g2, s.contacts[g2], s.k)
            W = m.ws_width
            back = min(pf, pg) if sign > 0 else min(W[f] - 1 - pf, W[g2] - 1 - pg)
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


def _spread_starts(model: GaitModel, count: int) -> list[GaitState]:
    """``model.start_states()[::step][:count]`` (evenly spread legal grasps at θ = 0),
    without building every state."""
    n = model.n
    parts = []
    for f, g in ((0, 1), (0, 2), (1, 2)):
        cf = (model.ws_start[f] + np.arange(model.ws_width[f])) % n
        cg = (model.ws_start[g] + np.arange(model.ws_width[g])) % n
        i, j = np.nonzero(model.stable[np.ix_(cf, cg)])
        parts.append((f, g, cf[i], cg[j]))
    total = sum(len(p[2]) for p in parts)
    out = []
    for idx in range(0, total, max(1, total // count)):
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
    A state (with its phase in the structure) is entered once.

    Parameters
    ----------
    start
        Start grasp at ``k = 0``; ``None``: up to 8 legal starts spread through
        :meth:`GaitModel.start_states` are tried in turn (their nodes add up).
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
        backward regrasp was used, else ``plus`` / ``combined``.
    """
    t0 = time.perf_counter()
    g = WorkspaceGrid.from_model(model)
    K = model.turn_steps(turn_deg)
    extra: dict[str, Any] = {"method": "modified-search"}
    if start is not None:
        if not model.is_legal_state(start) or start.k != 0:
            raise ValueError(f"start {start}: must be a legal state at k = 0")
        starts = [start]
    else:
        starts = _spread_starts(model, 8)
    if not starts:
        return _failure("modified-search", "no stable grasp lies inside the workspaces at "
                        "theta = 0", t0, extra, exhausted=True)
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
            trace = _Trace(model, [s0])
            for t, lab in zip(states[1:], labels, strict=True):
                trace._push(t, lab)
            back = sum(lab == "backward regrasp" for lab in labels)
            res = _result("modified-search", model, trace, t0, _pattern(model, trace, back),
                          {**extra, "structure": st})
            res.nodes_opened, res.nodes_created = opened, created
            assert res.plan is not None
            res.plan.stats["nodes_opened"] = opened
            return res
        if opened >= max_nodes:
            break
    why = "exhausted its" if exhausted else f"stopped at the node limit ({max_nodes}) in the"
    return _failure("modified-search", f"modified search ({' then '.join(order)}) {why} search "
                    f"space after {opened} nodes; best turn {_sign_deg(best, K, model):g} deg",
                    t0, extra, _sign_deg(best, K, model), (opened, created), exhausted)


def _sign_deg(best: int, K: int, model: GaitModel) -> float:
    """The best turn reached, in degrees, signed like the requested turn."""
    return (1 if K >= 0 else -1) * best * model.step_deg


# =========================================================================== combined
def rule_based(model: GaitModel, start: GaitState | None = None, turn_deg: float = 360.0,
               max_nodes: int = DEFAULT_MAX_NODES) -> PlannerResult:
    """The thesis's prototype-gait method (6.5, Table 6.1 "rule-based").

    The forward gait when its conditions hold (6.3.1), else the back-and-forth gait
    (6.3.2), else the modified search (6.4). ``planner="rule-based"``;
    ``extra["method"]`` says which of ``forward``, ``back-and-forth``,
    ``modified-search`` produced the plan, and ``extra["prototypes"]`` why the earlier
    ones did not. Moves made by a rule gait that then got stuck count as nodes opened.
    """
    t0 = time.perf_counter()
    notes = []
    spent = 0
    for fn in (forward_gait, back_and_forth_gait):
        r = fn(model, start, turn_deg)
        if r.success:
            r.extra["prototypes"] = notes
            r.nodes_opened += spent
            r.nodes_created += spent
            r.wall_time_s = time.perf_counter() - t0
            if r.plan is not None:
                r.plan.stats["nodes_opened"] = r.nodes_opened
            return r
        notes.append(r.reason)
        spent += r.nodes_opened
    r = modified_search(model, start, turn_deg, max_nodes=max_nodes)
    r.planner = "rule-based"
    r.nodes_opened += spent
    r.nodes_created += spent
    r.extra["prototypes"] = notes
    r.wall_time_s = time.perf_counter() - t0
    if r.plan is not None:
        r.plan.stats.update(planner="rule-based", nodes_opened=r.nodes_opened)
    else:
        r.reason = "; ".join(notes + [r.reason])
    return r


# =========================================================================== diagnosis
def diagnose_no_gait(model: GaitModel, start: GaitState | None = None,
                     turn_deg: float = 360.0, candidates: int = 8) -> str:
    """Why no gait turns the object, in the words of thesis 1.3, questions (2)–(4).

    The first of these that applies, as one line starting with its category:

    1. ``"no stable grasp at all (mu=0.3)"`` — the grasp map is empty;
    2. ``"stable grasps but none reachable inside the workspaces"`` — no stable pair has
       its two contacts in two fingers' workspaces at θ = 0;
    3. ``"stuck at angle X deg"`` — the exact planner
       (:func:`~graspgait_env.planners.exact.optimal_gait`) proves that no gait from
       ``start`` (or from any of ``candidates`` starts spread
       through the legal ones) turns further than X; the prototype numbers follow
       (band/box against ``w``), the reason rule-based gaits cannot help;
    4. ``"band/box smaller than the conditions need relative to w (...)"`` — a gait
       exists (found by the exact planner) but no prototype satisfies its conditions,
       so only a search finds it.

    When the forward or back-and-forth conditions hold and a gait exists, the line says so.
    """
    from graspgait_env.planners.exact import optimal_gait

    S = np.asarray(model.stable, dtype=bool)
    if not S.any():
        return (f"no stable grasp at all (mu={model.mu:g}): {model.shape.name}'s grasp map is "
                "empty; raise mu (thesis 1.3 (2))")
    starts = [start] if start is not None else model.start_states()
    if not starts:
        return (f"stable grasps but none reachable inside the workspaces: {int(S.sum())} stable "
                f"pairs at mu={model.mu:g}, none with both contacts in two fingers' workspaces "
                "at theta = 0 (thesis 1.3 (2))")
    g = WorkspaceGrid.from_model(model)
    band, fchecks = forward_conditions(S, g)
    box, bchecks = back_and_forth_conditions(S, g)
    proto = _prototype_numbers(band, fchecks, box, bchecks, g)
    tried = starts if start is not None else starts[:: max(1, len(starts) // candidates)][
        :candidates]
    best = 0.0
    for s0 in tried:
        r = optimal_gait(model, s0, turn_deg)
        if r.success:
            if all(fchecks) or all(bchecks):
                kind = "forward" if all(fchecks) else "back-and-forth"
                return f"a gait exists: the {kind} gait's conditions hold ({proto})"
            return (f"band/box smaller than the conditions need relative to w ({proto}); a gait "
                    f"still exists (exact planner: {r.regrasps} regrasps), found by search only")
        best = max(best, abs(r.max_turn_deg))
    where = (model.describe_state(start) if start is not None
             else f"each of {len(tried)} start grasps tried")
    return (f"stuck at angle {best:g} deg: from {where} no gait turns the object further "
            f"(exhaustive exact search, thesis 1.3 (3)-(4)); {proto}")


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
