"""Which periodic evaluation becomes ``best.zip``:
:func:`graspgait_env.agents.train.selection_score`."""

from __future__ import annotations

import doctest
import json

import pytest

import graspgait_env.agents.train
from graspgait_env.agents.card import read_card
from graspgait_env.agents.config import load_train_config
from graspgait_env.agents.train import selection_score, train
from graspgait_env.errors import GraspGaitInputError


def _s(rate, ratio):
    return {"success_rate_solvable": rate, "regrasps_vs_optimal": ratio}


def _best(evals, floor=None):
    return max(range(len(evals)), key=lambda i: selection_score(evals[i], floor))


def test_without_a_floor_success_comes_first_then_fewer_regrasps():
    evals = [_s(0.99, 1.05), _s(1.0, 1.15), _s(1.0, 1.12), _s(None, None)]
    assert _best(evals) == 2


def test_with_a_floor_the_fewest_regrasps_win_among_those_reaching_it():
    evals = [_s(0.99, 1.05), _s(1.0, 1.15), _s(0.97, 1.01), _s(1.0, 1.12)]
    assert _best(evals, 0.98) == 0
    # none reaches the floor: the rule without a floor
    below = [_s(0.90, 1.05), _s(0.95, 1.20), _s(0.95, 1.10)]
    assert _best(below, 0.98) == _best(below) == 2
    # an evaluation without successes never beats one reaching the floor
    assert selection_score(_s(1.0, 1.5), 0.98) > selection_score(_s(None, None), 0.98)
    assert selection_score(_s(0.98, 1.3), 0.98) > selection_score(_s(0.979, 1.0), 0.98)


def test_selection_score_doctest():
    assert doctest.testmod(graspgait_env.agents.train).failed == 0


@pytest.mark.parametrize("bad", [-0.1, 1.5, "high", True])
def test_best_success_floor_is_checked(bad):
    with pytest.raises(GraspGaitInputError, match="best_success_floor"):
        load_train_config("smoke", [f"best_success_floor={json.dumps(bad)}"])


def test_best_zip_follows_the_floor(tmp_path):
    import torch

    torch.set_num_threads(1)
    cfg = load_train_config("smoke", [f"run_root={tmp_path}", "best_success_floor=0.5",
                                      "eval_freq=64", "checkpoint_freq=0"])
    assert cfg.best_success_floor == 0.5
    res = train(cfg, progress=False)
    evals = json.loads((res.run_dir / "evaluations.json").read_text())
    want = evals[_best(evals, 0.5)]["steps"]
    assert read_card(res.run_dir / "best.zip")["steps"] == want
