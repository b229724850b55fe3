"""Execute a whole gait plan in simulation; record a video; measure step rates.

:func:`simulate_plan` runs every step of a :class:`~graspgait_env.plan.Plan` on the
simulated hand (:class:`~graspgait_env.sim.executor.GaitExecutor`) and reports success,
the rotation achieved, the final orientation and position errors, drops, slips, and
simulated and wall time. With ``video=`` it renders the run headless (``MUJOCO_GL=egl``)
and writes an MP4 atomically.

:func:`benchmark_step_rate` times the controller plus physics against raw ``mj_step``
on the same model in the same process (``graspgait perf`` rows in
:mod:`graspgait_env.sim.perf_rows`).
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from graspgait_env.atomic import atomic_write
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.objects import load_object
from graspgait_env.plan import Plan
from graspgait_env.shapes import Circle, Shape
from graspgait_env.sim.config import SimConfig, load_sim_config
from graspgait_env.sim.executor import (
    PERTURBATION_MAX_ANGLE_DEG,
    PERTURBATION_MAX_OFFSET_M,
    THESIS_MU,
    GaitExecutor,
    random_pose_perturbation,
)

__all__ = ["simulate_plan", "simulate_command", "parse_perturbation", "benchmark_step_rate",
           "format_result", "default_plan", "tug_test", "perturbation_limits",
           "check_perturbation", "check_video_path", "point_contact_warning", "VideoRecorder",
           "VIDEO_SUFFIX"]

VIDEO_SUFFIX = ".mp4"  # the container simulate_plan writes (imageio's FFMPEG plugin)
TUG_REPORT_S = 0.05  # (s) the tug test holds in pieces this long, checking contact after each


class VideoRecorder:
    """Renders frames of a run into an imageio writer, with the overlays of
    :class:`~graspgait_env.sim.view.HandView` (headless: ``MUJOCO_GL=egl`` before MuJoCo
    is imported, as :mod:`graspgait_env.sim` sets it).

    Parameters
    ----------
    executor
        The executor whose physics is drawn; its true object angle (monitoring) is the
        angle in the caption.
    writer
        An imageio writer (``append_data``).
    width, height
        Frame size (px).
    camera
        An MJCF camera name (``config.video_camera``); None: straight above, as
        ``GraspGaitMujoco-v1`` renders.
    plan
        The plan run, for the captions (object, friction, the turn asked for, move
        *i* of *n*); :attr:`move` is set by :func:`simulate_plan` before each step.
    """

    def __init__(self, executor: GaitExecutor, writer, *, width: int, height: int,
                 camera: str | None, plan: Plan) -> None:
        from graspgait_env.sim.view import HandView

        self.view = HandView(executor.sim, width=width, height=height, camera=camera)
        self.executor = executor
        self.writer = writer
        self.plan = plan
        self.move = 0  # the plan step being executed (0: the grasp)
        self.frames = 0

    def caption(self) -> list[str]:
        """The caption lines of the present frame."""
        ex, plan = self.executor, self.plan
        n = len(plan.steps) - 1  # the moves after the initial grasp
        op = plan.steps[self.move].get("op", "?") if self.move < len(plan.steps) else "end"
        lines = [f"{plan.object}: plan mu={plan.mu:g}, finger mu={ex.mu:g}",
                 f"theta={ex.theta_true:.1f} deg (true) of {plan.rotation_deg:g}",
                 f"move {self.move} of {n}: {op}" if self.move else f"grasp (moves: {n})",
                 f"t={ex.time:.2f} s"]
        if ex.dropped:
            lines.append("DROPPED")
        return lines

    def __call__(self, physics) -> None:
        self.writer.append_data(self.view.render(physics, self.caption()))
        self.frames += 1

    def close(self) -> None:
        """Release the off-screen renderer; the caller closes ``writer`` (the video file)."""
        self.view.close()


def _resolve_config(config: SimConfig | str | os.PathLike | None) -> SimConfig:
    if isinstance(config, SimConfig):
        return config
    return load_sim_config(config)


def simulate_plan(plan: Plan, *, video: str | os.PathLike | None = None, seed: int = 0,
                  pose_perturbation: tuple[float, float, float] | str | None = None,
                  config: SimConfig | str | os.PathLike | None = None,
                  progress: bool = False) -> dict[str, Any]:
    """Execute ``plan`` on the simulated hand with the thesis controller (ch. 7).

    Parameters
    ----------
    plan
        A gait plan (the JSON of docs/formats.md, :meth:`Plan.load`); its object is a bundled name
        or a YAML path, its ``mu`` the friction the planner assumed (the friction
        cone check uses it; the contacts' true friction is ``config.finger_mu``).
    video
        MP4 path: render the run (``config.video_*``) and write it atomically.
    seed
        Seed for ``pose_perturbation="random"`` (the physics is deterministic).
    pose_perturbation
        Initial object pose error ``(dx, dy, dtheta_deg)`` (m, m, deg) that the
        controller does not know; ``"random"``: drawn from ``seed``, up to 6 mm and 5°.
    config
        :class:`~graspgait_env.sim.config.SimConfig`, a YAML path, or None for
        ``configs/sim/default.yaml``.
    progress
        Show a tqdm progress bar over the plan's steps.

    Returns
    -------
    dict
        ``success`` (bool: every step done, no drop, final orientation within
        ``config.success_angle_deg``), ``rotation_deg`` (true rotation achieved),
        ``planned_rotation_deg``, ``final_angle_error_deg`` (true final angle minus the
        plan's goal; frames F and f coincide at the start), ``rotation_error_deg``
        (rotation achieved minus planned), ``orientation_observable`` (False for a
        circle, whose orientation no contact reveals: its success is judged on
        ``rotation_error_deg``), ``final_position_error_m``,
        ``dropped`` (bool), ``drop_reason``, ``status`` (of the last step run),
        ``steps_done``, ``steps_total``, ``slips``, ``max_slip_m``, ``max_grip_n``,
        ``localizations``, ``sim_time_s``, ``wall_time_s`` (the whole call),
        ``execute_wall_time_s`` (the steps only), ``physics_wall_time_s`` (inside
        ``mj_step``), ``physics_steps``, ``pose_perturbation``,
        ``finger_mu``, ``plan_mu``, ``object``, ``video`` and ``steps`` (one dict per
        step, :meth:`StepReport.to_dict`).
    """
    wall0 = time.perf_counter()
    cfg = _resolve_config(config)
    if not isinstance(plan, Plan):
        raise GraspGaitInputError(f"plan: expected a Plan (Plan.load(path)), got "
                                  f"{type(plan).__name__}")
    if not plan.steps or plan.steps[0].get("op") != "grasp":
        raise GraspGaitInputError("plan: the first step must be a 'grasp' (the plan format: "
                                  "`graspgait plan --help`)")
    rng = np.random.default_rng(seed)
    if isinstance(pose_perturbation, str):
        if pose_perturbation != "random":
            raise GraspGaitInputError(
                f"pose_perturbation={pose_perturbation!r}: give (dx, dy, dtheta_deg) or "
                "'random'")
        pose_perturbation = random_pose_perturbation(rng)
    if pose_perturbation is not None:
        pert = tuple(float(v) for v in pose_perturbation)
        if len(pert) != 3 or not all(math.isfinite(v) for v in pert):
            raise GraspGaitInputError(
                f"pose_perturbation={pose_perturbation!r}: give three finite numbers "
                "(dx m, dy m, dtheta deg)")
    else:
        pert = (0.0, 0.0, 0.0)

    ex = GaitExecutor.for_plan(plan, config=cfg)
    if video is None:
        result = _execute(ex, plan, pert, progress)
    else:
        import imageio.v3 as iio

        def write(fh) -> None:
            with iio.imopen(fh, "w", extension=".mp4", plugin="FFMPEG") as out:
                writer = out.legacy_get_writer(fps=cfg.video_fps, macro_block_size=8)
                rec = VideoRecorder(ex, writer, width=cfg.video_width,
                                    height=cfg.video_height, camera=cfg.video_camera,
                                    plan=plan)
                ex.frame_callback = rec
                try:
                    result.update(_execute(ex, plan, pert, progress, recorder=rec))
                    for _ in range(int(cfg.video_tail_s * cfg.video_fps)):  # the end, held
                        rec(ex.physics)
                finally:
                    ex.frame_callback = None
                    rec.close()
                    writer.close()

        result: dict[str, Any] = {}
        atomic_write(video, write)
    result["video"] = str(Path(video)) if video is not None else None
    result["seed"] = int(seed)
    result["wall_time_s"] = time.perf_counter() - wall0
    return result


def _execute(ex: GaitExecutor, plan: Plan, pert: tuple[float, float, float],
             progress: bool, recorder: VideoRecorder | None = None) -> dict[str, Any]:
    from tqdm import tqdm

    cfg = ex.config
    t_wall = time.perf_counter()
    step_wall0, steps0 = ex.physics.step_wall_s, ex.physics.steps
    reports = []
    bar = tqdm(total=len(plan.steps), desc=f"simulate {plan.object}", unit="step",
               disable=not progress, leave=False)
    try:
        first = plan.steps[0]
        rep = ex.reset(first["contacts"], pose_perturbation=pert)
        theta0 = pert[2]
        reports.append(rep)
        bar.update(1)
        for i, st in enumerate(plan.steps[1:], start=1):
            if not rep.ok:
                break
            if recorder is not None:
                recorder.move = i  # for the video's caption
            rep = ex.execute(st)
            reports.append(rep)
            bar.update(1)
            bar.set_postfix(theta=f"{ex.theta_true:.0f}")
    finally:
        bar.close()
    x, y, theta = ex.true_pose()
    goal = plan.rotation_deg
    done = len(reports) == len(plan.steps) and reports[-1].ok
    err = theta - goal
    rot_err = (theta - theta0) - goal
    # a circle's orientation cannot be observed from contact positions (7.4.5): the
    # controller can only make the commanded turn, so success is judged on that
    observable = not isinstance(ex.shape, Circle)
    judged = err if observable else rot_err
    grips = [max(r.grip_n) for r in reports]
    out = {
        "object": plan.object,
        "success": bool(done and not ex.dropped and abs(judged) <= cfg.success_angle_deg),
        "status": reports[-1].status,
        "dropped": bool(ex.dropped),
        "drop_reason": ex.drop_reason,
        "rotation_deg": float(theta - theta0),
        "planned_rotation_deg": float(goal),
        "final_angle_error_deg": float(err),
        "rotation_error_deg": float(rot_err),
        "orientation_observable": observable,
        "final_position_error_m": float(math.hypot(x, y)),
        "final_pose": (float(x), float(y), float(theta)),
        "final_pose_estimate": ex.pose_estimate(),
        "steps_done": sum(r.ok for r in reports),
        "steps_total": len(plan.steps),
        "slips": int(sum(r.slips for r in reports)),
        "max_slip_m": float(max(r.max_slip_m for r in reports)),
        "max_grip_n": float(max(grips)) if grips else 0.0,
        "localizations": int(sum(r.localized for r in reports)),
        "sim_time_s": float(ex.time),
        "execute_wall_time_s": time.perf_counter() - t_wall,
        "physics_wall_time_s": ex.physics.step_wall_s - step_wall0,
        "physics_steps": ex.physics.steps - steps0,
        "pose_perturbation": tuple(float(v) for v in pert),
        "finger_mu": ex.mu,
        "plan_mu": ex.plan_mu,
        "steps": [r.to_dict() for r in reports],
    }
    return out


def format_result(result: dict[str, Any]) -> str:
    """A short human-readable summary of :func:`simulate_plan`'s result."""
    verdict = "success" if result["success"] else (
        "DROPPED" if result["dropped"] else f"FAILED ({result['status']})")
    lines = [
        f"{result['object']}: {verdict}: turned {result['rotation_deg']:.1f} deg of "
        f"{result['planned_rotation_deg']:.0f}; final orientation error "
        f"{result['final_angle_error_deg']:+.2f} deg, position error "
        f"{1e3 * result['final_position_error_m']:.1f} mm",
        f"steps {result['steps_done']}/{result['steps_total']}, slips {result['slips']} "
        f"(max {1e3 * result['max_slip_m']:.1f} mm), localizations "
        f"{result['localizations']}, max grip {result['max_grip_n']:.2f} N",
        f"simulated {result['sim_time_s']:.2f} s in {result['wall_time_s']:.2f} s wall"
        + (f"; video {result['video']}" if result.get("video") else ""),
    ]
    if result["dropped"]:
        lines.insert(1, f"drop: {result['drop_reason']}")
    return "\n".join(lines)


def benchmark_step_rate(plan: Plan | None = None, *, object: str = "ellipse",
                        config: SimConfig | str | None = None, repeat: int = 1
                        ) -> dict[str, float]:
    """Physics steps per second with the controller, and of ``mj_step`` alone, measured
    in the same run.

    Runs ``plan`` (default: the optimal 360° gait of ``object`` at mu = 0.7) with
    :func:`simulate_plan`; the wall time spent inside ``mj_step`` is accumulated by
    :meth:`HandPhysics.step` around every call, so the raw rate is that of the very
    states the controlled run went through. The controller costs no more than the
    physics when ``controller_share <= 0.5``, i.e. ``controlled_steps_per_s >=
    raw_steps_per_s / 2``. Medians over ``repeat`` runs.

    Returns
    -------
    dict
        ``controlled_steps_per_s`` (physics steps per wall second, controller
        included), ``raw_steps_per_s`` (physics steps per second of ``mj_step`` wall
        time), ``controller_share`` (fraction of the execution's wall time outside
        ``mj_step``), ``gait_wall_s`` (the whole :func:`simulate_plan` call, model
        build included), ``gait_sim_s``, ``servo_hz``, ``physics_hz``.
    """
    cfg = _resolve_config(config)
    if plan is None:
        plan = default_plan(object)
    walls, ctrl_rates, raw_rates, shares = [], [], [], []
    sim_s = 0.0
    for _ in range(max(1, repeat)):
        res = simulate_plan(plan, config=cfg)
        walls.append(res["wall_time_s"])
        sim_s = res["sim_time_s"]
        t_exec = res["execute_wall_time_s"]
        ctrl_rates.append(res["physics_steps"] / t_exec)
        raw_rates.append(res["physics_steps"] / res["physics_wall_time_s"])
        shares.append(1.0 - res["physics_wall_time_s"] / t_exec)
    return {
        "controlled_steps_per_s": float(np.median(ctrl_rates)),
        "raw_steps_per_s": float(np.median(raw_rates)),
        "controller_share": float(np.median(shares)),
        "gait_wall_s": float(np.median(walls)),
        "gait_sim_s": float(sim_s),
        "servo_hz": cfg.servo_rate_hz,
        "physics_hz": 1.0 / cfg.timestep,
    }


def tug_test(object: str = "circle", contacts: dict | None = None, *,
             force: float = 4.0, direction_deg: float | None = None, along_grip: bool = False,
             grip_check: bool = True, ramp_s: float = 0.5, hold_s: float = 0.5,
             config: SimConfig | str | None = None, mu: float = THESIS_MU) -> dict[str, Any]:
    """Pull on a grasped object (thesis 7.5's tug) and measure what the grasp does.

    The object is grasped at ``contacts`` (default: fingers 1 and 2 on opposite sides,
    15° and 195°); a horizontal force on its centre of mass ramps to ``force`` (N) over
    ``ramp_s`` and stays for ``hold_s``, perpendicular to the grip line (or along it,
    toward finger 2, with ``along_grip``; or at ``direction_deg`` in frame F).

    Returns
    -------
    dict
        ``slip_m`` (largest sliding of a contact along the object), ``displacement_m``
        (of the object's centre, the servo springs' give included), ``lost_contact``
        (a gripping finger off the object at some check), ``dropped``, ``max_grip_n``.
    """
    cfg = _resolve_config(config).replace(grip_check=grip_check)
    contacts = contacts or {1: 15.0, 2: 195.0}
    ex = GaitExecutor(object, mu=mu, config=cfg)
    rep = ex.reset(contacts)
    if not rep.ok:
        raise RuntimeError(f"tug_test: the grasp failed: {rep.status} {rep.message}")
    fingers = sorted(ex.held)
    tips = ex.physics.tip_positions()[fingers, :2]
    grip_dir = tips[1] - tips[0]
    a_grip = math.degrees(math.atan2(grip_dir[1], grip_dir[0]))
    if direction_deg is None:
        direction_deg = a_grip if along_grip else a_grip + 90.0
    u = (math.cos(math.radians(direction_deg)), math.sin(math.radians(direction_deg)))
    t_start = ex.time
    ex.set_disturbance(lambda t: (force * min(1.0, (t - t_start) / ramp_s) * u[0],
                                  force * min(1.0, (t - t_start) / ramp_s) * u[1]))
    x0 = np.array(ex.physics.object_pose()[:2])
    tips0 = ex.tips_in_object_frame()
    lost = False
    slip = 0.0
    max_grip = 0.0
    n = max(1, int(round((ramp_s + hold_s) / TUG_REPORT_S)))
    status = "ok"
    for _ in range(n):
        r = ex.hold((ramp_s + hold_s) / n)
        max_grip = max(max_grip, max(r.grip_n))
        touch = ex.physics.tip_in_contact()
        lost |= not all(bool(touch[f]) for f in fingers)
        tips1 = ex.tips_in_object_frame()
        slip = max(slip, float(np.max(np.linalg.norm(tips1[fingers] - tips0[fingers], axis=1))))
        if not r.ok:
            status = r.status
            lost = True
            break
    ex.set_disturbance(None)
    x1 = np.array(ex.physics.object_pose()[:2])
    return {"object": object, "force_n": force, "direction_deg": float(direction_deg),
            "grip_check": grip_check, "slip_m": slip,
            "displacement_m": float(np.hypot(*(x1 - x0))), "lost_contact": bool(lost),
            "dropped": status == "dropped", "max_grip_n": max_grip}


def parse_perturbation(text: str | None) -> tuple[float, float, float] | str | None:
    """``"DX,DY,DTHETA"`` (m, m, deg) or ``"random"`` from a command line; None passes.

    Raises
    ------
    GraspGaitInputError
        Not three numbers, or one of them not finite (``nan``, ``inf``).
    """
    if text is None or text == "random":
        return text
    parts = text.split(",")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        vals = ()
    if len(vals) != 3:
        raise GraspGaitInputError(
            f"--perturb {text!r}: give DX,DY,DTHETA (metres, metres, degrees), e.g. "
            "0.004,-0.002,3, or 'random'")
    for name, unit, v in zip(("dx", "dy", "dtheta"), ("m", "m", "deg"), vals, strict=True):
        if not math.isfinite(v):
            raise GraspGaitInputError(
                f"--perturb {name}={v} {unit}: not a finite number; give DX,DY,DTHETA "
                "(metres, metres, degrees), e.g. 0.004,-0.002,3, or 'random'")
    return vals  # type: ignore[return-value]


def perturbation_limits(shape: Shape, config: SimConfig) -> tuple[float, float | None]:
    """The largest initial pose error the simulated hand recovers from by design:
    ``(offset_m, angle_deg)``; ``angle_deg`` is None when any angle will do.

    - **Offset** ``min(standoff, overshoot)`` (0.010 m by default): every finger finds
      the object along an approach line toward the expected centre (the probe's, thesis
      7.4.2, or the grasp's without the probe), whose contact detection (7.3) is armed
      from ``standoff`` outside the expected surface to ``overshoot`` inside it. An
      offset moves the surface along the line by about its own length: beyond
      ``standoff`` a finger runs into the object before detection is armed (and shoves
      it), beyond ``overshoot`` it never reaches it.
    - **Angle** ``probe_vertex_clearance_deg`` (8°): the probe aims that far from the
      expected object's vertices, so a smaller turn leaves each probe finger on the
      edge it aimed at, and the localizer's local search (7.4.5) starts within reach of
      the true pose. A circle's orientation is never observed and touches nothing: no
      bound (None).

    Measured on the four thesis objects' optimal plans (vertex clearance 4°): 192 of
    192 gaits succeed from offsets of 8 and 9.9 mm in eight directions at -7.9°, 0° and
    7.9°; from 13 and 20 mm at -15°, 0° and 15°, 39 of 192 fail (no contact, drops),
    none of them on the circle.
    """
    offset = min(config.standoff, config.overshoot)
    angle = None if isinstance(shape, Circle) else config.probe_vertex_clearance_deg
    return offset, angle


def check_perturbation(pert: tuple[float, float, float] | str | None, shape: Shape,
                       config: SimConfig, option: str = "--perturb") -> None:
    """Refuse an initial pose error beyond :func:`perturbation_limits` (or not finite),
    in one line naming the value, its unit and the bound. ``"random"`` is checked by
    the range it draws from (up to 6 mm and 5°); None passes.

    Raises
    ------
    GraspGaitInputError
        The perturbation is not finite or beyond what the hand recovers from.
    """
    if pert is None:
        return
    max_off, max_ang = perturbation_limits(shape, config)
    why_off = (f"the {max_off:g} m the approach lines can detect (contact detection runs "
               f"from standoff={config.standoff:g} m outside the expected surface to "
               f"overshoot={config.overshoot:g} m inside)")
    why_ang = (f"the {max_ang or 0.0:g} deg the probe tolerates (probe_vertex_clearance_deg: "
               "its contacts keep that far from the expected object's vertices)")
    if isinstance(pert, str):
        if pert != "random":
            raise GraspGaitInputError(f"{option} {pert!r}: give DX,DY,DTHETA or 'random'")
        if PERTURBATION_MAX_OFFSET_M > max_off:
            raise GraspGaitInputError(
                f"{option} random: draws offsets up to {PERTURBATION_MAX_OFFSET_M:g} m, "
                f"beyond {why_off}; give DX,DY,DTHETA with sqrt(dx^2 + dy^2) <= {max_off:g} m")
        if max_ang is not None and PERTURBATION_MAX_ANGLE_DEG > max_ang:
            raise GraspGaitInputError(
                f"{option} random: draws angles up to {PERTURBATION_MAX_ANGLE_DEG:g} deg, "
                f"beyond {why_ang}; give DX,DY,DTHETA with |dtheta| <= {max_ang:g} deg")
        return
    dx, dy, dth = (float(v) for v in pert)
    for name, unit, v in (("dx", "m", dx), ("dy", "m", dy), ("dtheta", "deg", dth)):
        if not math.isfinite(v):
            raise GraspGaitInputError(f"{option} {name}={v} {unit}: not a finite number")
    off = math.hypot(dx, dy)
    if off > max_off:
        name, v = ("dx", dx) if abs(dx) > max_off else ("dy", dy) if abs(dy) > max_off \
            else ("sqrt(dx^2 + dy^2)", off)
        raise GraspGaitInputError(
            f"{option} {name}={v:g} m: beyond {why_off}; give sqrt(dx^2 + dy^2) <= "
            f"{max_off:g} m")
    if max_ang is not None and abs(dth) > max_ang:
        raise GraspGaitInputError(
            f"{option} dtheta={dth:g} deg: beyond {why_ang}; give |dtheta| <= {max_ang:g} deg")


def check_video_path(video: str | os.PathLike) -> Path:
    """Refuse a ``--video`` path that :func:`simulate_plan` could not write, before the
    run: a suffix other than ``.mp4`` (the container written), an existing directory,
    or a folder that cannot be created or written. Creates the folder when missing.

    Raises
    ------
    GraspGaitInputError
        In one line, with the path and the fix.
    """
    from graspgait_env.outputs import check_output_path

    return check_output_path("--video", video, (VIDEO_SUFFIX,))


def point_contact_warning(plan: Plan, source: str | os.PathLike = "the plan") -> str | None:
    """A one-line warning when ``plan`` was made for the thesis's point contacts (no
    ``contact_model`` ``"hand"`` recorded, docs/formats.md), else None.

    Point-contact grasps may sit at the edge of the friction cone and next to vertices;
    the hand's ball tips roll and carry the rotations' load, and at finger friction = mu
    (the default) they drop such plans (measured: 0 of 24 perturbed runs of the four
    thesis objects' rule-based and optimal gaits held; docs/science/hand.md).
    """
    if plan.assumed_contact_model.is_point:
        return (f"{source} was planned for point contacts (no contact_model 'hand'); the "
                "hand may drop it at finger friction = mu: plan without --point-contacts")
    return None


def simulate_command(plan_path: str | os.PathLike, *, video: str | None = None,
                     seed: int = 0, perturb: str | None = None, config: str | None = None,
                     json_out: str | None = None, progress: bool = True) -> int:
    """``graspgait simulate PLAN.json [--video out.mp4] [--perturb DX,DY,DTH|random]
    [--seed N] [--config sim.yaml] [--json result.json]``.

    Prints :func:`format_result`; writes the result as JSON (atomically) when asked.
    Returns the exit status: 0 when the gait succeeded, 1 when the simulated hand
    failed it (dropped the object, missed a contact, or ended off the planned
    orientation). Bad input raises :class:`~graspgait_env.errors.GraspGaitInputError`
    (the CLI exits 2), all of it before the simulation runs: the plan, the config, a
    perturbation beyond :func:`perturbation_limits` (:func:`check_perturbation`) and a
    video path that could not be written (:func:`check_video_path`).
    """
    import json

    plan = Plan.load(plan_path)
    cfg = _resolve_config(config)
    pert = parse_perturbation(perturb)
    check_perturbation(pert, load_object(plan.object), cfg)
    if video is not None:
        check_video_path(video)
    warning = point_contact_warning(plan, plan_path)
    if warning:
        print(f"graspgait: warning: {warning}", file=sys.stderr)
    result = simulate_plan(plan, video=video, seed=seed, pose_perturbation=pert,
                           config=cfg, progress=progress)
    print(format_result(result))
    if json_out is not None:
        text = json.dumps(result, indent=1, default=float) + "\n"
        atomic_write(json_out, lambda fh: fh.write(text.encode("utf-8")))
    return 0 if result["success"] else 1


def default_plan(object: str = "ellipse", mu: float = THESIS_MU, planner: str = "optimal",
                 config: SimConfig | str | os.PathLike | None = None,
                 contact_model: str = "hand") -> Plan:
    """The 360° gait of ``object`` at ``mu`` by ``planner``
    (:mod:`graspgait_env.planners.registry`), as ``graspgait plan`` makes it: for the
    hand's contact model (:func:`graspgait_env.contact_model.hand_contact_model` of
    ``config``, default ``configs/sim/default.yaml``), or ``contact_model="point"`` for
    the thesis's point contacts.

    Raises
    ------
    GraspGaitInputError
        The planner finds no gait.
    """
    from graspgait_env.contact_model import contact_model_named
    from graspgait_env.gait import GaitModel
    from graspgait_env.planners.registry import run_planner

    cm = contact_model_named(contact_model, object, _resolve_config(config))
    model = GaitModel(object, mu, contact_model=cm)
    res = run_planner(planner, model, None, 360.0)
    if res.plan is None:
        raise GraspGaitInputError(f"{planner} planner found no gait for {object} at "
                                  f"mu={mu}: {res.reason}")
    return res.plan
