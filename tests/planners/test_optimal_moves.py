"""The moves of a fewest-regrasp gait, state by state (OptimalMoves)."""

from __future__ import annotations

import numpy as np
import pytest

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.planners.exact import RegraspsToGo, optimal_gait
from graspgait_env.planners.optimal_moves import OptimalMoves

THESIS = ("circle", "ellipse", "pentagon", "hexagon")


def _regrasps(states: list[GaitState]) -> int:
    return sum(a.contacts != b.contacts for a, b in zip(states, states[1:], strict=False))


@pytest.mark.parametrize("obj", THESIS)
@pytest.mark.parametrize("turn", [360.0, -180.0])
def test_following_any_optimal_move_spends_exactly_the_optimum(obj: str, turn: float) -> None:
    """From sampled starts, a walk that picks a random move of the set at every state
    reaches the turn with exactly the optimum's regrasps (optimal_gait's count)."""
    model = GaitModel(obj, 0.7, n=90)
    moves = OptimalMoves(model, turn)
    rng = np.random.default_rng(0)
    starts = model.start_states()
    walked = 0
    for i in rng.choice(len(starts), 12, replace=False):
        s = start = starts[i]
        L = moves.to_go(start)
        if L < 0:
            assert not moves(start).any()
            continue
        assert L == optimal_gait(model, start, turn).regrasps
        regrasps = 0
        for _ in range(2000):
            if (s.k - moves.turn_steps) * moves.sign >= 0:
                break
            mask = moves(s)
            assert mask.any() and not (mask & ~model.action_mask(s)).any()  # legal moves
            a = int(rng.choice(np.flatnonzero(mask)))
            t = model.apply(s, a)
            if (t.k - moves.turn_steps) * moves.sign >= 0:  # the turn (maybe overshot)
                assert a < 2 * model.R and moves.to_go(s) == 0
            elif a >= 2 * model.R:  # a regrasp of the set lowers the count by one
                regrasps += 1
                assert moves.to_go(t) == moves.to_go(s) - 1
            else:  # a rotation keeps it
                assert moves.to_go(t) == moves.to_go(s)
            s = t
        else:
            pytest.fail(f"{obj}: no end from {start}")
        assert regrasps == L
        walked += 1
    assert walked >= 6


@pytest.mark.parametrize("obj", THESIS)
def test_gait_follows_action_to_the_turn(obj: str) -> None:
    model = GaitModel(obj, 0.7, n=90)
    moves = OptimalMoves(model, 360.0)
    for start in model.start_states()[::40]:
        if moves.to_go(start) < 0:
            with pytest.raises(GraspGaitInputError, match="no gait"):
                moves.action(start)
            continue
        states = moves.gait(start)
        assert states[0] == start and states[-1].k >= moves.turn_steps
        assert all(model.encode(a, b) >= 0 for a, b in zip(states, states[1:], strict=False))
        assert _regrasps(states) == moves.to_go(start)


def test_a_grasp_a_full_turn_later_is_another_segment() -> None:
    """The same contacts 360 degrees apart hold other workspace positions: the cache is
    per segment, so the set at the second angle is that angle's own (found as a bug)."""
    model = GaitModel("pentagon", 0.7)
    moves = OptimalMoves(model, 360.0)
    n = model.n
    for s in model.start_states()[::25]:
        late = GaitState(s.k + n, s.contacts)
        if moves.to_go(s) < 0 or not model.is_legal_state(late):
            continue
        moves(late)  # cached first
        fresh = OptimalMoves(model, 360.0, to_go=moves.to_go)
        assert (moves(s) == fresh(s)).all()
        assert not (moves(s) & ~model.action_mask(s)).any()


def test_at_zero_to_go_the_longest_rotation_towards_the_turn() -> None:
    model = GaitModel("ellipse", 0.7, n=90)
    moves = OptimalMoves(model, 360.0)
    start = next(s for s in model.start_states() if moves.to_go(s) > 0)
    s = next(s for s in moves.gait(start) if moves.to_go(s) == 0)
    mask = moves(s)
    assert mask.sum() == 1
    a = int(np.flatnonzero(mask)[0])
    ccw, _ = model.state_rotation_room(s)
    assert a == min(ccw, model.R) - 1  # counter-clockwise, as far as the room allows


def test_bad_input_names_the_fix() -> None:
    model = GaitModel("ellipse", 0.7, n=90)
    with pytest.raises(GraspGaitInputError, match="state="):
        OptimalMoves(model, 360.0)(GaitState(0, (0, 1, 2)))
    other = RegraspsToGo(GaitModel("circle", 0.7, n=90), 360.0)
    with pytest.raises(GraspGaitInputError, match="to_go"):
        OptimalMoves(model, 360.0, to_go=other)
