"""Seeding and threading of the learning stack, in one place.

:func:`seed_everything` seeds Python's :mod:`random`, NumPy's global generator and
torch; the environments are seeded through ``reset(seed=...)`` (SB3's ``make_vec_env``
gives env ``i`` the seed ``seed + i``). With one torch thread on the CPU, two runs
with the same seed and config give the same weights bit for bit
(``tests/agents/test_train.py``).
"""

from __future__ import annotations

import random

import numpy as np

__all__ = ["seed_everything", "set_torch_threads"]


def seed_everything(seed: int) -> None:
    """Seed Python's ``random``, NumPy's global generator and torch (CPU and CUDA).

    Parameters
    ----------
    seed
        An integer ``>= 0``.
    """
    import torch

    random.seed(seed)
    np.random.seed(seed % 2**32)  # noqa: NPY002 (the global one libraries use)
    torch.manual_seed(seed)


def set_torch_threads(threads: int) -> None:
    """Set torch's intra-op threads (see
    :func:`graspgait_env.agents.config.default_torch_threads`)."""
    import torch

    torch.set_num_threads(int(threads))
