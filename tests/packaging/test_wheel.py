"""The built wheel is what a user installs: one import name, everything the code reads,
metadata, and the commands a new user runs first, from a folder that is not a clone.

The wheel is built once (``pip wheel --no-deps --no-build-isolation``). The default tests
unpack it into a fresh folder put first on ``PYTHONPATH`` (the third-party packages come
from this environment, every extra installed) and run from another, empty folder, so the
checkout cannot be imported by accident. The slow test installs it into a fresh virtual
environment with the base dependencies only, as ``pip install graspgait_env`` would.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import venv
import zipfile
from email.parser import Parser
from pathlib import Path

import pytest

import graspgait_env
from graspgait_env.agents.bench import SHIPPED_AGENTS
from graspgait_env.envs.registration import ENV_IDS

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "graspgait_env" / "configs"
EXTRA_MODULES = ("torch", "stable_baselines3", "sb3_contrib", "tensorboard", "ray", "rl_zoo3",
                 "moviepy", "imageio_ffmpeg")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "-w", str(out), str(ROOT)],
        cwd=out, capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stdout[-2000:] + build.stderr[-3000:]
    # every folder of the package is declared (setuptools warns about one left out)
    assert "BuildBackendWarning" not in build.stdout + build.stderr, build.stderr[-3000:]
    wheels = sorted(out.glob("graspgait_env-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


@pytest.fixture(scope="module")
def site(wheel: Path, tmp_path_factory) -> Path:
    """The wheel unpacked: the folder a non-editable install puts in site-packages."""
    folder = tmp_path_factory.mktemp("site")
    zipfile.ZipFile(wheel).extractall(folder)
    return folder


def _dist_info(names: list[str], leaf: str) -> str:
    found = [n for n in names if n.endswith(f".dist-info/{leaf}")]
    assert len(found) == 1, (leaf, found)
    return found[0]


def test_wheel_has_one_top_level_import_name(wheel: Path) -> None:
    zf = zipfile.ZipFile(wheel)
    names = zf.namelist()
    top = zf.read(_dist_info(names, "top_level.txt")).decode().split()
    assert top == ["graspgait_env"]
    roots = {n.split("/")[0] for n in names}
    assert roots == {"graspgait_env", f"graspgait_env-{graspgait_env.__version__}.dist-info"}
    for pkg in ("agents", "baselines", "configs"):  # beneath graspgait_env, not beside it
        assert f"graspgait_env/{pkg}/__init__.py" in names, pkg


def test_wheel_carries_every_config_asset_and_shipped_agent(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    sources = sorted(p.relative_to(CONFIGS) for p in CONFIGS.rglob("*.y*ml"))
    assert sources, "no configs found in the checkout"
    missing = [str(p) for p in sources if f"graspgait_env/configs/{p.as_posix()}" not in names]
    assert not missing, f"configs missing from the wheel: {missing}"
    assert "graspgait_env/sim/assets/hand.xml" in names
    for pkg in ("planners", "envs", "sim", "baselines", "agents"):
        assert any(n.startswith(f"graspgait_env/{pkg}/") and n.endswith(".py")
                   for n in names), pkg
    for name in SHIPPED_AGENTS:  # the model, its card and its Markdown card
        for suffix in (".zip", ".json", ".md"):
            assert f"graspgait_env/agents/models/{name}{suffix}" in names, name + suffix


def test_wheel_metadata(wheel: Path) -> None:
    zf = zipfile.ZipFile(wheel)
    names = zf.namelist()
    meta = Parser().parsestr(zf.read(_dist_info(names, "METADATA")).decode())
    assert meta["Version"] == graspgait_env.__version__
    assert meta["License-Expression"] == "MIT"
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)
    assert meta["Author"] and meta["Keywords"]
    assert len(meta.get_all("Classifier")) >= 5
    requires = meta.get_all("Requires-Dist")
    base = [r for r in requires if "extra ==" not in r]
    heavy = ("torch", "stable-baselines3", "sb3-contrib", "ray", "rl_zoo3", "tensorboard",
             "moviepy", "imageio-ffmpeg")
    assert not [r for r in base if r.startswith(heavy)], base  # extras, not the base
    torch = [r for r in requires if r.startswith("torch")]
    assert torch == ['torch>=2.1; extra == "train"'], torch  # a lower bound, never a pin
    assert not [r for r in requires if "==" in r.split(";")[0]], "no exact pins"
    extras = set(meta.get_all("Provides-Extra"))
    assert {"train", "ray", "zoo", "video", "all"} <= extras
    entry = zf.read(_dist_info(names, "entry_points.txt")).decode()
    assert "graspgait = graspgait_env.cli:main" in entry


SCRIPT = r"""
import sys, pathlib
import gymnasium as gym
import graspgait_env as gg
from graspgait_env.agents.card import load_agent, shipped_agents, shipped_models_dir
from graspgait_env.resources import bundled_names
from graspgait_env.sim.config import load_sim_config
from graspgait_env.workspace import bundled_hands, load_hand
site = pathlib.Path(sys.argv[1]).resolve()
assert pathlib.Path(gg.__file__).resolve().is_relative_to(site), gg.__file__
assert shipped_models_dir().resolve().is_relative_to(site), shipped_models_dir()
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
model, card = load_agent("circle")
assert card["env_id"] == "GraspGait-v0", card
print("objects", len(names), "hands", len(hands), "agents", ",".join(shipped_agents()))
"""


def _run(args: list[str], cwd: Path, site: Path, timeout: int = 300
         ) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(site), "MPLBACKEND": "Agg"}
    return subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=timeout)


def test_installed_wheel_works_from_another_directory(site: Path, tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = _run([sys.executable, "-c", SCRIPT, str(site)], elsewhere, site)
    assert run.returncode == 0, run.stdout + run.stderr[-3000:]
    assert f"agents {','.join(sorted(SHIPPED_AGENTS))}" in run.stdout
    plan = _run([sys.executable, "-m", "graspgait_env.cli", "plan", "ellipse", "--mu", "0.7",
                 "--planner", "rule", "--json", "plan.json"], elsewhere, site)
    assert plan.returncode == 0, plan.stdout + plan.stderr[-3000:]
    assert (elsewhere / "plan.json").is_file()
    sim_cfg = _run([sys.executable, "-c",
                    "import graspgait_env.sim.config as c; print(c.DEFAULT_SIM_CONFIG)"],
                   elsewhere, site)
    assert sim_cfg.returncode == 0, sim_cfg.stderr[-2000:]
    assert Path(sim_cfg.stdout.strip()).resolve().is_relative_to(site.resolve())


KITE = ("name: kite\ntype: polygon\n"
        "vertices: [[0.07, 0.0], [0.0, 0.05], [-0.09, 0.0], [0.0, -0.05]]\n")


@pytest.mark.parametrize("argv", [
    ["evaluate", "circle", "--episodes", "3"],
    ["evaluate", "general", "--object", "kite.yaml", "--episodes", "3"],
    ["story", "general"],
    ["bench", "--agents", "shipped", "--objects", "pentagon", "--starts", "2"],
    ["evaluate", "--list"],
    ["config", "sim", "default"],
], ids=lambda a: "-".join(a[:2]))
def test_a_new_users_first_commands_run_from_an_empty_folder(site: Path, tmp_path: Path,
                                                             argv: list[str]) -> None:
    """The installed wheel, every extra installed, in a folder holding only the object
    file the user wrote: shipped agents by name, a user's object, the bench."""
    (tmp_path / "kite.yaml").write_text(KITE)
    run = _run([sys.executable, "-m", "graspgait_env.cli", *argv, *(
        ["--quiet"] if argv[0] == "evaluate" and "--list" not in argv else [])],
               tmp_path, site)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-3000:]
    out = run.stdout
    if argv[0] == "evaluate" and "--list" not in argv:
        assert "success: " in out and "of 3 episodes" in out
    if "--object" in argv:
        assert "kite" in out
    if argv[0] == "story":
        assert (tmp_path / "out" / "ellipse_learned_plan.json").is_file()
    if argv[0] == "bench":
        assert "| pentagon |" in out and "pentagon" in out.split("agent")[-1]
    if argv[:1] == ["config"]:
        assert out == (CONFIGS / "sim" / "default.yaml").read_text()
    if "--list" in argv:
        for name in SHIPPED_AGENTS:
            assert name in out
        assert str(site) in out  # the install's models, not the clone's


BASE_SCRIPT = r"""
import json, sys, importlib.util
import gymnasium as gym
import graspgait_env
from graspgait_env.envs.registration import ENV_IDS
extras = [m for m in sys.argv[1].split(",") if importlib.util.find_spec(m) is not None]
made = []
for env_id in ENV_IDS:
    env = gym.make(env_id)
    env.reset(seed=0)
    env.step(int(env.unwrapped.action_masks().nonzero()[0][0]))
    env.close()
    made.append(env_id)
print(json.dumps({"made": made, "extras_present": extras}))
"""


@pytest.mark.slow
def test_base_install_makes_every_env_and_names_a_missing_extra(wheel: Path,
                                                                tmp_path: Path) -> None:
    """``pip install graspgait_env`` (the wheel, base dependencies only, from the package
    index) into a fresh venv outside the repository: ``gym.make`` works for every
    registered id, no extra's module is installed, and a command that needs one exits 2
    with one line naming it."""
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    py = env_dir / "bin" / "python"
    install = subprocess.run([str(py), "-m", "pip", "install", "-q", str(wheel)],
                             capture_output=True, text=True, timeout=1200)
    assert install.returncode == 0, install.stdout[-2000:] + install.stderr[-3000:]
    work = tmp_path / "empty"
    work.mkdir()
    clean = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    clean["MPLBACKEND"] = "Agg"

    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([str(py), *args], cwd=work, env=clean, capture_output=True,
                              text=True, timeout=600)

    r = run("-c", BASE_SCRIPT, ",".join(EXTRA_MODULES))
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    doc = json.loads(r.stdout.strip().splitlines()[-1])
    assert doc["made"] == list(ENV_IDS) and len(doc["made"]) >= 3
    assert doc["extras_present"] == [], doc  # the base install pulled no extra in
    site = run("-c", "import graspgait_env, pathlib; print(pathlib.Path("
               "graspgait_env.__file__).parent.parent)").stdout.strip()
    top = sorted(Path(site).glob("graspgait_env-*.dist-info/top_level.txt"))
    assert len(top) == 1 and top[0].read_text().split() == ["graspgait_env"]
    assert not (Path(site) / "agents").exists() and not (Path(site) / "baselines").exists()
    script = env_dir / "bin" / "graspgait"
    for argv, extra in ((["train", "smoke"], "train"),
                        (["evaluate", "hexagon", "--episodes", "1"], "train"),
                        (["bench", "--starts", "1", "--ray"], "ray")):
        r = subprocess.run([str(script), *argv], cwd=work, env=clean, capture_output=True,
                           text=True, timeout=600)
        assert r.returncode == 2, (argv, r.stdout[-1000:], r.stderr[-2000:])
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1, (argv, r.stderr)
        assert f"needs the [{extra}] extra" in lines[0], lines[0]
        assert f"pip install 'graspgait_env[{extra}]'" in lines[0], lines[0]
    # what needs no extra works: the map-level library and the planners
    r = subprocess.run([str(script), "plan", "pentagon", "--mu", "0.7", "--planner", "rule"],
                       cwd=work, env=clean, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
