"""Frames of both envs: the map-level picture (blitted), the hand seen from above with its
overlays, RecordVideo on both, and rendering headless with nothing set by the user."""

from __future__ import annotations

import os
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

from graspgait_env.envs.render import FRAME_SIZE, GaitFrames, render_frame
from graspgait_env.sim.view import offscreen_rendering_available

PREFIX = "graspgait_env.envs:"




needs_gl = pytest.mark.skipif(not offscreen_rendering_available(),
                              reason="no headless OpenGL (MUJOCO_GL=egl)")


def _moves(env: gym.Env, n: int, seed: int = 0):
    """Reset, then up to ``n`` masked random moves; yields after the reset and each move."""
    rng = np.random.default_rng(seed)
    _, info = env.reset(seed=seed)
    yield info
    for _ in range(n):
        legal = np.flatnonzero(info["action_mask"])
        _, _, term, trunc, info = env.step(int(legal[rng.integers(legal.size)]))
        yield info
        if term or trunc:
            return


# ---------------------------------------------------------------------------- map level
def test_map_frames_are_640x480_and_each_equals_a_fresh_draw():
    """The blitted frames (cached background) equal a full draw of the same state: a
    frame depends only on the state drawn, not on the frames drawn before."""
    env = gym.make(PREFIX + "GraspGait-v0", object="pentagon", render_mode="rgb_array")
    u = env.unwrapped
    frames = []
    for i, _ in enumerate(_moves(env, 6)):
        f = env.render()
        assert f.shape == (FRAME_SIZE[1], FRAME_SIZE[0], 3) and f.dtype == np.uint8
        if i in (0, 3, 6):
            fresh = render_frame(u.model, u._trail, u.config.turn_deg, u._regrasps)
            np.testing.assert_array_equal(f, fresh)
        frames.append(f)
    assert not np.array_equal(frames[0], frames[-1])  # the state drawn changed


def test_map_frame_shows_the_boxes_and_their_labels_at_theta():
    """Box outlines and labels are drawn per frame (not in the cached background): the
    map panel differs between two angles, and the labels are pasted inside the map."""
    env = gym.make(PREFIX + "GraspGait-v0", object="ellipse", render_mode="rgb_array")
    u = env.unwrapped
    env.reset(seed=1)
    gf = GaitFrames(u.model)
    k, cs = u._trail[-1]
    a = gf.frame([(k, cs)], 360.0, 0)
    b = gf.frame([(k + 10, cs)], 360.0, 0)  # the same contacts, 10 grid steps on
    r0, r1, c0, c1 = gf._clip
    assert not np.array_equal(a[r0:r1, c0:c1], b[r0:r1, c0:c1])
    blue = np.array([31, 119, 180])  # tab:blue, the inner boxes (outline and label)
    assert (np.abs(a[r0:r1, c0:c1].astype(int) - blue).sum(axis=2) < 30).sum() > 50


# ---------------------------------------------------------------------------- the hand
@needs_gl
def test_mujoco_frame_is_the_hand_from_above_with_overlays():
    from graspgait_env.sim.view import FINGER_RGB

    env = gym.make(PREFIX + "GraspGaitMujoco-v1", object="ellipse", render_mode="rgb_array")
    env.reset(seed=0)
    u = env.unwrapped
    f = env.render()
    assert f.shape == (480, 640, 3) and f.dtype == np.uint8
    view = u._hand_view
    sim = u.executor.sim
    # the workspace arcs: the middle of each arc is drawn in its finger's colour
    for i, (lo, hi) in enumerate(sim.workspaces_deg):
        mid = np.radians(0.5 * (lo + hi))
        c, r = view.project(np.array([[view.ring_radius * np.cos(mid),
                                       view.ring_radius * np.sin(mid),
                                       sim.thickness / 2]]))[0].round().astype(int)
        px = f[r, c].astype(int)
        assert np.abs(px - np.array(FINGER_RGB[i])).max() < 70, (i, px)
    # each fingertip is drawn in its finger's colour (its link, rising from it, hides
    # the part of the ball away from the image centre)
    tips = view.project(u.executor.physics.tip_positions()).round().astype(int)
    for i, (c, r) in enumerate(tips):
        patch = f[r - 6:r + 7, c - 6:c + 7].reshape(-1, 3).astype(float)
        want = np.array(FINGER_RGB[i], float)
        assert np.linalg.norm(patch - want, axis=1).min() < 90, (i, patch.mean(axis=0))
    # the object: its centre is drawn in the object's colour (orange-yellow), not table grey
    c, r = view.project(np.array([[0.01, 0.01, sim.thickness]]))[0].round().astype(int)
    R, G, B = f[r, c].astype(int)
    assert R > 150 and G > 100 and B < 0.7 * R, f[r, c]
    # the captions: dark text in the upper left corner
    assert (f[:60, :300].sum(axis=2) < 150).sum() > 200
    # a rotation turns the object: the frame changes; the context is kept across resets
    legal = np.flatnonzero(env.unwrapped.action_masks())
    env.step(int(legal[0]))
    assert not np.array_equal(f, env.render())
    ctx = view._ctx
    env.reset(seed=1)
    env.render()
    assert u._hand_view is view and view._ctx is ctx
    env.close()
    assert u._hand_view is None
    env.close()  # idempotent


@needs_gl
def test_hand_view_projects_through_a_named_camera_and_refuses_bad_sizes():
    from graspgait_env.errors import GraspGaitInputError
    from graspgait_env.sim.executor import GaitExecutor
    from graspgait_env.sim.view import HandView

    ex = GaitExecutor("circle")
    ex.reset({"1": 15.0, "2": 195.0})  # a fixed camera's pose is known once physics ran
    view = HandView(ex.sim, width=320, height=240, camera="overview")
    f = view.render(ex.physics, ["a caption"])
    assert f.shape == (240, 320, 3)
    c, r = view.project(np.array([[0.0, 0.0, ex.sim.thickness]]))[0]
    assert 0 <= c < 320 and 0 <= r < 240  # the object's centre is in view
    view.close()
    view.close()
    with pytest.raises(GraspGaitInputError, match="width=5000"):
        HandView(ex.sim, width=5000)
    with pytest.raises(GraspGaitInputError, match="camera='side'"):
        HandView(ex.sim, camera="side")


# ---------------------------------------------------------------------------- RecordVideo
@pytest.mark.parametrize("env_id", ["GraspGait-v0",
                                    pytest.param("GraspGaitMujoco-v1", marks=needs_gl)])
def test_record_video_writes_an_episode(env_id, tmp_path):
    import imageio_ffmpeg
    from gymnasium.wrappers import RecordVideo

    env = gym.make(PREFIX + env_id, object="circle", render_mode="rgb_array",
                   max_episode_steps=6)
    assert env.metadata["render_fps"] == 4  # one frame per move, four moves a second
    env = RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda e: e == 0,
                      disable_logger=True)
    moves = sum(1 for _ in _moves(env, 6)) - 1
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 1000
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(videos[0]))
    assert frames == moves + 1  # the reset's frame and one per move


@needs_gl
def test_mujoco_env_renders_headless_with_nothing_set(tmp_path):
    """A user who sets neither MUJOCO_GL nor a display gets frames (EGL by default)."""
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY",
                                                             "PYOPENGL_PLATFORM")}
    code = ("import gymnasium as gym; "
            "e = gym.make('graspgait_env.envs:GraspGaitMujoco-v1', render_mode='rgb_array'); "
            "e.reset(seed=0); print(e.render().shape)")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, timeout=120, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("(480, 640, 3)")


@needs_gl
def test_mujoco_human_mode_shows_the_hand_once_it_holds_the_object(monkeypatch):
    """Human mode (a window faked on Agg): ``reset`` shows one frame, made after the
    grasp (not the map-level reset's, before the hand exists); each move shows one."""
    import matplotlib.pyplot as plt

    from graspgait_env.envs import render

    shown = []
    monkeypatch.setattr(render, "can_show", lambda: True)
    monkeypatch.setattr(plt, "pause", lambda s: shown.append(s))
    env = gym.make(PREFIX + "GraspGaitMujoco-v1", object="circle", render_mode="human")
    env.reset(seed=0)
    assert len(shown) == 1 and shown[0] == 1.0 / 4
    legal = np.flatnonzero(env.unwrapped.action_masks())
    env.step(int(legal[0]))
    assert len(shown) == 2
    im = env.unwrapped._renderer._im.get_array()
    assert im.shape == (480, 640, 3)
    env.close()
