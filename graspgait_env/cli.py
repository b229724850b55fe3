"""The ``graspgait`` command line.

::

    graspgait map OBJECT --mu 0.7 [--n 180] [--theta 0] [--hand thesis] [--png F] [--npy F]
    graspgait sweep eccentricity|smoothness [--n 180] [--png F]
    graspgait plan OBJECT --mu 0.7 --planner P [--start PHI1,PHI2] [--turn 360] [--json F]
                   [--motion F] [--png F]
    graspgait bench [--objects ...] [--mus 0.8,0.7] [--planners ...] [--starts 10]
                    [--agents shipped|none|NAME,...] [--csv F] [--json F] [--md F] [--png F]
    graspgait simulate PLAN.json [--video F.mp4] [--json F] [--perturb DX,DY,DTH|random]
    graspgait perf [--repeat 100] [--json F]
    graspgait train CONFIG [--set KEY=VALUE ...] [--seeds 0-4 [--ray [ADDRESS]]]
    graspgait evaluate MODEL|NAME [--object OBJECT] [--mu MU] [--episodes N] | --list
    graspgait story [MODEL|NAME] [--object OBJECT] [--start PHI1,PHI2] [--out DIR] | --list
    graspgait config [KIND [NAME]]
    graspgait benchmark POLICY [--tasks T,...] [--seeds 0-4] [--episodes N] [--ray [ADDRESS]]
                        [--out DIR] [--csv F] [--json F] [--md F] [--png F] | --list-tasks
    graspgait dataset record TASK [--policy optimal|rule] [--episodes N] [--overwrite]

Every subcommand's ``--help`` shows its defaults, examples and, for the long ones, a
rough duration. Exit status: 0 on success; 2 on bad input (an argument, a file, a
field) or a missing extra, with one line ``graspgait: error: <message>`` on stderr and
no traceback; 1 when a question has no answer
(:class:`~graspgait_env.errors.NoGaitError`).

Subcommands are registered in :data:`SUBCOMMANDS`: each entry is a function that adds
its parser to the subparsers and sets ``func`` (the handler, ``args -> int``).
"""

from __future__ import annotations

import argparse
import contextlib
import math
import shlex
import sys
import textwrap
from collections.abc import Callable, Sequence

import numpy as np

from graspgait_env.errors import GraspGaitInputError, NoGaitError

__all__ = ["main", "build_parser", "SUBCOMMANDS"]

PROG = "graspgait"


class _HelpFormatter(argparse.HelpFormatter):
    """Help that stands alone: every option with a default shows it (unless its text
    already says it), descriptions are wrapped paragraphs, and an epilog's indented lines
    (the examples) keep their line breaks."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if (action.default is None or action.default is False
                or action.default == argparse.SUPPRESS or "default" in text
                or (not action.option_strings and action.nargs not in ("?", "*"))):
            return text
        return text + " (default: %(default)s)"

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        out = []
        for para in textwrap.dedent(text).strip("\n").split("\n\n"):
            if any(line.startswith(" ") for line in para.splitlines()):
                out.append("\n".join(indent + line for line in para.splitlines()))
            else:
                out.append(textwrap.fill(" ".join(para.split()), width,
                                         initial_indent=indent, subsequent_indent=indent))
        return "\n\n".join(out)


def _epilog(examples: Sequence[str], duration: str | None = None, notes: str = "") -> str:
    """An epilog: ``examples:`` (one command per line), then notes and ``takes about``."""
    text = "examples:\n" + "\n".join(f"  {PROG} {e}" for e in examples)
    if notes:
        text += "\n\n" + notes
    if duration:
        text += f"\n\ntakes about: {duration} (2-core machine, one torch thread)"
    return text


class _Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors: ``graspgait map: error: ...; see --help``, and
    :class:`_HelpFormatter` for every (sub)parser."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("formatter_class", _HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}; see `{self.prog} --help`\n")


def _require(extra: str, what: str) -> None:
    """Refuse, in one line naming the extra to install, a command whose extra is missing;
    before the work starts, not when it reaches the first import."""
    from graspgait_env.extras import require_extra

    require_extra(extra, what)


def _require_ray(args: argparse.Namespace, what: str) -> None:
    if getattr(args, "ray", None) is not None:
        _require("ray", f"{what} --ray")


def _print_shipped() -> int:
    """``--list``: the shipped agents, one line each (name, env, latest evaluation)."""
    from graspgait_env.agents.card import describe_shipped, shipped_models_dir

    rows = describe_shipped()
    if not rows:
        print("no shipped agents in this install")
        return 0
    width = max(len(name) for name, _ in rows)
    for name, line in rows:
        print(f"{name:<{width}}  {line}")
    print(f"(models and their cards NAME.zip, NAME.json, NAME.md in {shipped_models_dir()})")
    return 0


def _input_error(flag: str, exc: ValueError) -> GraspGaitInputError:
    """A library ValueError about a numeric argument, as a user error naming the flag."""
    return GraspGaitInputError(f"{flag}: {exc}")


def _check_mu(mu: float) -> float:
    from graspgait_env.force_closure import check_mu

    try:
        return check_mu(mu)
    except ValueError as exc:
        raise _input_error("--mu", exc) from None


def _check_n(n: int) -> int:
    from graspgait_env.grasp_map import check_n

    try:
        return check_n(n)
    except ValueError as exc:
        raise _input_error("--n", exc) from None


def _check_theta(theta: float) -> float:
    if not math.isfinite(theta):
        raise GraspGaitInputError(f"--theta {theta!r}: must be a finite angle in degrees, e.g. 30")
    return float(theta)


def _check_outputs(args: argparse.Namespace, specs: dict[str, tuple[str, ...] | None]) -> None:
    """Check every output path given (``{dest: suffixes}``) before any work."""
    from graspgait_env.outputs import check_output_path

    for dest, suffixes in specs.items():
        path = getattr(args, dest, None)
        if path is not None:
            check_output_path(f"--{dest}", path, suffixes)


def _figure_suffixes() -> tuple[str, ...]:
    from graspgait_env.outputs import figure_suffixes

    return figure_suffixes()


def _object_help() -> str:
    from graspgait_env.objects import bundled_objects

    return f"a bundled object ({', '.join(bundled_objects())}) or an object YAML path"


def _hand_help() -> str:
    from graspgait_env.workspace import bundled_hands

    return (f"a bundled hand ({', '.join(bundled_hands())}) or a hand YAML path "
            "(default: thesis, fig. 4.1)")


def _write_output(flag: str, path: str, write: Callable[[], object]) -> None:
    """Run a writer; an unwritable path is the user's to fix (exit 2), not a crash."""
    try:
        write()
    except OSError as exc:
        raise GraspGaitInputError(
            f"{flag} {path}: cannot write ({exc.strerror or exc}); give a writable path"
        ) from None


# --- map ------------------------------------------------------------------------------


def _cmd_map(args: argparse.Namespace) -> int:
    from graspgait_env.grasp_map import grasp_map
    from graspgait_env.objects import load_object
    from graspgait_env.workspace import load_hand

    mu = _check_mu(args.mu)
    n = _check_n(args.n)
    theta = _check_theta(args.theta)
    _check_outputs(args, {"png": _figure_suffixes() if args.png else None, "npy": (".npy",)})
    shape = load_object(args.object)
    hand, max_radius = load_hand(args.hand, shape)
    gm = grasp_map(shape, mu, n, max_radius=max_radius)
    cells = int(gm.stable.sum())
    print(shape.describe())
    ws = ", ".join(f"{k + 1}: [{lo:g}, {hi:g}]" for k, (lo, hi) in enumerate(hand.workspaces_deg))
    print(f"hand {hand.name}: workspaces (deg) {ws}; w = {hand.w_deg:g} deg")
    print(f"grasp map n={gm.n} ({gm.step_deg:g} deg grid), mu={gm.mu:g}: "
          f"{cells} of {gm.n * gm.n} cells stable (fraction {gm.fraction_stable():.4f})")
    if args.npy:
        from graspgait_env.plotting import atomic_write

        _write_output("--npy", args.npy,
                      lambda: atomic_write(args.npy, lambda fh: np.save(fh, gm.stable)))
        print(f"wrote {args.npy}")
    if args.png:
        from graspgait_env.plotting import map_figure, save_figure

        fig = map_figure(shape, mu, n, hand, theta, gm=gm)
        _write_output("--png", args.png, lambda: save_figure(fig, args.png))
        print(f"wrote {args.png}")
    return 0


def _add_map(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("map", help="compute and plot an object's grasp map (thesis ch. 3)",
                       description="Compute the grasp map of OBJECT at friction MU; print a "
                       "summary, optionally save the map (.npy) and a figure (.png): object "
                       "with normals, grasp map, extended map with the hand's finger pair "
                       "boxes at object angle THETA (thesis figs. 3.1, 4.5, 6.1).",
                       epilog=_epilog(["map ellipse --mu 0.7 --png ellipse_map.png",
                                       "map pentagon --mu 0.5 --theta 30 --hand wide "
                                       "--npy pentagon.npy",
                                       "map my_shape.yaml --mu 0.7 --png my_map.png"],
                                      notes="Write your own object YAML from a bundled one: "
                                      f"`{PROG} config objects pentagon > my_shape.yaml`."))
    p.add_argument("object", metavar="OBJECT", help=_object_help())
    p.add_argument("--mu", type=float, required=True, help="Coulomb friction coefficient (> 0)")
    p.add_argument("--n", type=int, default=180,
                   help="contacts on the contour (default 180: 2 deg)")
    p.add_argument("--theta", type=float, default=0.0,
                   help="object angle (deg) at which the finger pair boxes are drawn "
                   "(default 0)")
    p.add_argument("--hand", default=None,
                   help=_hand_help())
    p.add_argument("--png", metavar="FILE", help="write the figure here")
    p.add_argument("--npy", metavar="FILE", help="write the boolean map here (np.save)")
    p.set_defaults(func=_cmd_map)


# --- sweep ----------------------------------------------------------------------------


def _cmd_sweep(args: argparse.Namespace) -> int:
    from graspgait_env.grasp_map import grasp_map
    from graspgait_env.plotting import SWEEP_MUS, save_figure, sweep_figure, sweep_objects

    n = _check_n(args.n)
    png = args.png or f"sweep_{args.kind}.png"
    from graspgait_env.outputs import check_output_path

    check_output_path("--png", png, _figure_suffixes())
    print(f"{args.kind} sweep, n={n}: fraction of stable cells")
    print("object    " + "".join(f"  mu={mu:<5g}" for mu in SWEEP_MUS))
    for label, shape in sweep_objects(args.kind):
        fr = [grasp_map(shape, mu, n).fraction_stable() for mu in SWEEP_MUS]
        print(f"{label:<10}" + "".join(f"  {f:<8.4f}" for f in fr))
    fig = sweep_figure(args.kind, SWEEP_MUS, n)
    _write_output("--png", png, lambda: save_figure(fig, png))
    print(f"wrote {png}")
    return 0


def _add_sweep(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sweep", help="grasp maps over eccentricity or smoothness and friction",
                       description="Grasp maps of ellipses of decreasing eccentricity, or of a "
                       "circle and polygons of decreasing smoothness, for mu = .9 .. .1 "
                       "(thesis figs. 3.8-3.11).",
                       epilog=_epilog(["sweep eccentricity --png ecc.png",
                                       "sweep smoothness --n 90"], duration="10 s at n 180"))
    p.add_argument("kind", choices=("eccentricity", "smoothness"),
                   help="ellipses of decreasing eccentricity, or polygons of decreasing "
                   "smoothness")
    p.add_argument("--n", type=int, default=180, help="contacts on the contour (default 180)")
    p.add_argument("--png", metavar="FILE", help="figure path (default sweep_KIND.png)")
    p.set_defaults(func=_cmd_sweep)


# --- perf -----------------------------------------------------------------------------


def _cmd_perf(args: argparse.Namespace) -> int:
    from graspgait_env import perf

    if args.repeat < 1:
        raise GraspGaitInputError(f"--repeat {args.repeat}: must be >= 1, e.g. 100")
    _check_outputs(args, {"json": (".json",)})
    rows = perf.run_benchmarks(args.repeat)
    print(perf.environment_line())
    print()
    print(perf.markdown_table(rows))
    failed = [r.name for r in rows if r.passed is False]
    for mod, extra in perf.skipped_benchmark_modules():
        print(f"skipped {mod}: needs the [{extra}] extra (pip install "
              f"'graspgait_env[{extra}]')")
    print()
    print(f"FAIL: {', '.join(failed)}" if failed else "all targets PASS")
    if args.json:
        _write_output("--json", args.json, lambda: perf.write_json(rows, args.json))
        print(f"wrote {args.json}")
    return 0  # a missed target is reported, not an error


def _add_perf(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("perf", help="measure the performance targets",
                       description="Time every registered benchmark on this machine and print "
                       "one Markdown table of rows (measured figure, target, PASS/FAIL): the "
                       "grasp map (vectorized, against a per-cell loop in the same process), "
                       "the planners, the Gymnasium envs (steps/s of GraspGait-v0 against "
                       "CartPole-v1 in the same process, and the batched env against the "
                       "single one), rendering, the MuJoCo hand (a 360 deg gait's wall time, "
                       "physics steps/s) and, with the [train] extra, SB3 training "
                       "throughput. Exit 0 even when a target FAILs: a missed target is "
                       "reported, not an error.",
                       epilog=_epilog(["perf", "perf --repeat 20 --json perf.json"],
                                      duration="90 s with the defaults"))
    p.add_argument("--repeat", type=int, default=100,
                   help="timed repeats of the fast rows (their median; default 100)")
    p.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    p.set_defaults(func=_cmd_perf)


# --- plan -----------------------------------------------------------------------------


def _parse_start(text: str | None, model) -> object:
    """``PHI1,PHI2`` (object-frame degrees at theta = 0) to a start state; fingers follow
    from the workspaces each contact lies in."""
    if text is None:
        return None
    parts = text.split(",")
    try:
        phis = [float(p) for p in parts]
    except ValueError:
        phis = []
    if len(phis) != 2 or not all(math.isfinite(p) for p in phis):
        raise GraspGaitInputError(f"--start {text!r}: give two contact angles in degrees, "
                                  "e.g. --start 50,270")
    fingers = model.hand.finger_at(phis)
    for phi, f in zip(phis, fingers, strict=True):
        if f == 0:
            raise GraspGaitInputError(f"--start: contact {phi:g} deg lies in no finger's "
                                      f"workspace {list(model.hand.workspaces_deg)}; move it")
    if fingers[0] == fingers[1]:
        raise GraspGaitInputError(f"--start {text}: both contacts lie in finger "
                                  f"{int(fingers[0])}'s workspace; use two fingers")
    return model.start_state({int(f): phi for f, phi in zip(fingers, phis, strict=True)})


def _cmd_plan(args: argparse.Namespace) -> int:
    from graspgait_env.gait import GaitModel
    from graspgait_env.plan import InvalidPlanError, validate_plan
    from graspgait_env.planners.registry import get_planner, run_planner

    mu = _check_mu(args.mu)
    n = _check_n(args.n)
    if not math.isfinite(args.turn) or args.turn == 0:
        raise GraspGaitInputError(f"--turn {args.turn!r}: give a non-zero finite angle in "
                                  "degrees (positive counter-clockwise), e.g. 360")
    get_planner(args.planner)  # refuse unknown names before any work
    clearance = args.vertex_clearance
    if not (math.isfinite(clearance) and 0 <= clearance < 90):
        raise GraspGaitInputError(f"--vertex-clearance {clearance!r}: give degrees in "
                                  "[0, 90), e.g. 4 for plans run on the MuJoCo hand")
    _check_outputs(args, {"json": (".json",), "motion": ("", ".txt"),
                          "png": _figure_suffixes() if args.png else None})
    from graspgait_env.gait import MAX_PLAN_N

    if n > MAX_PLAN_N:
        raise GraspGaitInputError(f"--n {n}: planning takes at most {MAX_PLAN_N} grid points "
                                  f"(a {360 / MAX_PLAN_N:g}-degree grid; about 3 GB at n=1800); "
                                  "give e.g. 180")
    contact_model = _plan_contact_model(args)
    model = GaitModel(args.object, mu, hand=args.hand, n=n, vertex_clearance_deg=clearance,
                      contact_model=contact_model)
    try:
        model.turn_steps(args.turn)  # refuses a turn beyond what the planners can hold
    except GraspGaitInputError as exc:
        raise GraspGaitInputError(f"--turn: {exc}") from None
    start = _parse_start(args.start, model)
    res = run_planner(args.planner, model, start, args.turn)
    print(model.shape.describe())
    print(_describe_contact_model(contact_model))
    print(f"planner {res.planner}: nodes opened {res.nodes_opened}, created "
          f"{res.nodes_created}, wall time {res.wall_time_s * 1000:.1f} ms")
    if res.plan is None:
        from graspgait_env.planners.diagnosis import diagnose_no_gait

        # at most three lines (verdict, why, fix); the planner's own account and every
        # detail of the diagnosis under --verbose
        diagnosis = diagnose_no_gait(model, start, args.turn, verbose=args.verbose)
        if args.verbose:
            diagnosis = f"{res.planner}: {res.reason or 'no gait found'}\n{diagnosis}"
        raise NoGaitError(f"no gait turns {model.shape.name} {args.turn:g} deg: {diagnosis}")
    v = validate_plan(res.plan, model.shape, model.hand, args.turn, model.max_radius)
    if v is not None:  # a planner bug, never the user's input
        raise RuntimeError(f"planner {args.planner} returned an invalid plan: "
                           f"{InvalidPlanError(v)}")
    from graspgait_env.objects import bundled_objects

    if args.object not in bundled_objects():
        # an object file: the plan names the file, so `graspgait simulate` finds the shape
        res.plan.object = args.object
    res.plan.stats.update({"planner": res.planner, "nodes_opened": res.nodes_opened,
                           "regrasps": res.regrasps, "rotation_deg": res.rotation_deg,
                           "path_length": res.path_length})
    if res.pattern:
        res.plan.stats["pattern"] = res.pattern
    res.plan.contact_model = contact_model.to_json()  # what the hand must match
    print(f"gait: {res.regrasps} regrasps, path length {res.path_length}, rotation "
          f"{res.rotation_deg:g} deg" + (f", pattern {res.pattern}" if res.pattern else ""))
    print(f"start {res.plan.steps[0]['contacts']}; plan passes the validator")
    if res.extra.get("start_chosen"):  # optimal without --start: the object's optimum
        print(f"start chosen by the planner: the fewest regrasps over all "
              f"{res.extra['starts_seeded']} legal start grasps at theta = 0")
    if args.json:
        _write_output("--json", args.json, lambda: res.plan.save(args.json))
        print(f"wrote {args.json}")
    if args.motion:
        from graspgait_env.atomic import write_text_atomic

        _write_output("--motion", args.motion,
                      lambda: write_text_atomic(args.motion, res.plan.to_motion_file()))
        print(f"wrote {args.motion}")
    if args.png:
        from graspgait_env.plotting import gait_figure, save_figure

        fig = gait_figure(model.grasp_map, model.hand, res.plan.steps,
                          title=f"{model.shape.name}, mu={mu:g}: {res.planner} gait, "
                          f"{res.regrasps} regrasps, {res.rotation_deg:g} deg")
        _write_output("--png", args.png, lambda: save_figure(fig, args.png))
        print(f"wrote {args.png}")
    return 0


def _plan_contact_model(args: argparse.Namespace):
    """The contact model ``graspgait plan`` plans for: the hand's (ball tips, a friction
    margin for the rotations' load; graspgait_env.contact_model), derived from the
    simulation config, unless ``--point-contacts`` (the thesis's maps)."""
    from graspgait_env.contact_model import POINT_CONTACTS, hand_contact_model
    from graspgait_env.objects import load_object
    from graspgait_env.workspace import load_hand

    if args.point_contacts:
        if args.sim_config is not None:
            raise GraspGaitInputError("--sim-config with --point-contacts: point contacts "
                                      "assume no hand; drop one of them")
        return POINT_CONTACTS
    hand, _ = load_hand(args.hand, load_object(args.object))
    return hand_contact_model(args.object, args.sim_config,
                              workspaces_deg=hand.workspaces_deg, turn_deg=args.turn)


def _describe_contact_model(cm) -> str:
    """One line naming the contact model a plan assumes."""
    if cm.is_point:
        return "contact model: point contacts (the thesis's idealized maps)"
    return (f"contact model: hand: ball tips {1e3 * cm.tip_radius_m:.1f} mm, contacts "
            f"{1e3 * cm.vertex_clearance_m:.1f} mm clear of vertices, friction margin for a "
            f"{cm.load_torque_nm:.4f} N m rotation load at {cm.grip_n:g} N grip")


def _add_plan(sub: argparse._SubParsersAction) -> None:
    from graspgait_env.planners.registry import PLANNERS

    p = sub.add_parser("plan", help="plan a grasp gait (thesis ch. 5-6)",
                       description="Plan a gait turning OBJECT by TURN degrees with one of "
                       "the thesis's planners or the exact optimum; exit 0 with a plan, 1 "
                       "when no gait exists (with a diagnosis), 2 for bad input.",
                       epilog=_epilog(
                           ["plan pentagon --mu 0.7 --planner rule --json plan.json",
                            "plan pentagon --mu 0.7 --planner optimal --start 50,270 "
                            "--point-contacts --png gait.png",
                            "plan my_shape.yaml --mu 0.5 --planner best-first --turn 180"],
                           notes="The plan JSON: {\"object\", \"mu\", \"workspaces_deg\": "
                           "[[lo, hi] per finger], \"steps\": [{\"op\": \"grasp\", "
                           "\"contacts\": {\"1\": 50.0, \"3\": 270.0}}, {\"op\": \"rotate\", "
                           "\"delta\": 40.0}, {\"op\": \"regrasp\", \"contacts\": {...}}, ...], "
                           "\"stats\", \"contact_model\"}: fingers numbered 1-3 as strings, "
                           "contact angles phi in degrees in the object frame, rotations in "
                           "degrees, counter-clockwise positive. Every planner writes it; "
                           f"`{PROG} simulate` reads it."))
    p.add_argument("object", metavar="OBJECT", help=_object_help())
    p.add_argument("--mu", type=float, required=True, help="Coulomb friction coefficient (> 0)")
    p.add_argument("--planner", required=True, choices=list(PLANNERS), metavar="P",
                   help=f"one of: {', '.join(PLANNERS)}")
    p.add_argument("--start", metavar="PHI1,PHI2",
                   help="initial grasp: two object-frame contact angles (deg) at theta = 0; "
                   "default: the planner's choice (rule-based) or the first of a spread of "
                   "legal grasps from which a gait exists")
    p.add_argument("--turn", type=float, default=360.0,
                   help="turn in degrees, counter-clockwise positive (default 360)")
    p.add_argument("--n", type=int, default=180, help="grid: contacts and rotation steps "
                   "of 360/n deg (default 180)")
    p.add_argument("--hand", default=None, help=_hand_help())
    p.add_argument("--vertex-clearance", type=float, default=0.0, metavar="DEG",
                   help="also keep contacts DEG degrees off polygon vertices (default 0: "
                   "only what the contact model needs)")
    p.add_argument("--point-contacts", action="store_true",
                   help="plan for the thesis's idealized point contacts (the maps of "
                   "Tables 1 and 6.1) instead of the simulated hand's ball tips; "
                   "`graspgait simulate` warns about such plans")
    p.add_argument("--sim-config", metavar="SIM.yaml", default=None,
                   help="the simulation config whose hand the plan is for (default: the "
                   f"bundled one, `{PROG} config sim default`): tip radius, table friction, "
                   "rotation acceleration and grip set the contact model")
    p.add_argument("--verbose", action="store_true",
                   help="when no gait exists, print the planner's account and the whole "
                   "diagnosis (grasp map, prototype conditions, each start tried) instead "
                   "of three lines")
    p.add_argument("--json", metavar="FILE", help="write the plan JSON (its format: below)")
    p.add_argument("--motion", metavar="FILE", help="write the thesis's motion_file (7.4.1)")
    p.add_argument("--png", metavar="FILE", help="draw the gait over the maps")
    p.set_defaults(func=_cmd_plan)


# --- bench ----------------------------------------------------------------------------


def _add_ray_option(p: argparse.ArgumentParser, what: str) -> None:
    """``--ray [ADDRESS]``: ``args.ray`` is None (no Ray), ``"local"`` (a local Ray
    started here) or the cluster's address."""
    p.add_argument("--ray", nargs="?", const="local", metavar="ADDRESS",
                   help=f"{what}: on the Ray cluster at ADDRESS (auto, HOST:6379, "
                   "ray://HOST:10001), or without ADDRESS on a local Ray started here")


def _csv_list(flag: str, text: str, conv):
    try:
        vals = [conv(v) for v in text.split(",") if v.strip()]
    except ValueError:
        vals = []
    if not vals:
        raise GraspGaitInputError(f"{flag} {text!r}: give a comma-separated list")
    return vals


def _bench_cases(args: argparse.Namespace, objects: list[str], mus: list[float],
                 planners: list[str]) -> list:
    """The bench's cases, serially or (``--ray``) one Ray task per object and mu; a failed
    cell is reported on stderr (the exit status becomes 1) and the others kept."""
    from graspgait_env.baselines import bench

    if args.ray is None:
        return bench.run_bench(objects, mus, planners, args.starts)
    from graspgait_env.baselines.scale_out import bench_on_ray

    cases, failures = bench_on_ray(objects, mus, planners, args.starts, address=args.ray)
    for f in failures:
        _error(f"bench cell {f.label} failed on Ray: {f.error}")
    args.failed_cells = len(failures)
    return cases


def _cmd_bench(args: argparse.Namespace) -> int:
    from graspgait_env.baselines import bench
    from graspgait_env.planners.registry import get_planner

    mus = [_check_mu(m) for m in _csv_list("--mus", args.mus, float)]
    planners = _csv_list("--planners", args.planners, str)
    for p in planners:
        get_planner(p)
    objects = _csv_list("--objects", args.objects, str)
    if args.starts < 1:
        raise GraspGaitInputError(f"--starts {args.starts}: must be >= 1, e.g. 10")
    _check_outputs(args, {"csv": (".csv",), "json": (".json",), "md": (".md",)})
    from graspgait_env.objects import load_object

    for o in objects:
        load_object(o)  # refuse bad names before the long run
    _check_outputs(args, {"png": _figure_suffixes()})
    _require_ray(args, "graspgait bench")
    if args.agents != "none":
        _require("train", f"graspgait bench --agents {args.agents} (use --agents none for the "
                 "planners alone)")
    agents = _bench_agents(args.agents)  # graspgait_env.agents.bench; loaded before the long run
    with contextlib.ExitStack() as stack:
        if args.ray is not None:  # one Ray session for the planners' and the agents' tasks
            from graspgait_env.baselines.scale_out import ray_session

            stack.enter_context(ray_session(args.ray))
        cases = _bench_cases(args, objects, mus, planners)
        cases, agents_report = agents(args, cases, objects, mus, args.starts)
    report = bench.markdown_report(cases) + agents_report
    print(report)
    if args.csv:
        _write_output("--csv", args.csv, lambda: bench.write_csv(cases, args.csv))
        print(f"wrote {args.csv}")
    if args.json:
        _write_output("--json", args.json, lambda: bench.write_json(cases, args.json))
        print(f"wrote {args.json}")
    if args.md:
        from graspgait_env.atomic import write_text_atomic

        _write_output("--md", args.md, lambda: write_text_atomic(args.md, report + "\n"))
        print(f"wrote {args.md}")
    if args.png:
        from graspgait_env.agents.bench import plot_bench

        _write_output("--png", args.png, lambda: plot_bench(cases, args.png))
        print(f"wrote {args.png}")
    return 1 if getattr(args, "failed_cells", 0) else 0


def _add_bench(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="regenerate the thesis's Tables 1 and 6.1",
                       description="Run the planners on the thesis's four objects (fig. 5.3), "
                       "10 initial grasps each, mu 0.8 and 0.7, 90-degree workspaces; print "
                       "Tables 1 and 6.1 in Markdown beside the thesis's figures, then the "
                       "shipped agents from the same starts (needs the [train] extra; "
                       "--agents none without it).",
                       epilog=_epilog(["bench", "bench --agents none --md tables.md",
                                       "bench --agents shipped --objects pentagon --starts 2",
                                       "bench --ray --json bench.json --png bench.png"],
                                      duration="2.5 min with the defaults (20 s planners, "
                                      "the rest agents); seconds with --starts 2"))
    p.add_argument("--objects", default="circle,ellipse,pentagon,hexagon",
                   help="comma-separated objects (default the thesis's four)")
    p.add_argument("--mus", default="0.8,0.7", help="comma-separated friction coefficients "
                   "(default 0.8,0.7)")
    p.add_argument("--planners", default="best-first,best-first-newest,rule,modified,optimal",
                   help="comma-separated planner names (default: best-first with ties to the "
                   "oldest and to the newest node, rule, modified, optimal)")
    p.add_argument("--starts", type=int, default=10,
                   help="initial grasps per object and mu (default 10)")
    _add_ray_option(p, "run one Ray task per object and mu; same tables as the serial bench")
    p.add_argument("--csv", metavar="FILE", help="write one row per run")
    p.add_argument("--json", metavar="FILE", help="write runs and summary")
    p.add_argument("--md", metavar="FILE", help="write the Markdown tables")
    p.add_argument("--agents", default="shipped", metavar="shipped|none|NAME,...",
                   help="learned agents to run from the same starts: every shipped agent "
                   f"(default; `{PROG} evaluate --list` names them), none, or shipped "
                   "names / .zip paths")
    p.add_argument("--png", metavar="FILE", help="plot regrasps per 360 deg of every method")
    p.set_defaults(func=_cmd_bench)


def _bench_agents(spec: str) -> Callable[..., tuple[list, str]]:
    """The agents' part of ``graspgait bench`` (graspgait_env.agents.bench): ``run(args, cases,
    objects,
    mus, starts) -> (cases + the agents' runs, their Markdown section)``; with ``--ray``
    one Ray task per agent, object and mu (a failed one is reported, the others kept)."""
    from graspgait_env.agents.bench import agents_markdown, find_agents, run_agent_bench

    agents, notes = find_agents(spec)

    def run(args: argparse.Namespace, cases: list, objects: list[str], mus: list[float],
            starts: int) -> tuple[list, str]:
        if not agents and not notes:
            return cases, ""
        if args.ray is None:
            runs = run_agent_bench(agents, objects, mus, starts)
        else:
            from graspgait_env.agents.ray_train import bench_agents_on_ray

            runs, failures = bench_agents_on_ray(agents, objects, mus, starts,
                                                 address=args.ray)
            for f in failures:
                _error(f"bench cell {f.label} failed on Ray: {f.error}")
            args.failed_cells = getattr(args, "failed_cells", 0) + len(failures)
        cases = cases + runs
        return cases, "\n\n" + agents_markdown(cases, notes)

    return run


# --- simulate -------------------------------------------------------------------------


def _cmd_simulate(args: argparse.Namespace) -> int:
    # imported here so that MUJOCO_GL=egl is set (graspgait_env.sim) before MuJoCo loads
    from graspgait_env.sim.simulate import simulate_command

    _check_outputs(args, {"json": (".json",)})  # --video: simulate_command checks it
    _require_ray(args, "graspgait simulate")
    if args.video is not None:
        _require("video", "graspgait simulate --video")
    if args.seeds is not None or args.ray is not None:
        return _simulate_campaign(args)
    return simulate_command(args.plan, video=args.video, seed=args.seed, perturb=args.perturb,
                            config=args.config, json_out=args.json, progress=not args.quiet)


def _simulate_campaign(args: argparse.Namespace) -> int:
    """``--seeds``/``--ray``: the perturbed campaign (thesis 7.5), one run per seed, each
    from a random initial pose error drawn from its seed; a table and the tally; exit 0
    when every run succeeds, 1 otherwise (a failed run is reported, the others kept)."""
    import json

    from graspgait_env.baselines.scale_out import campaign, parse_seeds, summarize_campaign
    from graspgait_env.plan import Plan

    if args.video is not None or args.perturb not in (None, "random"):
        raise GraspGaitInputError(
            f"--seeds/--ray with --video/--perturb {args.perturb or ''}: the campaign draws a "
            "random pose error per seed and records no video; drop them")
    seeds = parse_seeds(args.seeds) if args.seeds is not None else [args.seed]
    plan = Plan.load(args.plan)
    from graspgait_env.sim.simulate import point_contact_warning

    warning = point_contact_warning(plan, args.plan)
    if warning:
        print(f"{PROG}: warning: {warning}", file=sys.stderr)
    results, failures = campaign(plan, seeds, args.config, address=args.ray,
                                 use_ray=args.ray is not None, progress=not args.quiet)
    print(summarize_campaign(results, seeds))
    for f in failures:
        _error(f"simulate {f.label} failed: {f.error}")
    if args.json:
        from graspgait_env.atomic import write_text_atomic

        doc = [{"seed": s, **(r or {"status": "failed"})} for s, r in zip(seeds, results,
                                                                          strict=True)]
        text = json.dumps(doc, indent=1, default=float) + "\n"
        _write_output("--json", args.json, lambda: write_text_atomic(args.json, text))
        print(f"wrote {args.json}")
    return 0 if all(r is not None and r["success"] for r in results) else 1


def _add_simulate(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("simulate", help="execute a plan on the MuJoCo hand (thesis ch. 7)",
                       description="Execute PLAN.json on the simulated three-finger hand with "
                       "the thesis controller (trajectory planner, PD servo, grip-force and "
                       "friction-cone check, object localizer) and report success, rotation, "
                       "final errors, drops, slips, sim and wall time. Exit 0 when the gait "
                       "succeeds, 1 when the hand fails it, 2 for bad input.",
                       epilog=_epilog(["simulate plan.json   # after: graspgait plan "
                                       "ellipse --mu 0.7 --planner optimal --json plan.json",
                                       "simulate plan.json --video gait.mp4   # needs "
                                       "the [video] extra",
                                       "simulate plan.json --perturb 0.003,-0.002,2",
                                       "simulate plan.json --seeds 0-9 --ray"],
                                      duration="1 s per run of a 360 deg gait (15 s with "
                                      "--video); --seeds 0-9 about 6 s"))
    p.add_argument("plan", metavar="PLAN.json", help="a plan written by `graspgait plan`")
    p.add_argument("--video", metavar="FILE.mp4", help="render a video (headless, EGL; the "
                   "[video] extra)")
    p.add_argument("--json", metavar="FILE", help="write the result JSON")
    p.add_argument("--perturb", metavar="DX,DY,DTH|random",
                   help="initial object pose error: metres, metres, degrees; or 'random' "
                   "(up to 6 mm and 5 deg, from --seed)")
    p.add_argument("--seed", type=int, default=0, help="seed for --perturb random "
                   "(default 0)")
    p.add_argument("--seeds", metavar="SEEDS", help="the perturbed campaign: one run per seed "
                   "(e.g. 0-9), each from a random pose error drawn from it; a table and tally")
    _add_ray_option(p, "run the campaign's runs as Ray tasks; same results")
    p.add_argument("--config", metavar="SIM.yaml", help="simulation config YAML (default: "
                   f"the bundled one; `{PROG} config sim default > my_sim.yaml` starts yours)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_simulate)


# --- train ----------------------------------------------------------------------------


def _cmd_train(args: argparse.Namespace) -> int:
    _require("train", "graspgait train")
    _require_ray(args, "graspgait train")
    from graspgait_env.agents.config import load_train_config
    from graspgait_env.agents.train import train

    config = load_train_config(args.config, args.set or [])
    if args.seeds is not None or args.ray is not None:
        return _train_seeds(args, config)
    result = train(config, run_dir=args.run_dir, resume=args.resume, progress=not args.quiet)
    ev = result.last_eval

    def pct(x: float | None) -> str:
        return "-" if x is None else f"{x:.1%}"

    vs = ev.get("regrasps_vs_optimal")
    print(f"trained {result.steps} steps in {result.wall_s:.0f} s; final evaluation: success "
          f"{pct(ev.get('success_rate'))} ({pct(ev.get('success_rate_solvable'))} of the starts "
          f"with a gait), regrasps x{'-' if vs is None else f'{vs:.3f}'} the optimum")
    print(f"wrote {result.model_path} (card {result.model_path.with_suffix('.json')}); "
          f"TensorBoard: tensorboard --logdir {result.run_dir / 'tb'}")
    return 0


def _train_seeds(args: argparse.Namespace, config) -> int:
    """``--seeds`` / ``--ray``: one run per seed (Ray Tune trials with ``--ray``); a table
    of the final evaluations; exit 1 when a seed failed (the others are kept)."""
    from graspgait_env.agents.ray_train import train_seeds
    from graspgait_env.baselines.scale_out import parse_seeds

    if args.resume is not None or args.run_dir is not None:
        raise GraspGaitInputError("--seeds/--ray with --resume/--run-dir: each seed gets its "
                                  "own run folder; resume one run at a time without --seeds")
    seeds = parse_seeds(args.seeds) if args.seeds is not None else [config.seed]
    outcomes = train_seeds(config, seeds, use_ray=args.ray is not None, address=args.ray,
                           progress=not args.quiet)
    print("| seed | steps | success | success (solvable) | regrasps vs optimum | run |")
    print("|---:|---:|---:|---:|---:|---|")
    for o in outcomes:
        if o.error is not None:
            _error(f"seed {o.seed} failed: {o.error}")
            continue
        ev = o.last_eval or {}
        cells = [ev.get("success_rate"), ev.get("success_rate_solvable")]
        pct = ["-" if x is None else f"{x:.1%}" for x in cells]
        vs = ev.get("regrasps_vs_optimal")
        print(f"| {o.seed} | {o.steps} | {pct[0]} | {pct[1]} | "
              f"{'-' if vs is None else f'{vs:.3f}'} | {o.run_dir} |")
    return 1 if any(o.error is not None for o in outcomes) else 0


def _add_train(sub: argparse._SubParsersAction) -> None:
    from graspgait_env.resources import bundled_names

    p = sub.add_parser("train", help="train a PPO / MaskablePPO agent from a YAML config",
                       description="Train an agent on a GraspGait env: progress bar, TensorBoard "
                       "logs, periodic evaluation against the exact optimum and the rule-based "
                       "gait, checkpoints; the run's folder is runs/{env}-{config}-s{seed}-{time}"
                       " and the model is saved there as model.zip with its card model.json. "
                       "Needs the [train] extra.",
                       epilog=_epilog(["train smoke --run-dir smoke_run",
                                       "train ellipse --set total_timesteps=100000",
                                       "train my_config.yaml --seeds 0-4 --ray",
                                       "config train ellipse > my_config.yaml"],
                                      duration="seconds for smoke; 4-12 min for the bundled "
                                      "configs (random, hexagon, general: imitation); --seeds "
                                      "runs one per seed (in parallel with --ray)"))
    p.add_argument("config", metavar="CONFIG", help="a bundled training config "
                   f"({', '.join(bundled_names('train'))}; `{PROG} config train NAME` prints "
                   "one) or a YAML path")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="replace a config field (YAML value; dots reach into env_kwargs, e.g. "
                   "env_kwargs.mu=0.8); repeatable")
    p.add_argument("--resume", metavar="CHECKPOINT",
                   help="continue from a checkpoint zip (RUN/checkpoints/model_N_steps.zip)")
    p.add_argument("--run-dir", metavar="DIR", help="the run's folder (default "
                   "RUN_ROOT/{env}-{config}-s{seed}-{time}; with --resume, the checkpoint's run)")
    p.add_argument("--seeds", metavar="SEEDS", help="one run per seed, e.g. 0-9 or 0,3,5 "
                   "(each in its own run folder; a table of the final evaluations)")
    _add_ray_option(p, "run the seeds as Ray Tune trials, one per seed")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_train)


# --- evaluate -------------------------------------------------------------------------


def _cmd_evaluate(args: argparse.Namespace) -> int:
    if args.list:
        return _print_shipped()
    if args.model is None:
        raise GraspGaitInputError("MODEL missing: give a shipped agent's name (e.g. general; "
                                  f"`{PROG} evaluate --list` names them) or a model zip path")
    _require("train", "graspgait evaluate")
    _require_ray(args, "graspgait evaluate")
    from graspgait_env.agents.config import apply_overrides
    from graspgait_env.agents.evaluate import evaluate, format_evaluation, write_evaluation

    _check_outputs(args, {"json": (".json",)})
    mu = None if args.mu is None else _check_mu(args.mu)
    if args.episodes < 1:
        raise GraspGaitInputError(f"--episodes {args.episodes}: must be >= 1, e.g. 100")
    if args.seed < 0:
        raise GraspGaitInputError(f"--seed {args.seed}: must be >= 0, e.g. 0")
    env_set = apply_overrides({"env_kwargs": {}},
                              [f"env_kwargs.{s}" for s in args.set or []])["env_kwargs"]
    if args.ray is not None and args.audit:
        raise GraspGaitInputError("--audit with --ray: the audit runs in this process; "
                                  "drop --ray (or --audit)")
    if args.ray is not None:
        from graspgait_env.agents.ray_train import evaluate_on_ray

        result = evaluate_on_ray(args.model, env_id=args.env, object=args.object, mu=mu,
                                 episodes=args.episodes, seed=args.seed, env_overrides=env_set,
                                 address=args.ray, progress=not args.quiet,
                                 reading=args.reading)
    else:
        result = evaluate(args.model, env_id=args.env, object=args.object, mu=mu,
                          episodes=args.episodes, seed=args.seed, env_overrides=env_set,
                          progress=not args.quiet, audit=args.audit,
                          batched=not args.one_by_one, reading=args.reading)
    print(format_evaluation(result))
    result["command"] = shlex.join(
        [PROG, "evaluate", args.model]
        + (["--env", args.env] if args.env else [])
        + (["--object", args.object] if args.object else [])
        + (["--mu", f"{mu:g}"] if mu is not None else [])
        + ["--episodes", str(args.episodes)] + (["--seed", str(args.seed)] if args.seed else [])
        + [x for s in args.set or [] for x in ("--set", s)]
        + (["--audit"] if args.audit else []) + (["--reading"] if args.reading else []))
    if args.json:
        _write_output("--json", args.json, lambda: write_evaluation(result, args.json))
        print(f"wrote {args.json}")
    return 0


def _add_evaluate(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("evaluate", help="evaluate a trained agent against the optimum",
                       description="Run a saved agent for N episodes and report its success "
                       "rate (over all episodes and over the starts from which a gait exists) "
                       "and its regrasps beside the exact optimum's and the rule-based gait's "
                       "from the same starts, under the same contact model. By default the env "
                       "settings the model was trained with (from its card). Needs the [train] "
                       "extra.",
                       epilog=_epilog(["evaluate --list",
                                       "evaluate general --object ellipse --episodes 20",
                                       "evaluate general --object my_shape.yaml --mu 0.5",
                                       "evaluate runs/RUN/model.zip --json eval.json",
                                       "evaluate general --object hexagon --reading",
                                       "evaluate general --object hexagon "
                                       "--env GraspGaitMujoco-v1 --episodes 5"],
                                      duration="5-60 s for 100 episodes at map level; about "
                                      "2 s per episode on the MuJoCo hand"))
    p.add_argument("model", metavar="MODEL", nargs="?",
                   help="a shipped agent's name (see --list) or a model zip saved by "
                   f"`{PROG} train` (RUN/model.zip, its card RUN/model.json beside it)")
    p.add_argument("--list", action="store_true", help="name the shipped agents and exit")
    p.add_argument("--env", metavar="ID", help="GraspGait-v0, GraspGaitRandom-v0 or "
                   "GraspGaitMujoco-v1 (default: the training env)")
    p.add_argument("--object", metavar="NAME|PATH", help="object (default: the trained one)")
    p.add_argument("--mu", type=float, help="friction coefficient (default: the trained one)")
    p.add_argument("--episodes", type=int, default=100, help="episodes (reset seeds SEED .. "
                   "SEED + N - 1; default 100)")
    p.add_argument("--seed", type=int, default=0, help="first reset seed (default 0)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="an env keyword argument (YAML value), e.g. bundled_fraction=0; "
                   "repeatable")
    p.add_argument("--json", metavar="FILE",
                   help="write the result JSON (per-episode records and the command line; "
                   "`graspgait card --evaluation` reads it)")
    p.add_argument("--audit", action="store_true",
                   help="price every move against the optimum: where the regrasps beyond "
                   "it go (idle regrasps, losing regrasps, losing rotations, and how many "
                   "from states farther from the goal than the look-ahead reads)")
    p.add_argument("--reading", action="store_true",
                   help="also play the greedy reading of the model's own look-ahead (no "
                   "learning: the move its reach look-ahead ranks first) from the same "
                   "starts, and compare the two start by start; for models trained with "
                   "regrasp_lookahead (general)")
    p.add_argument("--one-by-one", action="store_true",
                   help="play the episodes one by one in the single env, not side by side "
                   "in the batched one (same records; for timing the two)")
    _add_ray_option(p, "split the episodes over Ray tasks; same result as serially")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_evaluate)


# --- story ----------------------------------------------------------------------------


def _cmd_story(args: argparse.Namespace) -> int:
    if args.list:
        return _print_shipped()
    _require("train", "graspgait story")
    from graspgait_env.agents.card import resolve_model
    from graspgait_env.agents.story import gait_model_of, tell_story

    mu = None if args.mu is None else _check_mu(args.mu)
    model = str(resolve_model(args.model))  # a shipped agent's name or a path
    start = (None if args.start is None
             else _parse_start(args.start, gait_model_of(model, args.object, mu)))
    result = tell_story(model, args.out, start=start, object=args.object, mu=mu)
    print(result["table"])
    files = result["files"]
    print("wrote " + ", ".join(files.values()))
    if "learned_plan" not in files:
        print("the learned gait did not reach the turn from this start")
        return 1
    return 0


def _add_story(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("story", help="rule-based, optimal and learned gaits side by side",
                       description="From one start grasp, the thesis's rule-based gait, the "
                       "exact optimum and a saved agent's gait turn the object 360 deg: drawn "
                       "on the extended grasp map with a comparison table, each written as a "
                       "plan JSON (replay the learned one on the MuJoCo hand with `graspgait "
                       "simulate OUT/OBJECT_learned_plan.json --video F.mp4`). Exit 1 when the "
                       "agent does not reach the turn. Needs the [train] extra.",
                       epilog=_epilog(["story", "story circle --out story",
                                       "story general --object my_shape.yaml --mu 0.6",
                                       "story general --object ellipse --start 50,270"],
                                      duration="5-20 s"))
    p.add_argument("model", metavar="MODEL", nargs="?", default="general",
                   help="a shipped agent's name (see --list) or a model zip with its card "
                   "(default general, on its env's default object, the ellipse)")
    p.add_argument("--list", action="store_true", help="name the shipped agents and exit")
    p.add_argument("--object", metavar="NAME|PATH", help="object (default: the trained one)")
    p.add_argument("--mu", type=float, help="friction coefficient (default: the trained one)")
    p.add_argument("--start", metavar="PHI1,PHI2", help="start contacts at theta = 0 (deg, "
                   "object frame; default: the first of 24 spread starts with a gait)")
    p.add_argument("--out", metavar="DIR", default="out", help="output folder (default out)")
    p.set_defaults(func=_cmd_story)


def _cmd_card(args: argparse.Namespace) -> int:
    from graspgait_env.agents.hub_card import write_hub_card

    command = shlex.join(
        [PROG, "card", *args.models]
        + [x for f in args.evaluation or [] for x in ("--evaluation", f)]
        + [x for d in args.benchmark or [] for x in ("--benchmark", d)]
        + [x for d in args.against or [] for x in ("--against", d)]
        + (["--title", args.title] if args.title else [])
        + (["--out", args.out] if args.out else []))
    text = write_hub_card(args.models, args.out, args.title, args.benchmark or (),
                          args.against or (), args.evaluation or (), command)
    if args.out is None:
        sys.stdout.write(text)
    else:
        print(f"wrote {args.out}")
    return 0


def _add_card(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("card", help="write a Hugging Face-style model card over seeds",
                       description="The model card of one recipe's runs, in the form the "
                       "Hugging Face Hub and CleanRL use: YAML front matter (library_name, "
                       "tags, model-index with each metric as mean +/- std over the runs), "
                       "the env id and keywords, the metrics per run and over runs, the "
                       "hyper-parameters and the commands that reproduce it, all read from "
                       "the runs' own JSON cards (one per seed, e.g. the run folders of "
                       "`graspgait train CONFIG --seeds 0-4`). Runs of different recipes "
                       "(algo, env id or env keywords) are refused.",
                       epilog=_epilog(["card runs/*general*/model.zip --out README.md",
                                       "card general runs/general-s1/model.zip "
                                       "--benchmark bench/agent --benchmark bench/seeds",
                                       "card circle --benchmark bench/agent-circle "
                                       "--benchmark bench/config-circle "
                                       "--against general=bench/general-circle",
                                       "card hexagon"], duration="a second"))
    p.add_argument("models", metavar="MODEL", nargs="+",
                   help="saved models (zips with their cards) or shipped agents' names")
    p.add_argument("--out", metavar="FILE", help="write the card here (default: print it)")
    p.add_argument("--title", help="the card's heading (default: recipe and env id)")
    p.add_argument("--benchmark", metavar="DIR", action="append",
                   help="a finished `graspgait benchmark` row's folder (its --out) to add "
                   "to the card; repeatable: with the shipped run's row (agent:NAME) and the "
                   "retrained recipe's (RUNS/s{seed}/model.zip or config:NAME) the card says "
                   "whether the recipe retrained is worse")
    p.add_argument("--against", metavar="[NAME=]DIR", action="append",
                   help="another recipe's `graspgait benchmark` row on the same tasks and "
                   "seeds (e.g. general=bench/general-circle: the five general models on the "
                   "circle's tasks); repeatable: the card says whether this recipe is better "
                   "(its IQM above the upper end of the other's 95%% interval), worse or not "
                   "measurably different")
    p.add_argument("--evaluation", metavar="FILE", action="append",
                   help="a `graspgait evaluate MODEL ... --json FILE` result of one of these "
                   "models; repeatable: each a row of the card's measured results, with the "
                   "command that made it")
    p.set_defaults(func=_cmd_card)


# --- config ---------------------------------------------------------------------------


def _cmd_config(args: argparse.Namespace) -> int:
    from graspgait_env.resources import KINDS, bundled_file, bundled_names, config_dir

    if args.kind is None:
        for kind in KINDS:
            print(f"{kind:<8} {', '.join(bundled_names(kind))}")
        print(f"(`{PROG} config KIND NAME` prints one; bundled in {config_dir('objects').parent})")
        return 0
    if args.kind not in KINDS:
        raise GraspGaitInputError(f"KIND {args.kind!r}: must be one of {', '.join(KINDS)}")
    if args.name is None:
        for name in bundled_names(args.kind):
            print(name)
        return 0
    path = bundled_file(args.kind, args.name)
    if path is None:
        import difflib

        names = bundled_names(args.kind)
        near = difflib.get_close_matches(args.name, names, n=1)
        hint = f"did you mean {near[0]!r}? " if near else ""
        raise GraspGaitInputError(f"NAME {args.name!r}: no bundled {args.kind} file of that "
                                  f"name; {hint}give one of {', '.join(names)}")
    if args.path:
        print(path)
    else:
        sys.stdout.write(path.read_text(encoding="utf-8"))
    return 0


def _add_config(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("config", help="list or print the bundled YAML files",
                       description="The YAML files that ship with the package: objects, "
                       "hands, the simulation config, the training configs and RL Zoo's "
                       "hyper-parameters. Without KIND, list every kind and its names; with "
                       "KIND, list its names; with NAME, print the file (redirect it to start "
                       "your own).",
                       epilog=_epilog(["config", "config objects",
                                       "config objects pentagon > my_shape.yaml",
                                       "config sim default > my_sim.yaml",
                                       "config train ellipse > my_config.yaml",
                                       "config rlzoo ppo --path"]))
    p.add_argument("kind", metavar="KIND", nargs="?",
                   help="objects, hands, sim, train or rlzoo")
    p.add_argument("name", metavar="NAME", nargs="?", help="a bundled file's name")
    p.add_argument("--path", action="store_true",
                   help="print the installed file's path instead of its text")
    p.set_defaults(func=_cmd_config)


# --- benchmark ------------------------------------------------------------------------


def _cmd_benchmark(args: argparse.Namespace) -> int:
    _require("benchmark", "graspgait benchmark")
    from graspgait_env.benchmark.suite import format_suite, parse_tasks

    if args.list_tasks:
        tasks = parse_tasks(args.tasks)
        print(format_suite(tasks))
        if args.json:
            import json

            from graspgait_env.atomic import write_text_atomic

            text = json.dumps([t.to_dict() for t in tasks], indent=1) + "\n"
            _write_output("--json", args.json, lambda: write_text_atomic(args.json, text))
            print(f"wrote {args.json}")
        return 0
    if args.scoreboard:
        if args.policy is not None:
            raise GraspGaitInputError(f"POLICY {args.policy!r} with --scoreboard: give one "
                                      "or the other (--scoreboard reads finished rows)")
        _check_outputs(args, {"md": (".md",)})
        _check_outputs(args, {"png": _figure_suffixes()})
        from graspgait_env.benchmark.scoreboard import scoreboard

        print(scoreboard(args.scoreboard, md=args.md, png=args.png))
        for flag in ("md", "png"):
            if getattr(args, flag):
                print(f"wrote {getattr(args, flag)}")
        return 0
    if args.policy is None:
        raise GraspGaitInputError("POLICY missing: give random, a planner (e.g. rule), "
                                  "greedy-reach[:D], agent:NAME, a model .zip, config:NAME or "
                                  "bc; "
                                  f"`{PROG} benchmark --list-tasks` lists the tasks")
    from graspgait_env.baselines.scale_out import parse_seeds
    from graspgait_env.benchmark.policies import parse_policy

    spec = parse_policy(args.policy)
    if spec.kind in ("agent", "agent-template", "config", "bc"):
        _require("train", f"graspgait benchmark {args.policy}")
    if spec.kind == "rlzoo":
        _require("zoo", f"graspgait benchmark {args.policy}")
    _require_ray(args, "graspgait benchmark")
    tasks = parse_tasks(args.tasks)
    seeds = parse_seeds(args.seeds)
    if args.episodes is not None and args.episodes < 1:
        raise GraspGaitInputError(f"--episodes {args.episodes}: must be >= 1, e.g. 10")
    _check_outputs(args, {"csv": (".csv",), "json": (".json",), "md": (".md",)})
    _check_outputs(args, {"png": _figure_suffixes()})
    from graspgait_env.benchmark.run import run_benchmark

    command = " ".join([PROG, "benchmark", args.policy, "--tasks", args.tasks or "all",
                        "--seeds", args.seeds]
                       + (["--episodes", str(args.episodes)] if args.episodes else [])
                       + (["--reps", str(args.reps)] if args.reps != 2000 else []))
    if args.reps < 100:
        raise GraspGaitInputError(f"--reps {args.reps}: must be >= 100, e.g. 2000")
    result = run_benchmark(spec, tasks, seeds, out_dir=args.out, episodes=args.episodes,
                           ray=args.ray, progress=not args.quiet, command=command,
                           reps=args.reps)
    import shutil
    from pathlib import Path

    print(Path(result["files"]["md"]).read_text(encoding="utf-8"), end="")
    print(f"wrote {', '.join(result['files'].values())}")
    for flag in ("csv", "json", "md", "png"):
        dest = getattr(args, flag)
        if dest and flag in result["files"]:
            _write_output(f"--{flag}", dest, lambda f=flag, d=dest: shutil.copyfile(
                result["files"][f], d))
            print(f"wrote {dest}")
    for label, error in result["failures"]:
        _error(f"benchmark cell {label} failed: {error}")
    return 1 if result["failures"] else 0


def _add_benchmark(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("benchmark", help="score a policy on the benchmark suite over seeds",
                       description="Run POLICY on the tasks of the GraspGait benchmark suite "
                       "(the thesis objects with point contacts and the hand's contact model, "
                       "held-out procedural objects at levels 0-3, the simulated hand from "
                       "perturbed poses and below the planning friction), one run per seed, "
                       "and score each run: success over the starts from which a gait exists, "
                       "efficiency (the optimum's regrasps over the policy's), and their "
                       "product, the normalized score, beside the rule-based gait's. "
                       "Aggregates with rliable: per-task mean and IQM, per-track and suite "
                       "IQM, 95% stratified bootstrap confidence intervals, a performance "
                       "profile. The row's folder (--out) keeps one file per task and seed: "
                       "run it again to resume. POLICY: random (masked), a planner, "
                       "greedy-reach[:D] (the reach look-ahead read greedily, D regrasps "
                       "deep), agent:NAME or a "
                       "model .zip, config:NAME or a training config .yaml (trained once per "
                       "task and seed), bc[:optimal|rule] (behaviour cloning from `graspgait "
                       "dataset record`). Needs the [benchmark] extra (and [train] for "
                       "agents, configs and bc).",
                       epilog=_epilog(["benchmark --list-tasks",
                                       "benchmark random --tasks map-point-circle,random-l0 "
                                       "--seeds 0-1 --episodes 3",
                                       "benchmark rule --tasks map-point,random",
                                       "benchmark greedy-reach --json row.json --md row.md",
                                       "benchmark agent:general --tasks random --ray",
                                       "benchmark config:ellipse --tasks map-hand-ellipse",
                                       "benchmark --scoreboard benchmark/rule benchmark/random "
                                       "--md board.md --png board.png"],
                                      duration="seconds for the example with --episodes 3; "
                                      "7-21 min for a planner or random over the whole suite "
                                      "and 5 seeds (the hand track: 1-10 s per episode); "
                                      "hours for a training config"))
    p.add_argument("policy", metavar="POLICY", nargs="?",
                   help="random, a planner name, greedy-reach[:D], agent:NAME or a model .zip "
                   "({task}, {train_task}, {seed} in its path: one model per task and "
                   "seed), "
                   "config:NAME or a config .yaml, rlzoo:ALGO[:STEPS] (RL Zoo with the bundled "
                   "hyper-parameters), bc[:optimal|rule]")
    p.add_argument("--list-tasks", action="store_true",
                   help="print the suite (or the tasks of --tasks) and exit")
    p.add_argument("--scoreboard", nargs="+", metavar="DIR", help="print the scoreboard of "
                   "finished rows (their --out folders) side by side, with --md and --png "
                   "its tables and performance profiles, and exit")
    p.add_argument("--tasks", metavar="T,...", help="task ids and track names (map-point, "
                   "map-hand, random, mujoco), comma-separated (default: every task)")
    p.add_argument("--seeds", default="0-4", help="run seeds, e.g. 0-4 or 0,3 (default 0-4)")
    p.add_argument("--episodes", type=int, help="test episodes per run (default: each task's "
                   "budget, 40 at map level, 5 on the simulated hand)")
    p.add_argument("--out", metavar="DIR", help="the row's folder: one file per task and "
                   "seed, cells.csv, result.json, result.md, profile.png (default "
                   "benchmark/LABEL, LABEL from POLICY)")
    _add_ray_option(p, "run one Ray task per task and seed; same scores as serially")
    p.add_argument("--reps", type=int, default=2000, help="bootstrap replications of every "
                   "confidence interval (default 2000; the resampling is seeded, so a row's "
                   "intervals are reproducible)")
    p.add_argument("--csv", metavar="FILE", help="also write the per-run CSV here")
    p.add_argument("--json", metavar="FILE", help="also write the result JSON here (with "
                   "--list-tasks: the suite)")
    p.add_argument("--md", metavar="FILE", help="also write the Markdown tables here")
    p.add_argument("--png", metavar="FILE", help="also write the performance profile here")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_benchmark)


# --- dataset --------------------------------------------------------------------------


def _cmd_dataset(args: argparse.Namespace) -> int:
    _require("benchmark", "graspgait dataset")
    from graspgait_env.benchmark.datasets import datasets_path, record_dataset

    if args.episodes < 1:
        raise GraspGaitInputError(f"--episodes {args.episodes}: must be >= 1, e.g. 100")
    ds = record_dataset(args.task, args.policy, args.episodes, overwrite=args.overwrite,
                        progress=not args.quiet)
    print(f"recorded {ds.id}: {ds.total_episodes} episodes, {ds.total_steps} steps, in "
          f"{datasets_path()} (minari.load_dataset({ds.id!r}))")
    return 0


def _add_dataset(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("dataset", help="record demonstrations of a benchmark task (Minari)",
                       description="record: a planner (the exact optimum or the rule-based "
                       "method) plays a benchmark task's training env through Minari's "
                       "DataCollector, from the training reset seeds 0, 1, ... (a start "
                       "without a gait is skipped), and the dataset is written to Minari's "
                       "data path (MINARI_DATASETS_PATH, else ~/.minari/datasets) as "
                       "graspgait/TASK/POLICY-vN (N: the suite's version), with the env "
                       "spec, the test env as eval_env and the planner as expert_policy. "
                       "Load it with minari.load_dataset; `graspgait benchmark bc` clones it. "
                       "Needs the [benchmark] extra.",
                       epilog=_epilog(["dataset record map-point-ellipse --episodes 10",
                                       "dataset record random-l1 --policy rule --episodes 200",
                                       "dataset record map-hand-hexagon --overwrite"],
                                      duration="about 10 s for 10 episodes; a minute or two "
                                      "for 200 (the optimum's search per start)"))
    p.add_argument("action", choices=["record"], help="record: record demonstrations")
    p.add_argument("task", metavar="TASK", help="a task id (`graspgait benchmark "
                   "--list-tasks`); the hand track's tasks learn on their map-hand twin")
    p.add_argument("--policy", choices=["optimal", "rule"], default="optimal",
                   help="the demonstrating planner (default optimal)")
    p.add_argument("--episodes", type=int, default=100, help="demonstrations (default 100)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a dataset of the same id")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_dataset)


# --- registry -------------------------------------------------------------------------
# Later subcommands (plan, bench, simulate, train) are added HERE: write
# `_cmd_X(args) -> int` and `_add_X(sub)` as above and append `_add_X` below. Register
# only commands that work.
SUBCOMMANDS: list[Callable[[argparse._SubParsersAction], None]] = [
    _add_map,
    _add_sweep,
    _add_plan,
    _add_bench,
    _add_simulate,
    _add_perf,
    _add_train,
    _add_evaluate,
    _add_story,
    _add_card,
    _add_config,
    _add_benchmark,
    _add_dataset,
]


def build_parser() -> argparse.ArgumentParser:
    """The ``graspgait`` argument parser with every registered subcommand."""
    from graspgait_env import __version__
    from graspgait_env.objects import bundled_objects
    from graspgait_env.workspace import bundled_hands

    parser = _Parser(
        prog=PROG,
        description="Grasp gaits for planar object manipulation (Leveroni, MIT 1997): "
        "grasp maps, workspace maps, gaits, and their execution on a simulated hand.",
        epilog=f"Bundled objects (OBJECT): {', '.join(bundled_objects())}; or the path of an "
        f"object YAML (`{PROG} config objects NAME` prints a bundled one to start from). "
        f"Bundled hands (--hand): {', '.join(bundled_hands())}; or a hand YAML path. "
        "Exit status: 0 success, 1 no gait exists or the hand fails, 2 bad input or a "
        f"missing extra. `{PROG} COMMAND --help` gives each command's defaults and examples.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in SUBCOMMANDS:
        add(sub)
    return parser


def _error(message: str) -> None:
    print(f"{PROG}: error: {message}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``graspgait`` with ``argv`` (default ``sys.argv[1:]``); return the exit status.

    Bad input (:class:`~graspgait_env.errors.GraspGaitInputError`, which includes every
    :class:`~graspgait_env.errors.ConfigError` and
    :class:`~graspgait_env.extras.MissingExtraError`) prints one line and returns 2; so
    does a module of an extra that is not installed; a
    :class:`~graspgait_env.errors.NoGaitError` prints one line and returns 1. Usage
    errors (and ``--help``) print as argparse does; their exit status is returned
    rather than raised, so in-process callers always get an int.
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: usage error (2) or --help/--version (0)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    try:
        return int(args.func(args))
    except ModuleNotFoundError as exc:  # an extra's module, reached past the checks above
        from graspgait_env.extras import MissingExtraError, extra_for_module

        extra = extra_for_module(exc.name or "")
        if extra is None:
            raise
        _error(str(MissingExtraError(extra, f"{PROG} {args.command}", [exc.name])))
        return 2
    except GraspGaitInputError as exc:
        _error(str(exc))
        return 2
    except NoGaitError as exc:
        _error(str(exc))
        return 1
    except KeyboardInterrupt:
        _error("interrupted")
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`, which closed early
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
