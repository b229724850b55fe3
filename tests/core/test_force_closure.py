"""Force closure of two frictional point contacts (thesis 2.3, 3.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.force_closure import (
    cone_margin_deg,
    force_closure_nguyen,
    force_closure_wrench,
)
from graspgait_env.grasp_map import grid_angles_deg
from graspgait_env.objects import bundled_objects, load_object
from graspgait_env.shapes import Polygon

MUS = (0.1, 0.3, 0.5, 0.7, 0.9)
MARGIN_TOL_DEG = 1e-6  # cells this close to a friction-cone boundary may differ by rounding


def _grid_pairs(shape, n=180):
    phi = grid_angles_deg(n)
    P, N = shape.contour_point(phi), shape.inward_normal(phi)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    return P[i], N[i], P[j], N[j]


@pytest.mark.parametrize("name", bundled_objects())
def test_nguyen_and_wrench_agree_on_every_cell(name):
    """Both tests on all n² ordered pairs of grid contacts (diagonal and vertex contacts
    included: the tests take whatever normal they are given), every mu in MUS. Only cells
    whose |cone_margin_deg| < MARGIN_TOL_DEG = 1e-6° may differ; they are counted and must
    be few (at most 0.1 % of the cells)."""
    p1, n1, p2, n2 = _grid_pairs(load_object(name))
    for mu in MUS:
        a = force_closure_nguyen(p1, n1, p2, n2, mu)
        b = force_closure_wrench(p1, n1, p2, n2, mu)
        margin = cone_margin_deg(p1, n1, p2, n2, mu)
        near = np.abs(margin) < MARGIN_TOL_DEG
        assert near.sum() <= 0.001 * near.size, (name, mu, int(near.sum()))
        bad = (a != b) & ~near
        assert not bad.any(), (name, mu, np.argwhere(bad)[:5])
        # the margin's sign is the verdict away from the boundary
        far = ~near & np.isfinite(margin)
        np.testing.assert_array_equal(a[far], margin[far] > 0)
        assert a.any() or name in ("pentagon", "triangle")  # sanity: maps are not empty


# --------------------------------------------------------------------------- hand-made grasps

SQ = Polygon([[0.05, 0.05], [-0.05, 0.05], [-0.05, -0.05], [0.05, -0.05]])


@pytest.mark.parametrize("mu", [1e-6, 0.01, 0.1, 0.5, 2.0])
def test_antipodal_square_faces_stable_at_any_mu(mu):
    # the mirror image across the y axis (right/left faces) or x axis (top/bottom faces):
    # same height on the opposite face, so the segment runs along both normals
    phi1 = np.array([0.0, 20.0, -30.0, 90.0, 100.0, 60.0])
    phi2 = np.array([180.0, 160.0, 210.0, -90.0, -100.0, -60.0])
    np.testing.assert_allclose(SQ.contour_point(phi1) - SQ.contour_point(phi2),
                               [[0.1, 0], [0.1, 0], [0.1, 0], [0, 0.1], [0, 0.1], [0, 0.1]],
                               atol=1e-15)
    args = (SQ.contour_point(phi1), SQ.inward_normal(phi1),
            SQ.contour_point(phi2), SQ.inward_normal(phi2), mu)
    assert force_closure_nguyen(*args).all()
    assert force_closure_wrench(*args).all()
    np.testing.assert_allclose(cone_margin_deg(*args), math.degrees(math.atan(mu)), atol=1e-6)


@pytest.mark.parametrize("mu", [0.1, 0.9, 10.0, 1e6])
def test_same_face_never_force_closure(mu):
    phi1 = np.array([-40.0, -10.0, 5.0, 30.0, 100.0, 190.0])
    phi2 = np.array([-30.0, 40.0, 44.0, -44.0, 60.0, 220.0])
    args = (SQ.contour_point(phi1), SQ.inward_normal(phi1),
            SQ.contour_point(phi2), SQ.inward_normal(phi2), mu)
    assert not force_closure_nguyen(*args).any()
    assert not force_closure_wrench(*args).any()
    # the segment lies in the face: 90° from both normals
    np.testing.assert_allclose(cone_margin_deg(*args), math.degrees(math.atan(mu)) - 90.0,
                               atol=1e-9)


def test_coincident_contacts_never_force_closure():
    p, n = np.array([0.05, 0.0]), np.array([-1.0, 0.0])
    assert not force_closure_nguyen(p, n, p, n, 0.9)
    assert not force_closure_wrench(p, n, p, n, 0.9)


def _null_space_intensities(p1, n1, p2, n2):
    """Independent homogeneous solution c_h of W c = 0 (thesis eq. 3.2) from the SVD, scaled
    so that the first normal intensity is positive. t = n rotated by +90°."""
    def w(p, f):
        return [f[0], f[1], p[0] * f[1] - p[1] * f[0]]

    t1, t2 = np.array([-n1[1], n1[0]]), np.array([-n2[1], n2[0]])
    W = np.array([w(p1, n1), w(p2, n2), w(p1, t1), w(p2, t2)]).T
    assert np.linalg.matrix_rank(W) == 3
    c = np.linalg.svd(W)[2][-1]
    np.testing.assert_allclose(W @ c, 0, atol=1e-14)
    return c / np.sign(c[0])


def test_two_sided_friction_cone_refuses_what_the_one_sided_inequality_accepts():
    """The thesis prints c3 <= mu c1 (one-sided); the Coulomb cone is |c3| < mu c1.

    Here the internal force at contact 1 leans 36.9° (atan 3/4) off the normal on the
    negative-tangent side: c3 = -3k, c1 = 4k, and contact 2 is pushed straight along its
    normal (c4 = 0). The one-sided inequalities hold for mu = 0.3, the cone does not
    (36.9° > atan 0.3 = 16.7°), and the library refuses it.
    """
    mu = 0.3
    p1, n1 = np.array([0.0, 0.0]), np.array([0.0, 1.0])
    p2, n2 = np.array([0.03, 0.04]), np.array([-0.6, -0.8])
    c1, c2, c3, c4 = _null_space_intensities(p1, n1, p2, n2)
    assert c1 > 0 and c2 > 0
    np.testing.assert_allclose([c3 / c1, c4 / c2], [-0.75, 0.0], atol=1e-12)
    assert c3 <= mu * c1 and c4 <= mu * c2          # thesis's one-sided inequalities: pass
    assert not abs(c3) < mu * c1                      # two-sided Coulomb cone: fail
    assert not force_closure_wrench(p1, n1, p2, n2, mu)
    assert not force_closure_nguyen(p1, n1, p2, n2, mu)
    # mirrored (positive tangent side) is refused too, and both become stable when the
    # cone is wide enough (atan 0.76 > 36.87°)
    q2 = np.array([-0.03, 0.04])
    m2 = np.array([0.6, -0.8])
    assert not force_closure_wrench(p1, n1, q2, m2, mu)
    assert force_closure_wrench(p1, n1, p2, n2, 0.76)
    assert force_closure_wrench(p1, n1, q2, m2, 0.76)


def test_exactly_on_the_cone_boundary_is_not_force_closure():
    """3-4-5 triangle: d = (3/8, 1/2) is exactly atan(3/4) off n1 = (0, 1) and off
    -n2 = (0, 1), with mu = 0.75. Every input is a dyadic float, so the geometry is exactly
    on both cone boundaries (0.03, 0.04 would not be: they round to a grasp 1e-14° inside)."""
    p1, n1 = np.array([0.0, 0.0]), np.array([0.0, 1.0])
    p2, n2 = np.array([0.375, 0.5]), np.array([0.0, -1.0])
    assert not force_closure_nguyen(p1, n1, p2, n2, 0.75)
    assert not force_closure_wrench(p1, n1, p2, n2, 0.75)
    np.testing.assert_allclose(cone_margin_deg(p1, n1, p2, n2, 0.75), 0.0, atol=1e-9)
    # a hair either side
    for mu, expect in ((0.75 * (1 - 1e-6), False), (0.75 * (1 + 1e-6), True)):
        assert force_closure_nguyen(p1, n1, p2, n2, mu) == expect
        assert force_closure_wrench(p1, n1, p2, n2, mu) == expect


def test_cone_margin_by_hand():
    # segment 30° off n1 and 10° off n2 (reversed): margin = atan(mu) - 30°
    p1, n1 = np.zeros(2), np.array([0.0, 1.0])
    d = np.array([math.sin(math.radians(30)), math.cos(math.radians(30))])
    p2 = 0.1 * d
    a2 = math.radians(10)
    # n2 is -d rotated by 10°
    c, s = math.cos(a2), math.sin(a2)
    n2 = -np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])
    for mu in (0.3, 0.5, 1.0):
        np.testing.assert_allclose(cone_margin_deg(p1, n1, p2, n2, mu),
                                   math.degrees(math.atan(mu)) - 30.0, atol=1e-9)
    assert not force_closure_nguyen(p1, n1, p2, n2, 0.5)  # atan .5 = 26.6° < 30°
    assert force_closure_nguyen(p1, n1, p2, n2, 0.6)      # atan .6 = 31.0° > 30°
    assert force_closure_wrench(p1, n1, p2, n2, 0.6)


# A star-shaped polygon with a V-shaped slot along +x: apex (0.03, 0), walls to
# (0.1, ±0.03) at 23.2° (atan 3/7) either side of the x axis. Fingers inside the slot
# pushing the walls apart (an *expanding* grasp) squeeze nothing, yet the internal force
# (vertical) lies 23.2° off each wall's inward normal.
V_SLOT = Polygon([[0.03, 0.0], [0.1, 0.03], [-0.08, 0.08], [-0.08, -0.08], [0.1, -0.03]])


def test_expanding_grasp_in_a_slot_both_tests_agree():
    """Thesis 3.2 only asks for c1, c2 >= 0 and the tangential intensities inside the cone,
    so the wrench test accepts the expanding grasp (fingers at ±4° on the two slot walls)
    for mu = 0.5 (atan 0.5 = 26.6° > 23.2°). The module docstring says the two tests are
    "mathematically the same set", so Nguyen's test must accept it too."""
    phi1, phi2 = np.array([4.0, 10.0]), np.array([356.0, 350.0])
    args = (V_SLOT.contour_point(phi1), V_SLOT.inward_normal(phi1),
            V_SLOT.contour_point(phi2), V_SLOT.inward_normal(phi2))
    c = _null_space_intensities(*(a[0] for a in args))
    assert c[0] > 0 and c[1] > 0 and abs(c[2]) < 0.5 * c[0] and abs(c[3]) < 0.5 * c[1]
    np.testing.assert_allclose(abs(c[2] / c[0]), 3 / 7, rtol=1e-12)  # tan 23.2°
    assert force_closure_wrench(*args, 0.5).all()
    assert not force_closure_wrench(*args, 0.4).any()  # atan 0.4 = 21.8° < 23.2°
    assert force_closure_nguyen(*args, 0.5).all()
    assert (cone_margin_deg(*args, 0.5) > 0).all()


def test_broadcasting_shapes():
    p1 = np.zeros((4, 3, 2))
    n1 = np.broadcast_to([0.0, 1.0], (4, 3, 2))
    p2 = np.broadcast_to([0.0, 0.1], (4, 3, 2))
    n2 = np.broadcast_to([0.0, -1.0], (4, 3, 2))
    assert force_closure_nguyen(p1, n1, p2, n2, 0.3).shape == (4, 3)
    assert force_closure_wrench(p1, n1, p2, n2, 0.3).all()


@pytest.mark.parametrize("mu", [0, -0.3, float("nan"), float("inf"), "0.3", True, None])
def test_bad_mu_refused(mu):
    p1, n1 = np.zeros(2), np.array([0.0, 1.0])
    p2, n2 = np.array([0.0, 0.1]), np.array([0.0, -1.0])
    for f in (force_closure_nguyen, force_closure_wrench, cone_margin_deg):
        with pytest.raises(ValueError, match="mu"):
            f(p1, n1, p2, n2, mu)
