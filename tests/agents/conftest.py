"""Fixtures of the agent tests: one tiny trained model shared by the session."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def smoke_run(tmp_path_factory):
    """``graspgait train smoke`` (256 steps, a second or two) in a temporary run root."""
    import torch

    torch.set_num_threads(1)
    from graspgait_env.agents.config import load_train_config
    from graspgait_env.agents.train import train

    root = tmp_path_factory.mktemp("runs")
    config = load_train_config("smoke", [f"run_root={root}"])
    return train(config, progress=False)

