"""The demo's story: the thesis's rule-based gait, the exact optimum and a learned gait.

From one start grasp of one object, three gaits turn the object 360°:

- **rule-based**: the thesis's prototype-gait method (6.5, Table 6.1),
  :func:`graspgait_env.planners.rule_based.rule_based`;
- **optimal**: the fewest regrasps (beyond the thesis),
  :func:`graspgait_env.planners.exact.optimal_gait`;
- **learned**: a shipped (or any saved) agent played greedily in ``GraspGait-v0`` with
  the env settings of its model card, the states it visits turned into a plan.

:func:`tell_story` draws the three on the object's extended grasp map (thesis 4.3, one
panel each, the same map window), tabulates them (success, regrasps, rotation, moves,
wall time) and writes each as a plan JSON (``docs/formats.md``), so ``graspgait
simulate`` can replay the learned gait on the MuJoCo hand (``make demo`` records its
video).
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from graspgait_env.agents.card import load_agent
from graspgait_env.agents.envs import env_kwargs_for, make_env
from graspgait_env.agents.evaluate import agent_predictor
from graspgait_env.atomic import write_text_atomic
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import Plan, plan_from_states

__all__ = ["GAITS", "gait_model_of", "learned_gait", "story_figure", "story_table", "tell_story"]

GAITS = ("rule-based", "optimal", "learned")
"""The gaits of the story, in the order drawn and tabulated."""
_COLORS = {"rule-based": "tab:blue", "optimal": "tab:green", "learned": "tab:red"}


def learned_gait(model_path: str | os.PathLike[str],
                 start: Mapping[int, float] | GaitState | None = None,
                 object: Any = None, mu: float | None = None  # noqa: A002 - CLI's name
                 ) -> tuple[GaitModel, GaitState, list[GaitState], dict[str, Any]]:
    """Play a saved agent greedily for one episode of ``GraspGait-v0``.

    Parameters
    ----------
    model_path
        A model zip with its card (``agents/models/general.zip``).
    start
        ``{finger number: contact_deg}`` or a :class:`GaitState` at θ = 0 (the env's
        ``reset(options={"start": ...})``); None: the planners' default start
        (:func:`graspgait_env.planners.registry.default_start`, the first of 24 spread
        starts from which a gait exists).
    object, mu
        Replace the trained object and friction (None: the card's).

    Returns
    -------
    model, start, states, info
        The env's gait model, the start state, every state of the episode (the start
        first; one per move, illegal actions leave none) and the last step's ``info``
        plus ``wall_s`` (seconds the agent took).
    """
    from graspgait_env.planners.registry import default_start

    agent, card = load_agent(model_path)
    env = _story_env(card, object, mu)
    try:
        u = env.unwrapped
        options = {"start": start if start is not None else default_start(u.model)}
        predict = agent_predictor(agent)
        t0 = time.perf_counter()
        obs, info = env.reset(seed=0, options=options)
        first = u.state
        states = [first]
        done = False
        while not done:
            obs, _, terminated, truncated, info = env.step(
                np.int64(predict(obs, np.asarray(u.action_masks(), dtype=bool))))
            if u.state != states[-1]:
                states.append(u.state)
            done = terminated or truncated
        info = {**info, "wall_s": time.perf_counter() - t0}
        return u.model, first, states, info
    finally:
        env.close()


def _story_env(card: Mapping[str, Any], object: Any, mu: float | None) -> Any:  # noqa: A002
    """``GraspGait-v0`` with the card's env settings (object and ``mu`` replaced if given)."""
    trained_id = card.get("env_id") or "GraspGait-v0"
    kwargs = env_kwargs_for("GraspGait-v0", trained_id, card.get("env_kwargs") or {},
                            object, mu)
    return make_env("GraspGait-v0", kwargs, card.get("wrappers") or ())


def gait_model_of(model_path: str | os.PathLike[str], object: Any = None,  # noqa: A002
                  mu: float | None = None) -> GaitModel:
    """The gait model the story plays the agent on (the card's object, ``mu``, hand, grid
    and contact model, object and ``mu`` replaced if given): for parsing a start grasp."""
    from graspgait_env.agents.card import read_card

    env = _story_env(read_card(model_path), object, mu)
    try:
        return env.unwrapped.model
    finally:
        env.close()


def _table_cells(rows: Mapping[str, Mapping[str, Any]]) -> tuple[list[str], list[list[str]]]:
    """Header and cells of the comparison (one row per gait, :data:`GAITS` order)."""
    opt = rows.get("optimal", {}).get("regrasps")
    head = ["gait", "turned 360°", "regrasps", "x optimum", "rotation (deg)", "moves",
            "wall (ms)"]
    cells = []
    for name in GAITS:
        r = rows.get(name)
        if r is None:
            continue
        ok = bool(r["success"])
        cells.append([name, "yes" if ok else "no", str(r["regrasps"]) if ok else "-",
                      f"{r['regrasps'] / opt:.2f}" if ok and opt else "-",
                      f"{r['rotation_deg']:.0f}", str(r["moves"]), f"{1000 * r['wall_s']:.0f}"])
    return head, cells


def story_table(rows: Mapping[str, Mapping[str, Any]]) -> str:
    """The comparison as a Markdown table: one row per gait (:data:`GAITS` order).

    ``rows[name]`` holds ``success`` (bool), ``regrasps``, ``rotation_deg`` (total
    rotation, degrees, both directions counted), ``moves`` (regrasps + rotations as
    played, rotations merged for the planners) and ``wall_s``.
    """
    head, cells = _table_cells(rows)
    lines = ["| " + " | ".join(head) + " |", "|---|---|" + "---:|" * (len(head) - 2)]
    lines += ["| " + " | ".join(c) + " |" for c in cells]
    return "\n".join(lines)


def story_figure(model: GaitModel, plans: Mapping[str, Plan | None],
                 rows: Mapping[str, Mapping[str, Any]], title: str = "") -> Any:
    """The three gaits on the object's extended grasp map (object frame, thesis 4.3).

    One panel per gait in :data:`GAITS` order, all showing the same window of the map:
    grey cells are force-closure grasps at the model's ``mu``; regrasps are horizontal
    or vertical moves (one contact kept), a rotation leaves the grasp in place (thesis
    fig. 4.5); the start is a square, the end a star. The comparison table
    (:func:`story_table`'s rows) sits below.
    """
    from matplotlib.figure import Figure

    from graspgait_env.plotting import gait_path

    paths = {k: np.array([p["obj"] for p in gait_path(v.steps)])
             for k, v in plans.items() if v is not None}
    allxy = np.concatenate(list(paths.values())) if paths else np.zeros((1, 2))
    lo = allxy.min(axis=0) - 30.0
    hi = allxy.max(axis=0) + 30.0
    n, step = model.n, model.step_deg
    ix = np.arange(int(np.floor(lo[0] / step)), int(np.ceil(hi[0] / step)) + 1)
    iy = np.arange(int(np.floor(lo[1] / step)), int(np.ceil(hi[1] / step)) + 1)
    tile = model.stable[np.ix_(ix % n, iy % n)]
    extent = [ix[0] * step - step / 2, ix[-1] * step + step / 2,
              iy[0] * step - step / 2, iy[-1] * step + step / 2]
    fig = Figure(figsize=(15, 8.2), layout="constrained")
    grid = fig.add_gridspec(2, len(GAITS), height_ratios=[5, 1])
    axes = [fig.add_subplot(grid[0, i]) for i in range(len(GAITS))]
    for ax, name in zip(axes, GAITS, strict=True):
        ax.imshow(tile.T, origin="lower", cmap="Greys", vmin=0, vmax=1.6,
                  interpolation="nearest", extent=extent)
        ax.set_xlabel("finger on x: contact phi, object frame (deg, unwrapped)")
        xy = paths.get(name)
        if xy is None:
            ax.set_title(f"{name}: no gait")
            continue
        ax.plot(xy[:, 0], xy[:, 1], "-o", color=_COLORS[name], lw=1.8, ms=3.5)
        ax.plot(*xy[0], "s", color=_COLORS[name], mec="k", ms=9)
        ax.plot(*xy[-1], "*", color=_COLORS[name], mec="k", ms=14)
        ax.set_title(f"{name}: {plans[name].regrasps} regrasps")
    axes[0].set_ylabel("finger on y: contact phi, object frame (deg, unwrapped)")
    tab = fig.add_subplot(grid[1, :])
    tab.axis("off")
    head, cells = _table_cells(rows)
    tab.table(cellText=cells, colLabels=head, loc="center", cellLoc="center")
    fig.suptitle(title + "\n(grey: force-closure grasps; square: start, star: end; "
                 "a regrasp moves along one axis, a rotation leaves the grasp in place)")
    return fig


def tell_story(model_path: str | os.PathLike[str], out_dir: str | os.PathLike[str] = "out",
               start: Mapping[int, float] | GaitState | None = None,
               object: Any = None,  # noqa: A002 - the CLI's name
               mu: float | None = None, prefix: str | None = None) -> dict[str, Any]:
    """Compare the rule-based, optimal and learned gaits from one start; write the files.

    Parameters
    ----------
    model_path
        The learned agent (a model zip with its card).
    out_dir
        Folder for the outputs (created).
    start
        As :func:`learned_gait`.
    object, mu
        Replace the trained object and friction (None: the card's).
    prefix
        File name prefix (default: the object's name).

    Returns
    -------
    dict
        ``rows`` (per gait: success, regrasps, rotation_deg, moves, wall_s), ``table``
        (Markdown), ``files`` (name -> path: ``figure``, ``table``, and ``{gait}_plan``
        for each gait that reached the turn), ``start`` ({finger: deg}).

    Raises
    ------
    GraspGaitInputError
        A missing model, a bad start, object or ``mu`` (the message names it).
    """
    from graspgait_env.planners.exact import optimal_gait
    from graspgait_env.planners.rule_based import rule_based
    from graspgait_env.plotting import save_figure

    model, first, states, info = learned_gait(model_path, start, object, mu)
    turn = 360.0
    plans: dict[str, Plan | None] = {}
    rows: dict[str, dict[str, Any]] = {}
    for name, planner in (("rule-based", rule_based), ("optimal", optimal_gait)):
        t0 = time.perf_counter()
        res = planner(model, first, turn)
        wall = time.perf_counter() - t0
        plans[name] = res.plan
        rows[name] = _row(res.plan, res.success, wall)
    learned = plan_from_states(model, states, {"planner": "learned",
                                               "model": str(model_path)},
                               merge_rotations=True)
    ok = bool(info.get("is_success"))
    plans["learned"] = learned if ok else None
    rows["learned"] = _row(learned, ok, info["wall_s"])
    rows["learned"]["moves"] = len(states) - 1  # as played (rotations not merged)
    table = story_table(rows)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = prefix or model.shape.name
    start_deg = {str(f + 1): model.contact_deg(first.contacts[f]) for f in first.held()}
    contacts = getattr(getattr(model, "contact_model", None), "name", "point")
    title = (f"{model.shape.name}, mu = {model.mu:g}, {contacts} contacts: three gaits turning "
             f"the object 360 deg from the start {start_deg}")
    files = {"figure": out / f"{stem}_story.png", "table": out / f"{stem}_story.md"}
    save_figure(story_figure(model, plans, rows, title), files["figure"])
    write_text_atomic(files["table"], f"{title}\n\n{table}\n")
    for name, plan in plans.items():
        if plan is not None:
            files[f"{name}_plan"] = out / f"{stem}_{name}_plan.json"
            write_text_atomic(files[f"{name}_plan"], plan.to_json())
    return {"rows": rows, "table": table, "files": {k: str(v) for k, v in files.items()},
            "start": start_deg}


def _row(plan: Plan | None, success: bool, wall_s: float) -> dict[str, Any]:
    if plan is None:
        return {"success": False, "regrasps": None, "rotation_deg": 0.0, "moves": 0,
                "wall_s": wall_s}
    rot = sum(abs(float(s["delta"])) for s in plan.steps if s["op"] == "rotate")
    return {"success": bool(success), "regrasps": plan.regrasps, "rotation_deg": rot,
            "moves": len(plan.steps) - 1, "wall_s": wall_s}
