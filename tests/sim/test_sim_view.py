"""The video's frames: HandView's overlays through the video camera, captions that follow
the plan's moves (``graspgait simulate --video``)."""

from __future__ import annotations

import numpy as np
import pytest

from graspgait_env.plan import Plan
from graspgait_env.sim.config import load_sim_config
from graspgait_env.sim.executor import GaitExecutor
from graspgait_env.sim.view import offscreen_rendering_available

pytestmark = pytest.mark.skipif(not offscreen_rendering_available(),
                                reason="no headless OpenGL (MUJOCO_GL=egl)")


class _Frames:
    """An imageio-like writer keeping the frames."""

    def __init__(self) -> None:
        self.frames: list[np.ndarray] = []

    def append_data(self, frame: np.ndarray) -> None:
        self.frames.append(frame)


def test_video_frames_carry_the_overlays_and_follow_the_moves():
    from graspgait_env.sim.simulate import VideoRecorder
    from graspgait_env.sim.view import FINGER_RGB

    cfg = load_sim_config(overrides={"video_fps": 8, "initial_probe": False})
    plan = Plan("circle", 0.7, [[0.0, 90.0], [120.0, 210.0], [240.0, 330.0]],
                [{"op": "grasp", "contacts": {"1": 15.0, "2": 195.0}},
                 {"op": "rotate", "delta": 30.0}])
    ex = GaitExecutor.for_plan(plan, config=cfg)
    out = _Frames()
    rec = VideoRecorder(ex, out, width=320, height=240, camera=cfg.video_camera, plan=plan)
    ex.frame_callback = rec
    ex.reset(plan.steps[0]["contacts"])
    assert rec.caption()[2] == "grasp (moves: 1)"
    n_grasp = rec.frames
    rec.move = 1
    assert ex.execute(plan.steps[1]).ok
    assert rec.caption()[:3] == [f"circle: plan mu=0.7, finger mu={ex.mu:g}",
                                 f"theta={ex.theta_true:.1f} deg (true) of 30",
                                 "move 1 of 1: rotate"]
    rec.close()
    assert 0 < n_grasp < rec.frames == len(out.frames)  # frames during both moves
    f = out.frames[-1]
    assert f.shape == (240, 320, 3)
    # finger 1's workspace arc, seen through the video camera, in finger 1's colour
    view = rec.view
    mid = np.radians(45.0)
    c, r = view.project(np.array([[view.ring_radius * np.cos(mid),
                                   view.ring_radius * np.sin(mid),
                                   ex.sim.thickness / 2]]))[0].round().astype(int)
    assert np.abs(f[r, c].astype(int) - np.array(FINGER_RGB[0])).max() < 70, f[r, c]
