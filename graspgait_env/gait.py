"""The gait model: states, rotate/regrasp moves and the legal-move function (thesis 4.3, 5.2).

Discretization
--------------
Contacts lie on the grasp map's grid, ``phi_c = 360 c / n`` degrees (object frame), and
the object angle is ``theta = 360 k / n`` degrees: rotations move in steps of the same
grid (2° by default, as in the thesis's searches, 5.2), so a contact on the grid stays
on the grid in the workspace frame ``F``. ``n`` configures both; the thesis's Δx = Δy = Δθ
choice is kept. A contact ``c`` held at object angle ``k`` lies at ``F`` grid index
``(c + k) mod n``. A finger's workspace is the set of ``F`` grid angles inside its arc;
positions ``p = 0 .. W_f - 1`` count grid steps from the first of them.

State
-----
``(k, c_1, c_2, c_3)``: the object angle in grid steps (an unbounded integer: the turn
achieved so far is ``k * 360 / n`` degrees, counter-clockwise positive) and the contact
of each finger, ``-1`` for the free finger. Exactly two fingers hold the object.
In the thesis's terms (5.2) ``X = [theta, x, y]`` with the fingers implied by the
workspaces; we name the fingers explicitly since the action space does.

Moves (docs/conventions.md)
---------------------------
- **rotate** by ``±j`` grid steps: both contacts stay inside their fingers' workspaces
  all the way (thesis 5.2, fig. 5.1; either direction).
- **regrasp**: the free finger is placed at a grid contact reachable now (inside its
  workspace at the present angle), then one of the two old fingers is lifted; the new
  pair must be force-closure (thesis 4.2: one contact kept, a horizontal or vertical
  move in the map, into another finger pair box).

Action layout (one discrete space for the planners and the Gymnasium envs)
----------------------------------------------------------------------------
With ``R = max_f W_f - 1`` (the longest rotation) and ``P = max_f W_f``:

- ``0 .. R-1``: rotate counter-clockwise by ``a + 1`` steps;
- ``R .. 2R-1``: rotate clockwise by ``a - R + 1`` steps;
- ``2R + 2 p + l``: regrasp — put the free finger at position ``p`` of its workspace and
  lift the held finger with the lower (``l = 0``) or higher (``l = 1``) number.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.contact_model import POINT_CONTACTS, ContactModel
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.grasp_map import GraspMap, check_n, grasp_map
from graspgait_env.objects import load_object
from graspgait_env.shapes import Shape
from graspgait_env.workspace import Hand, load_hand

__all__ = ["GaitModel", "GaitState", "Move", "ROTATE", "REGRASP", "workspace_grid",
           "rotation_room_of", "MAX_PLAN_N", "MAX_TURN_STEPS"]

ROTATE = "rotate"
REGRASP = "regrasp"

# Bounds on what a plan may ask for, so that no planner allocates more than this machine
# holds. Measured peaks (2-core, 24 GiB machine): the exact planner at n = 720 turning
# 900 deg (1800 grid steps) 1.1 GB, at n = 180 turning 3600 deg (1800 steps) 0.5 GB,
# and at 18000 steps 24 GB; best-first and the exact planner at n = 1800 about 3.1 GB.
MAX_PLAN_N = 720  # (grid points) a 0.5-degree grid
MAX_TURN_STEPS = 1800  # (grid steps) |turn_deg| * n / 360: ten turns on the 2-degree grid


def workspace_grid(workspaces_deg, n: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Each finger's workspace on the ``360 / n``-degree grid (thesis 4.1, 5.2).

    The one definition of the workspace rounding: a workspace ``[lo, hi]`` (degrees,
    frame ``F``) holds the grid angles ``a`` with ``lo <= a * 360 / n <= hi`` (to 1e-9 of
    a step, so that 90° on a 2° grid is inside).

    Parameters
    ----------
    workspaces_deg
        ``[(lo, hi), ...]`` per finger, degrees, counter-clockwise from ``lo`` to ``hi``.
    n
        Grid size.

    Returns
    -------
    ws_start, ws_width
        Per finger: the unwrapped grid index of workspace position 0, and the number
        ``W_f`` of grid angles in the workspace.

    Raises
    ------
    GraspGaitInputError
        A workspace holds no grid angle.
    """
    step = 360.0 / n
    starts, widths = [], []
    for f, (lo, hi) in enumerate(workspaces_deg):
        a0 = math.ceil(lo / step - 1e-9)
        a1 = math.floor(hi / step + 1e-9)
        if a1 < a0:
            raise GraspGaitInputError(
                f"workspaces_deg[{f}]={[lo, hi]}: holds no grid angle at n={n}; "
                "widen the workspace or raise n")
        starts.append(a0)
        widths.append(a1 - a0 + 1)
    return np.array(starts, dtype=np.int64), np.array(widths, dtype=np.int64)


def rotation_room_of(ws_width: Any, f: Any, pf: Any, g: Any, pg: Any) -> tuple[Any, Any]:
    """:meth:`GaitModel.rotation_room` elementwise over NumPy arrays (thesis 5.2): the
    grid steps ``(ccw, cw)`` that fingers ``f``, ``g`` (finger indices, arrays allowed)
    at workspace positions ``pf``, ``pg`` may turn, with workspace widths ``ws_width``
    (grid points per finger): ``ccw = min(W_f - 1 - pf, W_g - 1 - pg)``, ``cw = min(pf,
    pg)``. Symmetric in the two fingers."""
    W = np.asarray(ws_width)
    return np.minimum(W[f] - 1 - pf, W[g] - 1 - pg), np.minimum(pf, pg)


class GaitState(NamedTuple):
    """``(k, contacts)``: object angle in grid steps and each finger's contact (-1: free)."""

    k: int
    contacts: tuple[int, ...]

    def held(self) -> tuple[int, ...]:
        """Fingers (0-based) on the object, ascending."""
        return tuple(f for f, c in enumerate(self.contacts) if c >= 0)


class Move(NamedTuple):
    """A decoded action: ``kind`` rotate (``delta`` grid steps, CCW positive) or regrasp
    (``finger`` placed at ``contact``, ``lifted`` removed; fingers 0-based).

    A NamedTuple, not a dataclass: the envs decode one per step, and a tuple is built in
    a third of the time (measured: 0.25 vs 0.75 us).
    """

    kind: str
    delta: int = 0
    finger: int = -1
    contact: int = -1
    lifted: int = -1


class GaitModel:
    """The discretized grasp-gait problem for one object, friction and hand.

    Parameters
    ----------
    shape
        Object (a :class:`~graspgait_env.shapes.Shape`, bundled name or YAML path).
    mu
        Coulomb friction coefficient (> 0).
    hand
        :class:`~graspgait_env.workspace.Hand`, a bundled hand name or YAML path;
        default the thesis hand of fig. 4.1. Exactly three fingers.
    n
        Grid size: contacts and rotations in steps of ``360 / n`` degrees (default 180).
    max_radius
        Reach cap (m) for the grasp map (thesis fig. 4.3); a reach hand supplies its own.
    vertex_clearance_deg
        Keep contacts this many degrees away from polygon vertices (see
        :func:`graspgait_env.grasp_map`); 0 (default) is the thesis's point-contact model.
    contact_model
        What the fingertips are (:mod:`graspgait_env.contact_model`): the default
        :data:`~graspgait_env.contact_model.POINT_CONTACTS` gives the thesis's maps;
        :func:`~graspgait_env.contact_model.hand_contact_model` the maps of plans the
        simulated hand can execute (friction margin for the rotation's load, contacts
        clear of the vertices a rolling ball would reach). Plans record it.

    Attributes
    ----------
    stable
        The ``(n, n)`` grasp map.
    ws_start, ws_width
        Per finger (0-based): unwrapped ``F`` grid index of workspace position 0, and
        the number ``W_f`` of grid angles in the workspace.
    n_actions
        Size of the discrete action space (see module docstring).
    """

    def __init__(self, shape: Shape | str, mu: float, hand: Hand | str | None = None,
                 n: int = 180, max_radius: float | None = None,
                 vertex_clearance_deg: float = 0.0,
                 contact_model: ContactModel = POINT_CONTACTS) -> None:
        self.n = check_n(n)
        if self.n > MAX_PLAN_N:
            raise GraspGaitInputError(
                f"n={n!r}: the gait model plans on at most {MAX_PLAN_N} grid points (a "
                f"{360 / MAX_PLAN_N:g}-degree grid; planners need about 3 GB at n=1800); "
                "give e.g. 180")
        self.shape = load_object(shape)
        self.hand, hand_cap = load_hand(hand, self.shape)
        if self.hand.n_fingers != 3:
            raise GraspGaitInputError(
                f"hand {self.hand.name!r}: has {self.hand.n_fingers} fingers; the gait model "
                "needs exactly 3 (two hold, one regrasps)")
        cap = max_radius if max_radius is not None else hand_cap
        self.max_radius = cap
        self.mu = float(mu)
        self.contact_model = contact_model
        self.grasp_map: GraspMap = grasp_map(self.shape, mu, self.n, max_radius=cap,
                                             vertex_clearance_deg=vertex_clearance_deg,
                                             contact_model=contact_model)
        self.stable: NDArray[np.bool_] = self.grasp_map.stable
        self.step_deg = 360.0 / self.n
        self.ws_start, self.ws_width = workspace_grid(self.hand.workspaces_deg, self.n)
        self.R = int(self.ws_width.max()) - 1
        self.P = int(self.ws_width.max())
        self.n_actions = 2 * self.R + 2 * self.P
        self._positions = np.arange(self.P)
        # hot-path caches for action_mask: Python ints, and the extended map transposed so
        # that "contact c against every contact from i0 on" is one contiguous row slice
        self._starts = [int(x) for x in self.ws_start]
        self._widths = [int(x) for x in self.ws_width]
        self._rows = np.ascontiguousarray(self.grasp_map.extended().T)

    # ----------------------------------------------------------------- geometry
    def position(self, finger: int, contact: int, k: int) -> int:
        """Workspace position of ``finger`` holding ``contact`` at angle ``k``; -1 if outside."""
        p = (contact + k - int(self.ws_start[finger])) % self.n
        return int(p) if p < self.ws_width[finger] else -1

    def rotation_room(self, f: int, pf: int, g: int, pg: int) -> tuple[int, int]:
        """Grid steps the object may turn ``(ccw, cw)`` with fingers ``f``, ``g`` at
        workspace positions ``pf``, ``pg`` (thesis 5.2, fig. 5.1).

        The one definition of the rotation limit: both contacts must stay inside their
        workspaces all the way, so the room is the tighter side each way:
        ``ccw = min(W_f - 1 - pf, W_g - 1 - pg)``, ``cw = min(pf, pg)``. Positions grow
        counter-clockwise; arguments may be NumPy arrays (elementwise).
        """
        if not isinstance(pf, int):
            return rotation_room_of(self.ws_width, f, pf, g, pg)
        wd = self._widths
        return min(wd[f] - 1 - pf, wd[g] - 1 - pg), min(pf, pg)

    def state_rotation_room(self, s: GaitState) -> tuple[int, int]:
        """:meth:`rotation_room` of the two fingers holding state ``s``."""
        f, g = s.held()
        return self.rotation_room(f, self.position(f, s.contacts[f], s.k),
                                  g, self.position(g, s.contacts[g], s.k))

    def is_legal_state(self, s: GaitState) -> bool:
        """Two fingers hold a stable grasp with both contacts inside their workspaces."""
        held = s.held()
        if len(held) != 2 or len(s.contacts) != 3:
            return False
        f, g = held
        return (bool(self.stable[s.contacts[f], s.contacts[g]])
                and self.position(f, s.contacts[f], s.k) >= 0
                and self.position(g, s.contacts[g], s.k) >= 0)

    def contact_deg(self, c: int) -> float:
        """Object-frame angle (degrees) of grid contact ``c``."""
        return (c % self.n) * self.step_deg

    def contact_index(self, phi_deg: float) -> int:
        """Grid index of an object-frame angle; refuses angles off the grid."""
        x = phi_deg / self.step_deg
        c = round(x)
        if abs(x - c) > 1e-6:
            raise GraspGaitInputError(
                f"contact {phi_deg} deg: not on the {self.step_deg:g}-degree grid; "
                f"give a multiple of {self.step_deg:g}")
        return int(c) % self.n

    def start_state(self, contacts: dict[int, float]) -> GaitState:
        """State at ``theta = 0`` from ``{finger (1-based): phi_deg}`` with two fingers.

        Raises
        ------
        GraspGaitInputError
            Not two fingers, an unknown finger, a contact outside its finger's workspace,
            or a pair that is not force-closure — each named with the fix.
        """
        if len(contacts) != 2:
            raise GraspGaitInputError(
                f"start grasp {contacts}: needs exactly two fingers; give e.g. {{1: 50, 3: 270}}")
        cs = [-1, -1, -1]
        for f, phi in contacts.items():
            if f not in (1, 2, 3):
                raise GraspGaitInputError(f"start grasp finger {f}: fingers are 1, 2, 3")
            c = self.contact_index(phi)
            if self.position(f - 1, c, 0) < 0:
                lo, hi = self.hand.workspaces_deg[f - 1]
                raise GraspGaitInputError(
                    f"start grasp: finger {f} at {phi} deg is outside its workspace [{lo}, {hi}]")
            cs[f - 1] = c
        s = GaitState(0, tuple(cs))
        f, g = s.held()
        if not self.stable[cs[f], cs[g]]:
            raise GraspGaitInputError(
                f"start grasp {contacts}: not force-closure at mu={self.mu}; pick a stable "
                "pair (see `graspgait map`)")
        return s

    def start_states(self) -> list[GaitState]:
        """Every legal grasp at ``theta = 0`` (all finger pairs), in a fixed order."""
        out = []
        for f, g in ((0, 1), (0, 2), (1, 2)):
            cf = (self.ws_start[f] + np.arange(self.ws_width[f])) % self.n
            cg = (self.ws_start[g] + np.arange(self.ws_width[g])) % self.n
            ok = self.stable[np.ix_(cf, cg)]
            for i, j in zip(*np.nonzero(ok), strict=True):
                cs = [-1, -1, -1]
                cs[f], cs[g] = int(cf[i]), int(cg[j])
                out.append(GaitState(0, tuple(cs)))
        return out

    # ----------------------------------------------------------------- moves
    def action_mask(self, s: GaitState) -> NDArray[np.bool_]:
        """Exactly the legal actions of state ``s`` (thesis 5.2 branching), vectorized.

        Every planner and both environments use this one function. Rotations: both
        contacts stay in their workspaces all the way (the room left on the tighter
        side, each way). Regrasps: the free finger ``h`` at every grid angle of its
        workspace, i.e. object contacts ``(s_h + p - k) mod n`` for ``p = 0 .. W_h - 1``,
        against the kept contact — two contiguous row slices of the (transposed,
        2 × 2-tiled) grasp map written into the interleaved regrasp block.
        """
        mask = np.zeros(self.n_actions, dtype=bool)
        c = s.contacts
        f, g = [i for i in range(3) if c[i] >= 0]
        h = 3 - f - g
        n, k = self.n, s.k
        st, wd = self._starts, self._widths
        pf = (c[f] + k - st[f]) % n
        pg = (c[g] + k - st[g]) % n
        ccw, cw = self.rotation_room(f, pf, g, pg)
        if ccw > 0:
            mask[:ccw] = True
        if cw > 0:
            mask[self.R : self.R + cw] = True
        W = wd[h]
        i0 = (st[h] - k) % n
        b = 2 * self.R
        mask[b : b + 2 * W : 2] = self._rows[c[g], i0 : i0 + W]  # lift f (lower), keep g
        mask[b + 1 : b + 2 * W : 2] = self._rows[c[f], i0 : i0 + W]  # lift g, keep f
        return mask

    def action_masks_at(self, k: ArrayLike, f: ArrayLike, g: ArrayLike, pf: ArrayLike,
                        pg: ArrayLike) -> NDArray[np.bool_]:
        """:meth:`action_mask` of a batch of states given by their held fingers'
        workspace positions: row ``i`` is the mask of the state at object angle ``k[i]``
        (grid steps) whose fingers ``f[i] < g[i]`` hold at workspace positions
        ``pf[i]``, ``pg[i]`` (the free finger is ``3 - f - g``); shape ``(N,
        n_actions)``. The same rule as :meth:`action_mask`, row for row (tested), for
        the searches that open a whole frontier at once
        (:func:`~graspgait_env.planners.search.breadth_first`)."""
        k, f, g, pf, pg = (np.asarray(x, dtype=np.int64).ravel() for x in (k, f, g, pf, pg))
        R, n = self.R, self.n
        h = 3 - f - g
        mask = np.zeros((k.size, self.n_actions), dtype=bool)
        ccw, cw = rotation_room_of(self.ws_width, f, pf, g, pg)
        steps = np.arange(R)
        mask[:, :R] = steps < ccw[:, None]
        mask[:, R:2 * R] = steps < cw[:, None]
        st = self.ws_start
        i0 = (st[h] - k) % n
        cols = i0[:, None] + self._positions  # < 2n: the extended map's columns
        valid = self._positions < self.ws_width[h][:, None]
        cf = (st[f] + pf - k) % n
        cg = (st[g] + pg - k) % n
        b = 2 * R
        mask[:, b::2] = self._rows[cg[:, None], cols] & valid  # lift f (lower), keep g
        mask[:, b + 1::2] = self._rows[cf[:, None], cols] & valid  # lift g, keep f
        return mask

    def decode(self, s: GaitState, action: int) -> Move:
        """The move that ``action`` names in state ``s`` (legal or not)."""
        a = int(action)
        if not 0 <= a < self.n_actions:
            raise ValueError(f"action={a}: must be in 0..{self.n_actions - 1}")
        if a < self.R:
            return Move(ROTATE, delta=a + 1)
        if a < 2 * self.R:
            return Move(ROTATE, delta=-(a - self.R + 1))
        p, lift = divmod(a - 2 * self.R, 2)
        f, g = s.held()
        h = 3 - f - g
        return Move(REGRASP, finger=h, contact=int((self.ws_start[h] + p - s.k) % self.n),
                    lifted=(f, g)[lift])

    def apply(self, s: GaitState, action: int) -> GaitState:
        """The state after ``action`` (assumed legal: check :meth:`action_mask` first)."""
        m = self.decode(s, action)
        if m.kind == ROTATE:
            return GaitState(s.k + m.delta, s.contacts)
        cs = list(s.contacts)
        cs[m.finger] = m.contact
        cs[m.lifted] = -1
        return GaitState(s.k, tuple(cs))

    def encode(self, s: GaitState, t: GaitState) -> int:
        """The action taking ``s`` to ``t`` (one move); raises ValueError if none does."""
        if t.contacts == s.contacts and t.k != s.k:
            d = t.k - s.k
            if 0 < d <= self.R:
                return d - 1
            if 0 < -d <= self.R:
                return self.R - d - 1
        elif t.k == s.k:
            f, g = s.held()
            h = 3 - f - g
            lifted = [x for x in (f, g) if t.contacts[x] < 0]
            if len(lifted) == 1 and t.contacts[h] >= 0:
                p = self.position(h, t.contacts[h], s.k)
                if p >= 0:
                    return 2 * self.R + 2 * p + (0 if lifted[0] == f else 1)
        raise ValueError(f"no single move takes {s} to {t}")

    def successors(self, s: GaitState) -> list[tuple[int, GaitState]]:
        """``(action, next_state)`` for every legal action of ``s``."""
        return [(int(a), self.apply(s, int(a))) for a in np.flatnonzero(self.action_mask(s))]

    def turn_steps(self, turn_deg: float) -> int:
        """The requested turn in grid steps (rounded away from zero to the grid).

        Raises
        ------
        GraspGaitInputError
            ``turn_deg`` not finite, or more than :data:`MAX_TURN_STEPS` grid steps
            (3600 degrees on the 2-degree grid): planners allocate in proportion to it.
        """
        if not math.isfinite(turn_deg):
            raise GraspGaitInputError(f"turn_deg={turn_deg!r}: give a finite angle in degrees, "
                                      "e.g. 360")
        x = turn_deg / self.step_deg
        if abs(x) > MAX_TURN_STEPS + 1e-9:
            raise GraspGaitInputError(
                f"turn_deg={turn_deg:g}: at most {MAX_TURN_STEPS} grid steps "
                f"({MAX_TURN_STEPS * self.step_deg:g} deg at n={self.n}); planners allocate "
                "in proportion to the turn; give e.g. 360")
        return int(math.ceil(x - 1e-9)) if x >= 0 else int(math.floor(x + 1e-9))

    def describe_state(self, s: GaitState) -> str:
        """``theta=40.0 deg, fingers {1: 50.0, 3: 270.0}``."""
        held = {f + 1: self.contact_deg(s.contacts[f]) for f in s.held()}
        return f"theta={s.k * self.step_deg:g} deg, fingers {held}"
