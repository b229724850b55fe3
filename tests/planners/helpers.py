"""Shared helpers of the planner tests: synthetic prototype maps, plan replay, a model cache.

Imported as ``tests.planners.helpers`` (pytest's importlib mode registers the test
folders as packages); the fixtures live in ``conftest.py``.
"""

from __future__ import annotations

import numpy as np

from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import validate_plan
from graspgait_env.planners import prototypes as P
from graspgait_env.workspace import Hand

N = 180
W = 15  # w = 30 deg on the 2-degree grid
GEOM = P.WorkspaceGrid.from_hand(Hand.default(), N)


def band_map(lo: int, hi: int, n: int = N) -> np.ndarray:
    """Pure band prototype: offsets lo..hi (grid steps) stable along the whole diagonal,
    mirrored below the diagonal (the map is symmetric)."""
    i = np.arange(n)
    S = np.zeros((n, n), dtype=bool)
    for d in range(lo, hi + 1):
        S[i, (i + d) % n] = True
    S |= S.T
    np.fill_diagonal(S, False)
    return S


def box_map(x0: int, y0: int, side: int, n: int = N, side_y: int | None = None) -> np.ndarray:
    """Pure box prototype: cells x0..x0+side × y0..y0+side_y (wrapping) and the mirror."""
    S = np.zeros((n, n), dtype=bool)
    xs = np.arange(x0, x0 + side + 1) % n
    ys = np.arange(y0, y0 + (side if side_y is None else side_y) + 1) % n
    S[np.ix_(xs, ys)] = True
    S |= S.T
    np.fill_diagonal(S, False)
    return S


def synthetic(S: np.ndarray) -> GaitModel:
    """A thesis-hand gait model whose grasp map is replaced by ``S``.

    GaitModel has no public hook for a hand-made map; ``action_mask`` reads a cached
    transposed tiling (``_rows``), so both are replaced here.
    """
    m = GaitModel("circle", 0.7)
    m.stable = S
    if hasattr(m, "_rows"):
        m._rows = np.ascontiguousarray(np.tile(S, (2, 2)).T)
    return m


def replay(model: GaitModel, res) -> list[GaitState]:
    """Replay a result's plan move by move, checking each move with ``action_mask``."""
    plan = res.plan
    steps = plan.steps
    cs = [-1, -1, -1]
    for f, phi in steps[0]["contacts"].items():
        cs[int(f) - 1] = model.contact_index(phi)
    s = GaitState(0, tuple(cs))
    assert model.is_legal_state(s)
    states = [s]
    for st in steps[1:]:
        if st["op"] == "rotate":
            t = GaitState(s.k + round(st["delta"] / model.step_deg), s.contacts)
        else:
            cs = [-1, -1, -1]
            for f, phi in st["contacts"].items():
                cs[int(f) - 1] = model.contact_index(phi)
            t = GaitState(s.k, tuple(cs))
        a = model.encode(s, t)
        assert model.action_mask(s)[a], (s, t)
        states.append(t)
        s = t
    return states


def check_plan(model: GaitModel, res, turn_deg: float = 360.0, physical: bool = True) -> None:
    """The result has a plan that replays legally, reaches the turn and counts right."""
    assert res.success, res.reason
    states = replay(model, res)
    assert states[-1].k == model.turn_steps(turn_deg)
    assert res.path_length == len(res.plan.steps) - 1
    assert res.regrasps == res.plan.regrasps
    if physical:
        assert validate_plan(res.plan, model.shape, model.hand, turn_deg=turn_deg) is None


def model(models: dict[tuple[str, float], GaitModel], name: str, mu: float) -> GaitModel:
    """The cached gait model of a bundled object at ``mu`` (built on first use)."""
    if (name, mu) not in models:
        models[(name, mu)] = GaitModel(name, mu)
    return models[(name, mu)]
