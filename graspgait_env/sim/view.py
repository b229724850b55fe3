"""Frames of the simulated hand seen from above, with the gait overlaid (thesis 7.2, fig. 4.1).

:class:`HandView` renders a :class:`~graspgait_env.sim.model.HandPhysics` off-screen
(``MUJOCO_GL=egl`` headless; set it before MuJoCo is imported) and draws on the RGB
array:

- the three finger workspaces (thesis fig. 4.1) as arcs in the fingers' colours (finger
  1 red, 2 green, 3 blue) on a ring around the origin of frame ``F`` at the object's
  mid-height; the ring's radius is 1.25 times the object's largest radius, outside
  the object, so that the arcs never hide a contact;
- the fingertips in the same colours, each with its finger number beside it;
- caption lines given by the caller (the object angle, the move count, ...) in the
  upper left corner.

The arcs are projected once through the camera (they are fixed in ``F``) into a
cached coverage mask that each frame blends with NumPy; the numbers and captions are
drawn with Pillow's FreeType text (DejaVu Sans Bold, matplotlib's bundled font). The
default camera is a free camera straight above the workspace centre, ``x`` to the
right and ``y`` up (counter-clockwise angles read as in the thesis's figures),
framing the ring and the finger homes; a named MJCF camera (``"top"``,
``"overview"``) may be given instead, and the overlays are projected through it the
same way.

Shadows, reflections and multisampling are off: from straight above shadows and
reflections add nothing, and each of them and the MJCF's 4x multisampling halves the
frame rate on a CPU renderer (measured at 640 x 480 on this project's 2-core machine,
MuJoCo 3 under EGL/llvmpipe: the bare scene 54 frames/s with shadows and reflections,
111 without; the whole frame with overlays 21 frames/s with 4x multisampling, 40
without, the same load). The overlays are anti-aliased by their own rasterizer; the
edges of the bodies are not.

The GL context and MuJoCo's render context are kept across models whose MJCF is the
same (``GraspGaitMujoco-v1`` builds a fresh model at every reset from the same MJCF),
so a reset does not cost a new context (~0.15 s each here).
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Sequence
from functools import lru_cache
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from PIL import ImageFont

    from graspgait_env.sim.model import HandPhysics, SimModel

__all__ = ["HandView", "FINGER_RGB", "RING_FACTOR", "offscreen_rendering_available",
           "project_points"]

# fingers 1, 2, 3: matplotlib's tab:red, tab:green, tab:blue (the map-level frames' colours)
FINGER_RGB: tuple[tuple[int, int, int], ...] = ((214, 39, 40), (44, 160, 44), (31, 119, 180))
RING_FACTOR = 1.25  # workspace ring radius / the object's largest radius
_ARC_WIDTH_PX = 7  # (px) thickness of a workspace arc
_ARC_ALPHA = 0.75  # opacity of the arcs over the rendered scene
_MARGIN = 1.15  # the free camera frames this much more than the ring and the finger homes


@lru_cache(maxsize=4)
def _font(size: int) -> ImageFont.FreeTypeFont:
    from pathlib import Path

    import matplotlib
    from PIL import ImageFont

    path = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans-Bold.ttf"
    return ImageFont.truetype(str(path), size)


def _gl_context(width: int, height: int):
    """An off-screen OpenGL context: MuJoCo's choice (``MUJOCO_GL`` when MuJoCo was
    imported), except that GLFW without a display (MuJoCo imported before
    :mod:`graspgait_env.sim` could default ``MUJOCO_GL`` to ``egl``) becomes EGL."""
    cls = mujoco.GLContext
    headless = (sys.platform.startswith("linux") and not os.environ.get("DISPLAY")
                and not os.environ.get("WAYLAND_DISPLAY"))
    if headless and cls.__module__.startswith("mujoco.glfw"):
        from mujoco.egl import GLContext as cls  # noqa: N813 - MuJoCo's class name
    try:
        return cls(width, height)
    except Exception as e:  # noqa: BLE001 - say what to set, keep MuJoCo's reason
        raise RuntimeError(
            f"no OpenGL context for rendering ({cls.__module__}: {e}); headless, set "
            "MUJOCO_GL=egl (or osmesa) before MuJoCo is first imported") from e


def offscreen_rendering_available() -> bool:
    """Whether an off-screen OpenGL context opens here, as :class:`HandView` and
    ``mujoco.Renderer`` need (headless: ``MUJOCO_GL=egl`` or ``osmesa``)."""
    try:
        context = _gl_context(16, 16)
    except RuntimeError:
        return False
    context.free()
    return True


def project_points(camera: mujoco.MjvGLCamera | Sequence[mujoco.MjvGLCamera],
                   points: NDArray[np.float64], width: int, height: int
                   ) -> NDArray[np.float64]:
    """Pixel coordinates of world points seen through an OpenGL camera of a scene.

    Parameters
    ----------
    camera
        ``scene.camera`` after ``mjv_updateScene`` (its two eyes are averaged, as
        ``mjr_render`` does in mono mode), or one :class:`mujoco.MjvGLCamera`.
    points
        ``(N, 3)`` points (m, MuJoCo world frame = frame ``F``).
    width, height
        The image size (px); the frustum's half-width follows the aspect ratio, as in
        ``mjr_render``.

    Returns
    -------
    ndarray
        ``(N, 2)`` pixel coordinates ``(column, row)``, row 0 at the top of the image
        (the orientation of :class:`HandView`'s frames); points behind the camera get NaN.
    """
    cams = [camera] if isinstance(camera, mujoco.MjvGLCamera) else list(camera)
    pos = np.mean([np.asarray(c.pos, dtype=float) for c in cams], axis=0)
    c0 = cams[0]
    fwd = np.asarray(c0.forward, dtype=float)
    up = np.asarray(c0.up, dtype=float)
    right = np.cross(fwd, up)
    top, bottom = float(c0.frustum_top), float(c0.frustum_bottom)
    half_w = 0.5 * width / height * (top - bottom)
    centre = float(c0.frustum_center)
    v = np.asarray(points, dtype=float) - pos
    xc, yc, zc = v @ right, v @ up, v @ fwd
    if c0.orthographic:
        xs, ys = xc, yc
    else:
        near = float(c0.frustum_near)
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = np.where(zc > 0, near * xc / zc, np.nan)
            ys = np.where(zc > 0, near * yc / zc, np.nan)
    col = (xs - (centre - half_w)) / (2.0 * half_w) * width
    row = (top - ys) / (top - bottom) * height
    return np.stack([col, row], axis=1)


def _thick_polyline_mask(pts: NDArray[np.float64], width: int, height: int,
                         thickness: float) -> NDArray[np.float64]:
    """Coverage in [0, 1] of a polyline of ``thickness`` px (anti-aliased by 1 px),
    rasterized with NumPy: distance of each pixel near the line to its nearest segment."""
    cov = np.zeros((height, width))
    half = 0.5 * thickness
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        lo = np.floor(np.minimum(a, b) - half - 1).astype(int)
        hi = np.ceil(np.maximum(a, b) + half + 1).astype(int)
        c0, r0 = max(lo[0], 0), max(lo[1], 0)
        c1, r1 = min(hi[0], width - 1), min(hi[1], height - 1)
        if c1 < c0 or r1 < r0:
            continue
        cc, rr = np.meshgrid(np.arange(c0, c1 + 1) + 0.5, np.arange(r0, r1 + 1) + 0.5)
        d = b - a
        L2 = float(d @ d) or 1.0
        t = np.clip(((cc - a[0]) * d[0] + (rr - a[1]) * d[1]) / L2, 0.0, 1.0)
        dist = np.hypot(cc - (a[0] + t * d[0]), rr - (a[1] + t * d[1]))
        c = np.clip(half + 0.5 - dist, 0.0, 1.0)
        np.maximum(cov[r0:r1 + 1, c0:c1 + 1], c, out=cov[r0:r1 + 1, c0:c1 + 1])
    return cov


class HandView:
    """Off-screen frames of the simulated hand with the gait overlaid (see the module).

    Parameters
    ----------
    sim
        The compiled hand and object (:class:`~graspgait_env.sim.model.SimModel`):
        its workspaces, largest object radius, finger homes and mid-height.
    width, height
        Frame size (px); at most the MJCF's ``offwidth`` x ``offheight`` (1280 x 960).
    camera
        None: a free camera straight above the centre of frame ``F`` framing the
        workspace ring and the finger homes (``x`` right, ``y`` up); or the name of an
        MJCF camera (``"top"``, ``"overview"``).

    Notes
    -----
    Needs an OpenGL context: headless, set ``MUJOCO_GL=egl`` (or ``osmesa``) before
    MuJoCo is first imported. :meth:`close` frees the context (idempotent); the view
    does not pickle (an env drops it and makes a new one).
    """

    def __init__(self, sim: SimModel, *, width: int = 640, height: int = 480,
                 camera: str | None = None) -> None:
        from graspgait_env.errors import GraspGaitInputError

        m = sim.model
        for name, v, cap in (("width", width, m.vis.global_.offwidth),
                             ("height", height, m.vis.global_.offheight)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 16 <= v <= cap:
                raise GraspGaitInputError(
                    f"{name}={v!r}: the frame {name} must be an integer in 16..{cap} "
                    "(the MJCF's off-screen buffer), e.g. 640 x 480")
        if camera is not None and mujoco.mj_name2id(
                m, mujoco.mjtObj.mjOBJ_CAMERA, str(camera)) < 0:
            names = [m.camera(i).name for i in range(m.ncam)]
            raise GraspGaitInputError(
                f"camera={camera!r}: not a camera of the hand model; use None (straight "
                f"above) or one of {names}")
        self.width, self.height = int(width), int(height)
        self.camera = camera
        self._gl = _gl_context(self.width, self.height)
        self._gl.make_current()
        self._ctx: mujoco.MjrContext | None = None
        self._xml: str | None = None
        self._rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        self._opt = mujoco.MjvOption()
        self._pert = mujoco.MjvPerturb()
        self.use(sim)

    # ------------------------------------------------------------------ model
    def use(self, sim: SimModel) -> None:
        """Render ``sim`` from now on (a new episode's model). The render context is
        rebuilt only when the MJCF differs from the previous model's."""
        m = sim.model
        self._gl.make_current()
        if self._ctx is None or sim.xml != self._xml:
            if self._ctx is not None:
                self._ctx.free()
            quality = m.vis.quality
            kept = quality.offsamples
            quality.offsamples = 0  # no multisampling (see the module docstring)
            try:
                self._ctx = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_150)
            finally:
                quality.offsamples = kept  # the model is the caller's: left as it was
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._ctx)
            self._xml = sim.xml
        self.sim = sim
        self._scene = mujoco.MjvScene(m, maxgeom=1000)
        self._scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        self._scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self._tip_rgba = {m.geom(f"finger{f + 1}_tip").id: np.array([*rgb, 255]) / 255.0
                          for f, rgb in enumerate(FINGER_RGB)}
        self._cam = mujoco.MjvCamera()
        z = sim.thickness / 2.0  # the fingertips' and arcs' height: the object's mid-height
        self.ring_radius = RING_FACTOR * sim.shape.r_max
        if self.camera is None:
            reach = max(self.ring_radius, float(np.hypot(*sim.home[:, :2].T).max()))
            half = _MARGIN * (reach + 0.03)  # and room for the finger numbers
            fovy = math.radians(m.vis.global_.fovy)
            aspect_fit = max(1.0, self.height / self.width)  # the narrower side frames it
            self._cam.type = mujoco.mjtCamera.mjCAMERA_FREE
            self._cam.lookat[:] = (0.0, 0.0, z)
            self._cam.distance = aspect_fit * half / math.tan(0.5 * fovy)
            self._cam.azimuth = 90.0  # image up = +y
            self._cam.elevation = -90.0  # straight down
        else:
            self._cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
            self._cam.fixedcamid = m.camera(self.camera).id
        self._z = z
        self._arcs: tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]] | None = None

    def _update_scene(self, data: mujoco.MjData) -> None:
        mujoco.mjv_updateScene(self.sim.model, data, self._opt, self._pert, self._cam,
                               mujoco.mjtCatBit.mjCAT_ALL, self._scene)
        geom, tips = mujoco.mjtObj.mjOBJ_GEOM, self._tip_rgba
        for g in self._scene.geoms[:self._scene.ngeom]:  # the fingertips in their colours
            if g.objtype == geom and g.objid in tips:
                g.rgba[:] = tips[g.objid]

    def project(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Pixel ``(column, row)`` of world points (m, frame ``F``) in the last frame's
        camera (:func:`project_points`)."""
        return project_points(self._scene.camera, points, self.width, self.height)

    def _arc_overlay(self) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
        """The workspace arcs as (flat pixel indices, coverage, colours), made once per
        model: the arcs are fixed in frame F and the camera does not move."""
        if self._arcs is None:
            idx_all, cov_all, col_all = [], [], []
            taken = np.zeros(self.width * self.height, dtype=bool)
            for f, (lo, hi) in enumerate(self.sim.workspaces_deg):
                a = np.radians(np.linspace(lo, hi, max(8, int(abs(hi - lo) / 2) + 1)))
                pts = np.stack([self.ring_radius * np.cos(a), self.ring_radius * np.sin(a),
                                np.full(a.size, self._z)], axis=1)
                cov = _thick_polyline_mask(self.project(pts), self.width, self.height,
                                           _ARC_WIDTH_PX).ravel()
                idx = np.flatnonzero((cov > 0) & ~taken)  # overlapping arcs: the first wins
                taken[idx] = True
                idx_all.append(idx)
                cov_all.append(cov[idx] * _ARC_ALPHA)
                col_all.append(np.broadcast_to(np.asarray(FINGER_RGB[f], float),
                                               (idx.size, 3)))
            self._arcs = (np.concatenate(idx_all), np.concatenate(cov_all)[:, None],
                          np.concatenate(col_all))
        return self._arcs

    # ------------------------------------------------------------------ frames
    def render(self, physics: HandPhysics, lines: Sequence[str] = ()) -> NDArray[np.uint8]:
        """The hand now, with the overlays: a new ``(height, width, 3)`` uint8 RGB array.

        Parameters
        ----------
        physics
            The physics to draw (its model must be the one given to the constructor
            or :meth:`use`).
        lines
            Caption lines, drawn top left in black on a white outline (e.g. the
            object angle and the move count).
        """
        from PIL import Image, ImageDraw

        if physics.model is not self.sim.model:
            raise ValueError("HandView.render: physics of another model; call "
                             "view.use(physics.sim) first")
        self._gl.make_current()
        self._update_scene(physics.data)
        mujoco.mjr_render(self._rect, self._scene, self._ctx)
        mujoco.mjr_readPixels(self._rgb, None, self._rect, self._ctx)
        frame = np.flipud(self._rgb).copy()  # row 0 at the top
        flat = frame.reshape(-1, 3)
        idx, cov, col = self._arc_overlay()
        under = flat[idx].astype(np.float64)
        flat[idx] = (under + cov * (col - under) + 0.5).astype(np.uint8)
        pil = Image.fromarray(frame)
        draw = ImageDraw.Draw(pil)
        size = max(10, round(self.height / 26))
        font = _font(size)
        tips = physics.tip_positions()
        uv = self.project(tips)
        centre = self.project(np.array([[0.0, 0.0, self._z]]))[0]
        for f in range(3):  # the finger number beside its tip, away from the centre
            if not np.all(np.isfinite(uv[f])):
                continue
            d = uv[f] - centre
            d = d / (np.hypot(*d) or 1.0)
            at = uv[f] + d * 1.6 * size
            draw.text((float(at[0]), float(at[1])), str(f + 1), fill=FINGER_RGB[f], font=font,
                      anchor="mm", stroke_width=2, stroke_fill=(255, 255, 255))
        y = 0.4 * size
        for line in lines:
            draw.text((0.5 * size, y), line, fill=(0, 0, 0), font=font, stroke_width=2,
                      stroke_fill=(255, 255, 255))
            y += 1.3 * size
        return np.asarray(pil).copy()

    def close(self) -> None:
        """Free the render and GL contexts (idempotent; never raises)."""
        ctx, gl = getattr(self, "_ctx", None), getattr(self, "_gl", None)
        self._ctx = self._gl = None  # (a view whose constructor raised has neither)
        try:
            if ctx is not None and gl is not None:
                gl.make_current()
                ctx.free()
            if gl is not None:
                gl.free()
        except Exception:  # noqa: BLE001 - freeing must never fail
            pass

    def __del__(self) -> None:
        self.close()
