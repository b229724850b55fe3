"""``GraspGait-v0``: grasp-gait discovery at map level (thesis ch. 4–6) as a Gymnasium env.

The environment is the discretized gait problem of :class:`graspgait_env.gait.GaitModel`
(states, moves, action layout and legal-move function) with an observation, a reward
made of named terms and episode ends. See :class:`GraspGaitEnv` for the documentation
page; :func:`state_from_observation` recovers the exact gait state from an observation.
The keyword arguments shared by the env family are
:class:`~graspgait_env.envs.config.GraspGaitConfig`.
"""

from __future__ import annotations

import inspect
import math
import os
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from graspgait_env.envs.config import (
    GraspGaitConfig,
    check_mu,
    check_object,
    check_options,
    check_seed,
    env_id_of,
)
from graspgait_env.envs.observation import (
    _ACHIEVED,
    _HELD,
    _PHI,
    _POS,
    _THETA,
    _TO_GO,
    ObservationLayout,
    ObservationParts,
)
from graspgait_env.envs.rows import (
    drop_reversals,
    k_tables,
    line_views,
    regrasps_gained,
    regrasps_opened,
    reward_terms,
    window_at,
    window_views,
    write_lines,
)
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import REGRASP, ROTATE, GaitModel, GaitState
from graspgait_env.planners.exact import RegraspsToGo
from graspgait_env.planners.optimal_moves import OptimalMoves
from graspgait_env.planners.reach import RegraspReach
from graspgait_env.shapes import Shape
from graspgait_env.workspace import Hand

__all__ = [
    "GraspGaitEnv",
    "REWARD_TERMS",
    "ResetNeededError",
    "Visits",
    "drop_revisits",
    "new_visits",
    "regrasp_openings",
    "visit_state",
    "state_from_observation",
]

# Reward terms, in the fixed order in which the reward is summed.
REWARD_TERMS: tuple[str, ...] = ("turn", "regrasp", "rotation", "success", "dead_end", "illegal")

_START_TRIES = 64  # random start draws before scanning all starts for one with a legal move


class ResetNeededError(gym.error.ResetNeeded, RuntimeError):
    """A call that needs an episode (``step``, ``action_masks``, ``state``, ``render``)
    came before the first ``reset()`` (or after a ``reset()`` that raised).

    Both Gymnasium's ``ResetNeeded`` (what ``gymnasium.make``'s order enforcing raises)
    and a ``RuntimeError``.
    """


def draw_start_index(rng: np.random.Generator, n_starts: int,
                     has_move: Callable[[int], bool]) -> int | None:
    """Index of a start grasp drawn as every GraspGait env draws it (*Starting State*).

    A uniform index, redrawn up to ``_START_TRIES`` times while ``has_move(i)`` is False
    (the grasp has no legal move); then a scan of all starts from a uniform offset.
    ``None`` when no start has a legal move. The one definition of the draw: the
    batched env calls it with its own table of ``has_move`` so that a sub-env's starts
    (and every later draw of its generator) are the single env's.
    """
    for _ in range(_START_TRIES):
        i = int(rng.integers(n_starts))
        if has_move(i):
            return i
    off = int(rng.integers(n_starts))
    for t in range(n_starts):
        i = (off + t) % n_starts
        if has_move(i):
            return i
    return None


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


Visits = tuple[dict[tuple[int, ...], set[int]], dict[int, set[tuple[int, ...]]]]
"""The states visited in an episode (``forbid_revisit``), indexed twice: contacts ->
object angles (grid steps) visited with them, and object angle -> contacts."""


def new_visits(k: int, contacts: tuple[int, ...]) -> Visits:
    """The visits of an episode that starts at angle ``k`` with ``contacts``."""
    return {contacts: {k}}, {k: {contacts}}


def visit_state(visits: Visits, k: int, contacts: tuple[int, ...]) -> None:
    """Record a visit of the state ``(k, contacts)`` (``contacts`` a tuple of ints)."""
    visits[0].setdefault(contacts, set()).add(k)
    visits[1].setdefault(k, set()).add(contacts)


def drop_revisits(model: GaitModel, mask: NDArray[np.bool_], k: int,
                  contacts: tuple[int, ...], by_contacts: dict[tuple[int, ...], set[int]],
                  by_angle: dict[int, set[tuple[int, ...]]]) -> None:
    """``forbid_revisit``: clear, in place, the moves of ``mask`` (the legal moves of the
    state ``(k, contacts)``) that lead to a visited state.

    A rotation keeps the contacts and a regrasp the angle, so only the angles visited
    with these contacts and the grasps visited at this angle are looked at, each
    mapped to the one action that reaches it (:meth:`GaitModel.encode`, checked with
    :meth:`GaitModel.apply`); the cost grows with those visits, not with the legal moves.
    """
    s = GaitState(k, contacts)
    near = [GaitState(k2, contacts) for k2 in by_contacts.get(contacts, ()) if k2 != k]
    near += [GaitState(k, c2) for c2 in by_angle.get(k, ()) if c2 != contacts]
    for t in near:
        try:
            a = model.encode(s, t)
        except ValueError:  # no one move reaches it
            continue
        if mask[a] and model.apply(s, a) == t:  # encode reads the moved contact only
            mask[a] = False


def regrasp_openings(model: GaitModel) -> NDArray[np.bool_]:
    """``out[h, c, i]``: some regrasp is legal that keeps held contact ``c`` and places the
    free finger ``h`` in its workspace when the workspace's first grid angle touches
    object contact ``i`` (thesis 4.2: the new pair must be force-closure).

    The regrasp rule of :meth:`GaitModel.action_mask` (contacts ``i .. i + W_h - 1``
    against ``c``, a run of the extended grasp map) reduced to "any" by a running count,
    for every ``c`` and ``i < n``: with the free finger ``h`` at object angle ``k``,
    ``i = (s_h - k) mod n``. Shape ``(3, n, n)``, read-only.
    """
    n = model.n
    rows = model.grasp_map.extended().T[:n]  # rows[c, j]: contact c against contact j mod n
    count = np.zeros((n, rows.shape[1] + 1), dtype=np.int32)
    np.cumsum(rows, axis=1, out=count[:, 1:])
    i = np.arange(n)
    out = np.stack([count[:, i + int(w)] > count[:, i] for w in model.ws_width])
    out.flags.writeable = False
    return out


def _contact_at(model: GaitModel, finger: int, p: int, k: int) -> int:
    """The contact that ``finger`` touches at workspace position ``p`` when the object is at
    ``k``: the contact a regrasp of the (free) finger to position ``p`` places it on,
    as :meth:`GaitModel.decode` computes it (action layout: ``2R + 2p + l``)."""
    probe = GaitState(k, tuple(-1 if i == finger else 0 for i in range(3)))
    return model.decode(probe, 2 * model.R + 2 * p).contact


def state_from_observation(obs: NDArray[np.floating], model: GaitModel,
                           turn_deg: float) -> GaitState:
    """The exact :class:`GaitState` that produced ``obs`` (a GraspGait observation).

    Uses the held one-hot, the workspace positions and the turn achieved, all of which
    encode integers exactly in float32. ``model`` and ``turn_deg`` must be the env's.
    Any ``observation_mode``: a box or flat vector (both begin with the 16 entries of
    the grasp part) or a dict (its ``grasp`` part).
    """
    if isinstance(obs, Mapping):
        obs = obs["grasp"]
    K = model.turn_steps(turn_deg)
    k = int(round(float(obs[_ACHIEVED]) * abs(K))) * (1 if K >= 0 else -1)
    cs = [-1, -1, -1]
    for f in range(3):
        if obs[_HELD + f] > 0.5:
            w = max(int(model.ws_width[f]) - 1, 1)  # the observation's scale, p / (W_f - 1)
            cs[f] = _contact_at(model, f, int(round(float(obs[_POS + f]) * w)), k)
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
    ``info["action_mask"]`` give exactly ``model.action_mask(state)`` (a bool array),
    less, where the opt-in ``forbid_reversal`` and ``forbid_revisit`` are set, the moves
    they forbid (*Arguments*).
    **An illegal action** (a valid index that is not a legal move) leaves the state as it
    is and costs the ``illegal`` reward term; it never raises. An action is a Python
    ``int``, a NumPy integer (what SB3 and Gymnasium vector envs pass) or a 0-d integer
    array (SB3's ``predict`` on one observation); anything else (a float such as ``2.0``,
    a string, ``None``, a bool, a list or a 1-element array) raises ``ValueError``
    (:class:`~graspgait_env.errors.GraspGaitInputError`) naming the value, as does an
    index outside the action space. Bools are refused although Gymnasium's ``Discrete``
    contains ``True``: an action given as a bool is a mask entry passed by mistake.
    ``step`` (and ``action_masks``, ``state``, ``render``) before the first ``reset``
    raises :class:`ResetNeededError` (a ``gymnasium.error.ResetNeeded`` and a
    ``RuntimeError``).

    ## Observation Space

    A flat ``Box(float32)`` of length ``16 + n_actions + cells**2`` (1494 by default;
    ``2 n`` more with ``map_lines``, then ``2 R`` more with ``rotation_lookahead``, then
    ``n_actions x D`` more with ``regrasp_lookahead = D``),
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
    | 16+A+C² ..    | with ``map_lines``: the grasp map's lines    | 0            | 1            |
    | 15+A+C²+2n    | through the grasp (see below), ``2 x n``     |              |              |
    | next ``2R``   | with ``rotation_lookahead``: per rotation    | 0            | 1            |
    |               | action ``a < 2R``, 1 when ``a`` is legal and |              |              |
    |               | a regrasp is legal after it (see below)      |              |              |
    | next ``A D``  | with ``regrasp_lookahead = D``: the reach    | 0            | ``1 + (B +   |
    |               | look-ahead, ``2P x D`` per regrasp action,   |              | Δ) / abs(T)``|
    |               | then ``2R x D`` per rotation (see below)     |              |              |

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

    The **map lines** (``map_lines=True``; off by default) are the grasp map's row and
    column through the present grasp at grid resolution: the regrasps of thesis 4.3,
    horizontal and vertical moves in the map. Line 0 belongs to the lower-numbered held
    finger ``f``, line 1 to the higher ``g``; entry ``j`` is 1 when the held contact and
    the contact that hand-frame angle ``j Δ`` touches now, ``(j - k) mod n``, form a
    force-closure grasp. So the regrasp placing the free finger at workspace position
    ``p`` and keeping ``f`` (``l = 1``) is legal exactly when line 0 is 1 at ``j = s_h +
    p`` (keeping ``g``: line 1); a rotation by ``d`` steps shifts both lines by ``d``,
    so they show which regrasps a rotation would open, over the whole circle.

    The **rotation look-ahead** (``rotation_lookahead=True``; off by default; beyond the
    thesis) answers, for each rotation action, whether the move after it may be a
    regrasp: entry ``a`` (``a < 2R``, the rotation by ``d_a`` grid steps of the *Action
    Space*) is 1 when rotation ``a`` is legal now and the state it leads to, ``(k + d_a,
    same contacts)``, has at least one legal regrasp (either lift), i.e. one step of
    :meth:`GaitModel.action_mask <graspgait_env.gait.GaitModel.action_mask>` looked ahead
    (thesis 5.2 for the rotation, 4.2 for the regrasp). It uses the legal-move function
    only, never the optimum's regrasps to go. Regrasps open only at a few object angles
    of a grasp's rotation range on maps with few force-closure grasps (the hexagon with
    the hand's ball tips: about one legal regrasp per grasp among about 30 legal
    rotations), where a policy that must find those angles by trial rarely regrasps.
    ``GraspGaitMujoco-v1`` computes it from the commanded state, as its header.

    The **reach look-ahead** (``regrasp_lookahead = D``, ``1 ..``
    :data:`~graspgait_env.planners.reach.MAX_REACH_DEPTH` ``+ 1``; off by default;
    beyond the thesis) prices each move by what it leads to, ``D`` regrasps deep. For
    the regrasp action ``2R + 2p + l`` (entries ``D (2p + l) + j``, ``j = 0 .. D - 1``):
    how far short of the turn the grasp it makes stays after the best chain of at most
    ``j`` more regrasps with any rotations between them (grid steps over ``abs(T) / Δ``;
    0: the turn is reached), :meth:`RegraspReach.shortfall
    <graspgait_env.planners.reach.RegraspReach.shortfall>`, a depth-limited search over
    the exact planner's segments. For the rotation action ``a`` (entries ``2 P D + D a
    + j``): the same ``D`` numbers of the regrasp legal after that rotation that falls
    least short at ``j = D - 1``, then ``D - 2``, ... (the regrasps of
    :meth:`GaitModel.action_mask <graspgait_env.gait.GaitModel.action_mask>` at the
    angle it leads to); 0 when the rotation itself reaches the turn (so is a rotation
    followed by a regrasp whose grasp reaches the turn by rotating: the turn to go in
    the header tells them apart). An illegal move (the mask, with ``forbid_reversal``
    and ``forbid_revisit``), or a rotation that opens no regrasp, reads the maximum,
    ``1 + (B + Δ) / abs(T)``. It is built from the grasp map and the workspaces alone
    (one table per object, at construction and, in ``GraspGaitRandom-v0``, at every
    new object): it never contains the optimum's regrasps to go, which at ``D`` below
    that count it cannot tell; the procedural objects need about 9 from a start.
    Measured (``tests/envs/test_regrasp_lookahead.py``): on 20 held-out procedural
    objects, the greedy reading of the field at ``D = 3`` (the move falling least short
    at depth ``D - 1``, then ``D - 2``, ...; a regrasp before a rotation on ties)
    needed 1.03 x the optimum's regrasps.

    With the held fingers, positions and turn achieved the observation determines the
    state exactly: :func:`state_from_observation`.

    **Named parts** (``observation_mode``; :mod:`graspgait_env.envs.observation`). The
    table above is the ``"box"`` observation, the default. ``observation_mode="dict"``
    returns a ``Dict`` of named parts instead: ``grasp`` (entries 0 .. 15 above),
    ``actions`` (``A x F``: per action, whether it is legal and what it leads to, the
    turn achieved and the rotation room towards and against the goal after it, and the
    look-ahead fields' entries of that action where they are on), ``window`` (``C x
    C``) and, with ``map_lines``, ``lines`` (``2 x n``). ``observation_mode="flat"``
    returns that dict flattened into one ``Box`` (``gymnasium.spaces.flatten``), for
    ``MlpPolicy``. ``env.layout.parts`` gives each part's place in the flat vector and
    ``env.layout.action_features`` the columns of ``actions``. The moves, masks and
    rewards are the same in every mode.

    ## Rewards

    The thesis's path metric ``M = αθ - βη - γr`` (5.4: θ the object angle, η regrasps,
    r rotations) paid step by step, plus episode-end terms. Each step's terms are in
    ``info["reward_terms"]`` (a dict, always all six keys, in this order) and the reward
    is their sum, computed in this order (so ``reward == sum(terms.values())`` exactly),
    by one method, ``_reward``, which ``GraspGaitMujoco-v1`` shares:

    | Term        | Value                                                                     |
    |-------------|---------------------------------------------------------------------------|
    | ``turn``    | ``alpha * Δθ* / turn_scale_deg``: turn gained towards the goal (degrees), |
    |             | with θ* = ``min(sigma θ, abs(T))`` so overshoot earns nothing             |
    | ``regrasp`` | ``-beta`` for a regrasp, ``+ to_go_weight * (G0 - G1)`` (below)          |
    | ``rotation``| ``-gamma`` for a rotation                                                 |
    | ``success`` | ``+success_bonus`` on reaching the turn                                   |
    | ``dead_end``| ``-dead_end_penalty`` on a dead end or on passing the wrong-way limit     |
    | ``illegal`` | ``-illegal_penalty`` for an illegal action (no move)                      |

    With ``turn_scale_deg=1`` and ``alpha = beta = gamma = 1`` the first three terms sum
    over an episode to the thesis's ``M`` (the thesis found all equal to 1 satisfactory);
    the defaults scale the turn to 1 for the whole turn and keep β, γ small.

    **Regrasps priced against the optimum** (beyond the thesis; off by default): with
    ``to_go_weight > 0`` each regrasp also earns ``to_go_weight * (G0 - G1)``, where
    ``G`` is the fewest regrasps still needed to reach the turn before (``G0``) and after
    (``G1``) it, the exact planner's count
    (:class:`~graspgait_env.planners.exact.RegraspsToGo`, one table per object, built at
    construction and, in ``GraspGaitRandom-v0``, at every reset). A regrasp of an
    optimal gait gains 1; one that gains nothing or leads away earns 0 or less. Over a
    successful episode these sum to ``to_go_weight * G(start)`` whatever the path (a
    potential-based shaping, Ng et al. 1999), so the optimum's count only guides
    learning: what a wasted regrasp costs is still ``beta`` and the discount. It never
    enters the observation. From a grasp with no gait ``G`` is undefined and the
    extra term is 0.

    ## Starting State

    θ = 0 and a grasp drawn uniformly by ``self.np_random`` from
    ``model.start_states()`` (every legal two-finger grasp at θ = 0) among those with at
    least one legal move. No check is made that a gait exists from it: on objects where
    none does (e.g. the triangle at mu = 0.7), episodes end in dead ends or at the time
    limit. ``reset(options={"start": {1: 50.0, 3: 270.0}})`` (finger number → contact in
    degrees, or a :class:`GaitState` at k = 0) starts from a given grasp. ``"start"`` is
    the only option; an unknown key raises ``ValueError`` naming it. ``seed`` is None or
    an integer >= 0 (a NumPy integer is taken as its value; a bool is refused).

    ## Episode End

    - **Success** (terminated, ``info["is_success"] = True``): the object has turned
      ``turn_deg`` (``sigma θ >= abs(T)``).
    - **Dead end** (terminated, ``is_success = False``): no legal move remains. (Every
      thesis move can be undone, so with ``GaitModel``'s moves this cannot follow a legal
      move; starts without a legal move are never drawn. With ``forbid_reversal`` it
      can: a rotation to an angle where no regrasp is legal and only rotations back
      are; with ``forbid_revisit`` too: every move leads to a state of this episode.)
    - **Wrong way** (terminated, ``is_success = False``): the object has turned more
      than ``max_backward_deg`` against the goal (bounds the observation; the gait graph
      repeats every 360°, so nothing is lost beyond one full turn back).
    - **Truncation**: only by ``gymnasium.make``'s ``TimeLimit`` (``max_episode_steps``
      of the registration, 500); ``step`` itself never truncates.

    ## Arguments

    ``gymnasium.make("graspgait_env:GraspGait-v0", object="ellipse", mu=0.7, *,
    config=None, render_mode=None, **fields)``, where ``fields`` are those of
    :class:`~graspgait_env.envs.config.GraspGaitConfig` (each documented there, with its
    units): ``hand=None, turn_deg=360.0, n=180, alpha=1.0, beta=0.01, gamma=0.01,
    turn_scale_deg=None, success_bonus=1.0, dead_end_penalty=1.0, illegal_penalty=0.1,
    to_go_weight=0.0, max_backward_deg=360.0, map_window_deg=360.0, map_window_cells=36,
    map_lines=False, contact_model="point", rotation_lookahead=False,
    regrasp_lookahead=0, forbid_reversal=False, forbid_revisit=False``.

    - ``object``: bundled name (``"ellipse"``, the thesis's fig. 5.3 ellipse), YAML path
      or :class:`~graspgait_env.shapes.Shape`.
    - ``mu``: Coulomb friction (> 0).
    - ``config``: a :class:`~graspgait_env.envs.config.GraspGaitConfig`; keyword
      ``fields`` given as well replace its values.
    - ``hand``: bundled hand name, YAML path or :class:`~graspgait_env.workspace.Hand`
      (default: thesis fig. 4.1); ``turn_deg``: requested turn (sign = direction);
      ``n``: grid size.
    - ``alpha, beta, gamma, turn_scale_deg`` (default ``abs(turn_deg)``),
      ``success_bonus, dead_end_penalty, illegal_penalty, to_go_weight``: reward
      weights (above).
    - ``max_backward_deg``: wrong-way limit (above).
    - ``map_window_deg, map_window_cells``: span and resolution of the grasp-map window.
    - ``map_lines``: append the grasp map's two lines through the grasp (above).
    - ``contact_model``: ``"point"`` (the thesis's) or ``"hand"`` (the simulated hand's
      ball tips; see :class:`~graspgait_env.envs.config.GraspGaitConfig`).
    - ``rotation_lookahead``: append the rotation look-ahead (above).
    - ``regrasp_lookahead``: append the reach look-ahead ``D`` regrasps deep (above).
    - ``forbid_reversal``: after a rotation, no rotation the other way until the next
      regrasp (:class:`~graspgait_env.envs.config.GraspGaitConfig`; the legal actions are
      then ``model.action_mask`` less those rotations).
    - ``forbid_revisit``: no move to a state (object angle and contacts) already visited
      in this episode (:class:`~graspgait_env.envs.config.GraspGaitConfig`; a
      deterministic policy cannot cycle; the fewest regrasps from the start are
      unchanged).
    - ``render_mode``: ``"rgb_array"`` returns a ``(480, 640, 3)`` uint8 frame: the
      object in the workspace frame with the three workspaces and the fingers, and the
      extended grasp map (finger pair boxes at the present θ) with the gait so far
      (:class:`~graspgait_env.envs.render.GaitFrames`: the fixed parts are drawn once
      per model, a frame costs a few ms). ``"human"`` shows the same frame in a
      matplotlib window when an interactive backend is available; headless (Agg
      backend, no display) it shows nothing and warns once. One frame per move:
      ``metadata["render_fps"]`` (4) is the rate of human mode and of a video recorded
      with Gymnasium's ``RecordVideo``, four moves per second.

    Every argument is checked at construction: a bad value raises ``ValueError``
    (:class:`~graspgait_env.errors.GraspGaitInputError`) naming it, the value and the
    fix (``mu='abc': must be a finite number > 0, e.g. 0.7``); a misspelled keyword
    raises naming it and listing the valid ones. The config is ``env.config``; each of
    its fields also reads as a read-only attribute (``env.beta``); ``env.turn_scale_deg``
    and ``env.hand`` are resolved (``abs(turn_deg)`` when None; the loaded
    :class:`~graspgait_env.workspace.Hand`).

    ## Version History

    - v0: initial version. Opt-in fields added since, each off by default (tested), so
      the defaults behave as before: ``to_go_weight``, ``map_lines``,
      ``contact_model``, ``rotation_lookahead``, ``forbid_reversal``,
      ``forbid_revisit``, ``regrasp_lookahead``, and ``observation_mode`` (named parts;
      the default ``"box"`` is the observation as before).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array"],
                                          "render_fps": 4}
    _RESET_OPTIONS: ClassVar[tuple[str, ...]] = ("start",)  # reset(options=...) keys
    _ARG_HINTS: ClassVar[dict[str, str]] = {}  # advice for a keyword that is not an argument

    def __init__(
        self,
        object: str | os.PathLike | Shape = "ellipse",  # noqa: A002 - the user-facing name
        mu: float = 0.7,
        *,
        config: GraspGaitConfig | None = None,
        render_mode: str | None = None,
        **fields: Any,
    ) -> None:
        self._configure(config, render_mode, fields)
        obj = check_object(object)
        self._use_model(GaitModel(obj, check_mu(mu), self.config.hand, self.config.n,
                                  contact_model=self._planning_contact_model(obj)))
        self._make_spaces()

    def _planning_contact_model(self, object: str | os.PathLike | Shape):  # noqa: A002
        """The grasp maps' contact model: ``config.contact_model`` for ``object``."""
        return self.config.planning_contact_model(object)

    # ------------------------------------------------------------------ set-up
    def _configure(self, config: GraspGaitConfig | None, render_mode: str | None,
                   fields: Mapping[str, Any]) -> None:
        """Check and store the config (``config`` with ``fields`` replaced) and the
        render mode; the env needs ``reset()`` before ``step``."""
        owner = env_id_of(type(self))
        params = inspect.signature(type(self).__init__).parameters.values()
        own = [p.name for p in params if p.name != "self"
               and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]
        self.config = GraspGaitConfig.merged(config, fields, owner=owner, other_args=own,
                                             hints=self._ARG_HINTS)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise GraspGaitInputError(
                f"render_mode={render_mode!r}: use None, "
                f"{' or '.join(map(repr, self.metadata['render_modes']))}")
        self.render_mode = render_mode
        self._renderer = None  # render.GaitRenderer, made by the first human-mode render()
        self._frames = None  # render.GaitFrames of the present model, made by render()
        self._mask: NDArray[np.bool_] | None = None  # None: reset() needed
        self.model: GaitModel

    @property
    def turn_scale_deg(self) -> float:
        """Degrees of turn that earn ``alpha``: ``config.turn_scale_deg`` or ``abs(turn_deg)``."""
        return self.config.turn_scale

    @property
    def hand(self) -> Hand:
        """The hand (loaded: a :class:`~graspgait_env.workspace.Hand`; ``config.hand`` is
        what was given)."""
        return self.model.hand

    def _use_model(self, model: GaitModel) -> None:
        """Bind a gait model: precompute every per-model table that ``step`` reads."""
        cfg = self.config
        self.model = model
        n = model.n
        self._n = n
        self._A = int(model.n_actions)
        # observation scale of a workspace position: p / (W_f - 1)
        self._inv_w = [1.0 / max(int(w) - 1, 1) for w in model.ws_width]
        self._step_deg = model.step_deg
        self._K = model.turn_steps(cfg.turn_deg)
        self._sign = 1 if self._K > 0 else -1
        self._Kabs = abs(self._K)
        if self._Kabs == 0:
            raise GraspGaitInputError(
                f"turn_deg={cfg.turn_deg!r}: rounds to no grid step at n={n}; ask for at "
                f"least {self._step_deg:g} degrees")
        self._back = model.turn_steps(cfg.max_backward_deg)
        self._turn_coef = cfg.alpha * self._step_deg / cfg.turn_scale
        # turn_deg, max_backward_deg: the per-angle tables (rows.k_tables, shared with the
        # batched env), and their columns as lists for this env's scalar step
        kt = self._kt = k_tables(self._sign, self._Kabs, self._back, int(model.R), n)
        self._k_reached = kt.reached.tolist()
        self._k_success = kt.success.tolist()
        self._k_ends = kt.ends.tolist()
        # GaitModel.decode of every rotation (a rotation's delta does not depend on the
        # state, so it is decoded once per model; 0: the action is a regrasp)
        probe = GaitState(0, (0, 0, -1))
        self._delta = [m.delta if m.kind == ROTATE else 0
                       for m in (model.decode(probe, a) for a in range(self._A))]
        phi = 2.0 * math.pi * np.arange(n) / n
        self._cos = np.cos(phi).tolist()
        self._sin = np.sin(phi).tolist()
        cells = cfg.map_window_cells
        s = cfg.window_stride()
        self._stride = s
        self._win_back = s * (cells // 2) + s // 2
        self._pooled = _pooled_map(model.stable, s)
        self._windows = window_views(self._pooled, s, cells)  # rows.window_at reads it
        # map_lines: the map's rows tiled twice, a held contact's line at angle k one
        # slice of it (rows.write_lines reads the views)
        self._line_src = (np.tile(model.stable, (1, 2)).astype(np.float32)
                          if cfg.map_lines else None)
        self._lines = line_views(self._line_src, n)
        # rotation_lookahead: which rotations open a regrasp (thesis 4.2, 5.2), per model
        self._openings = regrasp_openings(model) if cfg.rotation_lookahead else None
        self._rot_delta = np.asarray(self._delta[:2 * model.R], dtype=np.int64)
        self._ws_start = [int(x) for x in model.ws_start]
        self._ws_start_a = np.asarray(self._ws_start, dtype=np.int64)
        self._starts: list[GaitState] | None = None
        # regrasps to go from every state (the exact optimum's count; only when rewarded)
        self._to_go = (RegraspsToGo(model, cfg.turn_deg, cfg.max_backward_deg)
                       if cfg.to_go_weight > 0 else None)
        # regrasp_lookahead: the reach tables, D - 1 regrasps beyond the action's own
        self._reach = (RegraspReach(model, cfg.turn_deg, cfg.max_backward_deg,
                                    cfg.regrasp_lookahead - 1)
                       if cfg.regrasp_lookahead else None)
        self._gained = 0  # regrasps gained towards the goal by the move rewarded (_reward)
        self._optimal: OptimalMoves | None = None  # built by optimal_moves() when asked

    def _make_spaces(self) -> None:
        A, C = self._A, self.config.map_window_cells
        D, R2 = self.config.regrasp_lookahead, 2 * int(self.model.R)
        self.layout = ObservationLayout(A, C, self._n if self.config.map_lines else 0,
                                        R2 if self.config.rotation_lookahead else 0,
                                        (2 * int(self.model.P) + R2) * D)
        lo = np.zeros(self.layout.size, dtype=np.float64)
        hi = np.ones(self.layout.size, dtype=np.float64)
        lo[_POS:_THETA + 2] = -1.0
        R, K, B = int(self.model.R), self._Kabs, self._back  # R: the longest rotation
        lo[_ACHIEVED], hi[_ACHIEVED] = -(B + R) / K, (K + R) / K
        lo[_TO_GO], hi[_TO_GO] = 0.0, (K + B + R) / K
        hi[self.layout.reach] = (K + B + 1) / K  # the reach look-ahead's "none" (below)
        self.box_space = spaces.Box(lo.astype(np.float32), hi.astype(np.float32),
                                    dtype=np.float32)
        mode = self.config.observation_mode
        # observation_mode "dict" / "flat": the named parts, from the box vector
        self._parts = (None if mode == "box" else ObservationParts(
            self.layout, self.box_space, np.asarray(self.model.ws_width), self._rot_delta,
            self._sign, self._Kabs, mode))
        self.observation_space = (self.box_space if self._parts is None
                                  else self._parts.space)
        self.action_space = spaces.Discrete(A)
        self._obs = np.zeros(self.layout.size, dtype=np.float32)
        self._make_views()

    def _make_views(self) -> None:
        """Views of the box vector ``_obs`` that the step writes into (the rows
        functions take batches: the lines and the look-ahead as rows of one)."""
        C = self.config.map_window_cells
        self._win_view = self._obs[self.layout.window].reshape(C, C)
        self._mask_view = self._obs[self.layout.mask]
        self._line_view = self._obs[None, self.layout.lines].reshape(1, -1, self._n)
        self._look_view = self._obs[None, self.layout.lookahead]
        self._reach_view = self._obs[self.layout.reach]

    def _check_model_fits(self, model: GaitModel) -> None:
        if int(model.n_actions) != self.action_space.n or model.n != self._n:
            raise GraspGaitInputError(
                f"object {model.shape.name!r}: its gait model has {model.n_actions} actions "
                f"at n={model.n}, the env's spaces {self.action_space.n} at n={self._n}; "
                "keep n and the hand's workspaces fixed")

    # ------------------------------------------------------------------ state
    def _reset_needed(self, what: str) -> ResetNeededError:
        return ResetNeededError(f"{what}: call reset() first (no episode has started, or "
                                "the last reset() raised)")

    @property
    def state(self) -> GaitState:
        """The present gait state ``(k, contacts)`` (a fresh tuple)."""
        if self._mask is None:
            raise self._reset_needed("state")
        return GaitState(self._k, self._c)

    def action_masks(self) -> NDArray[np.bool_]:
        """Legal actions of the present state (sb3-contrib MaskablePPO protocol).

        Exactly ``self.model.action_mask(self.state)``. A fresh array per step; do not
        write into it.

        Raises
        ------
        ResetNeededError
            Before the first ``reset()``.
        """
        mask = self._mask
        if mask is None:
            raise self._reset_needed("action_masks")
        return mask

    def optimal_moves(self) -> NDArray[np.bool_]:
        """The legal moves of the present state that begin a fewest-regrasp gait (the
        exact optimum read per state, :class:`~graspgait_env.planners.optimal_moves.
        OptimalMoves`), as a mask over the actions: the teacher of imitation learning.

        The planner's set less what this env forbids (``forbid_reversal``,
        ``forbid_revisit``), so it can be empty where the episode's own rules block the
        optimum, and is empty when no gait reaches the turn from here. The tables are
        built for each model on the first call (the regrasps-to-go table is shared with
        ``to_go_weight``'s); the observation and the reward do not change.

        Raises
        ------
        ResetNeededError
            Before the first ``reset()``.
        """
        mask = self.action_masks()
        if self._optimal is None or self._optimal.model is not self.model:
            cfg = self.config
            self._optimal = OptimalMoves(self.model, cfg.turn_deg, cfg.max_backward_deg,
                                         to_go=self._to_go)
        return self._optimal(GaitState(self._k, self._c)) & mask

    def _set_state(self, s: GaitState) -> None:
        self._k = k = int(s.k)
        self._c = c = tuple(int(x) for x in s.contacts)  # contacts, a tuple (-1: free)
        self._f, self._g = s.held()
        self._h = 3 - self._f - self._g  # the free finger
        # workspace position of each finger's contact (GaitModel.position; -1: free)
        self._p = [self.model.position(f, c[f], k) if c[f] >= 0 else -1 for f in range(3)]
        self._last_turn = 0  # sign of the last move if a rotation, else 0 (forbid_reversal)
        # forbid_revisit: the states visited this episode (visit_state's two indexes)
        self._visited = new_visits(self._k, self._c) if self.config.forbid_revisit else None

    def _compute_mask(self) -> NDArray[np.bool_]:
        """The legal moves of the present state: ``model.action_mask`` (THE legal-move
        function; a fresh array each call), less, with ``forbid_reversal``, the rotations
        against the last move when it was a rotation."""
        mask = self.model.action_mask(GaitState(self._k, self._c))
        if self._last_turn and self.config.forbid_reversal:  # a batch of one
            drop_reversals(mask[None], np.array([self._last_turn]), int(self.model.R))
        if self._visited is not None:
            drop_revisits(self.model, mask, self._k, self._c, *self._visited)
        return mask

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
        n, wb = self._n, self._win_back
        self._win_view[...] = window_at(self._windows, (c[self._f] - wb) % n,
                                        (c[self._g] - wb) % n)

    def _write_motion(self) -> None:
        """Observation entries that change with every move."""
        o, f, g, k = self._obs, self._f, self._g, self._k
        o[_POS + f] = self._p[f] * self._inv_w[f]
        o[_POS + g] = self._p[g] * self._inv_w[g]
        # cos theta, sin theta, turn achieved and to go: one row of the k tables
        o[_THETA:_TO_GO + 1] = self._kt.head[k - self._kt.lo]
        self._mask_view[...] = self._mask
        if self._lines is not None or self._openings is not None:  # a batch of one
            cf, cg, kk = (np.array([x]) for x in (self._c[f], self._c[g], k))
            if self._lines is not None:  # map_lines (thesis 4.3)
                write_lines(self._line_view, self._lines, cf, cg, kk)
            if self._openings is not None:  # rotation_lookahead (thesis 4.2, 5.2)
                self._look_view[...] = regrasps_opened(
                    self._openings, np.array([self._h]), cf, cg, kk, self._ws_start_a,
                    self._rot_delta, self._n, self._mask[None, :self._rot_delta.size])
        if self._reach is not None:
            self._reach_view[...] = self._reach.move_shortfalls(
                self._h, f, g, self._p[f], self._p[g], k, self._mask, self._rot_delta)

    def _observe(self) -> Any:
        """The observation of the present state in the config's ``observation_mode``: a
        copy of the box vector, or its named parts (:class:`ObservationParts`, a batch
        of one)."""
        if self._parts is None:
            return self._obs.copy()
        def one(x: int) -> NDArray[np.int64]:
            return np.array([x], dtype=np.int64)

        out = self._parts.observe(self._obs[None], one(self._k), one(self._f), one(self._g),
                                  one(self._h), one(self._p[self._f]), one(self._p[self._g]))
        if isinstance(out, dict):
            return {name: v[0] for name, v in out.items()}
        return out[0]

    # ------------------------------------------------------------------ reward
    def _reward(self, k0: int, k1: int, move: str | None, ends: bool,
                is_success: bool) -> tuple[float, dict[str, float]]:
        """The reward of one step and its named terms (the *Rewards* table).

        Parameters
        ----------
        k0, k1
            Object angle before and after the step (grid steps).
        move
            :data:`~graspgait_env.gait.ROTATE` or :data:`~graspgait_env.gait.REGRASP`
            (the gait module's constants: the move made, or attempted and failed in
            physics), ``None`` for an illegal action (a no-op).
        ends
            The episode ends at this step for the first time (pays ``success`` or
            ``dead_end``).
        is_success
            The turn is reached.

        Returns
        -------
        reward, terms
            ``terms`` in :data:`REWARD_TERMS` order; ``reward`` is their sum in that
            order, so ``reward == sum(terms.values())`` exactly.
        """
        lo, reached = self._kt.lo, self._k_reached
        gained = 0
        if move is REGRASP and self._to_go is not None:  # priced against the optimum
            gained = self._gained
            self._gained = 0  # a regrasp whose outcome step() did not set gains nothing
        # thesis 5.4 and the episode-end terms: the one implementation (rows.reward_terms)
        turn, regrasp, rotation, success, dead_end, illegal = reward_terms(
            self.config, self._turn_coef, reached[k0 - lo], reached[k1 - lo],
            move is REGRASP, move is ROTATE, move is None, ends, is_success, gained)
        reward = turn + regrasp + rotation + success + dead_end + illegal
        return reward, {"turn": turn, "regrasp": regrasp, "rotation": rotation,
                        "success": success, "dead_end": dead_end, "illegal": illegal}

    # ------------------------------------------------------------------ API
    def _on_reset(self, options: Mapping[str, Any]) -> GaitState | None:
        """Hook for subclasses: choose the model for the new episode (here: keep it).

        May return a start state already drawn for the new model (else ``None``).
        """
        return None

    def _draw_start(self) -> GaitState:
        if self._starts is None:
            self._starts = self.model.start_states()
        starts = self._starts
        if not starts:
            raise GraspGaitInputError(
                f"object {self.model.shape.name!r} at mu={self.model.mu:g}: no legal grasp at "
                "theta = 0 with this hand; raise mu or change the hand")
        def has_move(i: int) -> bool:
            self._set_state(starts[i])
            return bool(self._compute_mask().any())

        i = draw_start_index(self.np_random, len(starts), has_move)
        if i is not None:
            return starts[i]
        raise GraspGaitInputError(
            f"object {self.model.shape.name!r} at mu={self.model.mu:g}: every legal start "
            f"grasp ({len(starts)}) is a dead end; raise mu or change the hand")

    def _parse_start(self, start: Any) -> GaitState:
        fix = ("give {finger: phi_deg} for two fingers, e.g. {1: 50.0, 3: 270.0}, or a "
               "GaitState at k = 0")
        if isinstance(start, GaitState):
            try:
                s = GaitState(int(start.k), tuple(int(c) for c in start.contacts))
            except (TypeError, ValueError):
                raise GraspGaitInputError(f"options['start']={start!r}: {fix}") from None
            if s.k != 0 or not self.model.is_legal_state(s):
                raise GraspGaitInputError(
                    f"options['start']={start!r}: must be a legal state at k = 0")
            return s
        if isinstance(start, Mapping):
            try:
                contacts = {int(f): float(v) for f, v in start.items()}
            except (TypeError, ValueError):
                raise GraspGaitInputError(f"options['start']={start!r}: {fix}") from None
            try:
                return self.model.start_state(contacts)
            except GraspGaitInputError as exc:
                raise GraspGaitInputError(f"options['start']={start!r}: {exc}") from None
        raise GraspGaitInputError(f"options['start']={start!r}: {fix}")

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[NDArray[np.float32], dict]:
        """Start an episode at θ = 0 (see *Starting State*); returns ``(obs, info)``.

        Raises
        ------
        GraspGaitInputError
            A bad ``seed``, an unknown option or a bad start grasp (the message names
            it); the env then needs another ``reset()`` before ``step``.
        """
        seed = check_seed(seed)
        options = check_options(options, self._RESET_OPTIONS, env_id_of(type(self)))
        self._mask = None  # until this reset succeeds
        super().reset(seed=seed)
        s = self._on_reset(options)
        start = options.get("start")
        if start is not None:
            s = self._parse_start(start)
        elif s is None:
            s = self._draw_start()
        self._set_state(s)
        mask = self._compute_mask()
        if not mask.any():
            raise GraspGaitInputError(
                f"options['start']={start!r}: this grasp has no legal move")
        self._mask = mask
        self._regrasps = 0
        self._rotations = 0
        self._terminal = False
        self._togo_now = -1 if self._to_go is None else self._to_go(s)
        self._trail: list[tuple[int, tuple[int, ...]]] = [(self._k, self._c)]
        self._write_grasp()
        self._write_motion()
        info = {"action_mask": self._mask, "is_success": False, "turn_deg": 0.0,
                "regrasps": 0, "object": self.model.shape.name, "mu": self.model.mu}
        if self.render_mode == "human":
            self.render()
        return self._observe(), info

    def _action_index(self, action: Any) -> int:
        """``action`` as an index into the action space (see *Action Space*), or raise."""
        if self._mask is None:
            raise self._reset_needed("step")
        t = type(action)
        if t is int or t is np.int64:  # the common cases first: a Python int, SB3's int64
            a = int(action)
        elif (isinstance(action, (int, np.integer))
              and not isinstance(action, (bool, np.bool_))):
            a = int(action)
        elif isinstance(action, np.ndarray) and action.shape == () and action.dtype.kind in "iu":
            a = int(action)
        else:
            why = ("a bool is not an action index" if isinstance(action, (bool, np.bool_))
                   else "must be an integer action index (a Python int, a NumPy integer or a "
                   "0-d integer array)")
            raise GraspGaitInputError(
                f"action={action!r}: {why}; give an integer in 0..{self._A - 1}, e.g. "
                "int(np.flatnonzero(info['action_mask'])[0])")
        if not 0 <= a < self._A:
            raise GraspGaitInputError(
                f"action={action!r}: outside the action space 0..{self._A - 1}")
        return a

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict]:
        """Apply one move; see the class docstring for actions, rewards and episode ends."""
        t = type(action)
        if (t is int or t is np.int64) and self._mask is not None:
            a = int(action)  # the common case (SB3 and vector envs pass NumPy int64)
            if not 0 <= a < self._A:
                a = self._action_index(action)  # raises, naming the action
        else:
            a = self._action_index(action)
        k0 = self._k
        if self._mask[a]:
            d = self._delta[a]
            if d:  # rotate by d grid steps: the contacts stay, each moves d through its workspace
                move = ROTATE
                self._k = k0 + d
                self._p[self._f] += d
                self._p[self._g] += d
                self._rotations += 1
                self._last_turn = 1 if d > 0 else -1
            else:  # regrasp: the free finger to m.contact, m.lifted lifted (GaitModel.decode)
                move = REGRASP
                m = self.model.decode(GaitState(k0, self._c), a)
                h, lifted = m.finger, m.lifted
                kept = self._f + self._g - lifted
                c = list(self._c)
                c[h] = m.contact
                c[lifted] = -1
                self._c = tuple(c)
                self._p[h] = self.model.position(h, m.contact, k0)
                self._p[lifted] = -1
                self._f, self._g = (h, kept) if h < kept else (kept, h)
                self._h = lifted
                self._regrasps += 1
                self._last_turn = 0
                self._write_grasp()
                if self._to_go is not None:  # to_go_weight, a batch of one
                    gained, now = regrasps_gained([self._to_go], np.array([self._togo_now]),
                                                  np.array([k0]), np.array([self._c]))
                    self._gained, self._togo_now = int(gained[0]), int(now[0])
            if self._visited is not None:
                visit_state(self._visited, self._k, self._c)
            self._mask = self._compute_mask()
            self._write_motion()
            if self.render_mode is not None:
                self._trail.append((self._k, self._c))
        else:
            move = None
            self._mask = self._mask.copy()  # every info gets its own array
        ki = self._k - self._kt.lo  # turn_deg, max_backward_deg: the k tables
        is_success = self._k_success[ki]
        terminated = self._k_ends[ki] or not self._mask.any()
        reward, terms = self._reward(k0, self._k, move, terminated and not self._terminal,
                                     is_success)
        self._terminal = terminated
        info = {
            "action_mask": self._mask,
            "reward_terms": terms,
            "is_success": is_success,
            "turn_deg": self._k * self._step_deg,
            "regrasps": self._regrasps,
        }
        if self.render_mode == "human":
            self.render()
        return self._observe(), reward, terminated, False, info

    # ------------------------------------------------------------------ rendering
    def render(self) -> NDArray[np.uint8] | None:
        """``rgb_array``: the frame as ``(H, W, 3)`` uint8; ``human``: show it (or no-op)."""
        if self.render_mode is None:
            gym.logger.warn(
                "You are calling render method without specifying any render mode. "
                "Set render_mode='rgb_array' or 'human' at construction, e.g. "
                'gymnasium.make("graspgait_env:GraspGait-v0", render_mode="rgb_array")')
            return None
        if self._mask is None:
            raise self._reset_needed("render")
        if self.render_mode == "rgb_array":
            return self._frame()
        if self._renderer is None:
            from graspgait_env.envs.render import GaitRenderer

            self._renderer = GaitRenderer(self.metadata["render_fps"])
        self._renderer.show(self._frame)
        return None

    def _frame(self) -> NDArray[np.uint8]:
        """The present frame (see ``render_mode``), drawn by a
        :class:`~graspgait_env.envs.render.GaitFrames` kept for the present model."""
        frames = getattr(self, "_frames", None)
        if frames is None or frames.model is not self.model:
            from graspgait_env.envs.render import GaitFrames

            frames = self._frames = GaitFrames(self.model)
        return frames.frame(self._trail, self.config.turn_deg, self._regrasps)

    def close(self) -> None:
        """Close the human-mode window, if any (idempotent)."""
        if self._renderer is not None:
            self._renderer.close()

    def __getstate__(self) -> dict[str, Any]:
        d = self.__dict__.copy()
        d.pop("_win_view", None)  # views into _obs, rebuilt on unpickling
        d.pop("_mask_view", None)
        d.pop("_line_view", None)
        d.pop("_look_view", None)
        d.pop("_reach_view", None)
        return d

    def __setstate__(self, d: dict[str, Any]) -> None:
        self.__dict__.update(d)
        self._make_views()


def _config_property(name: str) -> property:
    return property(lambda self: getattr(self.config, name),
                    doc=f"``config.{name}`` (read-only; see :class:`GraspGaitConfig`).")


# Every config field reads as an attribute of the env (``env.beta``), read-only, from the
# one list of fields; ``hand`` and ``turn_scale_deg`` are resolved properties above.
for _name in GraspGaitConfig.field_names():
    if _name not in vars(GraspGaitEnv):
        setattr(GraspGaitEnv, _name, _config_property(_name))
del _name
