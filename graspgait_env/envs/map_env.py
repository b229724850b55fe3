"""``GraspGait-v0``: grasp-gait discovery at map level (thesis ch. 4–6) as a Gymnasium env.

The environment is the discretized gait problem of :class:`graspgait_env.gait.GaitModel`
(states, moves, action layout and legal-move function) with an observation, a reward
made of named terms and episode ends. See :class:`GraspGaitEnv` for the documentation
page; :func:`state_from_observation` recovers the exact gait state from an observation.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.shapes import Shape
from graspgait_env.workspace import Hand

__all__ = [
    "GraspGaitEnv",
    "ObservationLayout",
    "REWARD_TERMS",
    "state_from_observation",
]

# Reward terms, in the fixed order in which the reward is summed.
REWARD_TERMS: tuple[str, ...] = ("turn", "regrasp", "rotation", "success", "dead_end", "illegal")

# Observation header (see the class docstring's table).
_HELD = 0  # 3 entries
_POS = 3  # 3 entries
_PHI = 6  # 6 entries: (cos, sin) per finger
_THETA = 12  # 2 entries: cos, sin
_ACHIEVED = 14
_TO_GO = 15
_HEADER = 16
_START_TRIES = 64  # random start draws before scanning all starts for one with a legal move


class ObservationLayout:
    """Where each part of the flat observation lives (slices into the vector).

    Attributes
    ----------
    held, position, contact_cos_sin, theta_cos_sin, achieved, to_go, mask, window
        Slices (``achieved`` and ``to_go`` are indices); ``window`` reshapes to
        ``(cells, cells)``.
    size
        Length of the observation vector.
    """

    def __init__(self, n_actions: int, cells: int) -> None:
        self.held = slice(_HELD, _HELD + 3)
        self.position = slice(_POS, _POS + 3)
        self.contact_cos_sin = slice(_PHI, _PHI + 6)
        self.theta_cos_sin = slice(_THETA, _THETA + 2)
        self.achieved = _ACHIEVED
        self.to_go = _TO_GO
        self.mask = slice(_HEADER, _HEADER + n_actions)
        self.window = slice(_HEADER + n_actions, _HEADER + n_actions + cells * cells)
        self.cells = cells
        self.size = _HEADER + n_actions + cells * cells


def _finite(name: str, v: Any, *, positive: bool = False, nonneg: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
        raise ValueError(f"{name}={v!r}: must be a number")
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"{name}={v!r}: must be finite")
    if positive and not v > 0:
        raise ValueError(f"{name}={v!r}: must be > 0")
    if nonneg and v < 0:
        raise ValueError(f"{name}={v!r}: must be >= 0 (it is subtracted as a penalty)")
    return v


def _pooled_map(stable: NDArray[np.bool_], s: int) -> NDArray[np.float32]:
    """``out[i, j]`` = fraction of stable cells in the ``s x s`` block at ``(i, j)`` (wrapping),
    tiled 2 x 2 like :meth:`GraspMap.extended` so windows are plain strided views."""
    n = stable.shape[0]
    x = stable.astype(np.float64)
    if s > 1:
        x = np.concatenate([x, x[: s - 1]], axis=0)
        x = np.concatenate([x, x[:, : s - 1]], axis=1)
    cs = np.zeros((x.shape[0] + 1, x.shape[1] + 1))
    cs[1:, 1:] = x.cumsum(axis=0).cumsum(axis=1)
    box = cs[s:s + n, s:s + n] - cs[:n, s:s + n] - cs[s:s + n, :n] + cs[:n, :n]
    out = np.tile((box / (s * s)).astype(np.float32), (2, 2))
    out.flags.writeable = False
    return out


def state_from_observation(obs: NDArray[np.floating], model: GaitModel,
                           turn_deg: float) -> GaitState:
    """The exact :class:`GaitState` that produced ``obs`` (a GraspGait observation).

    Uses the held one-hot, the workspace positions and the turn achieved, all of which
    encode integers exactly in float32. ``model`` and ``turn_deg`` must be the env's.
    """
    K = model.turn_steps(turn_deg)
    k = int(round(float(obs[_ACHIEVED]) * abs(K))) * (1 if K >= 0 else -1)
    cs = [-1, -1, -1]
    for f in range(3):
        if obs[_HELD + f] > 0.5:
            w = max(int(model.ws_width[f]) - 1, 1)
            p = int(round(float(obs[_POS + f]) * w))
            cs[f] = int((int(model.ws_start[f]) + p - k) % model.n)
    return GaitState(k, tuple(cs))


class GraspGaitEnv(gym.Env[NDArray[np.float32], np.int64]):
    r"""Reorient a planar object with a three-fingered hand through a grasp gait.

    ## Description

    The map-level grasp-gait problem of Leveroni's thesis (MIT 1997, ch. 4–6): a planar
    star-shaped object is held by two of three fingers in a force-closure grasp; the
    agent turns it by interleaving **rotations** (both contacts stay in their fingers'
    workspaces, thesis 5.2) with **regrasps** (the free finger is placed on a new
    contact, then one old finger lifts, thesis 4.2) until the object has turned
    ``turn_deg`` (default 360°, counter-clockwise). States, moves, the action layout and
    the legal-move function are exactly those of :class:`graspgait_env.gait.GaitModel`
    (``model`` attribute): contacts and object angles on a grid of ``360 / n`` degrees.

    ## Action Space

    ``Discrete(model.n_actions)`` (182 with the thesis hand at ``n = 180``), with
    ``R = max_f W_f - 1`` (``W_f`` grid angles in finger ``f``'s workspace):

    | Action            | Move                                                            |
    |-------------------|-----------------------------------------------------------------|
    | ``0 .. R-1``      | rotate counter-clockwise by ``a + 1`` grid steps                |
    | ``R .. 2R-1``     | rotate clockwise by ``a - R + 1`` grid steps                    |
    | ``2R + 2p + l``   | regrasp: free finger to workspace position ``p``; lift the held |
    |                   | finger with the lower (``l = 0``) or higher (``l = 1``) number  |

    Legal actions: :meth:`action_masks` (the sb3-contrib ``MaskablePPO`` protocol) and
    ``info["action_mask"]`` give exactly ``model.action_mask(state)`` (a bool array).
    **An illegal action** (a valid index that is not a legal move) leaves the state as it
    is and costs the ``illegal`` reward term; it never raises. An index outside the
    action space raises ``ValueError``.

    ## Observation Space

    A flat ``Box(float32)`` of length ``16 + n_actions + cells**2`` (1494 by default),
    every entry inside its bounds. Fingers ``f = 1, 2, 3``; ``T`` = ``turn_deg``;
    ``sigma = sign(T)``; ``B`` = ``max_backward_deg``; ``Δ = 360 / n``; ``θ`` the object
    angle (degrees, CCW).

    | Index         | Observation                                  | Min          | Max          |
    |---------------|----------------------------------------------|--------------|--------------|
    | 0, 1, 2       | finger ``f`` holds the object (1) or not (0) | 0            | 1            |
    | 3, 4, 5       | workspace position of finger ``f``'s contact | -1           | 1            |
    |               | ``p_f / (W_f - 1)``: 0 at the workspace's    |              |              |
    |               | first edge, 1 at its last; -1 when free      |              |              |
    | 6 .. 11       | ``cos φ_f, sin φ_f`` of finger ``f``'s       | -1           | 1            |
    |               | contact, object frame; 0, 0 when free        |              |              |
    | 12, 13        | ``cos θ, sin θ``                             | -1           | 1            |
    | 14            | turn achieved ``sigma θ / abs(T)``           | ``-(B+RΔ)    | ``1 + RΔ     |
    |               |                                              | / abs(T)``   | / abs(T)``   |
    | 15            | turn still to go                             | 0            | ``1 + (B+RΔ) |
    |               | ``max(0, abs(T) - sigma θ) / abs(T)``        |              | / abs(T)``   |
    | 16 .. 15+A    | legal-move mask (1: legal), ``A = n_actions``| 0            | 1            |
    | 16+A ..       | grasp-map window, ``C x C`` cells, row-major | 0            | 1            |
    | 15+A+C²       | (see below)                                  |              |              |

    With the defaults (``T = B = 360°``, ``R Δ = 90°``) the turn achieved lies in
    ``[-1.25, 1.25]`` and the turn to go in ``[0, 2.25]``.

    The **grasp-map window** shows the grasp map around the current grasp: cell
    ``(a, b)`` holds the fraction of force-closure grasps among the ``s x s`` grid pairs
    whose lower-numbered held finger's contact is offset by ``s (a - C/2)`` grid steps
    from its present one and the higher-numbered finger's by ``s (b - C/2)`` (``C =
    map_window_cells``, ``s`` the pooling stride, ``s C Δ ≈ map_window_deg``); the
    current grasp lies in cell ``(C//2, C//2)``. A rotation moves both contacts' workspace
    angles by the same amount, so these offsets are the same in the workspace frame
    ``F`` and the object frame: the window is the map as seen from the current grasp,
    the same for every object, which lets one policy work across objects. Regrasp
    targets reachable now are in the mask; the window shows what lies beyond.

    With the held fingers, positions and turn achieved the observation determines the
    state exactly: :func:`state_from_observation`.

    ## Rewards

    The thesis's path metric ``M = αθ - βη - γr`` (5.4: θ the object angle, η regrasps,
    r rotations) paid step by step, plus episode-end terms. Each step's terms are in
    ``info["reward_terms"]`` (a dict, always all six keys, in this order) and the reward
    is their sum, computed in this order (so ``reward == sum(terms.values())`` exactly):

    | Term        | Value                                                                     |
    |-------------|---------------------------------------------------------------------------|
    | ``turn``    | ``alpha * Δθ* / turn_scale_deg``: turn gained towards the goal (degrees), |
    |             | with θ* = ``min(sigma θ, abs(T))`` so overshoot earns nothing             |
    | ``regrasp`` | ``-beta`` for a regrasp                                                   |
    | ``rotation``| ``-gamma`` for a rotation                                                 |
    | ``success`` | ``+success_bonus`` on reaching the turn                                   |
    | ``dead_end``| ``-dead_end_penalty`` on a dead end or on passing the wrong-way limit     |
    | ``illegal`` | ``-illegal_penalty`` for an illegal action (no move)                      |

    With ``turn_scale_deg=1`` and ``alpha = beta = gamma = 1`` the first three terms sum
    over an episode to the thesis's ``M`` (the thesis found all equal to 1 satisfactory);
    the defaults scale the turn to 1 for the whole turn and keep β, γ small.

    ## Starting State

    θ = 0 and a grasp drawn uniformly by ``self.np_random`` from
    ``model.start_states()`` (every legal two-finger grasp at θ = 0) among those with at
    least one legal move. No check is made that a gait exists from it: on objects where
    none does (e.g. the triangle at mu = 0.7), episodes end in dead ends or at the time
    limit. ``reset(options={"start": {1: 50.0, 3: 270.0}})`` (finger number → contact in
    degrees, or a :class:`GaitState` at k = 0) starts from a given grasp.

    ## Episode End

    - **Success** (terminated, ``info["is_success"] = True``): the object has turned
      ``turn_deg`` (``sigma θ >= abs(T)``).
    - **Dead end** (terminated, ``is_success = False``): no legal move remains. (Every
      thesis move can be undone, so with ``GaitModel``'s moves this cannot follow a legal
      move; starts without a legal move are never drawn. The check stays for safety.)
    - **Wrong way** (terminated, ``is_success = False``): the object has turned more
      than ``max_backward_deg`` against the goal (bounds the observation; the gait graph
      repeats every 360°, so nothing is lost beyond one full turn back).
    - **Truncation**: only by ``gymnasium.make``'s ``TimeLimit`` (``max_episode_steps``
      of the registration, 500); ``step`` itself never truncates.

    ## Arguments

    ``gymnasium.make("graspgait_env:GraspGait-v0", object="ellipse", mu=0.7, hand=None,
    turn_deg=360.0, n=180, alpha=1.0, beta=0.01, gamma=0.01, turn_scale_deg=None,
    success_bonus=1.0, dead_end_penalty=1.0, illegal_penalty=0.1, max_backward_deg=360.0,
    map_window_deg=360.0, map_window_cells=36, render_mode=None)``

    - ``object``: bundled name (``"ellipse"``, the thesis's fig. 5.3 ellipse), YAML path
      or :class:`~graspgait_env.shapes.Shape`.
    - ``mu``: Coulomb friction; ``hand``: bundled hand name, YAML path or
      :class:`~graspgait_env.workspace.Hand` (default: thesis fig. 4.1).
    - ``turn_deg``: requested turn (sign = direction); ``n``: grid size.
    - ``alpha, beta, gamma, turn_scale_deg`` (default ``abs(turn_deg)``),
      ``success_bonus, dead_end_penalty, illegal_penalty``: reward weights (above).
    - ``max_backward_deg``: wrong-way limit (above).
    - ``map_window_deg, map_window_cells``: span and resolution of the grasp-map window.
    - ``render_mode``: ``"rgb_array"`` returns an ``(H, W, 3)`` uint8 frame: the object
      in the workspace frame with the three workspaces and the fingers, and the extended
      grasp map (finger pair boxes at the present θ) with the gait so far. ``"human"``
      shows the same frame in a matplotlib window when an interactive backend is
      available; headless (Agg backend, no display) it shows nothing and warns once.

    ## Version History

    - v0: initial version.
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 4}

    def __init__(
        self,
        object: str | Shape = "ellipse",  # noqa: A002 - the user-facing name (docs/cli.md OBJECT)
        mu: float = 0.7,
        hand: str | Hand | None = None,
        turn_deg: float = 360.0,
        n: int = 180,
        *,
        alpha: float = 1.0,
        beta: float = 0.01,
        gamma: float = 0.01,
        turn_scale_deg: float | None = None,
        success_bonus: float = 1.0,
        dead_end_penalty: float = 1.0,
        illegal_penalty: float = 0.1,
        max_backward_deg: float = 360.0,
        map_window_deg: float = 360.0,
        map_window_cells: int = 36,
        render_mode: str | None = None,
    ) -> None:
        self._configure(turn_deg=turn_deg, alpha=alpha, beta=beta, gamma=gamma,
                        turn_scale_deg=turn_scale_deg, success_bonus=success_bonus,
                        dead_end_penalty=dead_end_penalty, illegal_penalty=illegal_penalty,
                        max_backward_deg=max_backward_deg, map_window_deg=map_window_deg,
                        map_window_cells=map_window_cells, render_mode=render_mode)
        self._use_model(GaitModel(object, mu, hand, n))
        self._make_spaces()

    # ------------------------------------------------------------------ set-up
    def _configure(self, *, turn_deg, alpha, beta, gamma, turn_scale_deg, success_bonus,
                   dead_end_penalty, illegal_penalty, max_backward_deg, map_window_deg,
                   map_window_cells, render_mode) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode={render_mode!r}: use None, "
                             f"{' or '.join(map(repr, self.metadata['render_modes']))}")
        self.render_mode = render_mode
        self.turn_deg = _finite("turn_deg", turn_deg)
        if self.turn_deg == 0:
            raise ValueError("turn_deg=0: ask for a nonzero turn, e.g. 360 (CCW) or -360 (CW)")
        self.alpha = _finite("alpha", alpha)
        self.beta = _finite("beta", beta, nonneg=True)
        self.gamma = _finite("gamma", gamma, nonneg=True)
        self.turn_scale_deg = (abs(self.turn_deg) if turn_scale_deg is None
                               else _finite("turn_scale_deg", turn_scale_deg, positive=True))
        self.success_bonus = _finite("success_bonus", success_bonus)
        self.dead_end_penalty = _finite("dead_end_penalty", dead_end_penalty, nonneg=True)
        self.illegal_penalty = _finite("illegal_penalty", illegal_penalty, nonneg=True)
        self.max_backward_deg = _finite("max_backward_deg", max_backward_deg, positive=True)
        self.map_window_deg = _finite("map_window_deg", map_window_deg, positive=True)
        if self.map_window_deg > 360.0:
            raise ValueError(f"map_window_deg={map_window_deg!r}: at most 360 (the whole map)")
        if (isinstance(map_window_cells, bool) or not isinstance(map_window_cells, int)
                or map_window_cells < 1):
            raise ValueError(f"map_window_cells={map_window_cells!r}: must be an integer >= 1")
        self.map_window_cells = int(map_window_cells)
        self._fig = None
        self._human_warned = False
        self.model: GaitModel

    def _use_model(self, model: GaitModel) -> None:
        """Bind a gait model: precompute every per-model table that ``step`` reads."""
        self.model = model
        n = model.n
        self._n = n
        self._R = int(model.R)
        self._A = int(model.n_actions)
        self._S = [int(x) for x in model.ws_start]
        self._W = [int(x) for x in model.ws_width]
        self._inv_w = [1.0 / max(w - 1, 1) for w in self._W]
        self._step_deg = model.step_deg
        self._K = model.turn_steps(self.turn_deg)
        self._sign = 1 if self._K > 0 else -1
        self._Kabs = abs(self._K)
        if self._Kabs == 0:
            raise ValueError(f"turn_deg={self.turn_deg!r}: rounds to no grid step at n={n}")
        self._back = model.turn_steps(self.max_backward_deg)
        self._turn_coef = self.alpha * self._step_deg / self.turn_scale_deg
        phi = 2.0 * math.pi * np.arange(n) / n
        self._cos = np.cos(phi).tolist()
        self._sin = np.sin(phi).tolist()
        cells = self.map_window_cells
        span = max(1, round(self.map_window_deg / self._step_deg))
        s = max(1, span // cells)
        if s * cells > n:
            raise ValueError(
                f"map_window_cells={cells}: more cells than grid points in "
                f"map_window_deg={self.map_window_deg:g} at n={n}; use at most "
                f"{max(1, min(n, span))} cells")
        self._stride = s
        self._win_back = s * (cells // 2) + s // 2
        self._pooled = _pooled_map(model.stable, s)
        self._starts: list[GaitState] | None = None

    def _make_spaces(self) -> None:
        A, C = self._A, self.map_window_cells
        self.layout = ObservationLayout(A, C)
        lo = np.zeros(self.layout.size, dtype=np.float64)
        hi = np.ones(self.layout.size, dtype=np.float64)
        lo[_POS:_THETA + 2] = -1.0
        R, K, B = self._R, self._Kabs, self._back
        lo[_ACHIEVED], hi[_ACHIEVED] = -(B + R) / K, (K + R) / K
        lo[_TO_GO], hi[_TO_GO] = 0.0, (K + B + R) / K
        self.observation_space = spaces.Box(lo.astype(np.float32), hi.astype(np.float32),
                                            dtype=np.float32)
        self.action_space = spaces.Discrete(A)
        self._obs = np.zeros(self.layout.size, dtype=np.float32)
        self._win_view = self._obs[self.layout.window].reshape(C, C)
        self._mask_view = self._obs[self.layout.mask]

    def _check_model_fits(self, model: GaitModel) -> None:
        if int(model.n_actions) != self.action_space.n or model.n != self._n:
            raise ValueError(
                f"object {model.shape.name!r}: its gait model has {model.n_actions} actions "
                f"at n={model.n}, the env's spaces {self.action_space.n} at n={self._n}; "
                "keep n and the hand's workspaces fixed")

    # ------------------------------------------------------------------ state
    @property
    def state(self) -> GaitState:
        """The present gait state ``(k, contacts)`` (a fresh tuple)."""
        return GaitState(self._k, tuple(self._c))

    def action_masks(self) -> NDArray[np.bool_]:
        """Legal actions of the present state (sb3-contrib MaskablePPO protocol).

        Exactly ``self.model.action_mask(self.state)``. A fresh array per step; do not
        write into it.
        """
        return self._mask

    def _set_state(self, s: GaitState) -> None:
        self._k = int(s.k)
        self._c = [int(x) for x in s.contacts]
        held = [f for f in range(3) if self._c[f] >= 0]
        self._f, self._g = held
        self._h = 3 - held[0] - held[1]
        self._p = [-1, -1, -1]
        for f in held:
            self._p[f] = (self._c[f] + self._k - self._S[f]) % self._n

    def _compute_mask(self) -> NDArray[np.bool_]:
        """The legal moves of the present state: ``model.action_mask`` (THE legal-move
        function; a fresh array each call)."""
        return self.model.action_mask(GaitState(self._k, tuple(self._c)))

    # ------------------------------------------------------------------ observation
    def _write_grasp(self) -> None:
        """Observation entries that change only with the grasp (reset, regrasp)."""
        o, c = self._obs, self._c
        for f in range(3):
            if c[f] >= 0:
                o[_HELD + f] = 1.0
                o[_PHI + 2 * f] = self._cos[c[f]]
                o[_PHI + 2 * f + 1] = self._sin[c[f]]
            else:
                o[_HELD + f] = 0.0
                o[_POS + f] = -1.0
                o[_PHI + 2 * f] = 0.0
                o[_PHI + 2 * f + 1] = 0.0
        n, wb, s, L = self._n, self._win_back, self._stride, self._stride * self.map_window_cells
        i0 = (c[self._f] - wb) % n
        j0 = (c[self._g] - wb) % n
        self._win_view[...] = self._pooled[i0:i0 + L:s, j0:j0 + L:s]

    def _write_motion(self) -> None:
        """Observation entries that change with every move."""
        o, f, g = self._obs, self._f, self._g
        o[_POS + f] = self._p[f] * self._inv_w[f]
        o[_POS + g] = self._p[g] * self._inv_w[g]
        km = self._k % self._n
        o[_THETA] = self._cos[km]
        o[_THETA + 1] = self._sin[km]
        t = self._sign * self._k
        o[_ACHIEVED] = t / self._Kabs
        o[_TO_GO] = max(0, self._Kabs - t) / self._Kabs
        self._mask_view[...] = self._mask

    # ------------------------------------------------------------------ API
    def _on_reset(self, options: dict[str, Any]) -> GaitState | None:
        """Hook for subclasses: choose the model for the new episode (here: keep it).

        May return a start state already drawn for the new model (else ``None``).
        """
        return None

    def _draw_start(self) -> GaitState:
        if self._starts is None:
            self._starts = self.model.start_states()
        starts = self._starts
        if not starts:
            raise ValueError(
                f"object {self.model.shape.name!r} at mu={self.model.mu:g}: no legal grasp at "
                "theta = 0 with this hand; raise mu or change the hand")
        rng = self.np_random
        for _ in range(_START_TRIES):
            s = starts[int(rng.integers(len(starts)))]
            self._set_state(s)
            if self._compute_mask().any():
                return s
        off = int(rng.integers(len(starts)))
        for i in range(len(starts)):
            s = starts[(off + i) % len(starts)]
            self._set_state(s)
            if self._compute_mask().any():
                return s
        raise ValueError(
            f"object {self.model.shape.name!r} at mu={self.model.mu:g}: every legal start "
            f"grasp ({len(starts)}) is a dead end; raise mu or change the hand")

    def _parse_start(self, start: Any) -> GaitState:
        if isinstance(start, GaitState):
            s = GaitState(int(start.k), tuple(int(c) for c in start.contacts))
            if s.k != 0 or not self.model.is_legal_state(s):
                raise ValueError(f"options['start']={start!r}: must be a legal state at k = 0")
            return s
        if isinstance(start, dict):
            return self.model.start_state({int(f): float(v) for f, v in start.items()})
        raise ValueError(f"options['start']={start!r}: give {{finger: phi_deg}} for two "
                         "fingers, e.g. {1: 50.0, 3: 270.0}, or a GaitState at k = 0")

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[NDArray[np.float32], dict]:
        """Start an episode at θ = 0 (see *Starting State*); returns ``(obs, info)``."""
        super().reset(seed=seed)
        options = {} if options is None else options
        s = self._on_reset(options)
        start = options.get("start")
        if start is not None:
            s = self._parse_start(start)
        elif s is None:
            s = self._draw_start()
        self._set_state(s)
        self._mask = self._compute_mask()
        if not self._mask.any():
            raise ValueError(f"options['start']={start!r}: this grasp has no legal move")
        self._regrasps = 0
        self._rotations = 0
        self._terminal = False
        self._trail: list[tuple[int, tuple[int, ...]]] = [(self._k, tuple(self._c))]
        self._write_grasp()
        self._write_motion()
        info = {"action_mask": self._mask, "is_success": False, "turn_deg": 0.0,
                "regrasps": 0, "object": self.model.shape.name, "mu": self.model.mu}
        if self.render_mode == "human":
            self.render()
        return self._obs.copy(), info

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict]:
        """Apply one move; see the class docstring for rewards and episode ends."""
        a = int(action)
        if not 0 <= a < self._A:
            raise ValueError(f"action={action!r}: outside the action space 0..{self._A - 1}")
        k0 = self._k
        regrasp = rotation = success = dead_end = illegal = 0.0
        if self._mask[a]:
            R = self._R
            if a < 2 * R:
                d = a + 1 if a < R else R - 1 - a
                self._k = k0 + d
                self._p[self._f] += d
                self._p[self._g] += d
                rotation = -self.gamma
                self._rotations += 1
            else:
                pos, lift = divmod(a - 2 * R, 2)
                h = self._h
                f, g = self._f, self._g
                lifted, kept = (f, g) if lift == 0 else (g, f)
                self._c[h] = (self._S[h] + pos - k0) % self._n
                self._p[h] = pos
                self._c[lifted] = -1
                self._p[lifted] = -1
                self._f, self._g = (h, kept) if h < kept else (kept, h)
                self._h = lifted
                regrasp = -self.beta
                self._regrasps += 1
                self._write_grasp()
            self._mask = self._compute_mask()
            self._write_motion()
            if self.render_mode is not None:
                self._trail.append((self._k, tuple(self._c)))
        else:
            illegal = -self.illegal_penalty
            self._mask = self._mask.copy()  # every info gets its own array
        t1 = self._sign * self._k
        t0 = self._sign * k0
        K = self._Kabs
        turn = self._turn_coef * ((t1 if t1 < K else K) - (t0 if t0 < K else K))
        is_success = t1 >= K
        terminated = is_success or t1 < -self._back or not self._mask.any()
        if terminated and not self._terminal:
            if is_success:
                success = self.success_bonus
            else:
                dead_end = -self.dead_end_penalty
        self._terminal = terminated
        reward = turn + regrasp + rotation + success + dead_end + illegal
        info = {
            "action_mask": self._mask,
            "reward_terms": {"turn": turn, "regrasp": regrasp, "rotation": rotation,
                             "success": success, "dead_end": dead_end, "illegal": illegal},
            "is_success": is_success,
            "turn_deg": self._k * self._step_deg,
            "regrasps": self._regrasps,
        }
        if self.render_mode == "human":
            self.render()
        return self._obs.copy(), reward, terminated, False, info

    # ------------------------------------------------------------------ rendering
    def render(self) -> NDArray[np.uint8] | None:
        """``rgb_array``: the frame as ``(H, W, 3)`` uint8; ``human``: show it (or no-op)."""
        if self.render_mode is None:
            gym.logger.warn(
                "You are calling render method without specifying any render mode. "
                "Set render_mode='rgb_array' or 'human' at construction, e.g. "
                'gymnasium.make("graspgait_env:GraspGait-v0", render_mode="rgb_array")')
            return None
        from graspgait_env.envs import render

        if self.render_mode == "rgb_array":
            return render.render_frame(self)
        if render.can_show(self):
            render.show_human(self, render.render_frame(self))
        return None

    def close(self) -> None:
        """Close the human-mode window, if any (idempotent)."""
        fig, self._fig = self._fig, None
        if fig is not None:
            try:
                import matplotlib.pyplot as plt

                plt.close(fig)
            except Exception:  # noqa: BLE001 - closing must never fail
                pass

    def __getstate__(self) -> dict[str, Any]:
        d = self.__dict__.copy()
        d["_fig"] = None  # a matplotlib window is not picklable; reopened on demand
        d.pop("_fig_img", None)
        d.pop("_fig_im", None)
        d.pop("_win_view", None)
        d.pop("_mask_view", None)
        return d

    def __setstate__(self, d: dict[str, Any]) -> None:
        self.__dict__.update(d)
        C = self.map_window_cells
        self._win_view = self._obs[self.layout.window].reshape(C, C)
        self._mask_view = self._obs[self.layout.mask]
