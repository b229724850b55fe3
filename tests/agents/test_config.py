"""Training configs: bundled YAML, ``--set key=value`` overrides and their error messages."""

from __future__ import annotations

import pytest

from graspgait_env.agents.bench import SHIPPED_AGENTS
from graspgait_env.agents.config import (
    TrainConfig,
    apply_overrides,
    bundled_train_configs,
    default_torch_threads,
    load_train_config,
    parse_override,
)
from graspgait_env.errors import GraspGaitInputError


def test_bundled_configs_load_and_name_themselves():
    names = bundled_train_configs()
    assert {"circle", "ellipse", "pentagon", "hexagon", "random", "smoke"} <= set(names)
    for name in names:
        cfg = load_train_config(name)
        assert cfg.name == name
    for obj in ("circle", "ellipse", "pentagon", "hexagon"):
        cfg = load_train_config(obj)
        assert (cfg.algo, cfg.env_id, cfg.env_kwargs["object"], cfg.env_kwargs["mu"]) == (
            "maskable_ppo", "GraspGait-v0", obj, 0.7)
    assert load_train_config("random").env_id == "GraspGaitRandom-v0"


def test_overrides_use_yaml_scalars_and_dotted_keys():
    cfg = load_train_config("smoke", ["seed=3", "learning_rate=1e-3", "net_arch=[32, 16]",
                                      "env_kwargs.object=pentagon", "env_kwargs.beta=0.05",
                                      "features_extractor=null"])
    assert cfg.seed == 3 and isinstance(cfg.seed, int)
    assert cfg.learning_rate == pytest.approx(1e-3)
    assert cfg.net_arch == [32, 16]
    assert cfg.env_kwargs == {"object": "pentagon", "mu": 0.7, "beta": 0.05}
    assert parse_override("env_kwargs.mu=0.8") == (["env_kwargs", "mu"], 0.8)
    assert parse_override("name=abc") == (["name"], "abc")
    # later overrides win; a nested dict is created when missing
    assert apply_overrides({}, ["env_kwargs.mu=0.5", "env_kwargs.mu=0.6"]) == {
        "env_kwargs": {"mu": 0.6}}


def test_config_from_a_path(tmp_path):
    p = tmp_path / "mine.yaml"
    p.write_text("algo: ppo\nenv_kwargs: {object: circle, mu: 0.8}\ntotal_timesteps: 100\n"
                 "batch_size: 32\n")
    cfg = load_train_config(str(p))
    assert (cfg.name, cfg.algo, cfg.total_timesteps) == ("mine", "ppo", 100)


@pytest.mark.parametrize("overrides, match", [
    (["n_steps=0"], r"n_steps=0: must be an integer >= 1, e.g. 256"),
    (["algo=ppo2"], r"algo='ppo2': did you mean 'ppo'\?"),
    (["seeed=1"], r"'seeed': not a training config field; did you mean 'seed'\?"),
    (["seed"], r"--set 'seed': give key=value"),
    (["seed=-1"], r"seed=-1: must be an integer >= 0"),
    (["learning_rate=abc"], r"learning_rate='abc': must be a finite number > 0"),
    (["batch_size=5000"], r"batch_size=5000: larger than a rollout \(n_envs \* n_steps = "),
    (["net_arch=64"], r"net_arch=64: give a list of layer widths"),
    (["env_id=CartPole-v1"], r"env_id='CartPole-v1': must be one of 'GraspGait-v0'"),
    (["vec_env=batch"], r"vec_env='batch': .*must be one of 'dummy', 'subproc'"),
    (["env_kwargs=3", "env_kwargs.mu=0.7"], r"env_kwargs is 3, not a mapping"),
    (["net_arch=[64"], r"the value is not valid YAML"),
    (["wrappers=[nodots]"], r"wrappers\[0\]='nodots': give an import path"),
    (["policy_kwargs=3"], r"policy_kwargs=3: must be a mapping"),
    (["policy_kwargs={net_arch: [8]}"], r"policy_kwargs \['net_arch'\]: set by their own "
                                        r"fields; use net_arch instead"),
])
def test_bad_overrides_name_the_field_and_the_fix(overrides, match):
    with pytest.raises(GraspGaitInputError, match=match):
        load_train_config("ellipse", overrides)


def test_bad_config_files(tmp_path):
    with pytest.raises(GraspGaitInputError, match=r"CONFIG 'nope': no such file and not a "
                       r"bundled training config; use one of .*ellipse"):
        load_train_config("nope")
    bad = tmp_path / "bad.yaml"
    bad.write_text("total_timestep: 10\n")
    with pytest.raises(GraspGaitInputError, match=r"'total_timestep': not a training config "
                       r"field; did you mean 'total_timesteps'\?"):
        load_train_config(str(bad))
    bad.write_text("- 1\n- 2\n")
    with pytest.raises(GraspGaitInputError, match=r"must be a mapping of training config"):
        load_train_config(str(bad))


def test_torch_threads_follow_the_machine():
    assert [default_torch_threads(c) for c in (1, 2, 4, 8, 16, 64)] == [1, 1, 1, 2, 4, 4]
    assert TrainConfig().torch_threads == default_torch_threads()
    assert TrainConfig(torch_threads=3).torch_threads == 3


@pytest.mark.parametrize("name", SHIPPED_AGENTS)
def test_each_shipped_model_card_holds_its_bundled_config(name):
    """`graspgait train NAME` trains the shipped model's config: the bundled YAML and the
    config in `agents/models/NAME.json` make the same TrainConfig (a field added after
    a card was written takes its default), the extractor's keywords as the trainer
    builds them (``extractor_kwargs``: the config's own) included."""
    import dataclasses
    import json

    from graspgait_env.agents.bench import shipped_models_dir
    from graspgait_env.agents.train import extractor_kwargs

    card = shipped_models_dir() / f"{name}.json"
    assert card.is_file(), f"the shipped card {card} is missing from this install"
    shipped = json.loads(card.read_text(encoding="utf-8"))
    # run_root is where the run was written, not how it was trained
    bundled = load_train_config(name, [f"run_root={shipped['config']['run_root']}"])
    trained = TrainConfig(**shipped["config"])
    kw = extractor_kwargs(bundled)
    assert kw == trained.features_extractor_kwargs
    assert dataclasses.replace(bundled, features_extractor_kwargs=kw) == trained
    assert shipped["env_kwargs"] == shipped["config"]["env_kwargs"]


def test_the_shipped_general_is_one_stage_with_the_regrasp_scorer():
    """``general`` is trained in one run (no ``init``) with the shared regrasp scorer."""
    import json

    from graspgait_env.agents.card import load_agent, shipped_models_dir
    from graspgait_env.agents.policies import MaskableRegraspScorerPolicy

    card = json.loads((shipped_models_dir() / "general.json").read_text(encoding="utf-8"))
    assert card["config"]["init_model"] is None and "init" not in card
    assert card["config"]["policy"] == "graspgait_env.agents.policies:MaskableRegraspScorerPolicy"
    model, _ = load_agent(shipped_models_dir() / "general.zip")
    assert isinstance(model.policy, MaskableRegraspScorerPolicy)
