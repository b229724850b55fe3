"""Helpers that RL Zoo hyper-parameter files name (configs/rlzoo/ppo.yml)."""

from __future__ import annotations

from stable_baselines3.common.callbacks import BaseCallback

from graspgait_env.agents.config import default_torch_threads
from graspgait_env.agents.seeding import set_torch_threads

__all__ = ["TorchThreadsCallback"]


class TorchThreadsCallback(BaseCallback):
    """Sets torch's threads for the machine when training starts (RL Zoo's ``callback:``).

    ``python -m rl_zoo3.train`` leaves torch's threading at its default (one thread per
    core) unless ``--num-threads`` is given. The networks here are small MLPs, and extra
    threads only contend with the environment steps: on a 2-core machine under load,
    torch's default ran RL Zoo's PPO at 39 env steps/s, against hundreds with one
    thread (issue 11). This callback applies
    :func:`graspgait_env.agents.config.default_torch_threads`
    (1 up to 4 cores), as ``graspgait train`` does; an explicit ``--num-threads`` given to
    RL Zoo is overridden only when ``threads`` is None and the default differs.

    Parameters
    ----------
    threads
        Torch intra-op threads; None: :func:`graspgait_env.agents.config.default_torch_threads`.
    """

    def __init__(self, threads: int | None = None, verbose: int = 0) -> None:
        super().__init__(verbose)
        self.threads = threads

    def _on_training_start(self) -> None:
        n = self.threads if self.threads is not None else default_torch_threads()
        set_torch_threads(n)
        if self.verbose:
            print(f"torch threads: {n}")

    def _on_step(self) -> bool:
        return True
