"""Frames of the GraspGait environments (matplotlib on an off-screen Agg canvas, blitted).

Left panel: the object in the workspace frame ``F`` at its present angle θ, the three
finger workspaces as coloured arcs, the holding fingers as filled dots on their
contacts and the free finger as a ring at the middle of its workspace. Right panel:
the extended grasp map (object frame, thesis fig. 3.3) with the finger pair boxes at
the present θ (thesis figs. 4.5, 6.1) and the gait so far as a path of grasps,
unwrapped so that it climbs the extended map as the object turns.

:class:`GaitFrames` draws the parts that never change for a gait model (the axes, the
workspaces, the extended map, the legend) once, keeps that picture, and for each frame
restores it and draws only the changing artists on top (matplotlib's blitting): the
object, the fingers, the boxes at θ, the gait so far and the titles. A frame costs a
few milliseconds instead of a full figure draw (measured by ``graspgait perf``: the
``GraspGait-v0 frames/s`` row). The layout is fixed once, from a title of the longest
form, so a frame depends only on the state drawn, never on the frames drawn before.

:func:`render_frame` draws from plain data (the gait model, the gait so far, the turn
asked for, the regrasps made), never from an env's attributes; :class:`GaitRenderer`,
owned by the env, keeps what lives between frames (the human-mode window, the
"cannot show" warning). Nothing here touches pyplot except :meth:`GaitRenderer.show`,
which needs a window.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Polygon as PolygonPatch
from numpy.typing import NDArray

from graspgait_env.plotting import BOX_COLORS, extended_box_rects, plot_extended_map
from graspgait_env.shapes import Polygon

if TYPE_CHECKING:
    from matplotlib.artist import Artist

    from graspgait_env.gait import GaitModel

__all__ = ["render_frame", "can_show", "GaitRenderer", "GaitFrames", "FINGER_COLORS",
           "FRAME_SIZE"]

FINGER_COLORS = ("tab:red", "tab:green", "tab:blue")  # fingers 1, 2, 3
FRAME_SIZE = (640, 480)  # (px) width, height of a frame: GraspGaitMujoco-v1's size too
_DPI = 72
_FIGSIZE = (FRAME_SIZE[0] / _DPI, FRAME_SIZE[1] / _DPI)  # (inches)
_SPAN = 720.0  # (deg) the extended map's side
_LEGEND_TITLE = "box a-b: pairs fingers a (x) and b (y) both reach at the present theta"


def _outline(shape) -> NDArray[np.float64]:
    if isinstance(shape, Polygon):
        v = shape.vertices
        return np.vstack([v, v[:1]])
    return shape.contour_point(np.linspace(0.0, 360.0, 361))


def _rot(xy: NDArray[np.float64], theta_deg: float) -> NDArray[np.float64]:
    t = math.radians(theta_deg)
    c, s = math.cos(t), math.sin(t)
    return xy @ np.array([[c, s], [-s, c]])


def _hand_title(model: GaitModel, theta: float, turn_deg: float, regrasps: int) -> str:
    return (f"{model.shape.name}, mu={model.mu:.3g}: theta={theta:g} deg of "
            f"{turn_deg:g}, {regrasps} regrasps")


def _trail_points(model: GaitModel, trail: Sequence[tuple[int, tuple[int, ...]]]
                  ) -> NDArray[np.float64]:
    """The gait so far as points of the extended map (deg), the present grasp last and
    inside ``[0, 720)²``: finger on the horizontal axis, finger on the vertical axis."""
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
    p -= 360.0 * math.floor(p[-1].min() / 360.0)  # the present grasp inside [0, 720)²
    return p


class GaitFrames:
    """Frames of one gait model, blitted over a cached picture of what never changes.

    Frames are ``FRAME_SIZE`` = 640 x 480 px, ``(480, 640, 3)`` uint8 RGB. The cached
    picture is made at the first :meth:`frame` (a full draw, ~0.1 s); each frame then
    costs a few ms. Pickling drops the canvas (it is rebuilt on the next frame).

    Parameters
    ----------
    model
        The gait model (object, friction, hand, grid) whose states are drawn.
    """

    def __init__(self, model: GaitModel) -> None:
        self.model = model
        self._canvas: FigureCanvasAgg | None = None

    def _build(self) -> None:
        model = self.model
        shape, r = model.shape, model.shape.r_max
        fig = Figure(figsize=_FIGSIZE, dpi=_DPI, layout="constrained")
        canvas = FigureCanvasAgg(fig)
        ax_h, ax_m = fig.subplots(1, 2, width_ratios=[1.0, 1.15])
        # hand panel, fixed: the workspaces and the finger numbers
        ring = 1.3 * r
        self._rest = []  # (x, y) of each finger's ring when it is free
        for f, (lo, hi) in enumerate(model.hand.workspaces_deg):
            a = np.radians(np.linspace(lo, hi, 60))
            ax_h.plot(ring * np.cos(a), ring * np.sin(a), color=FINGER_COLORS[f], lw=4,
                      alpha=0.45, solid_capstyle="butt")
            mid = math.radians(0.5 * (lo + hi))
            ax_h.text(1.48 * r * math.cos(mid), 1.48 * r * math.sin(mid), str(f + 1),
                      color=FINGER_COLORS[f], ha="center", va="center", fontsize=11,
                      fontweight="bold")
            self._rest.append((ring * math.cos(mid), ring * math.sin(mid)))
        lim = 1.65 * r
        ax_h.set_xlim(-lim, lim)
        ax_h.set_ylim(-lim, lim)
        ax_h.set_aspect("equal")
        ax_h.set_xticks([])
        ax_h.set_yticks([])
        # hand panel, changing: the object, its x axis, the fingers, the title
        self._outline = _outline(shape)
        self._body = PolygonPatch(self._outline, closed=True, color="0.88", zorder=0)
        ax_h.add_patch(self._body)
        (self._edge,) = ax_h.plot([], [], color="k", lw=1.2)
        (self._mark,) = ax_h.plot([], [], color="0.4", lw=0.8, ls="--")
        self._dots = [ax_h.plot([], [], "o", color=c, ms=11, mec="k")[0] for c in FINGER_COLORS]
        self._rings = [ax_h.plot([], [], "o", mfc="none", mec=c, ms=11, mew=2)[0]
                       for c in FINGER_COLORS]
        # the layout is made for a title of the longest form, whatever the state
        widest = _hand_title(model, -99999.0, -99999.0, 99999)
        ax_h.set_title(widest, fontsize=9)
        # map panel, fixed: the extended map, its axes and legend, without the boxes
        plot_extended_map(ax_m, model.grasp_map, model.hand, 0.0, box_labels=False,
                          title="extended grasp map, gait so far")
        for p in [p for p in ax_m.patches if str(p.get_gid()).startswith("box ")]:
            p.remove()
        ax_m.get_legend().get_title().set_text(_LEGEND_TITLE)
        ax_m.tick_params(labelsize=7)
        ax_m.xaxis.label.set_fontsize(8)
        ax_m.yaxis.label.set_fontsize(8)
        # map panel, changing: the finger pair boxes at theta (one outline per kind)
        self._box_lines = {
            kind: ax_m.plot([], [], "-", color=color, lw=1.2, solid_joinstyle="miter")[0]
            for kind, color in BOX_COLORS.items()}
        self._sprites: dict[tuple[str, str], NDArray[np.float32]] = {}
        # map panel, changing: the gait so far
        (self._path,) = ax_m.plot([], [], "-", color="tab:orange", lw=1.2)
        (self._grasps,) = ax_m.plot([], [], ".", color="tab:orange", ms=4)
        (self._now,) = ax_m.plot([], [], "x", color="tab:orange", ms=10, mew=2.5)
        canvas.draw()  # lays the figure out once
        fig.set_layout_engine("none")
        self._changing: list[Artist] = [self._body, self._edge, self._mark, *self._dots,
                                        *self._rings, ax_h.title, self._path, self._grasps,
                                        self._now]
        for a in [*self._changing, *self._box_lines.values()]:
            a.set_animated(True)
        canvas.draw()
        self._background = canvas.copy_from_bbox(fig.bbox)
        self._height = int(fig.bbox.height)
        x0, y0, x1, y1 = ax_m.bbox.extents  # the map axes in pixels: labels clip to it
        self._clip = (int(round(self._height - y1)), int(round(self._height - y0)),
                      int(round(x0)), int(round(x1)))
        self._fig, self._canvas, self._ax_h, self._ax_m = fig, canvas, ax_h, ax_m

    def _label_sprite(self, text: str, kind: str) -> NDArray[np.float32]:
        """A box label (``"1-3"`` in the box's colour on a translucent white box, as
        :func:`~graspgait_env.plotting.plot_extended_map` writes it) as an ``(h, w, 4)``
        float RGBA image, rendered once with matplotlib and kept: pasting it costs far
        less than drawing the text each frame."""
        key = (text, kind)
        if key not in self._sprites:
            fig = Figure(figsize=(1.0, 0.5), dpi=_DPI, facecolor="none")
            canvas = FigureCanvasAgg(fig)
            fig.text(0.5, 0.5, text, color=BOX_COLORS.get(kind, "k"), fontsize=7,
                     ha="center", va="center",
                     bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                           "alpha": 0.7})
            canvas.draw()
            rgba = np.asarray(canvas.buffer_rgba()).astype(np.float32) / 255.0
            rows = np.flatnonzero(rgba[..., 3].any(axis=1))
            cols = np.flatnonzero(rgba[..., 3].any(axis=0))
            self._sprites[key] = rgba[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1].copy()
        return self._sprites[key]

    def _paste(self, labels: list[tuple[NDArray[np.float32], float, float]]) -> None:
        """Alpha-blend label sprites, centred on ``(column, row)`` pixels, into the
        canvas's buffer, clipped to the map axes."""
        buf = np.asarray(self._canvas.buffer_rgba())
        r_lo, r_hi, c_lo, c_hi = self._clip
        for sprite, col, row in labels:
            h, w = sprite.shape[:2]
            r0, c0 = int(round(row - h / 2)), int(round(col - w / 2))
            a0, b0 = max(r0, r_lo), max(c0, c_lo)
            a1, b1 = min(r0 + h, r_hi), min(c0 + w, c_hi)
            if a1 <= a0 or b1 <= b0:
                continue
            sp = sprite[a0 - r0:a1 - r0, b0 - c0:b1 - c0]
            alpha = sp[..., 3:]
            dst = buf[a0:a1, b0:b1, :3]
            dst[...] = (dst * (1.0 - alpha) + 255.0 * sp[..., :3] * alpha + 0.5).astype(np.uint8)

    def frame(self, trail: Sequence[tuple[int, tuple[int, ...]]], turn_deg: float,
              regrasps: int) -> NDArray[np.uint8]:
        """Draw a gait state; returns a new ``(480, 640, 3)`` uint8 RGB array.

        Parameters
        ----------
        trail
            The gait so far as ``(k, contacts)`` pairs, the present state last (at
            least one): ``k`` the object angle in grid steps, ``contacts`` the contact
            index of each finger (-1 for the free finger).
        turn_deg
            The requested turn (degrees), for the title.
        regrasps
            Regrasps made so far, for the title.
        """
        if self._canvas is None:
            self._build()
        model = self.model
        k, cs = trail[-1]
        theta = k * model.step_deg
        r = model.shape.r_max
        xy = _rot(self._outline, theta)
        self._body.set_xy(xy)
        self._edge.set_data(xy[:, 0], xy[:, 1])
        mark = _rot(np.array([[0.0, 0.0], [0.8 * r, 0.0]]), theta)  # the object's x axis
        self._mark.set_data(mark[:, 0], mark[:, 1])
        for f in range(3):
            c = cs[f]
            held = c >= 0
            if held:
                p = _rot(model.shape.contour_point(model.contact_deg(c))[None, :], theta)[0]
                self._dots[f].set_data([p[0]], [p[1]])
            else:
                self._rings[f].set_data([self._rest[f][0]], [self._rest[f][1]])
            self._dots[f].set_visible(held)
            self._rings[f].set_visible(not held)
        self._ax_h.set_title(_hand_title(model, theta, turn_deg, regrasps), fontsize=9)
        p = _trail_points(model, trail)
        self._path.set_data(p[:, 0], p[:, 1])
        self._grasps.set_data(p[:-1, 0], p[:-1, 1])
        self._now.set_data(p[-1:, 0], p[-1:, 1])

        canvas, ax_m = self._canvas, self._ax_m
        canvas.restore_region(self._background)
        for a in self._changing[:-3]:  # the hand panel's, the title included
            self._ax_h.draw_artist(a)
        boxes = {kind: [] for kind in self._box_lines}  # outlines at theta, NaN-separated
        labels = []  # (sprite, column, row) of each visible box label
        to_px = ax_m.transData.transform
        for box, x0, y0 in extended_box_rects(model.hand, theta, _SPAN):
            w = box.x_deg[1] - box.x_deg[0]
            h = box.y_deg[1] - box.y_deg[0]
            boxes.setdefault(box.kind, []).append(
                [(x0, y0), (x0 + w, y0), (x0 + w, y0 + h), (x0, y0 + h), (x0, y0),
                 (np.nan, np.nan)])
            cx, cy = x0 + w / 2, y0 + h / 2
            if 0.0 < cx < _SPAN and 0.0 < cy < _SPAN:
                sprite = self._label_sprite(f"{box.finger_x}-{box.finger_y}", box.kind)
                px, py = to_px((cx, cy))
                labels.append((sprite, px, self._height - py))
        for kind, line in self._box_lines.items():
            xy = np.array(boxes[kind], dtype=float).reshape(-1, 2) if boxes[kind] else \
                np.empty((0, 2))
            line.set_data(xy[:, 0], xy[:, 1])
            ax_m.draw_artist(line)
        if labels:
            self._paste(labels)
        for a in self._changing[-3:]:
            ax_m.draw_artist(a)
        canvas.blit(self._fig.bbox)
        return np.asarray(canvas.buffer_rgba())[..., :3].copy()

    def __getstate__(self) -> dict[str, Any]:
        return {"model": self.model}

    def __setstate__(self, d: dict[str, Any]) -> None:
        self.__init__(d["model"])


def render_frame(model: GaitModel, trail: Sequence[tuple[int, tuple[int, ...]]],
                 turn_deg: float, regrasps: int) -> NDArray[np.uint8]:
    """Draw a gait state; returns an ``(480, 640, 3)`` uint8 RGB array.

    A one-off :class:`GaitFrames` (its first frame is a full draw, ~0.1 s); to draw many
    frames of one model keep a :class:`GaitFrames` and call :meth:`GaitFrames.frame`.

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
    return GaitFrames(model).frame(trail, turn_deg, regrasps)


def can_show() -> bool:
    """True when matplotlib's backend can open a window (an interactive backend)."""
    import matplotlib
    from matplotlib.backends import BackendFilter, backend_registry

    backend = matplotlib.get_backend().lower()
    return backend not in backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE)


class GaitRenderer:
    """What a GraspGait env keeps between frames: the human-mode window and the warning.

    Pickling and ``copy.deepcopy`` drop the window (a matplotlib figure does not
    pickle); the next :meth:`show` opens a new one.

    Parameters
    ----------
    render_fps
        Frames per second of human mode (each :meth:`show` pauses ``1 / render_fps`` s).
    """

    def __init__(self, render_fps: float) -> None:
        self.render_fps = float(render_fps)
        self.warned = False  # the "cannot show" warning is given once per renderer
        self._fig: Any = None
        self._im: Any = None

    def show(self, draw: Callable[[], NDArray[np.uint8]]) -> None:
        """Show the frame that ``draw()`` returns (an ``(H, W, 3)`` uint8 RGB array) in a
        matplotlib window, reusing the window between calls, and pause ``1 /
        render_fps`` s; without a display, warn once and call nothing."""
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
        frame = draw()
        import matplotlib.pyplot as plt

        if self._fig is None or not plt.fignum_exists(self._fig.number):
            h, w = frame.shape[:2]
            self._fig = plt.figure("GraspGait", figsize=(w / _DPI, h / _DPI))
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
