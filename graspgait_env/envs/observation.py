"""The GraspGait observation by name: its layout and its three modes.

Every map-level GraspGait env (``GraspGait-v0``, ``GraspGaitRandom-v0``,
``GraspGaitMujoco-v1`` and the batched ``GraspGait-v0``) assembles one vector, the
**box** observation of the *Observation Space* table of
:class:`~graspgait_env.envs.map_env.GraspGaitEnv`. The config field ``observation_mode``
chooses what ``reset`` and ``step`` return:

- ``"box"`` (the default): that vector, as a ``Box`` (what the shipped models read);
- ``"dict"``: a ``Dict`` of named parts (:data:`PARTS`), in this order:

  - ``grasp``, ``(16,)``: the grasp and turn state, the box vector's header
    (:data:`GRASP_FIELDS`: held fingers, workspace positions, contact and object angles,
    turn achieved and to go);
  - ``actions``, ``(A, F)``: one row per action (the gait model's action layout), one
    column per feature of :attr:`ObservationLayout.action_features`: whether the move is
    legal and what it leads to (below);
  - ``window``, ``(C, C)``: the grasp-map window around the grasp;
  - ``lines``, ``(2, n)``: the grasp map's lines through the grasp, with ``map_lines``
    only;

- ``"flat"``: that ``Dict`` flattened into one ``Box``, the parts one after another in
  that order, each row-major: exactly ``gymnasium.spaces.flatten(dict_space, obs)``
  (a test checks it), for ``MlpPolicy``, RL Zoo and single-file trainers.

The per-action features are computed once, in NumPy, by :class:`ObservationParts`, for
one state or a batch (the single env calls it with a batch of one), so no policy
recomputes planner quantities from offsets. Columns, for action ``a`` (``A =
n_actions``, ``R`` rotations each way, ``K = abs(turn_deg) / Δ`` grid steps, ``σ`` the
turn's sign; thesis 5.2 for rotations, 4.2 for regrasps):

============  ======================================================================
``legal``     1 when ``a`` is legal now (the mask), else 0.
``rotation``  1 for a rotation action (``a < 2R``), 0 for a regrasp (fixed).
``achieved``  the turn achieved after the move, ``σ k' / K`` (a regrasp keeps ``k``).
``room_on``   grid steps the grasp after the move may still turn towards the goal,
              over ``K`` (``GaitModel.rotation_room``: both contacts stay in their
              workspaces).
``room_back`` the same against the goal.
``opens``     with ``rotation_lookahead``: 1 when the rotation is legal and a regrasp
              is legal after it (0 for regrasps).
``reach_j``   with ``regrasp_lookahead = D``, ``j = 1 .. D``: the reach look-ahead,
              ``j - 1`` more regrasps deep (the box vector's ``reach`` part, per
              action; an illegal move reads its maximum, "none").
``reach_rank`` with ``regrasp_lookahead``: the move's place in the greedy reading of the
              reach look-ahead (:func:`greedy_ranks`), over ``A - 1``: 0 for the move
              that reading plays, 1 for an illegal move.
============  ======================================================================

Why ``reach_rank``: the greedy reading is a lexicographic order over the ``D`` reach
columns with tie rules, which a small network learns poorly from labels; given the rank,
a policy need only learn where to depart from it. Measured (CHANGELOG, 2026-12-04): the
``general`` recipe at ``regrasp_lookahead: 5``, seed 0, DAgger on the optimum, needed
1.15x the optimum's regrasps on 45 held-out starts with a gait without it and 1.05x
with it.

``achieved``, ``room_on`` and ``room_back`` are 0 for an illegal action (``legal`` tells
it apart). :class:`ObservationLayout` is the one place that knows where a part lies in
a flat vector, in the box vector and in the flattened dict.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import rotation_room_of

__all__ = ["ACTION_FEATURES", "GRASP_FIELDS", "OBSERVATION_MODES", "ObservationLayout",
           "ObservationParts", "PARTS", "check_observation_mode", "greedy_ranks"]

OBSERVATION_MODES: tuple[str, ...] = ("box", "dict", "flat")
PARTS: tuple[str, ...] = ("grasp", "actions", "window", "lines")

# The box vector's header (the grasp and turn state), entry by entry.
_HELD = 0  # 3 entries
_POS = 3  # 3 entries
_PHI = 6  # 6 entries: (cos, sin) per finger
_THETA = 12  # 2 entries: cos, sin
_ACHIEVED = 14
_TO_GO = 15
_HEADER = 16
GRASP_FIELDS: tuple[str, ...] = (
    "held_1", "held_2", "held_3", "position_1", "position_2", "position_3",
    "cos_phi_1", "sin_phi_1", "cos_phi_2", "sin_phi_2", "cos_phi_3", "sin_phi_3",
    "cos_theta", "sin_theta", "achieved", "to_go")
ACTION_FEATURES: tuple[str, ...] = ("legal", "rotation", "achieved", "room_on", "room_back")
"""The per-action features every dict observation has; ``opens`` and ``reach_1 ..
reach_D``, ``reach_rank`` follow with ``rotation_lookahead`` and ``regrasp_lookahead =
D``."""


def greedy_ranks(reach: NDArray[np.floating], finishing: NDArray[np.bool_],
                 legal: NDArray[np.bool_], rot_delta: NDArray[np.int64], turn_steps: int,
                 none: int) -> NDArray[np.int64]:
    """Every move's place in the greedy reading of the reach look-ahead, for ``B`` states.

    The greedy reading (no learning; the benchmark's ``greedy-reach:D`` policy plays its
    first move) orders the legal moves by, in turn: a rotation that reaches the turn
    first; the least shortfall ``D - 1`` regrasps deep, then ``D - 2``, ... ``0``; a
    regrasp before a rotation and a shorter rotation first; then the regrasps in action
    order before the rotations in action order (every move gets its own place).

    Parameters
    ----------
    reach
        ``(B, A, D)``: each action's reach look-ahead (``regrasp_lookahead = D``), in the
        gait model's action order (the ``2 R`` rotations first), as the envs write it:
        shortfalls over ``turn_steps`` grid steps.
    finishing
        ``(B, A)``: the rotations that reach the turn.
    legal
        ``(B, A)``: the legal moves.
    rot_delta
        Signed grid steps of the ``2 R`` rotation actions.
    turn_steps
        ``K``, the turn in grid steps (> 0).
    none
        The shortfall (grid steps) written for "no such move", the largest.

    Returns
    -------
    ``(B, A)`` int64: 0 for the move the greedy reading plays, 1, 2, ... for the next
    legal moves, then the illegal moves (each ``A``).
    """
    B, A, D = reach.shape
    R2 = int(np.size(rot_delta))
    illegal = ~np.asarray(legal, dtype=bool)
    s = np.rint(np.asarray(reach, dtype=np.float64) * turn_steps).astype(np.int64)
    size = np.zeros(A, dtype=np.int64)
    size[:R2] = np.abs(rot_delta)
    tie = np.empty(A, dtype=np.int64)  # the regrasps, then the rotations
    tie[np.concatenate((np.arange(R2, A), np.arange(R2)))] = np.arange(A)
    # np.lexsort sorts by its last key first: illegal moves last, then a finishing
    # rotation first, the deepest shortfall, ..., the shallowest, the size, the tie
    # (a lexicographic sort, not one packed integer key, which overflows int64 deeper
    # than 6 regrasps)
    keys = [np.broadcast_to(tie, (B, A)), np.broadcast_to(size, (B, A))]
    keys += [s[:, :, j].clip(0, int(none)) for j in range(D)]
    keys += [~np.asarray(finishing, dtype=bool), illegal]
    ranks = np.empty((B, A), dtype=np.int64)
    np.put_along_axis(ranks, np.lexsort(keys, axis=-1), np.arange(A)[None, :], axis=1)
    ranks[illegal] = A
    return ranks


def check_observation_mode(value: Any) -> str:
    """``value`` if it is one of :data:`OBSERVATION_MODES`, else raise naming it."""
    if not isinstance(value, str) or value not in OBSERVATION_MODES:
        raise GraspGaitInputError(
            f"observation_mode={value!r}: use 'box' (one vector, the default), 'dict' "
            "(named parts: grasp, actions, window, lines) or 'flat' (the dict flattened "
            "into one vector)")
    return value


class ObservationLayout:
    """Where each part of a flat GraspGait observation lives.

    Two flat vectors exist: the **box** vector (``observation_mode="box"``, the
    attributes below) and the **flattened dict** (``observation_mode="flat"``,
    :attr:`parts`). This class is the one place that knows either's offsets.

    Attributes
    ----------
    held, position, contact_cos_sin, theta_cos_sin, achieved, to_go, mask, window, lines,
    lookahead, reach
        Slices of the box vector (``achieved`` and ``to_go`` are indices); ``window``
        reshapes to ``(cells, cells)``, ``lines`` (``map_lines``; else empty) to ``(2,
        n)``; ``lookahead`` (``rotation_lookahead``; else empty) has one entry per
        rotation action, ``2 R``; ``reach`` (``regrasp_lookahead = D``; else empty)
        holds ``2 P x D`` entries (per regrasp action, row-major), then ``2 R x D`` (per
        rotation).
    box_parts
        The names of the box vector's parts above, in index order.
    size
        Length of the box vector.
    action_features
        Column names of the dict's ``actions`` part (:data:`ACTION_FEATURES`, then
        ``opens`` and ``reach_1 .. reach_D`` where those fields are on).
    parts
        ``{name: (slice, shape)}`` of the flattened dict, in its order (``grasp``,
        ``actions``, ``window``, then ``lines`` with ``map_lines``).
    flat_size
        Length of the flattened dict.
    HEADER
        (class attribute) Entries of the box vector before ``mask``: the grasp and
        turn state, whatever the window and the opt-in fields.
    """

    HEADER: int = _HEADER

    def __init__(self, n_actions: int, cells: int, line_cells: int = 0,
                 lookahead: int = 0, reach: int = 0) -> None:
        self.held = slice(_HELD, _HELD + 3)
        self.position = slice(_POS, _POS + 3)
        self.contact_cos_sin = slice(_PHI, _PHI + 6)
        self.theta_cos_sin = slice(_THETA, _THETA + 2)
        self.achieved = _ACHIEVED
        self.to_go = _TO_GO
        self.mask = slice(_HEADER, _HEADER + n_actions)
        self.window = slice(_HEADER + n_actions, _HEADER + n_actions + cells * cells)
        end = self.window.stop
        self.lines = slice(end, end + 2 * line_cells)  # empty unless map_lines
        end = self.lines.stop
        self.lookahead = slice(end, end + lookahead)  # empty unless rotation_lookahead
        end = self.lookahead.stop
        self.reach = slice(end, end + reach)  # empty unless regrasp_lookahead
        self.box_parts: tuple[str, ...] = (
            "held", "position", "contact_cos_sin", "theta_cos_sin", "achieved", "to_go",
            "mask", "window", "lines", "lookahead", "reach")
        self.cells = cells
        self.size = end + reach
        self.n_actions = n_actions
        depth = reach // n_actions if n_actions else 0
        self.reach_depth = depth
        self.action_features: tuple[str, ...] = (
            ACTION_FEATURES + (("opens",) if lookahead else ())
            + tuple(f"reach_{j + 1}" for j in range(depth))
            + (("reach_rank",) if depth else ()))
        shapes: list[tuple[str, tuple[int, ...]]] = [
            ("grasp", (_HEADER,)), ("actions", (n_actions, len(self.action_features))),
            ("window", (cells, cells))]
        if line_cells:
            shapes.append(("lines", (2, line_cells)))
        self.parts: dict[str, tuple[slice, tuple[int, ...]]] = {}
        at = 0
        for name, shape in shapes:
            size = int(np.prod(shape))
            self.parts[name] = (slice(at, at + size), shape)
            at += size
        self.flat_size = at

    def feature(self, name: str) -> int:
        """Column of the per-action feature ``name`` in the ``actions`` part."""
        try:
            return self.action_features.index(name)
        except ValueError:
            raise GraspGaitInputError(
                f"feature={name!r}: this observation's per-action features are "
                f"{list(self.action_features)}") from None

    def unflatten(self, flat: NDArray[np.floating]) -> dict[str, NDArray[np.floating]]:
        """The named parts of a flattened dict observation ``(..., flat_size)`` (views,
        each of shape ``(..., *part_shape)``)."""
        if flat.shape[-1] != self.flat_size:
            raise GraspGaitInputError(
                f"flat.shape={flat.shape}: the flattened dict has {self.flat_size} entries "
                "in its last axis (observation_mode='flat')")
        lead = flat.shape[:-1]
        return {name: flat[..., sl].reshape(*lead, *shape)
                for name, (sl, shape) in self.parts.items()}

    def flatten(self, parts: dict[str, NDArray[np.floating]], batch: bool = False
                ) -> NDArray[np.float32]:
        """The named parts (one observation, or a batch with ``batch=True``) as one flat
        vector (rows), in :attr:`parts` order: ``gymnasium.spaces.flatten`` of the dict."""
        lead = 1 if batch else 0
        return np.concatenate(
            [np.asarray(parts[name], dtype=np.float32).reshape(
                *np.shape(parts[name])[:lead], -1) for name in self.parts], axis=-1)


class ObservationParts:
    """The dict (and flattened dict) observation from the box vector, one state or many.

    Built once per env from its box layout and spaces; :meth:`observe` turns a batch of
    box vectors and the states that made them into the named parts. The one
    implementation for the single and the batched envs (the single env passes a batch of
    one).

    Parameters
    ----------
    layout
        The env's :class:`ObservationLayout`.
    box_space
        The box observation space (its bounds give the parts' bounds).
    ws_width
        ``W_f`` per finger (grid angles in each workspace).
    rot_delta
        Signed grid steps of the ``2 R`` rotation actions.
    sign, turn_steps
        The turn's sign ``σ`` and ``K = abs(turn)`` in grid steps.
    mode
        ``"dict"`` or ``"flat"``.
    """

    def __init__(self, layout: ObservationLayout, box_space: spaces.Box,
                 ws_width: NDArray[np.int64], rot_delta: NDArray[np.int64], sign: int,
                 turn_steps: int, mode: str) -> None:
        if mode not in ("dict", "flat"):
            raise ValueError(f"mode={mode!r}: 'dict' or 'flat' (the box mode needs no parts)")
        self.layout, self.mode = layout, mode
        self._W = np.asarray(ws_width, dtype=np.int64)
        self._d = np.asarray(rot_delta, dtype=np.int64)
        self._R2 = int(self._d.size)
        A = layout.n_actions
        self._P2 = A - self._R2
        self._sign, self._K = int(sign), int(turn_steps)
        lo, hi = box_space.low, box_space.high
        R = self._R2 // 2
        F = len(layout.action_features)
        a_lo = np.zeros((A, F), dtype=np.float32)
        a_hi = np.ones((A, F), dtype=np.float32)
        col = layout.feature
        a_lo[:, col("achieved")] = min(0.0, float(lo[_ACHIEVED]))
        a_hi[:, col("achieved")] = hi[_ACHIEVED]
        a_hi[:, col("room_on")] = a_hi[:, col("room_back")] = R / self._K
        if layout.reach_depth:
            a_hi[:, col("reach_1"):col("reach_rank")] = hi[layout.reach.start]
            # the look-ahead's "none", in grid steps (its bound, the largest entry)
            self._none = int(round(float(hi[layout.reach.start]) * self._K))
        self._rotation = np.zeros(A, dtype=np.float32)
        self._rotation[:self._R2] = 1.0
        bounds = {"grasp": (lo[:_HEADER], hi[:_HEADER]), "actions": (a_lo, a_hi),
                  "window": (lo[layout.window].reshape(layout.cells, layout.cells),
                             hi[layout.window].reshape(layout.cells, layout.cells))}
        if "lines" in layout.parts:
            shape = layout.parts["lines"][1]
            bounds["lines"] = (lo[layout.lines].reshape(shape), hi[layout.lines].reshape(shape))
        self.dict_space = spaces.Dict([
            (name, spaces.Box(b[0].astype(np.float32), b[1].astype(np.float32),
                              dtype=np.float32)) for name, b in bounds.items()])
        self.flat_space = spaces.flatten_space(self.dict_space)
        self.space = self.dict_space if mode == "dict" else self.flat_space
        # the regrasp rows' free-finger positions p (row 2p + l) and lifts l
        self._pos = np.repeat(np.arange(self._P2 // 2), 2)
        self._lift = np.tile(np.array([0, 1]), self._P2 // 2)

    def observe(self, box: NDArray[np.float32], k: NDArray[np.int64], f: NDArray[np.int64],
                g: NDArray[np.int64], h: NDArray[np.int64], p_f: NDArray[np.int64],
                p_g: NDArray[np.int64]) -> Any:
        """The observations of ``B`` states from their box vectors ``(B, size)``.

        ``k`` object angles (grid steps), ``f < g`` the held fingers at workspace
        positions ``p_f``, ``p_g``, ``h`` the free finger, each ``(B,)``. Returns fresh
        arrays: a dict of ``(B, *shape)`` parts (``"dict"``) or ``(B, flat_size)``
        (``"flat"``).
        """
        lay, B, R2, K, sig = self.layout, box.shape[0], self._R2, self._K, self._sign
        W = self._W
        legal = box[:, lay.mask]
        out = np.empty((B, lay.n_actions, len(lay.action_features)), dtype=np.float32)
        out[:, :, 0] = legal
        out[:, :, 1] = self._rotation
        on = legal  # 1 where legal, 0 where not: the three features below read 0 there
        # rotation room now (GaitModel.rotation_room, thesis 5.2): ccw, cw; after rotating
        # by d: ccw - d, cw + d
        ccw, cw = (x[:, None] for x in rotation_room_of(W, f, p_f, g, p_g))
        d = self._d
        # a regrasp (thesis 4.2): h to position p, lift l = 0 keeps g, l = 1 keeps f
        pos, lift = self._pos, self._lift
        keep_g = lift == 0
        kept = np.where(keep_g, g[:, None], f[:, None])
        p_kept = np.where(keep_g, p_g[:, None], p_f[:, None])
        g_ccw, g_cw = rotation_room_of(W, h[:, None], pos, kept, p_kept)
        r_on, r_back = (ccw - d, cw + d) if sig > 0 else (cw + d, ccw - d)
        g_on, g_back = (g_ccw, g_cw) if sig > 0 else (g_cw, g_ccw)
        out[:, :R2, 2] = sig * (k[:, None] + d) * on[:, :R2]
        out[:, R2:, 2] = sig * k[:, None] * on[:, R2:]
        out[:, :R2, 3] = r_on * on[:, :R2]
        out[:, R2:, 3] = g_on * on[:, R2:]
        out[:, :R2, 4] = r_back * on[:, :R2]
        out[:, R2:, 4] = g_back * on[:, R2:]
        out[:, :, 2:5] /= K  # grid steps over K, each rounded once (as the bounds)
        col = 5
        if lay.lookahead.stop > lay.lookahead.start:
            out[:, :R2, col] = box[:, lay.lookahead]
            out[:, R2:, col] = 0.0  # a regrasp opens nothing
            col += 1
        D = lay.reach_depth
        if D:
            reach = box[:, lay.reach]
            P2 = self._P2
            out[:, R2:, col:col + D] = reach[:, :P2 * D].reshape(B, P2, D)
            out[:, :R2, col:col + D] = reach[:, P2 * D:].reshape(B, R2, D)
            finishing = np.zeros((B, lay.n_actions), dtype=bool)  # the rotations' achieved
            finishing[:, :R2] = out[:, :R2, 2] * K >= K - 0.5  # (x K: grid steps)
            ranks = greedy_ranks(out[:, :, col:col + D], finishing, legal > 0.5, d, K,
                                 self._none)
            out[:, :, col + D] = np.minimum(ranks, lay.n_actions - 1) / np.float32(
                max(lay.n_actions - 1, 1))
        parts = {"grasp": box[:, :_HEADER].copy(), "actions": out,
                 "window": box[:, lay.window].reshape(B, lay.cells, lay.cells).copy()}
        if "lines" in lay.parts:
            parts["lines"] = box[:, lay.lines].reshape(B, *lay.parts["lines"][1]).copy()
        if self.mode == "dict":
            return parts
        return lay.flatten(parts, batch=True)
