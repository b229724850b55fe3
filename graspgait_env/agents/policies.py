"""Policy networks for the GraspGait observation: a policy that scores every move with
one shared network over the env's named parts, and the extractor it reads them with.

**The policy design** (every learned agent that is not a plain MLP): MaskablePPO's
:class:`MaskableRegraspScorerPolicy` over :class:`PartsExtractor`, on an env with
``observation_mode: dict`` (the named parts of
:mod:`graspgait_env.envs.observation`): a global context and one small network,
shared by every move, that scores each move from its row of the env's ``actions``
part (``configs/train/general.yaml``).

:class:`GraspMapExtractor` is **retired for training**: ``graspgait train`` refuses a
config that names it (:func:`graspgait_env.agents.train.extractor_kwargs`, the error
names the fix). It stays only so that models saved with it (graspgait_env 0.1 and 0.2,
``tests/agents/test_shipped.py``) load and act as they did. What it computed from the
flat observation, the env now gives per move in the named parts (legality, the turn
achieved, the rotation room towards and against the goal after the move, the reach
look-ahead; :data:`~graspgait_env.envs.observation.ACTION_FEATURES`). It splits the
flat observation at :class:`graspgait_env.envs.observation.ObservationLayout`'s slices
and reads each part with the structure it has:

- the **header** (held fingers, workspace positions, contact and object angles, turn
  achieved and to go: 16 numbers) and the **legal-move mask** (one entry per action)
  pass through unchanged;
- the **grasp-map window** (``C x C`` cells, the map as seen from the current grasp,
  thesis 4.3's grasp map around the present grasp) goes through a 2-D convolution: a
  regrasp is a horizontal or vertical move in the map and a rotation a diagonal one
  (both contacts move by the same angle, thesis 5.2), so the same local pattern means
  the same thing wherever it lies in the window;
- the **map lines** (``map_lines=True``: the map's row and column through the grasp,
  ``2 x n`` over the whole circle) go through a 1-D convolution with circular padding.

With ``conv=False`` the window and the lines pass through flat instead. Its optional
features (a saved model's keyword arguments say which it uses): the **finishing
rotations** (``turn_steps`` and ``rotations``: per rotation towards the goal, 1 when it
is legal and reaches the turn), the **shortfall code** (``shortfall_bins``: the turn
still to go after the longest legal rotation, as a thermometer code), the
**forward-gait features** (``workspace_widths``: thesis 6.3.1's two choices, the
longest legal rotation towards the goal and the room each regrasp leaves), the
**regrasp block** (``regrasp_block``: :data:`REGRASP_CHANNELS` entries per regrasp,
:meth:`GraspMapExtractor.regrasp_block`) and the **action block** (``reach_depth``:
every move with the env's reach look-ahead, :meth:`GraspMapExtractor.action_block`).
Entries after the lines (``tail``) pass through unchanged.

Its features are the concatenation (header and mask, window features, line features,
tail, finishing rotations, the blocks). Every class here and its keyword arguments are
saved in the model zip by SB3 (``policy_kwargs``) and rebuilt on load, so a model loads
with :func:`graspgait_env.agents.card.load_agent` as any other
(``tests/agents/test_policies.py``, ``tests/agents/test_parts_policy.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import partial
from typing import Any

import gymnasium as gym
import torch
from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor, MlpExtractor
from torch import nn

from graspgait_env.envs.observation import ObservationLayout
from graspgait_env.errors import GraspGaitInputError

__all__ = ["REGRASP_CHANNELS", "GraspMapExtractor", "MaskableRegraspScorerPolicy",
           "PartsExtractor", "layout_of"]

REGRASP_CHANNELS = 9
"""Entries per regrasp action in :meth:`GraspMapExtractor.regrasp_block`."""
_ACTION_CHANNELS = 3  # with reach_depth: legal, is a rotation, the rotation's steps

def layout_of(observation_space: gym.spaces.Box, cells: int, line_cells: int,
              tail: int = 0) -> ObservationLayout:
    """The :class:`ObservationLayout` of a GraspGait observation space of known window size.

    ``n_actions`` is what remains of the vector after the header, the window
    (``cells**2``), the lines (``2 * line_cells``) and ``tail`` trailing entries; the
    layout returned covers the vector up to the lines (``layout.size``), the tail
    follows it.

    Raises
    ------
    GraspGaitInputError
        The space is not a flat Box, or ``cells``/``line_cells`` do not fit its length.
    """
    shape = getattr(observation_space, "shape", None)
    if shape is None or len(shape) != 1:
        raise GraspGaitInputError(f"observation space {observation_space!r}: GraspMapExtractor "
                                  "reads the flat GraspGait observation (a 1-D Box)")
    if min(cells, line_cells, tail) < 0 or cells < 1:
        raise GraspGaitInputError(
            f"features_extractor_kwargs cells={cells}, line_cells={line_cells}, tail={tail}: "
            "cells must be >= 1 and line_cells, tail >= 0, e.g. cells: 36, line_cells: 180")
    n_actions = int(shape[0]) - ObservationLayout.HEADER - cells * cells - 2 * line_cells - tail
    if n_actions < 1:
        raise GraspGaitInputError(
            f"features_extractor_kwargs cells={cells}, line_cells={line_cells}, tail={tail}: "
            f"do not fit an observation of length {shape[0]}; give the env's "
            "map_window_cells and, with map_lines, its grid size n (e.g. cells: 36, "
            "line_cells: 180)")
    return ObservationLayout(n_actions, cells, line_cells)


def _most_room(room: torch.Tensor) -> torch.Tensor:
    """``(batch, 2 W)``: 1 for the regrasps whose room (0 where illegal) is the most, all 0
    when none leaves any (thesis 6.3.1's choice)."""
    most = room.amax(dim=1, keepdim=True)
    return ((room == most) & (most > 0)).to(room.dtype)


class GraspMapExtractor(BaseFeaturesExtractor):
    """Header and mask as they are, a CNN over the grasp-map window, a 1-D CNN over the lines.

    Parameters
    ----------
    observation_space
        The env's flat ``Box`` (SB3 passes it).
    cells
        The env's ``map_window_cells`` (``C``; default 36).
    line_cells
        ``n`` (the grid size, 180 by default) when the env has ``map_lines=True``, else 0.
    tail
        Entries after the lines, passed through as they are (0 by default).
    conv
        Convolutions over the window and the lines (default); False: both pass through
        flat.
    shortfall_bins
        With ``turn_steps`` and ``rotations``: the shortfall code's bins (0: none; at
        most ``abs(turn_steps)``).
    workspace_widths
        With ``turn_steps`` and ``rotations``: the three fingers' workspace widths in
        grid points (``GaitModel``'s, ``[46, 46, 46]`` for the thesis hand at ``n =
        180``); adds the forward-gait features. None (default): none.
    best_regrasp
        With ``workspace_widths``: add the one-hot of the regrasps with the most room.
    regrasp_block
        With ``workspace_widths``: append :meth:`regrasp_block`, flattened (``2 W x``
        :data:`REGRASP_CHANNELS` entries, after every other feature), for
        :class:`MaskableRegraspScorerPolicy`, which sets it and reads the block apart.
    reach_depth
        The env's ``regrasp_lookahead`` ``D`` (its field is the last ``A x D`` entries,
        counted in ``tail``), with the regrasp block: the scored block then covers
        every action, :meth:`action_block` (the rotations are scored by the same
        network). 0 (default): the regrasp block alone.
    reach_relative, reach_best
        With ``reach_depth``: add to each action's block the field less its least over
        the legal moves, and a one-hot of the legal moves with that least, per depth
        (see :meth:`action_block`).
    turn_steps
        The requested turn in grid steps, signed (``turn_deg / (360 / n)``: 180 for the
        default 360° at ``n = 180``); with ``rotations``, adds the finishing rotations.
        0 (default): none.
    rotations
        ``R``, the rotations per direction of the action space (``model.R``: 45 with the
        thesis hand at ``n = 180``); 0 (default): no finishing rotations.
    window_channels
        Channels of the window's 3 x 3, stride-2 convolutions (ReLU after each).
    line_channels
        Channels of the lines' circular, stride-2 convolutions (kernel 5, ReLU after
        each); unused when ``line_cells`` is 0.
    window_features, line_features
        Width of the linear layer (ReLU) after each convolution stack.
    """

    def __init__(self, observation_space: gym.spaces.Box, cells: int = 36, line_cells: int = 0,
                 tail: int = 0, conv: bool = True, turn_steps: int = 0, rotations: int = 0,
                 shortfall_bins: int = 0, workspace_widths: Sequence[int] | None = None,
                 best_regrasp: bool = False, regrasp_block: bool = False,
                 reach_depth: int = 0, reach_relative: bool = False,
                 reach_best: bool = False,
                 window_channels: Sequence[int] = (8, 16),
                 line_channels: Sequence[int] = (8, 16),
                 window_features: int = 64, line_features: int = 64) -> None:
        layout = layout_of(observation_space, int(cells), int(line_cells), int(tail))
        n_flat = layout.window.start  # header + mask
        n_actions = layout.mask.stop - layout.mask.start
        finishing = bool(turn_steps) and rotations > 0
        if finishing and 2 * int(rotations) > n_actions:
            raise GraspGaitInputError(
                f"features_extractor_kwargs rotations={rotations}: more than the "
                f"{n_actions // 2} rotations per direction the action space can hold; give "
                "the env's model.R, e.g. 45")
        with_lines = line_cells > 0
        if conv:
            width = n_flat + window_features + (line_features if with_lines else 0)
        else:
            width = layout.size
        if shortfall_bins and not finishing:
            raise GraspGaitInputError(
                f"features_extractor_kwargs shortfall_bins={shortfall_bins}: needs "
                "turn_steps and rotations (the shortfall is the turn to go less the longest "
                "legal rotation), e.g. turn_steps: 180, rotations: 45")
        if not 0 <= int(shortfall_bins) <= abs(int(turn_steps or 0)):
            raise GraspGaitInputError(
                f"features_extractor_kwargs shortfall_bins={shortfall_bins}: must be 0 (none) "
                f"up to abs(turn_steps)={abs(int(turn_steps or 0))}, e.g. 90")
        self.shortfall_bins = int(shortfall_bins)
        widths = None if workspace_widths is None else [int(w) for w in workspace_widths]
        n_forward = 0
        if widths is not None:
            n_regrasp = n_actions - 2 * int(rotations)
            if not finishing or len(widths) != 3 or min(widths) < 1 or 2 * max(widths) != n_regrasp:
                raise GraspGaitInputError(
                    f"features_extractor_kwargs workspace_widths={workspace_widths!r}: give "
                    "the three fingers' workspace widths in grid points (the gait model's, "
                    f"2 x the widest = the {n_regrasp} regrasp actions), with turn_steps and "
                    "rotations, e.g. [46, 46, 46] for the thesis hand at n = 180")
            n_forward = int(rotations) + (2 if best_regrasp else 1) * n_regrasp
        elif regrasp_block:
            raise GraspGaitInputError(
                "features_extractor_kwargs regrasp_block=True: needs workspace_widths, "
                "turn_steps and rotations (the block is computed from them), e.g. "
                "workspace_widths: [46, 46, 46], turn_steps: 180, rotations: 45")
        self.reach_depth = int(reach_depth)
        if self.reach_depth:
            n_reach = n_actions * self.reach_depth
            if not regrasp_block or self.reach_depth < 0 or n_reach > int(tail):
                raise GraspGaitInputError(
                    f"features_extractor_kwargs reach_depth={reach_depth!r}: the env's "
                    "regrasp_lookahead (its last n_actions x D entries, inside tail), with "
                    "policy MaskableRegraspScorerPolicy; e.g. reach_depth: 3, tail: 546")
        #: entries per action in the scored block (regrasps only, or every action)
        self.reach_relative = bool(reach_relative) and self.reach_depth > 0
        self.reach_best = bool(reach_best) and self.reach_depth > 0
        self.block_channels = (REGRASP_CHANNELS + _ACTION_CHANNELS
                               + self.reach_depth * (1 + self.reach_relative + self.reach_best)
                               if self.reach_depth else REGRASP_CHANNELS)
        n_scored = n_actions if self.reach_depth else (n_regrasp if regrasp_block else 0)
        n_block = n_scored * self.block_channels if regrasp_block else 0
        super().__init__(observation_space,
                         width + int(tail) + (int(rotations) if finishing else 0)
                         + self.shortfall_bins + n_forward + n_block)
        self.with_block = bool(regrasp_block)
        #: where the regrasp actions lie in the action space (first index, count) and
        #: how many features precede the regrasp block (with ``regrasp_block``)
        self.regrasp_actions = (((0, n_actions) if self.reach_depth
                                 else (2 * int(rotations), n_block // REGRASP_CHANNELS))
                                if regrasp_block else (0, 0))
        self.block_start = self.features_dim - n_block
        self.gait_features = widths is not None
        self.best_regrasp = bool(best_regrasp) and widths is not None
        if widths is not None:
            w_max = max(widths)
            self.register_buffer("_widths", torch.tensor(widths, dtype=torch.float32),
                                 persistent=False)
            self.register_buffer("_positions", torch.arange(w_max, dtype=torch.float32),
                                 persistent=False)
            self.register_buffer("_lift", torch.arange(2 * w_max, dtype=torch.float32)[None, :]
                                 % 2, persistent=False)
        self.layout, self.n_flat, self.tail, self.conv = layout, n_flat, int(tail), bool(conv)
        self.cells, self.line_cells = int(cells), int(line_cells)
        self.turn_steps, self.rotations = int(turn_steps), int(rotations) if finishing else 0
        self.window_net = (self._stack(nn.Conv2d, 1, window_channels, 3, 1, "zeros",
                                       (1, self.cells, self.cells), window_features)
                           if conv else None)
        self.line_net = (self._stack(nn.Conv1d, 2, line_channels, 5, 2, "circular",
                                     (2, self.line_cells), line_features)
                         if conv and with_lines else None)
        # rotation a (0-based) moves a + 1 grid steps towards the goal
        self.register_buffer("_steps", torch.arange(1, self.rotations + 1, dtype=torch.float32),
                             persistent=False)
        # shortfall code thresholds: bin j is 1 when the shortfall exceeds j * width
        width_bins = abs(self.turn_steps) / max(self.shortfall_bins, 1)
        self.register_buffer("_thresholds", torch.arange(self.shortfall_bins,
                                                         dtype=torch.float32) * width_bins,
                             persistent=False)

    @staticmethod
    def _stack(conv: type, c_in: int, channels: Sequence[int], kernel: int, padding: int,
               padding_mode: str, in_shape: tuple[int, ...], out_features: int) -> nn.Sequential:
        layers: list[nn.Module] = []
        for c in channels:
            layers += [conv(c_in, int(c), kernel, stride=2, padding=padding,
                            padding_mode=padding_mode), nn.ReLU()]
            c_in = int(c)
        layers.append(nn.Flatten())
        with torch.no_grad():
            n = nn.Sequential(*layers)(torch.zeros(1, *in_shape)).shape[1]
        layers += [nn.Linear(n, int(out_features)), nn.ReLU()]
        return nn.Sequential(*layers)

    def finishing_rotations(self, observations: torch.Tensor) -> torch.Tensor:
        """``(batch, R)``: 1 where the rotation towards the goal by ``a + 1`` grid steps is
        legal and reaches the requested turn, else 0 (see the module docstring)."""
        legal, need = self._goal_rotations(observations), self._steps_to_go(observations)
        return legal * (self._steps >= need).to(legal.dtype)

    def _goal_rotations(self, observations: torch.Tensor) -> torch.Tensor:
        """``(batch, R)``: the mask's rotations towards the goal (CCW: actions 0..R-1, CW:
        R..2R-1), rotation ``a`` by ``a + 1`` grid steps."""
        R = self.rotations
        first = self.layout.mask.start + (0 if self.turn_steps > 0 else R)
        return observations[:, first:first + R]

    def _steps_to_go(self, observations: torch.Tensor) -> torch.Tensor:
        """``(batch, 1)``: the turn still to go, in grid steps (header entry 15)."""
        lay = self.layout
        return torch.round(observations[:, lay.to_go:lay.to_go + 1] * abs(self.turn_steps))

    def shortfall_code(self, observations: torch.Tensor) -> torch.Tensor:
        """``(batch, shortfall_bins)``: the turn still to go after the longest legal
        rotation towards the goal (grid steps, 0 when that rotation reaches the turn), as a
        thermometer code: bin ``j`` is 1 when it exceeds ``j * abs(turn_steps) /
        shortfall_bins`` (see the module docstring)."""
        reach = (self._goal_rotations(observations) * self._steps).amax(dim=1, keepdim=True)
        short = torch.clamp(self._steps_to_go(observations) - reach, min=0.0)
        return (short > self._thresholds).to(observations.dtype)

    def _regrasp_geometry(self, observations: torch.Tensor) -> dict[str, torch.Tensor]:
        """Per regrasp action ``2q + l`` (``(batch, 2 W)`` each): ``legal`` (the mask),
        ``goal`` and ``back`` (the rotation room towards and away from the goal of the
        grasp it makes, grid steps, clamped at 0, thesis 5.2), ``q`` (the new
        position over ``W_h - 1``), ``l`` (which held finger is lifted) and ``kept`` (the
        kept finger's position over its ``W - 1``)."""
        lay, R = self.layout, self.rotations
        held = observations[:, lay.held]
        wd = self._widths
        # workspace positions (free: < 0)
        p = torch.round(observations[:, lay.position] * (wd - 1))
        h = torch.argmin(held, dim=1, keepdim=True)  # the free finger
        f = (h == 0).long()  # the held fingers f < g
        g = torch.where(h == 2, 1, 2)
        w_h, w_f, w_g = wd[h], wd[f], wd[g]
        p_f, p_g = p.gather(1, f), p.gather(1, g)
        q = self._positions[None, :].expand(p.shape[0], -1)  # the free finger's new position
        ccw_g = torch.minimum(w_h - 1 - q, w_g - 1 - p_g)  # counter-clockwise room
        ccw_f = torch.minimum(w_h - 1 - q, w_f - 1 - p_f)
        cw_g, cw_f = torch.minimum(q, p_g), torch.minimum(q, p_f)  # clockwise room
        if self.turn_steps > 0:
            goal_g, goal_f, back_g, back_f = ccw_g, ccw_f, cw_g, cw_f
        else:
            goal_g, goal_f, back_g, back_f = cw_g, cw_f, ccw_g, ccw_f

        def pairs(keep_g: torch.Tensor, keep_f: torch.Tensor) -> torch.Tensor:
            return torch.stack((keep_g, keep_f), dim=2).reshape(p.shape[0], -1)  # 2q + l

        start = lay.mask.start + 2 * R
        legal = observations[:, start:start + 2 * q.shape[1]]
        kept = pairs((p_g / torch.clamp(w_g - 1, min=1.0)).expand_as(q),
                     (p_f / torch.clamp(w_f - 1, min=1.0)).expand_as(q))
        return {"legal": legal,
                "goal": legal * torch.clamp(pairs(goal_g, goal_f), min=0.0),
                "back": legal * torch.clamp(pairs(back_g, back_f), min=0.0),
                "q": pairs(q, q) / torch.clamp(w_h - 1, min=1.0),
                "l": self._lift.expand(p.shape[0], -1),
                "kept": kept * (kept >= 0).to(kept.dtype)}

    def regrasp_block(self, observations: torch.Tensor,
                      geometry: dict[str, torch.Tensor] | None = None) -> torch.Tensor:
        """``(batch, 2 W, REGRASP_CHANNELS)``: for each regrasp action ``2q + l``, the
        entries :class:`MaskableRegraspScorerPolicy` scores it by, all read off the
        observation (see the module docstring): legal; rotation room towards the goal and
        away from it, over ``R``; the new position ``q`` and the kept finger's position,
        each over its ``W - 1``; ``l``; whether the regrasps to the neighbouring positions
        ``q - 1`` and ``q + 1`` with the same lift are legal (a proxy for how far the
        new grasp lies inside the force-closure region); and 1 for the legal regrasps
        with the most room towards the goal (thesis 6.3.1's choice)."""
        geo = self._regrasp_geometry(observations) if geometry is None else geometry
        legal, R = geo["legal"], float(self.rotations)
        b = legal.shape[0]
        by_q = legal.reshape(b, -1, 2)  # [batch, q, l]
        zero = torch.zeros_like(by_q[:, :1])
        below = torch.cat((zero, by_q[:, :-1]), dim=1).reshape(b, -1)
        above = torch.cat((by_q[:, 1:], zero), dim=1).reshape(b, -1)
        goal = geo["goal"]
        return torch.stack((legal, goal / R, geo["back"] / R, geo["q"], geo["kept"], geo["l"],
                            below, above, _most_room(goal)), dim=2)

    def forward_gait_features(self, observations: torch.Tensor,
                              geometry: dict[str, torch.Tensor] | None = None) -> torch.Tensor:
        """``(batch, R + 2 W)``: the longest legal rotation towards the goal (one-hot over
        the ``R`` rotations that way), then for each regrasp action ``2p + l`` the room
        the grasp it makes leaves for a rotation towards the goal, over ``R`` (0 where the
        regrasp is illegal); with ``best_regrasp`` ``2 W`` more, a one-hot of the legal
        regrasps with the most room (all 0 when none leaves any); see the module
        docstring."""
        legal_rot = self._goal_rotations(observations)
        reach = (legal_rot * self._steps).amax(dim=1, keepdim=True)
        longest = legal_rot * (self._steps == reach).to(legal_rot.dtype)
        geo = self._regrasp_geometry(observations) if geometry is None else geometry
        room = geo["goal"] / self.rotations
        if not self.best_regrasp:
            return torch.cat((longest, room), dim=1)
        return torch.cat((longest, room, _most_room(room)), dim=1)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        """Features of a batch of observations, shape ``(batch, features_dim)``."""
        lay, b = self.layout, observations.shape[0]
        if self.window_net is None:
            parts = [observations[:, : lay.size]]
        else:
            parts = [observations[:, : self.n_flat],
                     self.window_net(observations[:, lay.window].reshape(b, 1, self.cells,
                                                                        self.cells))]
            if self.line_net is not None:
                parts.append(self.line_net(observations[:, lay.lines].reshape(
                    b, 2, self.line_cells)))
        if self.tail:
            parts.append(observations[:, lay.size:lay.size + self.tail])
        if self.rotations:
            parts.append(self.finishing_rotations(observations))
        if self.shortfall_bins:
            parts.append(self.shortfall_code(observations))
        if self.gait_features:
            geo = self._regrasp_geometry(observations)  # once for both users
            parts.append(self.forward_gait_features(observations, geo))
        if self.with_block:
            block = self.regrasp_block(observations, geo)
            if self.reach_depth:
                block = self.action_block(observations, block)
            parts.append(block.reshape(b, -1))
        return torch.cat(parts, dim=1)

    def action_block(self, observations: torch.Tensor, regrasp_block: torch.Tensor
                     ) -> torch.Tensor:
        """``(batch, A, block_channels)`` with ``reach_depth``: every action's entries for
        the shared scorer. Per action: the :meth:`regrasp_block` channels (0 for a
        rotation); legal (the mask); 1 for a rotation; the rotation's grid steps over
        ``R``, positive towards the goal (0 for a regrasp); then the env's reach
        look-ahead, ``reach_depth`` entries (the shortfall of the turn after ``j = 0 ..
        D - 1`` more regrasps, over the turn; see ``GraspGait-v0``'s *Observation
        Space*), read from the observation's last ``A x D`` entries; with
        ``reach_relative``, ``D`` more: each of those less its least over the legal
        moves (0 for an illegal move), so that the best moves read 0 whatever the
        state; with ``reach_best``, ``D`` more: 1 for the legal moves with that least
        (a one-hot of the best moves per depth, as ``best_regrasp`` is for the rotation
        room: one grid step is 1/180 of the turn, a difference a network reads poorly)."""
        lay, R, D = self.layout, self.rotations, self.reach_depth
        b = observations.shape[0]
        A = lay.mask.stop - lay.mask.start
        n_reg = A - 2 * R
        end = lay.size + self.tail
        reach = observations[:, end - A * D:end]
        per_regrasp = reach[:, :n_reg * D].reshape(b, n_reg, D)
        per_rotation = reach[:, n_reg * D:].reshape(b, 2 * R, D)
        legal = observations[:, lay.mask]
        steps = self._steps / R
        towards = steps if self.turn_steps > 0 else -steps
        signed = torch.cat((towards, -towards))  # CCW first, then CW (the action layout)
        rot = torch.zeros(b, 2 * R, REGRASP_CHANNELS, dtype=observations.dtype,
                          device=observations.device)
        kind = torch.cat((torch.ones(2 * R), torch.zeros(n_reg))).to(observations)
        step_col = torch.cat((signed, torch.zeros(n_reg, device=signed.device))).to(observations)
        base = torch.cat((rot, regrasp_block), dim=1)
        extra = torch.stack((legal, kind.expand(b, -1), step_col.expand(b, -1)), dim=2)
        field = torch.cat((per_rotation, per_regrasp), dim=1)  # [batch, A, D]
        parts = [base, extra, field]
        if self.reach_relative or self.reach_best:
            big = torch.finfo(field.dtype).max
            least = torch.where(legal[:, :, None] > 0, field, big).amin(dim=1, keepdim=True)
            least = torch.where(least == big, torch.zeros_like(least), least)
            above = (field - least) * legal[:, :, None]
        if self.reach_relative:  # each entry less the least over the legal moves
            parts.append(above)
        if self.reach_best:  # 1 for the legal moves with the least, per depth
            parts.append(((above <= 1e-6) & (legal[:, :, None] > 0)).to(field.dtype))
        return torch.cat(parts, dim=2)


class PartsExtractor(BaseFeaturesExtractor):
    """Features of the named-parts observation (``observation_mode="dict"``), read by name.

    ``features_extractor: graspgait_env.agents.policies:PartsExtractor`` with ``policy:
    graspgait_env.agents.policies:MaskableRegraspScorerPolicy`` and ``env_kwargs:
    {observation_mode: dict}``. Nothing is computed here that the env does not give: the
    per-action features (legality, the turn achieved and the rotation room towards and
    against the goal after the move, and the look-aheads' entries where the env has them:
    :mod:`graspgait_env.envs.observation`) come from the ``actions`` part, whatever its
    columns, so the same policy reads any set of opt-in fields.

    The features are the **global context** (``grasp``, the ``legal`` column of
    ``actions``, the ``window`` and ``lines`` parts flattened, and each feature column's
    least and greatest value over the legal moves: what the best move offers), then the
    **action block**: per action, its ``F`` features and each less its least over the
    legal moves (0 for an illegal move), so that a shared scorer sees how a move compares
    with the others. The policy keeps the block out of its MLPs and scores
    every action from its row of it with one network
    (:class:`MaskableRegraspScorerPolicy`).

    Parameters
    ----------
    observation_space
        The env's ``Dict`` observation space (SB3 passes it).
    extremes
        Add, per feature, 1 for the legal moves at its least and 1 for those at its
        greatest value (two one-hot codes of ``F`` entries each; default False): which
        moves are the best by each feature, whichever way is better. ``general`` sets it:
        without it, over seeds 0-4, the recipe spends 1.030x the optimum's regrasps at
        mu 0.5 on held-out objects against 1.019x (IQM; docs/agents.md). The default
        stays False so that a model saved without the keyword loads as it was trained.
    """

    def __init__(self, observation_space: gym.spaces.Dict, extremes: bool = False) -> None:
        from graspgait_env.envs.observation import ACTION_FEATURES

        names = list(getattr(observation_space, "spaces", {}) or {})
        if not isinstance(observation_space, gym.spaces.Dict) or not {
                "grasp", "actions", "window"} <= set(names):
            raise GraspGaitInputError(
                f"observation space {observation_space!r}: PartsExtractor reads the named "
                "parts (grasp, actions, window); set env_kwargs observation_mode: dict")
        n_actions, n_features = observation_space["actions"].shape
        self.legal = ACTION_FEATURES.index("legal")
        self.extremes = bool(extremes)
        self.names = [k for k in ("window", "lines") if k in names]
        flat = sum(math.prod(observation_space[k].shape) for k in self.names)
        width = int(observation_space["grasp"].shape[0]) + n_actions + flat + 2 * n_features
        self.block_channels = n_features * (2 + 2 * self.extremes)
        super().__init__(observation_space, width + n_actions * self.block_channels)
        #: the scored block: where it starts in the features and the actions it scores
        self.block_start = width
        self.regrasp_actions = (0, int(n_actions))

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """Features of a batch of named-parts observations, ``(batch, features_dim)``."""
        act = observations["actions"]
        b = act.shape[0]
        legal = act[:, :, self.legal] > 0.5
        big = torch.finfo(act.dtype).max
        lo = torch.where(legal[:, :, None], act, big).amin(dim=1)
        hi = torch.where(legal[:, :, None], act, -big).amax(dim=1)
        none = ~legal.any(dim=1, keepdim=True)  # no legal move: 0, 0
        lo, hi = lo.masked_fill(none, 0.0), hi.masked_fill(none, 0.0)
        parts = [observations["grasp"], act[:, :, self.legal]]
        parts += [observations[k].reshape(b, -1) for k in self.names]
        parts += [lo, hi]
        on = legal[:, :, None].to(act.dtype)
        block = [act, (act - lo[:, None, :]) * on]
        if self.extremes:  # 1e-6: the features are exact multiples of 1 / K or 0 / 1
            block.append((act <= lo[:, None, :] + 1e-6).to(act.dtype) * on)
            block.append((act >= hi[:, None, :] - 1e-6).to(act.dtype) * on)
        parts.append(torch.cat(block, dim=2).reshape(b, -1))
        return torch.cat(parts, dim=1)


class _ScorerExtractor(nn.Module):
    """SB3's ``MlpExtractor`` over the features before the regrasp block, and beside it
    the regrasp scorer: one small MLP, shared by every regrasp action, from that
    action's block entries and a context read off the policy latent to one score.
    ``forward_actor`` returns ``[policy latent, one score per regrasp action]``."""

    def __init__(self, base_dim: int, n_regrasp: int, net_arch: Any, activation_fn: type,
                 scorer_arch: Sequence[int], context: int, device: Any,
                 channels: int = REGRASP_CHANNELS) -> None:
        super().__init__()
        self.mlp = MlpExtractor(base_dim, net_arch=net_arch, activation_fn=activation_fn,
                                device=device)
        self.base_dim, self.n_regrasp = int(base_dim), int(n_regrasp)
        self.context = nn.Sequential(nn.Linear(self.mlp.latent_dim_pi, int(context)), nn.ReLU())
        layers: list[nn.Module] = []
        self.channels = int(channels)
        c_in = self.channels + int(context)
        for width in scorer_arch:
            layers += [nn.Linear(c_in, int(width)), nn.ReLU()]
            c_in = int(width)
        self.score = nn.Linear(c_in, 1)
        self.scorer = nn.Sequential(*layers, self.score)
        self.latent_dim_pi = self.mlp.latent_dim_pi + self.n_regrasp
        self.latent_dim_vf = self.mlp.latent_dim_vf

    def forward(self, features: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.forward_actor(features), self.forward_critic(features)

    def forward_actor(self, features: torch.Tensor) -> torch.Tensor:
        b = features.shape[0]
        latent = self.mlp.forward_actor(features[:, :self.base_dim])
        block = features[:, self.base_dim:].reshape(b, self.n_regrasp, self.channels)
        context = self.context(latent)[:, None, :].expand(-1, self.n_regrasp, -1)
        scores = self.scorer(torch.cat((block, context), dim=2)).squeeze(2)
        return torch.cat((latent, scores), dim=1)

    def forward_critic(self, features: torch.Tensor) -> torch.Tensor:
        return self.mlp.forward_critic(features[:, :self.base_dim])


class _ScoredActionNet(nn.Module):
    """The action logits: a linear layer over the policy latent (SB3's ``action_net``;
    left out with ``linear=False``) plus, on the scored actions, the scorer's scores
    times ``gain`` (a fixed 1, a parameter so that scaling the head's parameters,
    ``init_logit_scale``, scales every logit)."""

    def __init__(self, latent_dim: int, n_actions: int, regrasp_actions: tuple[int, int],
                 linear: bool = True) -> None:
        super().__init__()
        self.latent_dim = int(latent_dim)
        self.linear = nn.Linear(self.latent_dim, int(n_actions)) if linear else None
        self.gain = nn.Parameter(torch.ones(()), requires_grad=False)
        first, count = regrasp_actions
        self.pad = (int(first), int(n_actions) - int(first) - int(count))

    def forward(self, latent: torch.Tensor) -> torch.Tensor:
        scores = nn.functional.pad(latent[:, self.latent_dim:] * self.gain, self.pad)
        if self.linear is None:
            return scores
        return self.linear(latent[:, :self.latent_dim]) + scores


class MaskableRegraspScorerPolicy(MaskableActorCriticPolicy):
    """sb3-contrib's maskable actor-critic with a **shared regrasp scorer**.

    ``policy: graspgait_env.agents.policies:MaskableRegraspScorerPolicy`` in a training
    config, with ``algo: maskable_ppo`` and ``features_extractor:
    graspgait_env.agents.policies:PartsExtractor`` on the env's named parts
    (``observation_mode: dict``), where every action is scored from the env's per-action
    features. (Models saved with the retired :class:`GraspMapExtractor`, whose regrasp
    block the policy switched on, load too.)

    Each action's logit is SB3's (a linear layer over the ``net_arch`` policy latent;
    left out with ``linear_head=False``, the score alone then) plus a score of that
    move: one MLP (``scorer_arch``), the same for every move, over the move's row of
    :class:`PartsExtractor`'s action block (the env's per-action features of thesis
    4.2's moves, rotations and regrasps alike: legality, the turn
    achieved and the rotation room towards and against the goal after it, the
    look-aheads' entries, each also against the best legal move) and a
    ``scorer_context``-wide ReLU projection of the policy latent (what the state asks
    for). The value head is SB3's. (With the retired :class:`GraspMapExtractor` the
    scored rows are its :meth:`~GraspMapExtractor.regrasp_block` or
    :meth:`~GraspMapExtractor.action_block`.)

    Why: with a flat head every action has its own output weights, so what the agent
    learns of a regrasp at one workspace position (e.g. that one leaving no rotation
    room towards the goal loses a regrasp) does not carry to the same kind of regrasp at
    another; the shared scorer prices every move by the same function of what it does.
    It only re-weights legal moves, computed from the observation; it never sees the
    optimum's regrasps to go. Measured in ``agents/models/*.md``.

    Parameters
    ----------
    *args, **kwargs
        Those of ``MaskableActorCriticPolicy`` (SB3 passes them).
    scorer_arch
        Hidden layer widths of the scorer (ReLU), default ``(32,)``.
    scorer_context
        Width of the context the scorer reads off the policy latent, default 16.
    linear_head
        Add SB3's linear layer over the policy latent to the logits (default True). With
        False a move's logit is its score alone, so nothing in the policy belongs to an
        action's index: what the state asks for reaches a move only through the context
        its score reads. Needs :class:`PartsExtractor` (every move scored). Over 5 seeds
        of ``general``'s recipe (docs/agents.md, "The scorer on the named parts"), the
        layer's regrasps over the optimum's, IQM: 1.023x at mu 0.5 against 1.019x
        without it, 1.047x on the thesis hexagon against 1.008x, the same (1.007x and
        1.008x) on held-out procedural objects; ``general`` is trained without it.
    """

    def __init__(self, *args: Any, scorer_arch: Sequence[int] = (32,), scorer_context: int = 16,
                 linear_head: bool = True, **kwargs: Any) -> None:
        extractor = kwargs.get("features_extractor_class")
        if extractor is None or not issubclass(extractor, (GraspMapExtractor, PartsExtractor)):
            raise GraspGaitInputError(
                f"policy MaskableRegraspScorerPolicy with features_extractor {extractor!r}: "
                "needs graspgait_env.agents.policies:PartsExtractor (the env's per-action "
                "features; env_kwargs observation_mode: dict)")
        if issubclass(extractor, GraspMapExtractor):
            kwargs["features_extractor_kwargs"] = {
                **(kwargs.get("features_extractor_kwargs") or {}), "regrasp_block": True}
        if kwargs.get("share_features_extractor") is False:
            raise GraspGaitInputError("policy MaskableRegraspScorerPolicy: "
                                      "share_features_extractor=False is not supported; "
                                      "leave it at True")
        if (isinstance(scorer_context, bool) or not isinstance(scorer_context, int)
                or not isinstance(scorer_arch, (list, tuple))
                or any(isinstance(w, bool) or not isinstance(w, int) for w in scorer_arch)
                or int(scorer_context) < 1 or any(int(w) < 1 for w in scorer_arch)):
            raise GraspGaitInputError(
                f"policy_kwargs scorer_arch={scorer_arch!r}, scorer_context={scorer_context!r}: "
                "widths must be positive integers, e.g. scorer_arch: [32], scorer_context: 16")
        if not isinstance(linear_head, bool):
            raise GraspGaitInputError(f"policy_kwargs linear_head={linear_head!r}: must be "
                                      "true or false")
        if not linear_head and not issubclass(extractor, PartsExtractor):
            raise GraspGaitInputError(
                f"policy_kwargs linear_head=false with features_extractor "
                f"{extractor.__name__}: needs graspgait_env.agents.policies:PartsExtractor "
                "(every move scored); leave linear_head at true")
        # read by _build, which the base __init__ calls
        self.linear_head = linear_head
        self.scorer_arch = [int(w) for w in scorer_arch]
        self.scorer_context = int(scorer_context)
        super().__init__(*args, **kwargs)

    def _build_mlp_extractor(self) -> None:
        fx = self.features_extractor
        self.mlp_extractor = _ScorerExtractor(fx.block_start, fx.regrasp_actions[1],
                                              self.net_arch, self.activation_fn,
                                              self.scorer_arch, self.scorer_context, self.device,
                                              fx.block_channels)

    def _build(self, lr_schedule: Any) -> None:
        super()._build(lr_schedule)
        latent = self.mlp_extractor.mlp.latent_dim_pi
        self.action_net = _ScoredActionNet(latent, int(self.action_space.n),
                                           self.features_extractor.regrasp_actions,
                                           linear=self.linear_head)
        if self.ortho_init:  # SB3's small initial logits, the scorer's output included
            if self.action_net.linear is not None:
                self.action_net.linear.apply(partial(self.init_weights, gain=0.01))
            self.mlp_extractor.score.apply(partial(self.init_weights, gain=0.01))
        self.optimizer = self.optimizer_class(self.parameters(), lr=lr_schedule(1),
                                              **self.optimizer_kwargs)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.update(scorer_arch=self.scorer_arch, scorer_context=self.scorer_context,
                    linear_head=self.linear_head)
        return data
