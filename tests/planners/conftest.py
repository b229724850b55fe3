"""Fixtures of the planner tests (helpers: ``tests/planners/helpers.py``)."""

from __future__ import annotations

import pytest

from graspgait_env.gait import GaitModel


@pytest.fixture(scope="session")
def models() -> dict[tuple[str, float], GaitModel]:
    """A cache of bundled-object gait models shared by the planner tests (read only)."""
    return {}
