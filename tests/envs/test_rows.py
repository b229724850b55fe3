"""The per-field step functions (graspgait_env.envs.rows): one implementation that the
single env calls with its one row and the batched env with N rows."""

from __future__ import annotations

import ast
import inspect

import numpy as np
import pytest

from graspgait_env.envs import map_env, rows, vector_env
from graspgait_env.envs.config import GraspGaitConfig


def test_reward_terms_give_the_same_bits_for_one_row_and_for_a_batch():
    cfg = GraspGaitConfig(alpha=1.0, beta=0.3, gamma=0.05, success_bonus=2.0,
                          dead_end_penalty=1.5, illegal_penalty=0.7, to_go_weight=0.25)
    rng = np.random.default_rng(0)
    N = 64
    r0, r1 = rng.integers(-20, 180, N), rng.integers(-20, 180, N)
    regrasp = rng.random(N) < 0.5
    rotation = ~regrasp & (rng.random(N) < 0.8)
    illegal = ~regrasp & ~rotation
    ends, success = rng.random(N) < 0.3, rng.random(N) < 0.5
    gained = np.where(regrasp, rng.integers(-2, 3, N), 0)
    batch = rows.reward_terms(cfg, 0.01, r0, r1, regrasp, rotation, illegal, ends, success,
                              gained)
    for i in range(N):
        one = rows.reward_terms(cfg, 0.01, int(r0[i]), int(r1[i]), bool(regrasp[i]),
                                bool(rotation[i]), bool(illegal[i]), bool(ends[i]),
                                bool(success[i]), int(gained[i]))
        assert [float(t[i]) for t in batch] == list(one)
        assert all(np.signbit(x) == (x < 0) for x in one)  # no negative zeros


def test_reward_terms_by_hand():
    cfg = GraspGaitConfig(beta=0.3, gamma=0.05, success_bonus=2.0, dead_end_penalty=1.5,
                          illegal_penalty=0.7, to_go_weight=0.25)
    # a regrasp that gains one regrasp towards the optimum and ends the episode short
    assert rows.reward_terms(cfg, 0.5, 10, 10, True, False, False, True, False, 1) == (
        0.0, 0.25 - 0.3, 0.0, 0.0, -1.5, 0.0)
    # a rotation of 4 counted steps that reaches the turn
    assert rows.reward_terms(cfg, 0.5, 176, 180, False, True, False, True, True) == (
        2.0, 0.0, -0.05, 2.0, 0.0, 0.0)
    # an illegal action, mid-episode
    assert rows.reward_terms(cfg, 0.5, 3, 3, False, False, True, False, False) == (
        0.0, 0.0, 0.0, 0.0, 0.0, -0.7)


def test_k_tables_by_hand():
    kt = rows.k_tables(-1, 10, 3, 2, 36)  # a clockwise turn of 10 steps, 3 back allowed
    k = np.arange(kt.lo, -kt.lo + 1)
    t = -k
    assert kt.lo == -(10 + 3 + 2 + 1)
    assert np.array_equal(kt.reached, np.minimum(t, 10))
    assert np.array_equal(kt.success, t >= 10)
    assert np.array_equal(kt.ends, (t >= 10) | (t < -3))
    i = int(np.flatnonzero(k == -4)[0])  # 4 steps clockwise of 10
    assert kt.head[i, 2:].tolist() == pytest.approx([0.4, 0.6])
    assert kt.head[i, :2].tolist() == pytest.approx(
        [np.cos(2 * np.pi * 32 / 36), np.sin(2 * np.pi * 32 / 36)], abs=1e-6)


def test_drop_reversals_removes_only_the_reversing_rotations():
    R, A = 3, 10
    mask = np.ones((3, A), dtype=bool)
    rows.drop_reversals(mask, np.array([1, -1, 0]), R)
    assert mask[0].tolist() == [True] * 3 + [False] * 3 + [True] * 4
    assert mask[1].tolist() == [False] * 3 + [True] * 7
    assert mask[2].all()


def test_window_at_reads_the_same_window_for_ints_and_arrays():
    rng = np.random.default_rng(1)
    n, s, C = 30, 2, 5
    pooled = np.tile(rng.random((n, n)).astype(np.float32), (2, 2))
    views = rows.window_views(pooled, s, C)
    i0, j0 = rng.integers(0, n, 8), rng.integers(0, n, 8)
    batch = rows.window_at(views, i0, j0)
    for b, (i, j) in enumerate(zip(i0.tolist(), j0.tolist(), strict=True)):
        expect = pooled[i:i + s * C:s, j:j + s * C:s]
        assert np.array_equal(rows.window_at(views, i, j), expect)
        assert np.array_equal(batch[b], expect)


def _attributes(module) -> set[str]:
    tree = ast.parse(inspect.getsource(module))
    return {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)}


@pytest.mark.parametrize("field", ["beta", "gamma", "success_bonus", "dead_end_penalty",
                                   "illegal_penalty"])
def test_the_reward_weights_are_read_by_rows_alone(field):
    """The reward weights are read in one place, rows.reward_terms, by neither env."""
    assert field in _attributes(rows)
    for module in (map_env, vector_env):
        assert field not in _attributes(module), (
            f"{module.__name__} reads config.{field}: compute its term in rows.reward_terms")
