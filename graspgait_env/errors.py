"""Errors a user can act on.

Every error raised for bad input names the field, the bad value and the fix, in one
line, so that the CLI can print it and exit 2 without a traceback.
"""

from __future__ import annotations

__all__ = ["GraspGaitInputError", "ConfigError", "NoGaitError"]


class GraspGaitInputError(ValueError):
    """Bad input from a user (an argument, a file, a field); the CLI exits 2 with it."""


class ConfigError(GraspGaitInputError):
    """A YAML config (object or hand) is malformed.

    Parameters
    ----------
    source
        Where the config came from (a path, or ``"<dict>"``).
    field
        The offending field (``"vertices"``, ``"workspaces_deg[1]"``...), or ``""``
        for a problem with the whole file.
    problem
        What is wrong, including the bad value.
    fix
        What to do about it.
    """

    def __init__(self, source: str, field: str, problem: str, fix: str) -> None:
        self.source = source
        self.field = field
        self.problem = problem
        self.fix = fix
        where = f"{source}: field '{field}'" if field else source
        super().__init__(f"{where}: {problem}; fix: {fix}")


class NoGaitError(RuntimeError):
    """A question with no answer (no gait exists); the CLI exits 1 with it."""
