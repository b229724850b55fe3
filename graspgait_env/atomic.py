"""Atomic file writes: nothing is lost or half-written on failure."""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, BinaryIO

__all__ = ["atomic_write", "json_ready", "write_text_atomic"]


def atomic_write(path: str | os.PathLike[str], write: Callable[[BinaryIO], object]) -> Path:
    """Write a file atomically: ``write(fh)`` into a temporary file, then rename.

    The temporary file lives in the target's directory (created if missing), so
    :func:`os.replace` is atomic: a reader sees the old file or the whole new one,
    never a partial write. On any error the temporary file is removed.

    Parameters
    ----------
    path
        Target file.
    write
        Called with the open binary file handle.

    Returns
    -------
    Path
        The path written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        os.chmod(tmp, 0o644)  # mkstemp makes it private; outputs are for reading
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_write`)."""
    return atomic_write(path, lambda fh: fh.write(text.encode("utf-8")))


def json_ready(x: Any) -> Any:
    """``x`` with what JSON cannot hold replaced: NaN and infinities by None, NumPy scalars
    by Python numbers, mapping keys by strings, tuples by lists (recursively)."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, Mapping):
        return {str(k): json_ready(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_ready(v) for v in x]
    if hasattr(x, "item") and callable(x.item):  # NumPy scalars
        return json_ready(x.item())
    return x
