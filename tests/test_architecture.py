"""Architecture contracts: one-way layers and a pure-NumPy core (import-linter).

The contracts live in ``pyproject.toml`` (``[tool.importlinter]``); this test runs
``lint-imports`` on them and checks that every top-level module of the core package is
named in the layers contract, so a new module cannot slip past it.

import-linter (grimp) finds a package's modules by walking its folder, and the folders
``agents/``, ``baselines/`` and ``configs/`` of the repository install beneath
``graspgait_env`` only through ``[tool.setuptools.package-dir]``. The check therefore
runs on a copy of the sources laid out as the wheel lays them out (the mapping read from
``pyproject.toml``), so the contracts see ``graspgait_env.agents`` where users import it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import tomllib

import graspgait_env

ROOT = Path(__file__).resolve().parents[1]
COMPOSITION_ROOTS = {"cli", "perf"}  # may reach across the layers


def _contracts() -> list[dict]:
    return _pyproject()["tool"]["importlinter"]["contracts"]


def _pyproject() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)


def installed_layout(dest: Path) -> Path:
    """Copy the package's Python sources into ``dest`` as the wheel lays them out: the
    folder ``graspgait_env/`` with every ``package-dir`` mapping of ``pyproject.toml``
    (``graspgait_env.agents`` = ``agents/``, ...) placed beneath it. Returns ``dest``."""
    mapping = _pyproject()["tool"]["setuptools"].get("package-dir", {})
    ignore = shutil.ignore_patterns("__pycache__", "*.zip", "*.pyc")
    shutil.copytree(ROOT / "graspgait_env", dest / "graspgait_env", ignore=ignore)
    for package, folder in mapping.items():
        target = dest.joinpath(*package.split("."))
        shutil.copytree(ROOT / folder, target, ignore=ignore)
    return dest


def test_installed_layout_puts_every_mapped_folder_beneath_the_package(tmp_path) -> None:
    site = installed_layout(tmp_path)
    assert sorted(p.name for p in site.iterdir()) == ["graspgait_env"]
    for sub in ("agents", "baselines", "configs"):
        assert (site / "graspgait_env" / sub / "__init__.py").is_file(), sub
    assert (site / "graspgait_env" / "agents" / "policies.py").is_file()


def test_import_contracts_are_kept(tmp_path) -> None:
    site = installed_layout(tmp_path)
    exe = Path(sys.executable).with_name("lint-imports")
    env = {**os.environ, "PYTHONPATH": str(site)}
    out = subprocess.run([str(exe), "--no-cache", "--config", str(ROOT / "pyproject.toml")],
                         cwd=site, env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    assert "0 broken" in out.stdout
    # every contract was checked, the layers one on the installed names
    assert f"{len(_contracts())} kept" in out.stdout, out.stdout[-2000:]


def test_every_core_module_is_in_a_layer() -> None:
    layers = next(c for c in _contracts() if c["type"] == "layers")["layers"]
    named = {m.strip() for layer in layers for m in layer.replace("|", ":").split(":")}
    pkg = Path(graspgait_env.__file__).parent
    modules = {p.stem for p in pkg.glob("*.py")} - {"__init__"} - COMPOSITION_ROOTS
    missing = sorted(f"graspgait_env.{m}" for m in modules if f"graspgait_env.{m}" not in named)
    assert not missing, f"add {missing} to a layer of the import-linter contract"
    for sub in ("planners", "sim", "envs", "benchmark"):
        assert f"graspgait_env.{sub}" in named


def test_the_layers_run_in_the_documented_order() -> None:
    layers = next(c for c in _contracts() if c["type"] == "layers")["layers"]
    assert layers[:6] == ["graspgait_env.benchmark", "graspgait_env.agents",
                          "graspgait_env.baselines", "graspgait_env.envs", "graspgait_env.sim",
                          "graspgait_env.planners"]
