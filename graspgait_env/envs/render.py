"""Frames of the GraspGait environments (matplotlib, drawn off-screen on an Agg canvas).

Left panel: the object in the workspace frame ``F`` at its present angle θ, the three
finger workspaces as coloured arcs, the holding fingers as filled dots on their
contacts and the free finger as a ring at the middle of its workspace. Right panel:
the extended grasp map (object frame, thesis fig. 3.3) with the finger pair boxes at
the present θ (thesis figs. 4.5, 6.1) and the gait so far as a path of grasps,
unwrapped so that it climbs the extended map as the object turns.

Nothing here touches pyplot except :func:`show_human`, which needs a window.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray

from graspgait_env.plotting import plot_extended_map
from graspgait_env.shapes import Polygon

if TYPE_CHECKING:
    from graspgait_env.envs.map_env import GraspGaitEnv

__all__ = ["render_frame", "can_show", "show_human", "FINGER_COLORS"]

FINGER_COLORS = ("tab:red", "tab:green", "tab:blue")  # fingers 1, 2, 3
_FIGSIZE = (11.0, 5.5)  # (inches) at _DPI: a 792 x 396 frame
_DPI = 72


def _outline(shape) -> NDArray[np.float64]:
    if isinstance(shape, Polygon):
        v = shape.vertices
        return np.vstack([v, v[:1]])
    return shape.contour_point(np.linspace(0.0, 360.0, 361))


def _rot(xy: NDArray[np.float64], theta_deg: float) -> NDArray[np.float64]:
    t = math.radians(theta_deg)
    c, s = math.cos(t), math.sin(t)
    return xy @ np.array([[c, s], [-s, c]])


def _draw_hand(ax, env: GraspGaitEnv) -> None:
    model = env.model
    shape = model.shape
    st = env.state
    theta = st.k * model.step_deg
    xy = _rot(_outline(shape), theta)
    r = shape.r_max
    ax.fill(xy[:, 0], xy[:, 1], color="0.88", zorder=0)
    ax.plot(xy[:, 0], xy[:, 1], color="k", lw=1.2)
    mark = _rot(np.array([[0.0, 0.0], [0.8 * r, 0.0]]), theta)  # the object's x axis
    ax.plot(mark[:, 0], mark[:, 1], color="0.4", lw=0.8, ls="--")
    ring = 1.3 * r
    for f, (lo, hi) in enumerate(model.hand.workspaces_deg):
        a = np.radians(np.linspace(lo, hi, 60))
        ax.plot(ring * np.cos(a), ring * np.sin(a), color=FINGER_COLORS[f], lw=4, alpha=0.45,
                solid_capstyle="butt")
        mid = math.radians(0.5 * (lo + hi))
        ax.text(1.48 * r * math.cos(mid), 1.48 * r * math.sin(mid), str(f + 1),
                color=FINGER_COLORS[f], ha="center", va="center", fontsize=11,
                fontweight="bold")
        c = st.contacts[f]
        if c >= 0:
            phi = model.contact_deg(c)
            p = _rot(shape.contour_point(phi)[None, :], theta)[0]
            ax.plot([p[0]], [p[1]], "o", color=FINGER_COLORS[f], ms=11, mec="k")
        else:
            ax.plot([ring * math.cos(mid)], [ring * math.sin(mid)], "o", mfc="none",
                    mec=FINGER_COLORS[f], ms=11, mew=2)
    lim = 1.65 * r
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"{shape.name}, mu={model.mu:.3g}: theta={theta:g} deg of "
                 f"{env.turn_deg:g}, {env._regrasps} regrasps", fontsize=9)


def _draw_map(ax, env: GraspGaitEnv) -> None:
    model = env.model
    st = env.state
    theta = st.k * model.step_deg
    plot_extended_map(ax, model.grasp_map, model.hand, theta, box_labels=True,
                      title="extended grasp map, gait so far")
    trail = getattr(env, "_trail", [(st.k, st.contacts)])
    S, n, d = model.ws_start, model.n, model.step_deg

    def unwrapped(i: int, k: int, c: int) -> float:
        # x = s + p - k (grid steps): the path climbs the extended map as the object turns
        return (int(S[i]) + (c + k - int(S[i])) % n - k) * d

    k0, cs0 = trail[0]
    axes = [i for i in range(3) if cs0[i] >= 0]  # finger on the horizontal, vertical axis
    pts = []
    prev = cs0
    for k, cs in trail:
        if cs != prev:  # a regrasp: the kept finger keeps its axis (a horizontal or
            new = next(i for i in range(3) if cs[i] >= 0 and prev[i] < 0)  # vertical move)
            axes = [new if cs[a] < 0 else a for a in axes]
            prev = cs
        pts.append((unwrapped(axes[0], k, cs[axes[0]]), unwrapped(axes[1], k, cs[axes[1]])))
    p = np.array(pts, dtype=float)
    shift = 360.0 * math.floor(p[-1].min() / 360.0)  # the present grasp inside [0, 720)²
    p -= shift
    ax.plot(p[:, 0], p[:, 1], "-", color="tab:orange", lw=1.2)
    ax.plot(p[:-1, 0], p[:-1, 1], ".", color="tab:orange", ms=4)
    ax.plot(p[-1:, 0], p[-1:, 1], "x", color="tab:orange", ms=10, mew=2.5)
    ax.tick_params(labelsize=7)
    ax.xaxis.label.set_fontsize(8)
    ax.yaxis.label.set_fontsize(8)


def render_frame(env: GraspGaitEnv) -> NDArray[np.uint8]:
    """Draw the present state of ``env``; returns an ``(H, W, 3)`` uint8 RGB array."""
    fig = Figure(figsize=_FIGSIZE, dpi=_DPI, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    ax_h, ax_m = fig.subplots(1, 2, width_ratios=[1.0, 1.15])
    _draw_hand(ax_h, env)
    _draw_map(ax_m, env)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def can_show(env: GraspGaitEnv) -> bool:
    """True when matplotlib can open a window; otherwise warn once (per env) and say no."""
    import matplotlib
    from matplotlib.backends import BackendFilter, backend_registry

    backend = matplotlib.get_backend().lower()
    if backend not in backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE):
        return True
    if not env._human_warned:
        env._human_warned = True
        import gymnasium as gym

        gym.logger.warn(
            f"GraspGait render_mode='human': matplotlib backend {backend!r} cannot open a "
            "window (no display), so nothing is shown; use render_mode='rgb_array'")
    return False


def show_human(env: GraspGaitEnv, frame: NDArray[np.uint8]) -> None:
    """Show ``frame`` in a matplotlib window (pyplot), reusing it between calls."""
    import matplotlib.pyplot as plt

    if env._fig is None or not plt.fignum_exists(env._fig.number):
        env._fig = plt.figure("GraspGait", figsize=_FIGSIZE)
        env._fig_img = env._fig.add_axes((0, 0, 1, 1))
        env._fig_img.set_axis_off()
        env._fig_im = env._fig_img.imshow(frame)
    else:
        env._fig_im.set_data(frame)
    env._fig.canvas.draw_idle()
    plt.pause(1.0 / env.metadata["render_fps"])
