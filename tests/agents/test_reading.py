"""``graspgait evaluate --reading``: the greedy reading of a model's own look-ahead from
the model's starts (graspgait_env.envs.reading, agents.evaluate.compare_with_reading)."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.agents.card import resolve_model
from graspgait_env.agents.evaluate import compare_with_reading, evaluate, run_episodes
from graspgait_env.envs.reading import greedy_reading, greedy_reading_batch
from graspgait_env.errors import GraspGaitInputError

KW = {"object": "hexagon", "contact_model": "hand", "regrasp_lookahead": 8,
      "forbid_revisit": True, "map_window_cells": 1}


def test_the_reading_is_one_move_in_every_observation_mode():
    """Box, dict and flat envs driven alike: the reading picks the same move from each,
    the batched reading picks it from a stack of rows, and it is a legal move."""
    envs = {m: gym.make("GraspGait-v0", observation_mode=m, **KW)
            for m in ("box", "dict", "flat")}
    reads = {m: greedy_reading(e) for m, e in envs.items()}
    batch = {m: greedy_reading_batch(envs[m]) for m in ("dict", "flat")}
    outs = {m: e.reset(seed=3) for m, e in envs.items()}
    rng = np.random.default_rng(0)
    picked = set()
    for _ in range(30):
        mask = outs["box"][1]["action_mask"]
        moves = {m: reads[m](outs[m][0], mask) for m in envs}
        assert len(set(moves.values())) == 1, moves
        assert mask[moves["box"]]
        for m in batch:
            o = outs[m][0]
            stack = ({k: np.stack([v, v]) for k, v in o.items()} if m == "dict"
                     else np.stack([o, o]))
            assert batch[m](stack, np.stack([mask, mask])).tolist() == [moves["box"]] * 2
        picked.add(moves["box"])
        a = moves["box"] if rng.random() < 0.5 else int(rng.choice(np.flatnonzero(mask)))
        outs = {m: e.step(a) for m, e in envs.items()}
        if outs["box"][2] or outs["box"][3]:
            outs = {m: e.reset(seed=4) for m, e in envs.items()}
        else:
            outs = {m: (o[0], o[4]) for m, o in outs.items()}
    assert len(picked) > 3  # not one constant move


def test_the_reading_needs_the_look_ahead():
    env = gym.make("GraspGait-v0", object="ellipse")
    with pytest.raises(GraspGaitInputError, match="regrasp_lookahead=0"):
        greedy_reading(env)
    with pytest.raises(GraspGaitInputError, match="reach_rank"):
        greedy_reading_batch(gym.make("GraspGait-v0", regrasp_lookahead=2))


def test_benchmark_reading_refuses_another_depth():
    from graspgait_env.benchmark.policies import greedy_reach_predictor

    with pytest.raises(GraspGaitInputError, match="greedy-reach:3.*regrasp_lookahead=2"):
        greedy_reach_predictor(gym.make("GraspGait-v0", regrasp_lookahead=2), 3)


def _rec(obj, start, solvable, success, regrasps):
    return {"object": obj, "mu": 0.7, "start": start, "solvable": solvable,
            "success": success, "regrasps": regrasps,
            "optimal_regrasps": 2 if solvable else None,
            "rule_regrasps": None, "path_length": 3, "steps": 3, "illegal_actions": 0,
            "wall_s": 0.0}


def test_compare_with_reading_counts_start_by_start():
    """Hand-made records: fewer, more, as many, only one of the two, an unsolvable start."""
    starts = [{1: float(i)} for i in range(6)]
    model = [_rec("a", starts[0], True, True, 3), _rec("a", starts[1], True, True, 5),
             _rec("a", starts[2], True, True, 2), _rec("a", starts[3], True, True, 4),
             _rec("a", starts[4], True, False, 0), _rec("a", starts[5], False, False, 0)]
    read = [_rec("a", starts[0], True, True, 4), _rec("a", starts[1], True, True, 2),
            _rec("a", starts[2], True, True, 2), _rec("a", starts[3], True, False, 0),
            _rec("a", starts[4], True, True, 2), _rec("a", starts[5], False, False, 0)]
    out = compare_with_reading(model, read, 8)
    counts = (out["both_succeeded"], out["model_fewer"], out["model_more"], out["same"])
    assert counts == (3, 1, 1, 1)
    assert (out["model_regrasps"], out["reading_regrasps"]) == (10, 8)
    assert (out["only_model"], out["only_reading"]) == (1, 1)
    assert out["depth"] == 8 and out["episodes"] is read
    assert out["success_rate_solvable"] == pytest.approx(4 / 5)
    with pytest.raises(RuntimeError, match="episode 2: .*not the same start"):
        compare_with_reading(model, read[:2] + [_rec("b", starts[2], True, True, 2)] + read[3:], 8)
    with pytest.raises(RuntimeError, match="same starts"):
        compare_with_reading(model, read[:5], 8)


def test_evaluate_plays_the_reading_from_the_model_starts():
    """The shipped general agent on the hexagon: the reading's records are those of the
    reading played by itself, side by side or one by one alike, from the model's starts."""
    path = resolve_model("general")
    res = evaluate(path, object="hexagon", episodes=6, seed=2, reading=True)
    alone = evaluate(path, object="hexagon", episodes=6, seed=2, reading=True, batched=False)
    env = gym.make("GraspGait-v0", observation_mode="dict", mu=0.7, **KW)
    own = run_episodes(greedy_reading(env), env, 6, seed=2)
    strip = [{k: v for k, v in r.items() if k != "wall_s"} for r in own]
    for got in (res["reading"]["episodes"], alone["reading"]["episodes"]):
        assert [{k: v for k, v in r.items() if k != "wall_s"} for r in got] == strip
    assert [r["start"] for r in res["episodes"]] == [r["start"] for r in own]
    assert res["reading"]["depth"] == 8
    pairs = zip(res["episodes"], own, strict=True)
    assert res["reading"]["both_succeeded"] == sum(
        a["success"] and b["success"] and a["solvable"] for a, b in pairs)


def test_evaluate_reading_refuses_a_model_without_look_ahead():
    with pytest.raises(GraspGaitInputError, match="reading: .*regrasp_lookahead 0"):
        evaluate(resolve_model("circle"), episodes=1, reading=True)


def test_cli_reading_line_and_json(tmp_path, capsys):
    from graspgait_env.cli import main

    out = tmp_path / "e.json"
    assert main(["evaluate", "general", "--object", "hexagon", "--episodes", "3", "--reading",
                 "--quiet", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "greedy reading of the look-ahead (8 regrasps deep), same starts" in text
    assert "agent against the reading: of the" in text
    data = json.loads(out.read_text())
    assert data["command"].endswith("--reading")
    assert len(data["reading"]["episodes"]) == 3
