"""The README's commands and snippets run as written.

Every ```python block runs in a fresh interpreter; every ```yaml block is a valid object
file; every ``graspgait`` line of the ```sh blocks runs, in order, in one scratch folder
(so a later line can use what an earlier one wrote). ``make demo`` and ``make test`` are
the two commands CI itself runs (``.ci/run``), so they are not run again from here.
``graspgait bench`` and ``graspgait perf`` take minutes, and a line that renders a MuJoCo
video (``--video``) takes half a minute: they run in the slow suite.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BIN = Path(sys.executable).parent
SLOW_COMMANDS = {"bench", "perf"}
SLOW_FLAGS = {"--video"}


def _blocks(lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", README, flags=re.S | re.M)


def _commands() -> list[list[str]]:
    out = []
    for block in _blocks("sh"):
        for line in block.replace("\\\n", " ").splitlines():
            words = shlex.split(line, comments=True)
            if words and words[0] == "graspgait":
                out.append(words)
    return out


def _env() -> dict[str, str]:
    return {**os.environ, "MPLBACKEND": "Agg", "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}


MAX_LINES = 200  # a screen's worth: the rest is in the documentation site (docs/)
# the project's history lives in CHANGELOG.md; the README says what is, not what was
HISTORY_WORDS = ("was ", "were ", "previously", "this session", "earlier run",
                 "load average", "used to ", "no longer", "at the time")


def test_readme_is_short_and_holds_no_history() -> None:
    lines = README.splitlines()
    assert len(lines) <= MAX_LINES, f"README.md has {len(lines)} lines; move some to docs/"
    found = [(n, w) for n, line in enumerate(lines, 1) for w in HISTORY_WORDS
             if w in line.lower()]
    assert not found, f"history in README.md (line, word): {found}; it belongs in CHANGELOG.md"


def test_readme_links_point_into_the_repository() -> None:
    """Every link of the README is a file of the repository (the documentation site's
    sources), never an address outside it."""
    links = re.findall(r"\]\(([^)\s]+)\)", README)
    assert len(links) >= 10
    for link in links:
        assert "://" not in link, f"README.md links outside the repository: {link}"
        path = (ROOT / link.split("#")[0]).resolve()
        assert path.exists() and ROOT in path.parents, f"README.md: no such file {link}"


def test_readme_has_what_this_test_runs() -> None:
    assert len(_blocks("python")) >= 2
    assert len(_commands()) >= 6
    assert {c[1] for c in _commands()} >= {"map", "plan", "simulate", "bench", "perf"}
    assert any(ln.startswith("make demo") for b in _blocks("sh") for ln in b.splitlines())


@pytest.mark.parametrize("i", range(len(_blocks("python"))))
def test_python_snippet_runs(i: int, tmp_path: Path) -> None:
    code = _blocks("python")[i]
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=_env(),
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"snippet {i}:\n{code}\n{run.stderr[-3000:]}"


def test_yaml_snippets_are_valid_object_files(tmp_path: Path) -> None:
    import numpy as np

    from graspgait_env import load_object

    blocks = _blocks("yaml")
    assert blocks
    for k, text in enumerate(blocks):
        path = tmp_path / f"snippet{k}.yaml"
        path.write_text(text)
        shape = load_object(path)
        bundled = load_object(shape.name)  # the README shows a bundled object as written
        phi = np.arange(0.0, 360.0, 1.0)
        np.testing.assert_allclose(shape.radius(phi), bundled.radius(phi))


def _is_slow(words: list[str]) -> bool:
    return words[1] in SLOW_COMMANDS or bool(SLOW_FLAGS.intersection(words))


def _run_commands(tmp_path: Path, slow: bool) -> int:
    ran = 0
    for words in _commands():
        # the fast pass skips the slow lines; the slow pass runs every line, so that a
        # slow line finds what the lines before it wrote (hand.json)
        if not slow and _is_slow(words):
            continue
        run = subprocess.run([str(BIN / words[0]), *words[1:]], cwd=tmp_path, env=_env(),
                             capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, f"{shlex.join(words)}:\n{run.stderr[-3000:]}"
        for w in words:  # every file it was told to write is there
            if re.search(r"\.(png|npy|json|txt|mp4|csv|md)$", w):
                assert (tmp_path / w).is_file(), f"{shlex.join(words)} did not write {w}"
        ran += _is_slow(words) == slow  # count the lines of this pass's kind
    return ran


def test_readme_commands_run(tmp_path: Path) -> None:
    assert _run_commands(tmp_path, slow=False) >= 5


@pytest.mark.slow
def test_readme_slow_commands_run(tmp_path: Path) -> None:
    assert _run_commands(tmp_path, slow=True) >= 3
