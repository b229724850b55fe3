"""RL Zoo: the bundled hyper-parameters, the threads callback, reading RL Zoo's saved runs."""

from __future__ import annotations

from importlib.resources import files

import torch
import yaml

from graspgait_env.agents.card import load_agent, read_card
from graspgait_env.agents.envs import import_object
from graspgait_env.agents.rlzoo import TorchThreadsCallback


def test_bundled_ppo_yml_names_importable_wrappers_and_callback():
    text = (files("graspgait_env.configs") / "rlzoo" / "ppo.yml").read_text()
    hyper = yaml.safe_load(text)["GraspGait-v0"]
    for path in [*hyper["env_wrapper"], hyper["callback"]]:
        import_object(path)  # RL Zoo imports them the same way (module.Class)
    assert hyper["n_timesteps"] <= 2e5 and hyper["policy"] == "MlpPolicy"


def test_threads_callback_sets_torch_threads():
    before = torch.get_num_threads()
    try:
        cb = TorchThreadsCallback(threads=1)
        cb._on_training_start()
        assert torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(before)


RLZOO_CONFIG = """!!python/object/apply:collections.OrderedDict
- - - env_wrapper
    - - graspgait_env.agents.wrappers.SolvableStartWrapper
      - graspgait_env.agents.wrappers.LegalActionWrapper
  - - policy
    - MlpPolicy
"""
RLZOO_ARGS = """!!python/object/apply:collections.OrderedDict
- - - algo
    - ppo
  - - env
    - GraspGait-v0
  - - env_kwargs
    - null
"""


def test_a_zip_saved_by_rl_zoo_gets_a_card(smoke_run, tmp_path):
    run = tmp_path / "ppo" / "GraspGait-v0_1"
    (run / "GraspGait-v0").mkdir(parents=True)
    (run / "GraspGait-v0" / "config.yml").write_text(RLZOO_CONFIG)
    (run / "GraspGait-v0" / "args.yml").write_text(RLZOO_ARGS)
    zip_path = run / "GraspGait-v0.zip"
    zip_path.write_bytes(smoke_run.model_path.read_bytes())  # a MaskablePPO zip, no card
    assert read_card(zip_path) == {}
    model, card = load_agent(zip_path)
    assert card["env_id"] == "GraspGait-v0" and card["env_kwargs"] == {}
    assert card["wrappers"] == ["graspgait_env.agents.wrappers.SolvableStartWrapper",
                                "graspgait_env.agents.wrappers.LegalActionWrapper"]
    assert card["algo"] == "maskable_ppo"  # the zip's policy class, whatever args.yml says
    assert type(model).__name__ == "MaskablePPO"
    plain = tmp_path / "plain.zip"
    plain.write_bytes(smoke_run.model_path.read_bytes())
    model, card = load_agent(plain)
    assert card == {"algo": "maskable_ppo"}  # read from the zip's policy class
    assert type(model).__name__ == "MaskablePPO"
