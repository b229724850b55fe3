"""The reference pages' Python examples run (each block in a fresh interpreter), as the
README's do; the tutorials' run in tests/docs/test_tutorials.py. A block whose first line
is a comment starting ``# slow`` (a measurement that takes minutes) runs in the slow suite
only (``make test-all``)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def _snippets() -> list[tuple[str, int, str]]:
    out = []
    for path in sorted(DOCS.rglob("*.md")):
        rel = path.relative_to(DOCS).as_posix()
        if rel.startswith(("tutorials/", "_scripts/")):
            continue
        blocks = re.findall(r"^```python\n(.*?)^```", path.read_text(encoding="utf-8"),
                            flags=re.S | re.M)
        out += [(rel, i, code) for i, code in enumerate(blocks)]
    return out


def _params() -> list:
    return [pytest.param(p, i, code, id=f"{p}-{i}",
                         marks=[pytest.mark.slow] if code.startswith("# slow") else [])
            for p, i, code in _snippets()]


@pytest.mark.parametrize(("page", "i", "code"), _params())
def test_page_snippet_runs(page: str, i: int, code: str, tmp_path: Path) -> None:
    env = {**os.environ, "MPLBACKEND": "Agg", "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"docs/{page}, block {i}:\n{run.stderr[-3000:]}"
