"""Checks on output paths, made before any work: the format by suffix, and a writable folder.

Every command that writes a file checks its path first, so that a long computation is
never lost to a typo in ``--png`` or a folder that cannot exist; the write itself is
atomic (:mod:`graspgait_env.atomic`).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from graspgait_env.errors import GraspGaitInputError

__all__ = ["check_output_path", "figure_suffixes"]


def figure_suffixes() -> tuple[str, ...]:
    """The file suffixes Matplotlib can save a figure to (``.png``, ``.pdf``, ``.svg``...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(sorted(f".{ext}" for ext in FigureCanvasBase.get_supported_filetypes()))


def check_output_path(flag: str, path: str | os.PathLike[str],
                      suffixes: Iterable[str] | None = None) -> Path:
    """Refuse an output path that cannot be written in the format asked for.

    Parameters
    ----------
    flag
        The option that gave the path (``"--png"``), named in the message.
    path
        Where the file will be written.
    suffixes
        Accepted suffixes, lower case with the dot (``(".json",)``); ``""`` accepts a
        name without one. None accepts any.

    Returns
    -------
    Path
        ``path``, unchanged.

    Raises
    ------
    GraspGaitInputError
        An empty path, a wrong suffix, an existing directory at ``path``, or a folder
        that cannot be created or written. A missing folder is created here (as the
        write would create it), so that a path that cannot exist fails before the work.
    """
    text = os.fspath(path)
    if not text.strip():
        raise GraspGaitInputError(f"{flag} {text!r}: empty path; give a file name")
    p = Path(text)
    if suffixes is not None:
        allowed = tuple(suffixes)
        if p.suffix.lower() not in allowed:
            shown = ", ".join(s or "(none)" for s in allowed)
            raise GraspGaitInputError(
                f"{flag} {text}: the suffix {p.suffix or '(none)'!r} names no format this "
                f"writes; use one of {shown}")
    if p.is_dir():
        raise GraspGaitInputError(f"{flag} {text}: is a directory; give a file path inside it")
    parent = p.parent
    if not parent.exists():
        # create the folder now, so that a path that cannot exist fails before the work
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise GraspGaitInputError(
                f"{flag} {text}: cannot create the folder {parent} ({exc.strerror or exc}); "
                "give a path in a writable folder") from None
    if not parent.is_dir():
        raise GraspGaitInputError(f"{flag} {text}: {parent} is not a folder; give a path in one")
    try:  # a real write, not os.access: right for root and for read-only file systems
        with tempfile.TemporaryFile(dir=parent):
            pass
    except OSError as exc:
        raise GraspGaitInputError(
            f"{flag} {text}: cannot write in the folder {parent} ({exc.strerror or exc}); "
            "give a path in a writable folder") from None
    return p
