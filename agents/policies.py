"""Policy networks for the GraspGait observation: convolutions over the grasp map's views.

:class:`GraspMapExtractor` is an SB3 features extractor (``features_extractor:
agents.policies:GraspMapExtractor`` in a training config). It splits the flat
observation at :class:`graspgait_env.envs.map_env.ObservationLayout`'s slices and reads
each part with the structure it has:

- the **header** (held fingers, workspace positions, contact and object angles, turn
  achieved and to go: 16 numbers) and the **legal-move mask** (one entry per action)
  pass through unchanged;
- the **grasp-map window** (``C x C`` cells, the map as seen from the current grasp,
  thesis 4.3's grasp map around the present grasp) goes through a 2-D convolution: a
  regrasp is a horizontal or vertical move in the map and a rotation a diagonal one
  (both contacts move by the same angle, thesis 5.2), so the same local pattern means
  the same thing wherever it lies in the window;
- the **map lines** (``map_lines=True``: the map's row and column through the grasp,
  ``2 x n`` over the whole circle) go through a 1-D convolution with circular padding:
  a rotation by ``d`` grid steps shifts both lines by ``d``, so a shift-equivariant
  reading of them generalises across where the regrasps open.

With ``conv=False`` the window and the lines pass through flat instead (the
``MlpPolicy`` input, unchanged), for the finishing rotations alone.

The **finishing rotations** (``turn_steps`` and ``rotations`` given): one entry per
rotation towards the goal, ``a = 0 .. R-1`` (rotate by ``a + 1`` grid steps, the
*Action Space* of ``GraspGait-v0``), 1 when that rotation is legal now (the mask) and
reaches the requested turn (``a + 1 >= `` the turn to go in grid steps, header entry
15 times ``abs(turn_steps)``), else 0. It is a function of the observation alone (mask
and turn to go), computed exactly rather than learned: measured on the ellipse
(``agents/models/ellipse.md``), agents that played their learned gait cycle on from a
grasp whose rotation already reaches the turn spent two regrasps there (away from the
goal and back) in nearly every episode, most of their regrasps beyond the optimum.

The **shortfall code** (``shortfall_bins`` given, with the finishing rotations): the
turn still to go after the longest legal rotation towards the goal (grid steps, 0 when
it reaches the turn; the mask and the turn to go of the observation), as a thermometer
code of ``shortfall_bins`` entries (entry ``j`` is 1 when the shortfall exceeds ``j``
bin widths of ``abs(turn_steps) / shortfall_bins`` grid steps), so that a linear layer
reads any step function of it: the regrasps still needed rise in steps of the turn one
regrasp buys (about 45° on the circle), and a policy that reads the shortfall as one
number must learn that staircase itself.
The **forward-gait features** (``workspace_widths`` given, with the finishing
rotations): the two choices of thesis 6.3.1's forward (staircase) gait, as inputs per
action, computed from the observation (the held fingers, their workspace positions and
the mask): a one-hot of the longest legal rotation towards the goal (over its ``R``
rotations), and for each regrasp action the room for a rotation towards the goal that
the grasp it makes would have (the rotation room of thesis 5.2, ``min(W - 1 - p)`` over
the new pair counter-clockwise, ``min(p)`` clockwise; over ``R``; 0 where illegal),
and, with ``best_regrasp``, a one-hot of the legal regrasps with the most room.
With a linear policy head on them (``net_arch: {pi: [], vf: [...]}``) a logit can be a
weight times one of these entries, which a hidden layer narrower than the action space
cannot pass through for every action; the weights are learned, nothing forces the
forward gait.
Entries after the lines (``tail``, e.g. an opt-in field the env appends there) pass
through unchanged too. The features are the concatenation (header and mask, window
features, line features, tail, finishing rotations); SB3's ``net_arch`` MLP heads sit on top as with
``MlpPolicy``. The class
and its keyword arguments are saved in the model zip by SB3 (``policy_kwargs``) and
rebuilt on load, so a model trained with it loads with :func:`agents.card.load_agent`
as any other (``tests/agents/test_policies.py``).
"""

from __future__ import annotations

from collections.abc import Sequence

import gymnasium as gym
import torch
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from graspgait_env.envs.map_env import ObservationLayout
from graspgait_env.errors import GraspGaitInputError

__all__ = ["GraspMapExtractor", "layout_of"]

_HEADER = 16  # ObservationLayout's header: held, positions, contact and object angles, turn


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
    n_actions = int(shape[0]) - _HEADER - cells * cells - 2 * line_cells - tail
    if n_actions < 1:
        raise GraspGaitInputError(
            f"features_extractor_kwargs cells={cells}, line_cells={line_cells}, tail={tail}: "
            f"do not fit an observation of length {shape[0]}; give the env's "
            "map_window_cells and, with map_lines, its grid size n (e.g. cells: 36, "
            "line_cells: 180)")
    return ObservationLayout(n_actions, cells, line_cells)


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
                 best_regrasp: bool = False,
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
        super().__init__(observation_space,
                         width + int(tail) + (int(rotations) if finishing else 0)
                         + self.shortfall_bins + n_forward)
        self.gait_features = widths is not None
        self.best_regrasp = bool(best_regrasp) and widths is not None
        if widths is not None:
            w_max = max(widths)
            self.register_buffer("_widths", torch.tensor(widths, dtype=torch.float32),
                                 persistent=False)
            self.register_buffer("_positions", torch.arange(w_max, dtype=torch.float32),
                                 persistent=False)
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

    def forward_gait_features(self, observations: torch.Tensor) -> torch.Tensor:
        """``(batch, R + 2 W)``: the longest legal rotation towards the goal (one-hot over
        the ``R`` rotations that way), then for each regrasp action ``2p + l`` the room
        the grasp it makes leaves for a rotation towards the goal, over ``R`` (0 where the
        regrasp is illegal); with ``best_regrasp`` ``2 W`` more, a one-hot of the legal
        regrasps with the most room (all 0 when none leaves any); see the module
        docstring."""
        lay, R = self.layout, self.rotations
        legal_rot = self._goal_rotations(observations)
        reach = (legal_rot * self._steps).amax(dim=1, keepdim=True)
        longest = legal_rot * (self._steps == reach).to(legal_rot.dtype)
        held = observations[:, 0:3]
        wd = self._widths
        p = torch.round(observations[:, 3:6] * (wd - 1))  # workspace positions (free: < 0)
        h = torch.argmin(held, dim=1, keepdim=True)  # the free finger
        f = (h == 0).long()  # the held fingers f < g
        g = torch.where(h == 2, 1, 2)
        w_h, w_f, w_g = wd[h], wd[f], wd[g]
        p_f, p_g = p.gather(1, f), p.gather(1, g)
        q = self._positions[None, :]  # the free finger's new position
        if self.turn_steps > 0:  # counter-clockwise room: min(W - 1 - p) over the pair
            keep_g = torch.minimum(w_h - 1 - q, w_g - 1 - p_g)
            keep_f = torch.minimum(w_h - 1 - q, w_f - 1 - p_f)
        else:  # clockwise room: min(p) over the pair
            qb = q.expand(p.shape[0], -1)
            keep_g, keep_f = torch.minimum(qb, p_g), torch.minimum(qb, p_f)
        room = torch.stack((keep_g, keep_f), dim=2).reshape(p.shape[0], -1)  # 2p + l
        start = lay.mask.start + 2 * R
        legal_reg = observations[:, start:start + room.shape[1]]
        room = legal_reg * torch.clamp(room, min=0.0) / R
        if not self.best_regrasp:
            return torch.cat((longest, room), dim=1)
        most = room.amax(dim=1, keepdim=True)
        best = ((room == most) & (most > 0)).to(room.dtype)
        return torch.cat((longest, room, best), dim=1)

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
            parts.append(self.forward_gait_features(observations))
        return torch.cat(parts, dim=1)
