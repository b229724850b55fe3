"""Frames of the GraspGait environments (matplotlib, drawn off-screen on an Agg canvas).

Left panel: the object in the workspace frame ``F`` at its present angle θ, the three
finger workspaces as coloured arcs, the holding fingers as filled dots on their
contacts and the free finger as a ring at the middle of its workspace. Right panel:
the extended grasp map (object frame, thesis fig. 3.3) with the finger pair boxes at
the present θ (thesis figs. 4.5, 6.1) and the gait so far as a path of grasps,
unwrapped so that it climbs the extended map as the object turns.

:func:`render_frame` draws from plain data (the gait model, the gait so far, the turn
asked for, the regrasps made), never from an env's attributes; :class:`GaitRenderer`,
owned by the env, keeps what lives between frames (the human-mode window, the
"cannot show" warning). Nothing here touches pyplot except :meth:`GaitRenderer.show`,
which needs a window.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray

from graspgait_env.gait import GaitState
from graspgait_env.plotting import plot_extended_map
from graspgait_env.shapes import Polygon

if TYPE_CHECKING:
    from graspgait_env.gait import GaitModel

__all__ = ["render_frame", "can_show", "GaitRenderer", "FINGER_COLORS"]

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


def _draw_hand(ax, model: GaitModel, st: GaitState, turn_deg: float, regrasps: int) -> None:
    shape = model.shape
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
                 f"{turn_deg:g}, {regrasps} regrasps", fontsize=9)


def _draw_map(ax, model: GaitModel, trail: Sequence[tuple[int, tuple[int, ...]]]) -> None:
    theta = trail[-1][0] * model.step_deg
    plot_extended_map(ax, model.grasp_map, model.hand, theta, box_labels=True,
                      title="extended grasp map, gait so far")
    S, d = model.ws_start, model.step_deg

    def unwrapped(i: int, k: int, c: int) -> float:
        # x = s + p - k (grid steps): the path climbs the extended map as the object turns
        return (int(S[i]) + model.position(i, c, k) - k) * d

    cs0 = trail[0][1]
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


def render_frame(model: GaitModel, trail: Sequence[tuple[int, tuple[int, ...]]],
                 turn_deg: float, regrasps: int) -> NDArray[np.uint8]:
    """Draw a gait state; returns an ``(H, W, 3)`` uint8 RGB array.

    Parameters
    ----------
    model
        The gait model (object, friction, hand, grid).
    trail
        The gait so far as ``(k, contacts)`` pairs, the present state last (at least one).
    turn_deg
        The requested turn (degrees), for the title.
    regrasps
        Regrasps made so far, for the title.
    """
    k, cs = trail[-1]
    fig = Figure(figsize=_FIGSIZE, dpi=_DPI, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    ax_h, ax_m = fig.subplots(1, 2, width_ratios=[1.0, 1.15])
    _draw_hand(ax_h, model, GaitState(k, tuple(cs)), turn_deg, regrasps)
    _draw_map(ax_m, model, trail)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def can_show() -> bool:
    """True when matplotlib's backend can open a window (an interactive backend)."""
    import matplotlib
    from matplotlib.backends import BackendFilter, backend_registry

    backend = matplotlib.get_backend().lower()
    return backend not in backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE)


class GaitRenderer:
    """What a GraspGait env keeps between frames: the human-mode window and the warning.

    Parameters
    ----------
    render_fps
        Frames per second of human mode (each :meth:`show` pauses ``1 / render_fps`` s).

    Pickling and ``copy.deepcopy`` drop the window (a matplotlib figure does not
    pickle); the next :meth:`show` opens a new one.
    """

    def __init__(self, render_fps: float) -> None:
        self.render_fps = float(render_fps)
        self.warned = False  # the "cannot show" warning is given once per renderer
        self._fig: Any = None
        self._im: Any = None

    def show(self, model: GaitModel, trail: Sequence[tuple[int, tuple[int, ...]]],
             turn_deg: float, regrasps: int) -> None:
        """Draw the frame (as :func:`render_frame`) and show it in a matplotlib window,
        reusing the window between calls; without a display, warn once and draw nothing."""
        if not can_show():
            if not self.warned:
                self.warned = True
                import gymnasium as gym
                import matplotlib

                gym.logger.warn(
                    f"GraspGait render_mode='human': matplotlib backend "
                    f"{matplotlib.get_backend().lower()!r} cannot open a window (no display), "
                    "so nothing is shown; use render_mode='rgb_array'")
            return
        frame = render_frame(model, trail, turn_deg, regrasps)
        import matplotlib.pyplot as plt

        if self._fig is None or not plt.fignum_exists(self._fig.number):
            self._fig = plt.figure("GraspGait", figsize=_FIGSIZE)
            ax = self._fig.add_axes((0, 0, 1, 1))
            ax.set_axis_off()
            self._im = ax.imshow(frame)
        else:
            self._im.set_data(frame)
        self._fig.canvas.draw_idle()
        plt.pause(1.0 / self.render_fps)

    def close(self) -> None:
        """Close the window, if any (idempotent; never raises)."""
        fig, self._fig, self._im = self._fig, None, None
        if fig is not None:
            try:
                import matplotlib.pyplot as plt

                plt.close(fig)
            except Exception:  # noqa: BLE001 - closing must never fail
                pass

    def __getstate__(self) -> dict[str, Any]:
        return {"render_fps": self.render_fps, "warned": self.warned}

    def __setstate__(self, d: dict[str, Any]) -> None:
        self.__init__(d["render_fps"])
        self.warned = d["warned"]
