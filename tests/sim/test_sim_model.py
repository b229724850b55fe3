"""The MuJoCo model (thesis 7.2): builder, named elements, accessor, contact parameters."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from graspgait_env.objects import bundled_objects, load_object, load_object_physical
from graspgait_env.shapes import Polygon
from graspgait_env.sim.config import load_sim_config
from graspgait_env.sim.executor import GaitExecutor
from graspgait_env.sim.model import HandPhysics, build_model, prism_inertia

CFG = load_sim_config()


def _build(name: str, mu: float = 0.7):
    shape, phys = load_object_physical(name)
    return build_model(shape, mu=mu, thickness=phys["thickness"], mass=phys["mass"], config=CFG)


@pytest.mark.parametrize("name", bundled_objects())
def test_every_bundled_object_builds_and_rests_on_the_table(name):
    sim = _build(name)
    p = HandPhysics(sim)
    p.reset()
    p.step(300)
    x, y, th = p.object_pose()
    assert abs(x) < 1e-4 and abs(y) < 1e-4 and abs(th) < 0.01
    assert p.object_height() == pytest.approx(sim.thickness / 2, abs=5e-4)
    assert p.object_tilt_deg() < 0.1
    assert not p.tip_in_contact().any()
    m = sim.model
    assert m.body("object").mass[0] == pytest.approx(sim.mass)


def test_every_element_is_named():
    m = _build("star").model
    kinds = [(m.nbody, m.body), (m.ngeom, m.geom), (m.njnt, m.joint), (m.nu, m.actuator),
             (m.nsensor, m.sensor), (m.nsite, m.site), (m.ncam, m.camera),
             (m.nlight, m.light), (m.nmesh, m.mesh), (m.npair, m.pair)]
    for n, get in kinds:
        for i in range(n):
            assert get(i).name, f"unnamed {get.__name__} {i}"


def test_options_come_from_the_config():
    m = _build("ellipse").model
    assert m.opt.timestep == CFG.timestep
    assert m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert m.opt.impratio == CFG.impratio
    assert m.opt.noslip_iterations == CFG.noslip_iterations
    assert m.pair("finger1_object_rim").friction[0] == pytest.approx(0.7)
    assert m.pair("table_object_piece0").friction[0] == pytest.approx(CFG.table_mu)
    np.testing.assert_allclose(m.pair("finger2_object_rim").solref, CFG.finger_solref)
    assert m.geom("finger3_tip").size[0] == pytest.approx(CFG.tip_radius)


def test_shapes_become_the_right_pieces():
    assert _build("circle").pieces == ("object_piece0",)
    assert _build("ellipse").pieces == ("object_rim",)  # exact ellipse for the fingers
    assert _build("pentagon").pieces == ("object_piece0",)  # convex: one mesh
    star = load_object("star")
    assert isinstance(star, Polygon)
    assert len(_build("star").pieces) == len(star.vertices)  # a fan of triangles


def test_homes_are_120_degrees_apart_at_max_r():
    sim = _build("ellipse")
    a = np.degrees(np.arctan2(sim.home[:, 1], sim.home[:, 0])) % 360
    np.testing.assert_allclose(np.diff(a), [120, 120], atol=1e-9)
    np.testing.assert_allclose(np.hypot(sim.home[:, 0], sim.home[:, 1]),
                               1.5 * load_object("ellipse").r_max)
    assert sim.max_r == pytest.approx(1.5 * 0.1143)


def test_prism_inertia_matches_closed_forms():
    # square 2a x 2a, mass m: Izz = m (2a)^2 / 6; centroid at the origin
    a, m, h = 0.05, 0.2, 0.02
    sq = np.array([[a, a], [-a, a], [-a, -a], [a, -a]])
    c, full = prism_inertia(sq, m, h)
    np.testing.assert_allclose(c, [0, 0], atol=1e-15)
    assert full[2] == pytest.approx(m * (2 * a) ** 2 / 6)
    assert full[0] == pytest.approx(m * (2 * a) ** 2 / 12 + m * h**2 / 12)
    # an offset right triangle has its centroid at the mean of the vertices
    tri = np.array([[0.0, 0.0], [0.03, 0.0], [0.0, 0.06]]) + 0.01
    c, _ = prism_inertia(tri, m, h)
    np.testing.assert_allclose(c, tri.mean(axis=0))


def test_accessor_round_trips_by_name():
    sim = _build("pentagon")
    p = HandPhysics(sim)
    p.reset()
    np.testing.assert_allclose(p.tip_positions(), sim.home)
    assert p.tip_positions_flat() == pytest.approx(sim.home.ravel().tolist())
    p.set_object_pose(0.003, -0.002, 30.0)
    assert p.object_pose() == pytest.approx((0.003, -0.002, 30.0))
    p.set_finger_forces(np.arange(9.0).reshape(3, 3) / 10)
    np.testing.assert_allclose(p.finger_forces().ravel(), np.arange(9.0) / 10)
    p.set_tip_positions(sim.home + 0.01)
    np.testing.assert_allclose(p.tip_positions(), sim.home + 0.01)


def test_contact_sensor_reports_the_push_of_a_finger():
    """A finger pressed on the object: the sensor's net force equals the push (world frame)."""
    sim = _build("circle")
    p = HandPhysics(sim)
    p.reset()
    r = 0.0762 + CFG.tip_radius
    tips = sim.home.copy()
    tips[0, :2] = [r + 0.0005, 0.0]
    tips[1, :2] = [-r - 0.0005, 0.0]
    p.set_tip_positions(tips)
    f = np.zeros((3, 3))
    f[0, 0], f[1, 0] = -1.0, 1.0  # squeeze along x with 1 N
    f[:, 2] = 0.0
    for _ in range(300):
        p.set_finger_forces(f)
        p.step()
    assert p.tip_in_contact()[:2].all() and not p.tip_in_contact()[2]
    cf = p.tip_contact_forces()
    np.testing.assert_allclose(cf[0, :2], [-1.0, 0.0], atol=0.02)
    np.testing.assert_allclose(cf[1, :2], [1.0, 0.0], atol=0.02)


def test_grasp_holds_without_creep():
    """An ideal force-closure grasp (antipodal on the circle, 2 N grip, grip check off)
    under a steady tangential pull of 3 N (62% of the friction capacity): the contacts
    must not creep along the object (elliptic cone, impratio, solref of the config)."""
    cfg = load_sim_config(overrides={"grip_check": False})
    ex = GaitExecutor("circle", mu=0.7, config=cfg)
    assert ex.reset({1: 15.0, 2: 195.0}).ok
    t0 = ex.time
    u = (math.cos(math.radians(-75)), math.sin(math.radians(-75)))
    ex.set_disturbance(lambda t: (3.0 * min(1, (t - t0) / 0.3) * u[0],
                                  3.0 * min(1, (t - t0) / 0.3) * u[1]))
    assert ex.hold(0.5).ok
    a = ex.tips_in_object_frame()[:2].copy()
    assert ex.hold(2.0).ok
    b = ex.tips_in_object_frame()[:2]
    creep = np.linalg.norm(b - a, axis=1) / 2.0  # m/s
    assert creep.max() < 1e-4  # < 0.1 mm/s (measured 0.042 mm/s)
