"""``GraspGaitMujoco-v1``: the grasp-gait env with every move executed in MuJoCo (thesis ch. 7).

:class:`GraspGaitMujocoEnv` is :class:`~graspgait_env.envs.map_env.GraspGaitEnv` (same
spaces, observation layout, reward terms and mask function) whose legal actions are
turned into plan steps and executed on the simulated hand by the thesis controller
(:class:`~graspgait_env.sim.executor.GaitExecutor`). See the class docstring.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from graspgait_env.envs.config import GraspGaitConfig, check_number
from graspgait_env.envs.map_env import GraspGaitEnv
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.gait import REGRASP, ROTATE, GaitState
from graspgait_env.shapes import Shape
from graspgait_env.sim.config import SimConfig, load_sim_config
from graspgait_env.sim.executor import GaitExecutor, StepReport, random_pose_perturbation

__all__ = ["GraspGaitMujocoEnv", "MUJOCO_WARNINGS"]

# mjtWarning names, in MuJoCo's index order (mjData.warning[i] counts warning i)
MUJOCO_WARNINGS: tuple[str, ...] = tuple(mujoco.mjtWarning(i).name
                                         for i in range(mujoco.mjtWarning.mjNWARNING.value))
_START_TRIES = 4  # start grasps tried at reset before giving up on a physical grasp


class GraspGaitMujocoEnv(GraspGaitEnv):
    r"""``GraspGait-v0`` with every move executed on the simulated hand (thesis ch. 7).

    ## Description

    The map-level grasp-gait problem of :class:`~graspgait_env.envs.map_env.GraspGaitEnv`
    played on the MuJoCo model of the thesis hand (three 3-DOF point fingers with ball
    tips, the object on a table). The env keeps the map-level :class:`GaitState` as the
    **commanded state** (the plan so far); each legal action is turned into a plan step
    (``{"op": "rotate", "delta": deg}`` or ``{"op": "regrasp", "contacts": {...}}``,
    docs/formats.md) and executed by :class:`~graspgait_env.sim.executor.GaitExecutor`, the
    thesis controller (trajectory planner, PD servo, grip and friction cone check,
    object localizer; thesis 7.3-7.4). Physics is deterministic: an episode is a pure
    function of the start grasp, the pose perturbation and the actions.

    ## Action Space

    As ``GraspGait-v0``: ``Discrete(model.n_actions)`` (182 with the thesis hand).
    An illegal action is a penalized no-op that runs no physics.

    ## Observation Space

    As ``GraspGait-v0`` (same ``Box``, same layout, built by the same methods): the
    header and the grasp-map window describe the **commanded** state, so
    :func:`~graspgait_env.envs.map_env.state_from_observation` recovers it exactly
    (and :class:`graspgait_env.baselines.policies.PlannerPolicy` works unchanged). Only the mask
    entries
    (and ``info["action_mask"]``, ``action_masks()``) use the localizer's estimate:

    - the controller's estimated object angle ``θ̂`` (``StepReport.pose_estimate``) is
      rounded to the grid, ``k̂ = round(θ̂ / Δ)``;
    - if ``k̂ = k`` (the estimate lies within half a grid step of the commanded angle:
      always after a rotation, whose end the controller dead-reckons onto the commanded
      angle, thesis 7.4.5) the mask is ``model.action_mask(state)``, as at map level;
    - otherwise (after a regrasp, or when the initial probe found the object off by
      more than half a step) the regrasps whose new contact would lie outside the free
      finger's workspace at ``k̂`` are removed: the controller places the new finger
      on the contact at the *estimated* pose. Rotations keep the commanded mask: the
      controller folds the orientation error into the next rotation (thesis 7.4.5,
      7.5), so a rotation by ``d`` ends at the commanded angle ``k + d``, where the
      map-level mask checks the workspaces. If the restriction leaves no move, the
      commanded mask is kept (the estimate never makes a false dead end), and after
      any rotation ``k̂ = k`` again. ``info["mask_from_estimate"]`` says whether it
      removed a move. (A policy that ignores the mask, such as
      :class:`graspgait_env.baselines.policies.PlannerPolicy`, may then play an illegal regrasp, a
      no-op, again and again: mask-aware agents do not.)

    ## Rewards

    The six terms of ``GraspGait-v0`` (``REWARD_TERMS``), from the same method
    (``_reward``), summed in the same order; ``reward ==
    sum(info["reward_terms"].values())`` exactly. A move that ends in a drop, a failed
    contact or a MuJoCo warning costs its move term (``regrasp`` or ``rotation``) and
    ``dead_end``; it earns no ``turn``.

    ## Starting State

    As ``GraspGait-v0`` (θ = 0, a start grasp drawn by ``self.np_random``, or
    ``options["start"]``), then the object is placed at the centre plus a pose
    perturbation unknown to the controller, drawn from ``self.np_random`` uniformly in
    a disc of radius ``pose_noise[0]`` (m) and an angle in ``±pose_noise[1]`` (deg)
    (default ``(0, 0)``: the object exactly placed; the thesis tested ``(0.006, 5)``,
    ``pose_noise="thesis"``). The controller probes and localizes the object, then makes
    the start grasp (``GaitExecutor.reset``). A fresh MuJoCo model is built at every
    reset (~30 ms), so no physics state carries from one episode to the next. If the
    grasp fails (a drop or no contact) another start grasp is drawn (up to 4 tries,
    then ``RuntimeError``; with ``options["start"]`` it raises at once).

    ## Episode End

    - **Success** (terminated, ``is_success``): the turn reaches ``turn_deg``. It is
      judged on the commanded angle, which is also the estimated one (success comes
      from a rotation, after which the estimate equals the commanded angle). The true
      angle is reported in ``info["true_turn_deg"]``.
    - **Drop** (terminated, ``info["dropped"] = True``, ``is_success`` False,
      ``dead_end`` term): the executor's monitor found the object lost.
      ``info["sim_status"]`` is ``"dropped"``; a regrasp whose finger finds no object
      ends the episode the same way with ``sim_status = "no-contact"`` (``dropped``
      False).
    - **MuJoCo warning** (terminated, ``info["mujoco_warning"]`` the warning's name,
      e.g. ``"mjWARN_BADQACC"``, ``dead_end`` term): any ``mjData.warning`` counter
      rose during the move. MuJoCo resets its data after such a warning; the episode is
      ended rather than continued on a silently reset simulation.
    - Dead end, wrong way and truncation as in ``GraspGait-v0``.

    After a terminal move the mask is all False.

    ## Info

    The keys of ``GraspGait-v0`` plus ``dropped``, ``sim_status`` (``ok``, ``dropped``,
    ``no-contact``, ``warning`` or ``skipped`` for an illegal action), ``mujoco_warning``
    (a name or None), ``pose_estimate`` (x m, y m, θ deg), ``estimated_turn_deg``,
    ``true_turn_deg``, ``mask_from_estimate`` and ``sim_time_s`` (simulated time).

    ## Arguments

    ``gymnasium.make("graspgait_env:GraspGaitMujoco-v1", object="ellipse", mu=0.7, *,
    sim_config=None, pose_noise=(0.0, 0.0), config=None, render_mode=None, **fields)``

    - ``object, mu, config, render_mode`` and the ``fields`` of
      :class:`~graspgait_env.envs.config.GraspGaitConfig` (``hand``, ``turn_deg``,
      ``n``, reward weights, ``max_backward_deg``, map window): as in ``GraspGait-v0``,
      checked the same way. ``mu`` is the planning friction (the controller's friction
      cone check uses it); the contacts' true friction is ``sim_config.finger_mu``
      (default: ``mu`` itself). ``contact_model`` defaults to ``"hand"`` here (when no
      ``config`` is given): the grasp maps, and so the action masks, are those of the
      hand's rolling ball tips with the friction margin its rotations need
      (:mod:`graspgait_env.contact_model`); ``"point"`` gives ``GraspGait-v0``'s maps.
    - ``sim_config``: :class:`~graspgait_env.sim.config.SimConfig`, a YAML path or None
      for ``configs/sim/default.yaml``.
    - ``pose_noise``: ``(max_offset_m, max_angle_deg)`` of the initial pose
      perturbation, or ``"thesis"`` for ``(0.006, 5.0)``.
    - ``render_mode``: ``"rgb_array"`` returns a ``(480, 640, 3)`` uint8 frame of the
      simulated hand seen from straight above (MuJoCo's off-screen renderer; headless
      it needs ``MUJOCO_GL=egl``, which :mod:`graspgait_env.sim` sets when MuJoCo is
      not yet imported), with the finger workspaces as coloured arcs (finger 1 red,
      2 green, 3 blue), each fingertip in its finger's colour with its number beside
      it, and captions: the object and friction, the commanded object angle with the
      true one, and the move count (rotations, regrasps). ``"human"`` shows the same
      frame in a matplotlib window (see ``GraspGait-v0``). One frame per move, so
      ``metadata["render_fps"]`` (4) plays a recorded episode (Gymnasium's
      ``RecordVideo``) at four moves per second. See
      :class:`~graspgait_env.sim.view.HandView`.

    Attributes: ``executor`` (the :class:`GaitExecutor` of the present episode, None
    before the first reset) and ``physics`` (its by-name MuJoCo accessor).

    ## Pickling

    MuJoCo objects do not pickle. ``pickle`` and ``copy.deepcopy`` store the episode's
    start grasp, perturbation and executed plan steps, and rebuild the simulation by
    replaying them (deterministic; the replayed physics state is checked bit for bit).
    A disturbance set with ``executor.set_disturbance`` is not part of the replay.

    ## Version History

    - v1: plans and acts with the hand's contact model (``contact_model="hand"``:
      fingertip radius, load-torque friction margin, vertex clearance, rolling drift),
      the sim's finger friction equals ``mu`` (was 1.0), the controller's check cone is
      narrowed by the hand's margin and the fingers follow their rolling balls; renders
      the hand from a camera above with overlays (was the map-level picture).
      ``observation_mode`` (named parts) added since, opt-in: the default ``"box"`` is
      the observation as before.
    - v0: initial version.
    """

    def __init__(
        self,
        object: str | os.PathLike | Shape = "ellipse",  # noqa: A002 - the user-facing name
        mu: float = 0.7,
        *,
        sim_config: SimConfig | str | os.PathLike | None = None,
        pose_noise: tuple[float, float] | str = (0.0, 0.0),
        config: GraspGaitConfig | None = None,
        render_mode: str | None = None,
        **fields: Any,
    ) -> None:
        if not (sim_config is None or isinstance(sim_config, (SimConfig, str, os.PathLike))):
            raise GraspGaitInputError(
                f"sim_config={sim_config!r}: give a SimConfig, a path to a sim YAML, or None "
                "for the bundled one (`graspgait config sim default` prints it)")
        self.sim_config = (sim_config if isinstance(sim_config, SimConfig)
                           else load_sim_config(sim_config))
        if config is None and "contact_model" not in fields:
            fields = {**fields, "contact_model": "hand"}  # plans the hand can execute
        super().__init__(object, mu, config=config, render_mode=render_mode, **fields)
        fix = "give (max_offset_m, max_angle_deg), e.g. (0.006, 5.0), or 'thesis' for that"
        if isinstance(pose_noise, str):
            if pose_noise != "thesis":
                raise GraspGaitInputError(f"pose_noise={pose_noise!r}: {fix}")
            pose_noise = (0.006, 5.0)
        try:
            off, ang = pose_noise
        except (TypeError, ValueError):
            raise GraspGaitInputError(f"pose_noise={pose_noise!r}: {fix}") from None
        self.pose_noise = (check_number("pose_noise[0]", off, 0.006, minimum=0.0,
                                        why="metres"),
                           check_number("pose_noise[1]", ang, 5.0, minimum=0.0,
                                        why="degrees"))
        # the executor loads the object's physical fields from its file when it has one
        self._sim_object: str | Shape = object if isinstance(object, str) else self.model.shape
        self.executor: GaitExecutor | None = None
        self._est_k: int | None = None  # estimated angle on the grid (None: use commanded)
        self._restricted = False
        self._replay: dict[str, Any] | None = None
        self._hand_view = None  # sim.view.HandView, made by the first render()
        self._resetting = False  # within the map-level reset (no frame to draw yet)

    # ------------------------------------------------------------------ simulation
    def _planning_contact_model(self, object: str | os.PathLike | Shape):  # noqa: A002
        """``config.contact_model`` for ``object``, the hand's from ``sim_config``."""
        return self.config.planning_contact_model(object, self.sim_config)

    @property
    def physics(self):
        """The present episode's :class:`~graspgait_env.sim.model.HandPhysics` (or None)."""
        return None if self.executor is None else self.executor.physics

    def _make_executor(self) -> GaitExecutor:
        return GaitExecutor(self._sim_object, mu=self.model.mu, config=self.sim_config,
                            workspaces_deg=[tuple(w) for w in self.model.hand.workspaces_deg])

    def _warning_counts(self) -> list[int]:
        return [int(w.number) for w in self.executor.physics.data.warning]

    def _new_warning(self, before: list[int]) -> str | None:
        after = self._warning_counts()
        for name, b, a in zip(MUJOCO_WARNINGS, before, after, strict=False):
            if a > b:
                return name
        return None

    def _contacts_deg(self, contacts: tuple[int, ...]) -> dict[str, float]:
        return {str(f + 1): self.model.contact_deg(c) for f, c in enumerate(contacts) if c >= 0}

    def _plan_step(self, s: GaitState, action: int) -> dict[str, Any]:
        """The plan step (docs/formats.md) of a legal ``action`` in state ``s``."""
        m = self.model.decode(s, action)
        if m.kind == ROTATE:
            return {"op": "rotate", "delta": m.delta * self._step_deg}
        return {"op": "regrasp", "contacts": self._contacts_deg(self.model.apply(s, action)
                                                               .contacts)}

    def _set_estimate(self, report: StepReport) -> None:
        self._est_theta = float(report.pose_estimate[2])
        self._est_k = int(round(self._est_theta / self._step_deg))

    def _fingerprint(self) -> bytes:
        d = self.executor.physics.data
        return d.qpos.tobytes() + d.qvel.tobytes() + np.float64(d.time).tobytes()

    # ------------------------------------------------------------------ mask
    def _compute_mask(self) -> NDArray[np.bool_]:
        """The map-level mask of the commanded state; when the estimated angle is off
        the commanded one by more than half a grid step, regrasps whose new contact
        would lie outside the free finger's workspace at the estimated angle are
        removed (see *Observation Space*)."""
        mask = super()._compute_mask()
        self._restricted = False
        if self._est_k is None or self._est_k == self._k:
            return mask
        model, s, est_k = self.model, GaitState(self._k, self._c), self._est_k
        restricted = mask.copy()
        for a in np.flatnonzero(mask):
            m = model.decode(s, int(a))
            if m.kind == REGRASP and model.position(m.finger, m.contact, est_k) < 0:
                restricted[a] = False  # the new contact is outside the workspace at est_k
        if not restricted.any():
            return mask
        self._restricted = bool((restricted != mask).any())
        return restricted

    # ------------------------------------------------------------------ API
    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[NDArray[np.float32], dict]:
        """Draw a start grasp (``GraspGait-v0``), place the object with the pose
        perturbation and make the grasp on the simulated hand; returns ``(obs, info)``."""
        given = isinstance(options, Mapping) and options.get("start") is not None
        failures = []
        for attempt in range(1 if given else _START_TRIES):
            self._est_k = None
            self._resetting = True  # no human-mode frame until the hand holds the object
            try:
                obs, info = super().reset(seed=seed if attempt == 0 else None,
                                          options=options)
            finally:
                self._resetting = False
            pert = (0.0, 0.0, 0.0)
            if self.pose_noise != (0.0, 0.0):
                pert = random_pose_perturbation(self.np_random, *self.pose_noise)
            contacts = self._contacts_deg(self._c)
            self.executor = self._make_executor()
            before = self._warning_counts()
            report = self.executor.reset(contacts, pose_perturbation=pert)
            warn = self._new_warning(before)
            if report.ok and warn is None:
                break
            failures.append(f"{contacts}: {warn or report.status} {report.message}".strip())
        else:
            raise RuntimeError(
                f"object {self.model.shape.name!r} at mu={self.model.mu:g}: the simulated "
                f"hand could not make the start grasp ({'; '.join(failures)}); try another "
                "start, a smaller pose_noise or a higher sim_config.finger_mu")
        self._replay = {"contacts": contacts, "pert": pert, "steps": []}
        self._set_estimate(report)
        self._mask = self._compute_mask()
        if not self._mask.any():  # cannot happen: the commanded mask is kept then
            raise RuntimeError("no legal move at the start")
        self._write_motion()
        info["action_mask"] = self._mask
        info.update(self._sim_info(report, None))
        if self.render_mode == "human":
            self.render()
        return self._observe(), info

    def _sim_info(self, report: StepReport | None, warning: str | None) -> dict[str, Any]:
        ex = self.executor
        est = ex.pose_estimate()
        return {
            "dropped": bool(ex.dropped),
            "sim_status": ("skipped" if report is None
                           else "warning" if warning is not None else report.status),
            "mujoco_warning": warning,
            "pose_estimate": est,
            "estimated_turn_deg": est[2],
            "true_turn_deg": float(ex.theta_true),
            "mask_from_estimate": self._restricted,
            "sim_time_s": ex.time,
        }

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict]:
        """Execute one move on the simulated hand; see the class docstring."""
        a = self._action_index(action)  # raises before reset() and for a bad action
        if not self._mask[a]:  # illegal: a penalized no-op, no physics
            out = super().step(a)
            out[4].update(self._sim_info(None, None))
            return out
        plan_step = self._plan_step(self.state, a)
        before = self._warning_counts()
        report = self.executor.execute(plan_step)
        self._replay["steps"].append(plan_step)
        warning = self._new_warning(before)
        if warning is not None or not report.ok:
            return self._failed_move(plan_step, report, warning)
        self._set_estimate(report)
        obs, reward, terminated, truncated, info = super().step(a)
        info.update(self._sim_info(report, None))
        return obs, reward, terminated, truncated, info

    def _failed_move(self, plan_step: dict[str, Any], report: StepReport,
                     warning: str | None) -> tuple[NDArray[np.float32], float, bool, bool, dict]:
        """A drop, a failed contact or a MuJoCo warning: the episode ends; the commanded
        state stays where it was (the move did not complete)."""
        if plan_step["op"] == "rotate":
            move = ROTATE
            self._rotations += 1
        else:
            move = REGRASP
            self._regrasps += 1
        reward, terms = self._reward(self._k, self._k, move, not self._terminal, False)
        self._terminal = True
        self._restricted = False
        self._mask = np.zeros(self._A, dtype=bool)
        self._mask_view[...] = self._mask
        info = {
            "action_mask": self._mask,
            "reward_terms": terms,
            "is_success": False,
            "turn_deg": self._k * self._step_deg,
            "regrasps": self._regrasps,
        }
        info.update(self._sim_info(report, warning))
        if warning is None and report.status == "dropped":
            info["dropped"] = True
        if self.render_mode == "human":
            self.render()
        return self._observe(), reward, True, False, info

    # ------------------------------------------------------------------ rendering
    def render(self) -> NDArray[np.uint8] | None:
        """``rgb_array``: the hand now, ``(480, 640, 3)`` uint8; ``human``: show it (see
        ``render_mode``). Called by the map-level ``reset`` before the hand holds the
        object, it draws nothing (``reset`` shows the frame once the grasp is made)."""
        if getattr(self, "_resetting", False):
            return None
        return super().render()

    def _frame(self) -> NDArray[np.uint8]:
        """The hand now, from above, with the overlays (see ``render_mode``)."""
        from graspgait_env.sim.view import HandView

        ex = self.executor
        view = getattr(self, "_hand_view", None)
        if view is None:
            view = self._hand_view = HandView(ex.sim)
        elif view.sim is not ex.sim:  # a new episode's model
            view.use(ex.sim)
        theta = self._k * self._step_deg
        moves = self._rotations + self._regrasps
        lines = [f"{self.model.shape.name}: plan mu={self.model.mu:g}, finger mu={ex.mu:g}",
                 f"theta={theta:g} deg of {self.config.turn_deg:g} "
                 f"(true {ex.theta_true:.1f})",
                 f"moves {moves}: {self._rotations} rotations, {self._regrasps} regrasps"]
        if ex.dropped:
            lines.append("DROPPED")
        return view.render(ex.physics, lines)

    def close(self) -> None:
        """Free the renderer's GL context and close the human-mode window (idempotent)."""
        view, self._hand_view = getattr(self, "_hand_view", None), None
        if view is not None:
            view.close()
        super().close()

    # ------------------------------------------------------------------ pickling
    def __getstate__(self) -> dict[str, Any]:
        d = super().__getstate__()
        d.pop("_hand_view", None)  # a GL context does not pickle: the next render makes one
        ex = d.pop("executor", None)
        d["_fingerprint"] = None if ex is None else self._fingerprint()
        d["_disturbed"] = ex is not None and ex.disturbance_fn is not None
        return d

    def __setstate__(self, d: dict[str, Any]) -> None:
        fingerprint = d.pop("_fingerprint", None)
        d.pop("_disturbed", None)
        super().__setstate__(d)
        self.executor = None
        if self._replay is None:
            return
        self.executor = self._make_executor()
        rep = self._replay
        self.executor.reset(rep["contacts"], pose_perturbation=rep["pert"])
        for st in rep["steps"]:
            self.executor.execute(st)
        if fingerprint is not None and self._fingerprint() != fingerprint:
            raise RuntimeError("unpickling GraspGaitMujocoEnv: replaying the episode's "
                               f"{len(rep['steps'])} steps did not reproduce the physics "
                               "state (was a disturbance applied?)")
