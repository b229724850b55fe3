"""The object localizer (thesis 7.4.5): error function, weights, grown contour, convergence.

Tips are made the way the hand makes them: a ball of the tip radius touching the object
at contour angle ``phi`` has its centre at ``contour_point(phi) + rho * outward_normal``,
placed in frame F by the true pose. The contact sets are chosen off the exact 120° symmetry,
which hides rotation (see ``test_three_fingers_exactly_120_apart_hide_rotation``).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from graspgait_env.objects import load_object
from graspgait_env.shapes import Circle, Ellipse, Polygon
from graspgait_env.sim.localizer import (
    GrownContour,
    LocalizerConfig,
    ObjectLocalizer,
    curvature_weights,
    finger_radius_errors,
    localize,
    pose_error,
    tips_in_object_frame,
    wrap_deg,
)

RHO = LocalizerConfig().tip_radius
# contact angles (deg, object frame): a near-antipodal pair and a third finger between
CONTACTS = {
    "circle": (30.0, 150.0, 270.0),
    "ellipse": (69.0, 242.0, 357.0),
    "pentagon": (99.0, 176.0, 332.0),
    "hexagon": (14.0, 104.0, 202.0),
}
THESIS_OBJECTS = list(CONTACTS)


def make_tips(shape, pose, phis_deg, rho=RHO):
    """Centres (m, frame F) of ball tips touching ``shape`` at ``phis_deg`` at ``pose``."""
    phis = np.asarray(phis_deg, dtype=float)
    q = shape.contour_point(phis) - rho * shape.inward_normal(phis)
    t = math.radians(pose[2])
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    return q @ rot.T + np.asarray(pose[:2])


def offset_pose(rng, expected, dist=0.006, dtheta=5.0):
    """The expected pose moved ``dist`` (m) in a random direction and +/-``dtheta`` deg."""
    a = rng.uniform(0.0, 2.0 * math.pi)
    return np.asarray(expected) + [dist * math.cos(a), dist * math.sin(a),
                                   dtheta * rng.choice([-1.0, 1.0])]


def pos_err(pose, true):
    return math.hypot(pose[0] - true[0], pose[1] - true[1])


# --------------------------------------------------------------------------- config


def test_config_defaults_are_the_thesis_values_in_si():
    cfg = LocalizerConfig()
    assert cfg.tip_radius == pytest.approx(0.307 * 0.0254)   # 7.8 mm ball (thesis 7.2)
    assert cfg.allowable_error == pytest.approx(0.00635)     # 1/4 in (thesis 7.5)


@pytest.mark.parametrize("field,value", [
    ("tip_radius", -0.001), ("allowable_error", 0.0), ("step_xy", float("nan")),
    ("grid_half_width", 0), ("max_iterations", 1.5), ("max_weight", 1.0),
    ("angle_scale", -1.0), ("prior_weight", -1e-6), ("step_deg", True),
])
def test_config_refuses_bad_values_naming_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        LocalizerConfig(**{field: value})


# --------------------------------------------------------------------------- pieces


def test_curvature_weights_on_a_quadratic():
    # E = a x^2 sampled at 0, +h, -h: d2E/dx2 = 2a exactly, W = 1 / (1 + 2a)
    for a, h in [(0.5, 1e-3), (1.5, 2e-3), (10.0, 0.1)]:
        w = curvature_weights(0.0, a * h * h, a * h * h, h)
        np.testing.assert_allclose(w, 1.0 / (1.0 + 2.0 * a), rtol=1e-12)
    # vectorized per coordinate; flat -> 1 (keep the old value); concave counts as flat
    w = curvature_weights(1.0, [1.0, 0.0, 2.0], [1.0, 0.0, 2.0], [1.0, 1.0, 1.0])
    np.testing.assert_allclose(w, [1.0, 1.0, 1.0 / 3.0])


def test_tips_in_object_frame_by_hand():
    # object at (1, 2) turned 90 deg: the F point (1, 3) is 1 m along the object's x axis
    q = tips_in_object_frame([[1.0, 3.0], [0.0, 2.0]], [1.0, 2.0, 90.0])
    np.testing.assert_allclose(q, [[1.0, 0.0], [0.0, 1.0]], atol=1e-12)
    # vectorized over poses: (K, 3) -> (K, m, 2)
    assert tips_in_object_frame([[0.0, 0.0]] * 3, np.zeros((4, 3))).shape == (4, 3, 2)


def test_wrap_deg():
    np.testing.assert_allclose(wrap_deg([0.0, 190.0, -190.0, 720.0 + 5.0]), [0, -170, 170, 5])


def test_grown_circle_is_the_circle_plus_the_tip_radius():
    g = GrownContour(Circle(0.05), 0.0078)
    np.testing.assert_allclose(g.radius_deg(np.linspace(-180, 180, 37)), 0.0578, atol=1e-12)
    # point fingers: the shape's own radial function
    e = Ellipse(0.09, 0.06)
    phi = np.linspace(-180, 180, 73)
    np.testing.assert_allclose(GrownContour(e, 0.0).radius_deg(phi), e.radius(phi))


def test_grown_square_edges_and_corners_by_hand():
    half, rho = 0.05, 0.01
    sq = Polygon([[half, half], [-half, half], [-half, -half], [half, -half]])
    g = GrownContour(sq, rho)
    # the right edge grows to the line x = half + rho
    phi = np.array([0.0, 20.0, 35.0])
    np.testing.assert_allclose(g.radius_deg(phi), (half + rho) / np.cos(np.radians(phi)),
                               atol=1e-6)
    # the corner grows to an arc of radius rho about the vertex: along the diagonal
    np.testing.assert_allclose(g.radius_deg(45.0), half * math.sqrt(2) + rho, atol=1e-6)


@pytest.mark.parametrize("name", THESIS_OBJECTS)
def test_ball_tip_centres_lie_on_the_grown_contour(name):
    shape = load_object(name)
    phi = np.linspace(-179.9, 179.9, 3001)
    phi = phi[~shape.is_vertex(phi)]
    q = shape.contour_point(phi) - RHO * shape.inward_normal(phi)
    grown = GrownContour(shape, RHO)
    err = np.hypot(q[:, 0], q[:, 1]) - grown.radius_deg(np.degrees(np.arctan2(q[:, 1], q[:, 0])))
    assert np.max(np.abs(err)) < 1e-6


def test_radius_errors_by_hand_on_a_circle():
    # point fingers on a circle of radius R at (0, 0); the trial frame is moved by d along x:
    # the finger at (R, 0) is at R - d from the trial centre, the one at (-R, 0) at R + d
    R, d = 0.05, 0.002
    tips = [[R, 0.0], [-R, 0.0], [0.0, R]]
    e = finger_radius_errors(Circle(R), tips, [d, 0.0, 0.0])
    np.testing.assert_allclose(e, [-d, d, math.hypot(R, d) - R], atol=1e-15)


@pytest.mark.parametrize("name", THESIS_OBJECTS)
def test_error_is_zero_at_the_true_pose_and_grows_away_from_it(name):
    shape = load_object(name)
    true = (0.004, -0.003, 25.0)
    tips = make_tips(shape, true, CONTACTS[name])
    assert pose_error(shape, tips, true, RHO) < 1e-12
    for axis, steps in ((0, [1e-4, 5e-4, 2e-3]), (1, [1e-4, 5e-4, 2e-3]),
                        (2, [0.1, 0.5, 2.0])):
        if name == "circle" and axis == 2:
            continue  # a circle's rotation changes nothing
        for sign in (1.0, -1.0):
            poses = np.tile(true, (3, 1))
            poses[:, axis] += sign * np.array(steps)
            err = pose_error(shape, tips, poses, RHO)
            assert np.all(np.diff(err) > 0) and err[0] > 1e-12


def test_error_is_vectorized_over_trial_poses():
    shape = load_object("hexagon")
    tips = make_tips(shape, (0.0, 0.0, 10.0), CONTACTS["hexagon"])
    poses = np.random.default_rng(0).normal(0.0, [0.003, 0.003, 4.0], size=(5, 4, 3))
    grid = pose_error(shape, tips, poses, RHO)
    assert grid.shape == (5, 4)
    one = [pose_error(shape, tips, p, RHO) for p in poses.reshape(-1, 3)]
    np.testing.assert_allclose(grid.ravel(), one, rtol=1e-12)


def test_localizer_residuals_match_finger_radius_errors():
    shape = load_object("pentagon")
    loc = ObjectLocalizer(shape)
    tips = make_tips(shape, (0.002, 0.001, 3.0), CONTACTS["pentagon"])
    poses = [[0.0, 0.0, 0.0], [0.003, -0.002, 7.0]]
    np.testing.assert_allclose(loc.residuals(tips, poses),
                               finger_radius_errors(shape, tips, poses, RHO), atol=1e-15)


# --------------------------------------------------------------------------- convergence


@pytest.mark.parametrize("name", THESIS_OBJECTS)
def test_converges_from_6_mm_and_5_degrees_off(name):
    """Acceptance: three fingers, true pose 6 mm and 5 deg from the expected one."""
    shape = load_object(name)
    loc = ObjectLocalizer(shape)
    rng = np.random.default_rng(7)
    for _ in range(12):
        expected = np.array([rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01),
                             rng.uniform(-180.0, 180.0)])
        true = offset_pose(rng, expected)
        res = loc.localize(make_tips(shape, true, CONTACTS[name]), expected)
        assert res.converged
        assert pos_err(res.pose, true) < 1e-3
        if name == "circle":  # orientation unobservable: the expected angle is kept
            assert res.pose[2] == pytest.approx(expected[2], abs=1e-6)
            assert res.singular_values[2] < 1e-6
        else:
            assert abs(res.pose[2] - true[2]) < 1.0
            # exact data: in fact far tighter than the acceptance bound
            assert pos_err(res.pose, true) < 1e-5 and abs(res.pose[2] - true[2]) < 0.01
            assert res.orientation_error_deg == pytest.approx(true[2] - expected[2], abs=0.01)
        assert res.rms_error < 1e-6
        assert not res.recenter  # 6 mm is inside the 1/4 in allowable error


@pytest.mark.parametrize("name", THESIS_OBJECTS)
def test_tip_noise_of_0_2_mm(name):
    """Gaussian noise of 0.2 mm on each tip coordinate: within 1.5 mm and 1.5 deg."""
    shape = load_object(name)
    loc = ObjectLocalizer(shape)
    rng = np.random.default_rng(11)
    worst_pos = worst_deg = 0.0
    for _ in range(40):
        expected = np.array([0.0, 0.0, rng.uniform(-180.0, 180.0)])
        true = offset_pose(rng, expected)
        tips = make_tips(shape, true, CONTACTS[name]) + rng.normal(0.0, 2e-4, (3, 2))
        res = loc.localize(tips, expected)
        worst_pos = max(worst_pos, pos_err(res.pose, true))
        if name != "circle":
            worst_deg = max(worst_deg, abs(res.pose[2] - true[2]))
    assert worst_pos < 1.5e-3 and worst_deg < 1.5


def test_three_fingers_exactly_120_apart_hide_rotation():
    """At three equally spaced angles the second harmonic of an ellipse's r(phi) aliases
    onto the first (a translation): a small rotation looks like a shift. The smallest
    singular value of the residual Jacobian says so; the contact set used above does not
    suffer from it."""
    shape = load_object("ellipse")
    loc = ObjectLocalizer(shape)
    pose = (0.0, 0.0, 0.0)
    even = loc.localize(make_tips(shape, pose, (10.0, 130.0, 250.0)), pose)
    good = loc.localize(make_tips(shape, pose, CONTACTS["ellipse"]), pose)
    assert even.singular_values[2] < 0.05 < 0.2 < good.singular_values[2]


def test_two_fingers_fit_both_contacts_near_the_expected_pose():
    """Two fingers: two equations, three unknowns. Both contacts fit exactly; the pose
    along the curve of poses that fit is not observed and stays near the expected one."""
    shape = load_object("ellipse")
    loc = ObjectLocalizer(shape)
    rng = np.random.default_rng(3)
    s = loc.angle_scale * math.pi / 180.0  # (m per degree) theta as arc length
    for _ in range(8):
        expected = np.array([0.0, 0.0, rng.uniform(-180.0, 180.0)])
        true = offset_pose(rng, expected)
        res = loc.localize(make_tips(shape, true, (69.0, 242.0)), expected)
        assert np.max(np.abs(res.residuals)) < 1e-6
        assert res.singular_values[2] < 1e-6
        moved = math.hypot(math.hypot(*res.position_error), s * res.orientation_error_deg)
        assert moved <= 1.05 * math.hypot(0.006, s * 5.0)


def test_two_fingers_fix_a_circles_centre():
    shape = load_object("circle")
    rng = np.random.default_rng(5)
    for _ in range(8):
        expected = np.array([0.0, 0.0, 0.0])
        true = offset_pose(rng, expected)
        res = localize(shape, make_tips(shape, true, (30.0, 150.0)), expected)
        assert pos_err(res.pose, true) < 1e-5


def test_recenter_flag_and_orientation_error():
    shape = load_object("hexagon")
    loc = ObjectLocalizer(shape)
    expected = np.array([0.0, 0.0, 40.0])
    # 8 mm off: more than 1/4 in, the object must be recentred (thesis 7.5)
    far = expected + [0.008, 0.0, 3.0]
    res = loc.localize(make_tips(shape, far, CONTACTS["hexagon"]), expected)
    assert res.recenter
    np.testing.assert_allclose(res.position_error, [0.008, 0.0], atol=1e-5)
    assert res.orientation_error_deg == pytest.approx(3.0, abs=0.01)
    near = expected + [0.003, -0.002, -4.0]
    res = loc.localize(make_tips(shape, near, CONTACTS["hexagon"]), expected)
    assert not res.recenter
    assert res.orientation_error_deg == pytest.approx(-4.0, abs=0.01)


def test_theta_stays_continuous_with_the_expected_angle():
    shape = load_object("pentagon")
    expected = np.array([0.001, 0.0, 725.0])  # two turns into a gait
    true = expected + [0.0, 0.003, 4.0]
    res = localize(shape, make_tips(shape, true, CONTACTS["pentagon"]), expected)
    assert res.pose[2] == pytest.approx(729.0, abs=0.01)
    assert res.orientation_error_deg == pytest.approx(4.0, abs=0.01)


def test_thesis_single_step_is_a_lagged_filter():
    """One grid search and one blend (thesis literally): the estimate moves toward the
    true pose but, weighted by W_i = 1 / (1 + d2E/di2), not all the way."""
    shape = load_object("ellipse")
    expected = np.array([0.0, 0.0, 0.0])
    true = expected + [0.002, -0.002, 2.0]
    tips = make_tips(shape, true, CONTACTS["ellipse"])
    one = localize(shape, tips, expected,
                   LocalizerConfig(max_iterations=1, gauss_newton=False))
    assert not one.converged and one.iterations == 1
    assert 0.0 < min(one.weights) and max(one.weights) < 1.0
    before = pose_error(shape, tips, expected, RHO)
    assert pose_error(shape, tips, one.pose, RHO) < before
    assert 1e-4 < pos_err(one.pose, true) < pos_err(expected, true)
    # without weighting the single step jumps to the grid minimum: the true pose here,
    # which lies on the grid (2 mm, 2 deg spacing)
    jump = localize(shape, tips, expected, LocalizerConfig(
        max_iterations=1, gauss_newton=False, curvature_weighting=False))
    np.testing.assert_allclose(jump.pose, true, atol=1e-9)


def test_grid_search_alone_converges_too():
    shape = load_object("hexagon")
    expected = np.array([0.0, 0.0, 10.0])
    true = expected + [0.004, 0.004, -4.0]
    res = localize(shape, make_tips(shape, true, CONTACTS["hexagon"]), expected,
                   LocalizerConfig(gauss_newton=False))
    assert res.converged
    assert pos_err(res.pose, true) < 1e-4 and abs(res.pose[2] - true[2]) < 0.05


def test_function_and_class_agree():
    shape = load_object("pentagon")
    tips = make_tips(shape, (0.003, 0.002, 4.0), CONTACTS["pentagon"])
    a = localize(shape, tips, (0.0, 0.0, 0.0))
    b = ObjectLocalizer(shape).localize(tips, (0.0, 0.0, 0.0))
    assert a.pose == b.pose and a.iterations == b.iterations


def test_input_errors():
    shape = load_object("ellipse")
    loc = ObjectLocalizer(shape)
    with pytest.raises(ValueError, match=r"\(m, 2\)"):
        loc.localize(np.zeros((3, 3)), (0, 0, 0))
    with pytest.raises(ValueError, match="at least 2 fingers"):
        loc.localize([[0.1, 0.0]], (0, 0, 0))
    with pytest.raises(ValueError, match="NaN"):
        loc.localize([[0.1, 0.0], [np.nan, 0.0]], (0, 0, 0))
    with pytest.raises(ValueError, match="theta_deg"):
        loc.localize([[0.1, 0.0], [-0.1, 0.0]], (0, 0))
    with pytest.raises(TypeError, match="Shape"):
        ObjectLocalizer("ellipse")


def test_speed():
    """One localization, three fingers, 6 mm / 5 deg off: typically 0.3-0.5 ms."""
    shape = load_object("ellipse")
    loc = ObjectLocalizer(shape)
    expected = np.array([0.0, 0.0, 30.0])
    tips = make_tips(shape, expected + [0.0042, 0.0042, 5.0], CONTACTS["ellipse"])
    loc.localize(tips, expected)
    times = []
    for _ in range(30):
        t0 = time.perf_counter()
        loc.localize(tips, expected)
        times.append(time.perf_counter() - t0)
    assert float(np.median(times)) < 5e-3  # generous: shared CI machines


def test_the_module_imports_no_physics():
    """Pure NumPy (map level): the module itself imports neither MuJoCo nor torch. (The
    ``graspgait_env.sim`` package's ``__init__`` may load MuJoCo on its own.)"""
    import ast

    import graspgait_env.sim.localizer as mod

    tree = ast.parse(open(mod.__file__, encoding="utf-8").read())
    names = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import)
             for a in n.names}
    names |= {n.module.split(".")[0] for n in ast.walk(tree)
              if isinstance(n, ast.ImportFrom) and n.module}
    assert names <= {"__future__", "math", "dataclasses", "functools", "numpy",
                     "graspgait_env"}
