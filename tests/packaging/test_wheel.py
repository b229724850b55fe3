"""The built wheel carries everything the code reads, and works from any directory.

Builds the wheel (``pip wheel --no-deps --no-build-isolation``), checks that every file
of the source ``configs/`` and the MJCF assets are inside it, unpacks it into a fresh
folder, and from another directory (so the checkout cannot be imported by accident)
loads every bundled object and hand and the sim config, and runs ``graspgait plan``.
The third-party dependencies come from the test's own environment.
"""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(out), str(ROOT)],
        cwd=out, capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stdout[-2000:] + build.stderr[-3000:]
    wheels = sorted(out.glob("graspgait_env-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


def test_wheel_carries_every_config_and_asset(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    sources = sorted(p.relative_to(ROOT / "configs") for p in (ROOT / "configs").rglob("*.y*ml"))
    assert sources, "no configs found in the checkout"
    missing = [str(p) for p in sources if f"graspgait_env/configs/{p.as_posix()}" not in names]
    assert not missing, f"configs missing from the wheel: {missing}"
    assert "graspgait_env/sim/assets/hand.xml" in names
    for pkg in ("graspgait_env/planners/", "graspgait_env/envs/", "graspgait_env/sim/",
                "baselines/", "agents/"):
        assert any(n.startswith(pkg) for n in names), pkg


SCRIPT = r"""
import sys, pathlib
import graspgait_env as gg
from graspgait_env.resources import bundled_names
from graspgait_env.sim.config import load_sim_config
from graspgait_env.workspace import bundled_hands, load_hand
site = pathlib.Path(sys.argv[1]).resolve()
assert pathlib.Path(gg.__file__).resolve().is_relative_to(site), gg.__file__
names = gg.bundled_objects()
assert len(names) >= 10, names
for name in names:
    gg.load_object(name)
hands = bundled_hands()
assert "thesis" in hands, hands
for name in hands:
    load_hand(name, gg.load_object("ellipse"))
assert bundled_names("sim") == ["default"]
cfg = load_sim_config()
print("objects", len(names), "hands", len(hands), "sim", type(cfg).__name__)
"""


def test_installed_wheel_works_from_another_directory(wheel: Path, tmp_path: Path) -> None:
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site), "MPLBACKEND": "Agg"}
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(site)], cwd=elsewhere, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr[-3000:]
    assert "objects" in run.stdout
    plan = subprocess.run(
        [sys.executable, "-m", "graspgait_env.cli", "plan", "ellipse", "--mu", "0.7",
         "--planner", "rule", "--json", "plan.json"],
        cwd=elsewhere, env=env, capture_output=True, text=True, timeout=300)
    assert plan.returncode == 0, plan.stdout + plan.stderr[-3000:]
    assert (elsewhere / "plan.json").is_file()
    sim_cfg = subprocess.run(
        [sys.executable, "-c", "import graspgait_env.sim.config as c; print(c.DEFAULT_SIM_CONFIG)"],
        cwd=elsewhere, env=env, capture_output=True, text=True, timeout=300)
    assert sim_cfg.returncode == 0, sim_cfg.stderr[-2000:]
    assert Path(sim_cfg.stdout.strip()).resolve().is_relative_to(site.resolve())
