"""The shipped agents: there, by name, on any object file and friction, and a model saved
by graspgait_env 0.1 (before ``agents`` moved beneath ``graspgait_env``) still loads."""

from __future__ import annotations

import json
import sys
import types
import warnings
from pathlib import Path

import numpy as np
import pytest

from graspgait_env.agents.bench import SHIPPED_AGENTS
from graspgait_env.agents.card import (
    RETIRED_AGENTS,
    describe_shipped,
    load_agent,
    read_card,
    resolve_model,
    shipped_agents,
    shipped_models_dir,
)
from graspgait_env.agents.config import TrainConfig, load_train_config
from graspgait_env.agents.envs import make_env
from graspgait_env.agents.evaluate import evaluate
from graspgait_env.agents.legacy import legacy_module_names, upgrade_card, upgrade_import_path
from graspgait_env.errors import GraspGaitInputError

ROOT = Path(__file__).resolve().parents[2]
LEGACY = Path(__file__).parent / "data" / "legacy_0_1"

# An object no training run saw: a kite (no bundled object, outside the procedural
# generator's regular families), evaluated at a friction no shipped card trains at.
KITE = ("name: kite\ntype: polygon\n"
        "vertices: [[0.07, 0.0], [0.0, 0.05], [-0.09, 0.0], [0.0, -0.05]]\n")


def test_every_shipped_agent_is_installed_with_both_cards():
    """A missing model or card fails here (it is not skipped anywhere)."""
    assert shipped_agents() == sorted(SHIPPED_AGENTS)
    repo = sorted(p.stem for p in (ROOT / "graspgait_env" / "agents" / "models").glob("*.zip"))
    assert repo == sorted(SHIPPED_AGENTS)
    for name in SHIPPED_AGENTS:
        for suffix in (".zip", ".json", ".md"):
            assert (shipped_models_dir() / f"{name}{suffix}").is_file(), name + suffix
    described = dict(describe_shipped())
    assert sorted(described) == sorted(SHIPPED_AGENTS)
    assert "GraspGaitRandom-v0" in described["general"] and "x the optimum" in described["general"]


@pytest.mark.parametrize("name", SHIPPED_AGENTS)
def test_every_shipped_model_card_is_written_by_the_card_command(name):
    """Each ``NAME.md`` is ``graspgait card``'s output: its front matter, its heading line
    and its run table's row of the shipped model, read from ``NAME.json``, are what
    :func:`hub_card` writes from that JSON card; a card typed or edited by hand, or left
    behind by a retraining, fails here."""
    from graspgait_env.agents.hub_card import hub_card

    text = (shipped_models_dir() / f"{name}.md").read_text(encoding="utf-8")
    card = read_card(shipped_models_dir() / f"{name}.zip")
    alone = hub_card([card], names=[name])
    assert "Written by `graspgait card` from the runs' own cards." in text
    ev = card["eval"]
    row = (f"| `{name}` | {card['seed']} | {card['steps']} | {float(card['wall_s']):.0f} | "
           f"{100.0 * ev['success_rate_solvable']:.1f} | {ev['regrasps_vs_optimal']:.3f} |")
    assert row in text and row in alone
    assert f"- env keywords: `{json.dumps(card['env_kwargs'], sort_keys=True)}`" in text
    if "; 1 run (seed " in text:  # one run: the front matter's first result is this card's
        import yaml

        first = [yaml.safe_load(x.split("---\n")[1])["model-index"][0]["results"][0]
                 for x in (text, alone)]
        assert first[0] == first[1]


def test_the_circle_cards_measured_row_is_a_fresh_evaluation():
    """The circle card's first measured row, recomputed by the command it names."""
    import shlex

    from graspgait_env.agents.hub_card import evaluation_section

    text = (shipped_models_dir() / "circle.md").read_text(encoding="utf-8")
    block = text.split("## Measured results")[1].split("```bash\n")[1].split("```")[0]
    command = block.splitlines()[0]
    assert command == "graspgait evaluate circle --episodes 100"
    argv = shlex.split(command)
    result = evaluate("circle", episodes=int(argv[argv.index("--episodes") + 1]),
                      progress=False)
    result["command"] = command
    assert evaluation_section([result])[5] in text


def test_shipped_names_resolve_and_unknown_names_list_what_exists(tmp_path, monkeypatch):
    assert resolve_model("circle") == shipped_models_dir() / "circle.zip"
    assert resolve_model("circle.zip") == shipped_models_dir() / "circle.zip"
    # a file of that name in the working folder is the user's, and wins
    monkeypatch.chdir(tmp_path)
    (tmp_path / "circle.zip").write_bytes(b"")
    assert resolve_model("circle") == Path("circle.zip")
    with pytest.raises(GraspGaitInputError) as err:
        resolve_model("circel")
    msg = str(err.value)
    assert "did you mean 'circle'?" in msg and "evaluate --list" in msg
    assert ", ".join(sorted(SHIPPED_AGENTS)) in msg
    assert "agents/models" not in msg  # no path that only a clone has


@pytest.mark.parametrize("name", sorted(RETIRED_AGENTS))
def test_a_retired_agent_is_not_installed_and_its_name_says_what_replaces_it(name, tmp_path,
                                                                             monkeypatch):
    assert name not in SHIPPED_AGENTS and name not in shipped_agents()
    assert not (shipped_models_dir() / f"{name}.zip").exists()
    for spec in (name, f"{name}.zip"):
        with pytest.raises(GraspGaitInputError) as err:
            resolve_model(spec)
        msg = str(err.value)
        assert f"MODEL {name!r}: the shipped agent {name!r} was retired after" in msg
        assert f"graspgait train {name}" in msg
        if name == "random":  # the generalist: general on procedural objects and files
            assert "use general instead" in msg and "--object FILE" in msg
            assert "graspgait evaluate general --episodes 300 --seed 20000" in msg
        else:
            assert f"graspgait evaluate general --object {name}" in msg
    # its recipe stays bundled, and a file of that name in the working folder still wins
    kw = load_train_config(name).env_kwargs
    assert kw.get("object", "random") == name and ("level" in kw) == (name == "random")
    monkeypatch.chdir(tmp_path)
    (tmp_path / f"{name}.zip").write_bytes(b"")
    assert resolve_model(name) == Path(f"{name}.zip")


def test_load_agent_takes_a_name_and_its_zip_loads_without_the_loader():
    """The shipped zips name graspgait_env.agents.policies: plain SB3 loads them."""
    from sb3_contrib import MaskablePPO

    model, card = load_agent("general")
    assert card["config"]["policy"].startswith("graspgait_env.agents.policies:")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "could not deserialize" warning either
        plain = MaskablePPO.load(shipped_models_dir() / "general.zip", device="cpu")
    assert type(plain.policy).__module__ == "graspgait_env.agents.policies"
    assert "agents" not in sys.modules


@pytest.mark.parametrize("name", SHIPPED_AGENTS)
def test_every_shipped_model_evaluates_on_an_unseen_object_file(name, tmp_path):
    """Any object file, any friction: the look-ahead of ``general`` included (eight
    regrasps deep, played in the batched env)."""
    path = tmp_path / "kite.yaml"
    path.write_text(KITE)
    res = evaluate(name, object=str(path), mu=0.6, episodes=2, seed=3)
    assert res["object"] == "kite" and res["mu"] == 0.6
    assert res["env_id"] == "GraspGait-v0"
    assert len(res["episodes"]) == 2
    for ep in res["episodes"]:
        assert ep["object"] == "kite" and ep["steps"] >= 1
        if ep["success"]:
            assert ep["solvable"] and ep["regrasps"] >= ep["optimal_regrasps"]
    if name == "general":
        assert res["env_kwargs"]["regrasp_lookahead"] == 8


# the first 8 moves from reset seeds 0-2 of the ellipse agent shipped with graspgait_env
# 0.1 and 0.2 (the same network, re-saved; since retrained on the named parts), recorded
# with that agent on 2026-12-04
_ELLIPSE_0_2_MOVES = [[154, 12, 90, 10, 91, 140, 17, 91], [92, 154, 12, 90, 17, 95, 148, 12],
                      [154, 12, 90, 17, 95, 148, 12, 91]]


def test_a_model_saved_by_0_1_loads_and_acts_as_it_did():
    """The ellipse agent and its card as graspgait_env 0.1 wrote them (its pickles and
    card name ``agents.policies``): it loads, its card's import paths are today's, and
    it plays the moves the agent played when 0.2 shipped it."""
    from graspgait_env.agents.policies import GraspMapExtractor

    legacy_card = json.loads((LEGACY / "ellipse.json").read_text())
    assert legacy_card["config"]["features_extractor"] == "agents.policies:GraspMapExtractor"
    old, card = load_agent(LEGACY / "ellipse.zip")
    assert card["config"]["features_extractor"] == \
        "graspgait_env.agents.policies:GraspMapExtractor"
    TrainConfig(**card["config"])  # the card's config is a valid config again
    assert type(old.policy.features_extractor) is GraspMapExtractor
    env = make_env("GraspGait-v0", card["env_kwargs"])
    played = []
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        moves = []
        for _ in range(8):
            mask = env.unwrapped.action_masks()
            moves.append(int(old.predict(obs, action_masks=mask, deterministic=True)[0]))
            obs, _, terminated, truncated, _ = env.step(moves[-1])
            if terminated or truncated:
                break
        played.append(moves)
    assert played == _ELLIPSE_0_2_MOVES
    assert "agents" not in sys.modules and "agents.policies" not in sys.modules


def test_legacy_names_leave_a_users_own_agents_package_alone():
    mine = types.ModuleType("agents")
    sys.modules["agents"] = mine
    try:
        with legacy_module_names():
            import agents.policies  # noqa: F401 - the 0.1 name, while unpickling

            assert sys.modules["agents.policies"] is sys.modules["graspgait_env.agents.policies"]
            assert sys.modules["agents"] is sys.modules["graspgait_env.agents"]
        assert sys.modules["agents"] is mine and "agents.policies" not in sys.modules
        # the real package keeps its own spec (importlib.resources reads through it)
        assert shipped_models_dir().is_dir()
    finally:
        del sys.modules["agents"]


def test_import_paths_of_0_1_are_upgraded():
    assert upgrade_import_path("agents.policies:X") == "graspgait_env.agents.policies:X"
    assert upgrade_import_path("baselines.policies.P") == "graspgait_env.baselines.policies.P"
    assert upgrade_import_path("agentsmith.x:Y") == "agentsmith.x:Y"
    assert upgrade_import_path("my.agents.policies:X") == "my.agents.policies:X"
    card = {"wrappers": ["agents.wrappers:LegalActionWrapper"], "name": "agents x",
            "config": {"policy": "MlpPolicy"}}
    assert upgrade_card(card) == {"wrappers": ["graspgait_env.agents.wrappers:"
                                               "LegalActionWrapper"],
                                  "name": "agents x", "config": {"policy": "MlpPolicy"}}
    with pytest.warns(DeprecationWarning, match="graspgait_env.agents.policies"):
        cfg = TrainConfig(algo="maskable_ppo",
                          policy="agents.policies:MaskableRegraspScorerPolicy")
    assert cfg.policy == "graspgait_env.agents.policies:MaskableRegraspScorerPolicy"


def test_evaluate_general_on_an_object_file_runs_batched_as_the_single_envs(tmp_path,
                                                                           monkeypatch):
    """The look-ahead of ``general`` is batched: evaluation on an object file plays the
    episodes side by side, with the records of the single-env loop."""
    import graspgait_env.agents.evaluate as ev

    path = tmp_path / "kite.yaml"
    path.write_text(KITE)
    batched = evaluate("general", object=str(path), episodes=3)
    calls = []
    monkeypatch.setattr(ev, "batched_eval_env", lambda *a, **k: calls.append(1))  # None
    serial = evaluate("general", object=str(path), episodes=3)
    assert calls == [1]

    def strip(records):
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in records]

    assert strip(batched["episodes"]) == strip(serial["episodes"])
    assert np.isfinite(batched["wall_s"])
