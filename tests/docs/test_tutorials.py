"""The tutorials run as written.

Each tutorial (``docs/tutorials/*.md`` but the index) is one script: its ``python``
blocks in order, in one interpreter, each ``sh`` block run where it stands (``bash -c``
with ``set -euo pipefail``, this environment's ``graspgait`` and ``python`` first on
``PATH``), and each block with a file name (```` ```yaml title="egg.yaml" ````) saved
under that name, all in one scratch folder. Blocks marked ``text`` are shown, not run
(a Ray cluster's commands).

A tutorial that takes more than a few seconds runs in the slow suite as written, and in
the default suite as a quick variant: the same text with the substitutions of
:data:`QUICK` (a tiny budget, no video); each substitution must apply, so a tutorial
edit that drops one fails here.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TUTORIALS = ROOT / "docs" / "tutorials"
BIN = Path(sys.executable).parent

# tutorial -> (old, new) replacements of its quick variant (the default suite); the
# tutorials named here run as written only in the slow suite
QUICK: dict[str, list[tuple[str, str]]] = {
    "train-and-evaluate.md": [
        ("--episodes 20", "--episodes 2"),
        ("episodes=10", "episodes=2"),
    ],
    "your-own-object.md": [
        (" --video egg_gait.mp4", ""),
        ("--seeds 0-9", "--seeds 0-1"),
    ],
    "mujoco-hand.md": [
        (" --video out/ellipse_learned.mp4", ""),
        ("--episodes 5", "--episodes 1"),
    ],
    "rl-zoo.md": [
        ("-n 20000", "-n 512"),
        ("--episodes 20", "--episodes 2"),
        ("-n 1000 ", "-n 100 "),
    ],
    "ray.md": [
        ("--seeds 0-3", "--seeds 0-1"),
    ],
}
TIMEOUT_S = {"rl-zoo.md": 900}


def tutorials() -> list[str]:
    return sorted(p.name for p in TUTORIALS.glob("*.md") if p.name != "index.md")


def blocks(text: str) -> list[tuple[str, str, str]]:
    """The fenced ``python`` and ``sh`` blocks of ``text`` and the blocks with a file
    name (```` ```yaml title="egg.yaml" ````), in order: ``(lang, title, body)``."""
    found = re.findall(r'^```(python|sh|\w+ title="([^"]+)")\n(.*?)^```', text,
                       flags=re.S | re.M)
    return [(lang.split()[0], title, body) for lang, title, body in found]


def script(text: str) -> str:
    """The tutorial as one Python script (see the module docstring)."""
    out = ["import subprocess as _subprocess",
           "def _sh(cmd):",
           "    print('$', cmd, flush=True)",
           "    _subprocess.run(['bash', '-c', 'set -euo pipefail; ' + cmd], check=True)",
           ""]
    for lang, title, body in blocks(text):
        if title:  # a file the reader saves
            out.append(f"open({title!r}, 'w').write({body!r})")
        elif lang == "python":
            out.append(body)
        else:
            out.append(f"_sh({body!r})")
    return "\n".join(out) + "\n"


def quick_text(name: str) -> str:
    text = (TUTORIALS / name).read_text(encoding="utf-8")
    for old, new in QUICK.get(name, []):
        assert old in text, f"{name}: the quick variant's {old!r} is no longer in the text"
        text = text.replace(old, new)
    return text


def _run(name: str, text: str, tmp_path: Path) -> None:
    path = tmp_path / "tutorial.py"
    path.write_text(script(text), encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg",
           "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"),
           "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}"}
    run = subprocess.run([sys.executable, str(path)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=TIMEOUT_S.get(name, 600))
    assert run.returncode == 0, f"{name}:\n{run.stdout[-3000:]}\n{run.stderr[-4000:]}"


def test_every_tutorial_has_code_and_a_place_in_the_index() -> None:
    index = (TUTORIALS / "index.md").read_text(encoding="utf-8")
    assert len(tutorials()) >= 7
    for name in tutorials():
        assert blocks((TUTORIALS / name).read_text(encoding="utf-8")), name
        assert f"]({name})" in index, f"docs/tutorials/index.md does not link {name}"
    assert set(QUICK) <= set(tutorials())


@pytest.mark.parametrize("name", tutorials())
def test_tutorial_runs(name: str, tmp_path: Path) -> None:
    """The default suite: the quick variant of a slow tutorial, the others as written."""
    _run(name, quick_text(name), tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(QUICK))
def test_slow_tutorial_runs_as_written(name: str, tmp_path: Path) -> None:
    _run(name, (TUTORIALS / name).read_text(encoding="utf-8"), tmp_path)
