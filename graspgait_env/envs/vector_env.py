"""``GraspGait-v0`` batched: N map-level gait problems stepped in one NumPy call.

``gymnasium.make_vec("graspgait_env:GraspGait-v0", num_envs=N,
vectorization_mode="vector_entry_point")`` makes a :class:`GraspGaitVectorEnv`. Its
transitions are those of ``N`` single ``gymnasium.make("graspgait_env:GraspGait-v0")``
envs under Gymnasium's ``SyncVectorEnv`` (next-step autoreset), bit for bit: the same
observations, rewards, ``terminated``/``truncated`` (the 500-step time limit included)
and infos, for the same seeds. See the class docstring.

``gymnasium.make_vec("graspgait_env:GraspGaitRandom-v0", ...)`` makes a
:class:`GraspGaitRandomVectorEnv`: the same step, each sub-env with its own objects and
mu (each row reads its own grasp map), equal to ``SyncVectorEnv`` over
``GraspGaitRandom-v0`` in the same way.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping, Sequence
from dataclasses import MISSING, fields
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from graspgait_env.envs.config import GraspGaitConfig, check_count
from graspgait_env.envs.map_env import (
    REWARD_TERMS,
    GraspGaitEnv,
    ResetNeededError,
    Visits,
    draw_start_index,
    drop_revisits,
    new_visits,
    visit_state,
)
from graspgait_env.envs.observation import _HEADER, _HELD, _PHI, _POS, _THETA, _TO_GO
from graspgait_env.envs.registration import MAX_EPISODE_STEPS
from graspgait_env.envs.rows import (
    drop_reversals,
    grasp_map_runs,
    regrasps_gained,
    regrasps_opened,
    reward_terms,
    window_at,
    write_lines,
)
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.shapes import Shape

__all__ = ["GraspGaitRandomVectorEnv", "GraspGaitVectorEnv", "SUPPORTED_FIELDS",
           "sample_legal_actions", "unsupported_fields"]

# The config fields whose every value the batched step implements. A field added to
# GraspGaitConfig later is accepted at its default (opt-in fields change nothing there)
# and refused otherwise, naming the field (see GraspGaitVectorEnv.__init__).
RUNS_TABLE_MAX = 1 << 24  # (bools) the contiguous regrasp-run table; n = 180 needs 1.5 M

SUPPORTED_FIELDS: frozenset[str] = frozenset({
    "hand", "turn_deg", "n", "alpha", "beta", "gamma", "turn_scale_deg", "success_bonus",
    "dead_end_penalty", "illegal_penalty", "to_go_weight", "max_backward_deg",
    "map_window_deg", "map_window_cells", "map_lines", "contact_model", "rotation_lookahead",
    "regrasp_lookahead", "forbid_reversal", "forbid_revisit", "observation_mode",
})


class GraspGaitVectorEnv(gym.vector.VectorEnv):
    r"""``num_envs`` copies of ``GraspGait-v0`` stepped together, as arrays.

    ## Description

    The map-level grasp-gait problem of :class:`~graspgait_env.envs.map_env.GraspGaitEnv`
    (Leveroni, thesis ch. 4–6: rotations, thesis 5.2, and regrasps, thesis 4.2, until the
    object has turned ``turn_deg``), for ``N`` independent episodes at once. One
    :meth:`step` applies ``N`` moves, computes ``N`` legal-move masks (the rule of
    :meth:`GaitModel.action_mask <graspgait_env.gait.GaitModel.action_mask>`, batched),
    ``N`` observations and ``N`` rewards (the thesis path metric of 5.4 plus the
    episode-end terms) with a fixed number of NumPy calls, whatever ``N``.

    **Same transitions as N single envs.** With the same seeds, every array returned
    equals what ``gymnasium.vector.SyncVectorEnv`` over ``N`` ``gymnasium.make(
    "graspgait_env:GraspGait-v0", ...)`` envs returns (observations, rewards,
    ``terminated``, ``truncated`` and every info key, with its ``_key`` mask); a test
    compares them over random masked rollouts across autoresets. Each sub-env keeps its
    own random generator: ``reset(seed=s)`` seeds sub-env ``i`` with ``s + i`` (a list
    gives one seed each), and a sub-env restarted by autoreset draws its start grasp from
    its own generator, as a single env does.

    ## Action Space

    ``MultiDiscrete([A] * N)``: one action per sub-env, as for ``GraspGait-v0``
    (``single_action_space = Discrete(A)``, 182 with the thesis hand at ``n = 180``). An
    illegal action leaves that sub-env's state unchanged and costs the ``illegal`` term.
    ``actions`` must be an integer array (or sequence) of shape ``(N,)`` with every entry
    in ``0 .. A-1`` (actions of sub-envs that autoreset at this step are checked too,
    then ignored); anything else raises ``ValueError``
    (:class:`~graspgait_env.errors.GraspGaitInputError`) naming it.

    ## Observation Space

    ``(N, 16 + A + C**2)`` float32: row ``i`` is sub-env ``i``'s ``GraspGait-v0``
    observation (same layout, :class:`~graspgait_env.envs.map_env.ObservationLayout`).
    A fresh array at every call (``copy=False`` returns the env's own buffer instead,
    overwritten by the next call).

    ## Rewards

    Row by row those of ``GraspGait-v0`` (``alpha Δθ* / turn_scale_deg - beta [regrasp]
    - gamma [rotation]`` plus ``success``, ``dead_end`` and ``illegal`` terms), summed in
    the same order, so they are equal to the last bit; ``info["reward_terms"]`` holds
    the six terms as arrays.

    ## Starting State

    Each sub-env draws its start with the single env's own code
    (:meth:`GraspGaitEnv.reset <graspgait_env.envs.map_env.GraspGaitEnv.reset>`, on a
    light copy of one template env per sub-env sharing its model and tables), so the
    ``"start"`` option works as there and applies to every sub-env. ``reset(options=
    {"reset_mask": m})`` (a bool array of shape ``(N,)``) resets only the sub-envs where
    ``m`` is True, as ``SyncVectorEnv`` does.

    ## Episode End

    As ``GraspGait-v0`` (success, dead end, wrong way: ``terminated``), plus
    ``truncated`` after ``max_episode_steps`` steps of an episode (500, the registered
    time limit that ``gymnasium.make`` applies to the single env; None: no limit).
    **Autoreset** is Gymnasium's next-step mode (``metadata["autoreset_mode"] =
    AutoresetMode.NEXT_STEP``): the step after a sub-env's episode ends resets it, returns
    its first observation with reward 0, ``terminated = truncated = False`` and its reset
    info (``object``, ``mu`` keys, masked to the sub-envs that reset), and ignores its
    action.

    ## Infos

    ``action_mask`` ``(N, A)`` bool (a fresh array each step; :meth:`action_masks`
    returns the same), ``reward_terms`` (a dict of six ``(N,)`` float arrays),
    ``is_success`` (bool), ``turn_deg`` (float), ``regrasps`` (int), each with its
    ``_key`` mask, as ``SyncVectorEnv`` batches them.

    ## Arguments

    ``gymnasium.make_vec("graspgait_env:GraspGait-v0", num_envs=N,
    vectorization_mode="vector_entry_point", object="ellipse", mu=0.7, config=None,
    max_episode_steps=500, copy=True, **fields)``: the arguments of ``GraspGait-v0``
    (``fields`` of :class:`~graspgait_env.envs.config.GraspGaitConfig`), checked with
    the same messages, plus

    - ``num_envs``: number of sub-envs (an integer >= 1).
    - ``max_episode_steps``: the time limit (steps per episode; None: none).
    - ``copy``: return fresh observation arrays (default) or the env's buffer.

    Every field of today's config is implemented, each by one function of
    :mod:`graspgait_env.envs.rows` that the single env calls with its one row and this
    env with its ``N`` (the table there): the reward weights, ``map_lines``,
    ``rotation_lookahead``, ``regrasp_lookahead``, ``forbid_reversal`` and the rest.
    ``to_go_weight`` looks up the optimum's regrasps to go of each sub-env that
    regrasps, one at a time, and ``forbid_revisit`` keeps each sub-env's visited states
    in a Python set and checks them row by row, so these two opt-in fields slow the
    batched step. A field added to the config later (:data:`SUPPORTED_FIELDS` does not
    list it) is
    accepted at its default and raises ``ValueError`` naming it otherwise.
    ``render_mode`` must be None: the batched env draws nothing (make a single env with
    ``render_mode="rgb_array"`` to watch one episode).

    ## Version History

    - v0: initial version; ``regrasp_lookahead`` batched since graspgait_env 0.2 (before,
      refused away from its default).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": [],
                                          "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        object: str | os.PathLike | Shape = "ellipse",  # noqa: A002 - the user-facing name
        mu: float = 0.7,
        *,
        config: GraspGaitConfig | None = None,
        max_episode_steps: int | None = MAX_EPISODE_STEPS,
        render_mode: str | None = None,
        copy: bool = True,
        **fields_: Any,
    ) -> None:
        # The template: one single env checks the arguments (same messages) and holds
        # the per-model tables that the batched step reads (one definition of each).
        self._setup(GraspGaitEnv(object, mu, config=config, **fields_), num_envs,
                    max_episode_steps, render_mode, copy)

    # every sub-env plays the template's object (GraspGaitRandomVectorEnv: its own)
    _per_row_objects: ClassVar[bool] = False

    def _setup(self, env: GraspGaitEnv, num_envs: int, max_episode_steps: int | None,
               render_mode: str | None, copy: bool) -> None:
        """Everything but the template's construction: checks, spaces, tables, state."""
        N = check_count("num_envs", num_envs, 1, 16)
        if max_episode_steps is not None:
            max_episode_steps = check_count("max_episode_steps", max_episode_steps, 1,
                                            MAX_EPISODE_STEPS)
        if render_mode is not None:
            raise GraspGaitInputError(
                f"render_mode={render_mode!r}: the batched GraspGait env draws nothing; give "
                "None, or watch one episode with gymnasium.make(\"graspgait_env:GraspGait-v0\", "
                "render_mode=\"rgb_array\")")
        if not isinstance(copy, (bool, np.bool_)):
            raise GraspGaitInputError(f"copy={copy!r}: must be True or False")
        _check_supported(env.config)
        self.template = env
        self.config = env.config
        self.model = env.model
        self.layout = env.layout
        self._parts = env._parts  # observation_mode "dict" / "flat" (None: "box")
        self.num_envs = N
        self.max_episode_steps = max_episode_steps
        self.render_mode = None
        self.copy = bool(copy)
        self.single_observation_space = env.observation_space
        self.single_action_space = env.action_space
        self.observation_space = batch_space(env.observation_space, N)
        self.action_space = batch_space(env.action_space, N)

        # per-sub-env reset: light copies of the template (shared model and tables, own
        # random generator), so starts are drawn by the single env's own code
        if not self._per_row_objects:
            starts = env.model.start_states()
            env._starts = starts
            # for autoresets in step (_autoreset_subs): each start's contacts and whether
            # it has a legal move (the single env's _draw_start redraws those without one)
            self._start_contacts = np.array([s.contacts for s in starts],
                                            dtype=np.int64).reshape(-1, 3)
            self._start_ok = [bool(env.model.action_mask(s).any()) for s in starts]
        self._subs: list[GraspGaitEnv] = []
        for _ in range(N):
            sub = _copy_env(env)
            self._subs.append(sub)

        m = env.model
        self._A = A = int(m.n_actions)
        self._R = int(m.R)
        self._P = int(m.P)
        self._n = int(m.n)
        self._ws_start = np.asarray(m.ws_start, dtype=np.int64)
        self._ws_width = np.asarray(m.ws_width, dtype=np.int64)
        self._runs = grasp_map_runs(m, self._P)  # the mask's regrasp rule, batched
        # the same runs for c, i < n as one contiguous (n n, P) table, where it is small:
        # a row gather from it (np.take) is several times faster than from the view
        n2P = self._n * self._n * self._P
        self._runs_table = (np.ascontiguousarray(self._runs[:self._n, :self._n]).reshape(
            self._n * self._n, self._P) if n2P <= RUNS_TABLE_MAX else None)
        self._valid = np.arange(self._P) < self._ws_width[:, None]  # (3, P): inside W_h
        self._rotation_tables(m)
        # a regrasp with free finger h and lift l (thesis 4.2, GaitModel.decode): row 2h + l
        # gives the finger lifted (the lower held one for l = 0) and the new held pair f < g
        lifted, new_f, new_g = [], [], []
        for h in range(3):
            held = [x for x in range(3) if x != h]
            for lift in (0, 1):
                kept = held[1 - lift]
                lifted.append(held[lift])
                new_f.append(min(h, kept))
                new_g.append(max(h, kept))
        self._regrasp_lifted, self._regrasp_f, self._regrasp_g = (
            np.array(x, dtype=np.int64) for x in (lifted, new_f, new_g))
        self._arN = np.arange(N)
        self._row3 = 3 * self._arN  # flat offsets of rows in (N, 3) arrays
        self._rowA = A * self._arN  # ... and in (N, A) arrays
        self._delta = np.asarray(env._delta, dtype=np.int64)  # rotation delta per action
        # (cos, sin) of grid angle i at row i (the object angle theta = k mod n), and of
        # contact c at row c + 1 of _phi_cs, whose row 0 (a free finger, c = -1) is 0, 0
        self._theta_cs = np.column_stack([env._cos, env._sin]).astype(np.float64)
        self._phi_cs = np.vstack([np.zeros(2), self._theta_cs])
        self._all = np.ones(N, dtype=bool)  # the "_key" mask of keys every sub-env has
        self._all.flags.writeable = False
        self._inv_w = np.asarray(env._inv_w, dtype=np.float64)
        self._sign, self._Kabs, self._back = env._sign, env._Kabs, env._back
        self._turn_coef = env._turn_coef
        self._step_deg = env._step_deg
        kt = env._kt  # turn_deg, max_backward_deg: the template's k tables (rows.k_tables)
        self._k_lo, self._k_head, self._k_reached = kt.lo, kt.head, kt.reached
        self._k_success, self._k_ends = kt.success, kt.ends
        self._win_back = env._win_back
        self._windows = env._windows  # rows.window_views of the template's map
        self._lines = env._lines  # map_lines: rows.line_views (None without)
        # to_go_weight: the exact optimum's regrasps to go (the single env's table; looked
        # up one regrasp at a time, so this opt-in reward costs speed)
        self._to_go = env._to_go
        self._togo_now = np.full(N, -1, dtype=np.int64)
        # rotation_lookahead: the single env's table of the regrasps each rotation opens
        self._openings = env._openings
        self._rot_delta = env._rot_delta
        # regrasp_lookahead: the single env's reach tables, read for the whole batch by
        # the one implementation both envs call (RegraspReach.move_shortfalls_batch)
        self._reach = env._reach

        # batched state: object angle k, contacts c (-1: free), workspace positions p
        # (-1: free), held fingers f < g and free finger h, mask, counters
        self._k = np.zeros(N, dtype=np.int64)
        self._c = np.full((N, 3), -1, dtype=np.int64)
        self._p = np.full((N, 3), -1, dtype=np.int64)
        self._f = np.zeros(N, dtype=np.int64)
        self._g = np.ones(N, dtype=np.int64)
        self._h = np.full(N, 2, dtype=np.int64)
        self._mask = np.zeros((N, A), dtype=bool)
        self._regrasps = np.zeros(N, dtype=np.int64)
        # forbid_reversal: sign of each sub-env's last move if a rotation, else 0
        self._forbid_reversal = bool(self.config.forbid_reversal)
        self._last_turn = np.zeros(N, dtype=np.int64)
        # forbid_revisit: per sub-env, the states visited this episode (map_env.Visits)
        self._visited: list[Visits] | None = (
            [new_visits(0, ()) for _ in range(N)] if self.config.forbid_revisit else None)
        self._elapsed = np.zeros(N, dtype=np.int64)
        self._autoreset = np.zeros(N, dtype=bool)
        self._obs = np.zeros((N, self.layout.size), dtype=np.float32)
        # the observation's header (held, positions, contacts, theta, turn), built here
        # column by column and written into the observation rows in one assignment
        self._head = np.zeros((N, _HEADER), dtype=np.float32)
        self._started = False
        if self._per_row_objects:
            # each sub-env's own object: its model's tables per row, refreshed whenever
            # its reset draws a new object (_refresh_rows); the hand, grid and turn, so
            # the action space and every table above, are the same for every object
            self._row_model: list[Any] = [None] * N
            self._row_runs = np.zeros((N, self._n * self._n, self._P), dtype=bool)
            self._row_base = self._arN * (self._n * self._n)
            self._row_windows: list[Any] = [None] * N
            self._row_lines: list[Any] = [None] * N

    def _rotation_tables(self, model: Any) -> None:
        """The rotation block of the mask (its first ``2R`` entries) from a table.

        ``GaitModel.rotation_room`` (thesis 5.2, the one definition) gives the room
        ``(ccw, cw)`` of fingers ``f < g`` at workspace positions ``(p_f, p_g)``;
        ``_rot_index[f, g, p_f, p_g] = ccw (R + 1) + cw`` and row ``ccw (R + 1) + cw`` of
        ``_rot_rows`` sets the first ``ccw`` counter-clockwise and ``cw`` clockwise
        entries.
        """
        R, P = self._R, self._P
        ar = np.arange(R)
        room = np.arange(R + 1)
        ccw, cw = np.meshgrid(room, room, indexing="ij")
        self._rot_rows = np.concatenate([ar < ccw.reshape(-1, 1), ar < cw.reshape(-1, 1)],
                                        axis=1)
        self._rot_index = np.zeros((3, 3, P, P), dtype=np.int64)
        pf, pg = np.meshgrid(np.arange(P), np.arange(P), indexing="ij")
        for f, g in ((0, 1), (0, 2), (1, 2)):
            inside = (pf < self._ws_width[f]) & (pg < self._ws_width[g])
            a, b = model.rotation_room(f, np.where(inside, pf, 0), g, np.where(inside, pg, 0))
            self._rot_index[f, g] = np.where(inside, a * (R + 1) + b, 0)

    # ------------------------------------------------------------------ state
    def action_masks(self) -> NDArray[np.bool_]:
        """Legal actions of every sub-env, ``(N, A)`` bool (sb3-contrib MaskablePPO
        protocol); row ``i`` is ``model.action_mask`` of sub-env ``i``'s state. A fresh
        array.

        Raises
        ------
        ResetNeededError
            Before the first ``reset()``.
        """
        self._need_reset("action_masks")
        return self._mask.copy()

    def states(self) -> list[Any]:
        """Each sub-env's :class:`~graspgait_env.gait.GaitState` ``(k, contacts)``."""
        from graspgait_env.gait import GaitState

        self._need_reset("states")
        return [GaitState(int(k), tuple(int(x) for x in c))
                for k, c in zip(self._k, self._c, strict=True)]

    def _need_reset(self, what: str) -> None:
        if not self._started:
            raise ResetNeededError(f"{what}: call reset() first (no episode has started, "
                                   "or the last reset() raised)")

    # ------------------------------------------------------------------ reset
    def _reset_subs(self, idx: Sequence[int], seeds: Sequence[int | None],
                    options: Mapping[str, Any] | None, infos: dict[str, Any]) -> None:
        """Reset sub-envs ``idx`` with the single env's ``reset`` and load their states."""
        for i, seed in zip(idx, seeds, strict=True):
            sub = self._subs[i]
            _, info = sub.reset(seed=seed, options=options)
            s = sub.state
            self._obs[i] = sub._obs  # the box vector (any observation_mode)
            self._head[i] = sub._obs[:_HEADER]
            self._mask[i] = info["action_mask"]
            self._k[i] = s.k
            self._c[i] = s.contacts
            infos = self._add_info(infos, info, i)
        if self._per_row_objects:
            self._refresh_rows(idx)
        self._load_starts(np.asarray(idx, dtype=np.int64))

    def _refresh_rows(self, idx: Sequence[int]) -> None:
        """Per-row tables of sub-envs ``idx`` whose reset drew a new object: the runs of
        its grasp map (the mask's regrasp rule), its map-window views and map lines."""
        n, P = self._n, self._P
        for i in idx:
            sub = self._subs[i]
            if sub.model is self._row_model[i]:
                continue
            self._row_model[i] = sub.model
            self._row_runs[i] = grasp_map_runs(sub.model, P)[:n, :n].reshape(n * n, P)
            self._row_windows[i] = sub._windows
            self._row_lines[i] = sub._lines

    def _model_of(self, i: int) -> Any:
        """The gait model of sub-env ``i``."""
        return self._subs[i].model if self._per_row_objects else self.model

    def _load_starts(self, idx: NDArray[np.int64]) -> None:
        """Batched state of sub-envs ``idx`` whose contacts ``_c`` were just set to a
        start grasp: fingers, workspace positions and counters (``k`` is 0)."""
        c = self._c[idx]
        h = np.argmin(c, axis=1)  # the free finger: the one contact that is -1
        self._h[idx] = h
        self._f[idx] = (h == 0).astype(np.int64)  # held fingers, ascending
        self._g[idx] = np.where(h == 2, 1, 2)
        # workspace positions (GaitModel.position): p = (c + k - ws_start) mod n
        p = (c + self._k[idx, None] - self._ws_start) % self._n
        self._p[idx] = np.where(c >= 0, p, -1)
        self._regrasps[idx] = 0
        self._last_turn[idx] = 0
        if self._visited is not None:
            for i in idx.tolist():
                self._visited[i] = new_visits(int(self._k[i]), tuple(self._c[i].tolist()))
        if self._to_go is not None:
            from graspgait_env.gait import GaitState

            for i in idx.tolist():
                to_go = self._subs[i]._to_go if self._per_row_objects else self._to_go
                self._togo_now[i] = to_go(GaitState(int(self._k[i]), tuple(self._c[i].tolist())))
        self._elapsed[idx] = 0
        self._autoreset[idx] = False

    def _autoreset_subs(self, idx: NDArray[np.int64], infos: dict[str, Any]) -> None:
        """Restart sub-envs ``idx`` (their episode ended at the last step) in batch.

        Each draws its start grasp from its own generator with the single env's draw
        (:func:`~graspgait_env.envs.map_env.draw_start_index`, from a table of which
        starts have a legal move), so the start, and every later draw, is the single
        env's; the rest of the single env's
        ``reset`` (its observation, mask and info) is done for the whole batch by
        :meth:`step`. The reset infos that the step does not overwrite, ``object`` and
        ``mu``, are batched as ``SyncVectorEnv`` batches them (``_add_info``).
        """
        if self._per_row_objects:  # each its own object: the single env's whole reset
            idx_list = idx.tolist()
            self._reset_subs(idx_list, [None] * len(idx_list), None, infos)
            return
        has_move = self._start_ok.__getitem__
        L = len(self._start_ok)
        # never None: the first reset found a start with a legal move
        picks = [draw_start_index(self._subs[i].np_random, L, has_move) for i in idx.tolist()]
        self._k[idx] = 0
        self._c[idx] = self._start_contacts[picks]
        self._load_starts(idx)
        on = np.zeros(self.num_envs, dtype=bool)
        on[idx] = True
        name = np.full(self.num_envs, None, dtype=object)
        name[idx] = self.model.shape.name
        mu = np.zeros(self.num_envs, dtype=float)
        mu[idx] = self.model.mu
        infos["object"], infos["_object"] = name, on
        infos["mu"], infos["_mu"] = mu, on.copy()

    def reset(self, *, seed: int | Sequence[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[NDArray[np.float32], dict]:
        """Reset every sub-env (or those of ``options["reset_mask"]``).

        Parameters
        ----------
        seed
            None (fresh entropy for sub-envs without a generator), an integer ``s``
            (sub-env ``i`` gets ``s + i``) or a list of ``N`` seeds (None entries allowed).
        options
            ``{"start": ...}`` as for ``GraspGait-v0`` (every sub-env) and/or
            ``{"reset_mask": m}``, a bool array of shape ``(N,)``.

        Returns
        -------
        obs, info
            ``(N, obs_size)`` float32 and the batched reset infos.
        """
        N = self.num_envs
        if seed is None:
            seeds: list[int | None] = [None] * N
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)):
            seeds = [int(seed) + i for i in range(N)]
        elif isinstance(seed, Sequence) and not isinstance(seed, str) and len(seed) == N:
            seeds = list(seed)
        else:
            raise GraspGaitInputError(
                f"seed={seed!r}: give None, an integer >= 0 (sub-env i gets seed + i) or a "
                f"list of {N} seeds")
        opts = dict(options) if options is not None else None
        if opts is not None and "reset_mask" in opts:
            m = opts.pop("reset_mask")
            if not (isinstance(m, np.ndarray) and m.dtype == np.bool_ and m.shape == (N,)
                    and m.any()):
                raise GraspGaitInputError(
                    f"options['reset_mask']={m!r}: must be a NumPy bool array of shape "
                    f"({N},) with at least one True")
            idx = np.flatnonzero(m).tolist()
        else:
            idx = list(range(N))
            self._started = False  # until every sub-env has reset
        infos: dict[str, Any] = {}
        self._reset_subs(idx, [seeds[i] for i in idx], opts or None, infos)
        self._started = True
        return self._observation(), infos

    def _observation(self) -> NDArray[np.float32]:
        """The batch's observation: header, mask and (kept in ``_obs``) windows and lines.

        The header and mask are written into ``_obs``; with ``copy`` a copy of it is
        returned (one contiguous copy), without, ``_obs`` itself.
        """
        o = self._obs
        o[:, :_HEADER] = self._head
        o[:, self.layout.mask] = self._mask
        if self._parts is not None:  # observation_mode "dict" / "flat": fresh arrays
            arN, f, g, p = self._arN, self._f, self._g, self._p
            return self._parts.observe(o, self._k, f, g, self._h, p[arN, f], p[arN, g])
        # one contiguous copy is cheaper than assembling a fresh array part by part
        return o.copy() if self.copy else o

    # ------------------------------------------------------------------ step
    def _check_actions(self, actions: Any) -> NDArray[np.int64]:
        a = np.asarray(actions)
        N, A = self.num_envs, self._A
        if a.shape != (N,) or a.dtype.kind not in "iu":
            raise GraspGaitInputError(
                f"actions={actions!r}: must be an integer array of shape ({N},), one action "
                f"index in 0..{A - 1} per sub-env, e.g. env.action_space.sample("
                "mask=tuple(env.action_masks()))" if a.shape != (N,) or a.dtype.kind != "b"
                else f"actions={actions!r}: bools are not action indices; give an integer "
                f"array of shape ({N},)")
        if a.dtype != np.int64:
            a = a.astype(np.int64)
        if N and (a.view(np.uint64) >= A).any():  # negatives wrap to huge values
            i = int(np.flatnonzero((a < 0) | (a >= A))[0])
            raise GraspGaitInputError(
                f"actions[{i}]={int(a[i])}: outside the action space 0..{A - 1}")
        return a

    def _compute_masks(self) -> None:
        """``model.action_mask`` of every sub-env's state, in one batch (thesis 5.2).

        Rotations: the room left on the tighter side each way, ``ccw = min(W_f - 1 - p_f,
        W_g - 1 - p_g)``, ``cw = min(p_f, p_g)`` (``GaitModel.rotation_room``). Regrasps
        (thesis 4.2): the free finger ``h`` at every position of its workspace, object
        contact ``(s_h + p - k) mod n``, against the kept contact, read from the
        transposed extended grasp map; the two lifts interleaved (lower finger first).
        """
        R, n, row3 = self._R, self._n, self._row3
        f, g, h = self._f, self._g, self._h
        p, c = self._p.ravel(), self._c.ravel()
        mask = self._mask
        room = self._rot_index[f, g, p.take(row3 + f), p.take(row3 + g)]
        mask[:, :2 * R] = self._rot_rows.take(room, axis=0)
        i0 = (self._ws_start.take(h) - self._k) % n
        valid, b = self._valid.take(h, axis=0), 2 * R
        cg, cf = c.take(row3 + g), c.take(row3 + f)
        if self._per_row_objects:  # each row its own grasp map
            flat = self._row_runs.reshape(-1, self._P)
            run_g = flat.take(self._row_base + cg * n + i0, axis=0)
            run_f = flat.take(self._row_base + cf * n + i0, axis=0)
        elif self._runs_table is not None:
            run_g = self._runs_table.take(cg * n + i0, axis=0)
            run_f = self._runs_table.take(cf * n + i0, axis=0)
        else:
            run_g, run_f = self._runs[cg, i0], self._runs[cf, i0]
        # interleaved: keep g (lift f, l = 0) at even slots, keep f (lift g, l = 1) at odd
        np.logical_and(run_g, valid, out=mask[:, b::2])
        np.logical_and(run_f, valid, out=mask[:, b + 1::2])
        if self._forbid_reversal:  # no rotation against the last move if it was one
            drop_reversals(mask, self._last_turn, R)
        if self._visited is not None:  # the single env's rule, row by row
            for i, vis in enumerate(self._visited):
                drop_revisits(self._model_of(i), mask[i], int(self._k[i]),
                              tuple(self._c[i].tolist()), *vis)

    def _regrasps_gained(self, idx: NDArray[np.int64]) -> NDArray[np.int64]:
        """Fall in the optimum's regrasps to go of sub-envs ``idx`` (they just regrasped),
        as the single env counts it (-1 to -1, no gait before or after: 0)."""
        to_go = ([self._subs[i]._to_go for i in idx.tolist()] if self._per_row_objects
                 else [self._to_go] * idx.size)
        gained, self._togo_now[idx] = regrasps_gained(to_go, self._togo_now[idx],
                                                      self._k[idx], self._c[idx])
        return gained

    def _write_window(self, idx: NDArray[np.int64]) -> None:
        """Grasp-map window rows of sub-envs ``idx`` (their grasp changed): the single
        env's ``pooled[i0 : i0 + sC : s, j0 : j0 + sC : s]``, gathered as blocks."""
        n, c, at = self._n, self._c.ravel(), 3 * idx
        i0 = (c.take(at + self._f.take(idx)) - self._win_back) % n
        j0 = (c.take(at + self._g.take(idx)) - self._win_back) % n
        if self._per_row_objects:  # each row its own map
            win = np.stack([window_at(self._row_windows[i], a, b)
                            for i, a, b in zip(idx.tolist(), i0.tolist(), j0.tolist(),
                                               strict=True)])
        else:
            win = window_at(self._windows, i0, j0)
        self._obs[idx, self.layout.window] = win.reshape(idx.size, -1)

    def step(self, actions: Any) -> tuple[NDArray[np.float32], NDArray[np.float64],
                                          NDArray[np.bool_], NDArray[np.bool_], dict]:
        """One move in every sub-env (see the class docstring); returns
        ``(obs, rewards, terminated, truncated, info)``, each batched over sub-envs."""
        self._need_reset("step")
        a = self._check_actions(actions)
        N, R, n = self.num_envs, self._R, self._n
        infos: dict[str, Any] = {}
        reset_idx = self._autoreset.nonzero()[0]
        live = ~self._autoreset
        legal = self._mask.ravel().take(self._rowA + a) & live
        d = self._delta[a]
        rot = legal & (d != 0)
        rg = legal ^ rot  # legal and not a rotation
        # rotations (thesis 5.2): both contacts move d grid steps through their workspaces
        dk = np.where(rot, d, 0)
        self._k += dk
        if self._forbid_reversal:  # the last move's direction if a rotation, else 0
            self._last_turn[legal] = np.sign(dk[legal])
        self._p += dk[:, None] * (self._c >= 0)
        # regrasps (thesis 4.2): the free finger h to position p, the lifted finger freed
        ri = rg.nonzero()[0]
        if ri.size:
            q = a[ri] - 2 * R
            pos = q >> 1
            h = self._h[ri]
            move = 2 * h + (q & 1)  # (free finger, lift l): the new fingers from a table
            lifted = self._regrasp_lifted[move]
            self._c[ri, h] = (self._ws_start[h] + pos - self._k[ri]) % n
            self._c[ri, lifted] = -1
            self._p[ri, h] = pos
            self._p[ri, lifted] = -1
            self._f[ri] = self._regrasp_f[move]
            self._g[ri] = self._regrasp_g[move]
            self._h[ri] = lifted
            self._regrasps += rg
        if self._visited is not None:  # forbid_revisit: the states moved to
            for i in legal.nonzero()[0].tolist():
                visit_state(self._visited[i], int(self._k[i]), tuple(self._c[i].tolist()))
        # sub-envs whose last episode ended restart here (next-step autoreset)
        if reset_idx.size:
            self._autoreset_subs(reset_idx, infos)
            new_grasp = np.concatenate((ri, reset_idx))
        else:
            new_grasp = ri
        self._compute_masks()
        mask = self._mask
        # observation (the GraspGait-v0 table), every row
        o, hd, c, p, k = self._obs, self._head, self._c, self._p, self._k
        if new_grasp.size:  # rows whose grasp changed: a regrasp or a restart
            cr = c[new_grasp]
            hd[new_grasp, _HELD:_HELD + 3] = cr >= 0
            hd[new_grasp, _PHI:_PHI + 6] = self._phi_cs.take(cr + 1, axis=0).reshape(
                new_grasp.size, 6)
            self._write_window(new_grasp)
        hd[:, _POS:_POS + 3] = np.where(p >= 0, p * self._inv_w, -1.0)
        ki = k - self._k_lo  # rows of the per-k tables
        hd[:, _THETA:_TO_GO + 1] = self._k_head.take(ki, axis=0)
        if self._lines is not None or self._openings is not None:
            cf, cg = c[self._arN, self._f], c[self._arN, self._g]
        if self._lines is not None:  # map_lines (thesis 4.3): rows.write_lines
            lines = o[:, self.layout.lines].reshape(N, 2, n)
            if self._per_row_objects:  # each row its own map
                for r, src in enumerate(self._row_lines):
                    sl = slice(r, r + 1)
                    write_lines(lines[sl], src, cf[sl], cg[sl], k[sl])
            else:
                write_lines(lines, self._lines, cf, cg, k)
        if self._openings is not None:  # rotation_lookahead: rows.regrasps_opened
            if self._per_row_objects:  # each row its own table
                for r in range(N):
                    sl = slice(r, r + 1)
                    o[sl, self.layout.lookahead] = regrasps_opened(
                        self._subs[r]._openings, self._h[sl], cf[sl], cg[sl], k[sl],
                        self._ws_start, self._rot_delta, n, mask[sl, :2 * R])
            else:
                o[:, self.layout.lookahead] = regrasps_opened(
                    self._openings, self._h, cf, cg, k, self._ws_start, self._rot_delta, n,
                    mask[:, :2 * R])
        if self._reach is not None:  # the reach look-ahead, every row
            arN, f, g = self._arN, self._f, self._g
            pf, pg = p[arN, f], p[arN, g]
            if self._per_row_objects:  # each row its own tables
                for r in range(N):
                    sl = slice(r, r + 1)
                    o[sl, self.layout.reach] = self._subs[r]._reach.move_shortfalls_batch(
                        self._h[sl], f[sl], g[sl], pf[sl], pg[sl], k[sl], mask[sl],
                        self._rot_delta)
            else:
                o[:, self.layout.reach] = self._reach.move_shortfalls_batch(
                    self._h, f, g, pf, pg, k, mask, self._rot_delta)
        # episode ends and reward (GraspGaitEnv._reward's table, term by term, same order)
        is_success = self._k_success[ki]
        terminated = live & (self._k_ends[ki] | ~mask.any(axis=1))
        reached = self._k_reached
        reached0 = reached[ki - dk]
        if reset_idx.size:  # a restarted sub-env earns nothing at this step
            reached0[reset_idx] = reached[ki[reset_idx]]
        gained: Any = 0
        if self._to_go is not None and ri.size:  # to_go_weight: regrasps gained
            gained = np.zeros(N, dtype=np.int64)
            gained[ri] = self._regrasps_gained(ri)
        # thesis 5.4 and the episode-end terms: the one implementation (rows.reward_terms);
        # illegal: live and not legal (legal implies live)
        turn, regrasp, rotation, success, dead_end, illegal = reward_terms(
            self.config, self._turn_coef, reached0, reached[ki], rg, rot, live ^ legal,
            terminated, is_success, gained)
        reward = turn + regrasp + rotation + success + dead_end + illegal
        # the time limit (gymnasium's TimeLimit: truncated once elapsed >= the limit)
        self._elapsed += live
        if self.max_episode_steps is None:
            truncated = np.zeros(N, dtype=bool)
        else:
            truncated = live & (self._elapsed >= self.max_episode_steps)
        self._autoreset = terminated | truncated
        # infos, batched as SyncVectorEnv batches the single env's (the reset sub-envs'
        # keys were written above)
        # ("_key" masks are shared and read-only)
        on = self._all
        live.flags.writeable = False
        infos["action_mask"], infos["_action_mask"] = mask.copy(), on
        if reset_idx.size < N:  # the step's keys, where a sub-env stepped (not restarted)
            terms = (turn, regrasp, rotation, success, dead_end, illegal)
            rt: dict[str, Any] = {}
            for key, v in zip(REWARD_TERMS, terms, strict=True):
                rt[key], rt["_" + key] = v, live
            infos["reward_terms"], infos["_reward_terms"] = rt, live
        infos["is_success"], infos["_is_success"] = is_success, on
        infos["turn_deg"], infos["_turn_deg"] = k * self._step_deg, on
        infos["regrasps"], infos["_regrasps"] = self._regrasps.copy(), on
        obs = self._observation()
        return obs, reward, terminated, truncated, infos

    def close_extras(self, **kwargs: Any) -> None:
        """Nothing to release (no renderer, no processes)."""


class GraspGaitRandomVectorEnv(GraspGaitVectorEnv):
    """``GraspGaitRandom-v0`` batched: ``N`` sub-envs, each with its own object and mu.

    ``gymnasium.make_vec("graspgait_env:GraspGaitRandom-v0", num_envs=N,
    vectorization_mode="vector_entry_point", **kwargs)``. Each sub-env is a
    :class:`~graspgait_env.envs.random_env.GraspGaitRandomEnv` of its own (a light copy
    of one template, with its own generator), which draws its objects, frictions and
    starts with the single env's own ``reset``, at the first reset, at every autoreset
    and with ``reset(options=...)`` (``object``, ``object_seed``, ``mu``, ``start``).
    The moves, masks, observations and rewards of every sub-env are then computed for
    the batch in one NumPy call, as for ``GraspGait-v0``
    (:class:`GraspGaitVectorEnv`), reading each row's own grasp map; the tables that
    one object's look-aheads need (``map_lines``, ``rotation_lookahead``,
    ``regrasp_lookahead``, ``to_go_weight``) are read row by row. The transitions are
    those of ``N`` single ``gymnasium.make("graspgait_env:GraspGaitRandom-v0")`` envs
    under ``SyncVectorEnv``, bit for bit, for the same seeds (the tests compare them).
    The hand, the grid and the turn are the same for every object (the single env
    checks it), so are the spaces.

    Parameters
    ----------
    num_envs, max_episode_steps, copy
        As :class:`GraspGaitVectorEnv`.
    render_mode
        Must be None.
    **kwargs
        The arguments of ``GraspGaitRandom-v0`` (``level``, ``mu_range``,
        ``object_seeds``, ``exclude_seeds``, ``bundled_fraction``,
        ``episodes_per_object``, ``config`` and the config fields), checked with the
        same messages.
    """

    _per_row_objects: ClassVar[bool] = True

    def __init__(self, num_envs: int = 1, *, max_episode_steps: int | None = MAX_EPISODE_STEPS,
                 render_mode: str | None = None, copy: bool = True, **kwargs: Any) -> None:
        from graspgait_env.envs.random_env import GraspGaitRandomEnv

        self._setup(GraspGaitRandomEnv(**kwargs), num_envs, max_episode_steps, render_mode,
                    copy)


def sample_legal_actions(masks: NDArray[np.bool_], u: NDArray[np.floating]) -> NDArray[np.int64]:
    """One action per row, uniform over that row's legal actions (a masked random policy).

    Parameters
    ----------
    masks
        ``(N, A)`` bool legal-move masks (``info["action_mask"]``).
    u
        ``(N,)`` uniforms in ``[0, 1)`` (e.g. ``rng.random(N)``): row ``i`` takes its
        ``floor(u_i * L_i)``-th legal action (``L_i`` legal actions), in index order. A
        row without a legal action (a dead end, restarted by the next step) gets
        ``A - 1``.

    Returns
    -------
    ndarray of int64, shape (N,)
    """
    N, A = masks.shape
    # every legal action of the batch as a flat index (row i's lie in [i A, (i + 1) A)),
    # then one binary search per row for where its legal actions start in that list
    legal = masks.ravel().nonzero()[0]
    if legal.size == 0:
        return np.full(N, A - 1, dtype=np.int64)
    row_start = np.arange(0, (N + 1) * A, A)
    bounds = legal.searchsorted(row_start)
    first = bounds[:-1]
    count = bounds[1:] - first
    pick = legal.take(np.minimum(first + (u * count).astype(np.int64), legal.size - 1))
    return np.where(count > 0, pick - row_start[:-1], A - 1)


def _copy_env(env: GraspGaitEnv) -> GraspGaitEnv:
    """A light copy of ``env``: shares its model, tables and start list; no generator
    yet (the first ``reset`` seeds it, as a fresh single env's does)."""
    sub = copy.copy(env)
    sub._np_random = None
    sub._np_random_seed = None
    return sub


def unsupported_fields(values: GraspGaitConfig | Mapping[str, Any]) -> list[str]:
    """The config fields set off their default that the batched step does not implement
    (not in :data:`SUPPORTED_FIELDS`), in the config's order; empty when the batched env
    reproduces the single env for these settings.

    ``values`` is a :class:`GraspGaitConfig` or the keyword arguments of
    ``gymnasium.make("GraspGait-v0", ...)`` (keys that are not config fields, such as
    ``object`` and ``mu``, are ignored)."""
    get = ((lambda name: getattr(values, name)) if isinstance(values, GraspGaitConfig)
           else (lambda name: values.get(name, _UNSET)))
    out = []
    for fld in fields(GraspGaitConfig):
        if fld.name in SUPPORTED_FIELDS:
            continue
        value = get(fld.name)
        if value is not _UNSET and value != _default(fld):
            out.append(fld.name)
    return out


_UNSET = object()


def _default(fld: Any) -> Any:
    return fld.default_factory() if fld.default is MISSING else fld.default


def _check_supported(cfg: GraspGaitConfig) -> None:
    """Refuse config fields the batched step does not implement (set off their default)."""
    for name in unsupported_fields(cfg)[:1]:
        value = getattr(cfg, name)
        default = _default(next(f for f in fields(cfg) if f.name == name))
        raise GraspGaitInputError(
            f"{name}={value!r}: the batched GraspGait env (vectorization_mode="
            f"\"vector_entry_point\") implements only the default {default!r}; leave "
            f"{name} at its default, or use vectorization_mode=\"sync\"")
