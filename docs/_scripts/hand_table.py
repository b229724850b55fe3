"""The tables of docs/science/hand.md: the perturbed campaigns with each switch back.

For each row, the rule-based and optimal gaits of the four thesis objects at mu 0.7
(``graspgait plan OBJECT --mu 0.7 --planner P --json PLAN``, for the hand's contact model
unless the row says ``--point-contacts``), each run 10 times from a random initial pose
error (``graspgait simulate PLAN --seeds 0-9 --config SIM.yaml``, up to 6 mm and 5°) with
the simulation config of the row: the bundled one with the row's keys changed. A run
succeeds when the object turns without a drop and ends within 3° of the planned
orientation (its turn, for the circle, whose orientation cannot be observed).

    python docs/_scripts/hand_table.py --out out/hand_table.md   # about 17 min, one core
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import platform
import sys
import tempfile
import time
from datetime import date
from pathlib import Path

OBJECTS = ("circle", "ellipse", "pentagon", "hexagon")
PLANNERS = ("rule", "optimal")
SEEDS = range(10)
TOL_DEG = 3.0
THESIS_SPEEDS = {"trapezoidal_speed": False, "free_speed": 0.044, "approach_speed": 0.044,
                 "recenter_speed": 0.044, "rotation_speed_deg": 30.0}
# (label, point-contact plans, sim-config keys)
ROWS: list[tuple[str, bool, dict]] = [
    ("defaults", False, {}),
    ("point contacts", True, {}),
    ("cone_mu", False, {"cone_mu": 0.7}),
    ("rolling", False, {"rolling_compensation": False}),
    ("transfer", False, {"localize_during_transfer": False}),
    ("stabilization", False, {"stabilization_finger": True}),
    ("servo 1 kHz", False, {"servo_decimation": 1}),
    ("servo 3.5 kHz", False, {"timestep": 0.000285714, "servo_decimation": 1}),
    ("contact magnitude", False, {"contact_along_approach": False}),
    ("localizer", False, {"localizer_iterate": False, "localizer_prior_weight": 0.0}),
    ("probe", False, {"initial_probe": False}),
    ("constant velocity", False, {"trapezoidal_speed": False}),
    ("thesis speeds", False, THESIS_SPEEDS),
]


def _plan(obj: str, planner: str, point: bool, folder: Path) -> Path:
    from graspgait_env.cli import main

    path = folder / f"{obj}_{planner}_{'point' if point else 'hand'}.json"
    if not path.is_file():
        args = ["plan", obj, "--mu", "0.7", "--planner", planner, "--json", str(path)]
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(args + (["--point-contacts"] if point else [])) == 0
    return path


def _good(r: dict | None) -> bool:
    if r is None:
        return False
    err = r["final_angle_error_deg"] if r["orientation_observable"] else r["rotation_error_deg"]
    return bool(r["success"] and not r["dropped"] and abs(err) <= TOL_DEG)


def main() -> None:
    from graspgait_env.baselines.scale_out import campaign
    from graspgait_env.plan import Plan
    from graspgait_env.sim.config import load_sim_config

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="hand_table.md")
    ap.add_argument("--rows", default="", help="labels to run, comma-separated (default all)")
    args = ap.parse_args()
    wanted = [r for r in ROWS if not args.rows or r[0] in args.rows.split(",")]
    folder = Path(tempfile.mkdtemp(prefix="hand_table_"))
    lines = [f"measured {date.today().isoformat()}, Python {platform.python_version()}, "
             f"{platform.machine()}", "",
             "| row | success | circle, ellipse, pentagon, hexagon (rule, optimal) | wall (s) |",
             "|---|---:|---|---:|"]
    for label, point, keys in wanted:
        config = load_sim_config(overrides=keys or None)
        t0 = time.perf_counter()
        counts = []
        for obj in OBJECTS:
            for planner in PLANNERS:
                plan = Plan.load(_plan(obj, planner, point, folder))
                results, _ = campaign(plan, list(SEEDS), config, progress=False)
                counts.append(sum(_good(r) for r in results))
        wall = time.perf_counter() - t0
        lines.append(f"| {label} | {sum(counts)}/{len(counts) * len(SEEDS)} | "
                     f"{', '.join(map(str, counts))} | {wall:.0f} |")
        print(lines[-1], json.dumps(keys), flush=True)
        Path(args.out).write_text("\n".join(lines) + "\n")
    sys.stdout.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
