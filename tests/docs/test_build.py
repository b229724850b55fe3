"""The documentation site builds in strict mode (``make docs``): a broken link, a missing
page or a cross-reference to a renamed function is a warning, and strict mode fails on
any warning."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from graspgait_env.envs.registration import ENV_IDS

ROOT = Path(__file__).resolve().parents[2]
MKDOCS = Path(sys.executable).with_name("mkdocs")


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    assert MKDOCS.is_file(), ("mkdocs is not installed: pip install -e '.[docs]' "
                              "(make test installs it)")
    out = tmp_path_factory.mktemp("site")
    run = subprocess.run([str(MKDOCS), "build", "--strict", "--site-dir", str(out)],
                         cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert run.returncode == 0, run.stderr[-6000:]
    return out


def test_the_site_builds_strict_with_a_page_per_env_id(site: Path) -> None:
    for env_id in ENV_IDS:
        html = (site / "envs" / f"{env_id}.html").read_text(encoding="utf-8")
        for section in ("Description", "Action Space", "Observation Space", "Rewards",
                        "Starting State", "Episode End", "Arguments", "Version History"):
            assert f">{section}<" in html, (env_id, section)
    home = (site / "index.html").read_text(encoding="utf-8")
    assert "GraspGaitMujoco-v1" in home


def test_the_api_reference_renders_the_public_api(site: Path) -> None:
    html = (site / "api" / "graspgait_env.envs.map_env.html").read_text(
        encoding="utf-8")
    assert 'id="graspgait_env.envs.map_env.GraspGaitEnv"' in html
    assert 'id="graspgait_env.envs.map_env.state_from_observation"' in html
    card = (site / "api" / "graspgait_env.agents.card.html").read_text(
        encoding="utf-8")
    assert 'id="graspgait_env.agents.card.load_agent"' in card
    # a docstring's Sphinx role became a link to the object it names
    assert 'href="graspgait_env.gait.html#graspgait_env.gait.GaitModel"' in html


def test_the_site_keeps_the_reference_pages_and_the_changelog(site: Path) -> None:
    for page in ("cli", "formats", "conventions", "changelog", "gallery", "agents"):
        assert (site / f"{page}.html").is_file(), page
    assert "Keep a Changelog" in (site / "changelog.html").read_text(
        encoding="utf-8")
