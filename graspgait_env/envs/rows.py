"""What one ``GraspGait`` step computes for each config field, over a batch of rows.

Each function here is the one implementation of a config field's effect on a step, for
``N`` gait problems (rows) at once: :class:`~graspgait_env.envs.map_env.GraspGaitEnv`
calls it with its one row (a batch of one), :class:`~graspgait_env.envs.vector_env.
GraspGaitVectorEnv` with its ``N`` rows, and the per-object batched env
(``GraspGaitRandom-v0``) with each row's own tables. A field is thus written once and
works in both forms:

| config field | its one implementation |
|---|---|
| ``alpha``, ``beta``, ``gamma`` | :func:`reward_terms` (thesis 5.4's path metric) |
| ``turn_scale_deg`` | :func:`reward_terms` |
| ``success_bonus``, ``dead_end_penalty`` | :func:`reward_terms` (the episode-end |
| | terms) |
| ``illegal_penalty`` | :func:`reward_terms` |
| ``to_go_weight`` | :func:`regrasps_gained`, then :func:`reward_terms` |
| ``turn_deg``, ``max_backward_deg`` | :func:`k_tables` (turn achieved and to go, |
| | success, the wrong-way end) |
| ``map_window_deg``, ``map_window_cells`` | :func:`window_views`, :func:`window_at` |
| ``map_lines`` | :func:`line_views`, :func:`write_lines` |
| ``rotation_lookahead`` | :func:`regrasps_opened` |
| ``regrasp_lookahead`` | the reach look-ahead of a batch, |
| | :meth:`~graspgait_env.planners.reach.RegraspReach.move_shortfalls_batch` |
| ``forbid_reversal`` | :func:`drop_reversals` |
| ``forbid_revisit`` | :func:`~graspgait_env.envs.map_env.drop_revisits`, |
| | :func:`~graspgait_env.envs.map_env.visit_state` (a set per row) |
| ``observation_mode`` | :class:`~graspgait_env.envs.observation.ObservationParts` |
| ``hand``, ``n``, ``contact_model`` | the gait model and its tables, built once by |
| | the single env and shared by the batched env's rows |

What is not a field, the thesis's move itself (a rotation moves both contacts through
their workspaces, a regrasp places the free finger and lifts one, thesis 4.2 and 5.2)
and its legal-move rule (``GaitModel.action_mask``), is written twice: as Python
scalars in the single env, whose step keeps the speed of plain Python, and as arrays in
the batched env. A batch of one through the NumPy step is several times slower (a NumPy
call costs about a microsecond whatever its size): measured 2026-12-04 on the 2-core
machine, 43,292 steps/s for the single env against 9,678 for the batched env at ``N =
1`` (4.5x; ``graspgait perf``, the row "GraspGait-v0 single env / batched N=1"), which
would put the single env at about 0.14x CartPole-v1's steps/s, below the 0.3x it keeps.
The equality tests with ``SyncVectorEnv`` hold the two together over every field.

Shapes: ``N`` rows, ``A`` actions, ``R`` rotations per direction, ``n`` grid points
per turn. Angles are grid steps (``360 / n`` degrees each), contacts grid indices on
the object (-1: a free finger), positions workspace grid indices.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["KTables", "drop_reversals", "grasp_map_runs", "k_tables", "line_views",
           "regrasps_gained", "regrasps_opened", "reward_terms", "window_at",
           "window_views", "write_lines"]


class KTables(NamedTuple):
    """What depends on the object angle ``k`` alone, one entry per ``k`` from ``lo``:
    read entry ``k - lo``.

    Attributes
    ----------
    lo
        The least ``k`` tabled (negative).
    head
        ``(S, 4)`` float32: the observation's ``cos θ, sin θ``, turn achieved
        ``σk / |K|`` and turn to go ``max(0, |K| - σk) / |K|``.
    reached
        ``(S,)`` int64: ``min(σk, |K|)``, the turn towards the goal that counts (θ* of
        thesis 5.4; overshoot earns nothing).
    success, ends
        ``(S,)`` bool: the turn is reached (``σk >= |K|``); the episode ends
        (success, or ``σk < -B``, the wrong way).
    """

    lo: int
    head: NDArray[np.float32]
    reached: NDArray[np.int64]
    success: NDArray[np.bool_]
    ends: NDArray[np.bool_]


def k_tables(sign: int, K: int, back: int, R: int, n: int) -> KTables:
    """The per-angle tables of a turn of ``sign * K`` grid steps (``turn_deg``).

    Parameters
    ----------
    sign, K
        The turn's direction (+1 counter-clockwise, -1 clockwise) and size in grid
        steps (``K >= 1``).
    back
        ``max_backward_deg`` in grid steps: the episode ends once ``σk < -back``.
    R
        The longest rotation (grid steps): one move turns at most ``R``, so ``k`` stays
        within ``K + back + R`` of 0 and the tables span that.
    n
        Grid points per turn (``θ = k mod n``).
    """
    span = K + back + R + 1
    k = np.arange(-span, span + 1, dtype=np.int64)
    t = sign * k
    phi = 2.0 * np.pi * (k % n) / n
    head = np.empty((k.size, 4), dtype=np.float32)
    head[:, 0] = np.cos(phi)
    head[:, 1] = np.sin(phi)
    head[:, 2] = t / K
    head[:, 3] = np.maximum(0, K - t) / K
    success = t >= K
    return KTables(-span, head, np.minimum(t, K), success, success | (t < -back))


def reward_terms(cfg: Any, turn_coef: float, reached0: Any, reached1: Any, regrasp: Any,
                 rotation: Any, illegal: Any, ends: Any, success: Any,
                 gained: Any = 0) -> tuple[Any, Any, Any, Any, Any, Any]:
    """The six reward terms of a step (``REWARD_TERMS`` order), for one row or ``N``.

    Every argument after ``turn_coef`` is a Python scalar (one row) or an ``(N,)``
    array (the batch); the terms come back in the same form, so the single and the
    batched env sum the same numbers in the same order, and are equal to the last bit.

    Parameters
    ----------
    cfg
        The :class:`~graspgait_env.envs.config.GraspGaitConfig` (``beta``, ``gamma``,
        ``to_go_weight``, ``success_bonus``, ``dead_end_penalty``, ``illegal_penalty``).
    turn_coef
        ``alpha * (360 / n) / turn_scale_deg``: the turn term per grid step.
    reached0, reached1
        ``min(σk, |K|)`` before and after the step (:attr:`KTables.reached`).
    regrasp, rotation, illegal
        Bools: the move was a regrasp, a rotation (made, or attempted and failed in
        physics), an illegal action (a no-op).
    ends, success
        Bools: the episode ends at this step for the first time; the turn is reached.
    gained
        With ``to_go_weight``: the fall in the optimum's regrasps to go that the
        regrasp made (:func:`regrasps_gained`; 0 for other moves).

    Returns
    -------
    turn, regrasp, rotation, success, dead_end, illegal
        ``turn = alpha Δθ* / turn_scale_deg`` and ``- beta`` per regrasp, ``- gamma``
        per rotation (thesis 5.4), ``to_go_weight * gained`` added to the regrasp term,
        ``success_bonus`` or ``- dead_end_penalty`` once at the episode's end, ``-
        illegal_penalty`` per illegal action. No negative zeros: a term that does not
        apply is ``0.0``.
    """
    # one operation per term (this runs on every batched step); "0.0 - x", not "-x":
    # no negative zeros where a term does not apply
    turn = turn_coef * (reached1 - reached0)
    regrasp_t = cfg.to_go_weight * gained - cfg.beta * regrasp
    rotation_t = 0.0 - cfg.gamma * rotation
    success_t = cfg.success_bonus * (ends & success)
    # ends > success: "ends and not success", for Python bools and bool arrays alike
    dead_end_t = 0.0 - cfg.dead_end_penalty * (ends > success)
    illegal_t = 0.0 - cfg.illegal_penalty * illegal
    return turn, regrasp_t, rotation_t, success_t, dead_end_t, illegal_t


def regrasps_gained(to_go: Sequence[Any], before: NDArray[np.int64], k: NDArray[np.int64],
                    c: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``to_go_weight``: the fall in the exact optimum's regrasps to go of rows that
    just regrasped.

    Parameters
    ----------
    to_go
        Each row's :class:`~graspgait_env.planners.exact.RegraspsToGo` table.
    before
        ``(N,)``: each row's regrasps to go before the regrasp (-1: no gait).
    k, c
        ``(N,)`` object angles and ``(N, 3)`` contacts after it.

    Returns
    -------
    gained, now
        ``before - now`` and ``now`` (``(N,)`` int64). No gait before and after (-1 to
        -1) gains 0.
    """
    from graspgait_env.gait import GaitState

    now = np.array([t(GaitState(int(ki), tuple(int(x) for x in ci)))
                    for t, ki, ci in zip(to_go, k, c, strict=True)], dtype=np.int64)
    return np.asarray(before, dtype=np.int64) - now, now


def drop_reversals(mask: NDArray[np.bool_], last_turn: NDArray[np.int64], R: int) -> None:
    """``forbid_reversal``: remove, in place, the rotations against each row's last
    move when it was a rotation (clockwise after counter-clockwise and back).

    ``mask`` is ``(N, A)`` (rotations: counter-clockwise ``0 .. R-1``, clockwise ``R ..
    2R-1``), ``last_turn`` ``(N,)`` the sign of each row's last move if a rotation, else
    0.
    """
    mask[last_turn > 0, R:2 * R] = False
    mask[last_turn < 0, :R] = False


def grasp_map_runs(model: Any, P: int) -> NDArray[np.bool_]:
    """The extended grasp map, transposed, as a view of every run of ``P`` contacts:
    ``runs[c, i]`` is "contact ``c`` against contacts ``i .. i+P-1``",
    ``GaitModel.action_mask``'s regrasp rule (thesis 4.2), for a batch of states at once."""
    rows = np.ascontiguousarray(model.grasp_map.extended().T)
    return np.lib.stride_tricks.sliding_window_view(rows, P, axis=1)


def window_views(pooled: NDArray[np.float32], s: int, cells: int) -> NDArray[np.float32]:
    """Every grasp-map window as a read-only view ``V[ri, rj, qi, qj]`` of shape
    ``(s, s, ., ., cells, cells)``: the window whose origin is ``(s qi + ri, s qj + rj)``
    in the tiled pooled map, i.e. ``pooled[i0 : i0 + s cells : s, j0 : j0 + s cells : s]``
    with ``i0 = s qi + ri``. The map is regrouped by stride phase (a copy of its size),
    so that each window is a contiguous-stride block and a batch of windows is one
    fancy-indexed gather of blocks (:func:`window_at`)."""
    L = -(-pooled.shape[0] // s) * s
    padded = np.zeros((L, L), dtype=pooled.dtype)
    padded[:pooled.shape[0], :pooled.shape[1]] = pooled
    phases = np.ascontiguousarray(padded.reshape(L // s, s, L // s, s).transpose(1, 3, 0, 2))
    return np.lib.stride_tricks.sliding_window_view(phases, (cells, cells), axis=(2, 3))


def window_at(windows: NDArray[np.float32], i0: Any, j0: Any) -> NDArray[np.float32]:
    """The ``map_window_cells`` window of the grasp map with origin ``(i0, j0)`` (grid
    indices of the two held contacts, less the window's half-width, mod ``n``), from
    :func:`window_views`: ``(C, C)`` for integer ``i0, j0`` (a view), ``(N, C, C)`` for
    ``(N,)`` arrays."""
    s = windows.shape[0]
    return windows[i0 % s, j0 % s, i0 // s, j0 // s]


def line_views(line_src: NDArray[np.float32] | None, n: int) -> NDArray[np.float32] | None:
    """``map_lines``: every run of ``n`` of the grasp map's rows tiled twice, so that a
    held contact's line at angle ``k`` is row ``c``, column ``(-k) mod n``
    (:func:`write_lines`); None without ``map_lines``."""
    return (None if line_src is None
            else np.lib.stride_tricks.sliding_window_view(line_src, n, axis=1))


def write_lines(lines: NDArray[np.float32], views: NDArray[np.float32], cf: NDArray[np.int64],
                cg: NDArray[np.int64], k: NDArray[np.int64]) -> None:
    """``map_lines`` (thesis 4.3, the regrasps keeping finger ``f`` or ``g``): write
    into ``lines`` (``(N, 2, n)``) each row's two grasp-map lines, those of its held
    contacts ``cf``, ``cg`` at object angle ``k``: entry ``j`` is "contact ``c``
    against object angle ``j`` of finger F", i.e. grasp-map cell ``(c, (j - k) mod
    n)``. ``views`` is :func:`line_views`'s."""
    shift = -k % views.shape[2]
    lines[:, 0] = views[cf, shift]
    lines[:, 1] = views[cg, shift]


def regrasps_opened(openings: NDArray[np.bool_], h: NDArray[np.int64], cf: NDArray[np.int64],
                    cg: NDArray[np.int64], k: NDArray[np.int64], ws_start: NDArray[np.int64],
                    rot_delta: NDArray[np.int64], n: int,
                    rot_mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``rotation_lookahead`` (thesis 4.2, 5.2): for each row and each of its ``2R``
    rotations, whether that rotation is legal and opens a regrasp.

    After rotating by ``d`` grid steps the free finger ``h``'s workspace starts at
    object contact ``(s_h - k - d) mod n``; the rotation opens a regrasp when either
    held contact (``cf``, ``cg``) has a stable partner there (``openings``, from
    :func:`~graspgait_env.envs.map_env.regrasp_openings`). Arrays are ``(N,)`` but
    ``rot_mask``, the rotation block of the masks, ``(N, 2R)``; returns ``(N, 2R)``
    bool.
    """
    hh = h[:, None]
    i = (ws_start[hh] - k[:, None] - rot_delta) % n
    opens = openings[hh, cf[:, None], i] | openings[hh, cg[:, None], i]
    np.logical_and(opens, rot_mask, out=opens)
    return opens
